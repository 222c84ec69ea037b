//! The engine's tests, through the library facade: one test binary (each
//! integration-test file would link the whole engine again).

mod facade;
mod plain;
mod skipped_work;
