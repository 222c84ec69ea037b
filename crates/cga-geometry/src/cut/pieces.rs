//! Pieces of faces while they are routed through the planes: polygons as
//! ranges of flat corner arrays, and the stack of polygons still to route.

use super::*;

/// A polygon being routed through the planes: loops as ranges of `corners`.
#[derive(Clone, Debug, Default)]
pub(super) struct Poly {
    pub(super) corners: Vec<WCorner>,
    pub(super) loops: Vec<(u32, u32)>,
}

impl Poly {
    pub(super) fn clear(&mut self) {
        self.corners.clear();
        self.loops.clear();
    }
    pub(super) fn loop_slice(&self, k: usize) -> &[WCorner] {
        let (s, n) = self.loops[k];
        &self.corners[s as usize..(s + n) as usize]
    }
}

/// Polygons waiting to be routed from plane `k` on, last in first out:
/// `polys` holds `(first loop, loop count, k)` into `loops`, whose corner
/// ranges index `corners`. The top polygon's loops and corners are always
/// at the ends of the arrays, so popping it truncates them.
#[derive(Default)]
pub(super) struct PolyStack {
    pub(super) corners: Vec<WCorner>,
    pub(super) loops: Vec<(u32, u32)>,
    pub(super) polys: Vec<(u32, u32, u32)>,
}

/// The pieces of one split: loops in `corners`, each on a side (0 below,
/// 1 above) and owned by a piece (or, for a hole not yet placed, none).
#[derive(Default)]
pub(super) struct Pieces {
    pub(super) corners: Vec<WCorner>,
    pub(super) loops: Vec<PieceLoop>,
    /// Per piece: its side and its outer loop (index into `loops`).
    pub(super) pieces: Vec<(u8, u32)>,
}

#[derive(Clone, Copy)]
pub(super) struct PieceLoop {
    pub(super) start: u32,
    pub(super) len: u32,
    pub(super) side: u8,
    pub(super) owner: u32,
}

impl Pieces {
    pub(super) fn clear(&mut self) {
        self.corners.clear();
        self.loops.clear();
        self.pieces.clear();
    }
    pub(super) fn corners_of(&self, l: usize) -> &[WCorner] {
        let pl = self.loops[l];
        &self.corners[pl.start as usize..(pl.start + pl.len) as usize]
    }
    /// A loop appended to `corners` from `start` on, not yet owned.
    pub(super) fn add_loop(&mut self, start: usize, side: usize) -> usize {
        self.loops.push(PieceLoop {
            start: start as u32,
            len: (self.corners.len() - start) as u32,
            side: side as u8,
            owner: NONE,
        });
        self.loops.len() - 1
    }
    /// Makes loop `l` the outer loop of a new piece.
    pub(super) fn add_piece(&mut self, l: usize) {
        let p = self.pieces.len() as u32;
        self.loops[l].owner = p;
        self.pieces.push((self.loops[l].side, l as u32));
    }
    /// The loops of piece `p`: its outer loop, then its holes in the order
    /// they were given to it.
    pub(super) fn piece_loops(&self, p: usize) -> impl Iterator<Item = usize> + '_ {
        let outer = self.pieces[p].1 as usize;
        std::iter::once(outer).chain(
            (0..self.loops.len()).filter(move |&l| l != outer && self.loops[l].owner == p as u32),
        )
    }
}
