//! The integration tests of `cga-cli`, one binary (one link of the
//! crate for all of them).

mod common;

mod bad_inputs;
mod cli;
mod context;
mod instances;
mod lsp;
mod oracle;
mod precision;
mod texturing;
mod tiles;
mod workspace;
