//! Room on the stack for deep grammars, whatever thread calls.
//!
//! Parsing, resolving and deriving recurse with the rules: nested
//! expressions, function calls (up to the depth limit, `Limits::max_depth`)
//! and nested split blocks. Hosts call from threads with small stacks
//! (2 MiB for Rust's spawned threads, rayon's, tokio's, Python's), where a
//! legal grammar that recurses a thousand times would overflow and abort the
//! process. Every entry point of the library therefore runs on a stack with
//! at least [`MIN_ROOM`] left, switching to a fresh stack of [`STACK_SIZE`]
//! when the caller's has less (`stacker`, which maps the new stack and
//! frees it after; only the pages actually used are committed).

/// Stack room an entry point needs before it runs.
pub(crate) const MIN_ROOM: usize = 256 << 20;

/// Size of a stack the library switches to, and of its worker threads'.
pub(crate) const STACK_SIZE: usize = 1 << 30;

/// Runs `f` with at least [`MIN_ROOM`] of stack.
pub(crate) fn on_big_stack<R>(f: impl FnOnce() -> R) -> R {
    stacker::maybe_grow(MIN_ROOM, STACK_SIZE, f)
}
