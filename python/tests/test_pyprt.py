"""cga.pyprt, the PyPRT-compatible layer, against what CityEngine's
runtime gave on the oracle's rule packages (../shared/prt-oracle/golden,
skipped when the shared folder is absent)."""

import json
import os

import numpy as np
import pytest

from cga import pyprt

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
ORACLE = os.path.join(ROOT, "..", "shared", "prt-oracle")
needs_oracle = pytest.mark.skipif(not os.path.isdir(ORACLE), reason="../shared/prt-oracle is absent")

RECT = [0, 0, 0, 20, 0, 0, 20, 0, -30, 0, 0, -30]


def golden(name, what):
    with open(os.path.join(ORACLE, "golden", name, what)) as f:
        return json.load(f)


def obj_face(path):
    verts, face = [], None
    with open(path) as f:
        for line in f:
            p = line.split()
            if p and p[0] == "v":
                verts.append([float(x) for x in p[1:4]])
            elif p and p[0] == "f" and face is None:
                face = [int(q.split("/")[0]) - 1 for q in p[1:]]
    return [c for i in face for c in verts[i]]


@needs_oracle
def test_reports_as_prt_aggregates_them():
    rpk = os.path.join(ORACLE, "rpk", "extrusion_rule.rpk")
    shape = pyprt.InitialShape(RECT)
    [m] = pyprt.ModelGenerator([shape]).generate_model(
        [{"minBuildingHeight": 23.0, "maxBuildingHeight": 23.0}], rpk
    )
    want = golden("extrusion_rule.rect20x30.h23", "reports.json")
    got = m.get_report()
    assert sorted(got) == sorted(want)
    for k, v in want.items():
        assert got[k] == (pytest.approx(v) if isinstance(v, float) else v), k
    assert m.get_initial_shape_index() == 0
    assert m.get_cga_errors() == []

    [d] = pyprt.ModelGenerator([shape]).generate_model([{}], os.path.join(ORACLE, "rpk", "dynamic_imports.rpk"))
    assert d.get_report() == pytest.approx(golden("dynamic_imports.rect20x30", "reports.json"))


@needs_oracle
def test_candler_geometry_matches_prt(tmp_path):
    rpk = os.path.join(ORACLE, "rpk", "candler.rpk")
    shape = pyprt.InitialShape(obj_face(os.path.join(ORACLE, "lots", "candler_footprint.obj")))
    [m] = pyprt.ModelGenerator([shape]).generate_model([{}], rpk)
    want = golden("candler.candler_footprint", "summary.json")
    v = np.array(m.get_vertices()).reshape(-1, 3)
    idx = np.array(m.get_indices()).reshape(-1, 3)
    assert m.get_faces() == [3] * len(idx)
    p = v[idx]
    area = 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1).sum()
    assert area == pytest.approx(want["totals"]["area"], rel=1e-3)
    assert v.min(axis=0) == pytest.approx(want["bbox"]["min"], abs=1e-3)
    assert v.max(axis=0) == pytest.approx(want["bbox"]["max"], abs=1e-3)
    # Vertices shared where a leaf's faces meet, as PRT shares them: about
    # as many as PRT gives (85,777), half of a vertex per face corner.
    assert len(v) < 1.2 * want["totals"]["vertices"]
    assert len(np.unique(idx)) == len(v)
    # The GLTF encoder writes a GLB where outputPath and baseName say.
    pyprt.ModelGenerator([shape]).generate_model(
        [{}], rpk, "com.esri.prt.codecs.GLTFEncoder",
        {"outputPath": str(tmp_path), "baseName": "candler", "outputFormat": "GLB"},
    )
    assert (tmp_path / "candler.glb").read_bytes()[:4] == b"glTF"


def test_cga_files_and_bad_encoders(tmp_path):
    rules = tmp_path / "r.cga"
    rules.write_text('attr h = 3\nLot --> extrude(h) report("v", geometry.volume) print("hi") X.\n')
    shapes = [pyprt.InitialShape(RECT), pyprt.InitialShape([0, 0, 0, 2, 0, 0, 2, 0, -2])]
    a, b = pyprt.ModelGenerator(shapes).generate_model([{"h": 2.0}, {"/r/h": 10.0}], str(rules))
    assert a.get_report()["v_sum"] == pytest.approx(1200.0)
    assert b.get_report()["v_sum"] == pytest.approx(20.0)
    assert a.get_cga_prints() == "hi\n"
    assert len(a.get_faces()) == 12
    with pytest.raises(ValueError, match="unknown encoder"):
        pyprt.ModelGenerator(shapes).generate_model([{}], str(rules), "com.esri.prt.codecs.Nope", {})
