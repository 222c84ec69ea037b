//! Initial shapes: lots from a `W,D` rectangle, a grid of them, OBJ faces,
//! or GIS files (see [`crate::gis`]).
//!
//! Conventions: y is up, lots lie in the x-z plane, counter-clockwise seen
//! from above, and the first edge is the street front. The initial pivot
//! sits on the first vertex with its x axis along the first edge and its y
//! axis along the lot's normal; the scope is the lot's bounding box in that
//! frame. A polygon given clockwise keeps its orientation: its normal points
//! down and so do its extrusions, as in CityEngine's runtime (a clockwise
//! 10 x 10 OBJ lot extruded by 7 spans y -7..0 there). Rings of GIS files
//! are oriented counter-clockwise (holes clockwise) when read.

use std::sync::Arc;

use cga_geometry::{DMat3, DVec3, Mesh};
use cga_value::Value;

use crate::shape::{Frame, Geometry, Scope, Shape};

/// One lot: its polygon (object coordinates) and per-lot attribute values.
#[derive(Clone, Debug)]
pub struct Lot {
    pub name: String,
    pub mesh: Mesh,
    /// Values for rule attributes of the same name (feature properties;
    /// the names are shared by the lots of a file).
    pub attrs: Vec<(Arc<str>, Value)>,
    /// Where the lot's frame lies on the globe, for lots of georeferenced
    /// GIS files (`getGeoCoord(lon|lat)`).
    pub geo_origin: Option<crate::geo::GeoOrigin>,
}

/// The lot `(0,0,0) (W,0,0) (W,0,-D) (0,0,-D)`.
pub fn rect(w: f64, d: f64) -> Lot {
    Lot {
        name: format!("rect {w}x{d}"),
        mesh: Mesh::polygon(&[
            DVec3::ZERO,
            DVec3::new(w, 0.0, 0.0),
            DVec3::new(w, 0.0, -d),
            DVec3::new(0.0, 0.0, -d),
        ]),
        attrs: Vec::new(),
        geo_origin: None,
    }
}

/// Parses `W,D` (as in `--lot rect:20,30`).
pub fn parse_rect(spec: &str) -> Result<Lot, String> {
    let (w, d) = spec
        .split_once(',')
        .ok_or_else(|| format!("expected `rect:W,D`, found `rect:{spec}`"))?;
    let parse = |s: &str| {
        s.trim()
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite() && *x > 0.0)
            .ok_or_else(|| format!("`{s}` is not a positive size in `rect:{spec}`"))
    };
    Ok(rect(parse(w)?, parse(d)?))
}

/// Each face of an OBJ file is one lot, with its texture coordinates and
/// normals (a street given with UVs can be split in uv space).
pub fn from_obj(path: &std::path::Path) -> Result<Vec<Lot>, String> {
    from_obj_in(&cga_world::DiskWorld, path)
}

/// [`from_obj`] with the file read through `world` (a lot's material
/// library is not read: lots take no materials).
pub fn from_obj_in(
    world: &dyn cga_world::World,
    path: &std::path::Path,
) -> Result<Vec<Lot>, String> {
    let bad = |e: &dyn std::fmt::Display| format!("cannot read lot file {}: {e}", path.display());
    let text = world.read_text(path).map_err(|e| bad(&e))?;
    let dir = path
        .parent()
        .map(std::path::Path::to_path_buf)
        .unwrap_or_default();
    let asset = cga_geometry::parse_obj(&text, &dir, |_| Ok(String::new())).map_err(|e| bad(&e))?;
    let mesh = asset.mesh;
    let lots: Vec<Lot> = (0..mesh.faces.len())
        .filter(|&f| mesh.outer_loop(f).len >= 3)
        .enumerate()
        .map(|(n, f)| {
            let loops: Vec<Vec<usize>> = mesh
                .face_loops(f)
                .iter()
                .map(|&l| mesh.loop_corners(l).collect())
                .collect();
            Lot {
                name: format!("{} face {n}", path.display()),
                mesh: face_mesh(&mesh, &loops, mesh.faces[f].material),
                attrs: Vec::new(),
                geo_origin: None,
            }
        })
        .collect();
    if lots.is_empty() {
        return Err(format!("{} has no faces to use as lots", path.display()));
    }
    Ok(lots)
}

/// Why a lot cannot be derived, if it cannot: a polygon with fewer than
/// three distinct corners, or without area, or with coordinates that are
/// not finite.
pub fn degenerate(lot: &Lot) -> Option<String> {
    let m = &lot.mesh;
    if m.positions.iter().any(|p| !p.is_finite()) {
        return Some("its coordinates are not all finite numbers".into());
    }
    let area = cga_geometry::measure::mesh_area(m);
    let size = cga_geometry::measure::bounds(m)
        .map(|(lo, hi)| (hi - lo).length())
        .unwrap_or(0.0);
    // NaN areas (from NaN coordinates) count as no area too.
    if area.is_nan() || area <= 1e-12 * size.max(1.0).powi(2) {
        return Some(
            "it has no area (fewer than three distinct corners, or collinear ones)".into(),
        );
    }
    None
}

