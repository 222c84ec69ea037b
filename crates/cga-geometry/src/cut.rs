//! Cutting meshes with planes: the geometry behind CGA's `split`, and trim
//! planes.
//!
//! Written by hand: no crate cuts indexed polygon meshes with holes and
//! per-corner attributes, and closes the cut with cap polygons.
//!
//! # How a cut works
//!
//! Positions are first welded (coincident within [`mesh_tolerance`]), so
//! that faces sharing an edge share its vertex ids even when the mesh repeats
//! positions. Every vertex gets a signed distance `s` to each plane and is
//! *on* the plane if `|s| <= tol`. A face with no vertex strictly below goes
//! above; with none strictly above, below; with all vertices on the plane, to
//! the side its normal points away from (a top face lying in the plane closes
//! the part below it). Only faces with vertices strictly on both sides are
//! split:
//!
//! - The plane is symbolically pushed up by an infinitesimal amount, so that
//!   on-plane vertices count as below and no edge crosses it at a vertex
//!   ("simulation of simplicity"). An edge from an on-plane vertex to a vertex
//!   above crosses at that vertex itself; an edge between strictly opposite
//!   vertices crosses at a new vertex, created once per welded edge so that
//!   both faces of the edge share it.
//! - The crossings of all loops (outer and holes) are sorted along the cut
//!   line; consecutive pairs bound the segments of the line inside the face
//!   (ties at a shared vertex are ordered by where the pushed plane would cut
//!   the two edges). Walking each loop on one side and jumping along the line
//!   from a crossing to its partner traces every piece's outer boundary.
//!   Holes not crossing the line go to the piece containing them.
//! - Pieces are cleaned: repeated vertices (crossings at on-plane vertices)
//!   are merged, and pieces without area (all vertices on the plane) dropped:
//!   no slivers.
//!
//! If the input is closed (every welded edge used as often in one direction
//! as in the other), each part is closed with caps: the directed edges of a
//! part that lie in a cut plane and are not matched by a reverse edge of the
//! same part are exactly the boundary of the cross-section. They are chained
//! into loops in the plane (at a vertex where several continue, the sharpest
//! turn keeps loops simple), counter-clockwise loops become cap faces and
//! clockwise ones their holes (a cut through a tube gives a ring). Caps take
//! the material and group of the face along their first edge, UVs (0, 0) and,
//! if the mesh has normals, the cap's outward normal. Both parts use the same
//! cap vertices, so volumes add up exactly.
//!
//! Per-corner attributes of new corners are interpolated along the original
//! edge they lie on: every corner of a piece is stored as an original edge
//! `(a, b)` and a parameter `t`, which stays exact through successive cuts of
//! [`split_along_axis`].

use glam::{DVec2, DVec3};

use crate::measure::face_normal;
use crate::mesh::{Face, Loop, Mesh};
use crate::topology::{fx_map, mesh_tolerance, weld_points, FxHashMap};
use crate::triangulate::plane_basis;

/// Cuts `mesh` with the plane `normal · p = offset` into the part below
/// (`normal · p < offset`) and the part above. `normal` need not be of unit
/// length. Closed meshes give closed parts (see the module docs); a zero or
/// non-finite normal returns the whole mesh below.
pub fn cut_by_plane(mesh: &Mesh, normal: DVec3, offset: f64) -> (Mesh, Mesh) {
    let len = normal.length();
    if !(len > 0.0 && len.is_finite() && offset.is_finite()) {
        return (mesh.clone(), empty_like(mesh));
    }
    let mut parts = split_by_parallel_planes(mesh, normal / len, &[offset / len]);
    let above = parts.pop().unwrap_or_else(|| empty_like(mesh));
    let below = parts.pop().unwrap_or_else(|| empty_like(mesh));
    (below, above)
}

/// Cuts `mesh` at the planes `p[axis] = cuts[i]` into `cuts.len() + 1`
/// slabs: slab `i` lies between `cuts[i - 1]` and `cuts[i]` (slab 0 below
/// the first cut, the last above the last cut). Empty slabs are empty
/// meshes. `cuts` should be ascending; a smaller value than its predecessor
/// is raised to it. Faces lying inside one slab are copied once, so the work
/// is about linear in faces plus pieces. An `axis` beyond 2 returns the whole
/// mesh as the first slab.
pub fn split_along_axis(mesh: &Mesh, axis: usize, cuts: &[f64]) -> Vec<Mesh> {
    let normal = match axis {
        0 => DVec3::X,
        1 => DVec3::Y,
        2 => DVec3::Z,
        _ => {
            let mut out = vec![mesh.clone()];
            out.extend((0..cuts.len()).map(|_| empty_like(mesh)));
            return out;
        }
    };
    split_by_parallel_planes(mesh, normal, cuts)
}

/// Cuts `mesh` at the parallel planes `normal · p = offsets[i]` (`normal` of
/// unit length, `offsets` ascending) into `offsets.len() + 1` parts, as
/// [`split_along_axis`] does for a general direction.
pub fn split_by_parallel_planes(mesh: &Mesh, normal: DVec3, offsets: &[f64]) -> Vec<Mesh> {
    // Sanitise the offsets: ascending, finite (NaN sorts as "no cut": it is
    // replaced by its predecessor, or -inf for the first).
    let mut planes = Vec::with_capacity(offsets.len());
    let mut prev = f64::NEG_INFINITY;
    for &o in offsets {
        let o = if o.is_nan() { prev } else { o.max(prev) };
        planes.push(o);
        prev = o;
    }
    let mut cutter = Cutter::new(mesh, normal, planes);
    cutter.run();
    cutter.build()
}

/// An empty mesh with the same material slots and groups as `mesh`.
fn empty_like(mesh: &Mesh) -> Mesh {
    let mut m = Mesh::new();
    m.materials = mesh.materials.clone();
    m.groups = mesh.groups.clone();
    m
}

/// A corner of a piece: a vertex (welded id, or a new crossing vertex) and
/// where its attributes come from: the point at parameter `t` of the original
/// edge from corner `a` to corner `b` (`t = 0`: corner `a` itself). `a ==
/// CAP` marks a cap corner.
#[derive(Clone, Copy, Debug, PartialEq)]
struct WCorner {
    v: u32,
    a: u32,
    b: u32,
    t: f64,
}

const CAP: u32 = u32::MAX;
const NONE: u32 = u32::MAX;

/// Faces routed to a part: either a whole original face, or a piece stored in
/// the cutter's piece store.
#[derive(Clone, Copy, Debug)]
enum Item {
    Whole(u32),
    Piece(u32),
}

/// A piece of a face: loops `loops[first..first + count]` of the piece store.
#[derive(Clone, Copy, Debug)]
struct PieceRec {
    face: u32,
    first: u32,
    count: u32,
}

/// A polygon being routed through the planes: loops as ranges of `corners`.
#[derive(Clone, Debug, Default)]
struct Poly {
    corners: Vec<WCorner>,
    loops: Vec<(u32, u32)>,
}

impl Poly {
    fn clear(&mut self) {
        self.corners.clear();
        self.loops.clear();
    }
    fn push_loop(&mut self, l: &[WCorner]) {
        self.loops.push((self.corners.len() as u32, l.len() as u32));
        self.corners.extend_from_slice(l);
    }
    fn loop_slice(&self, k: usize) -> &[WCorner] {
        let (s, n) = self.loops[k];
        &self.corners[s as usize..(s + n) as usize]
    }
}

#[derive(Clone, Copy, Debug)]
struct Crossing {
    corner: WCorner,
    /// Loop index and edge start (position within the loop).
    lp: u32,
    edge: u32,
    lambda: f64,
    tie: f64,
    /// True if the loop goes from below to above here.
    up: bool,
}

enum Side {
    Below,
    Above,
    On,
    Both,
}

