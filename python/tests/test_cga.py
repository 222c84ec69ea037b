"""The Python package against real values: areas, triangle counts,
heights and reports of rules whose models are known by hand, and of
examples/building.cga."""

import _thread
import os
import signal
import threading
import time

import numpy as np
import pytest
import shapely

import cga
from glb import glb_json

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BUILDING = os.path.join(ROOT, "examples", "building.cga")

BOX = """
attr height = 10
@Range(min=1, max=100) @Group("Massing") @Description("Eaves height")
attr eaves = 3
@Enum("flat", "gable")
attr roof = "flat"
Lot --> extrude(height) comp(f) { top : report("roof", geometry.area) color("#ff0000") Roof. | side : report("walls", 1) Wall. }
"""


def area(model):
    """The area of a model's triangles."""
    total = 0.0
    for m in model.meshes:
        p = m.positions[m.indices.astype(np.int64)]
        total += 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1).sum()
    return total


def height(model):
    return max(m.positions[:, 1].max() for m in model.meshes)


@pytest.fixture(scope="module")
def box():
    return cga.Rules.from_string(BOX)


@pytest.fixture(scope="module")
def building():
    return cga.Rules.open(BUILDING)


def test_attributes_of_building(building):
    by_name = {a.name: a for a in building.attributes}
    assert sorted(by_name) == ["floorHeight", "floors", "glassColor", "groundFloorHeight", "tileWidth", "wallColor"]
    assert by_name["floors"].type == "float"
    assert by_name["floors"].default == 6.0
    assert by_name["floors"].range == (1.0, 40.0)
    assert by_name["wallColor"].type == "string"
    assert by_name["wallColor"].default == "#d8cfc4"
    assert by_name["tileWidth"].range is None
    assert building.start_rules[0] == "Lot"
    assert not building.has_errors
    assert building.diagnostics == []


def test_annotations(box):
    eaves = box.attribute("eaves")
    assert eaves.range == (1.0, 100.0)
    assert eaves.group == "Massing"
    assert eaves.description == "Eaves height"
    assert box.attribute("roof").enum == ["flat", "gable"]
    assert box.attribute("height").annotations == {}


def test_building_heights_follow_floors(building):
    lots = [shapely.box(0, 0, 20, 30), shapely.box(100, 0, 140, 25)]
    models = building.generate(lots, attrs=[{"floors": 3}, {}])
    assert [m.index for m in models] == [0, 1]
    assert all(m.error is None for m in models)
    # Ground floor 4.5 m, then floors of 3.2 m.
    assert height(models[0]) == pytest.approx(4.5 + 3 * 3.2)
    assert height(models[1]) == pytest.approx(4.5 + 6 * 3.2)
    # Walls, glass, ledges and the roof: several materials.
    colours = {tuple(round(c, 3) for c in m["color"]) for m in models[0].materials}
    assert (round(0x7A / 255, 3),) * 3 in colours
    assert len(models[0].materials) >= 4
    # The roof lies at the top, over the whole footprint.
    roof = [m for m in models[0].meshes if np.allclose(m.positions[:, 1], 4.5 + 3 * 3.2)]
    assert roof and area_of(roof[0]) == pytest.approx(600.0)
    # x east, y north becomes x, -z: the lot spans z in [-30, 0].
    allpos = np.vstack([m.positions for m in models[0].meshes])
    assert allpos[:, 2].min() == pytest.approx(-30.0, abs=0.6)
    assert allpos[:, 0].min() == pytest.approx(0.0, abs=0.6)


def area_of(mesh):
    p = mesh.positions[mesh.indices.astype(np.int64)]
    return 0.5 * np.linalg.norm(np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), axis=1).sum()