/// Removes repeated consecutive corners (GIS polygons often close their
/// rings twice or repeat points), which would make zero-length edges.
/// Texture coordinates and normals of the kept corners stay.
pub fn remove_repeated_corners(mesh: &mut Mesh) {
    let tol = cga_geometry::topology::mesh_tolerance(mesh);
    let pos = |c: usize| mesh.positions[mesh.corners[c] as usize];
    let mut out: Option<Mesh> = None;
    for f in 0..mesh.faces.len() {
        let loops: Vec<Vec<usize>> = mesh
            .face_loops(f)
            .iter()
            .map(|&l| {
                let mut kept: Vec<usize> = Vec::with_capacity(l.len as usize);
                for c in mesh.loop_corners(l) {
                    if kept.last().is_none_or(|&k| pos(k).distance(pos(c)) > tol) {
                        kept.push(c);
                    }
                }
                while kept.len() > 1 && pos(kept[0]).distance(pos(*kept.last().unwrap())) <= tol {
                    kept.pop();
                }
                kept
            })
            .filter(|l| l.len() >= 3)
            .collect();
        if loops.is_empty() {
            continue;
        }
        let face = face_mesh(mesh, &loops, mesh.faces[f].material);
        match &mut out {
            Some(o) => cga_geometry::transform::merge(o, &face),
            None => out = Some(face),
        }
    }
    let mut out = out.unwrap_or_default();
    out.materials = mesh.materials.clone();
    *mesh = out;
}

/// A mesh of one face made of the given corners of `src` (outer loop, then
/// holes), with their texture coordinates and normals.
fn face_mesh(src: &Mesh, loops: &[Vec<usize>], material: u32) -> Mesh {
    let mut m = Mesh::new();
    m.materials = src.materials.clone();
    let mut index_loops: Vec<Vec<u32>> = Vec::with_capacity(loops.len());
    for l in loops {
        let mut idx = Vec::with_capacity(l.len());
        for &c in l {
            idx.push(m.positions.len() as u32);
            m.positions.push(src.positions[src.corners[c] as usize]);
        }
        index_loops.push(idx);
    }
    for (k, set) in src.uvs.iter().enumerate() {
        if let Some(uv) = set {
            m.uvs[k] = Some(loops.iter().flatten().map(|&c| uv[c]).collect());
        }
    }
    if let Some(n) = &src.normals {
        m.normals = Some(loops.iter().flatten().map(|&c| n[c]).collect());
    }
    // `add_face` keeps the attribute arrays, which already have one entry per corner.
    let refs: Vec<&[u32]> = index_loops.iter().map(|l| l.as_slice()).collect();
    m.add_face(
        &refs,
        material.min(src.materials.len().saturating_sub(1) as u32),
    );
    m
}

/// The initial shape of a lot, ready for derivation.
pub fn initial_shape(lot: &Lot, seed: u64, name: u32) -> Shape {
    let mut mesh = lot.mesh.clone();
    mesh.share_on_this_thread();
    remove_repeated_corners(&mut mesh);
    let (normal, x) = first_edge_frame(&mesh);
    let y = normal;
    let x = (x - y * x.dot(y)).normalize_or(DVec3::X);
    let z = x.cross(y);
    let axes = DMat3::from_cols(x, y, z);
    let origin = mesh
        .corners
        .first()
        .map(|&c| mesh.positions[c as usize])
        .unwrap_or(DVec3::ZERO);
    let pivot = Frame { origin, axes };
    let local: Vec<DVec3> = mesh.positions.iter().map(|&p| pivot.to_local(p)).collect();
    let (lo, hi) = local.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let (lo, hi) = if lo.x.is_finite() {
        (lo, hi)
    } else {
        (DVec3::ZERO, DVec3::ZERO)
    };
    let scope = Scope {
        frame: Frame {
            origin: pivot.to_object(lo),
            axes,
        },
        size: hi - lo,
        rot: DVec3::ZERO,
    };
    for (p, l) in mesh.positions.iter_mut().zip(local) {
        *p = l - lo;
    }
    Shape {
        scope,
        pivot,
        geometry: Geometry::new(Arc::new(mesh)),
        parent_center: scope.center(),
        rng: std::cell::Cell::new(seed_stream(seed as f64)),
        seedian: seed as f64,
        name,
        ..Shape::blank()
    }
}

/// The random stream state that a seed value starts.
pub fn seed_stream(seed: f64) -> u64 {
    seed.to_bits() ^ 0x0005_EED0_FC6A_u64
}

