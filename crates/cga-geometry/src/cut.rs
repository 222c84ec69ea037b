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
//!
//! # Speed
//!
//! Typical calls are small (a building mass into floors, a facade into
//! tiles) and frequent, so the cut allocates nothing but its output: all
//! working arrays live in a per-thread `Bufs` reused from call to call
//! (freed when a huge input made them grow past a bound), pieces are ranges
//! of flat arrays, pieces above a plane wait on an explicit stack instead of
//! a recursion, crossing vertices are found in an open-addressing table
//! cleared in constant time, and cap edges are matched by sorting instead of
//! hashing. The common split (a polygon without holes crossing the plane at
//! two edges, no vertex on it: every convex face) takes a direct path,
//! `Cutter::split_simple`, that gives exactly the general path's result;
//! the tests compare both. `benches/cut.rs` measures the typical calls.

use std::cell::RefCell;

use glam::{DVec2, DVec3};

use crate::measure::face_normal;
use crate::mesh::{Face, Loop, Mesh};
use crate::topology::{mesh_tolerance, weld_points_into};
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
    // The working buffers of the cut are kept per thread and reused: a
    // split of a box into floors is a few microseconds of arithmetic, and
    // allocating its dozens of small buffers anew each time cost several
    // times that. `try_with` fails only while the thread shuts down, and
    // `try_borrow_mut` never fails (nothing here calls back into a cut);
    // both fall back to fresh buffers rather than panic.
    let run = |bufs: &mut Bufs| {
        let mut cutter = Cutter::new(mesh, normal, offsets, bufs);
        cutter.run();
        let out = cutter.build();
        bufs.trim();
        out
    };
    SCRATCH
        .try_with(|cell| match cell.try_borrow_mut() {
            Ok(mut bufs) => run(&mut bufs),
            Err(_) => run(&mut Bufs::default()),
        })
        .unwrap_or_else(|_| run(&mut Bufs::default()))
}

thread_local! {
    static SCRATCH: RefCell<Bufs> = RefCell::new(Bufs::default());
}

/// An empty mesh with the same material slots and groups as `mesh`.
fn empty_like(mesh: &Mesh) -> Mesh {
    // Not `Mesh::new()`: its default material would be built only to be
    // replaced.
    Mesh {
        positions: Vec::new(),
        corners: Vec::new(),
        loops: Vec::new(),
        faces: Vec::new(),
        uvs: Default::default(),
        normals: None,
        materials: mesh.materials.clone(),
        groups: mesh.groups.clone(),
        tags: mesh.tags.clone(),
        edge_tags: None,
        vertex_tags: None,
    }
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
    fn loop_slice(&self, k: usize) -> &[WCorner] {
        let (s, n) = self.loops[k];
        &self.corners[s as usize..(s + n) as usize]
    }
}

/// Polygons waiting to be routed from plane `k` on, last in first out:
/// `polys` holds `(first loop, loop count, k)` into `loops`, whose corner
/// ranges index `corners`. The top polygon's loops and corners are always
/// at the ends of the arrays, so popping it truncates them.
#[derive(Default)]
struct PolyStack {
    corners: Vec<WCorner>,
    loops: Vec<(u32, u32)>,
    polys: Vec<(u32, u32, u32)>,
}

/// The pieces of one split: loops in `corners`, each on a side (0 below,
/// 1 above) and owned by a piece (or, for a hole not yet placed, none).
#[derive(Default)]
struct Pieces {
    corners: Vec<WCorner>,
    loops: Vec<PieceLoop>,
    /// Per piece: its side and its outer loop (index into `loops`).
    pieces: Vec<(u8, u32)>,
}

#[derive(Clone, Copy)]
struct PieceLoop {
    start: u32,
    len: u32,
    side: u8,
    owner: u32,
}

