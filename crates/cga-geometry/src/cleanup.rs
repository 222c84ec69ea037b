//! Mesh clean-up, simplification and rectification: CGA's
//! `cleanupGeometry`, `reduceGeometry` and `rectify`.
//!
//! `cleanup` never changes how the model looks (within its tolerance): it
//! merges vertices, drops straight corners, joins coplanar neighbouring
//! faces and removes duplicate and degenerate faces. The tolerance `t` in
//! `[0, 1]` scales linearly: vertices closer than `t` metres merge, corners
//! and face normals within `10 t` degrees count as straight and coplanar,
//! faces smaller than `t` square metres are degenerate. `t = 0` only
//! removes exact cases (identical vertices, collinear corners, coplanar
//! faces, faces without area; "exact" meaning within the crate's rounding
//! tolerance).
//!
//! `reduce` collapses edges by the quadric error metric (Garland and
//! Heckbert, "Surface simplification using quadric error metrics", 1997)
//! on the triangulated mesh until the vertex count has dropped by the
//! given fraction; border edges are kept in place by constraint planes and
//! collapses that would fold a triangle over are refused.
//!
//! `rectify` snaps edges that are within an angle of the axes of the plane
//! the mesh is most parallel to (xy, yz or zx of the mesh's coordinates,
//! i.e. the scope) onto those axes.

use std::cmp::Ordering;
use std::collections::{BinaryHeap, HashMap};

use glam::{DMat3, DVec3};

use crate::measure::{face_area, face_normal};
use crate::mesh::Mesh;
use crate::topology::{mesh_tolerance, weld_points, Topology};
use crate::triangulate::triangulate_face;

/// Which clean-up steps to run (vertices are merged by all of them).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Parts {
    /// Remove straight (collinear) corners.
    pub vertices: bool,
    /// Join neighbouring coplanar faces.
    pub edges: bool,
    /// Remove duplicate faces and faces with (almost) no area.
    pub faces: bool,
}

/// `cleanupGeometry` (see the module docs). Per-corner attributes are kept
/// for the corners that remain.
pub fn cleanup(mesh: &Mesh, parts: Parts, t: f64) -> Mesh {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let eps = mesh_tolerance(mesh);
    let merge_dist = t.max(eps);
    let angle = (10.0 * t).to_radians();
    let min_area = t.max(eps * eps);
    let mut m = merge_vertices(mesh, merge_dist);
    if parts.faces {
        m = remove_faces(&m, min_area);
    }
    if parts.edges {
        m = join_coplanar(&m, angle.max(1e-9));
    }
    if parts.vertices {
        m = remove_straight_corners(&m, angle.max(1e-9));
    }
    m
}

/// Positions within `dist` become one (the first); corners repeated along
/// a loop are dropped, loops left with fewer than three corners too, and
/// faces without an outer loop.
fn merge_vertices(mesh: &Mesh, dist: f64) -> Mesh {
    let weld = weld_points(&mesh.positions, dist);
    let mut out = empty_like(mesh);
    out.positions = weld
        .representative
        .iter()
        .map(|&i| mesh.positions[i as usize])
        .collect();
    for f in 0..mesh.faces.len() {
        let mut loops: Vec<Vec<usize>> = Vec::new();
        for &l in mesh.face_loops(f) {
            let mut corners: Vec<usize> = Vec::new();
            for c in mesh.loop_corners(l) {
                let v = weld.id[mesh.corners[c] as usize];
                if corners
                    .last()
                    .is_some_and(|&p| weld.id[mesh.corners[p] as usize] == v)
                {
                    continue;
                }
                corners.push(c);
            }
            while corners.len() > 1
                && weld.id[mesh.corners[corners[0]] as usize]
                    == weld.id[mesh.corners[*corners.last().unwrap()] as usize]
            {
                corners.pop();
            }
            if corners.len() >= 3 {
                loops.push(corners);
            } else if loops.is_empty() {
                break;
            }
        }
        if loops.is_empty() {
            continue;
        }
        push_face(&mut out, mesh, f, &loops, |c| {
            weld.id[mesh.corners[c] as usize]
        });
    }
    out
}

