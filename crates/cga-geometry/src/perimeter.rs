//! Sections of a face perimeter set back by their own depths (CGA's
//! `splitAndSetbackPerimeter`).
//!
//! The perimeter is a chain of face edges (their order given by the
//! caller) measured by arc length. A section `[start, end)` of the chain is
//! set back by its depth on its own: the face's edges are cut at the
//! section's ends and only the pieces inside the section move inwards (the
//! straight-skeleton setback of [`crate::setback`], so corners inside a
//! section are mitred and a section ending mid-edge ends square). Where
//! sections overlap (at corners, or when deep sections reach each other)
//! the deeper section keeps the overlap and it is cut away from the other
//! (equal depths: the earlier section keeps it). The remainder is the face
//! without all sections.

use glam::{DVec2, DVec3};

use crate::footprint::{difference, union, Shapes};
use crate::measure::face_normal;
use crate::mesh::Mesh;
use crate::setback::{setback, OffsetFace};
use crate::triangulate::plane_basis;

/// A section of the chain (arc lengths from the chain's start, `start <
/// end <= chain length`) and its setback depth.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Section {
    pub start: f64,
    pub end: f64,
    pub depth: f64,
}

/// The result: the polygons of every section (in the caller's order) and
/// of the remainder, as meshes in the input's coordinates.
#[derive(Clone, Debug, Default)]
pub struct Perimeter {
    pub sections: Vec<Mesh>,
    pub remainder: Mesh,
}

/// Splits the perimeter chain `chain` (face-edge indices of `mesh`, in
/// face-edge order numbering: every edge of every loop of every face) into
/// `sections` and sets each back (see the module docs).
pub fn split_and_setback_perimeter(
    mesh: &Mesh,
    chain: &[usize],
    sections: &[Section],
) -> Perimeter {
    let mut out = Perimeter {
        sections: vec![Mesh::new(); sections.len()],
        remainder: Mesh::new(),
    };
    for m in out
        .sections
        .iter_mut()
        .chain(std::iter::once(&mut out.remainder))
    {
        m.materials = mesh.materials.clone();
    }
    // Face-edge index -> (face, loop, edge) and its length.
    let mut fe: Vec<(usize, usize, usize)> = Vec::new();
    for f in 0..mesh.faces.len() {
        for (li, &l) in mesh.face_loops(f).iter().enumerate() {
            for i in 0..l.len as usize {
                fe.push((f, li, i));
            }
        }
    }
    let edge_points = |k: usize| {
        let (f, li, i) = fe[k];
        let l = mesh.face_loops(f)[li];
        let idx = mesh.loop_indices(l);
        (
            mesh.positions[idx[i] as usize],
            mesh.positions[idx[(i + 1) % idx.len()] as usize],
        )
    };
    // Arc-length interval of every chain edge.
    let mut at: Vec<Option<(f64, f64)>> = vec![None; fe.len()];
    let mut s = 0.0;
    for &k in chain {
        if k >= fe.len() || at[k].is_some() {
            continue;
        }
        let (a, b) = edge_points(k);
        let len = (b - a).length();
        at[k] = Some((s, s + len));
        s += len;
    }
    for f in 0..mesh.faces.len() {
        face_sections(mesh, f, &fe, &at, sections, &mut out);
    }
    out
}

