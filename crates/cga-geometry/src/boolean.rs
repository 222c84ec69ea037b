//! Boolean operations on polygon meshes: CGA's `union`, `subtract` and
//! `intersect` (op_boolOp.md).
//!
//! # Method
//!
//! Volumes are combined with BSP trees, the classic CSG approach: the faces
//! of each operand are triangulated (BSP splitting needs convex polygons),
//! a BSP tree is built of each operand's triangles, each operand's polygons
//! are clipped against the other's tree, and the trees are inverted around
//! the clipping for `subtract` and `intersect`. A polygon that lies in a
//! plane of the other operand goes to the side its normal says, which makes
//! the first operand win where faces of both coincide (its material is
//! kept there, as CityEngine does) and removes faces where solids touch.
//!
//! The fragments are then put back together per source face: a face none of
//! whose triangles was cut or removed is copied as it was (same corners,
//! texture coordinates, normals); the fragments of a cut face are united in
//! the plane of the face (`i_overlay`) into polygons with holes, whose
//! per-corner attributes are interpolated from the source face's
//! triangulation (exact for any texture coordinates linear on the face's
//! triangles). Finally coincident vertices are welded and vertices lying on
//! another face's edge are inserted into that edge (T-junctions), so that
//! the result of closed operands is a closed mesh whose edges are used by
//! exactly two faces.
//!
//! # Open operands
//!
//! A BSP tree splits space by the planes of its polygons: an open operand
//! acts as the region behind its faces, extended through its openings (a
//! plane is a half-space, a box without its front face a prism open to the
//! front). As long as the other operand does not reach through an opening,
//! this is the closed solid the operand bounds, which is how CityEngine
//! treats open operands: "open operands are assumed closed as long as
//! boundaries are not intersected"; a plane that cuts through a cube
//! removes, in a union, everything of the cube below it.
//!
//! # Planar operands
//!
//! Two operands whose faces all lie in one plane (layouts: lots, disks,
//! quads) are combined in 2D instead, face by face, with `i_overlay`: a union
//! gives the parts of A's faces outside B, the parts inside B (A's faces,
//! both operands' source) and the parts of B's faces outside A.
//!
//! Tolerances are relative to the size of the model: points within 1e-8 of
//! the largest coordinate magnitude (at least 1) of a plane lie on it.

use std::cell::Cell;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use glam::{DVec2, DVec3};
use i_overlay::core::fill_rule::FillRule;
use i_overlay::core::overlay_rule::OverlayRule;
use i_overlay::float::overlay::FloatOverlay;
use i_overlay::float::simplify::SimplifyShape;

use crate::measure::{bounds, face_normal};
use crate::mesh::{Face, Loop, Mesh};
use crate::topology::weld_points;
use crate::transform::merge;
use crate::triangulate::{plane_basis, triangulate_face};

/// Which Boolean operation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BoolOp {
    /// A ∪ B.
    Union,
    /// A − B.
    Subtract,
    /// A ∩ B.
    Intersect,
}

/// The operand a result face comes from. CGA's auto-tags `bool.A` and
/// `bool.B` are derived from this (`Both`: a face of A where faces of both
/// operands overlap in 2D; it gets both tags).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FaceSource {
    A,
    B,
    Both,
}

/// The result of [`boolean`]: the mesh and, per face, the operand it comes
/// from. Faces of A come first, then those of B.
#[derive(Clone, Debug)]
pub struct BoolResult {
    pub mesh: Mesh,
    pub sources: Vec<FaceSource>,
}

/// `a op b`. Faces keep the material slot, group, texture coordinates and
/// normals of the face they come from; faces of B that bound a subtraction
/// are reversed (they face into the removed volume of B, out of the result).
/// Closed operands give a closed result. Never panics; degenerate faces
/// (fewer than three corners, no area) take no part in the operation.
pub fn boolean(a: &Mesh, b: &Mesh, op: BoolOp) -> BoolResult {
    match boolean_within(a, b, op, Stop::NEVER) {
        Ok(r) => r,
        Err(TimedOut) => unreachable!("no deadline, no time out"),
    }
}

/// The operation gave up at its deadline, or was cancelled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TimedOut;

/// When a long operation should give up: a point in time, or a flag
/// another thread sets (a cancelled generation).
#[derive(Clone, Copy, Debug, Default)]
pub struct Stop<'a> {
    pub deadline: Option<Instant>,
    pub cancel: Option<&'a AtomicBool>,
}

impl Stop<'_> {
    /// Never gives up.
    pub const NEVER: Stop<'static> = Stop {
        deadline: None,
        cancel: None,
    };
}

/// [`boolean`] that gives up once `stop` says so. Operands of many
/// thousands of faces can make the BSP trees fragment their polygons into
/// millions (each clip splits polygons by the other tree's planes), which
/// takes minutes: the engine's time limit and cancellation must hold
/// inside one operation.
pub fn boolean_within(
    a: &Mesh,
    b: &Mesh,
    op: BoolOp,
    stop: Stop<'_>,
) -> Result<BoolResult, TimedOut> {
    let clock = Clock::new(stop);
    let scale = a
        .positions
        .iter()
        .chain(&b.positions)
        .filter(|p| p.is_finite())
        .fold(1.0f64, |m, p| m.max(p.abs().max_element()));
    let tol = Tol {
        plane: 1e-8 * scale,
        weld: 1e-7 * scale,
        snap: 1e-6 * scale,
    };
    let has_area = |m: &Mesh| (0..m.faces.len()).any(|f| face_normal(m, f) != DVec3::ZERO);
    let (a_any, b_any) = (has_area(a), has_area(b));
    // Trivial cases: an empty operand, or operands whose bounds are apart.
    let apart = match (bounds(a), bounds(b)) {
        (Some((alo, ahi)), Some((blo, bhi))) => {
            (alo - tol.plane).cmpgt(bhi).any() || (blo - tol.plane).cmpgt(ahi).any()
        }
        _ => true,
    };
    if !a_any || !b_any || apart {
        return Ok(match op {
            BoolOp::Union => {
                let mut mesh = a.clone();
                merge(&mut mesh, b);
                let mut sources = vec![FaceSource::A; a.faces.len()];
                sources.resize(mesh.faces.len(), FaceSource::B);
                BoolResult { mesh, sources }
            }
            BoolOp::Subtract => BoolResult {
                mesh: a.clone(),
                sources: vec![FaceSource::A; a.faces.len()],
            },
            BoolOp::Intersect => BoolResult {
                mesh: empty_like(a),
                sources: Vec::new(),
            },
        });
    }
    if let Some(plane) = common_plane(a, b, tol.plane) {
        return boolean_2d(a, b, op, plane, &tol, &clock);
    }
    boolean_3d(a, b, op, &tol, &clock)
}

/// Tells the loops of an operation when to give up (looking at the time
/// and the cancel flag at the first question and every 256th; once passed,
/// always).
struct Clock<'a> {
    stop: Stop<'a>,
    asked: Cell<u32>,
    passed: Cell<bool>,
}