/// A mesh with `mesh`'s materials, groups and attribute layout, no faces.
fn empty_like(mesh: &Mesh) -> Mesh {
    let mut out = Mesh::new();
    out.share_slots(mesh);
    if mesh.edge_tags.is_some() {
        out.edge_tags = Some(Vec::new());
    }
    if mesh.vertex_tags.is_some() {
        out.vertex_tags = Some(Vec::new());
    }
    for (k, set) in mesh.uvs.iter().enumerate() {
        if set.is_some() {
            out.uvs[k] = Some(Vec::new());
        }
    }
    if mesh.normals.is_some() {
        out.normals = Some(Vec::new());
    }
    out
}

/// Adds a face of `out` made of corners of `src` (face `f` gives material
/// and group), with their attributes; `pos` maps a corner of `src` to a
/// position index of `out`.
fn push_face(
    out: &mut Mesh,
    src: &Mesh,
    f: usize,
    loops: &[Vec<usize>],
    pos: impl Fn(usize) -> u32,
) {
    let ids: Vec<Vec<u32>> = loops
        .iter()
        .map(|l| l.iter().map(|&c| pos(c)).collect())
        .collect();
    let refs: Vec<&[u32]> = ids.iter().map(|x| x.as_slice()).collect();
    let first = out.corners.len();
    let nf = out.add_face(&refs, src.faces[f].material);
    out.faces[nf].group = src.faces[f].group;
    out.faces[nf].tags = src.faces[f].tags;
    let corners: Vec<usize> = loops.iter().flatten().copied().collect();
    // A kept corner keeps its edge's tags (a dropped straight corner only
    // goes when both its edges carry the same tags) and its vertex's.
    if let Some(dst) = out.edge_tags.as_mut() {
        for (i, &c) in corners.iter().enumerate() {
            dst[first + i] = src.edge_tag_index(c);
        }
    }
    if let Some(dst) = out.vertex_tags.as_mut() {
        for (i, &c) in corners.iter().enumerate() {
            dst[first + i] = src.vertex_tag_index(c);
        }
    }
    for (k, set) in out.uvs.iter_mut().enumerate() {
        if let (Some(dst), Some(s)) = (set.as_mut(), src.uvs[k].as_ref()) {
            for (i, &c) in corners.iter().enumerate() {
                dst[first + i] = s[c];
            }
        }
    }
    if let (Some(dst), Some(s)) = (out.normals.as_mut(), src.normals.as_ref()) {
        for (i, &c) in corners.iter().enumerate() {
            dst[first + i] = s[c];
        }
    }
}

/// Removes faces with an area below `min_area` and faces that repeat an
/// earlier face's vertices (in either winding).
fn remove_faces(mesh: &Mesh, min_area: f64) -> Mesh {
    let mut out = empty_like(mesh);
    out.positions = mesh.positions.clone();
    let mut seen: HashMap<Vec<u32>, ()> = HashMap::new();
    for f in 0..mesh.faces.len() {
        if face_area(mesh, f) <= min_area {
            continue;
        }
        let mut key: Vec<u32> = mesh
            .face_loops(f)
            .iter()
            .flat_map(|&l| mesh.loop_indices(l).iter().copied())
            .collect();
        key.sort_unstable();
        if seen.insert(key, ()).is_some() {
            continue;
        }
        let loops: Vec<Vec<usize>> = mesh
            .face_loops(f)
            .iter()
            .map(|&l| mesh.loop_corners(l).collect())
            .collect();
        push_face(&mut out, mesh, f, &loops, |c| mesh.corners[c]);
    }
    out
}

