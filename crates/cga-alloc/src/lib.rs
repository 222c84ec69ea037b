//! The memory allocator of the `cga` command and of the Python module.
//!
//! Shapes are many small allocations, and leaves made on the deriving
//! threads are freed on the writing one: mimalloc's thread-local heaps do
//! both with fewer instructions than the system allocator (Candler: 227 M
//! to 202 M instructions for the derivation). A program makes it its
//! allocator with
//!
//! ```
//! #[global_allocator]
//! static ALLOCATOR: cga_alloc::Allocator = cga_alloc::Allocator;
//!
//! fn main() {
//!     cga_alloc::keep_freed_memory(None);
//!     let faces: Vec<[f64; 3]> = vec![[1.0; 3]; 5000];
//!     assert_eq!(faces.iter().map(|p| p[0]).sum::<f64>(), 5000.0);
//! }
//! ```
//!
//! and says how long freed memory is kept with [`keep_freed_memory`].

use std::alloc::{GlobalAlloc, Layout};

use libmimalloc_sys as mi;

/// mimalloc, asked for alignment only where a type needs more than a word.
///
/// Passing every request to `mi_malloc_aligned` (as the `mimalloc` crate's
/// allocator does) takes its slow path for any block over 1 KiB whose size
/// is not a power of two: the block is over-allocated and aligned by hand,
/// and its page marked as holding interior pointers. Candler made 47,000
/// of those per building, 4.5 % of its derivation's instructions. Every
/// mimalloc block is aligned to a word (block sizes are multiples of it),
/// so requests that need no more go to the plain calls, as the system
/// allocator's binding does with `malloc`.
pub struct Allocator;

/// The alignment every block of `mi_malloc` has.
const WORD: usize = std::mem::size_of::<usize>();

// SAFETY: each method forwards to the mimalloc function with the contract
// `GlobalAlloc` asks for: `mi_malloc`, `mi_zalloc` and `mi_realloc` give
// blocks aligned to a word and are used only when the layout needs no
// more; larger alignments go to the `_aligned` functions; `mi_free` frees
// blocks of both.
unsafe impl GlobalAlloc for Allocator {
    #[inline]
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if layout.align() <= WORD {
            unsafe { mi::mi_malloc(layout.size()).cast() }
        } else {
            unsafe { mi::mi_malloc_aligned(layout.size(), layout.align()).cast() }
        }
    }

    #[inline]
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if layout.align() <= WORD {
            unsafe { mi::mi_zalloc(layout.size()).cast() }
        } else {
            unsafe { mi::mi_zalloc_aligned(layout.size(), layout.align()).cast() }
        }
    }

    #[inline]
    unsafe fn dealloc(&self, ptr: *mut u8, _layout: Layout) {
        unsafe { mi::mi_free(ptr.cast()) }
    }

    #[inline]
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if layout.align() <= WORD {
            unsafe { mi::mi_realloc(ptr.cast(), new_size).cast() }
        } else {
            unsafe { mi::mi_realloc_aligned(ptr.cast(), new_size, layout.align()).cast() }
        }
    }
}

/// mimalloc's `mi_option_purge_delay` (its `mimalloc.h` option list).
const MI_OPTION_PURGE_DELAY: mi::mi_option_t = 15;

/// How long memory freed is kept for reuse before it is given back to the
/// system: `Some(milliseconds)`, or `None` for as long as the process
/// lives. mimalloc's default, 10 ms, is shorter than the time between one
/// lot's meshes being freed and the next lot's being made: given back,
/// the memory came back as fresh pages the kernel zeroed each time (a
/// sixth of the time of 25 Candler buildings).
pub fn keep_freed_memory(delay: Option<std::time::Duration>) {
    use std::os::raw::c_long;
    let ms = delay.map_or(-1, |d| {
        c_long::try_from(d.as_millis()).unwrap_or(c_long::MAX)
    });
    // SAFETY: sets one of mimalloc's documented options to a documented
    // value (milliseconds, or -1: never purge); options are atomics.
    unsafe { mi::mi_option_set(MI_OPTION_PURGE_DELAY, ms) };
}

