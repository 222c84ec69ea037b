//! Polygon offsets and setbacks: the geometry behind CGA's `offset`,
//! `setback`, `setbackPerEdge`, `setbackToArea` and `shapeL`/`shapeU`/
//! `shapeO`.
//!
//! All of them are the wavefront of the weighted straight skeleton
//! ([`crate::skeleton`]) stopped at a time: a setback moves each edge inwards
//! by its own distance (weight = distance, stopped at time 1; unselected
//! edges have weight 0 and stay), an inward offset moves all edges by the
//! same distance. The part of each edge's skeleton face swept until then is
//! that edge's *strip* (the `border` faces of `offset`, the setback faces of
//! `setback`), the wavefront where it stopped is the *remainder* (the
//! `inside` faces). Corners are mitred exactly; strips of edges that meet at
//! a corner share the mitre line; a remainder that pinches off falls apart
//! into several faces, one that vanishes is empty. Outward offsets run the
//! same wavefront on the outside of the polygon (inside a far box of
//! weight-zero edges), so that a notch closes as the polygon grows.
//!
//! Faces are given in the plane of the input face; [`Offset::source_edge`]
//! names the footprint edge of every strip, so that the engine can apply its
//! edge selectors (`front`, `street.front`, index, ...) to them.

use glam::{DVec2, DVec3};

use crate::measure::face_normal;
use crate::mesh::Mesh;
use crate::roof::SourceEdge;
use crate::skeleton::{polygon_area, skeleton, SkeletonError, StopAt, WeightChange};
use crate::triangulate::plane_basis;

/// What a face of an [`Offset`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OffsetFace {
    /// The strip swept by one edge (`border` of `offset`; a setback face).
    Strip,
    /// The offset polygon (`inside` of `offset`; `remainder` of `setback`).
    Inside,
}

/// The component tag of an edge of a setback face (CGA's auto-tags).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SetbackEdgeTag {
    /// `setback.front`: the original edge a strip was set back from.
    Front,
    /// `setback.back`: a new edge where the setback stopped.
    Back,
    /// `setback.side`: a mitre edge between strips, or a shortened original
    /// edge of the remainder.
    Side,
    /// `setback.remainder`: an original edge of the remainder left whole.
    Remainder,
}

impl SetbackEdgeTag {
    pub fn tag(self) -> &'static str {
        match self {
            SetbackEdgeTag::Front => "setback.front",
            SetbackEdgeTag::Back => "setback.back",
            SetbackEdgeTag::Side => "setback.side",
            SetbackEdgeTag::Remainder => "setback.remainder",
        }
    }
}

/// Strips and remainder of an offset or setback.
#[derive(Clone, Debug, Default)]
pub struct Offset {
    /// The faces: per input face, its strips (in face-edge order, edges that
    /// do not move have none), then its inside faces.
    pub mesh: Mesh,
    pub kinds: Vec<OffsetFace>,
    /// The footprint edge of every strip (`None` for inside faces).
    pub source_edge: Vec<Option<SourceEdge>>,
    /// Tag of the edge starting at every corner (aligned with
    /// `mesh.corners`).
    pub corner_tags: Vec<SetbackEdgeTag>,
    /// The input corner whose edge every corner's edge comes from (a
    /// strip's front and back edges, the remainder's edges along input
    /// edges), `u32::MAX` for new edges (sides, grown outlines): the edge
    /// tags they inherit (aligned with `mesh.corners`).
    pub corner_source: Vec<u32>,
    /// Input faces that failed (they are missing from the result).
    pub failed: Vec<(usize, SkeletonError)>,
}

impl Offset {
    /// Indices of the faces of one kind.
    pub fn faces_of(&self, kind: OffsetFace) -> Vec<usize> {
        (0..self.kinds.len())
            .filter(|&f| self.kinds[f] == kind)
            .collect()
    }
}

const NO_SOURCE: u32 = u32::MAX;

/// Gives the faces of `out` from `first` on the tags of input face `f`.
fn keep_face_tags(out: &mut Offset, mesh: &Mesh, first: usize, f: usize) {
    let tags = mesh.faces[f].tags;
    for face in &mut out.mesh.faces[first..] {
        face.tags = tags;
    }
}

