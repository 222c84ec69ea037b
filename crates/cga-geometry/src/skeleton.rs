//! Weighted straight skeletons and wavefront offsets of polygons with holes:
//! the geometry behind CGA's roofs (`roofHip`, `roofGable`), `offset` and the
//! `setback` family.
//!
//! # The wavefront
//!
//! Every edge of the polygon moves inwards, parallel to itself, at the speed
//! of its weight: at time `t` edge `i` lies on the line `n_i · p = c_i + w_i t`
//! (`n_i` its inward unit normal). Seen in (x, y, t) space each edge sweeps a
//! plane; the region an edge sweeps before it is overtaken is its *face*.
//! Lifting a face by `t` gives a roof plane of slope proportional to `1/w_i`:
//! weight 1 is the common slope, a larger weight a gentler slope, and weight 0
//! an edge that never moves, whose face stands vertically above it (a gable
//! end). Faces of one polygon tile it exactly; lifted, they form a roof.
//!
//! # Algorithm
//!
//! An event-driven wavefront simulation in the manner of Felkel & Obdržálek,
//! "Straight Skeleton Implementation" (SCCG 1998), generalised to weights as
//! in Eppstein & Erickson, "Raising roofs, crashing cycles, and playing pool"
//! (1999) and Biedl et al., "Weighted straight skeletons in the plane" (2015).
//! The wavefront is kept as circular lists of vertices; each vertex moves on
//! a straight line between its two edges (found by solving `v·n_a = w_a`,
//! `v·n_b = w_b`) and lives until an event replaces it:
//!
//! - *edge event*: an edge shrinks to zero length; its two vertices merge;
//! - *split event*: a reflex vertex reaches the line of another edge inside
//!   that edge's current segment; the wavefront splits into two (or, when the
//!   edge belongs to another component such as a hole, two components merge);
//! - *fold*: a vertex whose edges became antiparallel and coincident (two
//!   wavefront edges met head on) has no finite velocity; it collapses at
//!   once onto its nearer neighbour, leaving a ridge;
//! - *step*: two adjacent collinear edges of different weights cannot share a
//!   vertex; a zero-weight (vertical) edge is inserted between them, which
//!   becomes a vertical step face of its own ([`Skeleton::step_faces`]);
//! - *weight change*: an edge stops moving at a given time (used by
//!   `setbackToArea` with maximum distances).
//!
//! Events are processed in time order from a binary heap with lazy deletion
//! (an event is dropped when one of its vertices is gone). Simultaneous
//! events need no special case: each event leaves zero-length edges or loops
//! of one or two vertices behind, which the following events (at the same
//! time) collapse, so several vertices meeting at one point end up as one
//! node after [welding](crate::topology::weld_points) the nodes in (x, y, t).
//! Reflex vertices are recognised with the `robust` crate's exact `orient2d`
//! on the input; the face of every edge is assembled at the end by walking
//! the traces of the vertices that bounded it.
//!
//! Written by hand: no maintained Rust crate computes *weighted* skeletons of
//! polygons with holes, with faces per edge and stopping at a time (for
//! offsets), robustly enough for lots and footprints.
//!
//! # Robustness
//!
//! Coordinates are normalised to the unit box; coincidence tolerances are
//! `1e-9` of the polygon's size. Zero-length edges are dropped (their faces
//! are empty), collinear runs keep one face per edge, spikes fold, and the
//! number of processed events is bounded, so degenerate input ends quickly
//! with either a result or a [`SkeletonError`]. Every result is checked: each
//! face must be a closed chain and the face areas (plus the remaining
//! wavefront) must add up to the polygon's area. A failing check retries
//! once on a copy of the input perturbed by 1e-7 of its size (breaking
//! coincidences of events that should be simultaneous but are not in
//! floating point), then reports the error. Events at one instant are
//! bounded by the size of the wavefront, so a cycle of coincident events is
//! caught at once. On random and rectilinear polygons the first attempt
//! succeeds (a test asserts it); the retry is a safety net.
//!
//! # Complexity
//!
//! `O((n + r·m) log n)` time for `n` vertices, `r` reflex vertices and `m`
//! edges, because every reflex vertex tests every edge for a split; the
//! typical footprint of 200 vertices takes well under a millisecond.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use glam::{DVec2, DVec3};

use crate::topology::weld_points;

/// Why a skeleton could not be computed.
#[derive(Clone, Debug, PartialEq)]
pub enum SkeletonError {
    /// No loop with at least three distinct points.
    Empty,
    /// A coordinate or weight is not finite, or a weight is negative, or the
    /// numbers of loops and weight lists differ.
    BadInput,
    /// The simulation exceeded its event budget (pathological input).
    EventLimit,
    /// The wavefront did not collapse (all edges of a component have weight
    /// zero) and no stop time was given.
    NoCollapse,
    /// The face of the given edge (global edge index) did not close, or the
    /// faces did not tile the polygon: numerically inconsistent input.
    Inconsistent(usize),
}

impl std::fmt::Display for SkeletonError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SkeletonError::Empty => write!(f, "polygon has no area"),
            SkeletonError::BadInput => write!(f, "non-finite coordinates or invalid weights"),
            SkeletonError::EventLimit => write!(f, "straight skeleton event limit exceeded"),
            SkeletonError::NoCollapse => write!(f, "wavefront does not collapse"),
            SkeletonError::Inconsistent(e) => {
                write!(f, "straight skeleton inconsistent at edge {e}")
            }
        }
    }
}

impl std::error::Error for SkeletonError {}

/// A change of an edge's weight during the simulation: from `time` on, edge
/// `edge` (global index, see [`Skeleton::faces`]) moves with `weight`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WeightChange {
    pub edge: usize,
    pub time: f64,
    pub weight: f64,
}

/// When to stop the wavefront.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum StopAt {
    /// Run until the wavefront has vanished (a full skeleton).
    Collapse,
    /// Stop at this time (an offset): faces are cut off there, and the
    /// remaining wavefront is returned.
    Time(f64),
    /// Stop when the area enclosed by the wavefront has dropped to this value
    /// (or at collapse, if it never gets that small); the time is found
    /// exactly from the area, which is quadratic in time between events.
    Area(f64),
}