def test_box_reports_areas_and_triangles(box):
    [m] = box.generate(shapely.box(0, 0, 20, 30))
    assert m.reports == {"roof": 600.0, "walls": 4.0}
    assert m.report_values == [("roof", 600.0)] + [("walls", 1.0)] * 4
    assert m.triangles == 4 * 2 + 2
    assert area(m) == pytest.approx(600 + 2 * (20 + 30) * 10)
    assert m.meshes[0].positions.dtype == np.float64
    assert m.meshes[0].indices.dtype == np.uint32
    assert m.meshes[0].uvs.shape[1] == 2
    # Normals are unit vectors.
    for mesh in m.meshes:
        assert np.allclose(np.linalg.norm(mesh.normals, axis=1), 1.0)


def test_holes_and_multipolygons(box):
    holed = shapely.box(0, 0, 10, 10).difference(shapely.box(4, 4, 6, 6))
    multi = shapely.MultiPolygon([shapely.box(0, 0, 10, 10), shapely.box(20, 0, 25, 4)])
    a, b = box.generate([holed, multi])
    assert a.reports["roof"] == pytest.approx(96.0)
    # Eight walls: four outside, four around the hole.
    assert a.reports["walls"] == 8.0
    assert b.reports["roof"] == pytest.approx(120.0)
    assert b.reports["walls"] == 8.0