/// The edge tags of the result: every edge inherits the tags of the input
/// edge it comes from (`corner_source`); with `auto`, the setback's
/// auto-tags replace earlier setback tags.
fn finish_edge_tags(out: &mut Offset, mesh: &Mesh, auto: bool) {
    if !auto && mesh.edge_tags.is_none() {
        return;
    }
    let q = crate::tags::TagQuery::parse("setback");
    let n = out.mesh.corners.len();
    let mut list = vec![0u32; n];
    let mut memo: Vec<(u32, Option<SetbackEdgeTag>, u32)> = Vec::new();
    for (c, slot) in list.iter_mut().enumerate() {
        let src = out.corner_source.get(c).copied().unwrap_or(NO_SOURCE);
        let old = if src == NO_SOURCE {
            0
        } else {
            mesh.edge_tag_index(src as usize)
        };
        let role = if auto {
            out.corner_tags.get(c).copied()
        } else {
            None
        };
        if let Some(m) = memo.iter().find(|m| m.0 == old && m.1 == role) {
            *slot = m.2;
            continue;
        }
        let mut set = mesh.tag_set(old).clone();
        if let Some(r) = role {
            set = set
                .without(|t| q.matches(t))
                .with(&std::sync::Arc::from(r.tag()));
        }
        let i = out.mesh.intern_tags(set);
        memo.push((old, role, i));
        *slot = i;
    }
    out.mesh.edge_tags = (!list.iter().all(|&t| t == 0)).then_some(list);
}

/// A face projected into its plane.
struct Flat {
    o: DVec3,
    u: DVec3,
    v: DVec3,
    loops: Vec<Vec<DVec2>>,
    /// First input corner of every loop.
    starts: Vec<u32>,
}

fn flatten(mesh: &Mesh, f: usize) -> Option<Flat> {
    let n = face_normal(mesh, f);
    if n == DVec3::ZERO {
        return None;
    }
    let (u, v) = plane_basis(n);
    let o = mesh.positions[mesh.corners[mesh.outer_loop(f).start as usize] as usize];
    let loops = mesh
        .face_loops(f)
        .iter()
        .map(|&l| {
            mesh.loop_points(l)
                .map(|p| DVec2::new((p - o).dot(u), (p - o).dot(v)))
                .collect()
        })
        .collect();
    let starts = mesh.face_loops(f).iter().map(|l| l.start).collect();
    Some(Flat {
        o,
        u,
        v,
        loops,
        starts,
    })
}

impl Flat {
    /// The input corner of edge `e` counted over all loops of the face.
    fn corner_of(&self, mut e: usize) -> u32 {
        for (l, pts) in self.loops.iter().enumerate() {
            if e < pts.len() {
                return self.starts[l] + e as u32;
            }
            e -= pts.len();
        }
        NO_SOURCE
    }

    fn lift(&self, p: DVec2) -> DVec3 {
        self.o + self.u * p.x + self.v * p.y
    }
}

/// `offset(distance)`: negative insets, positive grows (see the module docs).
/// Inside faces are counter-clockwise; border strips are counter-clockwise
/// for insets and clockwise (facing down) when growing, so that in both
/// cases inside + border = the original face in signed area.
pub fn offset(mesh: &Mesh, distance: f64) -> Offset {
    let mut out = Offset {
        mesh: Mesh::new(),
        ..Default::default()
    };
    out.mesh.materials = mesh.materials.clone();
    out.mesh.tags = mesh.tags.clone();
    if !distance.is_finite() {
        return out;
    }
    for f in 0..mesh.faces.len() {
        let Some(flat) = flatten(mesh, f) else {
            continue;
        };
        let first = out.mesh.faces.len();
        let material = mesh.faces[f].material;
        let r = if distance <= 0.0 {
            let w: Vec<Vec<f64>> = flat.loops.iter().map(|l| vec![1.0; l.len()]).collect();
            strips_and_remainder(&mut out, &flat, &w, -distance, f, material)
        } else {
            grow(&mut out, &flat, distance, f, material)
        };
        if let Err(e) = r {
            out.failed.push((f, e));
        }
        keep_face_tags(&mut out, mesh, first, f);
    }
    finish_edge_tags(&mut out, mesh, false);
    out
}

