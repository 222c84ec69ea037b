//! The CGA interpreter.
pub mod split_layout;