impl Pieces {
    fn clear(&mut self) {
        self.corners.clear();
        self.loops.clear();
        self.pieces.clear();
    }
    fn corners_of(&self, l: usize) -> &[WCorner] {
        let pl = self.loops[l];
        &self.corners[pl.start as usize..(pl.start + pl.len) as usize]
    }
    /// A loop appended to `corners` from `start` on, not yet owned.
    fn add_loop(&mut self, start: usize, side: usize) -> usize {
        self.loops.push(PieceLoop {
            start: start as u32,
            len: (self.corners.len() - start) as u32,
            side: side as u8,
            owner: NONE,
        });
        self.loops.len() - 1
    }
    /// Makes loop `l` the outer loop of a new piece.
    fn add_piece(&mut self, l: usize) {
        let p = self.pieces.len() as u32;
        self.loops[l].owner = p;
        self.pieces.push((self.loops[l].side, l as u32));
    }
    /// The loops of piece `p`: its outer loop, then its holes in the order
    /// they were given to it.
    fn piece_loops(&self, p: usize) -> impl Iterator<Item = usize> + '_ {
        let outer = self.pieces[p].1 as usize;
        std::iter::once(outer).chain(
            (0..self.loops.len()).filter(move |&l| l != outer && self.loops[l].owner == p as u32),
        )
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

/// How [`Cutter::split_simple`] came out.
enum Simple {
    NotApplicable,
    /// The piece below is stored; the piece above, if it has area
    /// (`above`), is in `cur`.
    Done {
        above: bool,
    },
}

#[cfg(test)]
thread_local! {
    /// Set by tests to run the general path only, to compare with it.
    static GENERAL_PATH_ONLY: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    /// Number of splits done by [`Cutter::split_simple`], for tests.
    static SIMPLE_SPLITS: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

#[cfg(test)]
fn count_simple_split() {
    SIMPLE_SPLITS.with(|c| c.set(c.get() + 1));
}

#[cfg(not(test))]
#[inline(always)]
fn count_simple_split() {}

#[cfg(test)]
fn fast_paths_enabled() -> bool {
    !GENERAL_PATH_ONLY.with(|g| g.get())
}

#[cfg(not(test))]
#[inline(always)]
fn fast_paths_enabled() -> bool {
    true
}

/// How a split came out.
enum Split {
    /// The pieces are in `Bufs::pieces`.
    Pieces,
    /// The polygon could not be split consistently and stays whole on one
    /// side (`true`: above).
    Whole(bool),
}

/// Crossing vertices by (welded edge, plane): a hash table with open
/// addressing in reused memory. Cleared in constant time by stamping slots
/// with a generation: a slot of another generation is empty. (A general
/// hash map costs several times as much per lookup here, where a box split
/// into floors does little else than look up its crossings.)
#[derive(Default)]
struct CrossingTable {
    /// (edge key, plane, vertex, generation); the length is 0 or a power
    /// of two.
    slots: Vec<(u64, u32, u32, u32)>,
    generation: u32,
    len: usize,
}

impl CrossingTable {
    fn clear(&mut self) {
        self.len = 0;
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            // Wrapped around: stamps of old generations could look current.
            for s in &mut self.slots {
                s.3 = 0;
            }
            self.generation = 1;
        }
    }

    #[inline]
    fn home(&self, key: u64, plane: u32) -> usize {
        // Every bit of key and plane must reach the low bits that index the
        // table: an edge crossed by thousands of planes (a box split into
        // thousands of floors) would otherwise pile into one probe run and
        // make the cut quadratic. (The splitmix64 finalizer.)
        let mut h = key ^ (plane as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15);
        h = (h ^ (h >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        h = (h ^ (h >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        (h ^ (h >> 31)) as usize & (self.slots.len() - 1)
    }

    /// The vertex stored for (`key`, `plane`), or the slot to insert it at
    /// (valid until the next insertion).
    fn find(&mut self, key: u64, plane: u32) -> Result<u32, usize> {
        if 2 * (self.len + 1) > self.slots.len() {
            self.grow();
        }
        let mask = self.slots.len() - 1;
        let mut i = self.home(key, plane);
        loop {
            let s = self.slots[i];
            if s.3 != self.generation {
                return Err(i);
            }
            if s.0 == key && s.1 == plane {
                return Ok(s.2);
            }
            i = (i + 1) & mask;
        }
    }

    fn insert_at(&mut self, slot: usize, key: u64, plane: u32, v: u32) {
        self.slots[slot] = (key, plane, v, self.generation);
        self.len += 1;
    }

    fn grow(&mut self) {
        let old = std::mem::take(&mut self.slots);
        let generation = self.generation;
        self.slots = vec![(0, 0, 0, 0); (old.len() * 2).max(64)];
        self.generation = 1;
        self.len = 0;
        for s in old {
            if s.3 == generation {
                if let Err(i) = self.find(s.0, s.1) {
                    self.insert_at(i, s.0, s.1, s.2);
                }
            }
        }
    }
}

/// Every buffer a cut needs, kept between calls (see
/// [`split_by_parallel_planes`]). Each call clears what it uses; nothing
/// carries meaning from one call to the next.
#[derive(Default)]
struct Bufs {
    planes: Vec<f64>,
    /// Welded vertex id of each original position.
    vid: Vec<u32>,
    /// Original position of each welded vertex.
    rep: Vec<u32>,
    /// Vertex pool: welded positions, then crossing vertices.
    verts: Vec<DVec3>,
    /// Crossing vertices by (welded edge ends, plane).
    crossings: CrossingTable,
    /// Routed faces with their part, in routing order.
    items: Vec<(u32, Item)>,
    /// `items` sorted by part (stably): part `p` is
    /// `part_items[part_start[p]..part_start[p + 1]]`.
    part_items: Vec<Item>,
    part_start: Vec<u32>,
    store_corners: Vec<WCorner>,
    store_loops: Vec<(u32, u32)>,
    pieces_rec: Vec<PieceRec>,
    /// The polygon being routed.
    cur: Poly,
    stack: PolyStack,
    /// The result of the last split.
    pieces: Pieces,
    split: SplitBufs,
    caps: CapBufs,
    build: BuildBufs,
}

#[derive(Default)]
struct SplitBufs {
    xs: Vec<Crossing>,
    order: Vec<u32>,
    partner: Vec<u32>,
    at_edge: Vec<u32>,
    visited: Vec<bool>,
    traced: Vec<WCorner>,
    online: Vec<(f64, WCorner)>,
    /// Per vertex id: position in the loop being split, or NONE.
    slot: Vec<u32>,
    cleaned: Vec<WCorner>,
    pinch: Vec<WCorner>,
}

#[derive(Default)]
struct CapBufs {
    /// On-plane directed edges: (undirected key, first-seen rank, +1 if
    /// stored from the lower id, face).
    seen: Vec<(u64, u32, i32, u32)>,
    /// Net count per undirected edge: (first-seen rank, key, count, face).
    net: Vec<(u32, u64, i32, u32)>,
    /// Unmatched directed edges (start, end, face).
    edges: Vec<(u32, u32, u32)>,
    by_start: Vec<u32>,
    used: Vec<bool>,
    /// Closed loops: vertex ids in `loop_verts`, (start, len, face, area).
    loop_verts: Vec<u32>,
    loops: Vec<(u32, u32, u32, f64)>,
    /// Per loop: the cap it is the outer loop of or a hole in, or NONE.
    owner: Vec<u32>,
    /// Caps: (outer loop, face, area).
    caps: Vec<(u32, u32, f64)>,
}

#[derive(Default)]
struct BuildBufs {
    remap: Vec<u32>,
    touched: Vec<u32>,
    corners: Vec<u32>,
    loops: Vec<Loop>,
    faces: Vec<Face>,
    sources: Vec<WCorner>,
    cap_normals: Vec<DVec3>,
    balance: Vec<(u64, i32)>,
}

/// Buffers that grew beyond this many elements are freed after a cut, so
/// that one huge asset does not pin its memory to the thread for good.
const KEEP: usize = 1 << 16;

fn trim<T>(v: &mut Vec<T>) {
    if v.capacity() > KEEP {
        *v = Vec::new();
    }
}

impl Bufs {
    fn trim(&mut self) {
        trim(&mut self.planes);
        trim(&mut self.vid);
        trim(&mut self.rep);
        trim(&mut self.verts);
        if self.crossings.slots.len() > KEEP {
            self.crossings = CrossingTable::default();
        }
        trim(&mut self.items);
        trim(&mut self.part_items);
        trim(&mut self.part_start);
        trim(&mut self.store_corners);
        trim(&mut self.store_loops);
        trim(&mut self.pieces_rec);
        trim(&mut self.cur.corners);
        trim(&mut self.cur.loops);
        trim(&mut self.stack.corners);
        trim(&mut self.stack.loops);
        trim(&mut self.stack.polys);
        trim(&mut self.pieces.corners);
        trim(&mut self.pieces.loops);
        trim(&mut self.pieces.pieces);
        let s = &mut self.split;
        trim(&mut s.xs);
        trim(&mut s.order);
        trim(&mut s.partner);
        trim(&mut s.at_edge);
        trim(&mut s.visited);
        trim(&mut s.traced);
        trim(&mut s.online);
        trim(&mut s.slot);
        trim(&mut s.cleaned);
        trim(&mut s.pinch);
        let c = &mut self.caps;
        trim(&mut c.seen);
        trim(&mut c.net);
        trim(&mut c.edges);
        trim(&mut c.by_start);
        trim(&mut c.used);
        trim(&mut c.loop_verts);
        trim(&mut c.loops);
        trim(&mut c.owner);
        trim(&mut c.caps);
        let b = &mut self.build;
        trim(&mut b.remap);
        trim(&mut b.touched);
        trim(&mut b.corners);
        trim(&mut b.loops);
        trim(&mut b.faces);
        trim(&mut b.sources);
        trim(&mut b.cap_normals);
        trim(&mut b.balance);
    }
}

struct Cutter<'m, 'b> {
    mesh: &'m Mesh,
    n: DVec3,
    /// For axis-aligned cuts, the axis (crossing vertices get that coordinate
    /// set exactly to the plane's, so caps are exactly planar).
    axis: Option<usize>,
    tol: f64,
    /// The plane coordinates of the face being routed (see
    /// [`Cutter::face_basis`]).
    basis: (DVec3, DVec3),
    bufs: &'b mut Bufs,
}

impl<'m, 'b> Cutter<'m, 'b> {
    fn new(mesh: &'m Mesh, n: DVec3, offsets: &[f64], bufs: &'b mut Bufs) -> Cutter<'m, 'b> {
        // Sanitise the offsets: ascending, finite (NaN sorts as "no cut": it
        // is replaced by its predecessor, or -inf for the first).
        let planes = &mut bufs.planes;
        planes.clear();
        let mut prev = f64::NEG_INFINITY;
        for &o in offsets {
            let o = if o.is_nan() { prev } else { o.max(prev) };
            planes.push(o);
            prev = o;
        }
        let tol = mesh_tolerance(mesh).max(
            1e-9 * planes
                .iter()
                .filter(|p| p.is_finite())
                .fold(0.0f64, |m, p| m.max(p.abs())),
        );
        weld_points_into(&mesh.positions, tol, &mut bufs.vid, &mut bufs.rep);
        bufs.verts.clear();
        bufs.verts
            .extend(bufs.rep.iter().map(|&i| mesh.positions[i as usize]));
        bufs.crossings.clear();
        bufs.items.clear();
        bufs.store_corners.clear();
        bufs.store_loops.clear();
        bufs.pieces_rec.clear();
        let axis = [DVec3::X, DVec3::Y, DVec3::Z].iter().position(|&a| a == n);
        Cutter {
            mesh,
            n,
            axis,
            tol,
            basis: (DVec3::X, DVec3::Y),
            bufs,
        }
    }

    #[inline]
    fn height(&self, v: u32) -> f64 {
        let p = self.bufs.verts[v as usize];
        match self.axis {
            Some(a) => p[a],
            None => self.n.dot(p),
        }
    }

    #[inline]
    fn dist(&self, v: u32, k: usize) -> f64 {
        self.height(v) - self.bufs.planes[k]
    }

    #[inline]
    fn on_plane(&self, v: u32, k: usize) -> bool {
        self.dist(v, k).abs() <= self.tol
    }

    #[inline]
    fn original_vertex(&self, corner: u32) -> u32 {
        self.bufs.vid[self.mesh.corners[corner as usize] as usize]
    }

    /// A vertex in the coordinates `(u, v)` of a plane.
    #[inline]
    fn to2d(&self, v: u32, (u, w): (DVec3, DVec3)) -> DVec2 {
        let p = self.bufs.verts[v as usize];
        DVec2::new(p.dot(u), p.dot(w))
    }

    fn nplanes(&self) -> usize {
        self.bufs.planes.len()
    }

    fn run(&mut self) {
        let mesh = self.mesh;
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
                self.bufs.items.push((0, Item::Whole(face as u32)));
                continue;
            }
            // Skip the planes the face lies strictly above.
            let tol = self.tol;
            let mut k = self.bufs.planes.partition_point(|&c| lo - c > tol);
            let degenerate = mesh.outer_loop(face).len < 3;
            loop {
                if k == self.nplanes() {
                    self.bufs.items.push((k as u32, Item::Whole(face as u32)));
                    break;
                }
                let c = self.bufs.planes[k];
                let has_neg = lo - c < -tol;
                let has_pos = hi - c > tol;
                match (has_neg, has_pos) {
                    (true, false) => {
                        self.bufs.items.push((k as u32, Item::Whole(face as u32)));
                        break;
                    }
                    (false, true) => k += 1,
                    (false, false) => {
                        // In the plane: below if the normal points up
                        // (it closes the part below), else above. Edge and
                        // vertex shapes have no normal and stay below.
                        let up = degenerate || face_normal(mesh, face).dot(self.n) > 0.0;
                        if up {
                            self.bufs.items.push((k as u32, Item::Whole(face as u32)));
                            break;
                        }
                        k += 1;
                    }
                    (true, true) => {
                        self.load_face(face);
                        let normal = face_normal(mesh, face);
                        self.route(face as u32, normal, k);
                        break;
                    }
                }
            }
        }
    }

    /// Loads the face into `cur` as a polygon of corners that remember their
    /// original edge.
    fn load_face(&mut self, face: usize) {
        let mesh = self.mesh;
        let mut poly = std::mem::take(&mut self.bufs.cur);
        poly.clear();
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
        self.bufs.cur = poly;
    }

    /// Routes the polygon in `cur` (a face crossing plane `k`) through the
    /// planes from `k` on: splits it, stores the pieces below each plane and
    /// routes the pieces above on, depth first (the order in which the
    /// pieces reach each part is that of a recursion over the pieces).
    fn route(&mut self, face: u32, normal: DVec3, k: usize) {
        debug_assert!(self.bufs.stack.polys.is_empty());
        self.basis = self.face_basis(normal);
        self.route_one(face, normal, k);
        while let Some((first, count, k)) = self.bufs.stack.polys.pop() {
            let b = &mut self.bufs;
            b.cur.clear();
            let base = b.stack.loops[first as usize].0;
            for &(s, n) in &b.stack.loops[first as usize..(first + count) as usize] {
                b.cur.loops.push((s - base, n));
            }
            b.cur
                .corners
                .extend_from_slice(&b.stack.corners[base as usize..]);
            b.stack.loops.truncate(first as usize);
            b.stack.corners.truncate(base as usize);
            self.route_one(face, normal, k as usize);
        }
    }

    /// Routes `cur` from plane `k` on until it is stored or split; the
    /// pieces above a split are pushed on the stack.
    fn route_one(&mut self, face: u32, normal: DVec3, mut k: usize) {
        loop {
            if k == self.nplanes() {
                self.store_cur(face, k);
                return;
            }
            match self.classify(k) {
                Side::Below => {
                    self.store_cur(face, k);
                    return;
                }
                Side::Above => k += 1,
                Side::On => {
                    if self.bufs.cur.corners.len() < 3 || normal.dot(self.n) > 0.0 {
                        self.store_cur(face, k);
                        return;
                    }
                    k += 1;
                }
                Side::Both => {
                    match self.split_simple(face, normal, k) {
                        Simple::NotApplicable => {}
                        Simple::Done { above: true } => {
                            k += 1;
                            continue;
                        }
                        Simple::Done { above: false } => return,
                    }
                    let split = if self.bufs.cur.loops[0].1 < 3 {
                        self.split_segment(k)
                    } else {
                        self.split_polygon(normal, k)
                    };
                    match split {
                        Split::Whole(false) => {
                            self.store_cur(face, k);
                            return;
                        }
                        Split::Whole(true) => k += 1,
                        Split::Pieces => {
                            let pieces = std::mem::take(&mut self.bufs.pieces);
                            for p in 0..pieces.pieces.len() {
                                if pieces.pieces[p].0 == 0 {
                                    self.store_piece(face, &pieces, p, k);
                                }
                            }
                            // Pushed in reverse, so that the first piece
                            // above is routed first.
                            for p in (0..pieces.pieces.len()).rev() {
                                if pieces.pieces[p].0 == 1 {
                                    self.push_piece(&pieces, p, k + 1);
                                }
                            }
                            self.bufs.pieces = pieces;
                            return;
                        }
                    }
                }
            }
        }
    }

    /// Coordinates in the plane of a face with unit `normal` (or zero),
    /// in which pieces are told from holes.
    fn face_basis(&self, normal: DVec3) -> (DVec3, DVec3) {
        plane_basis(if normal == DVec3::ZERO {
            self.n
        } else {
            normal
        })
    }

    fn classify(&self, k: usize) -> Side {
        let mut neg = false;
        let mut pos = false;
        for c in &self.bufs.cur.corners {
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

    fn store_cur(&mut self, face: u32, part: usize) {
        let b = &mut self.bufs;
        let first = b.store_loops.len() as u32;
        for k in 0..b.cur.loops.len() {
            let l = b.cur.loop_slice(k);
            b.store_loops
                .push((b.store_corners.len() as u32, l.len() as u32));
            b.store_corners.extend_from_slice(l);
        }
        b.pieces_rec.push(PieceRec {
            face,
            first,
            count: b.cur.loops.len() as u32,
        });
        b.items
            .push((part as u32, Item::Piece(b.pieces_rec.len() as u32 - 1)));
    }

    fn store_piece(&mut self, face: u32, pieces: &Pieces, p: usize, part: usize) {
        let b = &mut self.bufs;
        let first = b.store_loops.len() as u32;
        let mut count = 0;
        for l in pieces.piece_loops(p) {
            let c = pieces.corners_of(l);
            b.store_loops
                .push((b.store_corners.len() as u32, c.len() as u32));
            b.store_corners.extend_from_slice(c);
            count += 1;
        }
        b.pieces_rec.push(PieceRec { face, first, count });
        b.items
            .push((part as u32, Item::Piece(b.pieces_rec.len() as u32 - 1)));
    }

    fn push_piece(&mut self, pieces: &Pieces, p: usize, k: usize) {
        let s = &mut self.bufs.stack;
        let first = s.loops.len() as u32;
        for l in pieces.piece_loops(p) {
            let c = pieces.corners_of(l);
            s.loops.push((s.corners.len() as u32, c.len() as u32));
            s.corners.extend_from_slice(c);
        }
        s.polys
            .push((first, s.loops.len() as u32 - first, k as u32));
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
        let key = edge_key(va, vb);
        let v = match self.bufs.crossings.find(key, k as u32) {
            Ok(v) => v,
            Err(slot) => {
                // Compute from the lower id to the higher so that the point
                // does not depend on which face asks first.
                let (p, q, sp, sq) = if va < vb {
                    (va, vb, sa, sb)
                } else {
                    (vb, va, sb, sa)
                };
                let t = sp / (sp - sq);
                let (pp, pq) = (self.bufs.verts[p as usize], self.bufs.verts[q as usize]);
                let mut x = pp + (pq - pp) * t;
                if let Some(a) = self.axis {
                    x[a] = self.bufs.planes[k];
                }
                self.bufs.verts.push(x);
                let v = self.bufs.verts.len() as u32 - 1;
                self.bufs.crossings.insert_at(slot, key, k as u32, v);
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
    fn split_segment(&mut self, k: usize) -> Split {
        let (c0, c1) = (self.bufs.cur.corners[0], self.bufs.cur.corners[1]);
        let x = self.crossing_corner(c0, c1, k);
        let (lower, upper) = if self.dist(c0.v, k) < 0.0 {
            ([c0, x], [x, c1])
        } else {
            ([x, c1], [c0, x])
        };
        let p = &mut self.bufs.pieces;
        p.clear();
        for (side, l) in [(0, lower), (1, upper)] {
            let start = p.corners.len();
            p.corners.extend_from_slice(&l);
            let l = p.add_loop(start, side);
            p.add_piece(l);
        }
        Split::Pieces
    }

    /// Splits the polygon in `cur`, with vertices strictly on both sides of
    /// plane `k`, into pieces below and above (see the module docs), left in
    /// `pieces`.
    /// The common case of a split, done directly: a polygon without holes
    /// and without repeated vertices, no vertex of which lies on plane `k`,
    /// crossing it at exactly two edges (every convex face that is cut).
    /// The piece below is stored, the piece above left in `cur`. The result
    /// is exactly what [`Cutter::split_polygon`] gives (the same crossing
    /// vertices created in the same order, the same corners in the same
    /// order, the same pieces dropped for a negative area); it returns
    /// `NotApplicable` for anything else, having at most created crossing
    /// vertices the general path finds again.
    fn split_simple(&mut self, face: u32, normal: DVec3, k: usize) -> Simple {
        const MAX: usize = 16;
        if !fast_paths_enabled() {
            return Simple::NotApplicable;
        }
        let tol = self.tol;
        let cur = &self.bufs.cur;
        let n = cur.corners.len();
        if cur.loops.len() != 1 || !(3..=MAX).contains(&n) {
            return Simple::NotApplicable;
        }
        let mut above = [false; MAX];
        let mut dist = [0.0; MAX];
        for (i, c) in cur.corners.iter().enumerate() {
            let s = self.dist(c.v, k);
            // On the plane (or NaN): the general path decides.
            if s.abs() <= tol || s.is_nan() {
                return Simple::NotApplicable;
            }
            above[i] = s > tol;
            dist[i] = s;
        }
        let mut edges = [0usize; 2];
        let mut m = 0;
        for e in 0..n {
            if above[e] != above[if e + 1 == n { 0 } else { e + 1 }] {
                if m == 2 {
                    return Simple::NotApplicable;
                }
                edges[m] = e;
                m += 1;
            }
        }
        if m != 2 {
            return Simple::NotApplicable;
        }
        for i in 1..n {
            let v = cur.corners[i].v;
            if cur.corners[..i].iter().any(|c| c.v == v) {
                return Simple::NotApplicable;
            }
        }
        // The crossings, created in edge order as the general path does,
        // with their position and tie-break along the cut line.
        let d = normal.cross(self.n);
        let mut xs = [(
            WCorner {
                v: 0,
                a: 0,
                b: 0,
                t: 0.0,
            },
            0.0,
            0.0,
            false,
        ); 2];
        for (x, &e) in xs.iter_mut().zip(&edges) {
            let j = if e + 1 == n { 0 } else { e + 1 };
            let (ci, cj) = (self.bufs.cur.corners[e], self.bufs.cur.corners[j]);
            let corner = self.crossing_corner(ci, cj, k);
            let (lo, hi, slo, shi) = if above[e] {
                (cj, ci, dist[j], dist[e])
            } else {
                (ci, cj, dist[e], dist[j])
            };
            let verts = &self.bufs.verts;
            let dl = verts[hi.v as usize] - verts[lo.v as usize];
            *x = (
                corner,
                verts[corner.v as usize].dot(d),
                dl.dot(d) / (shi - slo),
                above[j],
            );
        }
        if xs[0].0.v == xs[1].0.v {
            return Simple::NotApplicable;
        }
        // The general path pairs the crossings in order along the line (a
        // stable sort): the first must go up, the second down.
        let second_first = xs[1]
            .1
            .total_cmp(&xs[0].1)
            .then(xs[1].2.total_cmp(&xs[0].2))
            .is_lt();
        let (first, second) = if second_first {
            (xs[1], xs[0])
        } else {
            (xs[0], xs[1])
        };
        if !first.3 || second.3 {
            return Simple::NotApplicable;
        }
        // Below: from the crossing going down along the loop to the one
        // going up; above: the rest.
        let (xd, ed, xu, eu) = if xs[0].3 {
            (xs[1].0, edges[1], xs[0].0, edges[0])
        } else {
            (xs[0].0, edges[0], xs[1].0, edges[1])
        };
        // Pieces with a negative area are dropped, as the general path
        // does (they would be holes with no piece around them).
        let basis = self.basis;
        let mut p2 = [DVec2::ZERO; MAX];
        for (q, c) in p2.iter_mut().zip(&self.bufs.cur.corners) {
            *q = self.to2d(c.v, basis);
        }
        let (pd, pu) = (self.to2d(xd.v, basis), self.to2d(xu.v, basis));
        let area = |x0: DVec2, e0: usize, x1: DVec2, e1: usize| {
            let mut seq = [DVec2::ZERO; MAX + 2];
            seq[0] = x0;
            let mut len = 1;
            let mut e = e0;
            loop {
                e = if e + 1 == n { 0 } else { e + 1 };
                seq[len] = p2[e];
                len += 1;
                if e == e1 {
                    break;
                }
            }
            seq[len] = x1;
            signed_area_by(len + 1, |i| seq[i])
        };
        let mut piece = std::mem::take(&mut self.bufs.split.cleaned);
        if area(pd, ed, pu, eu) >= 0.0 {
            trace_piece(&self.bufs.cur.corners, &mut piece, (xd, ed), (xu, eu));
            let b = &mut self.bufs;
            b.store_loops
                .push((b.store_corners.len() as u32, piece.len() as u32));
            b.store_corners.extend_from_slice(&piece);
            b.pieces_rec.push(PieceRec {
                face,
                first: b.store_loops.len() as u32 - 1,
                count: 1,
            });
            b.items
                .push((k as u32, Item::Piece(b.pieces_rec.len() as u32 - 1)));
        }
        let keep = area(pu, eu, pd, ed) >= 0.0;
        if keep {
            trace_piece(&self.bufs.cur.corners, &mut piece, (xu, eu), (xd, ed));
            let cur = &mut self.bufs.cur;
            std::mem::swap(&mut cur.corners, &mut piece);
            cur.loops[0] = (0, cur.corners.len() as u32);
        }
        self.bufs.split.cleaned = piece;
        count_simple_split();
        Simple::Done { above: keep }
    }

    fn split_polygon(&mut self, normal: DVec3, k: usize) -> Split {
        let poly = std::mem::take(&mut self.bufs.cur);
        let mut sc = std::mem::take(&mut self.bufs.split);
        let split = self.split_polygon_with(&poly, normal, k, &mut sc);
        self.bufs.split = sc;
        if let Split::Whole(_) = split {
            // Inconsistent input (self-intersecting or badly non-planar
            // polygon): keep the face whole on the side of its centroid
            // rather than produce garbage.
            let c = poly.corners.iter().map(|c| self.dist(c.v, k)).sum::<f64>()
                / poly.corners.len() as f64;
            self.bufs.cur = poly;
            return Split::Whole(c > 0.0 || c.is_nan());
        }
        self.bufs.cur = poly;
        split
    }

    fn split_polygon_with(
        &mut self,
        poly: &Poly,
        normal: DVec3,
        k: usize,
        sc: &mut SplitBufs,
    ) -> Split {
        let tol = self.tol;
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
                let verts = &self.bufs.verts;
                let dl = verts[hi.v as usize] - verts[lo.v as usize];
                sc.at_edge[i] = sc.xs.len() as u32;
                sc.xs.push(Crossing {
                    corner,
                    lp: li as u32,
                    edge: e,
                    lambda: verts[corner.v as usize].dot(d),
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
            return Split::Whole(false);
        }

        let basis = self.basis;
        // The face's vertices on the cut line, by position along it. A jump
        // along the line passes through those lying between its ends: this
        // keeps edges of the line shared between pieces and caps (no
        // T-junctions) and exposes where a piece touches the line from the
        // other side, where it is then split (see `split_pinches`).
        sc.online.clear();
        for c in &poly.corners {
            if self.on_plane(c.v, k) {
                sc.online.push((self.bufs.verts[c.v as usize].dot(d), *c));
            }
        }
        sc.online
            .sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.v.cmp(&b.1.v)));
        sc.online.dedup_by_key(|x| x.1.v);
        let mut res = std::mem::take(&mut self.bufs.pieces);
        res.clear();
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
                let first_new = res.loops.len();
                self.split_pinches(
                    &sc.traced,
                    k,
                    side,
                    &mut sc.slot,
                    &mut sc.cleaned,
                    &mut sc.pinch,
                    &mut res,
                );
                for l in first_new..res.loops.len() {
                    // Counter-clockwise loops are pieces, clockwise ones
                    // holes of the piece around them.
                    let c = res.corners_of(l);
                    if signed_area_by(c.len(), |i| self.to2d(c[i].v, basis)) >= 0.0 {
                        res.add_piece(l);
                    }
                }
            }
        }
        // Loops without crossings lie on one side: holes of the piece that
        // contains them (or, for a malformed face, pieces of their own).
        for li in 0..poly.loops.len() {
            let l = poly.loop_slice(li);
            let (start, len) = poly.loops[li];
            if (start..start + len).any(|i| sc.at_edge[i as usize] != NONE) {
                continue;
            }
            let side = usize::from(l.iter().any(|c| self.dist(c.v, k) > tol));
            let at = res.corners.len();
            if !self.clean_loop_into(l, k, &mut res.corners) {
                continue;
            }
            let nl = res.add_loop(at, side);
            if li == 0 {
                res.add_piece(nl);
            }
        }
        // Holes (clockwise traced loops first, then the loops without
        // crossings) go to the piece of their side containing them.
        for side in 0..2u8 {
            let count = res.pieces.iter().filter(|p| p.0 == side).count();
            for h in 0..res.loops.len() {
                let hl = res.loops[h];
                if hl.side != side || hl.owner != NONE {
                    continue;
                }
                if count == 0 {
                    continue; // a hole without a piece around it: nothing to cut out of
                }
                let cl = res.corners_of(h);
                let probe = cl
                    .iter()
                    .find(|c| self.dist(c.v, k).abs() > tol)
                    .map(|c| self.to2d(c.v, basis));
                let mut of_side = (0..res.pieces.len()).filter(|&p| res.pieces[p].0 == side);
                let first = of_side.clone().next().unwrap_or(0);
                let target = match probe {
                    Some(q) if count > 1 => of_side
                        .find(|&p| {
                            let o = res.corners_of(res.pieces[p].1 as usize);
                            point_in_polygon_by(q, o.len(), |i| self.to2d(o[i].v, basis))
                        })
                        .unwrap_or(first),
                    _ => first,
                };
                res.loops[h].owner = target as u32;
            }
        }
        self.bufs.pieces = res;
        Split::Pieces
    }

    /// Appends `l` to `out` without repeated consecutive vertices; returns
    /// false, leaving `out` as it was, if fewer than three remain or all lie
    /// on plane `k` (a piece without area).
    fn clean_loop_into(&self, l: &[WCorner], k: usize, out: &mut Vec<WCorner>) -> bool {
        let base = out.len();
        for &c in l {
            if out.len() > base && out[out.len() - 1].v == c.v {
                continue;
            }
            out.push(c);
        }
        while out.len() - base > 1 && out[base].v == out[out.len() - 1].v {
            out.pop();
        }
        if out.len() - base < 3 || out[base..].iter().all(|c| self.on_plane(c.v, k)) {
            out.truncate(base);
            return false;
        }
        true
    }

    /// Splits a traced loop where it visits a vertex twice (a piece touching
    /// itself on the cut line, or a bridge along an edge lying in the line)
    /// into simple loops, dropping those without area; appends them to
    /// `out` on `side`, unowned.
    #[allow(clippy::too_many_arguments)]
    fn split_pinches(
        &self,
        l: &[WCorner],
        k: usize,
        side: usize,
        slot: &mut Vec<u32>,
        cleaned: &mut Vec<WCorner>,
        stack: &mut Vec<WCorner>,
        out: &mut Pieces,
    ) {
        cleaned.clear();
        if !self.clean_loop_into(l, k, cleaned) {
            return;
        }
        if slot.len() < self.bufs.verts.len() {
            slot.resize(self.bufs.verts.len(), NONE);
        }
        stack.clear();
        for &c in cleaned.iter() {
            let p = slot[c.v as usize];
            if p != NONE {
                // Close the sub-loop from the first visit up to here.
                let p = p as usize;
                for s in &stack[p + 1..] {
                    slot[s.v as usize] = NONE;
                }
                let at = out.corners.len();
                if self.clean_loop_into(&stack[p..], k, &mut out.corners) {
                    out.add_loop(at, side);
                }
                stack.truncate(p + 1);
                continue;
            }
            slot[c.v as usize] = stack.len() as u32;
            stack.push(c);
        }
        for s in stack.iter() {
            slot[s.v as usize] = NONE;
        }
        let at = out.corners.len();
        if self.clean_loop_into(stack, k, &mut out.corners) {
            out.add_loop(at, side);
        }
    }

    /// Sorts the routed items by part (stably) into `part_items`.
    fn group_items_by_part(&mut self) {
        let b = &mut self.bufs;
        let nparts = b.planes.len() + 1;
        b.part_start.clear();
        b.part_start.resize(nparts + 1, 0);
        for &(p, _) in &b.items {
            b.part_start[p as usize + 1] += 1;
        }
        for p in 0..nparts {
            b.part_start[p + 1] += b.part_start[p];
        }
        b.part_items.clear();
        b.part_items.resize(b.items.len(), Item::Whole(0));
        // `remap` serves as the fill pointers here.
        let fill = &mut b.build.remap;
        fill.clear();
        fill.extend_from_slice(&b.part_start[..nparts]);
        for &(p, item) in &b.items {
            let f = &mut fill[p as usize];
            b.part_items[*f as usize] = item;
            *f += 1;
        }
    }

    fn part_items(&self, part: usize) -> &[Item] {
        let b = &self.bufs;
        &b.part_items[b.part_start[part] as usize..b.part_start[part + 1] as usize]
    }

    /// True if every welded edge of the input is used as often in one
    /// direction as in the other (so cut parts can be closed with caps).
    fn input_is_closed(&mut self) -> bool {
        let mesh = self.mesh;
        let mut balance = std::mem::take(&mut self.bufs.build.balance);
        balance.clear();
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
                        balance.push((edge_key(a, b), d));
                    }
                }
            }
        }
        balance.sort_unstable_by_key(|e| e.0);
        let balanced = balance
            .chunk_by(|x, y| x.0 == y.0)
            .all(|g| g.iter().map(|e| e.1).sum::<i32>() == 0);
        self.bufs.build.balance = balance;
        any && balanced
    }

    /// Cap faces of `part` in plane `k`, facing `outward` (`+n` for the
    /// plane above the part, `-n` below), left in `caps`: each cap is an
    /// outer loop (then holes) of vertex ids, with the face whose material
    /// it takes.
    fn caps(&self, part: usize, k: usize, outward: DVec3, cb: &mut CapBufs) {
        let tol = self.tol;
        cb.caps.clear();
        cb.loops.clear();
        cb.loop_verts.clear();
        cb.owner.clear();
        // Net count of directed on-plane edges per undirected edge, in the
        // order the edges are first seen.
        cb.seen.clear();
        let add = |a: u32, b: u32, face: u32, seen: &mut Vec<(u64, u32, i32, u32)>| {
            if a == b || !self.on_plane(a, k) || !self.on_plane(b, k) {
                return;
            }
            let rank = seen.len() as u32;
            seen.push((edge_key(a, b), rank, if a < b { 1 } else { -1 }, face));
        };
        let mesh = self.mesh;
        for item in self.part_items(part) {
            match *item {
                Item::Whole(face) => {
                    if mesh.outer_loop(face as usize).len < 3 {
                        continue;
                    }
                    for &l in mesh.face_loops(face as usize) {
                        let r = mesh.loop_corners(l);
                        for c in r.clone() {
                            let n = if c + 1 == r.end { r.start } else { c + 1 };
                            let (a, b) = (
                                self.original_vertex(c as u32),
                                self.original_vertex(n as u32),
                            );
                            add(a, b, face, &mut cb.seen);
                        }
                    }
                }
                Item::Piece(p) => {
                    let rec = self.bufs.pieces_rec[p as usize];
                    let (_, outer_len) = self.bufs.store_loops[rec.first as usize];
                    if outer_len < 3 {
                        continue;
                    }
                    for li in rec.first..rec.first + rec.count {
                        let (s, n) = self.bufs.store_loops[li as usize];
                        let cs = &self.bufs.store_corners[s as usize..(s + n) as usize];
                        for i in 0..cs.len() {
                            let j = if i + 1 == cs.len() { 0 } else { i + 1 };
                            add(cs[i].v, cs[j].v, rec.face, &mut cb.seen);
                        }
                    }
                }
            }
        }
        if cb.seen.is_empty() {
            return;
        }
        cb.seen.sort_unstable_by_key(|e| (e.0, e.1));
        cb.net.clear();
        for g in cb.seen.chunk_by(|x, y| x.0 == y.0) {
            let count: i32 = g.iter().map(|e| e.2).sum();
            cb.net.push((g[0].1, g[0].0, count, g[0].3));
        }
        cb.net.sort_unstable_by_key(|e| e.0);
        // Unmatched edges, reversed: the caps' boundary edges.
        cb.edges.clear();
        for &(_, key, count, face) in &cb.net {
            let (a, b) = ((key >> 32) as u32, key as u32);
            for _ in 0..count.unsigned_abs() {
                if count > 0 {
                    cb.edges.push((b, a, face));
                } else {
                    cb.edges.push((a, b, face));
                }
            }
        }
        if cb.edges.is_empty() {
            return;
        }
        let basis = plane_basis(outward);
        let p2 = |i: u32| self.to2d(i, basis);
        let edges = &cb.edges;
        // Out-edges per start vertex (in edge order for equal starts).
        cb.by_start.clear();
        cb.by_start.extend(0..edges.len() as u32);
        cb.by_start
            .sort_unstable_by_key(|&e| (edges[e as usize].0, e));
        let by_start = &cb.by_start;
        let first_out = |vtx: u32| by_start.partition_point(|&e| edges[e as usize].0 < vtx);
        cb.used.clear();
        cb.used.resize(edges.len(), false);
        for e0 in 0..edges.len() {
            if cb.used[e0] {
                continue;
            }
            cb.used[e0] = true;
            let start = cb.loop_verts.len();
            cb.loop_verts.push(edges[e0].0);
            let mut cur = e0;
            let mut closed = false;
            for _ in 0..=edges.len() {
                let (a, w, _) = edges[cur];
                let first = first_out(w);
                let usable = |e: usize| !cb.used[e] || e == e0;
                let mut outs = by_start[first..]
                    .iter()
                    .take_while(|&&e| edges[e as usize].0 == w)
                    .map(|&e| e as usize)
                    .filter(|&e| usable(e));
                let Some(only) = outs.next() else {
                    break; // open chain: the section is not closed here
                };
                // At a vertex where several continue, the sharpest turn
                // (largest angle from the way back) keeps loops simple.
                let e = if outs.next().is_none() {
                    only
                } else {
                    let back = p2(a) - p2(w);
                    let mut best: Option<(usize, f64)> = None;
                    for &e in by_start[first..]
                        .iter()
                        .take_while(|&&e| edges[e as usize].0 == w)
                    {
                        let e = e as usize;
                        if !usable(e) {
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
                    best.map_or(only, |b| b.0)
                };
                if e == e0 {
                    closed = true;
                    break;
                }
                cb.used[e] = true;
                cb.loop_verts.push(edges[e].0);
                cur = e;
            }
            let len = cb.loop_verts.len() - start;
            if !closed || len < 3 {
                cb.loop_verts.truncate(start);
                continue;
            }
            let vs = &cb.loop_verts[start..];
            let area = signed_area_by(len, |i| p2(vs[i]));
            if area.abs() <= tol * tol {
                cb.loop_verts.truncate(start);
                continue;
            }
            cb.loops.push((start as u32, len as u32, edges[e0].2, area));
        }
        // Outer loops (counter-clockwise) become caps; each hole goes to the
        // smallest outer loop containing it.
        cb.owner.resize(cb.loops.len(), NONE);
        for (li, &(_, _, face, area)) in cb.loops.iter().enumerate() {
            if area > 0.0 {
                cb.owner[li] = cb.caps.len() as u32;
                cb.caps.push((li as u32, face, area));
            }
        }
        let loop_of = |li: usize| {
            let (s, n, _, _) = cb.loops[li];
            &cb.loop_verts[s as usize..(s + n) as usize]
        };
        for li in 0..cb.loops.len() {
            let area = cb.loops[li].3;
            if area > 0.0 {
                continue;
            }
            let verts = loop_of(li);
            let probe = hole_probe(verts, &p2, cb.caps.iter().map(|c| loop_of(c.0 as usize)));
            let mut best: Option<usize> = None;
            for (ci, &(outer, _, cap_area)) in cb.caps.iter().enumerate() {
                if cap_area > -area && best.is_none_or(|b| cap_area < cb.caps[b].2) {
                    let o = loop_of(outer as usize);
                    if point_in_polygon_by(probe, o.len(), |i| p2(o[i])) {
                        best = Some(ci);
                    }
                }
            }
            if let Some(b) = best {
                cb.owner[li] = b as u32;
            }
        }
    }

    /// Builds the output meshes.
    /// Where a piece of `face` starts its outer loop `cs`: at the edge that
    /// runs most nearly like the source face's first edge (ties: the earliest
    /// in the loop). A facade split into tiles and floors so keeps its first
    /// edges along the ground, and the pieces' `comp(f)` scopes keep the
    /// facade's orientation, whichever corner the cut reached first.
    fn first_corner(&self, cs: &[WCorner], face: u32) -> usize {
        let mesh = self.mesh;
        let outer = mesh.loop_indices(mesh.outer_loop(face as usize));
        let reference = (0..outer.len())
            .map(|i| {
                mesh.positions[outer[(i + 1) % outer.len()] as usize]
                    - mesh.positions[outer[i] as usize]
            })
            .find(|e| e.length() > self.tol)
            .map(|e| e.normalize());
        let Some(reference) = reference else {
            return 0;
        };
        let verts = &self.bufs.verts;
        let mut best = (f64::NEG_INFINITY, 0);
        for i in 0..cs.len() {
            let e = verts[cs[(i + 1) % cs.len()].v as usize] - verts[cs[i].v as usize];
            let len = e.length();
            if len <= self.tol {
                continue;
            }
            let along = e.dot(reference) / len;
            if along > best.0 + 1e-9 {
                best = (along, i);
            }
        }
        best.1
    }

    fn build(&mut self) -> Vec<Mesh> {
        let mesh = self.mesh;
        let closed = self.bufs.planes.is_empty() || self.input_is_closed();
        self.group_items_by_part();
        let nparts = self.nplanes() + 1;
        let mut out = Vec::with_capacity(nparts);
        let mut bb = std::mem::take(&mut self.bufs.build);
        let mut cb = std::mem::take(&mut self.bufs.caps);
        bb.remap.clear();
        bb.remap.resize(self.bufs.verts.len(), NONE);
        for part in 0..nparts {
            bb.touched.clear();
            bb.corners.clear();
            bb.loops.clear();
            bb.faces.clear();
            bb.sources.clear();
            bb.cap_normals.clear();
            let BuildBufs {
                remap,
                touched,
                corners,
                loops,
                faces,
                sources,
                cap_normals,
                ..
            } = &mut bb;
            let mut map = |v: u32| {
                let r = &mut remap[v as usize];
                if *r == NONE {
                    *r = touched.len() as u32;
                    touched.push(v);
                }
                *r
            };
            // Pieces keep their face's tags; caps get none (tag propagation
            // of cga_componentTags.md).
            let push_face = |loops: &Vec<Loop>, faces: &mut Vec<Face>, f: Face, nloops: u32| {
                faces.push(Face {
                    first_loop: loops.len() as u32 - nloops,
                    loop_count: nloops,
                    material: f.material,
                    group: f.group,
                    tags: f.tags,
                });
            };
            let items = self.part_items(part);
            for item in items {
                match *item {
                    Item::Whole(face) => {
                        let f = mesh.faces[face as usize];
                        for &l in mesh.face_loops(face as usize) {
                            let start = corners.len() as u32;
                            for c in mesh.loop_corners(l) {
                                corners.push(map(self.original_vertex(c as u32)));
                                sources.push(WCorner {
                                    v: 0,
                                    a: c as u32,
                                    b: c as u32,
                                    t: 0.0,
                                });
                            }
                            loops.push(Loop { start, len: l.len });
                        }
                        push_face(loops, faces, f, f.loop_count);
                    }
                    Item::Piece(p) => {
                        let rec = self.bufs.pieces_rec[p as usize];
                        let f = mesh.faces[rec.face as usize];
                        for li in rec.first..rec.first + rec.count {
                            let (s, n) = self.bufs.store_loops[li as usize];
                            let cs = &self.bufs.store_corners[s as usize..(s + n) as usize];
                            // The outer loop starts where its first edge runs
                            // like the source face's first edge.
                            let shift = if li == rec.first {
                                self.first_corner(cs, rec.face)
                            } else {
                                0
                            };
                            let start = corners.len() as u32;
                            for i in 0..cs.len() {
                                let c = &cs[(i + shift) % cs.len()];
                                corners.push(map(c.v));
                                sources.push(*c);
                            }
                            loops.push(Loop { start, len: n });
                        }
                        push_face(loops, faces, f, rec.count);
                    }
                }
            }
            if closed && !items.is_empty() {
                for (plane, outward) in [
                    (part.checked_sub(1), -self.n),
                    ((part < self.nplanes()).then_some(part), self.n),
                ] {
                    let Some(plane) = plane else { continue };
                    self.caps(part, plane, outward, &mut cb);
                    for (ci, &(outer, face, _)) in cb.caps.iter().enumerate() {
                        let f = mesh.faces[face as usize];
                        let holes = (0..cb.loops.len())
                            .filter(|&l| l != outer as usize && cb.owner[l] == ci as u32);
                        let mut nloops = 0;
                        for li in std::iter::once(outer as usize).chain(holes) {
                            let (s, n, _, _) = cb.loops[li];
                            let start = corners.len() as u32;
                            for &v in &cb.loop_verts[s as usize..(s + n) as usize] {
                                corners.push(map(v));
                                sources.push(WCorner {
                                    v: cap_normals.len() as u32,
                                    a: CAP,
                                    b: CAP,
                                    t: 0.0,
                                });
                            }
                            loops.push(Loop { start, len: n });
                            nloops += 1;
                        }
                        cap_normals.push(outward);
                        push_face(loops, faces, Face { tags: 0, ..f }, nloops);
                    }
                }
            }
            let verts = &self.bufs.verts;
            let mut m = empty_like(mesh);
            m.positions = touched.iter().map(|&v| verts[v as usize]).collect();
            m.corners = corners.to_vec();
            m.loops = loops.to_vec();
            m.faces = faces.to_vec();
            for &v in touched.iter() {
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
            carry_corner_tags(mesh, &mut m, sources);
            out.push(m);
        }
        self.bufs.build = bb;
        self.bufs.caps = cb;
        out
    }
}

/// Edge and vertex tags of a piece's corners from their sources: a corner
/// that is an original corner keeps its vertex tags; a corner keeps the
/// tags of the original edge its outgoing edge runs along (the edge from
/// an original corner, or through a crossing on it, to a later point of the
/// same edge); edges along the cut and cap corners get none.
fn carry_corner_tags(mesh: &Mesh, m: &mut Mesh, sources: &[WCorner]) {
    if mesh.edge_tags.is_none() && mesh.vertex_tags.is_none() {
        return;
    }
    if mesh.vertex_tags.is_some() {
        m.vertex_tags = Some(
            sources
                .iter()
                .map(|s| {
                    if s.a != CAP && s.t == 0.0 {
                        mesh.vertex_tag_index(s.a as usize)
                    } else {
                        0
                    }
                })
                .collect(),
        );
    }
    if mesh.edge_tags.is_some() {
        // The corner after every corner in its loop of the source mesh.
        let mut next = vec![0u32; mesh.corners.len()];
        for l in &mesh.loops {
            let r = mesh.loop_corners(*l);
            for c in r.clone() {
                if let Some(x) = next.get_mut(c) {
                    *x = if c + 1 == r.end { r.start } else { c + 1 } as u32;
                }
            }
        }
        let next_of = |c: u32| next.get(c as usize).copied().unwrap_or(c);
        let mut tags = vec![0u32; sources.len()];
        for l in &m.loops {
            let r = m.loop_corners(*l);
            for i in r.clone() {
                let j = if i + 1 == r.end { r.start } else { i + 1 };
                let (si, sj) = (sources[i], sources[j]);
                if si.a == CAP || sj.a == CAP {
                    continue;
                }
                // The original edge the corner lies at the start of or on.
                let (start, end) = if si.t == 0.0 {
                    (si.a, next_of(si.a))
                } else {
                    (si.a, si.b)
                };
                let along = (sj.t > 0.0 && sj.a == start && sj.b == end && sj.t > si.t)
                    || (sj.t == 0.0 && sj.a == end);
                if along {
                    tags[i] = mesh.edge_tag_index(start as usize);
                }
            }
        }
        m.edge_tags = Some(tags);
    }
}

/// The loop `corners` from crossing `x0` on edge `e0` along the loop to
/// crossing `x1` on edge `e1`, into `piece`.
fn trace_piece(
    corners: &[WCorner],
    piece: &mut Vec<WCorner>,
    (x0, e0): (WCorner, usize),
    (x1, e1): (WCorner, usize),
) {
    let n = corners.len();
    piece.clear();
    piece.push(x0);
    let mut e = e0;
    loop {
        e = if e + 1 == n { 0 } else { e + 1 };
        piece.push(corners[e]);
        if e == e1 {
            break;
        }
    }
    piece.push(x1);
}

/// An undirected edge as one sortable key (lower id in the high half).
fn edge_key(a: u32, b: u32) -> u64 {
    ((a.min(b) as u64) << 32) | a.max(b) as u64
}

/// Signed area of the polygon of points `pt(0..n)` (counter-clockwise
/// positive).
fn signed_area_by(n: usize, pt: impl Fn(usize) -> DVec2) -> f64 {
    let mut a = 0.0;
    for i in 0..n {
        a += pt(i).perp_dot(pt(if i + 1 == n { 0 } else { i + 1 }));
    }
    0.5 * a
}

/// Even-odd point in polygon test. The cut itself uses
/// [`point_in_polygon_by`]; this slice form stays for the other geometry
/// modules of the crate.
#[allow(dead_code)]
pub(crate) fn point_in_polygon(q: DVec2, pts: &[DVec2]) -> bool {
    point_in_polygon_by(q, pts.len(), |i| pts[i])
}

/// Even-odd test of `q` against the polygon of points `pt(0..n)`.
fn point_in_polygon_by(q: DVec2, n: usize, pt: impl Fn(usize) -> DVec2) -> bool {
    let mut inside = false;
    if n == 0 {
        return inside;
    }
    let mut b = pt(n - 1);
    for i in 0..n {
        let a = pt(i);
        if (a.y > q.y) != (b.y > q.y) {
            let x = a.x + (q.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if q.x < x {
                inside = !inside;
            }
        }
        b = a;
    }
    inside
}

/// A point of a hole loop to test containment with: the midpoint of its
/// first edge that is not on the boundary of a candidate outer loop
/// (holes may touch their outer loop at vertices).
fn hole_probe<'a>(
    verts: &[u32],
    p2: &impl Fn(u32) -> DVec2,
    outers: impl Iterator<Item = &'a [u32]> + Clone,
) -> DVec2 {
    let n = verts.len();
    for i in 0..n {
        let (a, b) = (verts[i], verts[(i + 1) % n]);
        let shared = outers.clone().any(|o| o.contains(&a) && o.contains(&b));
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

    /// One edge crossed by many planes (the vertical edges of a box split
    /// into thousands of floors) must spread over the crossing table: the
    /// longest run of occupied slots stays short, so lookups stay O(1).
    #[test]
    fn crossings_of_one_edge_spread_over_the_table() {
        let mut t = CrossingTable::default();
        t.clear();
        let key = (7u64 << 32) | 11;
        for plane in 0..10_000u32 {
            match t.find(key, plane) {
                Err(slot) => t.insert_at(slot, key, plane, plane),
                Ok(_) => panic!("plane {plane} found before it was inserted"),
            }
        }
        for plane in (0..10_000u32).step_by(97) {
            assert_eq!(t.find(key, plane), Ok(plane));
        }
        let (mut run, mut longest) = (0, 0);
        for s in &t.slots {
            run = if s.3 == t.generation { run + 1 } else { 0 };
            longest = longest.max(run);
        }
        assert!(
            longest < 64,
            "longest probe run {longest} of {}",
            t.slots.len()
        );
    }

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

    /// `split_along_axis` by the general path only, and the number of
    /// splits the fast path did in the normal run.
    fn split_both_ways(m: &Mesh, axis: usize, cuts: &[f64]) -> (Vec<Mesh>, Vec<Mesh>, usize) {
        SIMPLE_SPLITS.with(|c| c.set(0));
        let fast = split_along_axis(m, axis, cuts);
        let used = SIMPLE_SPLITS.with(|c| c.get());
        GENERAL_PATH_ONLY.with(|g| g.set(true));
        let general = split_along_axis(m, axis, cuts);
        GENERAL_PATH_ONLY.with(|g| g.set(false));
        (fast, general, used)
    }

    #[test]
    fn fast_path_splits_boxes_and_quads_as_the_general_path() {
        // Floors of a mass: every side face crosses 3 planes, all split by
        // the fast path; the output is the same, face for face.
        let mass = prism(&[(0., 0.), (20., 0.), (20., -30.), (0., -30.)], &[], 10.0);
        let (fast, general, used) = split_both_ways(&mass, 1, &[0.0, 3.0, 6.0, 9.0, 10.0]);
        assert_eq!(used, 12);
        assert_eq!(fast, general);
        assert_eq!(
            fast.iter().map(|m| m.faces.len()).collect::<Vec<_>>(),
            vec![0, 6, 6, 6, 6, 0]
        );
        // A facade with UVs into tiles, cuts on its borders included.
        let mut q = Mesh::polygon(&[
            v(0., 0., 0.),
            v(20., 0., 0.),
            v(20., 10., 0.),
            v(0., 10., 0.),
        ]);
        q.uvs[0] = Some(vec![
            DVec2::new(0., 0.),
            DVec2::new(1., 0.),
            DVec2::new(1., 1.),
            DVec2::new(0., 1.),
        ]);
        let cuts: Vec<f64> = (0..=10).map(|i| i as f64 * 2.0).collect();
        let (fast, general, used) = split_both_ways(&q, 0, &cuts);
        assert_eq!(used, 9);
        assert_eq!(fast, general);
        // Tile 3 spans x in [4, 6]; UVs are interpolated along the edges.
        let t = &fast[3];
        assert_eq!((t.faces.len(), t.positions.len()), (1, 4));
        let uv = t.uvs[0].as_ref().unwrap();
        for (k, &c) in t.corners.iter().enumerate() {
            let p = t.positions[c as usize];
            assert!(p.x == 4.0 || p.x == 6.0);
            assert!((uv[k] - DVec2::new(p.x / 20.0, p.y / 10.0)).length() < 1e-15);
        }
        // A cut through a vertex is left to the general path.
        let (fast, general, used) = split_both_ways(&q, 0, &[20.0]);
        assert_eq!((used, fast.len()), (0, 2));
        assert_eq!(fast, general);
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 300, .. ProptestConfig::default() })]

        /// Random planar convex quads in any orientation, with UVs and
        /// normals, cut along any axis, some cuts through their vertices.
        #[test]
        fn fast_path_equals_general_path_on_quads(
            o in prop::array::uniform3(-5.0f64..5.0),
            u in prop::array::uniform3(-3.0f64..3.0),
            w in prop::array::uniform3(-3.0f64..3.0),
            stretch in 0.3f64..1.7,
            shear in -0.4f64..0.4,
            axis in 0usize..3,
            fr in prop::collection::vec(-0.2f64..1.2, 1..8),
            through_vertex in prop::option::of(0usize..4),
        ) {
            let (o, u, w) = (DVec3::from(o), DVec3::from(u), DVec3::from(w));
            prop_assume!(u.cross(w).length() > 0.1);
            // Convex: a parallelogram with one corner pushed outwards.
            let pts = [o, o + u, o + u + w * stretch, o + w + u * shear];
            let mut m = Mesh::polygon(&pts);
            m.uvs[0] = Some((0..4).map(|i| DVec2::new(i as f64, 0.5 * i as f64)).collect());
            m.normals = Some(vec![u.cross(w).normalize(); 4]);
            let lo = pts.iter().map(|p| p[axis]).fold(f64::INFINITY, f64::min);
            let hi = pts.iter().map(|p| p[axis]).fold(f64::NEG_INFINITY, f64::max);
            let mut cuts: Vec<f64> = fr.iter().map(|f| lo + f * (hi - lo)).collect();
            if let Some(k) = through_vertex {
                cuts.push(pts[k][axis]);
            }
            cuts.sort_by(f64::total_cmp);
            let (fast, general, _) = split_both_ways(&m, axis, &cuts);
            prop_assert_eq!(fast, general);
        }

        /// Boxes, axis-aligned or rotated, split along any axis.
        #[test]
        fn fast_path_equals_general_path_on_boxes(
            size in prop::array::uniform3(0.1f64..10.0),
            at in prop::array::uniform3(-10.0f64..10.0),
            turn in prop::option::of((0.0f64..3.0, 0.0f64..1.0)),
            axis in 0usize..3,
            fr in prop::collection::vec(-0.2f64..1.2, 1..8),
            snap in any::<bool>(),
        ) {
            let mut b = crate::primitive::cube(DVec3::from(size));
            if let Some((y, x)) = turn {
                let r = glam::DAffine3::from_rotation_y(y) * glam::DAffine3::from_rotation_x(x);
                crate::transform::transform(&mut b, &r);
            }
            b.map_positions(|p| p + DVec3::from(at));
            let lo = b.positions.iter().map(|p| p[axis]).fold(f64::INFINITY, f64::min);
            let hi = b.positions.iter().map(|p| p[axis]).fold(f64::NEG_INFINITY, f64::max);
            let mut cuts: Vec<f64> = fr.iter().map(|f| {
                let f = if snap { (f * 4.0).round() / 4.0 } else { *f };
                lo + f * (hi - lo)
            }).collect();
            cuts.sort_by(f64::total_cmp);
            let (fast, general, _) = split_both_ways(&b, axis, &cuts);
            prop_assert_eq!(fast, general);
        }
    }
}