/// `setback(distances)`: edge `k` of the mesh in face-edge order (outer loop
/// then holes, face by face) is set back by `distances[k]` (missing,
/// negative or non-finite distances: no setback). Strips come only from
/// edges with a positive distance.
pub fn setback(mesh: &Mesh, distances: &[f64]) -> Offset {
    let mut out = Offset {
        mesh: Mesh::new(),
        ..Default::default()
    };
    out.mesh.materials = mesh.materials.clone();
    out.mesh.tags = mesh.tags.clone();
    let mut k = 0usize;
    for f in 0..mesh.faces.len() {
        let loops = mesh.face_loops(f);
        let count: usize = loops.iter().map(|l| l.len as usize).sum();
        let Some(flat) = flatten(mesh, f) else {
            k += count;
            continue;
        };
        let mut w = Vec::with_capacity(flat.loops.len());
        for l in &flat.loops {
            let mut wl = Vec::with_capacity(l.len());
            for _ in 0..l.len() {
                let d = distances.get(k).copied().unwrap_or(0.0);
                wl.push(if d.is_finite() && d > 0.0 { d } else { 0.0 });
                k += 1;
            }
            w.push(wl);
        }
        let first = out.mesh.faces.len();
        if let Err(e) = strips_and_remainder(&mut out, &flat, &w, 1.0, f, mesh.faces[f].material) {
            out.failed.push((f, e));
        }
        keep_face_tags(&mut out, mesh, first, f);
    }
    finish_edge_tags(&mut out, mesh, true);
    out
}

/// `setbackToArea(area, minDistances, maxDistances)`: the common extra
/// distance `s` such that setting back every selected edge by
/// `min[k] + s` (at most `max[k]`) leaves a remainder of `area`. Returns the
/// setback, the per-edge distances used, and whether the area was reached
/// (if not, the nearest feasible setback is returned: `s = 0` when the
/// shape is already too small, every edge at its maximum when the maximums
/// are too small).
///
/// For a single face the remainder's area is quadratic in time between
/// skeleton events, so `s` is solved exactly from one skeleton run; for
/// several faces (in different planes) the total is solved by bisection on
/// `s` over exact per-face evaluations.
pub fn setback_to_area(
    mesh: &Mesh,
    area: f64,
    selected: &[bool],
    min: Option<&[f64]>,
    max: Option<&[f64]>,
) -> (Offset, Vec<f64>, bool) {
    let n_edges: usize = (0..mesh.faces.len())
        .map(|f| {
            mesh.face_loops(f)
                .iter()
                .map(|l| l.len as usize)
                .sum::<usize>()
        })
        .sum();
    let sel = |k: usize| selected.get(k).copied().unwrap_or(false);
    let lo: Vec<f64> = (0..n_edges)
        .map(|k| {
            let d = min.and_then(|m| m.get(k)).copied().unwrap_or(0.0);
            if sel(k) && d.is_finite() {
                d.max(0.0)
            } else {
                0.0
            }
        })
        .collect();
    let cap: Vec<f64> = (0..n_edges)
        .map(|k| {
            if !sel(k) {
                return 0.0;
            }
            let m = max.and_then(|m| m.get(k)).copied().unwrap_or(f64::INFINITY);
            if m.is_nan() {
                f64::INFINITY
            } else {
                (m - lo[k]).max(0.0)
            }
        })
        .collect();
    let dist =
        |s: f64| -> Vec<f64> { (0..n_edges).map(|k| lo[k] + s.clamp(0.0, cap[k])).collect() };
    let remainder_area = |o: &Offset| -> f64 {
        o.faces_of(OffsetFace::Inside)
            .iter()
            .map(|&f| crate::measure::face_area(&o.mesh, f))
            .sum()
    };
    let at_min = setback(mesh, &lo);
    let a0 = remainder_area(&at_min);
    if area.is_nan() || area <= 0.0 || a0 <= area {
        return (at_min, lo, a0 == area);
    }
    let s = if mesh.faces.len() == 1 {
        solve_single(mesh, area, &lo, &cap)
    } else {
        None
    };
    let s = match s {
        Some(s) => s,
        None => {
            // Bisection on the monotone total area.
            let s_max = cap
                .iter()
                .copied()
                .filter(|c| c.is_finite())
                .fold(0.0, f64::max);
            let mut hi = if s_max > 0.0 { s_max } else { 1.0 };
            let size = crate::measure::bounds(mesh).map_or(1.0, |(a, b)| (b - a).max_element());
            if cap.iter().any(|c| c.is_infinite()) {
                hi = hi.max(size);
            }
            let mut lo_s = 0.0;
            for _ in 0..60 {
                let mid = 0.5 * (lo_s + hi);
                if remainder_area(&setback(mesh, &dist(mid))) > area {
                    lo_s = mid;
                } else {
                    hi = mid;
                }
            }
            hi
        }
    };
    let d = dist(s);
    let o = setback(mesh, &d);
    let ok = (remainder_area(&o) - area).abs() <= 1e-6 * area.max(1.0);
    (o, d, ok)
}

