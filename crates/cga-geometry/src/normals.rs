//! Vertex normals (CGA's `setNormals`, `softenNormals`) and consistent
//! face orientation (`setNormals(conform)`).

use glam::DVec3;

use crate::measure::{face_area, face_normal};
use crate::mesh::Mesh;
use crate::topology::Topology;

/// Sets per-corner normals: at every corner, the average of the normals of
/// the faces that share the corner's vertex (the same position index, as
/// CGA requires merged vertices) and whose normal is less than `angle`
/// degrees from the corner's own face normal. `angle <= 0`: hard normals
/// (each face its own normal); `angle >= 180`: fully soft.
pub fn soften_normals(mesh: &mut Mesh, angle: f64) {
    let nf = mesh.faces.len();
    let normals: Vec<DVec3> = (0..nf).map(|f| face_normal(mesh, f)).collect();
    // Faces at every position index (CSR).
    let np = mesh.positions.len();
    let mut count = vec![0u32; np + 1];
    for c in &mesh.corners {
        count[*c as usize + 1] += 1;
    }
    for i in 0..np {
        count[i + 1] += count[i];
    }
    let mut fill = count.clone();
    let mut faces_at = vec![0u32; count[np] as usize];
    for f in 0..nf {
        for &l in mesh.face_loops(f) {
            for c in mesh.loop_corners(l) {
                let p = mesh.corners[c] as usize;
                faces_at[fill[p] as usize] = f as u32;
                fill[p] += 1;
            }
        }
    }
    let cos = if angle >= 180.0 {
        -2.0
    } else {
        angle.max(0.0).to_radians().cos()
    };
    let mut out = vec![DVec3::ZERO; mesh.corners.len()];
    for f in 0..nf {
        let nf_ = normals[f];
        for &l in mesh.face_loops(f) {
            for c in mesh.loop_corners(l) {
                let p = mesh.corners[c] as usize;
                let mut acc = nf_;
                let mut last = f as u32;
                for &g in &faces_at[count[p] as usize..count[p + 1] as usize] {
                    if g == f as u32 || g == last {
                        continue;
                    }
                    last = g;
                    let ng = normals[g as usize];
                    // Strictly within the angle (0 degrees: hard).
                    if angle > 0.0 && nf_.dot(ng) > cos {
                        acc += ng;
                    }
                }
                out[c] = acc.normalize_or_zero();
            }
        }
    }
    mesh.normals = Some(out);
}

/// Orients the faces of every connected part (faces sharing edges) the
/// same way, then turns each part so that its faces face outwards (a closed
/// part: positive volume) or, for open parts, upwards on average (area
/// weighted). Returns the number of faces reversed.
pub fn conform_orientation(mesh: &mut Mesh) -> usize {
    let nf = mesh.faces.len();
    if nf == 0 {
        return 0;
    }
    let topo = Topology::new(mesh);
    // flip[f]: whether f is reversed relative to the part's seed face.
    let mut flip = vec![false; nf];
    let mut part = vec![u32::MAX; nf];
    let mut parts: Vec<Vec<u32>> = Vec::new();
    for seed in 0..nf {
        if part[seed] != u32::MAX {
            continue;
        }
        let id = parts.len() as u32;
        let mut members = vec![seed as u32];
        part[seed] = id;
        let mut stack = vec![seed as u32];
        while let Some(f) = stack.pop() {
            let f = f as usize;
            for &l in mesh.face_loops(f) {
                for c in mesh.loop_corners(l) {
                    let e = topo.edge_of_corner[c];
                    if e == u32::MAX {
                        continue;
                    }
                    let uses = topo.edge_uses(e as usize);
                    // Only manifold edges propagate an orientation.
                    if uses.len() != 2 {
                        continue;
                    }
                    let me = uses.iter().find(|u| u.corner as usize == c);
                    let other = uses.iter().find(|u| u.corner as usize != c);
                    let (Some(me), Some(other)) = (me, other) else {
                        continue;
                    };
                    let g = other.face as usize;
                    if g == f {
                        continue;
                    }
                    // Consistent neighbours run the shared edge in opposite
                    // directions.
                    let same_dir = me.reversed == other.reversed;
                    let want = flip[f] ^ same_dir;
                    if part[g] == u32::MAX {
                        part[g] = id;
                        flip[g] = want;
                        members.push(g as u32);
                        stack.push(g as u32);
                    }
                }
            }
        }
        parts.push(members);
    }
    let normals: Vec<DVec3> = (0..nf).map(|f| face_normal(mesh, f)).collect();
    let mut reversed = 0;
    let mut reverse_face = vec![false; nf];
    for members in &parts {
        let closed = members.iter().all(|&f| {
            mesh.face_loops(f as usize).iter().all(|&l| {
                mesh.loop_corners(l).all(|c| {
                    let e = topo.edge_of_corner[c];
                    e == u32::MAX || topo.edge_uses(e as usize).len() == 2
                })
            })
        });
        // Volume (closed) or upward area (open) of the part as oriented.
        let mut score = 0.0;
        for &f in members {
            let f = f as usize;
            let s = if flip[f] { -1.0 } else { 1.0 };
            if closed {
                let p = mesh.positions[mesh.corners[mesh.outer_loop(f).start as usize] as usize];
                score += s * face_area(mesh, f) * normals[f].dot(p);
            } else {
                score += s * face_area(mesh, f) * normals[f].y;
            }
        }
        let turn = score < 0.0;
        for &f in members {
            let f = f as usize;
            if flip[f] ^ turn {
                reverse_face[f] = true;
                reversed += 1;
            }
        }
    }
    if reversed > 0 {
        reverse_some(mesh, &reverse_face);
    }
    reversed
}

