//! The CGA interpreter.