struct Cutter<'m> {
    mesh: &'m Mesh,
    n: DVec3,
    /// For axis-aligned cuts, the axis (crossing vertices get that coordinate
    /// set exactly to the plane's, so caps are exactly planar).
    axis: Option<usize>,
    planes: Vec<f64>,
    tol: f64,
    /// Welded vertex id of each original position.
    vid: Vec<u32>,
    /// Vertex pool: welded positions, then crossing vertices.
    verts: Vec<DVec3>,
    /// Crossing vertices by (welded edge ends, plane).
    crossings: FxHashMap<(u32, u32, u32), u32>,
    /// Routed faces per part.
    parts: Vec<Vec<Item>>,
    store_corners: Vec<WCorner>,
    store_loops: Vec<(u32, u32)>,
    pieces: Vec<PieceRec>,
    /// Reused buffers.
    scratch: Scratch,
}

#[derive(Default)]
struct Scratch {
    xs: Vec<Crossing>,
    order: Vec<u32>,
    partner: Vec<u32>,
    at_edge: Vec<u32>,
    visited: Vec<bool>,
    traced: Vec<WCorner>,
    online: Vec<(f64, WCorner)>,
    /// Per vertex id: position in the loop being split, or NONE.
    slot: Vec<u32>,
}

impl<'m> Cutter<'m> {
    fn new(mesh: &'m Mesh, n: DVec3, planes: Vec<f64>) -> Cutter<'m> {
        let tol = mesh_tolerance(mesh).max(
            1e-9 * planes
                .iter()
                .filter(|p| p.is_finite())
                .fold(0.0f64, |m, p| m.max(p.abs())),
        );
        let weld = weld_points(&mesh.positions, tol);
        let verts: Vec<DVec3> = weld
            .representative
            .iter()
            .map(|&i| mesh.positions[i as usize])
            .collect();
        let axis = [DVec3::X, DVec3::Y, DVec3::Z].iter().position(|&a| a == n);
        let nparts = planes.len() + 1;
        Cutter {
            mesh,
            n,
            axis,
            planes,
            tol,
            vid: weld.id,
            verts,
            crossings: fx_map(0),
            parts: vec![Vec::new(); nparts],
            store_corners: Vec::new(),
            store_loops: Vec::new(),
            pieces: Vec::new(),
            scratch: Scratch::default(),
        }
    }

    #[inline]
    fn height(&self, v: u32) -> f64 {
        let p = self.verts[v as usize];
        match self.axis {
            Some(a) => p[a],
            None => self.n.dot(p),
        }
    }

    #[inline]
    fn dist(&self, v: u32, k: usize) -> f64 {
        self.height(v) - self.planes[k]
    }

    fn original_vertex(&self, corner: u32) -> u32 {
        self.vid[self.mesh.corners[corner as usize] as usize]
    }

    fn run(&mut self) {
        let mesh = self.mesh;
        let mut poly = Poly::default();
        for face in 0..mesh.faces.len() {
            // Height range of the whole face.
            let mut lo = f64::INFINITY;
            let mut hi = f64::NEG_INFINITY;
            for &l in mesh.face_loops(face) {
                for c in mesh.loop_corners(l) {
                    let h = self.height(self.original_vertex(c as u32));
                    lo = lo.min(h);
                    hi = hi.max(h);
                }
            }
            if lo.partial_cmp(&hi).is_none_or(|o| o.is_gt()) {
                // No corners (or non-finite positions): keep it in part 0.
                self.parts[0].push(Item::Whole(face as u32));
                continue;
            }
            // Skip the planes the face lies strictly above.
            let tol = self.tol;
            let mut k = self.planes.partition_point(|&c| lo - c > tol);
            let degenerate = mesh.outer_loop(face).len < 3;
            loop {
                if k == self.planes.len() {
                    self.parts[k].push(Item::Whole(face as u32));
                    break;
                }
                let c = self.planes[k];
                let has_neg = lo - c < -tol;
                let has_pos = hi - c > tol;
                match (has_neg, has_pos) {
                    (true, false) => {
                        self.parts[k].push(Item::Whole(face as u32));
                        break;
                    }
                    (false, true) => k += 1,
                    (false, false) => {
                        // In the plane: below if the normal points up
                        // (it closes the part below), else above. Edge and
                        // vertex shapes have no normal and stay below.
                        let up = degenerate || face_normal(mesh, face).dot(self.n) > 0.0;
                        if up {
                            self.parts[k].push(Item::Whole(face as u32));
                            break;
                        }
                        k += 1;
                    }
                    (true, true) => {
                        self.load_face(face, &mut poly);
                        let normal = face_normal(mesh, face);
                        self.route(face as u32, normal, &poly, k);
                        break;
                    }
                }
            }
        }
    }

    /// The face as a polygon of corners that remember their original edge.
    fn load_face(&self, face: usize, poly: &mut Poly) {
        poly.clear();
        let mesh = self.mesh;
        for &l in mesh.face_loops(face) {
            let start = poly.corners.len() as u32;
            let r = mesh.loop_corners(l);
            for c in r.clone() {
                let next = if c + 1 == r.end { r.start } else { c + 1 };
                poly.corners.push(WCorner {
                    v: self.original_vertex(c as u32),
                    a: c as u32,
                    b: next as u32,
                    t: 0.0,
                });
            }
            poly.loops.push((start, l.len));
        }
    }

    /// Routes a polygon (a face or a piece of it) known to reach below plane
    /// `k` or further: splits it at planes `k..` and stores the pieces.
    fn route(&mut self, face: u32, normal: DVec3, poly: &Poly, mut k: usize) {
        loop {
            if k == self.planes.len() {
                self.store(face, poly, k);
                return;
            }
            match self.classify(poly, k) {
                Side::Below => {
                    self.store(face, poly, k);
                    return;
                }
                Side::Above => k += 1,
                Side::On => {
                    if poly.corners.len() < 3 || normal.dot(self.n) > 0.0 {
                        self.store(face, poly, k);
                        return;
                    }
                    k += 1;
                }
                Side::Both => {
                    let (below, above) = if poly.loops[0].1 < 3 {
                        self.split_segment(poly, k)
                    } else {
                        self.split_polygon(poly, normal, k)
                    };
                    for p in &below {
                        self.store(face, p, k);
                    }
                    for p in &above {
                        self.route(face, normal, p, k + 1);
                    }
                    return;
                }
            }
        }
    }

    fn classify(&self, poly: &Poly, k: usize) -> Side {
        let mut neg = false;
        let mut pos = false;
        for c in &poly.corners {
            let s = self.dist(c.v, k);
            neg |= s < -self.tol;
            pos |= s > self.tol;
        }
        match (neg, pos) {
            (true, true) => Side::Both,
            (true, false) => Side::Below,
            (false, true) => Side::Above,
            (false, false) => Side::On,
        }
    }

    fn store(&mut self, face: u32, poly: &Poly, part: usize) {
        let first = self.store_loops.len() as u32;
        for k in 0..poly.loops.len() {
            let l = poly.loop_slice(k);
            self.store_loops
                .push((self.store_corners.len() as u32, l.len() as u32));
            self.store_corners.extend_from_slice(l);
        }
        self.pieces.push(PieceRec {
            face,
            first,
            count: poly.loops.len() as u32,
        });
        self.parts[part].push(Item::Piece(self.pieces.len() as u32 - 1));
    }

    /// The corner where plane `k` crosses the edge from corner `ci` to `cj`
    /// (strictly on opposite sides), shared by every face using that edge.
    fn crossing_corner(&mut self, ci: WCorner, cj: WCorner, k: usize) -> WCorner {
        // The original edge the sub-edge ci→cj lies on.
        let on_original_edge = ci.a != CAP && (cj.a == ci.a || (cj.a == ci.b && cj.t == 0.0));
        let (va, vb) = if on_original_edge {
            (self.original_vertex(ci.a), self.original_vertex(ci.b))
        } else {
            (ci.v, cj.v)
        };
        let (sa, sb) = (self.dist(va, k), self.dist(vb, k));
        let t_face = sa / (sa - sb);
        let key = (va.min(vb), va.max(vb), k as u32);
        let v = match self.crossings.get(&key) {
            Some(&v) => v,
            None => {
                // Compute from the lower id to the higher so that the point
                // does not depend on which face asks first.
                let (p, q, sp, sq) = if va < vb {
                    (va, vb, sa, sb)
                } else {
                    (vb, va, sb, sa)
                };
                let t = sp / (sp - sq);
                let (pp, pq) = (self.verts[p as usize], self.verts[q as usize]);
                let mut x = pp + (pq - pp) * t;
                if let Some(a) = self.axis {
                    x[a] = self.planes[k];
                }
                self.verts.push(x);
                let v = self.verts.len() as u32 - 1;
                self.crossings.insert(key, v);
                v
            }
        };
        if on_original_edge {
            WCorner {
                v,
                a: ci.a,
                b: ci.b,
                t: t_face,
            }
        } else {
            // Not on an original edge (cannot happen with parallel planes):
            // take the attributes of the nearer end.
            let src = if t_face < 0.5 { ci } else { cj };
            WCorner { v, ..src }
        }
    }

    /// Splits an edge shape (a loop of two corners) at plane `k`.
    fn split_segment(&mut self, poly: &Poly, k: usize) -> (Vec<Poly>, Vec<Poly>) {
        let (c0, c1) = (poly.corners[0], poly.corners[1]);
        let x = self.crossing_corner(c0, c1, k);
        let mut lower = Poly::default();
        let mut upper = Poly::default();
        if self.dist(c0.v, k) < 0.0 {
            lower.push_loop(&[c0, x]);
            upper.push_loop(&[x, c1]);
        } else {
            upper.push_loop(&[c0, x]);
            lower.push_loop(&[x, c1]);
        }
        (vec![lower], vec![upper])
    }

    /// Splits a polygon with vertices strictly on both sides of plane `k`
    /// into pieces below and above (see the module docs).
    fn split_polygon(&mut self, poly: &Poly, normal: DVec3, k: usize) -> (Vec<Poly>, Vec<Poly>) {
        let tol = self.tol;
        let mut sc = std::mem::take(&mut self.scratch);
        sc.xs.clear();
        sc.at_edge.clear();
        sc.at_edge.resize(poly.corners.len(), NONE);
        // Direction of the cut line along which the part below keeps itself
        // on the left: d = N × n.
        let d = normal.cross(self.n);
        for li in 0..poly.loops.len() {
            let (start, len) = poly.loops[li];
            for e in 0..len {
                let i = (start + e) as usize;
                let j = (start + (e + 1) % len) as usize;
                let (ci, cj) = (poly.corners[i], poly.corners[j]);
                let (si, sj) = (self.dist(ci.v, k), self.dist(cj.v, k));
                let (ai, aj) = (si > tol, sj > tol);
                if ai == aj {
                    continue;
                }
                let corner = if !ai && si >= -tol {
                    ci
                } else if !aj && sj >= -tol {
                    cj
                } else {
                    self.crossing_corner(ci, cj, k)
                };
                let (lo, hi) = if ai { (cj, ci) } else { (ci, cj) };
                let (slo, shi) = if ai { (sj, si) } else { (si, sj) };
                let dl = self.verts[hi.v as usize] - self.verts[lo.v as usize];
                sc.at_edge[i] = sc.xs.len() as u32;
                sc.xs.push(Crossing {
                    corner,
                    lp: li as u32,
                    edge: e,
                    lambda: self.verts[corner.v as usize].dot(d),
                    tie: dl.dot(d) / (shi - slo),
                    up: aj,
                });
            }
        }
        let m = sc.xs.len();
        sc.order.clear();
        sc.order.extend(0..m as u32);
        {
            let xs = &sc.xs;
            sc.order.sort_by(|&a, &b| {
                let (a, b) = (&xs[a as usize], &xs[b as usize]);
                a.lambda.total_cmp(&b.lambda).then(a.tie.total_cmp(&b.tie))
            });
        }
        sc.partner.clear();
        sc.partner.resize(m, NONE);
        let mut valid = m >= 2 && m.is_multiple_of(2);
        if valid {
            for p in sc.order.chunks_exact(2) {
                let (a, b) = (p[0] as usize, p[1] as usize);
                if !sc.xs[a].up || sc.xs[b].up {
                    valid = false;
                    break;
                }
                sc.partner[a] = b as u32;
                sc.partner[b] = a as u32;
            }
        }
        if !valid {
            // Inconsistent input (self-intersecting or badly non-planar
            // polygon): keep the face whole on the side of its centroid
            // rather than produce garbage.
            self.scratch = sc;
            let c = poly.corners.iter().map(|c| self.dist(c.v, k)).sum::<f64>()
                / poly.corners.len() as f64;
            return if c <= 0.0 {
                (vec![poly.clone()], vec![])
            } else {
                (vec![], vec![poly.clone()])
            };
        }

        let (u, v) = plane_basis(if normal == DVec3::ZERO {
            self.n
        } else {
            normal
        });
        let to2d = |p: DVec3| DVec2::new(p.dot(u), p.dot(v));
        // The face's vertices on the cut line, by position along it. A jump
        // along the line passes through those lying between its ends: this
        // keeps edges of the line shared between pieces and caps (no
        // T-junctions) and exposes where a piece touches the line from the
        // other side, where it is then split (see `split_pinches`).
        sc.online.clear();
        for c in &poly.corners {
            if self.dist(c.v, k).abs() <= tol {
                sc.online.push((self.verts[c.v as usize].dot(d), *c));
            }
        }
        sc.online
            .sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.v.cmp(&b.1.v)));
        sc.online.dedup_by_key(|x| x.1.v);
        let mut result: [Vec<Poly>; 2] = [Vec::new(), Vec::new()];
        let mut extra_holes: [Vec<Vec<WCorner>>; 2] = [Vec::new(), Vec::new()];
        for side in 0..2 {
            // side 0: below (entered at crossings going down), 1: above.
            let entering_up = side == 1;
            sc.visited.clear();
            sc.visited.resize(m, false);
            for s0 in 0..m {
                if sc.xs[s0].up != entering_up || sc.visited[s0] {
                    continue;
                }
                sc.traced.clear();
                let mut cur = s0;
                let mut guard = poly.corners.len() + 2 * m + 4;
                loop {
                    sc.visited[cur] = true;
                    let x = sc.xs[cur];
                    sc.traced.push(x.corner);
                    // Walk the loop to its next crossing.
                    let (start, len) = poly.loops[x.lp as usize];
                    let mut e = (x.edge + 1) % len;
                    let exit = loop {
                        sc.traced.push(poly.corners[(start + e) as usize]);
                        let c = sc.at_edge[(start + e) as usize];
                        if c != NONE {
                            break c as usize;
                        }
                        e = (e + 1) % len;
                    };
                    let ex = sc.xs[exit];
                    sc.traced.push(ex.corner);
                    cur = sc.partner[exit] as usize;
                    // Along the line to the partner, through on-line vertices.
                    let en = sc.xs[cur];
                    let (l0, l1) = (ex.lambda.min(en.lambda), ex.lambda.max(en.lambda));
                    let a = sc.online.partition_point(|o| o.0 <= l0);
                    let b = sc.online.partition_point(|o| o.0 < l1);
                    if a < b {
                        let skip = |c: &WCorner| c.v == ex.corner.v || c.v == en.corner.v;
                        if ex.lambda <= en.lambda {
                            for o in &sc.online[a..b] {
                                if !skip(&o.1) {
                                    sc.traced.push(o.1);
                                }
                            }
                        } else {
                            for o in sc.online[a..b].iter().rev() {
                                if !skip(&o.1) {
                                    sc.traced.push(o.1);
                                }
                            }
                        }
                    }
                    guard = guard.saturating_sub(1);
                    if cur == s0 || guard == 0 {
                        break;
                    }
                }
                if guard == 0 {
                    continue;
                }
                let traced = std::mem::take(&mut sc.traced);
                for l in self.split_pinches(&traced, k, &mut sc.slot) {
                    let pts: Vec<DVec2> =
                        l.iter().map(|c| to2d(self.verts[c.v as usize])).collect();
                    if signed_area(&pts) >= 0.0 {
                        let mut p = Poly::default();
                        p.push_loop(&l);
                        result[side].push(p);
                    } else {
                        extra_holes[side].push(l);
                    }
                }
                sc.traced = traced;
            }
        }
        // Loops without crossings lie on one side: holes of the piece that
        // contains them (or, for a malformed face, pieces of their own).
        let mut holes: [Vec<Vec<WCorner>>; 2] = extra_holes;
        for li in 0..poly.loops.len() {
            let l = poly.loop_slice(li);
            let (start, len) = poly.loops[li];
            if (start..start + len).any(|i| sc.at_edge[i as usize] != NONE) {
                continue;
            }
            let side = usize::from(l.iter().any(|c| self.dist(c.v, k) > tol));
            let Some(cl) = self.clean_loop(l, k) else {
                continue;
            };
            if li == 0 {
                let mut p = Poly::default();
                p.push_loop(&cl);
                result[side].push(p);
            } else {
                holes[side].push(cl);
            }
        }
        for side in 0..2 {
            let out = &mut result[side];
            for cl in std::mem::take(&mut holes[side]) {
                if out.is_empty() {
                    continue; // a hole without a piece around it: nothing to cut out of
                }
                let probe = cl
                    .iter()
                    .find(|c| self.dist(c.v, k).abs() > tol)
                    .map(|c| to2d(self.verts[c.v as usize]));
                let target = match probe {
                    Some(q) if out.len() > 1 => out
                        .iter()
                        .position(|p| {
                            let pts: Vec<DVec2> = p
                                .loop_slice(0)
                                .iter()
                                .map(|c| to2d(self.verts[c.v as usize]))
                                .collect();
                            point_in_polygon(q, &pts)
                        })
                        .unwrap_or(0),
                    _ => 0,
                };
                out[target].push_loop(&cl);
            }
        }
        self.scratch = sc;
        let [below, above] = result;
        (below, above)
    }

    /// Removes repeated consecutive vertices; `None` if fewer than three
    /// remain or all lie on plane `k` (a piece without area).
    fn clean_loop(&self, l: &[WCorner], k: usize) -> Option<Vec<WCorner>> {
        let mut out: Vec<WCorner> = Vec::with_capacity(l.len());
        for &c in l {
            if out.last().is_some_and(|p| p.v == c.v) {
                continue;
            }
            out.push(c);
        }
        while out.len() > 1 && out[0].v == out[out.len() - 1].v {
            out.pop();
        }
        if out.len() < 3 || out.iter().all(|c| self.dist(c.v, k).abs() <= self.tol) {
            return None;
        }
        Some(out)
    }

    /// Splits a traced loop where it visits a vertex twice (a piece touching
    /// itself on the cut line, or a bridge along an edge lying in the line)
    /// into simple loops, dropping those without area.
    fn split_pinches(&self, l: &[WCorner], k: usize, slot: &mut Vec<u32>) -> Vec<Vec<WCorner>> {
        let mut out = Vec::new();
        let Some(l) = self.clean_loop(l, k) else {
            return out;
        };
        if slot.len() < self.verts.len() {
            slot.resize(self.verts.len(), NONE);
        }
        let mut stack: Vec<WCorner> = Vec::with_capacity(l.len());
        for &c in &l {
            let p = slot[c.v as usize];
            if p != NONE {
                // Close the sub-loop from the first visit up to here.
                let sub: Vec<WCorner> = stack.drain(p as usize + 1..).collect();
                for s in &sub {
                    slot[s.v as usize] = NONE;
                }
                let mut lp = Vec::with_capacity(sub.len() + 1);
                lp.push(stack[p as usize]);
                lp.extend(sub);
                if let Some(lp) = self.clean_loop(&lp, k) {
                    out.push(lp);
                }
                continue;
            }
            slot[c.v as usize] = stack.len() as u32;
            stack.push(c);
        }
        for s in &stack {
            slot[s.v as usize] = NONE;
        }
        if let Some(lp) = self.clean_loop(&stack, k) {
            out.push(lp);
        }
        out
    }

    /// Loops of the faces of `part`, for cap computation.
    fn for_each_loop(&self, part: usize, mut f: impl FnMut(u32, &mut dyn Iterator<Item = u32>)) {
        let mesh = self.mesh;
        for item in &self.parts[part] {
            match *item {
                Item::Whole(face) => {
                    if mesh.outer_loop(face as usize).len < 3 {
                        continue;
                    }
                    for &l in mesh.face_loops(face as usize) {
                        let mut it = mesh.loop_corners(l).map(|c| self.original_vertex(c as u32));
                        f(face, &mut it);
                    }
                }
                Item::Piece(p) => {
                    let rec = self.pieces[p as usize];
                    let (_, outer_len) = self.store_loops[rec.first as usize];
                    if outer_len < 3 {
                        continue;
                    }
                    for li in rec.first..rec.first + rec.count {
                        let (s, n) = self.store_loops[li as usize];
                        let mut it = self.store_corners[s as usize..(s + n) as usize]
                            .iter()
                            .map(|c| c.v);
                        f(rec.face, &mut it);
                    }
                }
            }
        }
    }

    /// True if every welded edge of the input is used as often in one
    /// direction as in the other (so cut parts can be closed with caps).
    fn input_is_closed(&self) -> bool {
        let mesh = self.mesh;
        let mut balance: FxHashMap<(u32, u32), i32> = fx_map(mesh.corners.len());
        let mut any = false;
        for face in 0..mesh.faces.len() {
            if mesh.outer_loop(face).len < 3 {
                continue;
            }
            any = true;
            for &l in mesh.face_loops(face) {
                let r = mesh.loop_corners(l);
                for c in r.clone() {
                    let n = if c + 1 == r.end { r.start } else { c + 1 };
                    let (a, b) = (
                        self.original_vertex(c as u32),
                        self.original_vertex(n as u32),
                    );
                    if a != b {
                        let d = if a < b { 1 } else { -1 };
                        *balance.entry((a.min(b), a.max(b))).or_insert(0) += d;
                    }
                }
            }
        }
        any && balance.values().all(|&b| b == 0)
    }

    /// Cap faces of `part` in plane `k`, facing `outward` (`+n` for the
    /// plane above the part, `-n` below). Each cap is a list of loops (outer
    /// first) of vertex ids, with the face whose material it takes.
    fn caps(&self, part: usize, k: usize, outward: DVec3) -> Vec<(u32, Vec<Vec<u32>>)> {
        let tol = self.tol;
        let on = |v: u32| self.dist(v, k).abs() <= tol;
        // Net count of directed on-plane edges per undirected edge.
        let mut net: FxHashMap<(u32, u32), (i32, u32)> = fx_map(0);
        let mut order: Vec<(u32, u32)> = Vec::new();
        self.for_each_loop(part, &mut |face, it: &mut dyn Iterator<Item = u32>| {
            let vs: Vec<u32> = it.collect();
            let n = vs.len();
            for i in 0..n {
                let (a, b) = (vs[i], vs[(i + 1) % n]);
                if a == b || !on(a) || !on(b) {
                    continue;
                }
                let key = (a.min(b), a.max(b));
                let e = net.entry(key).or_insert_with(|| {
                    order.push(key);
                    (0, face)
                });
                e.0 += if a < b { 1 } else { -1 };
            }
        });
        // Unmatched edges, reversed: the caps' boundary edges.
        let mut edges: Vec<(u32, u32, u32)> = Vec::new();
        for key in &order {
            let (count, face) = net[key];
            let (a, b) = *key;
            for _ in 0..count.unsigned_abs() {
                if count > 0 {
                    edges.push((b, a, face));
                } else {
                    edges.push((a, b, face));
                }
            }
        }
        if edges.is_empty() {
            return Vec::new();
        }
        let (u, v) = plane_basis(outward);
        let p2 = |i: u32| {
            let p = self.verts[i as usize];
            DVec2::new(p.dot(u), p.dot(v))
        };
        // Out-edges per start vertex.
        let mut by_start: Vec<u32> = (0..edges.len() as u32).collect();
        by_start.sort_by_key(|&e| edges[e as usize].0);
        let first_out = |vtx: u32| by_start.partition_point(|&e| edges[e as usize].0 < vtx);
        let mut used = vec![false; edges.len()];
        let mut loops: Vec<(Vec<u32>, u32, f64)> = Vec::new(); // (vertices, face, signed area)
        for e0 in 0..edges.len() {
            if used[e0] {
                continue;
            }
            used[e0] = true;
            let mut verts = vec![edges[e0].0];
            let mut cur = e0;
            let mut closed = false;
            for _ in 0..=edges.len() {
                let (a, w, _) = edges[cur];
                let back = p2(a) - p2(w);
                let mut best: Option<(usize, f64)> = None;
                let mut idx = first_out(w);
                while idx < by_start.len() && edges[by_start[idx] as usize].0 == w {
                    let e = by_start[idx] as usize;
                    idx += 1;
                    if used[e] && e != e0 {
                        continue;
                    }
                    let dir = p2(edges[e].1) - p2(w);
                    let mut ang = back.perp_dot(dir).atan2(back.dot(dir));
                    if ang <= 0.0 {
                        ang += std::f64::consts::TAU;
                    }
                    if best.is_none_or(|(_, b)| ang > b) {
                        best = Some((e, ang));
                    }
                }
                let Some((e, _)) = best else {
                    break; // open chain: the section is not closed here
                };
                if e == e0 {
                    closed = true;
                    break;
                }
                used[e] = true;
                verts.push(edges[e].0);
                cur = e;
            }
            if !closed || verts.len() < 3 {
                continue;
            }
            let pts: Vec<DVec2> = verts.iter().map(|&i| p2(i)).collect();
            let area = signed_area(&pts);
            if area.abs() <= tol * tol {
                continue;
            }
            loops.push((verts, edges[e0].2, area));
        }
        // Outer loops (counter-clockwise) become caps; each hole goes to the
        // smallest outer loop containing it.
        let mut caps: Vec<CapCandidate> = Vec::new();
        for (verts, face, area) in &loops {
            if *area > 0.0 {
                let pts = verts.iter().map(|&i| p2(i)).collect();
                caps.push(CapCandidate {
                    face: *face,
                    loops: vec![verts.clone()],
                    area: *area,
                    outline: pts,
                });
            }
        }
        for (verts, _, area) in &loops {
            if *area > 0.0 {
                continue;
            }
            let probe = hole_probe(verts, &p2, &caps);
            let mut best: Option<usize> = None;
            for (ci, cap) in caps.iter().enumerate() {
                if cap.area > -area
                    && point_in_polygon(probe, &cap.outline)
                    && best.is_none_or(|b| cap.area < caps[b].area)
                {
                    best = Some(ci);
                }
            }
            if let Some(b) = best {
                caps[b].loops.push(verts.clone());
            }
        }
        caps.into_iter().map(|c| (c.face, c.loops)).collect()
    }

    /// Builds the output meshes.
    fn build(&self) -> Vec<Mesh> {
        let mesh = self.mesh;
        let closed = self.planes.is_empty() || self.input_is_closed();
        let nparts = self.parts.len();
        let mut out = Vec::with_capacity(nparts);
        let mut remap = vec![NONE; self.verts.len()];
        for part in 0..nparts {
            let mut m = empty_like(mesh);
            let mut sources: Vec<WCorner> = Vec::new();
            let mut cap_normals: Vec<DVec3> = Vec::new();
            let mut touched: Vec<u32> = Vec::new();
            let mut map = |v: u32, m: &mut Mesh, touched: &mut Vec<u32>| {
                if remap[v as usize] == NONE {
                    remap[v as usize] = m.positions.len() as u32;
                    m.positions.push(self.verts[v as usize]);
                    touched.push(v);
                }
                remap[v as usize]
            };
            let push_face = |m: &mut Mesh, mat: u32, group: u32, nloops: u32| {
                m.faces.push(Face {
                    first_loop: m.loops.len() as u32 - nloops,
                    loop_count: nloops,
                    material: mat,
                    group,
                });
            };
            for item in &self.parts[part] {
                match *item {
                    Item::Whole(face) => {
                        let f = mesh.faces[face as usize];
                        for &l in mesh.face_loops(face as usize) {
                            let start = m.corners.len() as u32;
                            for c in mesh.loop_corners(l) {
                                let p = map(self.original_vertex(c as u32), &mut m, &mut touched);
                                m.corners.push(p);
                                sources.push(WCorner {
                                    v: 0,
                                    a: c as u32,
                                    b: c as u32,
                                    t: 0.0,
                                });
                            }
                            m.loops.push(Loop { start, len: l.len });
                        }
                        push_face(&mut m, f.material, f.group, f.loop_count);
                    }
                    Item::Piece(p) => {
                        let rec = self.pieces[p as usize];
                        let f = mesh.faces[rec.face as usize];
                        for li in rec.first..rec.first + rec.count {
                            let (s, n) = self.store_loops[li as usize];
                            let start = m.corners.len() as u32;
                            for c in &self.store_corners[s as usize..(s + n) as usize] {
                                let p = map(c.v, &mut m, &mut touched);
                                m.corners.push(p);
                                sources.push(*c);
                            }
                            m.loops.push(Loop { start, len: n });
                        }
                        push_face(&mut m, f.material, f.group, rec.count);
                    }
                }
            }
            if closed && !self.parts[part].is_empty() {
                let mut all_caps = Vec::new();
                if part > 0 {
                    all_caps.push((self.caps(part, part - 1, -self.n), -self.n));
                }
                if part < self.planes.len() {
                    all_caps.push((self.caps(part, part, self.n), self.n));
                }
                for (caps, outward) in all_caps {
                    for (face, loops) in caps {
                        let f = mesh.faces[face as usize];
                        for l in &loops {
                            let start = m.corners.len() as u32;
                            for &v in l {
                                let p = map(v, &mut m, &mut touched);
                                m.corners.push(p);
                                sources.push(WCorner {
                                    v: cap_normals.len() as u32,
                                    a: CAP,
                                    b: CAP,
                                    t: 0.0,
                                });
                            }
                            m.loops.push(Loop {
                                start,
                                len: l.len() as u32,
                            });
                        }
                        cap_normals.push(outward);
                        push_face(&mut m, f.material, f.group, loops.len() as u32);
                    }
                }
            }
            for v in touched {
                remap[v as usize] = NONE;
            }
            // Per-corner attributes.
            for (set, src) in mesh.uvs.iter().enumerate() {
                if let Some(uv) = src {
                    let get = |i: u32| uv.get(i as usize).copied().unwrap_or(DVec2::ZERO);
                    m.uvs[set] = Some(
                        sources
                            .iter()
                            .map(|s| {
                                if s.a == CAP {
                                    DVec2::ZERO
                                } else if s.t == 0.0 {
                                    get(s.a)
                                } else {
                                    get(s.a).lerp(get(s.b), s.t)
                                }
                            })
                            .collect(),
                    );
                }
            }
            if let Some(nrm) = &mesh.normals {
                let get = |i: u32| nrm.get(i as usize).copied().unwrap_or(DVec3::ZERO);
                m.normals = Some(
                    sources
                        .iter()
                        .map(|s| {
                            if s.a == CAP {
                                cap_normals[s.v as usize]
                            } else if s.t == 0.0 {
                                get(s.a)
                            } else {
                                get(s.a).lerp(get(s.b), s.t).normalize_or_zero()
                            }
                        })
                        .collect(),
                );
            }
            out.push(m);
        }
        out
    }
}