impl<'a> Clock<'a> {
    fn new(stop: Stop<'a>) -> Clock<'a> {
        Clock {
            stop,
            asked: Cell::new(0),
            passed: Cell::new(false),
        }
    }

    fn passed(&self) -> bool {
        if self.stop.deadline.is_none() && self.stop.cancel.is_none() {
            return false;
        }
        if !self.passed.get() {
            let n = self.asked.get().wrapping_add(1);
            self.asked.set(n);
            // The first question and every 256th look at the time.
            if n % 256 == 1 {
                let late = self.stop.deadline.is_some_and(|d| Instant::now() >= d);
                let cancelled = self
                    .stop
                    .cancel
                    .is_some_and(|c| c.load(std::sync::atomic::Ordering::Relaxed));
                if late || cancelled {
                    self.passed.set(true);
                }
            }
        }
        self.passed.get()
    }

    fn check(&self) -> Result<(), TimedOut> {
        if self.passed.get() {
            Err(TimedOut)
        } else {
            Ok(())
        }
    }
}

struct Tol {
    /// A point this close to a plane lies on it.
    plane: f64,
    /// Points this close are one vertex.
    weld: f64,
    /// A point of a merged face this close to a fragment's vertex is moved
    /// onto it (undoing the rounding of the 2D union).
    snap: f64,
}

/// An empty mesh with `m`'s material slots and groups.
fn empty_like(m: &Mesh) -> Mesh {
    let mut out = Mesh::new();
    out.materials = m.materials.clone();
    out.groups = m.groups.clone();
    out.tags = m.tags.clone();
    for (d, s) in out.uvs.iter_mut().zip(&m.uvs) {
        if s.is_some() {
            *d = Some(Vec::new());
        }
    }
    if m.normals.is_some() {
        out.normals = Some(Vec::new());
    }
    out
}

// ----- BSP trees -----

#[derive(Clone, Copy, Debug)]
struct Plane {
    n: DVec3,
    w: f64,
}

impl Plane {
    fn flip(&mut self) {
        self.n = -self.n;
        self.w = -self.w;
    }
    fn dist(&self, p: DVec3) -> f64 {
        self.n.dot(p) - self.w
    }
}

#[derive(Clone, Debug)]
struct Poly {
    pts: Vec<DVec3>,
    plane: Plane,
    /// Index into the source faces (those of A, then those of B).
    src: u32,
    /// Still the whole triangle of the source face's triangulation.
    whole: bool,
    /// Reversed an odd number of times.
    flipped: bool,
}

impl Poly {
    fn flip(&mut self) {
        self.pts.reverse();
        self.plane.flip();
        self.flipped = !self.flipped;
    }
}

enum Split {
    Coplanar(Poly, bool),
    Front(Poly),
    Back(Poly),
    Spanning(Option<Poly>, Option<Poly>),
}

const COPLANAR: u8 = 0;
const FRONT: u8 = 1;
const BACK: u8 = 2;
const SPANNING: u8 = 3;

fn classify(d: f64, eps: f64) -> u8 {
    if d < -eps {
        BACK
    } else if d > eps {
        FRONT
    } else {
        COPLANAR
    }
}

/// Splits a convex polygon by a plane.
fn split(plane: &Plane, p: Poly, eps: f64) -> Split {
    let mut kind = 0u8;
    for &v in &p.pts {
        kind |= classify(plane.dist(v), eps);
    }
    match kind {
        COPLANAR => {
            let same = plane.n.dot(p.plane.n) > 0.0;
            Split::Coplanar(p, same)
        }
        FRONT => Split::Front(p),
        BACK => Split::Back(p),
        _ => {
            let n = p.pts.len();
            let mut f = Vec::with_capacity(n + 1);
            let mut b = Vec::with_capacity(n + 1);
            for i in 0..n {
                let j = (i + 1) % n;
                let (vi, vj) = (p.pts[i], p.pts[j]);
                let (di, dj) = (plane.dist(vi), plane.dist(vj));
                let (ti, tj) = (classify(di, eps), classify(dj, eps));
                if ti != BACK {
                    f.push(vi);
                }
                if ti != FRONT {
                    b.push(vi);
                }
                if ti | tj == SPANNING {
                    // Computed from the lexicographically smaller end, so
                    // that the neighbour sharing this edge (which walks it
                    // the other way) gets the very same point.
                    let v = if (vi.x, vi.y, vi.z) < (vj.x, vj.y, vj.z) {
                        vi.lerp(vj, di / (di - dj))
                    } else {
                        vj.lerp(vi, dj / (dj - di))
                    };
                    f.push(v);
                    b.push(v);
                }
            }
            let piece = |pts: Vec<DVec3>| {
                (pts.len() >= 3).then_some(Poly {
                    pts,
                    plane: p.plane,
                    src: p.src,
                    whole: false,
                    flipped: p.flipped,
                })
            };
            Split::Spanning(piece(f), piece(b))
        }
    }
}

const NONE: u32 = u32::MAX;

struct Node {
    plane: Option<Plane>,
    front: u32,
    back: u32,
    polys: Vec<Poly>,
}

/// A BSP tree in an arena (no recursion: deep trees cannot overflow the
/// stack). Its loops stop early once the clock says the deadline passed
/// (the caller then gives up: see [`Clock::check`]).
struct Bsp<'c> {
    nodes: Vec<Node>,
    eps: f64,
    clock: &'c Clock<'c>,
}