/// The normal of the first face and the direction of its first edge.
fn first_edge_frame(mesh: &Mesh) -> (DVec3, DVec3) {
    if mesh.faces.is_empty() {
        return (DVec3::Y, DVec3::X);
    }
    let pts: Vec<DVec3> = mesh.loop_points(mesh.outer_loop(0)).collect();
    let mut n = DVec3::ZERO;
    for i in 0..pts.len() {
        n += pts[i].cross(pts[(i + 1) % pts.len()]);
    }
    let n = n.normalize_or(DVec3::Y);
    // The first edge of non-zero length.
    let x = (0..pts.len())
        .map(|i| pts[(i + 1) % pts.len()] - pts[i])
        .find(|e| e.length() > 1e-12)
        .unwrap_or(DVec3::X);
    (n, x)
}

/// `grid:COLSxROWS` (20 x 30 lots) or `grid:COLSxROWS:LOTS.obj` (copies of
/// the OBJ's lots): a synthetic city of lots in a grid, for benchmarks.
pub fn grid(spec: &str) -> Result<Vec<Lot>, String> {
    grid_in(&cga_world::DiskWorld, spec)
}

/// [`grid`] with the OBJ read through `world`.
pub fn grid_in(world: &dyn cga_world::World, spec: &str) -> Result<Vec<Lot>, String> {
    let (dims, source) = match spec.split_once(':') {
        Some((d, s)) => (d, Some(s)),
        None => (spec, None),
    };
    let bad = || format!("expected grid:COLSxROWS[:LOTS.obj], found `grid:{spec}`");
    let (c, r) = dims.split_once('x').ok_or_else(bad)?;
    let cols: usize = c.trim().parse().map_err(|_| bad())?;
    let rows: usize = r.trim().parse().map_err(|_| bad())?;
    if cols == 0 || rows == 0 || cols.saturating_mul(rows) > 10_000_000 {
        return Err(bad());
    }
    let base = match source {
        Some(path) => from_obj_in(world, std::path::Path::new(path))?,
        None => vec![rect(20.0, 30.0)],
    };
    let (lo, hi) = base
        .iter()
        .filter_map(|l| cga_geometry::measure::bounds(&l.mesh))
        .fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), (a, b)| (lo.min(a), hi.max(b)),
        );
    let step = (hi - lo) + DVec3::splat(10.0);
    let mut lots = Vec::with_capacity(cols * rows * base.len());
    for row in 0..rows {
        for col in 0..cols {
            let shift = DVec3::new(col as f64 * step.x, 0.0, -(row as f64) * step.z);
            for b in &base {
                let mut l = b.clone();
                l.mesh.map_positions(|p| p + shift);
                l.name = format!("grid {col},{row} {}", b.name);
                lots.push(l);
            }
        }
    }
    Ok(lots)
}

/// Outer ring counter-clockwise seen from above (+y), holes clockwise.
pub(crate) fn orient_rings(positions: &[DVec3], loops: &mut [Vec<u32>]) {
    for (i, l) in loops.iter_mut().enumerate() {
        // Signed area in the x-z plane seen from +y: positive = counter-clockwise.
        let mut a = 0.0;
        for k in 0..l.len() {
            let p = positions[l[k] as usize];
            let q = positions[l[(k + 1) % l.len()] as usize];
            a += p.z * q.x - p.x * q.z;
        }
        let ccw = a > 0.0;
        if (i == 0) != ccw {
            l[1..].reverse();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rect_lot_scope_is_w_0_d() {
        let s = initial_shape(&rect(20.0, 30.0), 0, 0);
        assert!((s.scope.size - DVec3::new(20.0, 0.0, 30.0)).length() < 1e-12);
        // x along the first edge, y up, z towards the street (+z).
        assert!((s.scope.frame.axes.x_axis - DVec3::X).length() < 1e-12);
        assert!((s.scope.frame.axes.y_axis - DVec3::Y).length() < 1e-12);
        assert!((s.scope.frame.origin - DVec3::new(0.0, 0.0, -30.0)).length() < 1e-12);
        let m = s.object_mesh();
        assert!(m
            .positions
            .iter()
            .any(|p| (*p - DVec3::new(20.0, 0.0, -30.0)).length() < 1e-12));
    }

    #[test]
    fn clockwise_lot_faces_down() {
        let mut lot = rect(4.0, 2.0);
        lot.mesh.corners.reverse();
        let s = initial_shape(&lot, 0, 0);
        assert!((s.scope.frame.axes.y_axis + DVec3::Y).length() < 1e-12);
        // x along the first edge, (0,0,-2) -> (4,0,-2); a right-handed frame
        assert!((s.scope.frame.axes.x_axis - DVec3::X).length() < 1e-12);
        assert!((s.scope.frame.axes.z_axis + DVec3::Z).length() < 1e-12);
    }
}
