//! Vertex arrays written out and handed back for the next batches.
//!
//! An [`Encoder`](crate::Encoder) fills a batch's arrays off the writing
//! thread and gives them away whole (see `Encoded::take_batch`); the writer
//! writes them as they are and, before this pool, freed them. The memory
//! came back to the encoders as fresh blocks: mimalloc hands out untouched
//! pages of its arena rather than those another thread freed, so a run's
//! resident memory grew with its output (20 Candler buildings into a GLB
//! with two jobs: from 31 to 148 MiB, linearly, with the kernel zeroing
//! every new page, a sixth of the run's samples). Now the writer puts each
//! written array here and an encoder takes its next arrays from here: the
//! same memory goes round, already touched.

use std::sync::Mutex;

use crate::bucket::Bucket;

/// Arrays kept per kind at most, and their room in bytes at most; beyond,
/// the smallest are freed. A batch has about five arrays per material and
/// the writer holds a lot's batches at a time (a few dozen arrays, a few
/// MB); the byte bound keeps a model's largest batches from being held
/// to its end.
const KEPT_PER_KIND: usize = 192;
const KEPT_BYTES_PER_KIND: usize = 64 << 20;

/// Empty arrays of each kind a [`Bucket`] holds, with their room.
#[derive(Default)]
pub(crate) struct ArrayPool {
    /// Positions and normals.
    pub vectors: Shelf<[f32; 3]>,
    pub coords: Shelf<[f32; 2]>,
    pub tangents: Shelf<[f32; 4]>,
    pub indices: Shelf<[u32; 3]>,
}

/// Empty arrays of one element type.
pub(crate) struct Shelf<T>(Mutex<Vec<Vec<T>>>);

impl<T> Default for Shelf<T> {
    fn default() -> Self {
        Shelf(Mutex::new(Vec::new()))
    }
}

impl<T> Shelf<T> {
    /// An empty array with room for `n`: the kept one of least room that
    /// has enough, else a new one (growing a kept smaller one would copy
    /// its room for nothing) with room for the power of two at or above
    /// `n`. Rooms of a few sizes fill few of the allocator's size classes,
    /// each of which takes pages of its own (mimalloc: 4 MiB for blocks of
    /// 84-512 KiB, per class and thread) that a huge page zeroes whole;
    /// rooms of exactly `n` spread over ten such classes (20 Candler
    /// buildings, two jobs: 398 new arrays, 93 of them in that range), and
    /// a new array fits more later requests. Larger arrays are rounded too
    /// (their room past what is written is never touched, but counts
    /// towards `KEPT_BYTES_PER_KIND`).
    pub fn take(&self, n: usize) -> Vec<T> {
        if n == 0 {
            return Vec::new();
        }
        let mut kept = self.0.lock().unwrap_or_else(|e| e.into_inner());
        let best = kept
            .iter()
            .enumerate()
            .filter(|(_, v)| v.capacity() >= n)
            .min_by_key(|(_, v)| v.capacity())
            .map(|(k, _)| k);
        match best {
            Some(k) => kept.swap_remove(k),
            None => Vec::with_capacity(n.next_power_of_two()),
        }
    }

    /// Keeps `v`'s room for a later `take`.
    pub fn give(&self, mut v: Vec<T>) {
        if v.capacity() == 0 {
            return;
        }
        v.clear();
        let mut kept = self.0.lock().unwrap_or_else(|e| e.into_inner());
        kept.push(v);
        // Bytes: the largest go first.
        let size = std::mem::size_of::<T>().max(1);
        while kept.iter().map(Vec::capacity).sum::<usize>() > KEPT_BYTES_PER_KIND / size {
            let largest = kept.iter().enumerate().max_by_key(|(_, v)| v.capacity());
            let Some((k, _)) = largest else { break };
            kept.swap_remove(k);
        }
        // Count: the least room is the least use.
        if kept.len() > KEPT_PER_KIND {
            let smallest = kept.iter().enumerate().min_by_key(|(_, v)| v.capacity());
            if let Some((k, _)) = smallest {
                kept.swap_remove(k);
            }
        }
    }