/// Drops corners whose two edges turn by less than `angle` (radians) in
/// every face that uses the vertex, so that no neighbour keeps a vertex
/// its neighbour lost.
fn remove_straight_corners(mesh: &Mesh, angle: f64) -> Mesh {
    let cos = angle.cos();
    let np = mesh.positions.len();
    let mut removable = vec![true; np];
    let mut used = vec![false; np];
    let straight = |l: crate::mesh::Loop, i: usize| {
        let idx = mesh.loop_indices(l);
        let k = idx.len();
        let a = mesh.positions[idx[(i + k - 1) % k] as usize];
        let b = mesh.positions[idx[i] as usize];
        let c = mesh.positions[idx[(i + 1) % k] as usize];
        let (d1, d2) = ((b - a).normalize_or_zero(), (c - b).normalize_or_zero());
        d1 != DVec3::ZERO && d2 != DVec3::ZERO && d1.dot(d2) >= cos
    };
    for f in 0..mesh.faces.len() {
        for &l in mesh.face_loops(f) {
            let r = mesh.loop_corners(l);
            for (i, &p) in mesh.loop_indices(l).iter().enumerate() {
                used[p as usize] = true;
                // Tagged vertices, and vertices between edges with
                // different tags, are kept (cga_componentTags.md).
                let c = r.start + i;
                let prev = if i == 0 { r.end - 1 } else { c - 1 };
                let tagged = mesh.vertex_tag_index(c) != 0
                    || mesh.edge_tags_at(prev) != mesh.edge_tags_at(c);
                if tagged || !straight(l, i) {
                    removable[p as usize] = false;
                }
            }
        }
    }
    let mut out = empty_like(mesh);
    out.positions = mesh.positions.clone();
    for f in 0..mesh.faces.len() {
        let mut loops: Vec<Vec<usize>> = Vec::new();
        for &l in mesh.face_loops(f) {
            let keep: Vec<usize> = mesh
                .loop_corners(l)
                .filter(|&c| {
                    !(used[mesh.corners[c] as usize] && removable[mesh.corners[c] as usize])
                })
                .collect();
            if keep.len() >= 3 {
                loops.push(keep);
            } else {
                loops.push(mesh.loop_corners(l).collect());
            }
        }
        push_face(&mut out, mesh, f, &loops, |c| mesh.corners[c]);
    }
    out
}

/// Joins faces that share an edge (used by exactly those two faces, in
/// opposite directions), have the same material and normals within
/// `angle` radians: the shared edges disappear.
fn join_coplanar(mesh: &Mesh, angle: f64) -> Mesh {
    let nf = mesh.faces.len();
    let topo = Topology::with_tolerance(mesh, 0.0);
    let normals: Vec<DVec3> = (0..nf).map(|f| face_normal(mesh, f)).collect();
    let cos = angle.cos();
    let mut parent: Vec<usize> = (0..nf).collect();
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    for e in 0..topo.edges.len() {
        let u = topo.edge_uses(e);
        if u.len() != 2 || u[0].face == u[1].face || u[0].reversed == u[1].reversed {
            continue;
        }
        let (a, b) = (u[0].face as usize, u[1].face as usize);
        // Tagged edges and edges between faces with different tags stay.
        if mesh.faces[a].material != mesh.faces[b].material
            || mesh.face_tags(a) != mesh.face_tags(b)
            || mesh.edge_tag_index(u[0].corner as usize) != 0
            || mesh.edge_tag_index(u[1].corner as usize) != 0
            || normals[a] == DVec3::ZERO
            || normals[a].dot(normals[b]) < cos
        {
            continue;
        }
        let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
        if ra != rb {
            parent[rb] = ra;
        }
    }
    let mut groups: HashMap<usize, Vec<usize>> = HashMap::new();
    let mut order: Vec<usize> = Vec::new();
    for f in 0..nf {
        let r = find(&mut parent, f);
        let g = groups.entry(r).or_default();
        if g.is_empty() {
            order.push(r);
        }
        g.push(f);
    }
    let mut out = empty_like(mesh);
    out.positions = mesh.positions.clone();
    for r in order {
        let faces = &groups[&r];
        if faces.len() == 1 {
            let f = faces[0];
            let loops: Vec<Vec<usize>> = mesh
                .face_loops(f)
                .iter()
                .map(|&l| mesh.loop_corners(l).collect())
                .collect();
            push_face(&mut out, mesh, f, &loops, |c| mesh.corners[c]);
            continue;
        }
        match merged_loops(mesh, &topo, faces, &normals) {
            Some(loops) => push_face(&mut out, mesh, faces[0], &loops, |c| mesh.corners[c]),
            None => {
                for &f in faces {
                    let loops: Vec<Vec<usize>> = mesh
                        .face_loops(f)
                        .iter()
                        .map(|&l| mesh.loop_corners(l).collect())
                        .collect();
                    push_face(&mut out, mesh, f, &loops, |c| mesh.corners[c]);
                }
            }
        }
    }
    out
}