/// mimalloc's `mi_option_allow_thp` (its `mimalloc.h` option list).
const MI_OPTION_ALLOW_THP: mi::mi_option_t = 43;

/// Whether the kernel may back the process's memory with transparent huge
/// pages (on by default). A fault on a huge page may stall while the
/// kernel compacts memory to find 2 MiB in one piece: for a batch that is
/// time well spent (fewer faults, fewer TLB misses), for a server that
/// answers edits it is a latency spike. `cga serve` turns them off: its
/// model encoding of a 10-lot street took 100-170 ms instead of about 25
/// in three or four of 16 regenerations with them, at most 67 ms without.
pub fn allow_huge_pages(allow: bool) {
    // SAFETY: sets one of mimalloc's documented options to a documented
    // value (0 or 1); options are atomics. mimalloc reads it for each
    // mapping it makes from then on.
    unsafe { mi::mi_option_set(MI_OPTION_ALLOW_THP, allow as std::os::raw::c_long) };
    // Memory mapped before (mimalloc's first arena) follows the process's
    // flag, which the kernel reads at each fault.
    #[cfg(target_os = "linux")]
    // SAFETY: PR_SET_THP_DISABLE takes 0 or 1 and no pointers.
    unsafe {
        libc::prctl(libc::PR_SET_THP_DISABLE, (!allow) as libc::c_ulong, 0, 0, 0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Huge pages turned off are off for mimalloc and for the kernel's
    /// view of the process, and back on when allowed again.
    #[test]
    fn huge_pages_are_allowed_as_asked() {
        let option = || unsafe { mi::mi_option_get(MI_OPTION_ALLOW_THP) };
        allow_huge_pages(false);
        assert_eq!(option(), 0);
        #[cfg(target_os = "linux")]
        assert_eq!(
            unsafe { libc::prctl(libc::PR_GET_THP_DISABLE, 0, 0, 0, 0) },
            1
        );
        allow_huge_pages(true);
        assert_eq!(option(), 1);
        #[cfg(target_os = "linux")]
        assert_eq!(
            unsafe { libc::prctl(libc::PR_GET_THP_DISABLE, 0, 0, 0, 0) },
            0
        );
    }

    /// The delay set is the one mimalloc purges by; `None` never purges.
    #[test]
    fn freed_memory_is_kept_as_long_as_asked() {
        let get = || unsafe { mi::mi_option_get(MI_OPTION_PURGE_DELAY) };
        keep_freed_memory(Some(std::time::Duration::from_millis(2500)));
        assert_eq!(get(), 2500);
        keep_freed_memory(None);
        assert_eq!(get(), -1);
    }

    /// Blocks of every alignment a layout may ask for are aligned, keep
    /// their contents through a reallocation, and are zeroed when asked.
    #[test]
    fn blocks_have_the_alignment_and_contents_asked_for() {
        let a = Allocator;
        for align in [1, 2, 4, 8, 16, 32, 64, 4096] {
            for size in [1, 7, 24, 1000, 1500, 5000, 100_000] {
                let layout = Layout::from_size_align(size, align).unwrap();
                unsafe {
                    let p = a.alloc(layout);
                    assert!(!p.is_null());
                    assert_eq!(p as usize % align, 0, "size {size} align {align}");
                    for i in 0..size {
                        *p.add(i) = (i % 251) as u8;
                    }
                    let q = a.realloc(p, layout, size * 3);
                    assert_eq!(q as usize % align, 0, "realloc {size} align {align}");
                    for i in 0..size {
                        assert_eq!(*q.add(i), (i % 251) as u8);
                    }
                    a.dealloc(q, Layout::from_size_align(size * 3, align).unwrap());
                    let z = a.alloc_zeroed(layout);
                    assert_eq!(z as usize % align, 0);
                    assert!((0..size).all(|i| *z.add(i) == 0));
                    a.dealloc(z, layout);
                }
            }
        }
    }
}