    /// `v` with room for `n` more: where it is short, moved into a kept
    /// array of at least twice its room (growth stays geometric; a new one
    /// if none fits) and its own array kept instead. Growing in place
    /// would take fresh memory from the allocator.
    pub fn grow(&self, v: &mut Vec<T>, n: usize)
    where
        T: Copy,
    {
        if v.capacity() - v.len() >= n {
            return;
        }
        let mut grown = self.take((v.len() + n).max(2 * v.capacity()));
        grown.extend_from_slice(v);
        self.give(std::mem::replace(v, grown));
    }

    #[cfg(test)]
    fn len(&self) -> usize {
        self.0.lock().unwrap().len()
    }
}

impl ArrayPool {
    /// Frees every array kept.
    #[cfg(test)]
    pub fn clear(&self) {
        self.vectors.0.lock().unwrap().clear();
        self.coords.0.lock().unwrap().clear();
        self.tangents.0.lock().unwrap().clear();
        self.indices.0.lock().unwrap().clear();
    }

    /// Keeps the arrays of a bucket's segment that was written out (its
    /// own arrays, not those of segments sealed into it).
    pub fn give_arrays(&self, b: Bucket) {
        debug_assert!(b.sealed.is_empty());
        self.vectors.give(b.positions);
        self.vectors.give(b.normals);
        for c in b.coords {
            self.coords.give(c);
        }
        if let Some(t) = b.tangents {
            self.tangents.give(t);
        }
        self.indices.give(b.indices);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_array_given_back_is_taken_again_when_it_has_the_room() {
        let pool = ArrayPool::default();
        let mut b = Bucket::with_layout(vec![0], true);
        b.positions.reserve_exact(100);
        b.positions.push([1.0, 2.0, 3.0]);
        b.normals.reserve_exact(40);
        b.coords[0].reserve_exact(100);
        b.indices.reserve_exact(30);
        let (positions, normals) = (b.positions.as_ptr(), b.normals.as_ptr());
        pool.give_arrays(b);
        // An empty tangent array has no room to keep.
        assert_eq!(pool.tangents.len(), 0);
        assert_eq!(pool.vectors.len(), 2);

        // The least room that fits: the normals' for 40, the positions'
        // for 41.
        let v = pool.vectors.take(30);
        assert_eq!((v.as_ptr(), v.len()), (normals, 0));
        let v = pool.vectors.take(41);
        assert_eq!((v.as_ptr(), v.len()), (positions, 0));
        // Nothing kept fits: a new array, its room the power of two at or
        // above the room asked.
        let v = pool.vectors.take(7);
        assert!(v.capacity() == 8 && v.is_empty());
        assert_eq!(pool.coords.take(101).capacity(), 128);
        // The kept one (room for 100) for less.
        assert_eq!(pool.coords.take(64).capacity(), 100);
        assert_eq!(pool.coords.len(), 0);
        assert!(pool.indices.take(0).capacity() == 0);
        assert_eq!(pool.indices.len(), 1, "room for 0 takes nothing");
    }

    #[test]
    fn a_full_shelf_keeps_the_largest_arrays_within_its_bytes() {
        let shelf = Shelf::<u32>::default();
        let least = |shelf: &Shelf<u32>| shelf.0.lock().unwrap().iter().map(Vec::capacity).min();
        for n in 1..=KEPT_PER_KIND + 10 {
            shelf.give(Vec::with_capacity(n));
        }
        assert_eq!(shelf.len(), KEPT_PER_KIND);
        assert_eq!(least(&shelf), Some(11));
        // Smaller than all kept: freed.
        shelf.give(Vec::with_capacity(3));
        assert_eq!((shelf.len(), least(&shelf)), (KEPT_PER_KIND, Some(11)));
        // Room past the byte bound (reserved, never touched): the largest
        // goes, the others stay.
        shelf.give(Vec::with_capacity(KEPT_BYTES_PER_KIND / 4));
        let most = shelf.0.lock().unwrap().iter().map(Vec::capacity).max();
        assert_eq!(
            (shelf.len(), most),
            (KEPT_PER_KIND, Some(KEPT_PER_KIND + 10))
        );
        assert_eq!(least(&shelf), Some(11));
    }
}