/// The result of [`skeleton`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Skeleton {
    /// Node positions: the input points first (in loop order, all of them,
    /// duplicates included), then the nodes created by events.
    pub nodes: Vec<DVec2>,
    /// The time at which the wavefront passes each node (0 for input points):
    /// the offset distance for weight 1, the height of a roof of slope 1.
    pub times: Vec<f64>,
    /// One face per input edge, edges numbered globally in loop order (edge
    /// `i` of a loop runs from its point `i` to point `i + 1`). A face is a
    /// counter-clockwise list of node indices starting with the edge's two
    /// end points; empty for zero-length edges. Faces of weight-zero edges
    /// have no area in the plane (they are vertical when lifted).
    pub faces: Vec<Vec<u32>>,
    /// Vertical faces of the steps inserted between adjacent collinear edges
    /// of different weights (see the module docs), counter-clockwise.
    pub step_faces: Vec<Vec<u32>>,
    /// With [`StopAt::Time`] or [`StopAt::Area`], the wavefront where it
    /// stopped: closed loops of `(node, edge)`, the edge (global index) being
    /// the one that runs from that node to the next. Outer loops are
    /// counter-clockwise, holes clockwise. Empty after a full collapse.
    pub wavefront: Vec<Vec<(u32, u32)>>,
    /// The time the simulation stopped at (the largest node time after a
    /// full collapse).
    pub stop_time: f64,
}

impl Skeleton {
    /// Position of node `i` lifted to 3D as `(x, y, time)`.
    pub fn node3(&self, i: u32) -> DVec3 {
        let p = self.nodes[i as usize];
        DVec3::new(p.x, p.y, self.times[i as usize])
    }
}

/// Computes the weighted straight skeleton (or the wavefront up to a stop)
/// of the polygon bounded by `loops`: each loop a closed list of points with
/// the interior on its left (outer boundaries counter-clockwise, holes
/// clockwise). `weights[l][i]` is the speed of edge `i` of loop `l` (0 =
/// the edge does not move; must be finite and not negative).
pub fn skeleton(
    loops: &[Vec<DVec2>],
    weights: &[Vec<f64>],
    stop: StopAt,
    changes: &[WeightChange],
) -> Result<Skeleton, SkeletonError> {
    if loops.len() != weights.len()
        || loops.iter().zip(weights).any(|(l, w)| l.len() != w.len())
        || loops.iter().flatten().any(|p| !p.is_finite())
        || weights.iter().flatten().any(|w| !w.is_finite() || *w < 0.0)
        || changes
            .iter()
            .any(|c| !c.time.is_finite() || !c.weight.is_finite() || c.weight < 0.0)
    {
        return Err(SkeletonError::BadInput);
    }
    let first = run(loops, weights, stop, changes, 0.0);
    match first {
        Ok(s) => Ok(s),
        Err(SkeletonError::Inconsistent(_)) | Err(SkeletonError::EventLimit) => {
            // Retry once with a tiny deterministic perturbation: events that
            // are simultaneous in exact arithmetic but almost-simultaneous in
            // floating point are the usual cause of inconsistencies.
            let mut s = run(loops, weights, stop, changes, 1e-7)?;
            // Report the input points where they were given.
            let mut k = 0;
            for l in loops {
                for &p in l {
                    s.nodes[k] = p;
                    k += 1;
                }
            }
            Ok(s)
        }
        Err(e) => Err(e),
    }
}

/// The full skeleton with all weights 1 (a hip roof's skeleton).
pub fn straight_skeleton(loops: &[Vec<DVec2>]) -> Result<Skeleton, SkeletonError> {
    let w: Vec<Vec<f64>> = loops.iter().map(|l| vec![1.0; l.len()]).collect();
    skeleton(loops, &w, StopAt::Collapse, &[])
}

/// Signed area of a closed polygon (positive if counter-clockwise).
pub fn polygon_area(points: &[DVec2]) -> f64 {
    let n = points.len();
    if n < 3 {
        return 0.0;
    }
    let o = points[0];
    let mut a = 0.0;
    for i in 1..n - 1 {
        a += (points[i] - o).perp_dot(points[i + 1] - o);
    }
    0.5 * a
}

// ---------------------------------------------------------------------------

const NONE: u32 = u32::MAX;

#[derive(Clone, Copy, Debug)]
struct Edge {
    dir: DVec2,
    /// Inward unit normal (left of `dir`).
    n: DVec2,
    w: f64,
    /// The line at time t: n·p = c + w t.
    c: f64,
    /// Alive vertices whose outgoing edge this is.
    active: u32,
}

#[derive(Clone, Copy, Debug)]
struct Vert {
    pos: DVec2,
    t0: f64,
    vel: DVec2,
    ein: u32,
    eout: u32,
    prev: u32,
    next: u32,
    node: u32,
    alive: bool,
    /// Velocity known (not a fold awaiting collapse).
    ready: bool,
}

