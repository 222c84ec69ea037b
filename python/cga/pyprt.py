"""A small PyPRT-compatible layer: a script written for PyPRT runs on this
engine by changing its import::

    from cga import pyprt

    shape = pyprt.InitialShape([0, 0, 0,  0, 0, 100,  100, 0, 100,  100, 0, 0])
    m = pyprt.ModelGenerator([shape]).generate_model([{}], "candler.rpk")[0]
    m.get_vertices(), m.get_indices(), m.get_faces(), m.get_report()

Rule packages (``.rpk``) and ``.cga`` files both work. What differs:
faces are triangles (``get_faces()`` is all 3s; PRT keeps polygons), and
random numbers come from this engine's generator, so stochastic rules
give other (equally valid) buildings. Encoders: ``com.esri.pyprt.PyEncoder``
(the default: models in memory), ``com.esri.prt.codecs.GLTFEncoder`` and
``com.esri.prt.codecs.OBJEncoder`` (files in ``outputPath``).
"""

import os

import numpy as np

from . import Rules, write

__all__ = ["InitialShape", "ModelGenerator", "GeneratedModel", "initialize_prt", "shutdown_prt", "is_prt_initialized"]

PY_ENCODER = "com.esri.pyprt.PyEncoder"
ENCODERS = {
    PY_ENCODER: None,
    "com.esri.prt.codecs.GLTFEncoder": "glb",
    "com.esri.prt.codecs.OBJEncoder": "obj",
}


def initialize_prt(*_args, **_kwargs):
    """Nothing to start: kept for scripts that call it."""


def shutdown_prt():
    """Nothing to stop: kept for scripts that call it."""


def is_prt_initialized():
    return True


class InitialShape:
    """A lot: flat vertex coordinates ``[x0, y0, z0, x1, ...]`` in the
    engine's axes (y up), and optionally the vertex indices and vertex
    count of each face (PyPRT's ``InitialShape(vertices, indices,
    face_counts)``); without them, one face through all vertices."""

    def __init__(self, vertices, indices=None, face_counts=None, holes=None):
        v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
        if indices is None:
            indices = list(range(len(v)))
        if face_counts is None:
            face_counts = [len(indices)]
        self._vertices = v
        self._indices = list(indices)
        self._face_counts = list(face_counts)
        self._holes = holes

    def get_vertex_count(self):
        return len(self._vertices)

    def get_index_count(self):
        return len(self._indices)

    def get_face_counts_count(self):
        return len(self._face_counts)

    def get_path(self):
        return ""

    def _faces(self):
        """Each face's ring of vertices, an (n, 3) array."""
        faces, at = [], 0
        for n in self._face_counts:
            faces.append(self._vertices[self._indices[at:at + n]])
            at += n
        return faces


class GeneratedModel:
    """One generated lot, as PyPRT's ``GeneratedModel`` gives it."""

    def __init__(self, index, model):
        self._index = index
        self._model = model

    def get_initial_shape_index(self):
        return self._index

    def get_vertices(self):
        """Flat vertex coordinates ``[x0, y0, z0, ...]`` of all meshes."""
        if not self._model.meshes:
            return []
        return np.concatenate([m.positions.ravel() for m in self._model.meshes]).tolist()

    def get_indices(self):
        """Flat vertex indices of the faces (triangles), into get_vertices."""
        out, offset = [], 0
        for m in self._model.meshes:
            out.append(m.indices.astype(np.int64).ravel() + offset)
            offset += len(m.positions)
        return np.concatenate(out).tolist() if out else []

    def get_faces(self):
        """The vertex count of each face: 3 (faces are triangles)."""
        return [3] * self._model.triangles

    def get_report(self):
        """Reports as PRT aggregates them: ``KEY_n``, ``KEY_sum``,
        ``KEY_avg``, ``KEY_min``, ``KEY_max`` (bool and string reports:
        the last value)."""
        values = {}
        for k, v in self._model.report_values:
            values.setdefault(k, []).append(v)
        out = {}
        for k, vs in values.items():
            if all(isinstance(v, float) for v in vs):
                out.update({
                    f"{k}_n": float(len(vs)), f"{k}_sum": float(sum(vs)),
                    f"{k}_avg": float(sum(vs) / len(vs)), f"{k}_min": min(vs), f"{k}_max": max(vs),
                })
            else:
                out.update({f"{k}_n": float(len(vs))})
                out.update({f"{k}_{s}": vs[-1] for s in ("sum", "avg", "min", "max")})
        return out

    def get_cga_prints(self):
        return "".join(p + "\n" for p in self._model.prints)

    def get_cga_errors(self):
        return [] if self._model.error is None else [self._model.error]

    def get_attributes(self):
        return {}


class ModelGenerator:
    """Generates models on initial shapes, as PyPRT's does."""

    def __init__(self, initial_shapes):
        self._shapes = list(initial_shapes)

    def generate_model(self, shape_attributes, rule_package_path=None,
                       geometry_encoder=PY_ENCODER, encoder_options=None):
        if rule_package_path is None:
            raise ValueError("give the rule package (.rpk) or rule file (.cga) to generate with")
        options = dict(encoder_options or {})
        if geometry_encoder not in ENCODERS:
            raise ValueError(f"unknown encoder {geometry_encoder!r}; known: {', '.join(ENCODERS)}")
        attrs = list(shape_attributes)
        if len(attrs) == 1 and len(self._shapes) > 1:
            attrs = attrs * len(self._shapes)
        if len(attrs) != len(self._shapes):
            raise ValueError(f"{len(attrs)} attribute sets for {len(self._shapes)} shapes")
        seeds = [a.get("seed") for a in attrs]
        per_lot = [{k: v for k, v in a.items() if k != "seed" and not k.startswith("/")} for a in attrs]
        # CityEngine names attributes of the main rule file "/ruleFile/name";
        # PyPRT scripts often use the bare name. Both are accepted.
        for a, p in zip(attrs, per_lot):
            for k, v in a.items():
                if k.startswith("/") and k.count("/") >= 2:
                    p[k.rsplit("/", 1)[1]] = v
        for p, s in zip(per_lot, seeds):
            if s is not None:
                p["seed"] = s
        rules = Rules.open(rule_package_path)
        lots = []
        for i, shape in enumerate(self._shapes):
            faces = shape._faces()
            if len(faces) != 1:
                raise ValueError(f"initial shape {i} has {len(faces)} faces; this layer takes shapes of one face")
            lots.append(faces[0])
        kind = ENCODERS[geometry_encoder]
        emit_geometry = options.get("emitGeometry", True)
        if kind is None:
            # Vertices and faces alone, as PyEncoder gives them: positions
            # shared where a leaf's faces meet.
            geometry = "positions" if emit_geometry else False
            models = rules.generate(lots, attrs=per_lot, geometry=geometry, progress=False)
            return [GeneratedModel(m.index, m) for m in models]
        out_dir = options.get("outputPath", ".")
        os.makedirs(out_dir, exist_ok=True)
        path = os.path.join(out_dir, options.get("baseName", "model") + "." + kind)
        models = rules.generate(lots, attrs=per_lot, output=path, progress=False)
        return [GeneratedModel(m.index, m) for m in models]

