//! The working arrays of a cut, kept per thread between calls.

use glam::DVec3;

use crate::mesh::{Face, Loop};

use super::*;

/// Every buffer a cut needs, kept between calls (see
/// [`split_by_parallel_planes`]). Each call clears what it uses; nothing
/// carries meaning from one call to the next.
#[derive(Default)]
pub(super) struct Bufs {
    pub(super) planes: Vec<f64>,
    /// Welded vertex id of each original position.
    pub(super) vid: Vec<u32>,
    /// Original position of each welded vertex.
    pub(super) rep: Vec<u32>,
    /// Vertex pool: welded positions, then crossing vertices.
    pub(super) verts: Vec<DVec3>,
    /// Crossing vertices by (welded edge ends, plane).
    pub(super) crossings: CrossingTable,
    /// Routed faces with their part, in routing order.
    pub(super) items: Vec<(u32, Item)>,
    /// `items` sorted by part (stably): part `p` is
    /// `part_items[part_start[p]..part_start[p + 1]]`.
    pub(super) part_items: Vec<Item>,
    pub(super) part_start: Vec<u32>,
    pub(super) store_corners: Vec<WCorner>,
    pub(super) store_loops: Vec<(u32, u32)>,
    pub(super) pieces_rec: Vec<PieceRec>,
    /// The polygon being routed.
    pub(super) cur: Poly,
    pub(super) stack: PolyStack,
    /// The result of the last split.
    pub(super) pieces: Pieces,
    pub(super) split: SplitBufs,
    pub(super) caps: CapBufs,
    pub(super) build: BuildBufs,
    /// Cuts of small meshes remembered for replay (`trim` keeps them).
    pub(super) replays: replay::Replays,
}

#[derive(Default)]
pub(super) struct SplitBufs {
    pub(super) xs: Vec<Crossing>,
    pub(super) order: Vec<u32>,
    pub(super) partner: Vec<u32>,
    pub(super) at_edge: Vec<u32>,
    pub(super) visited: Vec<bool>,
    pub(super) traced: Vec<WCorner>,
    pub(super) online: Vec<(f64, WCorner)>,
    /// Per vertex id: position in the loop being split, or NONE.
    pub(super) slot: Vec<u32>,
    pub(super) cleaned: Vec<WCorner>,
    pub(super) pinch: Vec<WCorner>,
}

#[derive(Default)]
pub(super) struct CapBufs {
    /// On-plane directed edges: (undirected key, first-seen rank, +1 if
    /// stored from the lower id, face).
    pub(super) seen: Vec<(u64, u32, i32, u32)>,
    /// Net count per undirected edge: (first-seen rank, key, count, face).
    pub(super) net: Vec<(u32, u64, i32, u32)>,
    /// Unmatched directed edges (start, end, face).
    pub(super) edges: Vec<(u32, u32, u32)>,
    pub(super) by_start: Vec<u32>,
    pub(super) used: Vec<bool>,
    /// Closed loops: vertex ids in `loop_verts`, (start, len, face, area).
    pub(super) loop_verts: Vec<u32>,
    pub(super) loops: Vec<(u32, u32, u32, f64)>,
    /// Per loop: the cap it is the outer loop of or a hole in, or NONE.
    pub(super) owner: Vec<u32>,
    /// Caps: (outer loop, face, area).
    pub(super) caps: Vec<(u32, u32, f64)>,
}

#[derive(Default)]
pub(super) struct BuildBufs {
    pub(super) remap: Vec<u32>,
    pub(super) touched: Vec<u32>,
    pub(super) corners: Vec<u32>,
    pub(super) loops: Vec<Loop>,
    pub(super) faces: Vec<Face>,
    pub(super) sources: Vec<WCorner>,
    pub(super) cap_normals: Vec<DVec3>,
    pub(super) balance: Vec<(u64, i32)>,
}

/// Buffers that grew beyond this many elements are freed after a cut, so
/// that one huge asset does not pin its memory to the thread for good.
pub(super) const KEEP: usize = 1 << 16;

pub(super) fn trim<T>(v: &mut Vec<T>) {
    if v.capacity() > KEEP {
        *v = Vec::new();
    }
}

impl Bufs {
    pub(super) fn trim(&mut self) {
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