impl Vert {
    #[inline]
    fn at(&self, t: f64) -> DVec2 {
        self.pos + self.vel * (t - self.t0)
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    Fold { v: u32 },
    Edge { a: u32, b: u32 },
    Split { v: u32, e: u32 },
    Weight { e: u32, w: f64 },
}

#[derive(Clone, Copy, Debug)]
struct Event {
    t: f64,
    seq: u32,
    kind: Kind,
}

impl Event {
    fn rank(&self) -> u8 {
        match self.kind {
            Kind::Fold { .. } => 0,
            Kind::Edge { .. } => 1,
            Kind::Split { .. } => 2,
            Kind::Weight { .. } => 3,
        }
    }
}

impl PartialEq for Event {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for Event {}
impl PartialOrd for Event {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Event {
    // Reversed: BinaryHeap is a max-heap and we want the earliest event.
    fn cmp(&self, o: &Self) -> Ordering {
        o.t.total_cmp(&self.t)
            .then(o.rank().cmp(&self.rank()))
            .then(o.seq.cmp(&self.seq))
    }
}

/// A trace of a vertex (or a ridge) between two nodes, bounding the faces of
/// `ein` (walked from -> to) and `eout` (walked to -> from).
#[derive(Clone, Copy, Debug)]
struct Piece {
    from: u32,
    to: u32,
    ein: u32,
    eout: u32,
}

/// Coincidence tolerance in normalised coordinates.
const EPS: f64 = 1e-9;

struct Sim {
    edges: Vec<Edge>,
    /// Face index of each edge (input edges first, then steps).
    verts: Vec<Vert>,
    nodes: Vec<DVec2>,
    times: Vec<f64>,
    pieces: Vec<Piece>,
    heap: BinaryHeap<Event>,
    seq: u32,
    tc: f64,
    /// For each edge, the vertices ever created with it as outgoing edge.
    verts_of_edge: Vec<Vec<u32>>,
    /// Number of alive vertices.
    alive: usize,
    /// Split candidates `(time, edge)`, sorted per vertex; `cand_next[v]..
    /// cand_end[v]` are those of vertex `v` not yet tried. Only the earliest
    /// of each vertex is in the heap, which keeps the heap small.
    cands: Vec<(f64, u32)>,
    cand_next: Vec<u32>,
    cand_end: Vec<u32>,
}

enum Motion {
    Vel(DVec2),
    Fold,
    Step,
}

impl Sim {
    fn push(&mut self, t: f64, kind: Kind) {
        self.seq = self.seq.wrapping_add(1);
        self.heap.push(Event {
            t: t.max(self.tc),
            seq: self.seq,
            kind,
        });
    }

    fn node(&mut self, p: DVec2, t: f64) -> u32 {
        self.nodes.push(p);
        self.times.push(t);
        (self.nodes.len() - 1) as u32
    }

    fn new_vert(&mut self, pos: DVec2, ein: u32, eout: u32, node: u32) -> u32 {
        let id = self.verts.len() as u32;
        self.verts.push(Vert {
            pos,
            t0: self.tc,
            vel: DVec2::ZERO,
            ein,
            eout,
            prev: NONE,
            next: NONE,
            node,
            alive: true,
            ready: false,
        });
        self.edges[eout as usize].active += 1;
        self.verts_of_edge[eout as usize].push(id);
        self.alive += 1;
        self.cand_next.push(0);
        self.cand_end.push(0);
        id
    }

    fn kill(&mut self, v: u32, node: u32) {
        let vv = self.verts[v as usize];
        if !vv.alive {
            return;
        }
        self.pieces.push(Piece {
            from: vv.node,
            to: node,
            ein: vv.ein,
            eout: vv.eout,
        });
        self.verts[v as usize].alive = false;
        self.edges[vv.eout as usize].active -= 1;
        self.alive -= 1;
    }

    fn link(&mut self, a: u32, b: u32) {
        self.verts[a as usize].next = b;
        self.verts[b as usize].prev = a;
    }

    fn motion(&self, ein: u32, eout: u32) -> Motion {
        let a = self.edges[ein as usize];
        let b = self.edges[eout as usize];
        let cr = a.dir.perp_dot(b.dir);
        let dt = a.dir.dot(b.dir);
        let same_w = (a.w - b.w).abs() <= 1e-12 * a.w.max(b.w).max(1.0);
        if cr.abs() < 1e-9 {
            if dt < 0.0 {
                return Motion::Fold;
            }
            if same_w {
                return Motion::Vel((a.n + b.n).normalize_or(a.n) * a.w);
            }
            return Motion::Step;
        }
        if same_w && a.n.dot(b.n) > -0.5 {
            // The bisector formula is exact and stable for nearly collinear
            // edges, where solving the 2x2 system would cancel.
            return Motion::Vel((a.n + b.n) * (a.w / (1.0 + a.n.dot(b.n))));
        }
        let det = a.n.perp_dot(b.n);
        Motion::Vel(DVec2::new(
            (a.w * b.n.y - b.w * a.n.y) / det,
            (a.n.x * b.w - b.n.x * a.w) / det,
        ))
    }

    /// Gives a new vertex its velocity and schedules its events; resolves
    /// loops of one or two vertices, folds and steps.
    fn settle(&mut self, v: u32) {
        let vv = self.verts[v as usize];
        if !vv.alive {
            return;
        }
        let t = self.tc;
        if vv.next == v {
            let n = self.node(vv.at(t), t);
            self.kill(v, n);
            return;
        }
        let nx = vv.next;
        if self.verts[nx as usize].next == v {
            self.resolve_two(v, nx);
            return;
        }
        match self.motion(vv.ein, vv.eout) {
            Motion::Vel(vel) => {
                let x = &mut self.verts[v as usize];
                x.vel = vel;
                x.ready = true;
                let (p, n) = (x.prev, x.next);
                self.schedule_edge(p, v);
                self.schedule_edge(v, n);
                let a = self.edges[vv.ein as usize].dir;
                let b = self.edges[vv.eout as usize].dir;
                if a.perp_dot(b) < -1e-12 {
                    self.schedule_splits(v);
                }
            }
            Motion::Fold => {
                self.push(t, Kind::Fold { v });
            }
            Motion::Step => {
                let a = self.edges[vv.ein as usize];
                let b = self.edges[vv.eout as usize];
                // The faster edge runs ahead; the step wall faces the slower.
                let dir = if a.w > b.w { -a.n } else { a.n };
                let n = dir.perp();
                let p = vv.pos;
                let e = self.edges.len() as u32;
                self.edges.push(Edge {
                    dir,
                    n,
                    w: 0.0,
                    c: n.dot(p),
                    active: 0,
                });
                self.verts_of_edge.push(Vec::new());
                let (pv, nv) = (vv.prev, vv.next);
                // Same node: the zero-length trace of `v` is dropped later.
                self.kill(v, vv.node);
                let v1 = self.new_vert(p, vv.ein, e, vv.node);
                let v2 = self.new_vert(p, e, vv.eout, vv.node);
                self.link(pv, v1);
                self.link(v1, v2);
                self.link(v2, nv);
                self.settle(v1);
                self.settle(v2);
            }
        }
    }