/// Exact `s` for a single face: offset by the minimums, then run a
/// wavefront with weight 1 on selected edges (dropping to 0 when an edge
/// reaches its maximum) until the area reaches the target.
fn solve_single(mesh: &Mesh, area: f64, lo: &[f64], cap: &[f64]) -> Option<f64> {
    let flat = flatten(mesh, 0)?;
    let mut w = Vec::new();
    let mut k = 0;
    for l in &flat.loops {
        w.push(
            l.iter()
                .map(|_| {
                    k += 1;
                    lo[k - 1]
                })
                .collect::<Vec<f64>>(),
        );
    }
    let n: usize = k;
    // Phase 1: the remainder at the minimum distances, with edge ids.
    let base = skeleton(&flat.loops, &w, StopAt::Time(1.0), &[]).ok()?;
    let mut loops = Vec::new();
    let mut weights = Vec::new();
    let mut changes = Vec::new();
    let mut g = 0;
    for lp in &base.wavefront {
        let pts: Vec<DVec2> = lp.iter().map(|&(nd, _)| base.nodes[nd as usize]).collect();
        let ws: Vec<f64> = lp
            .iter()
            .map(|&(_, e)| {
                let e = e as usize;
                if e < n && cap[e] > 0.0 {
                    1.0
                } else {
                    0.0
                }
            })
            .collect();
        for (i, &(_, e)) in lp.iter().enumerate() {
            let e = e as usize;
            if e < n && cap[e].is_finite() && cap[e] > 0.0 {
                changes.push(WeightChange {
                    edge: g + i,
                    time: cap[e],
                    weight: 0.0,
                });
            }
        }
        g += pts.len();
        loops.push(pts);
        weights.push(ws);
    }
    if loops.is_empty() {
        return None;
    }
    match skeleton(&loops, &weights, StopAt::Area(area), &changes) {
        Ok(s) => Some(s.stop_time),
        // Never reaches the area: every edge at its maximum.
        Err(SkeletonError::NoCollapse) => Some(cap.iter().copied().fold(0.0, f64::max)),
        Err(_) => None,
    }
}

/// The setback behind `shapeL`/`shapeU`/`shapeO`: [`setback`] with the
/// remainder tagged as the page's figure shows it (op_shapeLUO: "exactly
/// like the setback operation", with the remainder's original edges,
/// shortened by a wing or whole, `setback.remainder`).
pub fn setback_luo(mesh: &Mesh, distances: &[f64]) -> Offset {
    let mut o = setback(mesh, distances);
    let mut corner = 0;
    for f in 0..o.mesh.faces.len() {
        let n: usize = o.mesh.face_loops(f).iter().map(|l| l.len as usize).sum();
        if o.kinds[f] == OffsetFace::Inside {
            for c in corner..corner + n {
                if o.corner_tags[c] == SetbackEdgeTag::Side && o.corner_source[c] != NO_SOURCE {
                    o.corner_tags[c] = SetbackEdgeTag::Remainder;
                }
            }
        }
        corner += n;
    }
    finish_edge_tags(&mut o, mesh, true);
    o
}

