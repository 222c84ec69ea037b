//! The integration tests of `cga-export`, one binary (one link of the
//! crate for all of them).

mod common;

mod gltf_encoding;
mod gltf_export;
mod gltf_streaming;
mod obj_export;
mod texturing;