/// The loops (as corners of `mesh`, outer first) of the union of `faces`:
/// their directed edges without the pairs that cancel. `None` if the
/// remaining edges do not form one outer loop and holes.
fn merged_loops(
    mesh: &Mesh,
    topo: &Topology,
    faces: &[usize],
    normals: &[DVec3],
) -> Option<Vec<Vec<usize>>> {
    let in_group: std::collections::HashSet<u32> = faces.iter().map(|&f| f as u32).collect();
    // Remaining corners: those whose edge is not shared within the group.
    let mut next_of: HashMap<u32, usize> = HashMap::new();
    let mut rest: Vec<usize> = Vec::new();
    for &f in faces {
        for &l in mesh.face_loops(f) {
            for c in mesh.loop_corners(l) {
                let e = topo.edge_of_corner[c];
                if e == u32::MAX {
                    continue;
                }
                let inner = topo
                    .edge_uses(e as usize)
                    .iter()
                    .filter(|u| in_group.contains(&u.face))
                    .count()
                    == 2;
                if inner {
                    continue;
                }
                let v = topo.weld.id[mesh.corners[c] as usize];
                if next_of.insert(v, c).is_some() {
                    // Two boundary edges leave one vertex: not simple.
                    return None;
                }
                rest.push(c);
            }
        }
    }
    let next_corner = |c: usize| -> usize {
        let l = mesh
            .loops
            .iter()
            .find(|l| mesh.loop_corners(**l).contains(&c))
            .copied()
            .expect("corner of a loop");
        let r = mesh.loop_corners(l);
        if c + 1 == r.end {
            r.start
        } else {
            c + 1
        }
    };
    let mut used: std::collections::HashSet<usize> = std::collections::HashSet::new();
    let mut loops: Vec<Vec<usize>> = Vec::new();
    for &start in &rest {
        if used.contains(&start) {
            continue;
        }
        let mut lp = Vec::new();
        let mut c = start;
        loop {
            if !used.insert(c) {
                if c == start {
                    break;
                }
                return None;
            }
            lp.push(c);
            let to = topo.weld.id[mesh.corners[next_corner(c)] as usize];
            c = *next_of.get(&to)?;
            if lp.len() > rest.len() {
                return None;
            }
        }
        if lp.len() >= 3 {
            loops.push(lp);
        }
    }
    // Outer loop first: the one with the largest area along the normal.
    let n = normals[faces[0]];
    let area = |lp: &[usize]| {
        let mut a = DVec3::ZERO;
        for i in 0..lp.len() {
            let p = mesh.positions[mesh.corners[lp[i]] as usize];
            let q = mesh.positions[mesh.corners[lp[(i + 1) % lp.len()]] as usize];
            a += p.cross(q);
        }
        0.5 * a.dot(n)
    };
    let positive = loops.iter().filter(|l| area(l) > 0.0).count();
    if positive != 1 {
        return None;
    }
    loops.sort_by(|a, b| area(b).total_cmp(&area(a)));
    Some(loops)
}

// ----- reduceGeometry -----

#[derive(Clone, Copy)]
struct Quadric([f64; 10]);

impl Quadric {
    fn plane(n: DVec3, d: f64, w: f64) -> Quadric {
        let (a, b, c) = (n.x, n.y, n.z);
        Quadric(
            [
                a * a,
                a * b,
                a * c,
                a * d,
                b * b,
                b * c,
                b * d,
                c * c,
                c * d,
                d * d,
            ]
            .map(|x| x * w),
        )
    }
    fn add(&mut self, o: &Quadric) {
        for i in 0..10 {
            self.0[i] += o.0[i];
        }
    }
    fn error(&self, p: DVec3) -> f64 {
        let q = &self.0;
        let (x, y, z) = (p.x, p.y, p.z);
        q[0] * x * x
            + 2.0 * q[1] * x * y
            + 2.0 * q[2] * x * z
            + 2.0 * q[3] * x
            + q[4] * y * y
            + 2.0 * q[5] * y * z
            + 2.0 * q[6] * y
            + q[7] * z * z
            + 2.0 * q[8] * z
            + q[9]
    }
    /// The point minimising the error, if the system is well conditioned.
    fn optimum(&self) -> Option<DVec3> {
        let q = &self.0;
        let m = DMat3::from_cols(
            DVec3::new(q[0], q[1], q[2]),
            DVec3::new(q[1], q[4], q[5]),
            DVec3::new(q[2], q[5], q[7]),
        );
        let det = m.determinant();
        if det.abs() < 1e-12 {
            return None;
        }
        Some(m.inverse() * DVec3::new(-q[3], -q[6], -q[8]))
    }
}

