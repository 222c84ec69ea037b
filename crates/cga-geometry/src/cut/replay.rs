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

use super::*;

/// Inputs up to this many corners are remembered (a facade's tiles and
/// floors have four).
const MAX_CORNERS: usize = 32;

/// Cuts remembered per thread; the oldest is forgotten first.
const ENTRIES: usize = 32;

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

/// The remembered cuts of one thread.
#[derive(Default)]
pub(super) struct Replays {
    entries: Vec<Entry>,
    next: usize,
}

impl Replays {
    /// The parts of cutting `mesh` as remembered under `key`, with `mesh`'s
    /// attributes carried to them; `None` if not remembered.
    pub(super) fn replay(&self, key: &Key, mesh: &Mesh) -> Option<Vec<Mesh>> {
        let entry = self
            .entries
            .iter()
            .find(|e| e.key.hash == key.hash && e.key.data == key.data)?;
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

    /// Remembers the parts of a cut under `key`.
    pub(super) fn remember(&mut self, key: Key, parts: Vec<PartPlan>) {
        let entry = Entry { key, parts };
        if self.entries.len() < ENTRIES {
            self.entries.push(entry);
        } else {
            self.entries[self.next] = entry;
            self.next = (self.next + 1) % ENTRIES;
        }
    }
}