/// A cap being assembled: an outer loop (then holes) of vertex ids.
struct CapCandidate {
    /// The face whose material and group the cap takes.
    face: u32,
    loops: Vec<Vec<u32>>,
    area: f64,
    /// The outer loop in plane coordinates.
    outline: Vec<DVec2>,
}

fn signed_area(pts: &[DVec2]) -> f64 {
    let n = pts.len();
    let mut a = 0.0;
    for i in 0..n {
        a += pts[i].perp_dot(pts[(i + 1) % n]);
    }
    0.5 * a
}

/// Even-odd point in polygon test.
pub(crate) fn point_in_polygon(q: DVec2, pts: &[DVec2]) -> bool {
    let n = pts.len();
    let mut inside = false;
    let mut j = n.wrapping_sub(1);
    for i in 0..n {
        let (a, b) = (pts[i], pts[j]);
        if (a.y > q.y) != (b.y > q.y) {
            let x = a.x + (q.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if q.x < x {
                inside = !inside;
            }
        }
        j = i;
    }
    inside
}

/// A point of a hole loop to test containment with: the midpoint of its
/// first edge that is not on the boundary of a candidate outer loop
/// (holes may touch their outer loop at vertices).
fn hole_probe(verts: &[u32], p2: &impl Fn(u32) -> DVec2, caps: &[CapCandidate]) -> DVec2 {
    let n = verts.len();
    for i in 0..n {
        let (a, b) = (verts[i], verts[(i + 1) % n]);
        let shared = caps
            .iter()
            .any(|c| c.loops[0].contains(&a) && c.loops[0].contains(&b));
        if !shared {
            return (p2(a) + p2(b)) * 0.5;
        }
    }
    p2(verts[0])
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::measure::{face_area, mesh_area, volume};
    use crate::topology::Topology;
    use proptest::prelude::*;

    fn v(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    /// A prism over the polygon `outer` (x, z pairs, counter-clockwise seen
    /// from above) with clockwise `holes`, from y = 0 to y = h, outward
    /// normals, positions shared. Every corner has UV (1, 1) so that cap
    /// corners (UV 0, 0) can be told apart.
    pub(crate) fn prism(outer: &[(f64, f64)], holes: &[Vec<(f64, f64)>], h: f64) -> Mesh {
        let mut m = Mesh::new();
        let mut rings: Vec<Vec<u32>> = Vec::new();
        for ring in std::iter::once(outer).chain(holes.iter().map(|r| r.as_slice())) {
            let base = m.positions.len() as u32;
            for &(x, z) in ring {
                m.positions.push(v(x, 0.0, z));
            }
            rings.push((base..base + ring.len() as u32).collect());
        }
        let nb = m.positions.len() as u32;
        for i in 0..nb as usize {
            let p = m.positions[i];
            m.positions.push(p + DVec3::Y * h);
        }
        m.uvs[0] = Some(Vec::new());
        // bottom: reversed rings
        let bottom: Vec<Vec<u32>> = rings
            .iter()
            .map(|r| r.iter().rev().copied().collect())
            .collect();
        let refs: Vec<&[u32]> = bottom.iter().map(|r| r.as_slice()).collect();
        m.add_face(&refs, 0);
        let top: Vec<Vec<u32>> = rings
            .iter()
            .map(|r| r.iter().map(|i| i + nb).collect())
            .collect();
        let refs: Vec<&[u32]> = top.iter().map(|r| r.as_slice()).collect();
        m.add_face(&refs, 0);
        for r in &rings {
            for k in 0..r.len() {
                let (a, b) = (r[k], r[(k + 1) % r.len()]);
                m.add_face(&[&[a, b, b + nb, a + nb]], 0);
            }
        }
        let n = m.corners.len();
        m.uvs[0] = Some(vec![DVec2::ONE; n]);
        m
    }

    fn unit_box() -> Mesh {
        prism(&[(0., 0.), (1., 0.), (1., -1.), (0., -1.)], &[], 1.0)
    }

    fn is_cap(m: &Mesh, f: usize) -> bool {
        let uv = m.uvs[0].as_ref().unwrap();
        m.face_loops(f)
            .iter()
            .all(|&l| m.loop_corners(l).all(|c| uv[c] == DVec2::ZERO))
    }

    fn non_cap_area(m: &Mesh) -> f64 {
        (0..m.faces.len())
            .filter(|&f| !is_cap(m, f))
            .map(|f| face_area(m, f))
            .sum()
    }

    fn closed(m: &Mesh) -> bool {
        Topology::new(m).is_closed(m)
    }

    fn no_unused_positions(m: &Mesh) -> bool {
        let mut used = vec![false; m.positions.len()];
        for &c in &m.corners {
            used[c as usize] = true;
        }
        used.iter().all(|&u| u)
    }

    #[test]
    fn box_cut_in_the_middle() {
        let b = unit_box();
        let (lo, hi) = cut_by_plane(&b, DVec3::Y, 0.25);
        assert!((volume(&lo) - 0.25).abs() < 1e-12);
        assert!((volume(&hi) - 0.75).abs() < 1e-12);
        assert!(closed(&lo) && closed(&hi));
        assert_eq!(lo.faces.len(), 6);
        assert_eq!(hi.faces.len(), 6);
        assert_eq!(lo.positions.len(), 8);
        assert!(no_unused_positions(&lo) && no_unused_positions(&hi));
        // The cap of the lower part faces up and has area 1.
        let cap = lo.faces.len() - 1;
        assert!(is_cap(&lo, cap));
        assert_eq!(face_normal(&lo, cap), DVec3::Y);
        assert_eq!(face_area(&lo, cap), 1.0);
        assert_eq!(face_normal(&hi, hi.faces.len() - 1), -DVec3::Y);
        // Side faces keep their UVs, material and order (bottom first).
        assert!(!is_cap(&lo, 0));
        assert_eq!(face_normal(&lo, 0), -DVec3::Y);
        assert!((mesh_area(&lo) - (1.0 + 1.0 + 4.0 * 0.25)).abs() < 1e-12);
    }

    #[test]
    fn extruded_lot_split_into_floors() {
        // Lot 20 x 30 extruded by 10, split(y) at 3, 6, 9: four closed
        // floors, the last 1 m high.
        let lot = Mesh::polygon(&[
            v(0., 0., 0.),
            v(20., 0., 0.),
            v(20., 0., -30.),
            v(0., 0., -30.),
        ]);
        let mass = crate::extrude::extrude(&lot, crate::extrude::Extrusion::FaceNormal, 10.0);
        let floors = split_along_axis(&mass, 1, &[3.0, 6.0, 9.0]);
        let vols: Vec<f64> = floors.iter().map(volume).collect();
        assert_eq!(
            vols.iter().map(|v| v.round()).collect::<Vec<_>>(),
            vec![1800.0, 1800.0, 1800.0, 600.0]
        );
        for (i, f) in floors.iter().enumerate() {
            assert!(closed(f), "floor {i}");
            assert_eq!(f.faces.len(), 6);
            assert_eq!(f.positions.len(), 8);
            // Side faces keep their order: the front (+z) comes right after
            // the bottom and top (or caps) of the original mass.
            assert!(f.faces.iter().all(|x| x.loop_count == 1));
        }
        // The ground floor: original bottom, then the 4 sides, then the cap.
        assert_eq!(face_normal(&floors[0], 0), -DVec3::Y);
        assert_eq!(face_normal(&floors[0], 1), DVec3::Z);
        assert_eq!(face_normal(&floors[0], 5), DVec3::Y);
        // The front facade split into 4 tiles along x: open, area kept.
        let facade = Mesh::polygon(&[
            v(0., 0., 0.),
            v(20., 0., 0.),
            v(20., 10., 0.),
            v(0., 10., 0.),
        ]);
        let tiles = split_along_axis(&facade, 0, &[5.0, 10.0, 15.0]);
        assert!(tiles
            .iter()
            .all(|t| mesh_area(t) == 50.0 && t.faces.len() == 1));
    }

    #[test]
    fn cut_at_faces_lying_in_the_plane() {
        let b = unit_box();
        // At the top face: everything below, nothing above, no caps.
        let (lo, hi) = cut_by_plane(&b, DVec3::Y, 1.0);
        assert_eq!(lo.faces.len(), 6);
        assert!(hi.is_empty() && hi.positions.is_empty());
        // At the bottom face: everything above.
        let (lo, hi) = cut_by_plane(&b, DVec3::Y, 0.0);
        assert!(lo.is_empty());
        assert_eq!(hi.faces.len(), 6);
        // Within tolerance of the top: still no sliver.
        let (lo, hi) = cut_by_plane(&b, DVec3::Y, 1.0 - 1e-13);
        assert_eq!(lo.faces.len(), 6);
        assert!(hi.is_empty());
    }

    #[test]
    fn diagonal_cut_through_edges() {
        // The plane x - z = 1 contains the vertical edges at (1, 0) and
        // (0, -1): it cuts the box into two triangular prisms.
        let b = unit_box();
        let (lo, hi) = cut_by_plane(&b, v(1.0, 0.0, -1.0), 1.0);
        assert!((volume(&lo) - 0.5).abs() < 1e-12, "{}", volume(&lo));
        assert!((volume(&hi) - 0.5).abs() < 1e-12);
        assert!(closed(&lo) && closed(&hi));
        assert_eq!(lo.faces.len(), 5);
        assert_eq!(hi.faces.len(), 5);
        assert_eq!(lo.positions.len(), 6);
        let cap = lo.faces.len() - 1;
        assert!((face_area(&lo, cap) - 2f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn hollow_tube_gives_ring_caps() {
        let outer = [(0., 0.), (4., 0.), (4., -4.), (0., -4.)];
        let hole = vec![(1., -1.), (1., -3.), (3., -3.), (3., -1.)];
        let tube = prism(&outer, &[hole], 2.0);
        assert!((volume(&tube) - 24.0).abs() < 1e-12);
        // Horizontal cut: ring caps with one hole each.
        let (lo, hi) = cut_by_plane(&tube, DVec3::Y, 0.5);
        assert!((volume(&lo) - 6.0).abs() < 1e-12);
        assert!((volume(&hi) - 18.0).abs() < 1e-12);
        assert!(closed(&lo) && closed(&hi));
        let cap = lo.faces.len() - 1;
        assert!(is_cap(&lo, cap));
        assert_eq!(lo.faces[cap].loop_count, 2);
        assert_eq!(face_area(&lo, cap), 12.0);
        // Vertical cut through the hole: the bottom and top faces' hole
        // becomes part of the pieces' outlines; caps are two rectangles.
        let parts = split_along_axis(&tube, 0, &[2.0]);
        assert!((volume(&parts[0]) - 12.0).abs() < 1e-12);
        assert!((volume(&parts[1]) - 12.0).abs() < 1e-12);
        assert!(closed(&parts[0]) && closed(&parts[1]));
        let caps: Vec<usize> = (0..parts[0].faces.len())
            .filter(|&f| is_cap(&parts[0], f))
            .collect();
        assert_eq!(caps.len(), 2);
        for f in caps {
            assert_eq!(face_area(&parts[0], f), 2.0);
            assert_eq!(face_normal(&parts[0], f), DVec3::X);
        }
        assert!(parts[0].faces.iter().all(|f| f.loop_count == 1));
    }

    #[test]
    fn concave_u_gives_two_pieces_above() {
        // A U open to the back (-z): arms at x in [0,1] and [2,3].
        let u = [
            (0., 0.),
            (3., 0.),
            (3., -3.),
            (2., -3.),
            (2., -1.),
            (1., -1.),
            (1., -3.),
            (0., -3.),
        ];
        let m = prism(&u, &[], 1.0);
        let total = volume(&m);
        assert!((total - 7.0).abs() < 1e-12);
        let parts = split_along_axis(&m, 2, &[-2.0]);
        // parts[0] is z < -2: the two arm ends.
        assert!((volume(&parts[0]) - 2.0).abs() < 1e-12);
        assert!((volume(&parts[1]) - 5.0).abs() < 1e-12);
        assert!(closed(&parts[0]) && closed(&parts[1]));
        let caps0 = (0..parts[0].faces.len())
            .filter(|&f| is_cap(&parts[0], f))
            .count();
        let caps1 = (0..parts[1].faces.len())
            .filter(|&f| is_cap(&parts[1], f))
            .count();
        assert_eq!((caps0, caps1), (2, 2));
        // The bottom face splits into two pieces in parts[0].
        let bottoms = (0..parts[0].faces.len())
            .filter(|&f| face_normal(&parts[0], f) == -DVec3::Y)
            .count();
        assert_eq!(bottoms, 2);
        // Cut exactly at the notch's end (z = -1): the notch edge lies in
        // the plane.
        let parts = split_along_axis(&m, 2, &[-1.0]);
        assert!((volume(&parts[0]) - 4.0).abs() < 1e-12);
        assert!((volume(&parts[1]) - 3.0).abs() < 1e-12);
        assert!(closed(&parts[0]) && closed(&parts[1]));
    }

    #[test]
    fn flat_lot_split_keeps_area_and_interpolates_uvs() {
        let mut lot = Mesh::polygon(&[
            v(0., 0., 0.),
            v(10., 0., 0.),
            v(10., 0., -5.),
            v(0., 0., -5.),
        ]);
        lot.uvs[0] = Some(vec![
            DVec2::new(0., 0.),
            DVec2::new(1., 0.),
            DVec2::new(1., 1.),
            DVec2::new(0., 1.),
        ]);
        lot.normals = Some(vec![DVec3::Y; 4]);
        let parts = split_along_axis(&lot, 0, &[2.5, 2.5, 7.5, 20.0]);
        assert_eq!(parts.len(), 5);
        let areas: Vec<f64> = parts.iter().map(mesh_area).collect();
        assert_eq!(areas, vec![12.5, 0.0, 25.0, 12.5, 0.0]);
        assert!(parts[1].is_empty() && parts[4].is_empty());
        let p = &parts[2];
        assert_eq!(p.faces.len(), 1);
        assert_eq!(p.positions.len(), 4);
        let uv = p.uvs[0].as_ref().unwrap();
        for (k, &c) in p.corners.iter().enumerate() {
            let x = p.positions[c as usize].x;
            assert!((uv[k].x - x / 10.0).abs() < 1e-15);
        }
        assert_eq!(p.normals.as_ref().unwrap(), &vec![DVec3::Y; 4]);
        // The part keeps the counter-clockwise orientation.
        assert_eq!(face_normal(p, 0), DVec3::Y);
    }

    #[test]
    fn cut_through_a_vertex_of_a_concave_polygon() {
        // A flat "W": the cut line y = 1 touches the middle reflex vertex.
        let w = Mesh::polygon(&[
            v(0., 0., 0.),
            v(4., 0., 0.),
            v(4., 2., 0.),
            v(3., 2., 0.),
            v(2., 1., 0.),
            v(1., 2., 0.),
            v(0., 2., 0.),
        ]);
        let total = mesh_area(&w);
        let (lo, hi) = cut_by_plane(&w, DVec3::Y, 1.0);
        assert_eq!(lo.faces.len(), 1);
        assert_eq!(hi.faces.len(), 2);
        assert!((mesh_area(&lo) - 4.0).abs() < 1e-12);
        assert!((mesh_area(&lo) + mesh_area(&hi) - total).abs() < 1e-12);
        // The lower piece has the touching vertex on its top edge.
        assert_eq!(lo.positions.len(), 5);
    }

    #[test]
    fn edge_shapes_are_split_too() {
        let mut e = Mesh::new();
        e.positions.extend([v(0., 0., 0.), v(4., 0., 0.)]);
        e.add_face(&[&[0, 1]], 0);
        let parts = split_along_axis(&e, 0, &[1.0, 3.0]);
        let lens: Vec<f64> = parts
            .iter()
            .map(|m| {
                m.positions[m.corners[1] as usize].distance(m.positions[m.corners[0] as usize])
            })
            .collect();
        assert_eq!(lens, vec![1.0, 2.0, 1.0]);
    }

    /// A star-shaped simple polygon (concave in general) counter-clockwise
    /// from above in (x, z): radii at increasing angles.
    fn star(radii: &[f64], scale: f64) -> Vec<(f64, f64)> {
        let n = radii.len();
        (0..n)
            .map(|i| {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                // counter-clockwise seen from above = clockwise in (x, -z)...
                (scale * radii[i] * a.cos(), -scale * radii[i] * a.sin())
            })
            .collect()
    }

    fn check_split(m: &Mesh, axis: usize, cuts: &[f64]) {
        let total_v = volume(m);
        let total_a = mesh_area(m);
        assert!(closed(m));
        let parts = split_along_axis(m, axis, cuts);
        assert_eq!(parts.len(), cuts.len() + 1);
        let mut vsum = 0.0;
        let mut asum = 0.0;
        for (i, p) in parts.iter().enumerate() {
            if p.is_empty() {
                continue;
            }
            assert!(closed(p), "part {i} of {cuts:?} along {axis} not closed");
            assert!(no_unused_positions(p));
            let pv = volume(p);
            assert!(pv > -1e-9, "part {i} has negative volume {pv}");
            vsum += pv;
            asum += non_cap_area(p);
        }
        assert!(
            (vsum - total_v).abs() <= 1e-9 * total_v.abs(),
            "volume {vsum} vs {total_v}"
        );
        assert!(
            (asum - total_a).abs() <= 1e-9 * total_a,
            "area {asum} vs {total_a}"
        );
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 200, .. ProptestConfig::default() })]

        #[test]
        fn boxes_split_exactly(
            lo in prop::array::uniform3(-10.0f64..10.0),
            size in prop::array::uniform3(0.1f64..10.0),
            axis in 0usize..3,
            fr in prop::collection::vec(-0.2f64..1.2, 1..5),
            snap in any::<bool>(),
        ) {
            let (x0, y0, z0) = (lo[0], lo[1], lo[2]);
            let (sx, sy, sz) = (size[0], size[1], size[2]);
            let mut b = prism(&[(x0, z0), (x0 + sx, z0), (x0 + sx, z0 - sz), (x0, z0 - sz)], &[], sy);
            b.map_positions(|p| p + DVec3::Y * y0);
            let (base, ext) = match axis { 0 => (x0, sx), 1 => (y0, sy), _ => (z0 - sz, sz) };
            let mut cuts: Vec<f64> = fr.iter().map(|f| {
                // Snap some cuts onto the box faces.
                let f = if snap { (f * 2.0).round() / 2.0 } else { *f };
                base + f * ext
            }).collect();
            cuts.sort_by(f64::total_cmp);
            check_split(&b, axis, &cuts);
        }

        #[test]
        fn prisms_split_exactly(
            radii in prop::collection::vec(0.5f64..2.0, 3..12),
            hole in prop::option::of(3usize..7),
            h in 0.5f64..3.0,
            axis in 0usize..3,
            fr in prop::collection::vec(-0.1f64..1.1, 1..4),
            through_vertex in prop::option::of(0usize..12),
        ) {
            let outer = star(&radii, 1.0);
            let holes: Vec<Vec<(f64, f64)>> = hole
                .map(|n| {
                    // A regular polygon well inside (radii >= 0.5), clockwise.
                    let mut r = star(&vec![0.3; n], 1.0);
                    r.reverse();
                    vec![r]
                })
                .unwrap_or_default();
            let m = prism(&outer, &holes, h);
            let (lo, hi) = match axis { 0 => (-2.0, 2.0), 1 => (0.0, h), _ => (-2.0, 2.0) };
            let mut cuts: Vec<f64> = fr.iter().map(|f| lo + f * (hi - lo)).collect();
            if let Some(k) = through_vertex {
                // A cut exactly through a vertex of the outline.
                let (x, z) = outer[k % outer.len()];
                cuts.push(match axis { 0 => x, 1 => h, _ => z });
            }
            cuts.sort_by(f64::total_cmp);
            check_split(&m, axis, &cuts);
        }

        #[test]
        fn rectilinear_combs_split_exactly(
            heights in prop::collection::vec(1u8..4, 2..8),
            axis in prop::sample::select(vec![0usize, 2]),
            cuts in prop::collection::vec(0u8..17, 1..5),
        ) {
            // A histogram polygon: column i spans x in [i, i+1] and z from 0
            // to -heights[i]. Cuts at multiples of 0.5 hit its edges lying in
            // the cut planes and its reflex corners.
            let n = heights.len();
            let mut outer = vec![(0.0, 0.0), (n as f64, 0.0)];
            for i in (0..n).rev() {
                let h = -(heights[i] as f64);
                outer.push(((i + 1) as f64, h));
                outer.push((i as f64, h));
            }
            outer.dedup();
            let m = prism(&outer, &[], 1.0);
            let mut cs: Vec<f64> = cuts
                .iter()
                .map(|&c| if axis == 0 { c as f64 * 0.5 } else { -(c as f64) * 0.25 })
                .collect();
            cs.sort_by(f64::total_cmp);
            check_split(&m, axis, &cs);
        }

        #[test]
        fn primitives_split_exactly(
            kind in 0usize..3,
            sides in 3usize..12,
            axis in 0usize..3,
            cuts in prop::collection::vec(0u8..=8, 1..4),
        ) {
            // Cuts at multiples of 1/8 of the size hit ring vertices, poles
            // and caps exactly.
            let size = DVec3::new(2.0, 3.0, 4.0);
            let m = match kind {
                0 => crate::primitive::sphere(sides, sides.max(2), size),
                1 => crate::primitive::cylinder(sides, size),
                _ => crate::primitive::cone(sides, size),
            };
            let mut cs: Vec<f64> = cuts.iter().map(|&c| size[axis] * c as f64 / 8.0).collect();
            cs.sort_by(f64::total_cmp);
            let total_a = mesh_area(&m);
            let total_v = volume(&m);
            let parts = split_along_axis(&m, axis, &cs);
            let mut vsum = 0.0;
            let mut asum = 0.0;
            for p in &parts {
                prop_assert!(p.is_empty() || closed(p));
                vsum += volume(p);
                // Primitives carry UVs; caps are the faces whose corners all
                // have UV (0, 0) — primitives have such corners too, so
                // count areas through normals of the faces lying in the cut
                // planes instead: total area = original + 2 * cap areas.
                asum += mesh_area(p);
            }
            prop_assert!((vsum - total_v).abs() <= 1e-9 * total_v);
            prop_assert!(asum >= total_a * (1.0 - 1e-9));
        }

        #[test]
        fn general_planes_preserve_volume(
            radii in prop::collection::vec(0.5f64..2.0, 3..10),
            n in prop::array::uniform3(-1.0f64..1.0),
            off in -1.0f64..1.0,
        ) {
            let nv = DVec3::from(n);
            prop_assume!(nv.length() > 0.1);
            let m = prism(&star(&radii, 1.0), &[], 1.0);
            let (a, b) = cut_by_plane(&m, nv, off);
            let total = volume(&m);
            prop_assert!((volume(&a) + volume(&b) - total).abs() <= 1e-9 * total);
            prop_assert!(a.is_empty() || closed(&a));
            prop_assert!(b.is_empty() || closed(&b));
            prop_assert!((non_cap_area(&a) + non_cap_area(&b) - mesh_area(&m)).abs() <= 1e-9 * mesh_area(&m));
        }
    }
}