/// Reverses the faces marked in `which`, as `transform::reverse_faces` does.
fn reverse_some(mesh: &mut Mesh, which: &[bool]) {
    for (f, &rev) in which.iter().enumerate() {
        if !rev {
            continue;
        }
        for l in mesh.face_loops(f).to_vec() {
            let r = mesh.loop_corners(l);
            if r.len() < 3 {
                continue;
            }
            let tail = r.start + 1..r.end;
            mesh.corners[tail.clone()].reverse();
            for uv in mesh.uvs.iter_mut().flatten() {
                uv[tail.clone()].reverse();
            }
            if let Some(n) = &mut mesh.normals {
                n[tail.clone()].reverse();
                for v in &mut n[r.clone()] {
                    *v = -*v;
                }
            }
            crate::tags::reverse_loop_tags(mesh, r);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::volume;
    use crate::primitive::cube;

    #[test]
    fn soft_hard_and_auto_normals_of_a_cube() {
        let mut m = cube(DVec3::ONE);
        // The primitive cube may or may not share position indices between
        // faces; share them so that softening has neighbours.
        let topo = Topology::new(&m);
        for c in 0..m.corners.len() {
            let p = m.corners[c] as usize;
            m.corners[c] = topo.weld.representative[topo.weld.id[p] as usize];
        }
        soften_normals(&mut m, 180.0);
        let n = m.normals.clone().unwrap();
        let d = 1.0 / 3f64.sqrt();
        assert!(n
            .iter()
            .all(|v| (v.abs() - DVec3::splat(d)).length() < 1e-9));
        soften_normals(&mut m, 30.0);
        for (c, v) in m.normals.clone().unwrap().iter().enumerate() {
            // 90-degree edges are hard at 30 degrees: the face normal.
            let f = (0..m.faces.len())
                .find(|&f| {
                    m.face_loops(f)
                        .iter()
                        .any(|l| m.loop_corners(*l).contains(&c))
                })
                .unwrap();
            assert!((*v - face_normal(&m, f)).length() < 1e-9);
        }
    }

    #[test]
    fn conform_turns_an_inside_out_face() {
        let mut m = cube(DVec3::ONE);
        let topo = Topology::new(&m);
        for c in 0..m.corners.len() {
            let p = m.corners[c] as usize;
            m.corners[c] = topo.weld.representative[topo.weld.id[p] as usize];
        }
        let v = volume(&m);
        assert!(v > 0.0);
        // Reverse one face: the solid is no longer consistent.
        let mut which = vec![false; m.faces.len()];
        which[2] = true;
        reverse_some(&mut m, &which);
        assert_eq!(conform_orientation(&mut m), 1);
        assert!((volume(&m) - v).abs() < 1e-12);
        // Everything inside out: all faces turn.
        let mut all = m.clone();
        crate::transform::reverse_faces(&mut all);
        assert_eq!(conform_orientation(&mut all), 6);
        assert!((volume(&all) - v).abs() < 1e-12);
    }
}
