//! `insertAlongUV(uvSet, filePath, height[, heightDirection, heightAlignment])`:
//! an asset laid out along the shape's texture coordinates.
//!
//! The asset's x extent is mapped to u in [0, 1], its z extent to v in
//! [0, 1] reversed (the asset's largest z at v = 0: "z is mapped to -v"),
//! both repeated over every whole tile of the shape's uv range, and its y
//! extent is scaled to `height` along the height direction: the shape's
//! scope y axis (`scope.y`, the default) or its vertex normals
//! (`vertex.normal`: averaged over the faces that share a vertex,
//! interpolated over each face). `alignPosition` (the default) sets the
//! asset's bottom on the surface; `keepPosition` keeps its height relative
//! to its origin (an asset reaching below y = 0 goes below the surface).
//!
//! Only triangles and quads without holes receive the asset, as in
//! CityEngine. Per face and tile, every asset polygon is clipped (in uv
//! space) to the face's uv polygon and its corners are carried to the
//! surface: by barycentric coordinates on triangles, by inverting the
//! bilinear map of the corners' uvs on quads. The asset is thus cut at the
//! face edges and bent along the surface. Its materials and texture
//! coordinates stay; its normals do not (`setNormals` can make new ones).
//! A face whose uvs are mirrored (running clockwise seen along the height
//! direction) gets a mirrored asset, with its faces turned so they keep
//! facing outwards.

use cga_geometry::{DVec2, DVec3, Mesh, UV_SETS};

/// Most asset copies one operation creates, so that a uv range of 1e6 does
/// not fill memory.
pub const MAX_TILES: usize = 100_000;

/// How the asset stands on the surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    pub height: f64,
    /// Along the vertex normals (else along the scope's y axis).
    pub along_normals: bool,
    /// Keep the asset's height relative to its origin (else its bottom on
    /// the surface).
    pub keep_position: bool,
}

/// A corner of an asset polygon while it is clipped: its place in the
/// asset's uv-aligned space, its height, and its own texture coordinates.
#[derive(Clone, Copy, Debug)]
struct Corner {
    uv: DVec2,
    height: f64,
    tex: [DVec2; UV_SETS],
}

impl Corner {
    fn lerp(&self, other: &Corner, t: f64) -> Corner {
        let mut tex = self.tex;
        for (a, b) in tex.iter_mut().zip(&other.tex) {
            *a = a.lerp(*b, t);
        }
        Corner {
            uv: self.uv.lerp(other.uv, t),
            height: self.height + (other.height - self.height) * t,
            tex,
        }
    }
}

/// An asset polygon in its normalised space: loops (outer first) of corners.
struct Polygon {
    loops: Vec<Vec<Corner>>,
    material: u32,
    lo: DVec2,
    hi: DVec2,
}

/// A surface face that receives the asset: its corners' uvs (counter-
/// clockwise), positions and height directions, in the same order.
struct Target {
    uv: Vec<DVec2>,
    pos: Vec<DVec3>,
    up: Vec<DVec3>,
    /// The uvs run clockwise seen along the height direction.
    mirrored: bool,
}

/// The geometry of `insertAlongUV` on `surface` (scope-local coordinates;
/// `scope_y` is the scope's y axis in them) with UV set `set`; `None` if
/// more than [`MAX_TILES`] asset copies would be needed.
pub fn insert_along_uv(
    surface: &Mesh,
    set: usize,
    asset: &Mesh,
    place: Placement,
    scope_y: DVec3,
) -> Option<Mesh> {
    let mut out = Mesh::new();
    out.materials = asset.materials.clone();
    out.groups = asset.groups.clone();
    let sets: Vec<usize> = (0..UV_SETS).filter(|&k| asset.uvs[k].is_some()).collect();
    for &k in &sets {
        out.uvs[k] = Some(Vec::new());
    }
    let (Some(uvs), Some(polygons)) = (surface.uvs[set].as_deref(), normalised(asset, place))
    else {
        return Some(out);
    };
    let normals = place.along_normals.then(|| vertex_normals(surface));
    // Corners computed from the same asset vertex on the same face and tile
    // are bitwise equal: they share one position.
    let mut welded: std::collections::HashMap<[u64; 3], u32> = Default::default();
    let mut tiles = 0usize;
    for f in 0..surface.faces.len() {
        let Some(target) = target(surface, f, uvs, normals.as_deref(), scope_y) else {
            continue;
        };
        let (lo, hi) = bounds(&target.uv);
        let eps = 1e-9 * (hi - lo).max_element();
        // The tiles the face covers; a range that ends a rounding error
        // past a whole number does not reach into the next tile.
        let tiles_of = |lo: f64, hi: f64| {
            let first = (lo + eps).floor();
            let last = (hi - eps).ceil().max(first + 1.0);
            (first as i64, last as i64)
        };
        let (i0, i1) = tiles_of(lo.x, hi.x);
        let (j0, j1) = tiles_of(lo.y, hi.y);
        let count = (i1 - i0).saturating_mul(j1 - j0);
        tiles = tiles.saturating_add(usize::try_from(count).unwrap_or(usize::MAX));
        if tiles > MAX_TILES {
            return None;
        }
        for i in i0..i1 {
            for j in j0..j1 {
                let shift = DVec2::new(i as f64, j as f64);
                for poly in &polygons {
                    // Polygons touching the face's border still count: an
                    // asset's end walls lie on the tile's edges.
                    if poly.hi.x + shift.x < lo.x - eps
                        || poly.lo.x + shift.x > hi.x + eps
                        || poly.hi.y + shift.y < lo.y - eps
                        || poly.lo.y + shift.y > hi.y + eps
                    {
                        continue;
                    }
                    place_polygon(&mut out, &mut welded, poly, shift, &target, &sets);
                }
            }
        }
    }
    Some(out)
}