/// Strips of `shapeL`/`shapeU`/`shapeO` merged into one shape: the union of
/// the strip faces of a [`setback`] (faces sharing mitre edges are joined),
/// as faces with holes (an O shape is a ring). The remainder is the setback's
/// inside faces.
pub fn merge_strips(o: &Offset) -> Mesh {
    let strips = o.faces_of(OffsetFace::Strip);
    let topo_tol = crate::topology::mesh_tolerance(&o.mesh);
    let weld = crate::topology::weld_points(&o.mesh.positions, topo_tol);
    // Directed edges of all strips; opposite pairs cancel.
    let mut half: Vec<(u32, u32)> = Vec::new();
    for &f in &strips {
        for &l in o.mesh.face_loops(f) {
            let idx = o.mesh.loop_indices(l);
            for i in 0..idx.len() {
                let a = weld.id[idx[i] as usize];
                let b = weld.id[idx[(i + 1) % idx.len()] as usize];
                if a != b {
                    half.push((a, b));
                }
            }
        }
    }
    let mut set: std::collections::HashMap<(u32, u32), u32> = std::collections::HashMap::new();
    for &h in &half {
        *set.entry(h).or_insert(0) += 1;
    }
    let mut rest: Vec<(u32, u32)> = Vec::new();
    for &(a, b) in &half {
        let back = set.get(&(b, a)).copied().unwrap_or(0);
        if back == 0 {
            rest.push((a, b));
        }
    }
    let pos = |w: u32| o.mesh.positions[weld.representative[w as usize] as usize];
    let mut used = vec![false; rest.len()];
    let mut loops3: Vec<Vec<DVec3>> = Vec::new();
    for s in 0..rest.len() {
        if used[s] {
            continue;
        }
        used[s] = true;
        let start = rest[s].0;
        let mut cur = rest[s].1;
        let mut lp = vec![pos(start)];
        let mut guard = 0;
        while cur != start && guard <= rest.len() {
            guard += 1;
            lp.push(pos(cur));
            match (0..rest.len()).find(|&j| !used[j] && rest[j].0 == cur) {
                Some(j) => {
                    used[j] = true;
                    cur = rest[j].1;
                }
                None => break,
            }
        }
        if cur == start && lp.len() >= 3 {
            loops3.push(lp);
        }
    }
    let n = strips
        .first()
        .map_or(DVec3::Y, |&f| face_normal(&o.mesh, f));
    let mut m = faces_from_loops(&loops3, n, o.mesh.faces.first().map_or(0, |f| f.material));
    m.tags = o.mesh.tags.clone();
    if let Some(&f) = strips.first() {
        let tags = o.mesh.faces[f].tags;
        for face in &mut m.faces {
            face.tags = tags;
        }
    }
    copy_strip_edge_tags(&mut m, o, &strips, topo_tol);
    m
}

/// Gives every edge of the merged strips `m` the edge tags of the strip
/// edge it lies on (the strips' front, back and side edges keep their
/// auto-tags and inherited tags through the merge).
fn copy_strip_edge_tags(m: &mut Mesh, o: &Offset, strips: &[usize], tol: f64) {
    let Some(src_tags) = o.mesh.edge_tags.as_ref() else {
        return;
    };
    // Every strip edge: its end points and its tag set.
    let mut edges: Vec<(DVec3, DVec3, u32)> = Vec::new();
    for &f in strips {
        for &l in o.mesh.face_loops(f) {
            let idx = o.mesh.loop_indices(l);
            for i in 0..idx.len() {
                let c = l.start as usize + i;
                let a = o.mesh.positions[idx[i] as usize];
                let b = o.mesh.positions[idx[(i + 1) % idx.len()] as usize];
                edges.push((a, b, src_tags[c]));
            }
        }
    }
    let tol = tol.max(1e-9);
    let on = |a: DVec3, b: DVec3, p: DVec3| {
        let ab = b - a;
        let len2 = ab.length_squared();
        if len2 == 0.0 {
            return false;
        }
        let t = (p - a).dot(ab) / len2;
        (-1e-9..=1.0 + 1e-9).contains(&t) && (a + ab * t).distance(p) <= tol
    };
    let mut list = vec![0u32; m.corners.len()];
    for f in 0..m.faces.len() {
        for &l in m.face_loops(f) {
            let idx = m.loop_indices(l).to_vec();
            for i in 0..idx.len() {
                let a = m.positions[idx[i] as usize];
                let b = m.positions[idx[(i + 1) % idx.len()] as usize];
                let mid = (a + b) * 0.5;
                if let Some(&(_, _, t)) = edges.iter().find(|(p, q, _)| on(*p, *q, mid)) {
                    list[l.start as usize + i] = t;
                }
            }
        }
    }
    m.edge_tags = (!list.iter().all(|&t| t == 0)).then_some(list);
}

