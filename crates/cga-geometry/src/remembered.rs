//! Results remembered for replay: a bounded store, per thread in its
//! users, of what an operation decided for inputs given as bits.
//!
//! A city repeats its shapes: a facade's tiles are cut alike, its window
//! frames extruded alike, each kind again and again but not in a row. The
//! cut (`cut::replay`) and the extrusion (`extrude`) remember, for the
//! geometry they were given (every bit of it), what they made of it, and
//! replay that for the next input with the same bits, carrying the new
//! input's own attributes (texture coordinates) along. This module is the
//! store they share: entries oldest first, found by their key's hash,
//! the oldest forgotten beyond a number of entries or of bytes.

use std::collections::VecDeque;

use crate::mesh::Mesh;
use crate::topology::FxHashMap;

/// The number of values [`push_mesh_bits`] pushes for `mesh`.
pub(crate) fn mesh_bits_len(mesh: &Mesh) -> usize {
    5 + 3 * mesh.positions.len() + mesh.corners.len() + mesh.loops.len() + 3 * mesh.faces.len()
}

/// Pushes the bits of `mesh`'s geometry onto a key's data: its counts,
/// which per-corner attributes it has (not their values, which a replay
/// carries), its positions, corners, loops and faces (with their material,
/// group and tag numbers).
pub(crate) fn push_mesh_bits(data: &mut Vec<u64>, mesh: &Mesh) {
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
        flags,
    ]);
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
}

/// Everything a remembered result depends on, as bits, and their hash.
pub(crate) struct Key {
    hash: u64,
    data: Vec<u64>,
}

impl Key {
    pub(crate) fn new(data: Vec<u64>) -> Key {
        let hash = data.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &x| {
            (h ^ x).wrapping_mul(0x0000_0100_0000_01b3).rotate_left(29)
        });
        Key { hash, data }
    }

    /// Bytes the key holds.
    fn bytes(&self) -> usize {
        self.data.len() * std::mem::size_of::<u64>()
    }
}

/// Remembered results `P` by key.
pub(crate) struct Remembered<P> {
    /// Each entry with the bytes it was counted for.
    entries: VecDeque<(Key, P, usize)>,
    /// The number given to the entry of each hash remembered (of two keys
    /// with one hash, the later); entry `n` is at `n - first`.
    index: FxHashMap<u64, u64>,
    /// The number of the oldest entry, and of the next one remembered.
    first: u64,
    next: u64,
    /// Bytes the entries hold, and at most; entries at most.
    bytes: usize,
    budget: usize,
    max_entries: usize,
}

impl<P> Remembered<P> {
    /// An empty store of at most `max_entries` entries holding at most
    /// `budget` bytes.
    pub(crate) fn new(max_entries: usize, budget: usize) -> Remembered<P> {
        Remembered {
            entries: VecDeque::new(),
            index: FxHashMap::default(),
            first: 0,
            next: 0,
            bytes: 0,
            budget,
            max_entries,
        }
    }

    /// The result remembered under `key` (compared in full, not by hash).
    pub(crate) fn get(&self, key: &Key) -> Option<&P> {
        let &n = self.index.get(&key.hash)?;
        let (k, p, _) = &self.entries[(n - self.first) as usize];
        (k.data == key.data).then_some(p)
    }

    /// Remembers `result` (holding `bytes` besides its key) under `key`,
    /// forgetting the oldest entries beyond the bounds.
    pub(crate) fn insert(&mut self, key: Key, result: P, bytes: usize) {
        let bytes = bytes + key.bytes() + std::mem::size_of::<(Key, P, usize)>();
        self.bytes += bytes;
        self.index.insert(key.hash, self.next);
        self.entries.push_back((key, result, bytes));
        self.next += 1;
        while self.entries.len() > self.max_entries || self.bytes > self.budget {
            let Some((old, _, b)) = self.entries.pop_front() else {
                break;
            };
            self.bytes -= b;
            if self.index.get(&old.hash) == Some(&self.first) {
                self.index.remove(&old.hash);
            }
            self.first += 1;
        }
    }

    /// Entries remembered and the bytes they hold.
    #[cfg(test)]
    pub(crate) fn size(&self) -> (usize, usize) {
        (self.entries.len(), self.bytes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Entries are found by their whole key, the oldest go first beyond
    /// the number of entries or of bytes, and a key sharing another's hash
    /// neither finds nor loses the other's entry.
    #[test]
    fn entries_are_kept_within_bounds_and_found_by_their_whole_key() {
        let mut r: Remembered<u32> = Remembered::new(3, 10_000);
        for i in 0..5u64 {
            r.insert(Key::new(vec![i, 7]), i as u32, 0);
        }
        assert_eq!(r.size().0, 3);
        assert_eq!(r.get(&Key::new(vec![1, 7])), None);
        assert_eq!(r.get(&Key::new(vec![2, 7])), Some(&2));
        assert_eq!(r.get(&Key::new(vec![4, 7])), Some(&4));
        assert_eq!(r.get(&Key::new(vec![4])), None);
        // Two keys with one hash: the later is found, the earlier's going
        // leaves it.
        let mut r: Remembered<u32> = Remembered::new(2, 10_000);
        let a = Key {
            hash: 9,
            data: vec![1],
        };
        r.insert(a, 1, 0);
        r.insert(
            Key {
                hash: 9,
                data: vec![2],
            },
            2,
            0,
        );
        assert_eq!(
            r.get(&Key {
                hash: 9,
                data: vec![1]
            }),
            None
        );
        r.insert(Key::new(vec![3]), 3, 0);
        assert_eq!(
            r.get(&Key {
                hash: 9,
                data: vec![2]
            }),
            Some(&2)
        );
        // The budget of bytes: an entry larger than it is not kept.
        let mut r: Remembered<u32> = Remembered::new(100, 1_000);
        r.insert(Key::new(vec![1]), 1, 300);
        r.insert(Key::new(vec![2]), 2, 300);
        assert_eq!(r.size().0, 2);
        r.insert(Key::new(vec![3]), 3, 300);
        assert!(r.size().1 <= 1_000);
        assert_eq!(r.get(&Key::new(vec![1])), None);
        assert_eq!(r.get(&Key::new(vec![3])), Some(&3));
        r.insert(Key::new(vec![4]), 4, 5_000);
        assert_eq!(r.size(), (0, 0));
        assert_eq!(r.get(&Key::new(vec![4])), None);
    }
}