    fn resolve_two(&mut self, u: u32, v: u32) {
        let t = self.tc;
        let uu = self.verts[u as usize];
        let vv = self.verts[v as usize];
        let nu = self.node(uu.at(t), t);
        let nv = self.node(vv.at(t), t);
        self.kill(u, nu);
        self.kill(v, nv);
        self.pieces.push(Piece {
            from: nu,
            to: nv,
            ein: uu.ein,
            eout: uu.eout,
        });
    }

    fn schedule_edge(&mut self, a: u32, b: u32) {
        let va = self.verts[a as usize];
        let vb = self.verts[b as usize];
        if !va.ready || !vb.ready || !va.alive || !vb.alive {
            return;
        }
        let t = self.tc;
        let d = self.edges[va.eout as usize].dir;
        let len = (vb.at(t) - va.at(t)).dot(d);
        let rate = (vb.vel - va.vel).dot(d);
        if len <= EPS {
            if rate > 1e-12 && len > -EPS {
                return; // a zero-length edge that grows (a fresh step)
            }
            self.push(t, Kind::Edge { a, b });
        } else if rate < -1e-15 {
            self.push(t + len / -rate, Kind::Edge { a, b });
        }
    }

    fn schedule_splits(&mut self, v: u32) {
        let vv = self.verts[v as usize];
        let t = self.tc;
        let p = vv.at(t);
        self.cand_next[v as usize] = self.cands.len() as u32;
        for e in 0..self.edges.len() as u32 {
            if e == vv.ein || e == vv.eout {
                continue;
            }
            let ed = self.edges[e as usize];
            if ed.active == 0 {
                continue;
            }
            let rate = ed.n.dot(vv.vel) - ed.w;
            if rate >= -1e-12 {
                continue;
            }
            let dist = ed.n.dot(p) - ed.c - ed.w * t;
            if dist < -EPS {
                continue;
            }
            if dist <= EPS && self.edge_has_vertex_at(e, p, v) {
                // The edge passes through v's point through one of its own
                // vertices there: that meeting has just been resolved.
                continue;
            }
            let te = t + dist.max(0.0) / -rate;
            self.cands.push((te, e));
        }
        let start = self.cand_next[v as usize] as usize;
        self.cands[start..].sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        self.cand_end[v as usize] = self.cands.len() as u32;
        if start < self.cands.len() {
            let (te, e) = self.cands[start];
            self.cand_next[v as usize] += 1;
            self.push(te, Kind::Split { v, e });
        }
    }

    /// The next untried split candidate of `v`.
    fn next_candidate(&mut self, v: u32) -> Option<(f64, u32)> {
        let i = self.cand_next[v as usize];
        if i >= self.cand_end[v as usize] {
            return None;
        }
        self.cand_next[v as usize] += 1;
        Some(self.cands[i as usize])
    }

    fn edge_has_vertex_at(&self, e: u32, p: DVec2, not: u32) -> bool {
        let t = self.tc;
        self.verts_of_edge[e as usize].iter().any(|&x| {
            let vx = &self.verts[x as usize];
            let vy = &self.verts[vx.next as usize];
            x != not
                && vx.alive
                && vx.eout == e
                && (vx.at(t).distance(p) <= EPS * 4.0 || vy.at(t).distance(p) <= EPS * 4.0)
        })
    }

    fn collapse(&mut self, a: u32, b: u32, point: DVec2) {
        let t = self.tc;
        let va = self.verts[a as usize];
        let vb = self.verts[b as usize];
        let node = self.node(point, t);
        self.kill(a, node);
        self.kill(b, node);
        if va.prev == b {
            return; // the loop was [a, b]: both gone
        }
        let c = self.new_vert(point, va.ein, vb.eout, node);
        self.link(va.prev, c);
        self.link(c, vb.next);
        self.settle(c);
    }

    fn split(&mut self, v: u32, e: u32, x: u32, y: u32, p: DVec2) {
        let t = self.tc;
        let vv = self.verts[v as usize];
        let node = self.node(p, t);
        self.kill(v, node);
        let v1 = self.new_vert(p, vv.ein, e, node);
        let v2 = self.new_vert(p, e, vv.eout, node);
        let (pv, nv) = (vv.prev, vv.next);
        self.link(pv, v1);
        self.link(v1, y);
        self.link(x, v2);
        self.link(v2, nv);
        self.settle(v1);
        self.settle(v2);
    }

