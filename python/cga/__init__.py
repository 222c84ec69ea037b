"""CGA: procedural buildings from lots, on the open CGA engine.

    >>> import cga, shapely
    >>> rules = cga.Rules.from_string('''
    ... attr height = 10
    ... Lot --> extrude(height) comp(f) { top : report("roof", geometry.area) Roof. | side : Wall. }
    ... ''')
    >>> [model] = rules.generate([shapely.box(0, 0, 20, 30)], attrs={"height": 12})
    >>> model.reports["roof"]
    600.0
    >>> sum(len(m.indices) for m in model.meshes)
    10

See ``docs/python.md`` for the whole API.
"""

import os
import threading
from dataclasses import dataclass, field
from typing import Any, List, Optional

import numpy as np

from . import _cga
from ._lots import normalize as _normalize

__all__ = [
    "Rules",
    "Model",
    "Mesh",
    "Attribute",
    "Diagnostic",
    "RuleError",
    "Limits",
    "write",
    "generate_frame",
]


@dataclass(frozen=True)
class Diagnostic:
    """An error or warning in a rule file: where, and what."""

    severity: str
    message: str
    file: Optional[str] = None
    line: Optional[int] = None
    column: Optional[int] = None
    end_line: Optional[int] = None
    end_column: Optional[int] = None
    line_text: Optional[str] = None
    label: Optional[str] = None
    notes: List[str] = field(default_factory=list)
    rendered: str = ""

    @property
    def is_error(self):
        return self.severity == "error"

    def __str__(self):
        return self.rendered or self.message


def _str_file(d):
    if d.get("file") is not None:
        d["file"] = os.fspath(d["file"])
    return d


class RuleError(Exception):
    """A rule file with errors. ``file``, ``line``, ``column`` and
    ``message`` are those of the first error; ``diagnostics`` has all."""

    def __init__(self, diagnostics):
        self.diagnostics = list(diagnostics)
        errors = [d for d in self.diagnostics if d.is_error] or self.diagnostics
        first = errors[0] if errors else Diagnostic("error", "the rules have errors")
        self.file, self.line, self.column = first.file, first.line, first.column
        self.message = first.message
        where = f"{first.file}:{first.line}:{first.column}: " if first.file else ""
        more = f" (and {len(errors) - 1} more)" if len(errors) > 1 else ""
        super().__init__(f"{where}{first.message}{more}")


@dataclass(frozen=True)
class Attribute:
    """A rule attribute: ``type`` is ``float``, ``bool``, ``string`` or an
    array type; ``default`` its value on the default lot (20 x 30);
    ``annotations`` maps ``Range``, ``Enum``, ``Group``, ... to their
    arguments (a list of ``(name or None, value)``)."""

    name: str
    type: Optional[str]
    default: Any
    annotations: dict
    doc: Optional[str] = None
    file: Optional[str] = None
    line: Optional[int] = None

    def _arg(self, annotation, name, index):
        args = self.annotations.get(annotation)
        if args is None:
            return None
        for n, v in args:
            if n == name:
                return v
        positional = [v for n, v in args if n is None]
        return positional[index] if index < len(positional) else None

    @property
    def range(self):
        """``(min, max)`` of ``@Range``, or None."""
        lo, hi = self._arg("Range", "min", 0), self._arg("Range", "max", 1)
        return None if lo is None or hi is None else (lo, hi)

    @property
    def enum(self):
        """The values of ``@Enum``, or None."""
        args = self.annotations.get("Enum")
        if args is None:
            return None
        out = []
        for n, v in args:
            if n == "restricted":
                continue
            out.extend(v if isinstance(v, list) else [v])
        return out

    @property
    def group(self):
        return self._arg("Group", "name", 0)

    @property
    def description(self):
        return self._arg("Description", "value", 0)

    @property
    def hidden(self):
        return "Hidden" in self.annotations


@dataclass(frozen=True)
class Limits:
    """Where runaway rules stop (per lot): derivation depth, shapes,
    seconds, faces of one shape's geometry."""

    max_depth: int = 1000
    max_shapes: int = 5_000_000
    max_seconds: float = 300.0
    max_faces: int = 5_000_000