#[derive(PartialEq)]
struct Cand {
    cost: f64,
    a: u32,
    b: u32,
    stamp: (u32, u32),
    target: DVec3,
}
impl Eq for Cand {}
impl PartialOrd for Cand {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Cand {
    fn cmp(&self, o: &Self) -> Ordering {
        o.cost
            .total_cmp(&self.cost)
            .then(o.a.cmp(&self.a))
            .then(o.b.cmp(&self.b))
    }
}

/// `reduceGeometry(fraction)`: the mesh triangulated and simplified until
/// its vertex count has dropped by `fraction` (or no collapse is left).
/// Materials are kept per triangle; texture coordinates and normals are
/// dropped (the surface changes).
pub fn reduce(mesh: &Mesh, fraction: f64) -> Mesh {
    let fraction = if fraction.is_finite() {
        fraction.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let weld = weld_points(&mesh.positions, mesh_tolerance(mesh));
    let mut pos: Vec<DVec3> = weld
        .representative
        .iter()
        .map(|&i| mesh.positions[i as usize])
        .collect();
    let mut tris: Vec<([u32; 3], u32)> = Vec::new();
    let mut buf = Vec::new();
    for f in 0..mesh.faces.len() {
        buf.clear();
        triangulate_face(mesh, f, &mut buf);
        for t in &buf {
            let v = t.map(|c| weld.id[mesh.corners[c as usize] as usize]);
            if v[0] != v[1] && v[1] != v[2] && v[0] != v[2] {
                tris.push((v, mesh.faces[f].material));
            }
        }
    }
    let nv = pos.len();
    let used_count = {
        let mut u = vec![false; nv];
        for (t, _) in &tris {
            for &v in t {
                u[v as usize] = true;
            }
        }
        u.iter().filter(|&&x| x).count()
    };
    let target = ((1.0 - fraction) * used_count as f64).round() as usize;
    if fraction <= 0.0 || tris.is_empty() {
        return rebuild(mesh, &pos, &tris);
    }
    // Quadrics: triangle planes, and planes through border edges
    // perpendicular to their triangle (to hold the border in place).
    let mut q = vec![Quadric([0.0; 10]); nv];
    let mut edge_count: HashMap<(u32, u32), u32> = HashMap::new();
    for (t, _) in &tris {
        let (a, b, c) = (pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]);
        let n = (b - a).cross(c - a);
        let area = 0.5 * n.length();
        let n = n.normalize_or_zero();
        let pq = Quadric::plane(n, -n.dot(a), area.max(1e-12));
        for &v in t {
            q[v as usize].add(&pq);
        }
        for i in 0..3 {
            let (x, y) = (t[i], t[(i + 1) % 3]);
            *edge_count.entry((x.min(y), x.max(y))).or_insert(0) += 1;
        }
    }
    for (t, _) in &tris {
        let (a, b, c) = (pos[t[0] as usize], pos[t[1] as usize], pos[t[2] as usize]);
        let n = (b - a).cross(c - a).normalize_or_zero();
        for i in 0..3 {
            let (x, y) = (t[i], t[(i + 1) % 3]);
            if edge_count[&(x.min(y), x.max(y))] == 1 {
                let (px, py) = (pos[x as usize], pos[y as usize]);
                let m = (py - px).cross(n).normalize_or_zero();
                let w = (py - px).length_squared() * 1e3;
                let pq = Quadric::plane(m, -m.dot(px), w);
                q[x as usize].add(&pq);
                q[y as usize].add(&pq);
            }
        }
    }
    // Vertex -> triangles.
    let mut vt: Vec<Vec<u32>> = vec![Vec::new(); nv];
    for (i, (t, _)) in tris.iter().enumerate() {
        for &v in t {
            vt[v as usize].push(i as u32);
        }
    }
    let mut alive_tri = vec![true; tris.len()];
    let mut remap: Vec<u32> = (0..nv as u32).collect();
    let mut stamp = vec![0u32; nv];
    let mut heap = BinaryHeap::new();
    // Border vertices stay on the border: a border vertex never moves off
    // its place unless it slides along a border edge into its neighbour,
    // and corners of the border (where it turns by more than 30 degrees, or
    // where more than two border edges meet) never move.
    let mut border = vec![false; nv];
    let mut border_dirs: Vec<Vec<DVec3>> = vec![Vec::new(); nv];
    for (&(x, y), &c) in &edge_count {
        if c == 1 {
            border[x as usize] = true;
            border[y as usize] = true;
            let d = (pos[y as usize] - pos[x as usize]).normalize_or_zero();
            border_dirs[x as usize].push(d);
            border_dirs[y as usize].push(d);
        }
    }
    let mut corner: Vec<bool> = border_dirs
        .iter()
        .map(|ds| {
            ds.len() > 2 || (ds.len() == 2 && ds[0].dot(ds[1]).abs() < 30f64.to_radians().cos())
        })
        .collect();
    let cand = |a: u32,
                b: u32,
                q: &[Quadric],
                pos: &[DVec3],
                stamp: &[u32],
                border: &[bool],
                corner: &[bool]| {
        let mut s = q[a as usize];
        s.add(&q[b as usize]);
        let (pa, pb) = (pos[a as usize], pos[b as usize]);
        let (ba, bb) = (border[a as usize], border[b as usize]);
        let (ca, cb) = (corner[a as usize], corner[b as usize]);
        let options: Vec<DVec3> = match (ba, bb) {
            (false, false) => {
                let mid = (pa + pb) * 0.5;
                let mut v = vec![mid, pa, pb];
                if let Some(o) = s.optimum() {
                    if (o - mid).length() <= (pb - pa).length() * 2.0 {
                        v.push(o);
                    }
                }
                v
            }
            (true, false) => vec![pa],
            (false, true) => vec![pb],
            (true, true) => match (ca, cb) {
                (true, true) => Vec::new(),
                (true, false) => vec![pa],
                (false, true) => vec![pb],
                (false, false) => vec![pa, pb],
            },
        };
        let best = options
            .into_iter()
            .map(|p| (s.error(p), p))
            .min_by(|x, y| x.0.total_cmp(&y.0));
        best.map(|(cost, target)| Cand {
            cost,
            a,
            b,
            stamp: (stamp[a as usize], stamp[b as usize]),
            target,
        })
    };
    for &(a, b) in edge_count.keys() {
        if let Some(c) = cand(a, b, &q, &pos, &stamp, &border, &corner) {
            heap.push(c);
        }
    }
    let mut alive_v = used_count;
    while alive_v > target {
        let Some(c) = heap.pop() else { break };
        let (a, b) = (c.a, c.b);
        if remap[a as usize] != a
            || remap[b as usize] != b
            || c.stamp != (stamp[a as usize], stamp[b as usize])
        {
            continue;
        }
        // Two border vertices may only merge along a border edge (one
        // triangle on it), else the mesh would pinch.
        if border[a as usize] && border[b as usize] {
            let shared = vt[a as usize]
                .iter()
                .filter(|&&ti| alive_tri[ti as usize] && tris[ti as usize].0.contains(&b))
                .count();
            if shared != 1 {
                continue;
            }
        }
        // Refuse collapses that flip a triangle around a or b.
        let flips = |v: u32, tris: &[([u32; 3], u32)], alive: &[bool]| {
            vt[v as usize].iter().any(|&ti| {
                let ti = ti as usize;
                if !alive[ti] {
                    return false;
                }
                let t = tris[ti].0;
                if t.contains(&a) && t.contains(&b) {
                    return false;
                }
                let p: Vec<DVec3> = t.iter().map(|&x| pos[x as usize]).collect();
                let n0 = (p[1] - p[0]).cross(p[2] - p[0]);
                let moved: Vec<DVec3> = t
                    .iter()
                    .map(|&x| if x == v { c.target } else { pos[x as usize] })
                    .collect();
                let n1 = (moved[1] - moved[0]).cross(moved[2] - moved[0]);
                n0.dot(n1) <= 0.0
            })
        };
        if flips(a, &tris, &alive_tri) || flips(b, &tris, &alive_tri) {
            continue;
        }
        // Collapse b into a (which takes b's border role if it had one).
        pos[a as usize] = c.target;
        border[a as usize] |= border[b as usize];
        corner[a as usize] |= corner[b as usize];
        remap[b as usize] = a;
        let qb = q[b as usize];
        q[a as usize].add(&qb);
        let moved: Vec<u32> = std::mem::take(&mut vt[b as usize]);
        for ti in moved {
            let t = &mut tris[ti as usize].0;
            for x in t.iter_mut() {
                if *x == b {
                    *x = a;
                }
            }
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                alive_tri[ti as usize] = false;
            } else {
                vt[a as usize].push(ti);
            }
        }
        vt[a as usize].retain(|&ti| alive_tri[ti as usize]);
        stamp[a as usize] += 1;
        alive_v -= 1;
        let mut nb: Vec<u32> = vt[a as usize]
            .iter()
            .flat_map(|&ti| tris[ti as usize].0)
            .filter(|&x| x != a)
            .collect();
        nb.sort_unstable();
        nb.dedup();
        for x in nb {
            if let Some(c) = cand(a.min(x), a.max(x), &q, &pos, &stamp, &border, &corner) {
                heap.push(c);
            }
        }
    }
    let kept: Vec<([u32; 3], u32)> = tris
        .iter()
        .zip(&alive_tri)
        .filter(|(_, &a)| a)
        .map(|(t, _)| *t)
        .collect();
    rebuild(mesh, &pos, &kept)
}