impl<'c> Bsp<'c> {
    fn new(polys: Vec<Poly>, eps: f64, clock: &'c Clock) -> Bsp<'c> {
        let mut t = Bsp {
            nodes: Vec::new(),
            eps,
            clock,
        };
        t.build(polys);
        t
    }

    fn new_node(&mut self) -> u32 {
        self.nodes.push(Node {
            plane: None,
            front: NONE,
            back: NONE,
            polys: Vec::new(),
        });
        self.nodes.len() as u32 - 1
    }

    fn build(&mut self, polys: Vec<Poly>) {
        if polys.is_empty() {
            return;
        }
        if self.nodes.is_empty() {
            self.new_node();
        }
        let mut stack = vec![(0u32, polys)];
        while let Some((ni, ps)) = stack.pop() {
            if self.clock.passed() {
                return;
            }
            let Some(first) = ps.first() else { continue };
            let plane = *self.nodes[ni as usize].plane.get_or_insert(first.plane);
            let (mut front, mut back) = (Vec::new(), Vec::new());
            for p in ps {
                match split(&plane, p, self.eps) {
                    Split::Coplanar(p, _) => self.nodes[ni as usize].polys.push(p),
                    Split::Front(p) => front.push(p),
                    Split::Back(p) => back.push(p),
                    Split::Spanning(f, b) => {
                        front.extend(f);
                        back.extend(b);
                    }
                }
            }
            if !front.is_empty() {
                let mut fi = self.nodes[ni as usize].front;
                if fi == NONE {
                    fi = self.new_node();
                    self.nodes[ni as usize].front = fi;
                }
                stack.push((fi, front));
            }
            if !back.is_empty() {
                let mut bi = self.nodes[ni as usize].back;
                if bi == NONE {
                    bi = self.new_node();
                    self.nodes[ni as usize].back = bi;
                }
                stack.push((bi, back));
            }
        }
    }

    /// Solid becomes empty space and the other way round.
    fn invert(&mut self) {
        for n in &mut self.nodes {
            if let Some(p) = &mut n.plane {
                p.flip();
            }
            for p in &mut n.polys {
                p.flip();
            }
            std::mem::swap(&mut n.front, &mut n.back);
        }
    }

    /// The parts of `polys` outside this tree's solid.
    fn clip_polygons(&self, polys: Vec<Poly>) -> Vec<Poly> {
        if self.nodes.is_empty() {
            return polys;
        }
        let mut out = Vec::new();
        let mut stack = vec![(0u32, polys)];
        while let Some((ni, ps)) = stack.pop() {
            if self.clock.passed() {
                break;
            }
            let node = &self.nodes[ni as usize];
            let Some(plane) = node.plane else {
                out.extend(ps);
                continue;
            };
            let (mut front, mut back) = (Vec::new(), Vec::new());
            for p in ps {
                match split(&plane, p, self.eps) {
                    Split::Coplanar(p, true) | Split::Front(p) => front.push(p),
                    Split::Coplanar(p, false) | Split::Back(p) => back.push(p),
                    Split::Spanning(f, b) => {
                        front.extend(f);
                        back.extend(b);
                    }
                }
            }
            if node.front != NONE {
                stack.push((node.front, front));
            } else {
                out.extend(front);
            }
            if node.back != NONE {
                stack.push((node.back, back));
            }
        }
        out
    }

    /// Removes the parts of this tree's polygons inside `other`'s solid.
    fn clip_to(&mut self, other: &Bsp) {
        for i in 0..self.nodes.len() {
            if self.clock.passed() {
                return;
            }
            let ps = std::mem::take(&mut self.nodes[i].polys);
            self.nodes[i].polys = other.clip_polygons(ps);
        }
    }

    fn into_polygons(self, out: &mut Vec<Poly>) {
        for n in self.nodes {
            out.extend(n.polys);
        }
    }
}

// ----- source faces -----

/// A face of an operand taking part in the operation.
struct SrcFace {
    /// 0: operand A, 1: operand B.
    operand: u8,
    face: u32,
    normal: DVec3,
    /// Plane offset along `normal`.
    w: f64,
    /// The face's triangles (corner indices of its mesh).
    tris: Vec<[u32; 3]>,
}

/// The triangles of every face of `mesh` as BSP polygons.
fn polygons(mesh: &Mesh, operand: u8, eps: f64, srcs: &mut Vec<SrcFace>) -> Vec<Poly> {
    let mut out = Vec::with_capacity(mesh.faces.len() * 2);
    let mut tris = Vec::new();
    for f in 0..mesh.faces.len() {
        let n = face_normal(mesh, f);
        if n == DVec3::ZERO || !n.is_finite() {
            continue;
        }
        tris.clear();
        triangulate_face(mesh, f, &mut tris);
        let outer = mesh.loop_indices(mesh.outer_loop(f));
        let w = outer
            .iter()
            .map(|&i| n.dot(mesh.positions[i as usize]))
            .sum::<f64>()
            / outer.len() as f64;
        let planar = mesh
            .face_loops(f)
            .iter()
            .flat_map(|&l| mesh.loop_indices(l))
            .all(|&i| (n.dot(mesh.positions[i as usize]) - w).abs() <= eps);
        let src = srcs.len() as u32;
        let mut kept = Vec::with_capacity(tris.len());
        for t in &tris {
            let pts: Vec<DVec3> = t
                .iter()
                .map(|&c| mesh.positions[mesh.corners[c as usize] as usize])
                .collect();
            let tn = (pts[1] - pts[0]).cross(pts[2] - pts[0]);
            let len = tn.length();
            if len.is_nan() || len <= eps * eps || !len.is_finite() {
                continue;
            }
            // Triangles of a planar face share its plane exactly, so that
            // coplanarity between them is never in doubt.
            let plane = if planar {
                Plane { n, w }
            } else {
                let tn = tn / len;
                Plane {
                    n: tn,
                    w: tn.dot(pts[0]),
                }
            };
            out.push(Poly {
                pts,
                plane,
                src,
                whole: true,
                flipped: false,
            });
            kept.push(*t);
        }
        if kept.is_empty() {
            continue;
        }
        srcs.push(SrcFace {
            operand,
            face: f as u32,
            normal: n,
            w,
            tris: kept,
        });
    }
    out
}

fn boolean_3d(
    a: &Mesh,
    b: &Mesh,
    op: BoolOp,
    tol: &Tol,
    clock: &Clock<'_>,
) -> Result<BoolResult, TimedOut> {
    let mut srcs = Vec::new();
    let pa = polygons(a, 0, tol.plane, &mut srcs);
    let pb = polygons(b, 1, tol.plane, &mut srcs);
    let mut ta = Bsp::new(pa, tol.plane, clock);
    let mut tb = Bsp::new(pb, tol.plane, clock);
    // The sequences of csg.js (Evan Wallace): clipping keeps what is outside
    // the other solid; inverting a tree turns its solid inside out.
    let flip_all = match op {
        BoolOp::Union => {
            ta.clip_to(&tb);
            tb.clip_to(&ta);
            tb.invert();
            tb.clip_to(&ta);
            tb.invert();
            false
        }
        BoolOp::Subtract => {
            ta.invert();
            ta.clip_to(&tb);
            tb.clip_to(&ta);
            tb.invert();
            tb.clip_to(&ta);
            tb.invert();
            true
        }
        BoolOp::Intersect => {
            ta.invert();
            tb.clip_to(&ta);
            tb.invert();
            ta.clip_to(&tb);
            tb.clip_to(&ta);
            true
        }
    };
    // A tree cut short is not the operation's result.
    clock.check()?;
    let mut polys = Vec::new();
    ta.into_polygons(&mut polys);
    tb.into_polygons(&mut polys);
    if flip_all {
        for p in &mut polys {
            p.flip();
        }
    }
    polys.sort_unstable_by_key(|p| p.src);
    let mut out = [empty_like(a), empty_like(b)];
    let mut scratch = Scratch::default();
    let mut i = 0;
    while i < polys.len() {
        let src = polys[i].src;
        let mut j = i;
        while j < polys.len() && polys[j].src == src {
            j += 1;
        }
        let group = &polys[i..j];
        i = j;
        let sf = &srcs[src as usize];
        let mesh = if sf.operand == 0 { a } else { b };
        let dst = &mut out[sf.operand as usize];
        let flipped = group[0].flipped;
        if group.len() == sf.tris.len() && group.iter().all(|p| p.whole && p.flipped == flipped) {
            copy_face(dst, mesh, sf.face as usize, flipped);
            continue;
        }
        // The fragments united in the plane of the face, in their current
        // orientation (all fragments of a face have the same).
        let n = if flipped { -sf.normal } else { sf.normal };
        let (u, v) = plane_basis(n);
        let loops = fragment_loops(group, u, v, tol.weld, &mut scratch.snap);
        let shapes = union_2d(&loops);
        let w = if flipped { -sf.w } else { sf.w };
        emit_shapes(
            dst,
            mesh,
            sf,
            &shapes,
            Frame2 { u, v, n, w },
            flipped,
            tol,
            &mut scratch,
        );
    }
    finish(out, tol, Vec::new(), clock)
}

/// The fragments of one face as 2D loops ready for their union: vertices
/// closer than `tol` welded (into `snap`, in 3D) and the vertices of other
/// fragments that lie on an edge inserted into it. Fragments meet at
/// T-junctions (one was split where its neighbour was not); the 2D union
/// rounds coordinates to integers, which would leave slivers between
/// edges that only nearly share their points.
fn fragment_loops(
    group: &[Poly],
    u: DVec3,
    v: DVec3,
    tol: f64,
    snap: &mut Vec<DVec3>,
) -> Vec<Vec<DVec2>> {
    let pts: Vec<DVec3> = group.iter().flat_map(|p| p.pts.iter().copied()).collect();
    let weld = weld_points(&pts, tol);
    snap.clear();
    snap.extend(weld.representative.iter().map(|&r| pts[r as usize]));
    let flat: Vec<DVec2> = snap
        .iter()
        .map(|q| DVec2::new(q.dot(u), q.dot(v)))
        .collect();
    let mut loops = Vec::with_capacity(group.len());
    let mut ids: Vec<u32> = Vec::new();
    let mut on_edge: Vec<(f64, u32)> = Vec::new();
    let mut k = 0;
    for p in group {
        ids.clear();
        for _ in 0..p.pts.len() {
            let id = weld.id[k];
            k += 1;
            if ids.last() != Some(&id) {
                ids.push(id);
            }
        }
        while ids.len() > 1 && ids.first() == ids.last() {
            ids.pop();
        }
        if ids.len() < 3 {
            continue;
        }
        let mut lp = Vec::with_capacity(ids.len() + 2);
        for i in 0..ids.len() {
            let (a, b) = (ids[i], ids[(i + 1) % ids.len()]);
            lp.push(flat[a as usize]);
            let (pa, pb) = (snap[a as usize], snap[b as usize]);
            let d = pb - pa;
            let len2 = d.length_squared();
            on_edge.clear();
            for (id, &q) in snap.iter().enumerate() {
                let id = id as u32;
                if id == a || id == b {
                    continue;
                }
                let t = (q - pa).dot(d) / len2;
                if t > 0.0 && t < 1.0 && (pa + d * t - q).abs().max_element() <= tol {
                    on_edge.push((t, id));
                }
            }
            on_edge.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
            lp.extend(on_edge.iter().map(|&(_, id)| flat[id as usize]));
        }
        loops.push(lp);
    }
    loops
}

/// Appends B's result to A's and stitches; `sources` names the faces of
/// A's result (missing entries: `A`), those of B's are `B`.
fn finish(
    out: [Mesh; 2],
    tol: &Tol,
    mut sources: Vec<FaceSource>,
    clock: &Clock<'_>,
) -> Result<BoolResult, TimedOut> {
    let [mut ma, mb] = out;
    sources.resize(ma.faces.len(), FaceSource::A);
    merge(&mut ma, &mb);
    sources.resize(ma.faces.len(), FaceSource::B);
    let keep = stitch(&mut ma, tol.weld, clock)?;
    let sources = sources
        .into_iter()
        .zip(keep)
        .filter_map(|(s, k)| k.then_some(s))
        .collect();
    Ok(BoolResult { mesh: ma, sources })
}

/// Copies face `f` of `src` into `dst` (same slots: `dst` was made by
/// [`empty_like`] of `src`), reversed if `flip`.
fn copy_face(dst: &mut Mesh, src: &Mesh, f: usize, flip: bool) {
    let face = src.faces[f];
    let first_loop = dst.loops.len() as u32;
    for &l in src.face_loops(f) {
        let r = src.loop_corners(l);
        let mut order: Vec<usize> = r.clone().collect();
        if flip && order.len() > 1 {
            order[1..].reverse();
        }
        let start = dst.corners.len() as u32;
        for &c in &order {
            dst.positions.push(src.positions[src.corners[c] as usize]);
            dst.corners.push(dst.positions.len() as u32 - 1);
            for (d, s) in dst.uvs.iter_mut().zip(&src.uvs) {
                if let (Some(d), Some(s)) = (d, s) {
                    d.push(s.get(c).copied().unwrap_or(DVec2::ZERO));
                }
            }
            if let (Some(d), Some(s)) = (&mut dst.normals, &src.normals) {
                let nv = s.get(c).copied().unwrap_or(DVec3::ZERO);
                d.push(if flip { -nv } else { nv });
            }
        }
        dst.loops.push(Loop {
            start,
            len: order.len() as u32,
        });
    }
    dst.faces.push(Face {
        first_loop,
        loop_count: dst.loops.len() as u32 - first_loop,
        material: face.material,
        group: face.group,
        tags: face.tags,
    });
}

#[derive(Default)]
struct Scratch {
    /// Points a merged face's corners are snapped to.
    snap: Vec<DVec3>,
    tris2: Vec<[DVec2; 3]>,
}

/// A plane with a basis: a 2D point (x, y) is at `u x + v y + n w`.
#[derive(Clone, Copy)]
struct Frame2 {
    u: DVec3,
    v: DVec3,
    n: DVec3,
    w: f64,
}

/// Adds the polygons `shapes` (2D, in `fr`) as faces of `dst` made from face
/// `sf` of `mesh`: its material and group, texture coordinates and normals
/// interpolated on its triangles; reversed attributes if `flipped`.
#[allow(clippy::too_many_arguments)]
fn emit_shapes(
    dst: &mut Mesh,
    mesh: &Mesh,
    sf: &SrcFace,
    shapes: &[Vec<Vec<DVec2>>],
    fr: Frame2,
    flipped: bool,
    tol: &Tol,
    scratch: &mut Scratch,
) {
    let face = mesh.faces[sf.face as usize];
    // The source triangles in the same 2D frame, for interpolation.
    scratch.tris2.clear();
    for t in &sf.tris {
        scratch.tris2.push(t.map(|c| {
            let p = mesh.positions[mesh.corners[c as usize] as usize];
            DVec2::new(p.dot(fr.u), p.dot(fr.v))
        }));
    }
    for shape in shapes {
        let first_loop = dst.loops.len() as u32;
        for lp in shape {
            if lp.len() < 3 {
                continue;
            }
            let start = dst.corners.len() as u32;
            for &q in lp {
                let mut p = fr.u * q.x + fr.v * q.y + fr.n * fr.w;
                if let Some(s) = nearest(&scratch.snap, p, tol.snap) {
                    p = s;
                }
                // The source triangle containing q (the one it is least
                // outside of) and q's barycentric coordinates in it.
                let mut best = (f64::NEG_INFINITY, 0usize, [1.0, 0.0, 0.0]);
                for (k, t) in scratch.tris2.iter().enumerate() {
                    if let Some(l) = barycentric(t, q) {
                        let m = l[0].min(l[1]).min(l[2]);
                        if m > best.0 {
                            best = (m, k, l);
                        }
                    }
                }
                let (_, k, l) = best;
                let corners = sf.tris.get(k).copied().unwrap_or([0, 0, 0]);
                dst.positions.push(p);
                dst.corners.push(dst.positions.len() as u32 - 1);
                for (d, s) in dst.uvs.iter_mut().zip(&mesh.uvs) {
                    if let (Some(d), Some(s)) = (d, s) {
                        let at = |i: usize| s.get(corners[i] as usize).copied().unwrap_or_default();
                        d.push(at(0) * l[0] + at(1) * l[1] + at(2) * l[2]);
                    }
                }
                if let (Some(d), Some(s)) = (&mut dst.normals, &mesh.normals) {
                    let at = |i: usize| s.get(corners[i] as usize).copied().unwrap_or_default();
                    let nv = (at(0) * l[0] + at(1) * l[1] + at(2) * l[2]).normalize_or_zero();
                    d.push(if flipped { -nv } else { nv });
                }
            }
            dst.loops.push(Loop {
                start,
                len: dst.corners.len() as u32 - start,
            });
        }
        let loop_count = dst.loops.len() as u32 - first_loop;
        if loop_count > 0 {
            dst.faces.push(Face {
                first_loop,
                loop_count,
                material: face.material,
                group: face.group,
                tags: face.tags,
            });
        }
    }
}

fn barycentric(t: &[DVec2; 3], q: DVec2) -> Option<[f64; 3]> {
    let (a, b, c) = (t[0], t[1], t[2]);
    let d = (b - a).perp_dot(c - a);
    if d.abs() < f64::MIN_POSITIVE || !d.is_finite() {
        return None;
    }
    let l1 = (q - a).perp_dot(c - a) / d;
    let l2 = (b - a).perp_dot(q - a) / d;
    Some([1.0 - l1 - l2, l1, l2])
}

/// The point of `pts` nearest to `p` within `tol` (per coordinate).
fn nearest(pts: &[DVec3], p: DVec3, tol: f64) -> Option<DVec3> {
    let mut best: Option<(f64, DVec3)> = None;
    for &s in pts {
        let d = (s - p).abs().max_element();
        if d <= tol && best.is_none_or(|(bd, _)| d < bd) {
            best = Some((d, s));
        }
    }
    best.map(|(_, s)| s)
}

type Shapes2 = Vec<Vec<Vec<DVec2>>>;

fn to_raw(loops: &[Vec<DVec2>]) -> Vec<Vec<[f64; 2]>> {
    loops
        .iter()
        .filter(|l| l.len() >= 3 && l.iter().all(|p| p.is_finite()))
        .map(|l| l.iter().map(|p| [p.x, p.y]).collect())
        .collect()
}

fn from_raw(shapes: Vec<Vec<Vec<[f64; 2]>>>) -> Shapes2 {
    shapes
        .into_iter()
        .map(|s| {
            s.into_iter()
                .map(|l| l.into_iter().map(|[x, y]| DVec2::new(x, y)).collect())
                .collect()
        })
        .collect()
}

/// The union of counter-clockwise loops (clockwise ones subtract):
/// polygons with holes, outer loops counter-clockwise, holes clockwise.
fn union_2d(loops: &[Vec<DVec2>]) -> Shapes2 {
    let raw = to_raw(loops);
    if raw.is_empty() {
        return Vec::new();
    }
    from_raw(raw.simplify_shape(FillRule::NonZero))
}

fn overlay_2d(subject: &[Vec<DVec2>], clip: &[Vec<DVec2>], rule: OverlayRule) -> Shapes2 {
    let (s, c) = (to_raw(subject), to_raw(clip));
    if s.is_empty() {
        return Vec::new();
    }
    if c.is_empty() {
        return match rule {
            OverlayRule::Intersect => Vec::new(),
            _ => union_2d(subject),
        };
    }
    let mut overlay = FloatOverlay::with_subj_and_clip(&s, &c);
    from_raw(overlay.overlay(rule, FillRule::NonZero))
}

fn shapes_area(shapes: &Shapes2) -> f64 {
    shapes
        .iter()
        .flatten()
        .map(|l| {
            let mut s = 0.0;
            for i in 0..l.len() {
                s += l[i].perp_dot(l[(i + 1) % l.len()]);
            }
            s / 2.0
        })
        .sum()
}

// ----- planar operands -----

/// The plane (normal, offset) all faces of both meshes lie in, if there is one.
fn common_plane(a: &Mesh, b: &Mesh, eps: f64) -> Option<(DVec3, f64)> {
    let f = (0..a.faces.len()).find(|&f| face_normal(a, f) != DVec3::ZERO)?;
    let n = face_normal(a, f);
    let p0 = a.positions[a.loop_indices(a.outer_loop(f))[0] as usize];
    let w = n.dot(p0);
    let on = |m: &Mesh| {
        m.corners
            .iter()
            .all(|&i| (n.dot(m.positions[i as usize]) - w).abs() <= eps)
    };
    (on(a) && on(b)).then_some((n, w))
}

/// The 2D loops of face `f` in the frame, each counter-clockwise when the
/// face faces the frame's normal.
fn face_loops_2d(m: &Mesh, f: usize, fr: &Frame2, out: &mut Vec<Vec<DVec2>>) {
    let reverse = face_normal(m, f).dot(fr.n) < 0.0;
    for &l in m.face_loops(f) {
        let mut lp: Vec<DVec2> = m
            .loop_points(l)
            .map(|p| DVec2::new(p.dot(fr.u), p.dot(fr.v)))
            .collect();
        if reverse {
            lp.reverse();
        }
        out.push(lp);
    }
}

fn boolean_2d(
    a: &Mesh,
    b: &Mesh,
    op: BoolOp,
    (n, w): (DVec3, f64),
    tol: &Tol,
    clock: &Clock<'_>,
) -> Result<BoolResult, TimedOut> {
    let (u, v) = plane_basis(n);
    let fr = Frame2 { u, v, n, w };
    let region = |m: &Mesh| {
        let mut loops = Vec::new();
        for f in 0..m.faces.len() {
            if face_normal(m, f) != DVec3::ZERO {
                face_loops_2d(m, f, &fr, &mut loops);
            }
        }
        loops
    };
    let (reg_a, reg_b) = (region(a), region(b));
    let mut out = [empty_like(a), empty_like(b)];
    let mut both = Vec::new();
    let mut scratch = Scratch::default();
    let mut srcs = Vec::new();
    let _ = polygons(a, 0, tol.plane, &mut srcs);
    let _ = polygons(b, 1, tol.plane, &mut srcs);
    let snap_all: Vec<DVec3> = a.positions.iter().chain(&b.positions).copied().collect();
    let small = tol.weld * tol.weld;
    for sf in &srcs {
        let (mesh, other) = if sf.operand == 0 {
            (a, &reg_b)
        } else {
            (b, &reg_a)
        };
        let f = sf.face as usize;
        let mut own = Vec::new();
        face_loops_2d(mesh, f, &fr, &mut own);
        // Faces facing away from the plane's normal are emitted reversed
        // back to their own orientation.
        let flipped = sf.normal.dot(n) < 0.0;
        let efr = if flipped {
            let (u2, v2) = plane_basis(-n);
            Frame2 {
                u: u2,
                v: v2,
                n: -n,
                w: -w,
            }
        } else {
            fr
        };
        let to_own = |s: Shapes2| -> Shapes2 {
            if !flipped {
                return s;
            }
            // Re-express in the reversed frame: 3D point, then (u2, v2).
            s.into_iter()
                .map(|shape| {
                    shape
                        .into_iter()
                        .map(|l| {
                            l.into_iter()
                                .map(|q| {
                                    let p = u * q.x + v * q.y;
                                    DVec2::new(p.dot(efr.u), p.dot(efr.v))
                                })
                                .collect()
                        })
                        .collect()
                })
                .collect()
        };
        let inside = overlay_2d(&own, other, OverlayRule::Intersect);
        let touched = shapes_area(&inside).abs() > small;
        let outside = || overlay_2d(&own, other, OverlayRule::Difference);
        scratch.snap.clear();
        scratch.snap.extend_from_slice(&snap_all);
        let dst = &mut out[sf.operand as usize];
        match (op, sf.operand) {
            (BoolOp::Union, 0) | (BoolOp::Subtract, 0) => {
                if !touched {
                    copy_face(dst, mesh, f, false);
                    continue;
                }
                let o = to_own(outside());
                emit_shapes(dst, mesh, sf, &o, efr, false, tol, &mut scratch);
                if op == BoolOp::Union {
                    // The overlap keeps A's face (material), and is both
                    // operands' face.
                    let before = dst.faces.len();
                    let i = to_own(inside);
                    emit_shapes(dst, mesh, sf, &i, efr, false, tol, &mut scratch);
                    both.extend(before..dst.faces.len());
                }
            }
            (BoolOp::Intersect, 0) => {
                let before = dst.faces.len();
                let i = to_own(inside);
                emit_shapes(dst, mesh, sf, &i, efr, false, tol, &mut scratch);
                both.extend(before..dst.faces.len());
            }
            (BoolOp::Union, _) => {
                if !touched {
                    copy_face(dst, mesh, f, false);
                    continue;
                }
                let o = to_own(outside());
                emit_shapes(dst, mesh, sf, &o, efr, false, tol, &mut scratch);
            }
            _ => {}
        }
    }
    let mut sources = vec![FaceSource::A; out[0].faces.len()];
    for f in both {
        sources[f] = FaceSource::Both;
    }
    finish(out, tol, sources, clock)
}

// ----- stitching -----

/// Welds vertices closer than `tol`, removes repeated corners and loops
/// without area, and inserts into every edge the vertices lying on it
/// (T-junctions), interpolating per-corner attributes. Returns, per input
/// face, whether it was kept.
fn stitch(mesh: &mut Mesh, tol: f64, clock: &Clock<'_>) -> Result<Vec<bool>, TimedOut> {
    let weld = weld_points(&mesh.positions, tol);
    let positions: Vec<DVec3> = weld
        .representative
        .iter()
        .map(|&r| mesh.positions[r as usize])
        .collect();
    // Vertices sorted by x, to find those near an edge.
    let mut by_x: Vec<u32> = (0..positions.len() as u32).collect();
    by_x.sort_unstable_by(|&i, &j| positions[i as usize].x.total_cmp(&positions[j as usize].x));
    let xs: Vec<f64> = by_x.iter().map(|&i| positions[i as usize].x).collect();

    let mut out = Mesh::new();
    out.materials = mesh.materials.clone();
    out.groups = mesh.groups.clone();
    out.tags = mesh.tags.clone();
    for (d, s) in out.uvs.iter_mut().zip(&mesh.uvs) {
        if s.is_some() {
            *d = Some(Vec::with_capacity(mesh.corners.len()));
        }
    }
    if mesh.normals.is_some() {
        out.normals = Some(Vec::with_capacity(mesh.corners.len()));
    }
    let mut keep = Vec::with_capacity(mesh.faces.len());
    let mut lp: Vec<usize> = Vec::new();
    let mut on_edge: Vec<(f64, u32)> = Vec::new();
    for f in 0..mesh.faces.len() {
        if clock.passed() {
            return Err(TimedOut);
        }
        let face = mesh.faces[f];
        let first_loop = out.loops.len() as u32;
        let mut outer_ok = false;
        for (k, &l) in mesh.face_loops(f).iter().enumerate() {
            // Corners without repeats (welded neighbours collapse).
            lp.clear();
            for c in mesh.loop_corners(l) {
                let id = weld.id[mesh.corners[c] as usize];
                if lp.last().map(|&p| weld.id[mesh.corners[p] as usize]) != Some(id) {
                    lp.push(c);
                }
            }
            while lp.len() > 1
                && weld.id[mesh.corners[lp[0]] as usize]
                    == weld.id[mesh.corners[lp[lp.len() - 1]] as usize]
            {
                lp.pop();
            }
            if lp.len() < 3 {
                if k == 0 {
                    break;
                }
                continue;
            }
            outer_ok |= k == 0;
            let start = out.corners.len() as u32;
            for i in 0..lp.len() {
                let (ca, cb) = (lp[i], lp[(i + 1) % lp.len()]);
                let ia = weld.id[mesh.corners[ca] as usize];
                let ib = weld.id[mesh.corners[cb] as usize];
                push_corner(&mut out, mesh, ia, ca, cb, 0.0);
                let (pa, pb) = (positions[ia as usize], positions[ib as usize]);
                let d = pb - pa;
                let len2 = d.length_squared();
                if len2 <= tol * tol {
                    continue;
                }
                on_edge.clear();
                let (lo, hi) = (pa.x.min(pb.x) - tol, pa.x.max(pb.x) + tol);
                let from = xs.partition_point(|&x| x < lo);
                for s in from..xs.len() {
                    if xs[s] > hi {
                        break;
                    }
                    let id = by_x[s];
                    if id == ia || id == ib {
                        continue;
                    }
                    let p = positions[id as usize];
                    let t = (p - pa).dot(d) / len2;
                    if t <= 0.0 || t >= 1.0 {
                        continue;
                    }
                    if (pa + d * t - p).abs().max_element() <= tol {
                        on_edge.push((t, id));
                    }
                }
                on_edge.sort_unstable_by(|x, y| x.0.total_cmp(&y.0));
                for &(t, id) in &on_edge {
                    push_corner(&mut out, mesh, id, ca, cb, t);
                }
            }
            out.loops.push(Loop {
                start,
                len: out.corners.len() as u32 - start,
            });
        }
        // A face whose outer loop collapsed is dropped with its holes
        // (nothing of it was pushed).
        if outer_ok {
            out.faces.push(Face {
                first_loop,
                loop_count: out.loops.len() as u32 - first_loop,
                material: face.material,
                group: face.group,
                tags: face.tags,
            });
        }
        keep.push(outer_ok);
    }
    out.positions = positions;
    *mesh = out;
    Ok(keep)
}

/// Pushes a corner at vertex `id` with the attributes of corner `ca` of
/// `src` interpolated towards corner `cb` by `t`.
fn push_corner(out: &mut Mesh, src: &Mesh, id: u32, ca: usize, cb: usize, t: f64) {
    out.corners.push(id);
    for (d, s) in out.uvs.iter_mut().zip(&src.uvs) {
        if let (Some(d), Some(s)) = (d, s) {
            let (a, b) = (
                s.get(ca).copied().unwrap_or_default(),
                s.get(cb).copied().unwrap_or_default(),
            );
            d.push(a.lerp(b, t));
        }
    }
    if let (Some(d), Some(s)) = (&mut out.normals, &src.normals) {
        let (a, b) = (
            s.get(ca).copied().unwrap_or_default(),
            s.get(cb).copied().unwrap_or_default(),
        );
        d.push(if t == 0.0 {
            a
        } else {
            a.lerp(b, t).normalize_or_zero()
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::Material;
    use crate::measure::{face_area, is_closed, mesh_area, volume};
    use crate::primitive;
    use glam::DAffine3;
    use proptest::prelude::*;

    fn boxm(lo: DVec3, size: DVec3) -> Mesh {
        let mut m = primitive::cube(size);
        m.map_positions(|p| p + lo);
        m
    }

    #[test]
    fn a_passed_deadline_gives_up_and_a_later_one_does_not() {
        let a = boxm(DVec3::ZERO, DVec3::ONE * 2.0);
        let b = boxm(DVec3::ONE, DVec3::ONE * 2.0);
        let past = Instant::now();
        for op in [BoolOp::Union, BoolOp::Subtract, BoolOp::Intersect] {
            let at = |deadline| Stop {
                deadline: Some(deadline),
                cancel: None,
            };
            assert_eq!(boolean_within(&a, &b, op, at(past)).err(), Some(TimedOut));
            let later = Instant::now() + std::time::Duration::from_secs(3600);
            let r = boolean_within(&a, &b, op, at(later)).unwrap();
            assert_eq!(r.mesh.faces.len(), boolean(&a, &b, op).mesh.faces.len());
        }
    }

    #[test]
    fn a_set_cancel_flag_gives_up() {
        let a = boxm(DVec3::ZERO, DVec3::ONE * 2.0);
        let b = boxm(DVec3::ONE, DVec3::ONE * 2.0);
        let flag = AtomicBool::new(true);
        let stop = Stop {
            deadline: None,
            cancel: Some(&flag),
        };
        assert_eq!(
            boolean_within(&a, &b, BoolOp::Union, stop).err(),
            Some(TimedOut)
        );
        flag.store(false, std::sync::atomic::Ordering::Relaxed);
        assert!(boolean_within(&a, &b, BoolOp::Union, stop).is_ok());
    }

    fn unit_at(lo: f64) -> Mesh {
        boxm(DVec3::splat(lo), DVec3::ONE)
    }

    fn with_color(mut m: Mesh, name: &str) -> Mesh {
        let mat = Material {
            name: name.into(),
            ..Material::default()
        };
        m.materials = vec![mat].into();
        m
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() <= 1e-9 * (1.0 + a.abs().max(b.abs()))
    }

    fn check(r: &BoolResult, vol: f64) {
        assert_eq!(r.sources.len(), r.mesh.faces.len());
        if vol > 0.0 {
            assert!(is_closed(&r.mesh), "result is not closed");
        } else {
            assert!(r.mesh.faces.is_empty(), "{} faces left", r.mesh.faces.len());
        }
        let v = volume(&r.mesh);
        assert!(close(v, vol), "volume {v}, expected {vol}");
    }

    fn bounds_of(m: &Mesh) -> (DVec3, DVec3) {
        bounds(m).expect("empty")
    }

    #[test]
    fn overlapping_unit_cubes() {
        let (a, b) = (unit_at(0.0), unit_at(0.5));
        let u = boolean(&a, &b, BoolOp::Union);
        check(&u, 1.875);
        assert_eq!(bounds_of(&u.mesh), (DVec3::ZERO, DVec3::splat(1.5)));
        // Three faces of each cube are whole; three of each are L-shaped
        // (the corner of the other cube cut out).
        assert_eq!(u.mesh.faces.len(), 12);
        assert!(close(mesh_area(&u.mesh), 2.0 * (6.0 - 0.75)));
        let i = boolean(&a, &b, BoolOp::Intersect);
        check(&i, 0.125);
        assert_eq!(i.mesh.faces.len(), 6);
        assert_eq!(bounds_of(&i.mesh), (DVec3::splat(0.5), DVec3::ONE));
        let s = boolean(&a, &b, BoolOp::Subtract);
        check(&s, 0.875);
        // 3 whole faces + 3 L-shaped of A, 3 quarter faces of B inside A.
        assert_eq!(s.mesh.faces.len(), 9);
        assert_eq!(s.sources.iter().filter(|s| **s == FaceSource::B).count(), 3);
        let r = boolean(&b, &a, BoolOp::Subtract);
        check(&r, 0.875);
    }

    #[test]
    fn faces_keep_their_operand_material() {
        let a = with_color(unit_at(0.0), "blue");
        let b = with_color(unit_at(0.5), "green");
        let s = boolean(&a, &b, BoolOp::Subtract);
        for (f, src) in s.mesh.faces.iter().zip(&s.sources) {
            let name = &*s.mesh.materials[f.material as usize].name;
            match src {
                FaceSource::A => assert_eq!(name, "blue"),
                _ => assert_eq!(name, "green"),
            }
        }
        // The faces of B left are its low faces (x, y, z = 0.5), reversed: they
        // face away from the remaining solid of A, towards +x, +y or +z.
        let b_faces: Vec<usize> = (0..s.mesh.faces.len())
            .filter(|&f| s.sources[f] == FaceSource::B)
            .collect();
        for f in b_faces {
            let n = face_normal(&s.mesh, f);
            assert!(close(n.max_element(), 1.0), "normal {n}");
            assert!(close(face_area(&s.mesh, f), 0.25));
        }
    }

    #[test]
    fn disjoint_cubes() {
        let (a, b) = (unit_at(0.0), unit_at(3.0));
        let u = boolean(&a, &b, BoolOp::Union);
        check(&u, 2.0);
        assert_eq!(u.mesh.faces.len(), 12);
        check(&boolean(&a, &b, BoolOp::Intersect), 0.0);
        let s = boolean(&a, &b, BoolOp::Subtract);
        check(&s, 1.0);
        assert_eq!(s.mesh, a);
    }

    #[test]
    fn touching_cubes_unite_without_the_shared_face() {
        let a = unit_at(0.0);
        let b = boxm(DVec3::new(1.0, 0.0, 0.0), DVec3::ONE);
        let u = boolean(&a, &b, BoolOp::Union);
        check(&u, 2.0);
        // 5 faces of each; the touching faces are gone.
        assert_eq!(u.mesh.faces.len(), 10);
        assert!(close(mesh_area(&u.mesh), 10.0));
        check(&boolean(&a, &b, BoolOp::Intersect), 0.0);
        let s = boolean(&a, &b, BoolOp::Subtract);
        check(&s, 1.0);
        assert_eq!(s.mesh.faces.len(), 6);
    }

    #[test]
    fn identical_cubes() {
        let a = with_color(unit_at(0.0), "blue");
        let b = with_color(unit_at(0.0), "green");
        let u = boolean(&a, &b, BoolOp::Union);
        check(&u, 1.0);
        assert_eq!(u.mesh.faces.len(), 6);
        // Coinciding faces are taken from the first operand.
        assert!(u.sources.iter().all(|s| *s == FaceSource::A));
        assert!(u
            .mesh
            .faces
            .iter()
            .all(|f| &*u.mesh.materials[f.material as usize].name == "blue"));
        let i = boolean(&a, &b, BoolOp::Intersect);
        check(&i, 1.0);
        assert!(i.sources.iter().all(|s| *s == FaceSource::A));
        check(&boolean(&a, &b, BoolOp::Subtract), 0.0);
    }

    #[test]
    fn contained_cube() {
        let a = boxm(DVec3::ZERO, DVec3::splat(2.0));
        let b = boxm(DVec3::splat(0.5), DVec3::ONE);
        let u = boolean(&a, &b, BoolOp::Union);
        check(&u, 8.0);
        assert_eq!(u.mesh.faces.len(), 6);
        let s = boolean(&a, &b, BoolOp::Subtract);
        check(&s, 7.0);
        assert_eq!(s.mesh.faces.len(), 12);
        assert!(close(mesh_area(&s.mesh), 24.0 + 6.0));
        let i = boolean(&a, &b, BoolOp::Intersect);
        check(&i, 1.0);
        assert!(i.sources.iter().all(|s| *s == FaceSource::B));
        // B inside A: nothing left of B minus A.
        check(&boolean(&b, &a, BoolOp::Subtract), 0.0);
    }

    #[test]
    fn cut_faces_keep_their_texture_coordinates() {
        // A 2x2x2 box whose UVs are the unit square on every face: after
        // cutting a corner away, every corner's UV is still the linear
        // function of its position on its face.
        let a = boxm(DVec3::ZERO, DVec3::splat(2.0));
        let b = unit_at(1.5);
        let s = boolean(&a, &b, BoolOp::Subtract);
        check(&s, 8.0 - 0.125);
        let uvs = s.mesh.uvs[0].as_ref().expect("uv set 0");
        // The top face (y = 2, normal +y) of A: u along +x, v along -z
        // (corners 4 5 6 7 = (0,2,2) (2,2,2) (2,2,0) (0,2,0)).
        let top = (0..s.mesh.faces.len())
            .find(|&f| s.sources[f] == FaceSource::A && face_normal(&s.mesh, f).y > 0.5)
            .expect("top face");
        assert!(close(face_area(&s.mesh, top), 4.0 - 0.25));
        for c in s.mesh.loop_corners(s.mesh.outer_loop(top)) {
            let p = s.mesh.positions[s.mesh.corners[c] as usize];
            let uv = uvs[c];
            assert!(
                close(uv.x, p.x / 2.0) && close(uv.y, 1.0 - p.z / 2.0),
                "{p} {uv}"
            );
        }
    }

    #[test]
    fn a_plane_through_a_cube_is_a_half_space() {
        // A quad crossing the cube at y = 0.5, normal up: everything below
        // is inside it. The union is the quad with the cube's section cut
        // out, and the upper half of the cube.
        let a = unit_at(0.0);
        let mut b = primitive::quad(11.0, 11.0);
        b.map_positions(|p| p + DVec3::new(-5.0, 0.5, -5.0));
        let u = boolean(&a, &b, BoolOp::Union);
        assert!(close(mesh_area(&u.mesh), 121.0 - 1.0 + 1.0 + 4.0 * 0.5));
        assert_eq!(bounds_of(&u.mesh).0.y, 0.5);
        // Minus the plane: the upper half, closed by the quad's piece.
        let s = boolean(&a, &b, BoolOp::Subtract);
        check(&s, 0.5);
        assert_eq!(s.mesh.faces.len(), 6);
        let i = boolean(&a, &b, BoolOp::Intersect);
        check(&i, 0.5);
        assert_eq!(bounds_of(&i.mesh), (DVec3::ZERO, DVec3::new(1.0, 0.5, 1.0)));
        // A plane minus a volume: the plane with a hole, plus the cube's
        // faces below it (the part of the cube in the plane's half-space).
        let p = boolean(&b, &a, BoolOp::Subtract);
        assert!(close(mesh_area(&p.mesh), 121.0 - 1.0 + 1.0 + 4.0 * 0.5));
        let plane_faces = p.sources.iter().filter(|s| **s == FaceSource::A).count();
        assert_eq!(plane_faces, 1);
        assert_eq!(crate::measure::hole_count(&p.mesh), 1);
    }

    #[test]
    fn coplanar_quad_and_disk_in_2d() {
        let a = with_color(primitive::quad(4.0, 4.0), "blue");
        let mut b = with_color(primitive::disk(16, 4.0, 4.0), "green");
        b.map_positions(|p| p + DVec3::new(2.0, 0.0, 2.0));
        let disk_area = face_area(&b, 0);
        let overlap = disk_area / 4.0;
        let u = boolean(&a, &b, BoolOp::Union);
        // A outside B, A inside B, B outside A.
        assert_eq!(u.mesh.faces.len(), 3);
        assert_eq!(
            u.sources,
            vec![FaceSource::A, FaceSource::Both, FaceSource::B]
        );
        assert!(close(mesh_area(&u.mesh), 16.0 + disk_area - overlap));
        let names: Vec<&str> = u
            .mesh
            .faces
            .iter()
            .map(|f| &*u.mesh.materials[f.material as usize].name)
            .collect();
        assert_eq!(names, vec!["blue", "blue", "green"]);
        assert!((0..3).all(|f| close(face_normal(&u.mesh, f).y, 1.0)));
        let s = boolean(&a, &b, BoolOp::Subtract);
        assert_eq!(s.mesh.faces.len(), 1);
        assert!(close(mesh_area(&s.mesh), 16.0 - overlap));
        let i = boolean(&a, &b, BoolOp::Intersect);
        assert_eq!(i.mesh.faces.len(), 1);
        assert!(close(mesh_area(&i.mesh), overlap));
        assert_eq!(
            &*i.mesh.materials[i.mesh.faces[0].material as usize].name,
            "blue"
        );
    }

    /// vol(A∪B) + vol(A∩B) = vol(A) + vol(B) and vol(A−B) = vol(A) − vol(A∩B),
    /// with closed results (the union only if `manifold_union`: solids
    /// touching along an edge unite into a surface whose edge four faces use).
    fn identities(a: &Mesh, b: &Mesh) -> (f64, f64, f64) {
        identities_with(a, b, true)
    }

    fn identities_with(a: &Mesh, b: &Mesh, manifold_union: bool) -> (f64, f64, f64) {
        let (va, vb) = (volume(a), volume(b));
        let u = boolean(a, b, BoolOp::Union);
        let i = boolean(a, b, BoolOp::Intersect);
        let s = boolean(a, b, BoolOp::Subtract);
        let (vu, vi, vs) = (volume(&u.mesh), volume(&i.mesh), volume(&s.mesh));
        let tol = 1e-7 * (1.0 + va + vb);
        assert!(
            (vu + vi - va - vb).abs() <= tol,
            "union {vu} + {vi} vs {va} + {vb}"
        );
        assert!(
            (vs - (va - vi)).abs() <= tol,
            "subtract {vs} vs {va} - {vi}"
        );
        for (name, r, v) in [
            ("union", &u, vu),
            ("intersect", &i, vi),
            ("subtract", &s, vs),
        ] {
            if v > tol && (manifold_union || name != "union") {
                assert!(is_closed(&r.mesh), "{name} is not closed");
            }
        }
        (vu, vi, vs)
    }

    #[test]
    fn primitives_cube_sphere_cylinder() {
        let cube = boxm(DVec3::ZERO, DVec3::splat(2.0));
        let mut sphere = primitive::sphere(16, 8, DVec3::splat(2.0));
        sphere.map_positions(|p| p + DVec3::splat(0.7));
        let mut cyl = primitive::cylinder(12, DVec3::new(1.0, 4.0, 1.0));
        cyl.map_positions(|p| p + DVec3::new(0.3, -1.0, 0.6));
        let (_, vi, _) = identities(&cube, &sphere);
        assert!(vi > 0.5 && vi < volume(&sphere));
        let (_, vi, vs) = identities(&cube, &cyl);
        // The cylinder goes through the cube: its middle 2 of 4 length units.
        assert!(close(vi, volume(&cyl) / 2.0), "{vi}");
        assert!(close(vs, 8.0 - volume(&cyl) / 2.0));
        identities(&sphere, &cyl);
        identities(&cyl, &sphere);
        // A rotated cube.
        let mut rot = boxm(DVec3::splat(-0.8), DVec3::splat(1.6));
        let m = DAffine3::from_translation(DVec3::splat(1.5))
            * DAffine3::from_rotation_y(0.4)
            * DAffine3::from_rotation_x(0.3);
        rot.map_positions(|p| m.transform_point3(p));
        identities(&cube, &rot);
        identities(&rot, &sphere);
    }

    /// A cube minus a cylinder through its corner: the cube's cut faces
    /// come back as one polygon each (not the BSP's fragments).
    #[test]
    fn cut_faces_are_merged_into_one_polygon() {
        let a = primitive::cube(DVec3::splat(10.0));
        let mut b = primitive::cylinder(16, DVec3::splat(10.0));
        b.map_positions(|p| p + DVec3::splat(3.0));
        let r = boolean(&a, &b, BoolOp::Subtract);
        // A: bottom, top, 2 cut sides, 2 whole sides... the top and the
        // sides x = 10 and z = 10 are cut, the bottom and the two other
        // sides are whole. B: the bottom cap and the 7 side quads (of 22.5
        // degrees, vertices half a step off the axes) that reach into the
        // cube, over the 137 degrees of the ring inside it.
        let from_a = r.sources.iter().filter(|s| **s == FaceSource::A).count();
        assert_eq!(from_a, 6);
        assert_eq!(r.mesh.faces.len() - from_a, 8);
        assert!(is_closed(&r.mesh));
        let top = (0..r.mesh.faces.len())
            .find(|&f| r.sources[f] == FaceSource::A && face_normal(&r.mesh, f).y > 0.5)
            .expect("top");
        let cap = (0..r.mesh.faces.len())
            .find(|&f| r.sources[f] == FaceSource::B && face_normal(&r.mesh, f).y > 0.5)
            .expect("cap");
        assert!(close(
            face_area(&r.mesh, top) + face_area(&r.mesh, cap),
            100.0
        ));
        assert!(close(
            volume(&r.mesh),
            1000.0 - 7.0 * face_area(&r.mesh, cap)
        ));
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 60, .. ProptestConfig::default() })]

        #[test]
        fn random_boxes(
            lo_a in prop::array::uniform3(-3.0f64..3.0),
            sz_a in prop::array::uniform3(0.2f64..4.0),
            lo_b in prop::array::uniform3(-3.0f64..3.0),
            sz_b in prop::array::uniform3(0.2f64..4.0),
        ) {
            let (la, sa) = (DVec3::from(lo_a), DVec3::from(sz_a));
            let (lb, sb) = (DVec3::from(lo_b), DVec3::from(sz_b));
            let overlap = (la + sa).min(lb + sb) - la.max(lb);
            let vi_exact = overlap.max(DVec3::ZERO).element_product();
            let (vu, vi, vs) = identities(&boxm(la, sa), &boxm(lb, sb));
            let tol = 1e-7 * (1.0 + sa.element_product() + sb.element_product());
            prop_assert!((vi - vi_exact).abs() <= tol);
            prop_assert!((vu - (sa.element_product() + sb.element_product() - vi_exact)).abs() <= tol);
            prop_assert!((vs - (sa.element_product() - vi_exact)).abs() <= tol);
        }

        /// Boxes on an integer grid: coplanar and touching faces, shared
        /// edges and corners everywhere.
        #[test]
        fn grid_boxes(
            lo_a in prop::array::uniform3(0i32..4),
            sz_a in prop::array::uniform3(1i32..4),
            lo_b in prop::array::uniform3(0i32..4),
            sz_b in prop::array::uniform3(1i32..4),
        ) {
            let f = |v: [i32; 3]| DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64);
            let (la, sa, lb, sb) = (f(lo_a), f(sz_a), f(lo_b), f(sz_b));
            let overlap = (la + sa).min(lb + sb) - la.max(lb);
            let vi_exact = overlap.max(DVec3::ZERO).element_product();
            // Boxes in contact along an edge or at a corner only.
            let thin = overlap.cmpge(DVec3::ZERO).all()
                && overlap.to_array().iter().filter(|&&d| d > 0.0).count() < 2;
            let (_, vi, _) = identities_with(&boxm(la, sa), &boxm(lb, sb), !thin);
            prop_assert!((vi - vi_exact).abs() <= 1e-9);
        }
    }
}