def test_geojson_features_and_arrays(box):
    feature = {
        "type": "Feature",
        "properties": {"height": 4, "unrelated": "x"},
        "geometry": {"type": "Polygon", "coordinates": [[[0, 0], [6, 0], [6, 5], [0, 5], [0, 0]]]},
    }
    mapping = {"type": "Polygon", "coordinates": [[[0, 0], [2, 0], [2, 2], [0, 2]]]}
    # An (n, 3) array is in the engine's axes: y up.
    array = np.array([[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [3.0, 0.0, -3.0], [0.0, 0.0, -3.0]])
    f, g, a = box.generate([feature, mapping, array])
    assert f.reports["roof"] == pytest.approx(30.0)
    assert height(f) == pytest.approx(4.0)
    assert g.reports["roof"] == pytest.approx(4.0)
    assert height(g) == pytest.approx(10.0)
    assert a.reports["roof"] == pytest.approx(9.0)
    collection = {"type": "FeatureCollection", "features": [feature, {"type": "Feature", "id": "b", "properties": {}, "geometry": mapping}]}
    ms = box.generate(collection)
    assert [m.name for m in ms] == ["0", "b"]


def test_geodataframe_columns_set_attributes(box):
    gpd = pytest.importorskip("geopandas")
    frame = gpd.GeoDataFrame(
        {"height": [5.0, 20.0, np.nan], "name": ["a", "b", "c"]},
        geometry=[shapely.box(0, 0, 10, 10), shapely.box(0, 0, 4, 5), shapely.box(0, 0, 1, 1)],
    )
    models = box.generate(frame)
    assert [height(m) for m in models] == pytest.approx([5.0, 20.0, 10.0])
    out = cga.generate_frame(frame, box)
    assert list(out.columns) == ["height", "name", "geometry", "roof", "walls", "cga_error"]
    assert out["roof"].tolist() == pytest.approx([100.0, 20.0, 1.0])
    assert out["walls"].tolist() == [4.0, 4.0, 4.0]
    assert out["cga_error"].tolist() == [None, None, None]
    # A GeoSeries, seeded and with one attribute for all.
    [m] = box.generate(frame.geometry.iloc[:1], attrs={"height": 7})
    assert height(m) == pytest.approx(7.0)


def test_geographic_frames_are_refused(box):
    gpd = pytest.importorskip("geopandas")
    frame = gpd.GeoDataFrame(geometry=[shapely.box(8.5, 47.3, 8.5001, 47.3001)], crs="EPSG:4326")
    with pytest.raises(ValueError, match="geographic CRS"):
        box.generate(frame)


def test_rules_from_string_with_files_in_memory():
    rules = cga.Rules.from_string(
        'import lib : "lib/parts.cga"\n'
        'attr w = 2\n'
        'Lot --> extrude(lib.h) report("h", lib.h) report("t", lib.word) X.\n',
        files={"lib/parts.cga": "attr h = 6\nconst word = readTextFile(\"words.txt\")\n", "lib/words.txt": b"hello"},
        disk=False,
    )
    [m] = rules.generate(shapely.box(0, 0, 2, 2))
    assert m.reports == {"h": 6.0, "t": "hello"}
    assert height(m) == pytest.approx(6.0)


def test_rule_errors_name_the_place():
    with pytest.raises(cga.RuleError) as e:
        cga.Rules.from_string("attr a = 1\nLot --> extrud(a) X.\n", path="broken.cga")
    err = e.value
    assert err.file.endswith("broken.cga")
    assert (err.line, err.column) == (2, 9)
    assert err.message == "unknown operation or rule `extrud`"
    assert str(err) == err.file + ":2:9: unknown operation or rule `extrud`"
    # Rules with errors can still be looked at.
    rules = cga.Rules.from_string("attr a = 1\nLot --> extrude(a\n", check=False)
    # The argument list is still open at the end of the file.
    assert rules.has_errors
    assert [(d.severity, d.line, d.column) for d in rules.diagnostics] == [("error", 3, 1)]
    with pytest.raises(cga.RuleError):
        rules.generate(shapely.box(0, 0, 1, 1))
    with pytest.raises(FileNotFoundError):
        cga.Rules.open("no/such/rules.cga")


def test_bad_lots_raise_value_errors_naming_the_lot(box):
    good = shapely.box(0, 0, 1, 1)
    with pytest.raises(ValueError, match=r"lot 1 \(1\): .*not a finite number"):
        box.generate([good, np.array([[0, 0, 0], [np.nan, 0, 0], [1, 0, 1.0]])])
    with pytest.raises(ValueError, match=r"lot 2 .*2 distinct points"):
        box.generate([good, good, {"type": "Polygon", "coordinates": [[[0, 0], [1, 1], [0, 0]]]}])
    with pytest.raises(ValueError, match=r"lot 1 .*no attribute `heigth`"):
        box.generate([good, good], attrs=[{}, {"heigth": 3}])
    with pytest.raises(ValueError, match="no attribute `heigth`"):
        box.generate([good], attrs={"heigth": 3})
    with pytest.raises(ValueError, match="lot 0 .*Point"):
        box.generate([shapely.Point(0, 0)])
    with pytest.raises(ValueError, match="start rule|no rule"):
        box.generate([good], start_rule="Nope")


def test_a_lot_at_a_limit_is_reported_and_the_others_generated():
    rules = cga.Rules.from_string(
        'attr deep = false\n'
        'Lot --> case deep : Grow else : extrude(3) report("ok", 1) X.\n'
        'Grow --> split(x) { ~1 : Grow }*\n'
    )
    lots = [shapely.box(0, 0, 10, 10)] * 3
    models = rules.generate(lots, attrs=[{}, {"deep": True}, {}], limits=cga.Limits(max_depth=50))
    assert models[0].error is None and models[2].error is None
    assert models[0].reports == {"ok": 1.0}
    assert models[1].error is not None and "depth" in models[1].error
    # The extruded box: top, bottom and four sides.
    assert models[2].triangles == 12


def test_output_is_the_same_with_any_number_of_threads(building):
    lots = [shapely.box(i * 50, 0, i * 50 + 15 + i, 20 + 2 * i) for i in range(12)]
    one = building.generate(lots, jobs=1, seed=7)
    two = building.generate(lots, jobs=2, seed=7)
    for a, b in zip(one, two):
        assert a.triangles == b.triangles
        for ma, mb in zip(a.meshes, b.meshes):
            assert np.array_equal(ma.positions, mb.positions)
            assert np.array_equal(ma.indices, mb.indices)


def test_write_glb_and_obj(tmp_path, box, building):
    models = building.generate([shapely.box(0, 0, 20, 30), shapely.box(40, 0, 60, 30)])
    stats = cga.write(models, tmp_path / "city.glb")
    assert stats["triangles"] == sum(m.triangles for m in models)
    data = (tmp_path / "city.glb").read_bytes()
    assert data[:4] == b"glTF"
    # Written straight from the generation: the same triangles.
    direct = building.generate([shapely.box(0, 0, 20, 30), shapely.box(40, 0, 60, 30)], output=tmp_path / "direct.glb")
    assert direct[0].meshes == [] and building.last_write["triangles"] == stats["triangles"]
    # Each streamed model says how many triangles of it were written.
    assert [m.triangles for m in direct] == [m.triangles for m in models]
    assert models[0].triangles > 100
    cga.write(box.generate([shapely.box(0, 0, 2, 2)]), tmp_path / "box.obj")
    obj = (tmp_path / "box.obj").read_text()
    assert obj.count("\nf ") == 10
    with pytest.raises(ValueError, match=r"\.glb"):
        cga.write(models, tmp_path / "city.stl")


def test_far_lots_keep_their_millimetres(tmp_path, box):
    # Lots in a national grid's metres: GLB positions are relative to the
    # lots' centre, which the nodes' translation holds.
    far = shapely.box(2683000.0, 1247000.0, 2683020.123, 1247015.5)
    [model] = box.generate([far])
    xs = np.concatenate([m.positions[:, 0] for m in model.meshes])
    assert xs.min() == pytest.approx(2683000.0) and xs.max() == pytest.approx(2683020.123)
    for out in ("written.glb", "direct.glb"):
        if out == "written.glb":
            cga.write([model], tmp_path / out)
        else:
            box.generate([far], output=tmp_path / out)
        j = glb_json(tmp_path / out)
        t = j["nodes"][0]["translation"]
        assert t[0] == 2683010.0
        acc = j["accessors"][j["meshes"][0]["primitives"][0]["attributes"]["POSITION"]]
        # Local positions: the box's 20.123 m kept to a tenth of a millimetre.
        assert acc["max"][0] - acc["min"][0] == pytest.approx(20.123, abs=1e-4)
        assert abs(acc["min"][0] + t[0] - 2683000.0) < 1e-3


def test_to_trimesh(box):
    trimesh = pytest.importorskip("trimesh")
    [m] = box.generate(shapely.box(0, 0, 20, 30))
    t = m.to_trimesh()
    assert isinstance(t, trimesh.Trimesh)
    assert len(t.faces) == 10
    assert t.area == pytest.approx(600 + 2 * (20 + 30) * 10)
    assert t.bounds.tolist() == [[0, 0, -30], [20, 10, 0]]


def triangles_by_position(model):
    """The model's triangles as sorted rows of their nine coordinates."""
    rows = [m.positions[m.indices.astype(np.int64)].reshape(-1, 9) for m in model.meshes]
    return sorted(map(tuple, np.vstack(rows).tolist()))


def test_positions_alone(tmp_path, box):
    mass = cga.Rules.from_string("attr h = 10\nLot --> extrude(h) Mass.\n")
    lot = shapely.box(0, 0, 20, 30)
    [m] = mass.generate(lot, geometry="positions")
    [full] = mass.generate(lot)
    [k] = m.meshes
    # One leaf, a closed box: its six faces share its eight corners.
    assert k.positions.shape == (8, 3) and k.indices.shape == (12, 3)
    assert k.normals is None and k.uvs is None
    assert full.meshes[0].positions.shape == (24, 3)
    assert triangles_by_position(m) == triangles_by_position(full)
    # Shared corners make a closed surface: its signed volume is the box's.
    p = k.positions[k.indices.astype(np.int64)]
    volume = np.einsum("ij,ij->i", p[:, 0], np.cross(p[:, 1], p[:, 2])).sum() / 6
    assert volume == pytest.approx(20 * 30 * 10)
    # The box of comp's faces: each face its own leaf, the same triangles
    # and reports.
    [b] = box.generate(lot, geometry="positions")
    [bf] = box.generate(lot)
    assert triangles_by_position(b) == triangles_by_position(bf)
    assert b.reports == bf.reports == {"roof": 600.0, "walls": 4.0}
    with pytest.raises(ValueError, match="positions"):
        cga.write([b], str(tmp_path / "b.glb"))
    with pytest.raises(ValueError, match="geometry must be"):
        box.generate(lot, geometry="normals")


def test_prints_and_progress(box):
    rules = cga.Rules.from_string('Lot --> print("lot " + geometry.area) X.')
    seen = []
    models = rules.generate([shapely.box(0, 0, 2, 3)] * 5, progress=lambda done, total: seen.append((done, total)))
    assert [m.prints for m in models] == [["lot 6"]] * 5
    assert seen[-1] == (5, 5)


# Four million shapes. The condition reads where each shape stands, so
# that every one is derived: without geometry, subtrees that repeat
# elsewhere are otherwise derived once (docs/performance.md).
SLOW = """
Lot --> Grow(0)
Grow(n) --> case n < 22 && scope.tx >= 0 : split(x) { '0.5 : Grow(n + 1) | '0.5 : Grow(n + 1) } else : X.
"""


def test_ctrl_c_interrupts_a_generation():
    rules = cga.Rules.from_string(SLOW)
    lots = [shapely.box(0, 0, 10, 10)] * 64
    # Python's own Ctrl-C handler, also where the tests were started with
    # SIGINT ignored (a background job of a shell without job control),
    # where `interrupt_main` would do nothing.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        timer = threading.Timer(0.5, _thread.interrupt_main)
        start = time.perf_counter()
        timer.start()
        with pytest.raises(KeyboardInterrupt):
            rules.generate(lots, geometry=False, jobs=2)
        assert time.perf_counter() - start < 5.0
    finally:
        signal.signal(signal.SIGINT, previous)


def test_the_gil_is_released_while_generating():
    rules = cga.Rules.from_string(SLOW.replace("22", "17"))
    ticks = []
    stop = threading.Event()

    def tick():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.005)

    t = threading.Thread(target=tick)
    t.start()
    start = time.perf_counter()
    models = rules.generate([shapely.box(0, 0, 10, 10)] * 8, geometry=False, jobs=1)
    took = time.perf_counter() - start
    stop.set()
    t.join()
    # Every split made two shapes, 17 generations deep.
    assert all(m.shapes == 2 ** 18 - 2 for m in models)
    during = [x for x in ticks if start <= x <= start + took]
    # Ticking every 5 ms went on while the engine worked.
    assert took > 0.2
    assert len(during) > took / 0.005 * 0.3


