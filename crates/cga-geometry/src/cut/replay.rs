//! Cuts remembered for replay: a facade's tiles are cut alike.
//!
//! A repeated split cuts many small meshes that are the same but for their
//! texture coordinates (the tiles of a facade, projected across it): the
//! same positions (in each tile's own frame), faces and planes. Everything
//! a cut decides (welding, routing, crossings, pieces, caps) depends on
//! those alone; the per-corner attributes (texture coordinates, normals,
//! edge and vertex tags) are only carried along, each corner of a piece
//! from its source corners (see [`WCorner`]). So a cut of a small mesh is
//! remembered per thread as its parts' geometry and each corner's source,
//! and a later cut with the same input is replayed: the same geometry, and
//! the attributes of the new mesh carried by the same rule. The result is
//! the one the cutter gives, value for value (a test compares both).

use glam::DVec3;

use crate::mesh::{Face, Loop, Mesh};
use crate::remembered::{mesh_bits_len, push_mesh_bits, Key, Remembered};

use super::*;

/// Inputs up to this many corners are remembered (a facade's tiles and
/// floors have four).
const MAX_CORNERS: usize = 32;

/// Cuts remembered per thread at most; the oldest is forgotten first.
pub(super) const ENTRIES: usize = 1024;

/// Bytes the cuts remembered per thread hold at most (a tile's cut into
/// five parts holds about 2 KiB; a cut of 32 corners by 32 planes may hold
/// a hundred times that).
pub(super) const BUDGET_BYTES: usize = 8 << 20;

#[cfg(test)]
thread_local! {
    /// Cuts replayed on this thread, for tests.
    pub(crate) static REPLAYED: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

/// One part of a remembered cut: its geometry and where each corner's
/// attributes come from (`cap_normals` for cap corners).
pub(super) struct PartPlan {
    pub positions: Vec<DVec3>,
    pub corners: Vec<u32>,
    pub loops: Vec<Loop>,
    pub faces: Vec<Face>,
    pub sources: Vec<WCorner>,
    pub cap_normals: Vec<DVec3>,
}

/// The key of cutting `mesh` at `offsets` along `normal` (everything a
/// cut's geometry depends on, as bits: the counts, the planes' normal and
/// offsets, which attributes the mesh has, its positions, corners, loops
/// and faces), if the mesh is small enough to remember.
pub(super) fn key_of(mesh: &Mesh, normal: DVec3, offsets: &[f64]) -> Option<Key> {
    if mesh.corners.len() > MAX_CORNERS || offsets.len() > MAX_CORNERS {
        return None;
    }
    let mut data = Vec::with_capacity(8 + offsets.len() + mesh_bits_len(mesh));
    data.push(offsets.len() as u64);
    data.extend(normal.to_array().map(f64::to_bits));
    data.extend(offsets.iter().map(|o| o.to_bits()));
    push_mesh_bits(&mut data, mesh);
    Some(Key::new(data))
}

/// Bytes the plans of a cut's parts hold (what the budget counts).
fn plan_bytes(parts: &[PartPlan]) -> usize {
    use std::mem::size_of;
    parts
        .iter()
        .map(|p| {
            p.positions.len() * size_of::<DVec3>()
                + p.corners.len() * size_of::<u32>()
                + p.loops.len() * size_of::<Loop>()
                + p.faces.len() * size_of::<Face>()
                + p.sources.len() * size_of::<WCorner>()
                + p.cap_normals.len() * size_of::<DVec3>()
                + size_of::<PartPlan>()
        })
        .sum()
}

/// The remembered cuts of one thread. A city's facades cut a few hundred
/// kinds of tile, each again and again but not in a row (Candler: 836
/// kinds among 42,000 cuts of 20 buildings; with the 32 last cuts
/// remembered, 8,400 of them were cut afresh, each some 28,000
/// instructions against 2,200 for a replay).
pub(super) struct Replays(Remembered<Vec<PartPlan>>);

impl Default for Replays {
    fn default() -> Replays {
        Replays(Remembered::new(ENTRIES, BUDGET_BYTES))
    }
}

impl Replays {
    /// The parts of cutting `mesh` as remembered under `key`, with `mesh`'s
    /// attributes carried to them; `None` if not remembered.
    pub(super) fn replay(&self, key: &Key, mesh: &Mesh) -> Option<Vec<Mesh>> {
        let parts = self.0.get(key)?;
        #[cfg(test)]
        REPLAYED.with(|r| r.set(r.get() + 1));
        Some(
            parts
                .iter()
                .map(|p| {
                    let mut m = empty_like(mesh);
                    m.positions = p.positions.clone();
                    m.corners = p.corners.clone();
                    m.loops = p.loops.clone();
                    m.faces = p.faces.clone();
                    build::carry_corner_attributes(mesh, &mut m, &p.sources, &p.cap_normals);
                    m
                })
                .collect(),
        )
    }

    /// Remembers the parts of a cut under `key`, forgetting the oldest
    /// entries beyond [`ENTRIES`] or the budget of bytes.
    pub(super) fn remember(&mut self, key: Key, parts: Vec<PartPlan>) {
        let bytes = plan_bytes(&parts);
        self.0.insert(key, parts, bytes);
    }

    /// No entries, and at most `budget` bytes in them (for tests).
    #[cfg(test)]
    pub(super) fn with_budget(budget: usize) -> Replays {
        Replays(Remembered::new(ENTRIES, budget))
    }

    /// Entries remembered and the bytes they hold (for tests).
    #[cfg(test)]
    pub(super) fn size(&self) -> (usize, usize) {
        self.0.size()
    }
}