fn rebuild(mesh: &Mesh, pos: &[DVec3], tris: &[([u32; 3], u32)]) -> Mesh {
    let mut out = Mesh::new();
    out.materials = mesh.materials.clone();
    let mut index = vec![u32::MAX; pos.len()];
    for (t, material) in tris {
        let ids = t.map(|v| {
            if index[v as usize] == u32::MAX {
                index[v as usize] = out.positions.len() as u32;
                out.positions.push(pos[v as usize]);
            }
            index[v as usize]
        });
        out.add_face(&[&ids], *material);
    }
    out
}

// ----- rectify -----

/// `rectify(angle)`: see the module docs. Vertices are welded first, so
/// that the faces sharing a vertex move it together.
pub fn rectify(mesh: &Mesh, angle: f64) -> Mesh {
    let angle = if angle.is_finite() {
        angle.clamp(0.0, 45.0)
    } else {
        0.0
    };
    let mut out = merge_vertices(mesh, mesh_tolerance(mesh));
    if out.faces.is_empty() || angle <= 0.0 {
        return out;
    }
    // The plane the mesh is most parallel to: the dominant axis of its
    // area-weighted normal (absolute, so opposite faces do not cancel).
    let mut acc = DVec3::ZERO;
    for f in 0..out.faces.len() {
        acc += (face_normal(&out, f) * face_area(&out, f)).abs();
    }
    let k = if acc.y >= acc.x && acc.y >= acc.z {
        1
    } else if acc.z >= acc.x {
        2
    } else {
        0
    };
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    let tan = angle.to_radians().tan();
    let n = out.positions.len();
    // Edges close to axis i share their j coordinate, and vice versa.
    let mut same_j: Vec<usize> = (0..n).collect();
    let mut same_i: Vec<usize> = (0..n).collect();
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    for f in 0..out.faces.len() {
        for &l in out.face_loops(f) {
            let idx = out.loop_indices(l);
            for e in 0..idx.len() {
                let (a, b) = (idx[e] as usize, idx[(e + 1) % idx.len()] as usize);
                let d = out.positions[b] - out.positions[a];
                let (di, dj) = (d[i].abs(), d[j].abs());
                if di > 0.0 && dj <= di * tan {
                    let (ra, rb) = (find(&mut same_j, a), find(&mut same_j, b));
                    same_j[rb] = ra;
                } else if dj > 0.0 && di <= dj * tan {
                    let (ra, rb) = (find(&mut same_i, a), find(&mut same_i, b));
                    same_i[rb] = ra;
                }
            }
        }
    }
    let average = |parent: &mut Vec<usize>, axis: usize, pos: &mut [DVec3]| {
        let mut sum: HashMap<usize, (f64, u32)> = HashMap::new();
        for (v, p) in pos.iter().enumerate() {
            let r = find(parent, v);
            let e = sum.entry(r).or_insert((0.0, 0));
            e.0 += p[axis];
            e.1 += 1;
        }
        for (v, p) in pos.iter_mut().enumerate() {
            let r = find(parent, v);
            let (s, c) = sum[&r];
            p[axis] = s / c as f64;
        }
    };
    let mut positions = out.positions.clone();
    average(&mut same_j, j, &mut positions);
    average(&mut same_i, i, &mut positions);
    out.positions = positions;
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::mesh_area;

    fn grid(n: usize) -> Mesh {
        let mut m = Mesh::new();
        for z in 0..=n {
            for x in 0..=n {
                let h = ((x as f64) * 0.7).sin() * ((z as f64) * 0.5).cos();
                m.positions.push(DVec3::new(x as f64, h, -(z as f64)));
            }
        }
        let w = (n + 1) as u32;
        for z in 0..n as u32 {
            for x in 0..n as u32 {
                let a = z * w + x;
                m.add_face(&[&[a, a + 1, a + w + 1, a + w]], 0);
            }
        }
        m
    }

    #[test]
    fn cleanup_joins_coplanar_faces_and_merges_vertices() {
        // A 2 x 1 rectangle made of two squares with separate vertices.
        let mut m = Mesh::polygon(&[
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, -1.0),
            DVec3::new(0.0, 0.0, -1.0),
        ]);
        let s = Mesh::polygon(&[
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, 0.0),
            DVec3::new(2.0, 0.0, -1.0),
            DVec3::new(1.0, 0.0, -1.0),
        ]);
        crate::transform::merge(&mut m, &s);
        let all = Parts {
            vertices: true,
            edges: true,
            faces: true,
        };
        let c = cleanup(&m, all, 0.0);
        assert_eq!(c.faces.len(), 1);
        // The straight corners at x = 1 are gone too.
        assert_eq!(c.outer_loop(0).len, 4);
        assert!((mesh_area(&c) - 2.0).abs() < 1e-12);
        // Only merging: two faces, six distinct positions used.
        let v = cleanup(
            &m,
            Parts {
                faces: true,
                ..Parts::default()
            },
            0.0,
        );
        assert_eq!(v.faces.len(), 2);
        assert_eq!(v.positions.len(), 6);
        // A duplicate and a sliver are removed.
        let mut d = m.clone();
        crate::transform::merge(&mut d, &s);
        crate::transform::merge(
            &mut d,
            &Mesh::polygon(&[DVec3::ZERO, DVec3::X, DVec3::new(0.5, 0.0, -1e-6)]),
        );
        let c = cleanup(
            &d,
            Parts {
                faces: true,
                ..Parts::default()
            },
            0.01,
        );
        assert_eq!(c.faces.len(), 2);
    }

    #[test]
    fn reduce_drops_the_requested_share_of_vertices() {
        let g = grid(10);
        let r = reduce(&g, 0.8);
        let used: std::collections::HashSet<u32> = r.corners.iter().copied().collect();
        assert_eq!(used.len(), (121.0f64 * 0.2).round() as usize);
        // The border stays: the footprint's extent is unchanged.
        let (lo, hi) = crate::measure::bounds(&r).unwrap();
        assert!(
            (hi.x - lo.x - 10.0).abs() < 1e-9 && (hi.z - lo.z - 10.0).abs() < 1e-9,
            "{lo} {hi}"
        );
        assert_eq!(reduce(&g, 0.0).faces.len(), 200);
    }

    #[test]
    fn rectify_snaps_nearly_axis_parallel_edges() {
        let m = Mesh::polygon(&[
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(10.0, 0.0, 0.3),
            DVec3::new(10.2, 0.0, -6.0),
            DVec3::new(0.0, 0.0, -6.0),
        ]);
        let r = rectify(&m, 5.0);
        let p = &r.positions;
        assert!((p[0].z - p[1].z).abs() < 1e-12);
        assert!((p[1].x - p[2].x).abs() < 1e-12);
        assert!(crate::measure::is_rectangular(&r, 1e-9));
        // Too strict an angle: unchanged.
        let r = rectify(&m, 1.0);
        assert_eq!(r.positions, m.positions);
    }
}