/// Faces from closed loops in a plane of normal `n`: counter-clockwise loops
/// are outer boundaries, clockwise ones holes of the outer loop containing
/// them.
fn faces_from_loops(loops: &[Vec<DVec3>], n: DVec3, material: u32) -> Mesh {
    let mut m = Mesh::new();
    let (u, v) = plane_basis(n);
    let flat: Vec<Vec<DVec2>> = loops
        .iter()
        .map(|l| l.iter().map(|p| DVec2::new(p.dot(u), p.dot(v))).collect())
        .collect();
    let (outers, holes): (Vec<usize>, Vec<usize>) =
        (0..loops.len()).partition(|&i| polygon_area(&flat[i]) > 0.0);
    let mut holes_of: Vec<Vec<usize>> = vec![Vec::new(); outers.len()];
    for &h in &holes {
        // The smallest outer loop containing the hole's first point.
        let p = flat[h][0];
        let best = outers
            .iter()
            .enumerate()
            .filter(|&(_, &o)| contains(&flat[o], p))
            .min_by(|a, b| polygon_area(&flat[*a.1]).total_cmp(&polygon_area(&flat[*b.1])));
        if let Some((k, _)) = best {
            holes_of[k].push(h);
        }
    }
    for (k, &o) in outers.iter().enumerate() {
        let mut ids: Vec<Vec<u32>> = Vec::new();
        for &l in std::iter::once(&o).chain(holes_of[k].iter()) {
            let start = m.positions.len() as u32;
            m.positions.extend_from_slice(&loops[l]);
            ids.push((start..start + loops[l].len() as u32).collect());
        }
        let refs: Vec<&[u32]> = ids.iter().map(|x| x.as_slice()).collect();
        m.add_face(&refs, material);
    }
    m
}

/// Winding-number point-in-polygon test (points on the boundary count as
/// inside), with exact orientation tests.
fn contains(poly: &[DVec2], p: DVec2) -> bool {
    let c = |q: DVec2| robust::Coord { x: q.x, y: q.y };
    let mut wn = 0i32;
    let n = poly.len();
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        let o = robust::orient2d(c(a), c(b), c(p));
        if o == 0.0 && (p - a).dot(p - b) <= 0.0 {
            return true;
        }
        if a.y <= p.y {
            if b.y > p.y && o > 0.0 {
                wn += 1;
            }
        } else if b.y <= p.y && o < 0.0 {
            wn -= 1;
        }
    }
    wn != 0
}

fn add_face_tagged(
    out: &mut Offset,
    pts: &[DVec3],
    tags: &[SetbackEdgeTag],
    sources: &[u32],
    kind: OffsetFace,
    src: Option<SourceEdge>,
    material: u32,
) {
    let start = out.mesh.positions.len() as u32;
    out.mesh.positions.extend_from_slice(pts);
    let ids: Vec<u32> = (start..start + pts.len() as u32).collect();
    out.mesh.add_face(&[&ids], material);
    out.corner_tags.extend_from_slice(tags);
    out.corner_source.extend_from_slice(sources);
    out.kinds.push(kind);
    out.source_edge.push(src);
}