/// The sections and remainder of one face.
fn face_sections(
    mesh: &Mesh,
    f: usize,
    fe: &[(usize, usize, usize)],
    at: &[Option<(f64, f64)>],
    sections: &[Section],
    out: &mut Perimeter,
) {
    let n = face_normal(mesh, f);
    let material = mesh.faces[f].material;
    let whole = |out: &mut Perimeter| {
        let sub = face_copy(mesh, f);
        crate::transform::merge(&mut out.remainder, &sub);
    };
    if n == DVec3::ZERO {
        whole(out);
        return;
    }
    let (u, v) = plane_basis(n);
    let o = mesh.positions[mesh.corners[mesh.outer_loop(f).start as usize] as usize];
    let to2 = |p: DVec3| DVec2::new((p - o).dot(u), (p - o).dot(v));
    let lift = |q: DVec2| o + u * q.x + v * q.y;
    // The face with its edges cut at every section end; each piece knows
    // the arc-length interval it covers (None: not on the chain).
    let first_fe = fe.iter().position(|&(g, _, _)| g == f).unwrap_or(0);
    let mut loops: Vec<Vec<DVec3>> = Vec::new();
    let mut pieces: Vec<Option<(f64, f64)>> = Vec::new();
    let mut k = first_fe;
    for &l in mesh.face_loops(f) {
        let pts: Vec<DVec3> = mesh.loop_points(l).collect();
        let mut lp = Vec::new();
        for i in 0..pts.len() {
            let (a, b) = (pts[i], pts[(i + 1) % pts.len()]);
            lp.push(a);
            match at[k] {
                Some((s0, s1)) if s1 > s0 => {
                    let mut cuts: Vec<f64> = sections
                        .iter()
                        .flat_map(|s| [s.start, s.end])
                        .filter(|&c| c > s0 + 1e-9 && c < s1 - 1e-9)
                        .collect();
                    cuts.sort_by(f64::total_cmp);
                    cuts.dedup_by(|x, y| (*x - *y).abs() <= 1e-9);
                    let mut prev = s0;
                    for c in cuts {
                        lp.push(a + (b - a) * ((c - s0) / (s1 - s0)));
                        pieces.push(Some((prev, c)));
                        prev = c;
                    }
                    pieces.push(Some((prev, s1)));
                }
                _ => pieces.push(None),
            }
            k += 1;
        }
        loops.push(lp);
    }
    let mut cut_face = Mesh::new();
    let mut ids: Vec<Vec<u32>> = Vec::new();
    for lp in &loops {
        let s = cut_face.positions.len() as u32;
        cut_face.positions.extend_from_slice(lp);
        ids.push((s..s + lp.len() as u32).collect());
    }
    let refs: Vec<&[u32]> = ids.iter().map(|x| x.as_slice()).collect();
    cut_face.add_face(&refs, 0);
    // The region each section sweeps on this face, alone.
    let mut regions: Vec<(usize, Shapes)> = Vec::new();
    for (si, sec) in sections.iter().enumerate() {
        if sec.depth.is_nan() || sec.depth <= 0.0 || !sec.depth.is_finite() {
            continue;
        }
        let d: Vec<f64> = pieces
            .iter()
            .map(|p| match p {
                Some((a, b)) if 0.5 * (a + b) >= sec.start && 0.5 * (a + b) < sec.end => sec.depth,
                _ => 0.0,
            })
            .collect();
        if d.iter().all(|&x| x == 0.0) {
            continue;
        }
        let o = setback(&cut_face, &d);
        let strips: Vec<Vec<DVec2>> = o
            .faces_of(OffsetFace::Strip)
            .into_iter()
            .map(|g| o.mesh.loop_points(o.mesh.outer_loop(g)).map(to2).collect())
            .collect();
        let r = union(&strips);
        if !r.is_empty() {
            regions.push((si, r));
        }
    }
    // Deeper sections first; they keep what they overlap.
    let mut order: Vec<usize> = (0..regions.len()).collect();
    order.sort_by(|&a, &b| {
        sections[regions[b].0]
            .depth
            .total_cmp(&sections[regions[a].0].depth)
            .then(regions[a].0.cmp(&regions[b].0))
    });
    let flat = |s: &Shapes| -> Vec<Vec<DVec2>> { s.iter().flatten().cloned().collect() };
    let mut taken: Vec<Vec<DVec2>> = Vec::new();
    for &i in &order {
        let (si, ref r) = regions[i];
        let mine = if taken.is_empty() {
            r.clone()
        } else {
            difference(&flat(r), &taken)
        };
        taken.extend(flat(r));
        taken = flat(&union(&taken));
        add_shapes(&mut out.sections[si], &mine, &lift, material);
    }
    let face2: Vec<Vec<DVec2>> = mesh
        .face_loops(f)
        .iter()
        .map(|&l| mesh.loop_points(l).map(to2).collect())
        .collect();
    if taken.is_empty() {
        whole(out);
    } else {
        let rest = difference(&face2, &taken);
        add_shapes(&mut out.remainder, &rest, &lift, material);
    }
}