    /// Resolves all wavefront vertices meeting at `p` now (a generalised
    /// vertex event in the sense of Eppstein & Erickson): runs of consecutive
    /// vertices there collapse to one, and the remaining runs are re-linked
    /// by pairing, counter-clockwise around `p`, each outgoing edge with the
    /// next incoming edge. Returns false (doing nothing) if the rays around
    /// `p` do not alternate, which only inconsistent input produces.
    fn vertex_event(&mut self, p: DVec2) -> bool {
        let t = self.tc;
        let tol = EPS * 4.0;
        let members: Vec<u32> = (0..self.verts.len() as u32)
            .filter(|&v| {
                let x = &self.verts[v as usize];
                x.alive && x.at(t).distance(p) <= tol
            })
            .collect();
        if members.len() < 2 {
            return false;
        }
        let is_member = |s: &Sim, v: u32| members.contains(&v) && s.verts[v as usize].alive;
        // Runs of consecutive members: (first, last).
        // Loops entirely at p have no run start: they are simply removed.
        let mut chains: Vec<(u32, u32)> = Vec::new();
        for &m in &members {
            let prev = self.verts[m as usize].prev;
            if is_member(self, prev) {
                continue;
            }
            let mut last = m;
            let mut guard = 0;
            while is_member(self, self.verts[last as usize].next) && guard < members.len() {
                last = self.verts[last as usize].next;
                guard += 1;
            }
            chains.push((m, last));
        }
        let mut rays: Vec<(f64, u8, usize)> = Vec::with_capacity(chains.len() * 2);
        for (k, &(a, b)) in chains.iter().enumerate() {
            let ein = self.edges[self.verts[a as usize].ein as usize].dir;
            let eout = self.edges[self.verts[b as usize].eout as usize].dir;
            rays.push((eout.y.atan2(eout.x), 0, k));
            rays.push(((-ein.y).atan2(-ein.x), 1, k));
        }
        rays.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        let m = rays.len();
        let mut pairs: Vec<(usize, usize)> = Vec::with_capacity(chains.len());
        let mut used = vec![false; chains.len()];
        if chains.len() == 1 {
            pairs.push((0, 0));
        } else if chains.len() > 1 {
            for i in 0..m {
                if rays[i].1 != 0 {
                    continue;
                }
                let mut j = (i + 1) % m;
                while rays[j].1 != 1 {
                    j = (j + 1) % m;
                }
                let k = rays[j].2;
                if used[k] {
                    return false;
                }
                used[k] = true;
                pairs.push((k, rays[i].2)); // (in-chain, out-chain)
            }
        }
        let node = self.node(p, t);
        let ends: Vec<(u32, u32, u32, u32)> = chains
            .iter()
            .map(|&(a, b)| {
                let va = self.verts[a as usize];
                let vb = self.verts[b as usize];
                (va.prev, va.ein, vb.eout, vb.next)
            })
            .collect();
        for &mm in &members {
            self.kill(mm, node);
        }
        // Each chain's outside neighbours are not members, and each is used
        // by exactly one pair, so the links are consistent.
        let mut created = Vec::with_capacity(pairs.len());
        for &(ki, ko) in &pairs {
            let (prev, ein, _, _) = ends[ki];
            let (_, _, eout, next) = ends[ko];
            let c = self.new_vert(p, ein, eout, node);
            created.push((c, prev, next));
        }
        for &(c, prev, next) in &created {
            self.link(prev, c);
            self.link(c, next);
        }
        for &(c, _, _) in &created {
            self.settle(c);
        }
        true
    }

    /// Performs the split of `v` against `e` now if it is valid; returns
    /// whether it was.
    fn try_split(&mut self, v: u32, e: u32) -> bool {
        let vv = self.verts[v as usize];
        if !vv.alive || !vv.ready || self.edges[e as usize].active == 0 {
            return false;
        }
        let t = self.tc;
        let p = vv.at(t);
        let ed = self.edges[e as usize];
        let tol = EPS * (1.0 + vv.vel.length());
        let mut found = None;
        for &x in &self.verts_of_edge[e as usize] {
            let vx = self.verts[x as usize];
            if !vx.alive || vx.eout != e || !vx.ready {
                continue;
            }
            let y = vx.next;
            let vy = self.verts[y as usize];
            if !vy.ready {
                continue;
            }
            let xt = vx.at(t);
            let yt = vy.at(t);
            let s = (p - xt).dot(ed.dir);
            let len = (yt - xt).dot(ed.dir);
            if s >= -tol && s <= len + tol && (p - xt).dot(ed.n).abs() <= tol * 10.0 {
                found = Some((x, y));
                break;
            }
        }
        if let Some((x, y)) = found {
            // Insert a flat vertex on the edge at the hit point unless
            // an end of the segment is there already, then resolve
            // everything that meets at the point at once.
            let tol_p = EPS * 4.0;
            let xt = self.verts[x as usize].at(t);
            let yt = self.verts[y as usize].at(t);
            let near_end = p.distance(xt) <= tol_p || p.distance(yt) <= tol_p;
            let flat = if near_end {
                NONE
            } else {
                let node = self.node(p, t);
                let f = self.new_vert(p, e, e, node);
                self.verts[f as usize].ready = true;
                self.verts[f as usize].vel = DVec2::ZERO;
                self.link(x, f);
                self.link(f, y);
                f
            };
            if !self.vertex_event(p) {
                // Unresolvable configuration: fall back to the plain
                // split of the segment (the result is checked later).
                if flat != NONE && self.verts[flat as usize].alive {
                    self.verts[flat as usize].alive = false;
                    self.edges[e as usize].active -= 1;
                    self.alive -= 1;
                    self.link(x, y);
                }
                if self.verts[v as usize].alive
                    && self.verts[x as usize].alive
                    && self.verts[x as usize].next == y
                {
                    self.split(v, e, x, y, p);
                }
            }
        }
        found.is_some()
    }

    fn replace(&mut self, v: u32) {
        let t = self.tc;
        let vv = self.verts[v as usize];
        if !vv.alive {
            return;
        }
        let p = vv.at(t);
        let node = self.node(p, t);
        self.kill(v, node);
        let c = self.new_vert(p, vv.ein, vv.eout, node);
        self.link(vv.prev, c);
        self.link(c, vv.next);
        self.settle(c);
    }

    /// Gives edge `e` the weight (speed) `w` from time `t` on, keeping its
    /// line where it is at `t`.
    fn set_weight(&mut self, e: u32, w: f64, t: f64) {
        let ed = &mut self.edges[e as usize];
        ed.c += (ed.w - w) * t;
        ed.w = w;
    }