/// Runs the wavefront with weights `w` until `time` and adds the strips and
/// the remainder of one face.
fn strips_and_remainder(
    out: &mut Offset,
    flat: &Flat,
    w: &[Vec<f64>],
    time: f64,
    f: usize,
    material: u32,
) -> Result<(), SkeletonError> {
    let sk = skeleton(&flat.loops, w, StopAt::Time(time), &[])?;
    let stop = sk.stop_time;
    let tol = 1e-9 * (1.0 + stop);
    let mut g = 0;
    for (l, wl) in w.iter().enumerate() {
        for (i, &wi) in wl.iter().enumerate() {
            let face = &sk.faces[g];
            g += 1;
            if wi <= 0.0 || face.len() < 3 {
                continue;
            }
            let p3: Vec<DVec3> = face
                .iter()
                .map(|&nd| flat.lift(sk.nodes[nd as usize]))
                .collect();
            let m = face.len();
            let tags: Vec<SetbackEdgeTag> = (0..m)
                .map(|j| {
                    let (a, b) = (face[j], face[(j + 1) % m]);
                    if j == 0 {
                        SetbackEdgeTag::Front
                    } else if (sk.times[a as usize] - stop).abs() <= tol
                        && (sk.times[b as usize] - stop).abs() <= tol
                    {
                        SetbackEdgeTag::Back
                    } else {
                        SetbackEdgeTag::Side
                    }
                })
                .collect();
            let src = Some(SourceEdge {
                face: f as u32,
                loop_index: l as u32,
                edge: i as u32,
            });
            let from = flat.starts[l] + i as u32;
            let sources: Vec<u32> = tags
                .iter()
                .map(|t| match t {
                    SetbackEdgeTag::Side => NO_SOURCE,
                    _ => from,
                })
                .collect();
            add_face_tagged(out, &p3, &tags, &sources, OffsetFace::Strip, src, material);
        }
    }
    // The remainder: wavefront loops grouped into faces with holes.
    let n_in: usize = flat.loops.iter().map(|l| l.len()).sum();
    let weight_of = |e: u32| -> f64 {
        let mut e = e as usize;
        if e >= n_in {
            return 0.0;
        }
        for wl in w {
            if e < wl.len() {
                return wl[e];
            }
            e -= wl.len();
        }
        0.0
    };
    let flat_loops: Vec<Vec<DVec2>> = sk
        .wavefront
        .iter()
        .map(|lp| lp.iter().map(|&(nd, _)| sk.nodes[nd as usize]).collect())
        .collect();
    let (outers, holes): (Vec<usize>, Vec<usize>) =
        (0..flat_loops.len()).partition(|&i| polygon_area(&flat_loops[i]) > 0.0);
    let input_pts: Vec<DVec2> = flat.loops.iter().flatten().copied().collect();
    let is_input = |p: DVec2| input_pts.iter().any(|q| q.distance(p) <= tol * 10.0);
    let mut holes_of: Vec<Vec<usize>> = vec![Vec::new(); outers.len()];
    for &h in &holes {
        let p = flat_loops[h][0];
        let best = outers
            .iter()
            .enumerate()
            .filter(|&(_, &o)| contains(&flat_loops[o], p))
            .min_by(|a, b| {
                polygon_area(&flat_loops[*a.1]).total_cmp(&polygon_area(&flat_loops[*b.1]))
            });
        if let Some((k, _)) = best {
            holes_of[k].push(h);
        }
    }
    for (k, &o) in outers.iter().enumerate() {
        let mut ids: Vec<Vec<u32>> = Vec::new();
        let mut tags = Vec::new();
        let mut sources = Vec::new();
        for &l in std::iter::once(&o).chain(holes_of[k].iter()) {
            let lp = &sk.wavefront[l];
            let start = out.mesh.positions.len() as u32;
            for (j, &(nd, e)) in lp.iter().enumerate() {
                out.mesh.positions.push(flat.lift(sk.nodes[nd as usize]));
                let next = sk.nodes[lp[(j + 1) % lp.len()].0 as usize];
                sources.push(if (e as usize) < n_in {
                    flat.corner_of(e as usize)
                } else {
                    NO_SOURCE
                });
                tags.push(if weight_of(e) > 0.0 {
                    SetbackEdgeTag::Back
                } else if is_input(sk.nodes[nd as usize]) && is_input(next) {
                    SetbackEdgeTag::Remainder
                } else {
                    SetbackEdgeTag::Side
                });
            }
            ids.push((start..start + lp.len() as u32).collect());
        }
        let refs: Vec<&[u32]> = ids.iter().map(|x| x.as_slice()).collect();
        out.mesh.add_face(&refs, material);
        out.corner_tags.extend(tags);
        out.corner_source.extend(sources);
        out.kinds.push(OffsetFace::Inside);
        out.source_edge.push(None);
    }
    Ok(())
}