class Mesh:
    """The triangles of one material: ``positions`` and ``normals``
    (n, 3) float64, ``uvs`` (n, 2) float64, ``indices`` (m, 3) uint32 into
    them (counter-clockwise seen from the normal's side). y is up. Generated
    with ``geometry="positions"``: ``normals`` and ``uvs`` are None."""

    __slots__ = ("material", "positions", "normals", "uvs", "indices", "_material_index")

    def __init__(self, material_index, material, positions, normals, uvs, indices):
        self._material_index = material_index
        self.material = material
        self.positions = positions
        self.normals = normals
        self.uvs = uvs
        self.indices = indices

    def __repr__(self):
        return f"<cga.Mesh {self.material.get('name') or self.material['color']}: {len(self.indices)} triangles>"


class Model:
    """What generating one lot gave.

    ``meshes``: one :class:`Mesh` per material (empty when geometry was not
    kept); ``materials``: dicts (``name``, ``color``, ``opacity``,
    ``textures``, ...); ``reports``: each ``report()`` key with its value
    (numbers summed over the lot's reports, other values the last one, as
    CityEngine's report tables have them); ``report_values``: every
    ``(key, value)`` in order; ``prints``; ``warnings``; ``error``: the
    error that stopped the lot (what was made before it is kept), or None.
    """

    __slots__ = (
        "index", "name", "meshes", "materials", "reports", "report_values",
        "prints", "warnings", "error", "shapes", "leaves", "_written", "_native_materials",
        "_rules",
    )

    def __init__(self, d, rules):
        self.index = d["index"]
        self.name = d["name"]
        self._native_materials = d["materials"]
        self.materials = self._native_materials.to_dicts() if len(self._native_materials) else []
        self.meshes = [Mesh(m[0], self.materials[m[0]], *m[1:]) for m in d["meshes"]]
        self.report_values = d["reports"]
        reports = {}
        for k, v in self.report_values:
            prev = reports.get(k)
            if isinstance(v, float) and isinstance(prev, float):
                reports[k] = prev + v
            else:
                reports[k] = v
        self.reports = reports
        self.prints = d["prints"]
        self.warnings = d["warnings"]
        e = d["error"]
        self.error = None if e is None else e["message"]
        self.shapes = d["shapes"]
        self.leaves = d["leaves"]
        self._written = d.get("written")
        self._rules = rules

    @classmethod
    def failed(cls, index, name, why, rules):
        """The model of a lot that could not be made."""
        return cls({
            "index": index, "name": name, "materials": _NO_MATERIALS, "meshes": [],
            "reports": [], "prints": [], "warnings": [], "error": {"message": why},
            "shapes": 0, "leaves": 0,
        }, rules)

    @property
    def triangles(self):
        """Triangles over all meshes; for a model generated into a file
        (``output=``), the triangles written of it (the same number: an
        asset written once and placed as instances counts per placement)."""
        if self._written is not None and not self.meshes:
            return self._written
        return sum(len(m.indices) for m in self.meshes)

    def to_trimesh(self):
        """The model as one ``trimesh.Trimesh`` with a face colour per
        material (needs trimesh)."""
        import trimesh

        if not self.meshes:
            return trimesh.Trimesh()
        parts, offset, faces, colors = [], 0, [], []
        for m in self.meshes:
            parts.append(m.positions)
            faces.append(m.indices.astype(np.int64) + offset)
            offset += len(m.positions)
            rgb = np.clip(np.asarray(m.material["color"]) * 255, 0, 255)
            rgba = np.append(rgb, m.material.get("opacity", 1.0) * 255).astype(np.uint8)
            colors.append(np.tile(rgba, (len(m.indices), 1)))
        return trimesh.Trimesh(
            vertices=np.vstack(parts),
            faces=np.vstack(faces),
            face_colors=np.vstack(colors),
            process=False,
        )

    def __repr__(self):
        state = f" error: {self.error}" if self.error else ""
        return f"<cga.Model {self.index} ({self.name}): {self.triangles} triangles{state}>"


class _NoMaterials:
    def __len__(self):
        return 0


_NO_MATERIALS = _NoMaterials()


def _stderr_is_terminal():
    import sys

    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):
        return False


def _progress_bar(progress, total):
    """A callable(done, total) for the native loop, or None."""
    if progress is False:
        return None, None
    if progress is None and (total < 1000 or not _stderr_is_terminal()):
        return None, None
    if callable(progress) and progress is not True:
        return progress, None
    try:
        from tqdm.auto import tqdm
    except ImportError:
        return None, None
    bar = tqdm(total=total, unit="lot")

    def update(done, _total):
        bar.update(done - bar.n)

    return update, bar