/// The asset's polygons in the space where its x extent is [0, 1] (u) and
/// its z extent [1, 0] (v), with each corner's height above the surface.
fn normalised(asset: &Mesh, place: Placement) -> Option<Vec<Polygon>> {
    let (lo, hi) = crate::shape::local_bounds(asset)?;
    let span = hi - lo;
    let inv = |s: f64| if s.abs() > 1e-12 { 1.0 / s } else { 0.0 };
    let (ix, iy, iz) = (inv(span.x), inv(span.y), inv(span.z));
    // An asset without extent along x (z) stands in the middle of the tile.
    let (mid_x, mid_z) = (
        if ix == 0.0 { 0.5 } else { 0.0 },
        if iz == 0.0 { 0.5 } else { 0.0 },
    );
    let mut polygons = Vec::with_capacity(asset.faces.len());
    for f in 0..asset.faces.len() {
        let mut loops = Vec::new();
        for &l in asset.face_loops(f) {
            let corners: Vec<Corner> = asset
                .loop_corners(l)
                .map(|c| {
                    let p = asset.positions[asset.corners[c] as usize];
                    let mut tex = [DVec2::ZERO; UV_SETS];
                    for (k, t) in tex.iter_mut().enumerate() {
                        if let Some(u) = &asset.uvs[k] {
                            *t = u.get(c).copied().unwrap_or(DVec2::ZERO);
                        }
                    }
                    let y = if place.keep_position { p.y } else { p.y - lo.y };
                    Corner {
                        uv: DVec2::new((p.x - lo.x) * ix + mid_x, (hi.z - p.z) * iz + mid_z),
                        height: y * iy * place.height,
                        tex,
                    }
                })
                .collect();
            loops.push(corners);
        }
        if loops.first().is_none_or(|l| l.len() < 3) {
            continue;
        }
        let (lo, hi) = bounds(&loops[0].iter().map(|c| c.uv).collect::<Vec<_>>());
        polygons.push(Polygon {
            loops,
            material: asset.faces[f].material,
            lo,
            hi,
        });
    }
    Some(polygons)
}