fn add_shapes(m: &mut Mesh, shapes: &Shapes, lift: &dyn Fn(DVec2) -> DVec3, material: u32) {
    for shape in shapes {
        let mut ids: Vec<Vec<u32>> = Vec::new();
        for l in shape {
            let s = m.positions.len() as u32;
            m.positions.extend(l.iter().map(|&q| lift(q)));
            ids.push((s..s + l.len() as u32).collect());
        }
        let refs: Vec<&[u32]> = ids.iter().map(|x| x.as_slice()).collect();
        m.add_face(&refs, material);
    }
}

fn face_copy(mesh: &Mesh, f: usize) -> Mesh {
    let mut m = Mesh::new();
    m.materials = mesh.materials.clone();
    m.tags = mesh.tags.clone();
    let mut ids: Vec<Vec<u32>> = Vec::new();
    for &l in mesh.face_loops(f) {
        let s = m.positions.len() as u32;
        m.positions.extend(mesh.loop_points(l));
        ids.push((s..s + l.len).collect());
    }
    let refs: Vec<&[u32]> = ids.iter().map(|x| x.as_slice()).collect();
    let nf = m.add_face(&refs, mesh.faces[f].material);
    m.faces[nf].tags = mesh.faces[f].tags;
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::mesh_area;

    fn rect(w: f64, d: f64) -> Mesh {
        Mesh::polygon(&[
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(w, 0.0, 0.0),
            DVec3::new(w, 0.0, -d),
            DVec3::new(0.0, 0.0, -d),
        ])
    }

    #[test]
    fn sections_along_one_edge_and_around_a_corner() {
        let m = rect(20.0, 10.0);
        // [2, 8) on the front at depth 3, [15, 25) around the front-right
        // corner at depth 2.
        let p = split_and_setback_perimeter(
            &m,
            &[0, 1, 2, 3],
            &[
                Section {
                    start: 2.0,
                    end: 8.0,
                    depth: 3.0,
                },
                Section {
                    start: 15.0,
                    end: 25.0,
                    depth: 2.0,
                },
            ],
        );
        assert!((mesh_area(&p.sections[0]) - 18.0).abs() < 1e-6);
        // 5 along the front, 5 up the right side, the corner square once.
        assert!((mesh_area(&p.sections[1]) - (5.0 * 2.0 + 5.0 * 2.0 - 4.0)).abs() < 1e-6);
        let total = mesh_area(&p.sections[0]) + mesh_area(&p.sections[1]) + mesh_area(&p.remainder);
        assert!((total - 200.0).abs() < 1e-6);
    }

    #[test]
    fn the_deeper_section_keeps_the_overlap() {
        let m = rect(10.0, 10.0);
        // Both sides of the front-right corner: 4 deep on the front's last
        // 2 m, 6 deep on the right side's first 2 m.
        let p = split_and_setback_perimeter(
            &m,
            &[0, 1, 2, 3],
            &[
                Section {
                    start: 8.0,
                    end: 10.0,
                    depth: 4.0,
                },
                Section {
                    start: 10.0,
                    end: 12.0,
                    depth: 6.0,
                },
            ],
        );
        // Right section: 2 along the side, 6 deep = 12. The front
        // section's 2 x 4 rectangle loses its 2 x 2 overlap with it.
        assert!((mesh_area(&p.sections[1]) - 12.0).abs() < 1e-6);
        assert!((mesh_area(&p.sections[0]) - 4.0).abs() < 1e-6);
        assert!((mesh_area(&p.remainder) - 84.0).abs() < 1e-6);
    }
}
