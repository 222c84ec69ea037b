//! The integration tests of `cga-value`, one binary (one link of the
//! crate for all of them).

mod common;

mod arrays;
mod operators;