    fn process(&mut self, ev: Event) {
        match ev.kind {
            Kind::Fold { v } => {
                let vv = self.verts[v as usize];
                if !vv.alive || vv.ready {
                    return;
                }
                let t = self.tc;
                let (p, n) = (vv.prev, vv.next);
                let pp = self.verts[p as usize].at(t);
                let pn = self.verts[n as usize].at(t);
                let here = vv.at(t);
                if here.distance_squared(pp) <= here.distance_squared(pn) {
                    self.collapse(p, v, pp);
                } else {
                    self.collapse(v, n, pn);
                }
            }
            Kind::Edge { a, b } => {
                let va = self.verts[a as usize];
                let vb = self.verts[b as usize];
                if !va.alive || !vb.alive || va.next != b || !va.ready || !vb.ready {
                    return;
                }
                let t = self.tc;
                let point = 0.5 * (va.at(t) + vb.at(t));
                self.collapse(a, b, point);
            }
            Kind::Split { v, e } => {
                self.try_split(v, e);
            }
            Kind::Weight { e, w } => {
                let t = self.tc;
                self.set_weight(e, w, t);
                // Every other weight change due now too (an envelope changes
                // all edges' weights at one height): the vertices are then
                // renewed once, not once per edge, which made it quadratic
                // in the edge count.
                while let Some(next) = self.heap.peek().copied() {
                    let Kind::Weight { e, w } = next.kind else {
                        break;
                    };
                    if next.t != t {
                        break;
                    }
                    self.heap.pop();
                    self.set_weight(e, w, t);
                }
                // All vertices are renewed: split candidates against these
                // edges are stale, and they are recomputed with the vertices.
                let affected: Vec<u32> = (0..self.verts.len() as u32)
                    .filter(|&v| self.verts[v as usize].alive)
                    .collect();
                for v in affected {
                    self.replace(v);
                }
            }
        }
    }

