//! Texture coordinates carried from a face to the polygons cut out of it
//! (offsets, setbacks, convex pieces, inner rectangles, perimeter
//! sections): every new polygon lies in the plane of a source face, and
//! takes its coordinates from that face's affine map (position in the
//! plane -> uv, fitted to the face's corners), so that a texture projected
//! before the operation stays where it was.

use glam::{DMat3, DVec2, DVec3};

use crate::measure::{face_area, face_normal};
use crate::mesh::Mesh;
use crate::triangulate::plane_basis;

/// The affine map of one face and one uv set: `uv = m * (x, y, 1)` in the
/// face's plane basis.
struct Map {
    o: DVec3,
    u: DVec3,
    v: DVec3,
    coef: [[f64; 3]; 2],
}

impl Map {
    fn fit(mesh: &Mesh, f: usize, uvs: &[DVec2]) -> Option<Map> {
        let n = face_normal(mesh, f);
        if n == DVec3::ZERO {
            return None;
        }
        let (u, v) = plane_basis(n);
        let l = mesh.outer_loop(f);
        let o = mesh.positions[mesh.corners[l.start as usize] as usize];
        // Normal equations of the least-squares fit over all corners.
        let mut ata = DMat3::ZERO;
        let mut atb = [DVec3::ZERO; 2];
        for &lp in mesh.face_loops(f) {
            for c in mesh.loop_corners(lp) {
                let p = mesh.positions[mesh.corners[c] as usize] - o;
                let row = DVec3::new(p.dot(u), p.dot(v), 1.0);
                ata += DMat3::from_cols(row * row.x, row * row.y, row * row.z);
                atb[0] += row * uvs[c].x;
                atb[1] += row * uvs[c].y;
            }
        }
        if ata.determinant().abs() < 1e-18 {
            return None;
        }
        let inv = ata.inverse();
        let (a, b) = (inv * atb[0], inv * atb[1]);
        Some(Map {
            o,
            u,
            v,
            coef: [[a.x, a.y, a.z], [b.x, b.y, b.z]],
        })
    }

    fn at(&self, p: DVec3) -> DVec2 {
        let q = p - self.o;
        let (x, y) = (q.dot(self.u), q.dot(self.v));
        DVec2::new(
            self.coef[0][0] * x + self.coef[0][1] * y + self.coef[0][2],
            self.coef[1][0] * x + self.coef[1][1] * y + self.coef[1][2],
        )
    }
}

/// Gives `out` the uv sets of `src`: every face of `out` takes the map of
/// the source face whose plane it lies in and that contains its centre
/// (the nearest plane if none does). Faces of `out` keep zeros where no
/// map exists (a source face whose coordinates do not vary). Does nothing
/// if `src` has no texture coordinates.
pub fn carry_uvs(src: &Mesh, out: &mut Mesh) {
    if src.uvs.iter().all(Option::is_none) || out.faces.is_empty() {
        return;
    }
    let normals: Vec<DVec3> = (0..src.faces.len()).map(|f| face_normal(src, f)).collect();
    let scale = crate::measure::bounds(src).map_or(1.0, |(a, b)| (b - a).max_element().max(1.0));
    // The source face of every output face.
    let source: Vec<Option<usize>> = (0..out.faces.len())
        .map(|f| {
            let n = face_normal(out, f);
            let l = out.outer_loop(f);
            let pts: Vec<DVec3> = out.loop_points(l).collect();
            let c = pts.iter().copied().sum::<DVec3>() / pts.len().max(1) as f64;
            let mut best: Option<(f64, usize)> = None;
            for (s, &ns) in normals.iter().enumerate() {
                if ns == DVec3::ZERO {
                    continue;
                }
                let ps = src.positions[src.corners[src.outer_loop(s).start as usize] as usize];
                let off = ns.dot(c - ps).abs() + (1.0 - n.dot(ns).abs()) * scale;
                let inside = contains(src, s, ns, c);
                // Inside and in the plane first, then nearest plane.
                let score = off + if inside { 0.0 } else { scale };
                if best.is_none_or(|b| score < b.0) {
                    best = Some((score, s));
                }
            }
            best.map(|b| b.1)
        })
        .collect();
    for set in 0..src.uvs.len() {
        let Some(src_uv) = &src.uvs[set] else {
            continue;
        };
        let maps: Vec<Option<Map>> = (0..src.faces.len())
            .map(|s| {
                if face_area(src, s) > 0.0 {
                    Map::fit(src, s, src_uv)
                } else {
                    None
                }
            })
            .collect();
        let mut uv = vec![DVec2::ZERO; out.corners.len()];
        for (f, s) in source.iter().enumerate() {
            let Some(map) = s.and_then(|s| maps[s].as_ref()) else {
                continue;
            };
            for &l in out.face_loops(f) {
                for c in out.loop_corners(l) {
                    uv[c] = map.at(out.positions[out.corners[c] as usize]);
                }
            }
        }
        out.uvs[set] = Some(uv);
    }
}

/// Whether point `p` (in the plane of face `f`) lies in the face (even-odd
/// over all loops).
fn contains(mesh: &Mesh, f: usize, n: DVec3, p: DVec3) -> bool {
    let (u, v) = plane_basis(n);
    let q = DVec2::new(p.dot(u), p.dot(v));
    let mut inside = false;
    for &l in mesh.face_loops(f) {
        let pts: Vec<DVec2> = mesh
            .loop_points(l)
            .map(|x| DVec2::new(x.dot(u), x.dot(v)))
            .collect();
        for i in 0..pts.len() {
            let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
            if (a.y > q.y) != (b.y > q.y) {
                let x = a.x + (q.y - a.y) / (b.y - a.y) * (b.x - a.x);
                if q.x < x {
                    inside = !inside;
                }
            }
        }
    }
    inside
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_offset_keeps_the_projection() {
        let mut m = Mesh::polygon(&[
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(10.0, 0.0, 0.0),
            DVec3::new(10.0, 0.0, -4.0),
            DVec3::new(0.0, 0.0, -4.0),
        ]);
        // u = x / 10, v = -z / 4.
        m.uvs[0] = Some(
            m.positions
                .iter()
                .map(|p| DVec2::new(p.x / 10.0, -p.z / 4.0))
                .collect(),
        );
        let o = crate::setback::offset(&m, -1.0);
        let mut out = o.mesh.clone();
        carry_uvs(&m, &mut out);
        let uv = out.uvs[0].as_ref().unwrap();
        for (c, &p) in out.corners.iter().enumerate() {
            let p = out.positions[p as usize];
            assert!((uv[c] - DVec2::new(p.x / 10.0, -p.z / 4.0)).length() < 1e-12);
        }
        // Without coordinates nothing is added.
        let mut bare = o.mesh.clone();
        carry_uvs(&o.mesh, &mut bare);
        assert!(bare.uvs[0].is_none());
    }
}