def _boxes_in_a_child(conn):
    rules = cga.Rules.from_string(BOX)
    models = rules.generate([shapely.box(0, 0, 10, 10), shapely.box(20, 0, 25, 10)], jobs=2)
    conn.send([m.triangles for m in models])
    conn.close()


def test_a_forked_process_generates_after_its_parent(box):
    # The parent's worker threads wait for the next call between calls; a
    # forked child has none of them and must make its own.
    assert [m.triangles for m in box.generate([shapely.box(0, 0, 10, 10)] * 3, jobs=2)] == [10] * 3
    import multiprocessing

    ctx = multiprocessing.get_context("fork")
    parent, child = ctx.Pipe()
    p = ctx.Process(target=_boxes_in_a_child, args=(child,), daemon=True)
    p.start()
    assert parent.poll(60), "the forked child did not answer"
    assert parent.recv() == [10, 10]
    p.join(10)
    assert p.exitcode == 0


def test_calls_from_several_threads_at_once(building):
    lots = [shapely.box(i * 50, 0, i * 50 + 15 + i, 20 + 2 * i) for i in range(6)]
    want = [m.triangles for m in building.generate(lots, jobs=2, seed=3)]
    got = {}

    def call(k):
        got[k] = [m.triangles for m in building.generate(lots, jobs=2, seed=3)]

    threads = [threading.Thread(target=call, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(120)
    assert got == {k: want for k in range(4)}