fn bounds(points: &[DVec2]) -> (DVec2, DVec2) {
    points.iter().fold(
        (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    )
}

/// Face `f` as a target, if it is a triangle or quad without holes whose uvs
/// span an area.
fn target(
    surface: &Mesh,
    f: usize,
    uvs: &[DVec2],
    normals: Option<&[DVec3]>,
    scope_y: DVec3,
) -> Option<Target> {
    let loops = surface.face_loops(f);
    if loops.len() != 1 || !(3..=4).contains(&loops[0].len) {
        return None;
    }
    let corners: Vec<usize> = surface.loop_corners(loops[0]).collect();
    let mut uv: Vec<DVec2> = corners.iter().map(|&c| uvs[c]).collect();
    let mut pos: Vec<DVec3> = corners
        .iter()
        .map(|&c| surface.positions[surface.corners[c] as usize])
        .collect();
    let mut up: Vec<DVec3> = match normals {
        Some(n) => corners
            .iter()
            .map(|&c| n[surface.corners[c] as usize])
            .collect(),
        None => vec![scope_y; corners.len()],
    };
    let area2: f64 = (0..uv.len())
        .map(|i| uv[i].perp_dot(uv[(i + 1) % uv.len()]))
        .sum();
    let (lo, hi) = bounds(&uv);
    let extent = (hi - lo).max_element();
    let has_area = area2.abs() > 1e-12 * extent * extent;
    if !has_area {
        return None;
    }
    // Clipping wants the uv polygon counter-clockwise.
    if area2 < 0.0 {
        uv.reverse();
        pos.reverse();
        up.reverse();
    }
    // Orientation of the surface parameterisation: d(pos)/du x d(pos)/dv
    // against the height direction, from the first corner's triangle.
    let (e1, e2) = (pos[1] - pos[0], pos[2] - pos[0]);
    let (d1, d2) = (uv[1] - uv[0], uv[2] - uv[0]);
    let det = d1.perp_dot(d2);
    let dpdu = (e1 * d2.y - e2 * d1.y) / det;
    let dpdv = (e2 * d1.x - e1 * d2.x) / det;
    let mean_up: DVec3 = up.iter().copied().sum();
    let mirrored = dpdu.cross(dpdv).dot(mean_up) < 0.0;
    Some(Target {
        uv,
        pos,
        up,
        mirrored,
    })
}

/// Area-weighted normals of the surface's positions, welded: faces that
/// meet at a position share its normal.
fn vertex_normals(surface: &Mesh) -> Vec<DVec3> {
    let tol = cga_geometry::topology::mesh_tolerance(surface);
    let key = |p: DVec3| {
        let q = (p / tol.max(1e-12)).round();
        (q.x as i64, q.y as i64, q.z as i64)
    };
    let mut sums: std::collections::HashMap<(i64, i64, i64), DVec3> = Default::default();
    for f in 0..surface.faces.len() {
        let l = surface.outer_loop(f);
        let pts: Vec<DVec3> = surface.loop_points(l).collect();
        // Newell: twice the area times the unit normal.
        let mut n = DVec3::ZERO;
        for i in 0..pts.len() {
            n += pts[i].cross(pts[(i + 1) % pts.len()]);
        }
        for p in pts {
            *sums.entry(key(p)).or_default() += n;
        }
    }
    surface
        .positions
        .iter()
        .map(|&p| {
            sums.get(&key(p))
                .copied()
                .unwrap_or(DVec3::ZERO)
                .normalize_or(DVec3::Y)
        })
        .collect()
}

/// Clips `poly` (moved by `shift`) to the target's uv polygon, carries it
/// onto the surface and appends it to `out`.
fn place_polygon(
    out: &mut Mesh,
    welded: &mut std::collections::HashMap<[u64; 3], u32>,
    poly: &Polygon,
    shift: DVec2,
    t: &Target,
    sets: &[usize],
) {
    let mut loops: Vec<Vec<Corner>> = Vec::with_capacity(poly.loops.len());
    for (k, l) in poly.loops.iter().enumerate() {
        let moved: Vec<Corner> = l
            .iter()
            .map(|c| Corner {
                uv: c.uv + shift,
                ..*c
            })
            .collect();
        let clipped = clip(moved, &t.uv);
        if clipped.len() >= 3 {
            loops.push(clipped);
        } else if k == 0 {
            return;
        }
    }
    let first_loop = out.loops.len() as u32;
    for l in &loops {
        let start = out.corners.len() as u32;
        let order: Box<dyn Iterator<Item = &Corner>> = if t.mirrored {
            Box::new(l.iter().rev())
        } else {
            Box::new(l.iter())
        };
        for c in order {
            let (p, up) = surface_point(t, c.uv);
            let p = p + up * c.height;
            let next = out.positions.len() as u32;
            let id = *welded.entry(p.to_array().map(f64::to_bits)).or_insert(next);
            if id == next {
                out.positions.push(p);
            }
            out.corners.push(id);
            for &k in sets {
                if let Some(u) = out.uvs[k].as_mut() {
                    u.push(c.tex[k]);
                }
            }
        }
        out.loops.push(cga_geometry::Loop {
            start,
            len: l.len() as u32,
        });
    }
    out.faces.push(cga_geometry::Face {
        first_loop,
        loop_count: loops.len() as u32,
        material: poly.material,
        group: 0,
        tags: 0,
    });
}

/// Sutherland-Hodgman: `subject` clipped to the convex, counter-clockwise
/// polygon `clip_poly`, with the corners' attributes interpolated on the
/// cut edges. Points within a rounding error outside an edge count as on
/// it: an asset's end wall lies exactly on a tile border, and rotated or
/// normalised uvs put that border at 1e-17 instead of 0. (A non-convex quad
/// is clipped to its edges in order, which is only approximately right.)
fn clip(mut subject: Vec<Corner>, clip_poly: &[DVec2]) -> Vec<Corner> {
    let n = clip_poly.len();
    let (lo, hi) = bounds(clip_poly);
    let extent = (hi - lo).max_element().max(1e-300);
    for i in 0..n {
        if subject.is_empty() {
            break;
        }
        let (a, b) = (clip_poly[i], clip_poly[(i + 1) % n]);
        let edge = b - a;
        // perp_dot is the distance to the edge times the edge's length.
        let tol = 1e-9 * extent * edge.length();
        let side = |p: DVec2| {
            let s = edge.perp_dot(p - a);
            if s.abs() <= tol {
                0.0
            } else {
                s
            }
        };
        let input = std::mem::take(&mut subject);
        for j in 0..input.len() {
            let cur = &input[j];
            let next = &input[(j + 1) % input.len()];
            let (sc, sn) = (side(cur.uv), side(next.uv));
            if sc >= 0.0 {
                subject.push(*cur);
            }
            if (sc > 0.0 && sn < 0.0) || (sc < 0.0 && sn > 0.0) {
                let t = sc / (sc - sn);
                subject.push(cur.lerp(next, t));
            }
        }
    }
    subject
}

/// The surface point (and height direction) of the target at `uv`.
fn surface_point(t: &Target, uv: DVec2) -> (DVec3, DVec3) {
    let w = weights(&t.uv, uv);
    let mut p = DVec3::ZERO;
    let mut up = DVec3::ZERO;
    for (k, &wk) in w.iter().enumerate().take(t.uv.len()) {
        p += t.pos[k] * wk;
        up += t.up[k] * wk;
    }
    (p, up.normalize_or(t.up[0]))
}

/// Interpolation weights of the corners at `q`: barycentric on triangles,
/// the inverse of the bilinear map on quads (Newton's method from the
/// centre; a parallelogram, as projected uvs give, converges at once).
fn weights(uv: &[DVec2], q: DVec2) -> [f64; 4] {
    if uv.len() == 3 {
        let (a, b, c) = (uv[0], uv[1], uv[2]);
        let det = (b - a).perp_dot(c - a);
        let wb = (q - a).perp_dot(c - a) / det;
        let wc = (b - a).perp_dot(q - a) / det;
        return [1.0 - wb - wc, wb, wc, 0.0];
    }
    let bilinear = |s: f64, t: f64| {
        uv[0] * ((1.0 - s) * (1.0 - t))
            + uv[1] * (s * (1.0 - t))
            + uv[2] * (s * t)
            + uv[3] * ((1.0 - s) * t)
    };
    let (mut s, mut t) = (0.5, 0.5);
    for _ in 0..20 {
        let r = bilinear(s, t) - q;
        if r.length_squared() < 1e-28 {
            break;
        }
        let ds = (uv[1] - uv[0]) * (1.0 - t) + (uv[2] - uv[3]) * t;
        let dt = (uv[3] - uv[0]) * (1.0 - s) + (uv[2] - uv[1]) * s;
        let det = ds.perp_dot(dt);
        if det.abs() < 1e-300 {
            break;
        }
        s -= r.perp_dot(dt) / det;
        t -= ds.perp_dot(r) / det;
    }
    [(1.0 - s) * (1.0 - t), s * (1.0 - t), s * t, (1.0 - s) * t]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bilinear_weights_invert_a_trapezoid() {
        let uv = [
            DVec2::new(0.0, 0.0),
            DVec2::new(4.0, 0.0),
            DVec2::new(3.0, 2.0),
            DVec2::new(1.0, 2.0),
        ];
        for (s, t) in [(0.25, 0.5), (0.9, 0.1), (0.0, 1.0)] {
            let q = uv[0] * ((1.0 - s) * (1.0 - t))
                + uv[1] * (s * (1.0 - t))
                + uv[2] * (s * t)
                + uv[3] * ((1.0 - s) * t);
            let w = weights(&uv, q);
            let back: DVec2 = (0..4).map(|k| uv[k] * w[k]).sum();
            assert!((back - q).length() < 1e-12);
            assert!((w[1] + w[2] - s).abs() < 1e-9, "{w:?}");
        }
    }

    #[test]
    fn clipping_a_square_to_a_triangle_interpolates() {
        let corner = |x: f64, y: f64| Corner {
            uv: DVec2::new(x, y),
            height: x,
            tex: [DVec2::new(x, y); UV_SETS],
        };
        let square = vec![
            corner(0.0, 0.0),
            corner(1.0, 0.0),
            corner(1.0, 1.0),
            corner(0.0, 1.0),
        ];
        let tri = [DVec2::ZERO, DVec2::new(1.0, 0.0), DVec2::new(0.0, 1.0)];
        let out = clip(square, &tri);
        let area: f64 = (0..out.len())
            .map(|i| out[i].uv.perp_dot(out[(i + 1) % out.len()].uv))
            .sum::<f64>()
            / 2.0;
        assert!((area - 0.5).abs() < 1e-12);
        for c in &out {
            assert!((c.height - c.uv.x).abs() < 1e-12);
            assert!((c.tex[3] - c.uv).length() < 1e-12);
        }
    }
}
