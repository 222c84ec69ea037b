//! Where planes cross edges: crossings along a cut line, how a face lies
//! against a plane, and the table that gives each crossed welded edge one
//! vertex per plane.

use super::*;

#[derive(Clone, Copy, Debug)]
pub(super) struct Crossing {
    pub(super) corner: WCorner,
    /// Loop index and edge start (position within the loop).
    pub(super) lp: u32,
    pub(super) edge: u32,
    pub(super) lambda: f64,
    pub(super) tie: f64,
    /// True if the loop goes from below to above here.
    pub(super) up: bool,
}

pub(super) enum Side {
    Below,
    Above,
    On,
    Both,
}

/// How [`Cutter::split_simple`] came out.
pub(super) enum Simple {
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
    pub(super) static GENERAL_PATH_ONLY: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    /// Number of splits done by [`Cutter::split_simple`], for tests.
    pub(super) static SIMPLE_SPLITS: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

#[cfg(test)]
pub(super) fn count_simple_split() {
    SIMPLE_SPLITS.with(|c| c.set(c.get() + 1));
}

#[cfg(not(test))]
#[inline(always)]
pub(super) fn count_simple_split() {}

#[cfg(test)]
pub(super) fn fast_paths_enabled() -> bool {
    !GENERAL_PATH_ONLY.with(|g| g.get())
}

#[cfg(not(test))]
#[inline(always)]
pub(super) fn fast_paths_enabled() -> bool {
    true
}

/// How a split came out.
pub(super) enum Split {
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
pub(super) struct CrossingTable {
    /// (edge key, plane, vertex, generation); the length is 0 or a power
    /// of two.
    pub(super) slots: Vec<(u64, u32, u32, u32)>,
    pub(super) generation: u32,
    pub(super) len: usize,
}

impl CrossingTable {
    pub(super) fn clear(&mut self) {
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
    pub(super) fn home(&self, key: u64, plane: u32) -> usize {
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
    pub(super) fn find(&mut self, key: u64, plane: u32) -> Result<u32, usize> {
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

    pub(super) fn insert_at(&mut self, slot: usize, key: u64, plane: u32, v: u32) {
        self.slots[slot] = (key, plane, v, self.generation);
        self.len += 1;
    }

    pub(super) fn grow(&mut self) {
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