class Rules:
    """Rules loaded from a ``.cga`` file or ``.rpk`` rule package: their
    ``attributes``, ``diagnostics``, ``start_rules``, and generation."""

    def __init__(self, native, spec=None):
        self._native = native
        self._spec = spec
        self._attributes = None

    def __reduce__(self):
        # Rules travel (to Dask workers, other processes) as what they were
        # loaded from, and are loaded once per process there.
        if self._spec is None:
            raise TypeError("these rules cannot be pickled")
        return (_load, (self._spec,))

    @classmethod
    def open(cls, path, *, workspaces=(), check=True):
        """Loads a rule file (``.cga``) or rule package (``.rpk``).
        ``workspaces``: CityEngine workspace folders where ``/Project/...``
        paths are looked for. Raises :class:`RuleError` when the rules
        have errors (``check=False``: gives them, with their diagnostics)."""
        path = os.fspath(path)
        if not os.path.exists(path):
            raise FileNotFoundError(path)
        spec = ("open", os.path.abspath(path), tuple(os.fspath(w) for w in workspaces))
        rules = _load(spec, fresh=True)
        if check:
            rules._raise_errors()
        return rules

    @classmethod
    def from_string(cls, text, files=None, *, path=None, disk=True, workspaces=(), check=True):
        """Loads rule text. ``files`` maps paths (relative to the rule
        file's folder, or absolute) to their text or bytes: imports,
        assets and tables served from memory; other files are read from
        disk unless ``disk=False``. ``path``: where the text is as if it
        were a file (default: ``rules.cga`` in the current folder)."""
        path = os.path.abspath(os.fspath(path) if path is not None else "rules.cga")
        base = os.path.dirname(path)
        served = []
        for name, content in (files or {}).items():
            full = os.path.normpath(os.path.join(base, os.fspath(name)))
            if isinstance(content, str):
                content = content.encode("utf-8")
            served.append((full, bytes(content)))
        spec = ("text", path, text, tuple(served), bool(disk), tuple(os.fspath(w) for w in workspaces))
        rules = _load(spec, fresh=True)
        if check:
            rules._raise_errors()
        return rules

    def _raise_errors(self):
        if self._native.has_errors:
            raise RuleError(self.diagnostics)

    @property
    def path(self):
        """The rule file's path (inside a rule package: ``city.rpk/rules/x.cga``)."""
        return os.fspath(self._native.path)

    @property
    def diagnostics(self):
        """Every error and warning of the rule file and its imports."""
        return [Diagnostic(**_str_file(d)) for d in self._native.diagnostics()]

    @property
    def has_errors(self):
        return self._native.has_errors

    @property
    def attributes(self):
        """The attributes of the main rule file, by name."""
        if self._attributes is None:
            out = []
            for d in self._native.attributes():
                annotations = {}
                for name, args in d.pop("annotations"):
                    annotations.setdefault(name, args)
                out.append(Attribute(annotations=annotations, **_str_file(d)))
            self._attributes = out
        return self._attributes

    def attribute(self, name):
        for a in self.attributes:
            if a.name == name:
                return a
        raise KeyError(name)

    @property
    def start_rules(self):
        return self._native.start_rules()

    @property
    def styles(self):
        return self._native.styles()

    def generate(self, lots, attrs=None, seed=0, start_rule=None, jobs=None, *,
                 geometry=True, output=None, progress=None, limits=None, invalid="raise",
                 first_index=0):
        """Generates models on ``lots``: shapely polygons or multipolygons
        (holes too), a GeoSeries, a GeoDataFrame (columns named like
        attributes set them per lot), GeoJSON mappings (a Feature's
        properties set attributes), ``(n, 3)`` arrays in the engine's axes
        (y up), or a list of any of these.

        ``attrs``: attribute values for every lot (a dict), or one dict
        per lot (a list). ``seed``: the run's seed. ``jobs``: threads
        (default: all cores). ``geometry=False``: reports, prints and
        errors only; ``geometry="positions"``: meshes of positions and
        triangles alone (the same triangles, each leaf's faces sharing a
        vertex where they meet, as its mesh has it; ``normals`` and
        ``uvs`` are None), lighter and faster when only the shape of the
        model counts (volumes, footprints, ``to_trimesh()``). ``output``: write the models into this ``.glb``,
        ``.gltf`` or ``.obj`` file as they are generated (memory stays
        flat however many lots); the returned models then have no meshes.
        ``progress``: a tqdm bar (True; by default from 1,000 lots when
        tqdm is installed and standard error is a terminal), False, or a callable ``(done, total)``.

        ``invalid``: a lot that cannot be made (NaN coordinates, fewer than
        3 points, not a polygon, an unknown attribute) raises ValueError
        naming it (``"raise"``), or is a model with that ``error`` and no
        geometry (``"report"``). ``first_index``: the place of the first lot
        in a larger run (a partition's): each lot gets the index and the
        seed it has in that run (also after lots left out as invalid).

        Returns one :class:`Model` per lot, in order. Lots run in parallel
        with the GIL released; Ctrl-C stops the generation.
        """
        if invalid not in ("raise", "report"):
            raise ValueError(f"invalid must be 'raise' or 'report', not {invalid!r}")
        skip = invalid == "report"
        if isinstance(geometry, str):
            if geometry != "positions":
                raise ValueError(f'geometry must be True, False or "positions", not {geometry!r}')
            kind = "positions"
        else:
            kind = "meshes" if geometry else "none"
        native_lots, common = _normalize(lots, attrs, self._native.attribute_names(), skip=skip)
        if self.has_errors:
            raise RuleError(self.diagnostics)
        callback, bar = _progress_bar(progress, len(native_lots))
        lim = None
        if limits is not None:
            lim = (limits.max_depth, limits.max_shapes, float(limits.max_seconds), limits.max_faces)
        try:
            models, stats, bad = self._native.generate(
                native_lots, common, int(seed), start_rule, jobs, kind,
                None if output is None else os.path.abspath(os.fspath(output)),
                callback, lim, int(first_index), skip,
            )
        finally:
            if bar is not None:
                bar.close()
        self.last_write = stats
        out = [Model(m, self) for m in models]
        if bad:
            out.extend(Model.failed(i, name, why, self) for i, name, why in bad)
            out.sort(key=lambda m: m.index)
        return out


