//! The integration tests of `cga-syntax`, one binary (one link of the
//! crate for all of them).

mod constructs;
mod errors;
mod fixtures;
mod oracle_rules;
mod robustness;