    /// Signed area of the wavefront at `tc + tau` as `a0 + a1 tau + a2 tau²`.
    fn area_poly(&self) -> (f64, f64, f64) {
        let t = self.tc;
        let (mut a0, mut a1, mut a2) = (0.0, 0.0, 0.0);
        for v in &self.verts {
            if !v.alive {
                continue;
            }
            let w = &self.verts[v.next as usize];
            let (p, q) = (v.at(t), w.at(t));
            a0 += p.perp_dot(q);
            a1 += p.perp_dot(w.vel) + v.vel.perp_dot(q);
            a2 += v.vel.perp_dot(w.vel);
        }
        (0.5 * a0, 0.5 * a1, 0.5 * a2)
    }
}

/// Smallest root in `[0, hi]` of `a0 + a1 x + a2 x² = target`, if any.
fn solve_area(a: (f64, f64, f64), target: f64, hi: f64) -> Option<f64> {
    let (c, b, q) = (a.0 - target, a.1, a.2);
    if c <= 0.0 {
        return Some(0.0);
    }
    let mut best: Option<f64> = None;
    let mut consider = |x: f64| {
        if x.is_finite() && x >= 0.0 && x <= hi && best.is_none_or(|b| x < b) {
            best = Some(x);
        }
    };
    if q.abs() < 1e-14 * (b.abs() + c.abs()).max(1e-300) {
        if b != 0.0 {
            consider(-c / b);
        }
    } else {
        let disc = b * b - 4.0 * q * c;
        if disc >= 0.0 {
            let s = disc.sqrt();
            // Numerically stable pair of roots.
            let k = -0.5 * (b + b.signum() * s);
            if k != 0.0 {
                consider(k / q);
                consider(c / k);
            } else {
                consider(0.0);
            }
        }
    }
    best
}

fn run(
    loops_in: &[Vec<DVec2>],
    weights: &[Vec<f64>],
    stop: StopAt,
    changes: &[WeightChange],
    jitter: f64,
) -> Result<Skeleton, SkeletonError> {
    // Normalise to the unit box for scale-free tolerances.
    let mut lo = DVec2::splat(f64::INFINITY);
    let mut hi = DVec2::splat(f64::NEG_INFINITY);
    for p in loops_in.iter().flatten() {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    if !lo.is_finite() {
        return Err(SkeletonError::Empty);
    }
    let scale = (hi - lo).max_element().max(1e-300);
    let origin = 0.5 * (lo + hi);
    let inv = 1.0 / scale;
    let mut k = 0u64;
    let norm = |p: DVec2, k: &mut u64| {
        let mut q = (p - origin) * inv;
        if jitter > 0.0 {
            // Deterministic pseudo-random jitter (splitmix64).
            *k = k.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = *k;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^= z >> 31;
            let a = (z >> 11) as f64 / (1u64 << 53) as f64 * std::f64::consts::TAU;
            q += DVec2::new(a.cos(), a.sin()) * jitter;
        }
        q
    };

    let n_edges: usize = loops_in.iter().map(|l| l.len()).sum();
    let mut sim = Sim {
        edges: Vec::with_capacity(n_edges + 4),
        verts: Vec::with_capacity(n_edges * 3),
        nodes: Vec::with_capacity(n_edges * 3),
        times: Vec::with_capacity(n_edges * 3),
        pieces: Vec::with_capacity(n_edges * 4),
        heap: BinaryHeap::new(),
        seq: 0,
        tc: 0.0,
        verts_of_edge: Vec::with_capacity(n_edges),
        alive: 0,
        cands: Vec::with_capacity(n_edges * 8),
        cand_next: Vec::with_capacity(n_edges * 3),
        cand_end: Vec::with_capacity(n_edges * 3),
    };
    for p in loops_in.iter().flatten() {
        let q = norm(*p, &mut k);
        sim.nodes.push(q);
        sim.times.push(0.0);
    }
    // Edges; zero-length ones are kept as dead entries so that indices match.
    let mut base = 0usize;
    let mut loop_verts: Vec<Vec<u32>> = Vec::new();
    let mut any = false;
    for (pts, wl) in loops_in.iter().zip(weights) {
        let n = pts.len();
        for (i, &w) in wl.iter().enumerate() {
            let a = sim.nodes[base + i];
            let b = sim.nodes[base + (i + 1) % n];
            let d = b - a;
            let len = d.length();
            let dir = if len > EPS { d / len } else { DVec2::X };
            let nn = dir.perp();
            sim.edges.push(Edge {
                dir,
                n: nn,
                w,
                c: nn.dot(a),
                active: 0,
            });
            sim.verts_of_edge.push(Vec::new());
        }
        // Vertices at the starts of non-degenerate edges whose previous
        // non-degenerate edge gives their incoming edge.
        let good: Vec<usize> = (0..n)
            .filter(|&i| {
                let a = sim.nodes[base + i];
                let b = sim.nodes[base + (i + 1) % n];
                (b - a).length() > EPS
            })
            .collect();
        if good.len() < 2 {
            base += n;
            continue;
        }
        let mut ids = Vec::with_capacity(good.len());
        for (j, &i) in good.iter().enumerate() {
            let prev = good[(j + good.len() - 1) % good.len()];
            let node = (base + i) as u32;
            let pos = sim.nodes[node as usize];
            let v = sim.new_vert(pos, (base + prev) as u32, (base + i) as u32, node);
            ids.push(v);
        }
        for j in 0..ids.len() {
            sim.link(ids[j], ids[(j + 1) % ids.len()]);
        }
        any |= good.len() >= 3;
        loop_verts.push(ids);
        base += n;
    }
    if !any {
        return Err(SkeletonError::Empty);
    }
    // Velocities first, then events (edge events need both ends).
    let all: Vec<u32> = loop_verts.iter().flatten().copied().collect();
    for &v in &all {
        let vv = sim.verts[v as usize];
        if vv.next == v || sim.verts[vv.next as usize].next == v {
            continue;
        }
        if let Motion::Vel(vel) = sim.motion(vv.ein, vv.eout) {
            sim.verts[v as usize].vel = vel;
            sim.verts[v as usize].ready = true;
        }
    }
    for &v in &all {
        let vv = sim.verts[v as usize];
        if !vv.alive {
            continue;
        }
        if !vv.ready {
            sim.settle(v);
            continue;
        }
        sim.schedule_edge(v, vv.next);
        // Reflex test on the input with exact arithmetic.
        let a = sim.nodes[sim.verts[vv.prev as usize].node as usize];
        let b = sim.nodes[vv.node as usize];
        let c = sim.nodes[sim.verts[vv.next as usize].node as usize];
        let o = robust::orient2d(
            robust::Coord { x: a.x, y: a.y },
            robust::Coord { x: b.x, y: b.y },
            robust::Coord { x: c.x, y: c.y },
        );
        if o < 0.0 {
            sim.schedule_splits(v);
        }
    }
    for c in changes {
        if c.edge < n_edges {
            sim.push(
                c.time * inv,
                Kind::Weight {
                    e: c.edge as u32,
                    w: c.weight,
                },
            );
        }
    }

    let stop_t = match stop {
        StopAt::Time(t) => Some((t * inv).max(0.0)),
        _ => None,
    };
    let target_area = match stop {
        StopAt::Area(a) => Some(a * inv * inv),
        _ => None,
    };
    let mut stopped_at: Option<f64> = None;
    let budget = 64 * all.len() + 4 * changes.len() + 256;
    let mut processed = 0usize;
    let pop_budget = budget * (all.len() + 8) * 4;
    let mut pops = 0usize;
    let (mut instant_t, mut instant_n, mut instant_limit) = (f64::NEG_INFINITY, 0usize, 0usize);
    while let Some(ev) = sim.heap.peek().copied() {
        pops += 1;
        if pops > pop_budget {
            return Err(SkeletonError::EventLimit);
        }
        let t = ev.t.max(sim.tc);
        if let Some(ts) = stop_t {
            if t > ts {
                stopped_at = Some(ts);
                break;
            }
        }
        if let Some(target) = target_area {
            let a = sim.area_poly();
            if let Some(tau) = solve_area(a, target, t - sim.tc) {
                stopped_at = Some(sim.tc + tau);
                break;
            }
        }
        sim.heap.pop();
        sim.tc = t;
        let before = sim.pieces.len();
        if let Kind::Split { v, e } = ev.kind {
            // Try the candidates of v in time order; those before the next
            // queued event are checked right here (nothing moves differently
            // until then), the first later one goes back into the queue.
            let mut e = e;
            while sim.verts[v as usize].alive && !sim.try_split(v, e) {
                let Some((t2, e2)) = sim.next_candidate(v) else {
                    break;
                };
                let limit = sim.heap.peek().map_or(f64::INFINITY, |x| x.t);
                let inline = target_area.is_none() && t2 <= limit && stop_t.is_none_or(|s| t2 <= s);
                if inline {
                    sim.tc = t2.max(sim.tc);
                    e = e2;
                } else {
                    sim.push(t2, Kind::Split { v, e: e2 });
                    break;
                }
            }
        } else {
            sim.process(ev);
        }
        if sim.pieces.len() != before {
            processed += 1;
            if processed > budget {
                return Err(SkeletonError::EventLimit);
            }
            // Events at one instant are bounded by the wavefront's size; more
            // means a cycle among coincident events (a split re-created by
            // the collapse it causes): give up early, the caller retries on
            // a perturbed copy.
            if t - instant_t > EPS {
                instant_t = t;
                instant_n = 0;
            }
            instant_n += 1;
            if instant_n == 1 {
                instant_limit = 4 * sim.alive + 64;
            }
            if instant_n > instant_limit {
                return Err(SkeletonError::EventLimit);
            }
        }
    }
    let alive: Vec<u32> = (0..sim.verts.len() as u32)
        .filter(|&v| sim.verts[v as usize].alive)
        .collect();
    if stopped_at.is_none() && !alive.is_empty() {
        match (stop_t, target_area) {
            (Some(ts), _) => stopped_at = Some(ts),
            (None, Some(_)) => {
                // Never reaches the target: stays as it is.
                return Err(SkeletonError::NoCollapse);
            }
            _ => return Err(SkeletonError::NoCollapse),
        }
    }
    let mut wavefront = Vec::new();
    let final_t;
    if let Some(ts) = stopped_at {
        sim.tc = ts.max(sim.tc);
        final_t = sim.tc;
        let t = sim.tc;
        let mut node_of = vec![NONE; sim.verts.len()];
        for &v in &alive {
            let p = sim.verts[v as usize].at(t);
            node_of[v as usize] = sim.node(p, t);
        }
        for &v in &alive {
            let vv = sim.verts[v as usize];
            let nx = vv.next;
            sim.pieces.push(Piece {
                from: node_of[nx as usize],
                to: node_of[v as usize],
                ein: vv.eout,
                eout: NONE,
            });
            sim.kill(v, node_of[v as usize]);
        }
        let mut seen = vec![false; sim.verts.len()];
        for &v in &alive {
            if seen[v as usize] {
                continue;
            }
            let mut lp = Vec::new();
            let mut x = v;
            while !seen[x as usize] {
                seen[x as usize] = true;
                lp.push((node_of[x as usize], sim.verts[x as usize].eout));
                x = sim.verts[x as usize].next;
            }
            wavefront.push(lp);
        }
    } else {
        final_t = sim.times.iter().copied().fold(0.0, f64::max);
    }

    // Assemble faces on welded nodes.
    let pts3: Vec<DVec3> = sim
        .nodes
        .iter()
        .zip(&sim.times)
        .map(|(p, t)| DVec3::new(p.x, p.y, *t))
        .collect();
    let weld = weld_points(&pts3, EPS * 4.0);
    let n_faces = sim.edges.len();
    let mut count = vec![0u32; n_faces + 1];
    let wid = |i: u32| weld.id[i as usize];
    for pc in &sim.pieces {
        if wid(pc.from) == wid(pc.to) {
            continue;
        }
        if pc.ein != NONE {
            count[pc.ein as usize] += 1;
        }
        if pc.eout != NONE {
            count[pc.eout as usize] += 1;
        }
    }
    let mut start = vec![0u32; n_faces + 1];
    for f in 0..n_faces {
        start[f + 1] = start[f] + count[f];
    }
    let mut fill = start.clone();
    let mut half: Vec<(u32, u32)> = vec![(0, 0); start[n_faces] as usize];
    for pc in &sim.pieces {
        let (a, b) = (wid(pc.from), wid(pc.to));
        if a == b {
            continue;
        }
        if pc.ein != NONE {
            half[fill[pc.ein as usize] as usize] = (a, b);
            fill[pc.ein as usize] += 1;
        }
        if pc.eout != NONE {
            half[fill[pc.eout as usize] as usize] = (b, a);
            fill[pc.eout as usize] += 1;
        }
    }
    // A representative node id (the first of its weld cluster) for output.
    let rep = |w: u32| weld.representative[w as usize];
    let mut used: Vec<bool> = vec![false; half.len()];
    let walk = |f: usize, from: u32, to: u32, used: &mut Vec<bool>| -> Option<Vec<u32>> {
        let r = start[f] as usize..start[f + 1] as usize;
        let mut out = vec![rep(to)];
        let mut cur = to;
        let mut steps = 0;
        while cur != from || steps == 0 {
            steps += 1;
            if steps > r.len() + 1 {
                return None;
            }
            let mut next = None;
            for h in r.clone() {
                if !used[h] && half[h].0 == cur {
                    used[h] = true;
                    next = Some(half[h].1);
                    break;
                }
            }
            cur = next?;
            if cur != from {
                out.push(rep(cur));
            }
        }
        Some(out)
    };
    let mut faces: Vec<Vec<u32>> = vec![Vec::new(); n_edges];
    let mut base = 0usize;
    for pts in loops_in {
        let n = pts.len();
        for i in 0..n {
            let f = base + i;
            let a = (base + i) as u32;
            let b = (base + (i + 1) % n) as u32;
            let (wa, wb) = (weld.id[a as usize], weld.id[b as usize]);
            if wa == wb || sim.verts_of_edge[f].is_empty() {
                continue;
            }
            let chain = walk(f, wa, wb, &mut used).ok_or(SkeletonError::Inconsistent(f))?;
            let mut face = Vec::with_capacity(chain.len() + 1);
            face.push(a);
            face.push(b);
            face.extend_from_slice(&chain[1..]);
            faces[f] = face;
        }
        base += n;
    }
    let mut step_faces = Vec::new();
    for f in n_edges..n_faces {
        let r = start[f] as usize..start[f + 1] as usize;
        if r.is_empty() {
            continue;
        }
        let s = half[r.start].0;
        let first = half[r.start].1;
        used[r.start] = true;
        let chain = walk(f, s, first, &mut used).ok_or(SkeletonError::Inconsistent(f))?;
        let mut face = vec![rep(s)];
        face.extend(chain);
        if face.len() >= 3 {
            step_faces.push(face);
        }
    }

    // Check: faces (and the remaining wavefront) tile the polygon.
    let area_of = |face: &[u32]| -> f64 {
        let pts: Vec<DVec2> = face.iter().map(|&i| sim.nodes[i as usize]).collect();
        polygon_area(&pts)
    };
    let mut total = 0.0;
    let mut base = 0usize;
    for pts in loops_in {
        let n = pts.len();
        let p: Vec<DVec2> = (0..n).map(|i| sim.nodes[base + i]).collect();
        total += polygon_area(&p);
        base += n;
    }
    let mut sum = 0.0;
    let mut abs_sum = 0.0;
    for (f, face) in faces.iter().enumerate() {
        let a = area_of(face);
        if a < -1e-7 {
            return Err(SkeletonError::Inconsistent(f));
        }
        sum += a;
        abs_sum += a.abs();
    }
    for lp in &wavefront {
        let pts: Vec<DVec2> = lp.iter().map(|&(n, _)| sim.nodes[n as usize]).collect();
        sum += polygon_area(&pts);
    }
    if (sum - total).abs() > 1e-7 * abs_sum.max(total.abs()).max(1e-12) + 1e-12 {
        return Err(SkeletonError::Inconsistent(usize::MAX));
    }

    // Back to the caller's coordinates.
    let nodes = sim.nodes.iter().map(|p| *p * scale + origin).collect();
    let times = sim.times.iter().map(|t| t * scale).collect();
    Ok(Skeleton {
        nodes,
        times,
        faces,
        step_faces,
        wavefront,
        stop_time: final_t * scale,
    })
}

#[cfg(test)]
#[path = "skeleton_tests.rs"]
mod tests;