_loaded = {}
_loaded_lock = threading.Lock()


def _load(spec, fresh=False):
    """Rules for a load specification. Unpickled rules are loaded once per
    process (a Dask worker loads the rules of many partitions once);
    ``fresh``: loaded anew (``Rules.open`` sees a file's changes)."""
    rules = None
    if not fresh:
        with _loaded_lock:
            rules = _loaded.get(spec)
    if rules is None:
        if spec[0] == "open":
            native = _cga.load(spec[1], list(spec[2]))
        else:
            _, path, text, served, disk, workspaces = spec
            native = _cga.load_text(path, text, list(served), disk, list(workspaces))
        rules = Rules(native, spec)
        with _loaded_lock:
            # Files change: only rules without errors are kept.
            if not native.has_errors:
                _loaded[spec] = rules
    return rules


def write(models, path):
    """Writes generated models (with their geometry) into one ``.glb``,
    ``.gltf`` or ``.obj`` file; textures are found as the rules that made
    the models find them. Returns the counts written (``faces``,
    ``triangles``) and ``warnings``."""
    models = list(models)
    if any(k.normals is None for m in models for k in m.meshes):
        raise ValueError('models generated with geometry="positions" have no normals or '
                         'texture coordinates to write: generate them with geometry=True')
    rules = next((m._rules._native for m in models if m._rules is not None), None)
    data = [
        (m._native_materials,
         [(k._material_index, k.positions, k.normals, k.uvs, k.indices) for k in m.meshes])
        for m in models
    ]
    return _cga.write(os.path.abspath(os.fspath(path)), rules, data)


def generate_frame(frame, rules, attrs=None, seed=0, start_rule=None, jobs=None, *,
                   output=None, progress=None, limits=None, errors="cga_error"):
    """``frame`` (a GeoDataFrame) with one column per report key (each
    lot's reported numbers summed, as CityEngine's report tables have
    them) and, named ``errors``, each lot's error (None where it was
    generated). ``rules``: :class:`Rules` or a path. ``output``: also write
    the model of every lot into this file."""
    if not isinstance(rules, Rules):
        rules = Rules.open(rules)
    models = rules.generate(
        frame, attrs=attrs, seed=seed, start_rule=start_rule, jobs=jobs,
        geometry=False, output=output, progress=progress, limits=limits,
    )
    return _with_reports(frame, models, errors)


def _with_reports(frame, models, errors="cga_error"):
    out = frame.copy()
    keys = []
    for m in models:
        for k in m.reports:
            if k not in keys:
                keys.append(k)
    for k in keys:
        out[k] = [m.reports.get(k) for m in models]
    if errors:
        out[errors] = [m.error for m in models]
    return out
