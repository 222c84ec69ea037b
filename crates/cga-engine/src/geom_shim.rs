//! Geometric measures the interpreter needs, delegated to `cga-geometry`.

use cga_geometry::{DVec3, Mesh};

fn newell(points: impl Iterator<Item = DVec3>) -> DVec3 {
    let mut n = DVec3::ZERO;
    let pts: Vec<DVec3> = points.collect();
    for i in 0..pts.len() {
        let a = pts[i];
        let b = pts[(i + 1) % pts.len()];
        n += a.cross(b);
    }
    n * 0.5
}

pub fn face_normal(mesh: &Mesh, face: usize) -> DVec3 {
    newell(mesh.loop_points(mesh.outer_loop(face))).normalize_or_zero()
}

pub fn face_area(mesh: &Mesh, face: usize) -> f64 {
    let loops = mesh.face_loops(face);
    let mut a = newell(mesh.loop_points(loops[0])).length();
    for &h in &loops[1..] {
        a -= newell(mesh.loop_points(h)).length();
    }
    a.max(0.0)
}

pub fn area(mesh: &Mesh) -> f64 {
    (0..mesh.faces.len()).map(|f| face_area(mesh, f)).sum()
}

pub fn volume(mesh: &Mesh) -> f64 {
    let mut v = 0.0;
    for f in 0..mesh.faces.len() {
        for &l in mesh.face_loops(f) {
            let pts: Vec<DVec3> = mesh.loop_points(l).collect();
            if pts.len() < 3 {
                continue;
            }
            for i in 1..pts.len() - 1 {
                v += pts[0].dot(pts[i].cross(pts[i + 1])) / 6.0;
            }
        }
    }
    v.abs()
}

pub fn n_vertices(mesh: &Mesh) -> usize {
    let mut used = vec![false; mesh.positions.len()];
    for &c in &mesh.corners {
        used[c as usize] = true;
    }
    used.iter().filter(|&&u| u).count()
}

pub fn n_holes(mesh: &Mesh) -> usize {
    mesh.faces.iter().map(|f| f.loop_count as usize - 1).sum()
}

pub fn bbox(mesh: &Mesh) -> Option<(DVec3, DVec3)> {
    let mut it = mesh.corners.iter().map(|&c| mesh.positions[c as usize]);
    let first = it.next()?;
    Some(it.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p))))
}

pub fn is_closed(mesh: &Mesh) -> bool {
    use std::collections::HashMap;
    let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
    for l in &mesh.loops {
        let idx = mesh.loop_indices(*l);
        if idx.len() < 3 {
            return false;
        }
        for i in 0..idx.len() {
            let (a, b) = (idx[i], idx[(i + 1) % idx.len()]);
            *edges.entry((a.min(b), a.max(b))).or_default() += if a < b { 1 } else { -1 };
        }
    }
    !edges.is_empty() && edges.values().all(|&c| c == 0)
}
