"""Lots from what Python users hold: shapely geometries, GeoSeries and
GeoDataFrames, GeoJSON mappings (and anything with ``__geo_interface__``),
and ``(n, 3)`` coordinate arrays.

Each lot becomes ``(name, polygons, gis_axes, attrs)`` for the native
module: ``polygons`` a list of polygons, each a list of ``(n, 3)`` float64
rings (outer ring first, then holes).

Axes: GIS data (shapely, GeoPandas, GeoJSON, ``(n, 2)`` arrays) has x east
and y north; the engine's lots lie in its x-z plane with y up, so a point
``(x, y)`` becomes ``(x, 0, -y)``, as the ``cga`` command reads GIS files.
An ``(n, 3)`` array is taken in the engine's own axes (y up), as PyPRT's
``InitialShape`` vertices are.
"""

import math
from collections.abc import Mapping

import numpy as np


def _ring(coords):
    a = np.asarray(coords, dtype=np.float64)
    if a.ndim != 2 or a.shape[1] not in (2, 3):
        raise ValueError(f"a ring must be a list of (x, y) or (x, y, z) points, got shape {a.shape}")
    if a.shape[1] == 2:
        a = np.column_stack([a, np.zeros(len(a))])
    else:
        a = np.ascontiguousarray(a)
    return a


def _geojson_polygons(geometry):
    """Polygons of a GeoJSON geometry mapping, as lists of rings."""
    kind = geometry.get("type")
    coords = geometry.get("coordinates")
    if kind == "Polygon":
        return [[_ring(r) for r in coords]]
    if kind == "MultiPolygon":
        return [[_ring(r) for r in poly] for poly in coords]
    if kind == "GeometryCollection":
        out = []
        for g in geometry.get("geometries", []):
            out.extend(_geojson_polygons(g))
        return out
    raise ValueError(f"a lot must be a Polygon or MultiPolygon, not a {kind}")


def _shapely_polygons(geom):
    kind = geom.geom_type
    if kind == "Polygon":
        return [[_ring(geom.exterior.coords)] + [_ring(h.coords) for h in geom.interiors]]
    if kind in ("MultiPolygon", "GeometryCollection"):
        out = []
        for g in geom.geoms:
            if g.geom_type in ("Polygon", "MultiPolygon", "GeometryCollection"):
                out.extend(_shapely_polygons(g))
        if out:
            return out
    raise ValueError(f"a lot must be a Polygon or MultiPolygon, not a {kind}")


def _is_shapely(x):
    return type(x).__module__.startswith("shapely")


def _one(lot):
    """``(polygons, gis_axes, attrs)`` of one lot."""
    if _is_shapely(lot):
        if lot.is_empty:
            raise ValueError("the geometry is empty")
        return _shapely_polygons(lot), True, {}
    if isinstance(lot, np.ndarray) or (isinstance(lot, (list, tuple)) and lot and not isinstance(lot[0], Mapping)):
        a = np.asarray(lot, dtype=np.float64)
        if a.ndim == 2 and a.shape[1] == 3:
            return [[np.ascontiguousarray(a)]], False, {}
        if a.ndim == 2 and a.shape[1] == 2:
            return [[_ring(a)]], True, {}
        raise ValueError(f"a lot array must have shape (n, 3) or (n, 2), not {a.shape}")
    if hasattr(lot, "__geo_interface__") and not isinstance(lot, Mapping):
        lot = lot.__geo_interface__
    if isinstance(lot, Mapping):
        if lot.get("type") == "Feature":
            geometry = lot.get("geometry")
            if geometry is None:
                raise ValueError("the feature has no geometry")
            return _geojson_polygons(geometry), True, dict(lot.get("properties") or {})
        return _geojson_polygons(lot), True, {}
    raise TypeError(f"cannot make a lot of a {type(lot).__name__}")


def _plain(v):
    """numpy scalars as Python values; missing values as None."""
    if isinstance(v, np.generic):
        v = v.item()
    if isinstance(v, float) and math.isnan(v):
        return None
    if isinstance(v, np.ndarray):
        return [_plain(x) for x in v.tolist()]
    return v


def _is_frame(x):
    return type(x).__name__ == "GeoDataFrame" and hasattr(x, "geometry")


def _is_series(x):
    return type(x).__name__ == "GeoSeries"


def _check_crs(crs):
    if crs is not None and getattr(crs, "is_geographic", False):
        raise ValueError(
            f"the lots are in a geographic CRS ({crs.name}): longitude and latitude are not "
            "metres. Project them first, for example frame.to_crs(frame.estimate_utm_crs())"
        )


def normalize(lots, attrs, attribute_names, skip=False):
    """The native lots for ``lots``, with per-lot attributes from frame
    columns named like attributes (and ``seed``) and from ``attrs`` when
    it is a list (one mapping per lot). Returns ``(native_lots, common)``
    where ``common`` are the attributes set for every lot."""
    names = set(attribute_names) | {"seed"}
    per_lot = None
    common = {}
    if attrs is None:
        pass
    elif isinstance(attrs, Mapping):
        common = dict(attrs)
    else:
        per_lot = list(attrs)

    columns = []
    if _is_frame(lots):
        _check_crs(lots.crs)
        columns = [c for c in lots.columns if c in names and c != lots.geometry.name]
        values = {c: lots[c].tolist() for c in columns}
        ids = [str(i) for i in lots.index]
        geoms = list(lots.geometry)
    elif _is_series(lots):
        _check_crs(lots.crs)
        ids = [str(i) for i in lots.index]
        geoms = list(lots)
    elif _is_shapely(lots) or isinstance(lots, Mapping) or (isinstance(lots, np.ndarray) and lots.ndim == 2):
        if isinstance(lots, Mapping) and lots.get("type") == "FeatureCollection":
            geoms = list(lots.get("features", []))
            ids = [str(f.get("id", i)) for i, f in enumerate(geoms)]
        else:
            geoms = [lots]
            ids = ["0"]
    else:
        geoms = list(lots)
        ids = [str(i) for i in range(len(geoms))]

    if per_lot is not None and len(per_lot) != len(geoms):
        raise ValueError(f"attrs has {len(per_lot)} entries for {len(geoms)} lots")
    out = []
    for i, geom in enumerate(geoms):
        try:
            if geom is None:
                raise ValueError("the lot has no geometry")
            polygons, gis, own = _one(geom)
        except (ValueError, TypeError) as e:
            if skip:
                # (name, why): the native side lists it as invalid in its
                # place, so that the other lots keep their indices and seeds.
                out.append((ids[i], str(e)))
                continue
            raise type(e)(f"lot {i} ({ids[i]}): {e}") from None
        lot_attrs = {k: v for k, v in own.items() if k in names}
        for c in columns:
            lot_attrs[c] = values[c][i]
        if per_lot is not None and per_lot[i]:
            lot_attrs.update(per_lot[i])
        out.append((ids[i], polygons, gis, [(k, _plain(v)) for k, v in lot_attrs.items()]))
    return out, [(k, _plain(v)) for k, v in common.items()]
