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
use crate::topology::FxHashMap;

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

/// Everything a cut's geometry depends on, as bits: the counts, the
/// planes' normal and offsets, which attributes the mesh has, its
/// positions, corners, loops and faces.
pub(super) struct Key {
    hash: u64,
    data: Vec<u64>,
}

impl Key {
    /// The key of cutting `mesh` at `offsets` along `normal`, if the mesh
    /// is small enough to remember.
    pub(super) fn of(mesh: &Mesh, normal: DVec3, offsets: &[f64]) -> Option<Key> {
        if mesh.corners.len() > MAX_CORNERS || offsets.len() > MAX_CORNERS {
            return None;
        }
        let mut data = Vec::with_capacity(
            12 + offsets.len()
                + 3 * mesh.positions.len()
                + mesh.corners.len()
                + mesh.loops.len()
                + 3 * mesh.faces.len(),
        );
        let uv_sets = mesh
            .uvs
            .iter()
            .enumerate()
            .fold(0u64, |m, (k, u)| m | (u64::from(u.is_some()) << k));
        let flags = uv_sets
            | u64::from(mesh.normals.is_some()) << 16
            | u64::from(mesh.edge_tags.is_some()) << 17
            | u64::from(mesh.vertex_tags.is_some()) << 18;
        data.extend([
            mesh.positions.len() as u64,
            mesh.corners.len() as u64,
            mesh.loops.len() as u64,
            mesh.faces.len() as u64,
            offsets.len() as u64,
            flags,
        ]);
        data.extend(normal.to_array().map(f64::to_bits));
        data.extend(offsets.iter().map(|o| o.to_bits()));
        for p in &mesh.positions {
            data.extend(p.to_array().map(f64::to_bits));
        }
        data.extend(mesh.corners.iter().map(|&c| u64::from(c)));
        data.extend(
            mesh.loops
                .iter()
                .map(|l| u64::from(l.start) << 32 | u64::from(l.len)),
        );
        for f in &mesh.faces {
            data.extend([
                u64::from(f.first_loop) << 32 | u64::from(f.loop_count),
                u64::from(f.material) << 32 | u64::from(f.group),
                u64::from(f.tags),
            ]);
        }
        let hash = data.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &x| {
            (h ^ x).wrapping_mul(0x0000_0100_0000_01b3).rotate_left(29)
        });
        Some(Key { hash, data })
    }
}

struct Entry {
    key: Key,
    parts: Vec<PartPlan>,
}

impl Entry {
    /// Bytes the entry's arrays hold (what the budget counts).
    fn bytes(&self) -> usize {
        use std::mem::size_of;
        let parts: usize = self
            .parts
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
            .sum();
        parts + self.key.data.len() * size_of::<u64>() + size_of::<Entry>()
    }
}

/// The remembered cuts of one thread, oldest first, found by their key's
/// hash. A city's facades cut a few hundred kinds of tile, each again and
/// again but not in a row (Candler: 836 kinds among 42,000 cuts of 20
/// buildings; with the 32 last cuts remembered, 8,400 of them were cut
/// afresh, each some 28,000 instructions against 2,200 for a replay).
pub(super) struct Replays {
    entries: std::collections::VecDeque<Entry>,
    /// The number given to the entry of each hash remembered (of two keys
    /// with one hash, the later); entry `n` is at `n - first`.
    index: FxHashMap<u64, u64>,
    /// The number of the oldest entry, and of the next one remembered.
    first: u64,
    next: u64,
    /// Bytes the entries hold, and at most.
    bytes: usize,
    budget: usize,
}

impl Default for Replays {
    fn default() -> Replays {
        Replays {
            entries: Default::default(),
            index: Default::default(),
            first: 0,
            next: 0,
            bytes: 0,
            budget: BUDGET_BYTES,
        }
    }
}

impl Replays {
    /// The parts of cutting `mesh` as remembered under `key`, with `mesh`'s
    /// attributes carried to them; `None` if not remembered.
    pub(super) fn replay(&self, key: &Key, mesh: &Mesh) -> Option<Vec<Mesh>> {
        let &n = self.index.get(&key.hash)?;
        let entry = &self.entries[(n - self.first) as usize];
        if entry.key.data != key.data {
            return None;
        }
        #[cfg(test)]
        REPLAYED.with(|r| r.set(r.get() + 1));
        Some(
            entry
                .parts
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
        let entry = Entry { key, parts };
        self.bytes += entry.bytes();
        self.index.insert(entry.key.hash, self.next);
        self.entries.push_back(entry);
        self.next += 1;
        while self.entries.len() > ENTRIES || self.bytes > self.budget {
            let Some(old) = self.entries.pop_front() else {
                break;
            };
            self.bytes -= old.bytes();
            if self.index.get(&old.key.hash) == Some(&self.first) {
                self.index.remove(&old.key.hash);
            }
            self.first += 1;
        }
    }

    /// No entries, and at most `budget` bytes in them (for tests).
    #[cfg(test)]
    pub(super) fn with_budget(budget: usize) -> Replays {
        Replays {
            budget,
            ..Replays::default()
        }
    }

    /// Entries remembered and the bytes they hold (for tests).
    #[cfg(test)]
    pub(super) fn size(&self) -> (usize, usize) {
        (self.entries.len(), self.bytes)
    }
}