/// Outward offset of one face: the wavefront of the outside (the loops
/// reversed, inside a far static box) stopped at `d`.
fn grow(
    out: &mut Offset,
    flat: &Flat,
    d: f64,
    f: usize,
    material: u32,
) -> Result<(), SkeletonError> {
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    for p in flat.loops.iter().flatten() {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let m = 2.0 * d + (hi - lo).max_element() + 1.0;
    let (a, b) = (lo - DVec2::splat(m), hi + DVec2::splat(m));
    let mut loops: Vec<Vec<DVec2>> = flat
        .loops
        .iter()
        .map(|l| {
            let mut r = l.clone();
            r.reverse();
            r
        })
        .collect();
    let n_in: usize = loops.iter().map(|l| l.len()).sum();
    loops.push(vec![a, DVec2::new(b.x, a.y), b, DVec2::new(a.x, b.y)]);
    let mut w: Vec<Vec<f64>> = loops.iter().map(|l| vec![1.0; l.len()]).collect();
    *w.last_mut().unwrap() = vec![0.0; 4];
    let sk = skeleton(&loops, &w, StopAt::Time(d), &[])?;
    let stop = sk.stop_time;
    let tol = 1e-9 * (1.0 + stop);
    // Border strips: the outside faces reversed (clockwise), from the
    // original edge a -> b.
    let mut g = 0;
    for (l, pts) in flat.loops.iter().enumerate() {
        let k = pts.len();
        for j in 0..k {
            // Original edge j (a -> b) is reversed edge k - 2 - j (b -> a).
            let rev = (2 * k - 2 - j) % k;
            let face = &sk.faces[g + rev];
            if face.len() < 3 {
                continue;
            }
            // face = [b, a, n1, .., nm] -> [a, b, nm, .., n1]
            let mut ids = vec![face[1], face[0]];
            ids.extend(face[2..].iter().rev());
            let p3: Vec<DVec3> = ids
                .iter()
                .map(|&nd| flat.lift(sk.nodes[nd as usize]))
                .collect();
            let mm = ids.len();
            let tags: Vec<SetbackEdgeTag> = (0..mm)
                .map(|q| {
                    let (x, y) = (ids[q], ids[(q + 1) % mm]);
                    if q == 0 {
                        SetbackEdgeTag::Front
                    } else if (sk.times[x as usize] - stop).abs() <= tol
                        && (sk.times[y as usize] - stop).abs() <= tol
                    {
                        SetbackEdgeTag::Back
                    } else {
                        SetbackEdgeTag::Side
                    }
                })
                .collect();
            let src = Some(SourceEdge {
                face: f as u32,
                loop_index: l as u32,
                edge: j as u32,
            });
            let from = flat.starts[l] + j as u32;
            let sources: Vec<u32> = tags
                .iter()
                .map(|t| match t {
                    SetbackEdgeTag::Side => NO_SOURCE,
                    _ => from,
                })
                .collect();
            add_face_tagged(out, &p3, &tags, &sources, OffsetFace::Strip, src, material);
        }
        g += k;
    }
    // The grown polygon: remaining wavefront loops except the box, reversed.
    let mut loops3: Vec<Vec<DVec3>> = Vec::new();
    for lp in &sk.wavefront {
        if lp.iter().any(|&(_, e)| e as usize >= n_in) {
            continue;
        }
        let mut p: Vec<DVec3> = lp
            .iter()
            .map(|&(nd, _)| flat.lift(sk.nodes[nd as usize]))
            .collect();
        p.reverse();
        loops3.push(p);
    }
    let n = flat.u.cross(flat.v);
    let faces = faces_from_loops(&loops3, n, material);
    for pf in 0..faces.faces.len() {
        let mut ids: Vec<Vec<u32>> = Vec::new();
        for &l in faces.face_loops(pf) {
            let start = out.mesh.positions.len() as u32;
            out.mesh.positions.extend(faces.loop_points(l));
            ids.push((start..start + l.len).collect());
            out.corner_tags
                .extend(std::iter::repeat_n(SetbackEdgeTag::Back, l.len as usize));
            out.corner_source
                .extend(std::iter::repeat_n(NO_SOURCE, l.len as usize));
        }
        let refs: Vec<&[u32]> = ids.iter().map(|x| x.as_slice()).collect();
        out.mesh.add_face(&refs, material);
        out.kinds.push(OffsetFace::Inside);
        out.source_edge.push(None);
    }
    Ok(())
}

#[cfg(test)]
#[path = "setback_tests.rs"]
mod tests;
