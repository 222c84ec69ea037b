//! The CGA engine as a library.
//!
//! CGA is the shape grammar of procedural buildings (the rule language of
//! CityEngine). This crate is the engine's public surface: everything the
//! `cga` command, the Python package, the language server and the live
//! preview do, they do through it.
//!
//! - An [`Engine`] reads files through a [`World`]: the disk
//!   ([`DiskWorld`]), files held in memory over another world
//!   ([`MemoryWorld`]: unsaved buffers, rule text from a string), or a world
//!   confined to given folders ([`ConfinedWorld`]) for rules one did not
//!   write. It keeps what it read (assets, textures, tables), so reloading
//!   rules after an edit rereads only what changed.
//! - [`Engine::load`] gives [`Rules`], always: a file with errors still
//!   gives everything that resolved, with its [`Diagnostic`]s. Rules list
//!   their [`Attribute`]s with annotations (`@Range`, `@Enum`, `@Group`, ...).
//! - [`Rules::generate`] derives one [`Lot`] into plain meshes
//!   ([`LotResult`]); [`Rules::generate_lots`] derives many in parallel and
//!   in order, into meshes or a model file ([`ModelWriter`], GLB into any
//!   stream), handing each lot's prints, reports, warnings and error to the
//!   caller as lots finish. Each leaf's [`Provenance`] says which rule made
//!   it.
//! - Any thread can call: deep grammars get stack room of their own, limits
//!   stop runaway rules, and a [`Cancel`] stops a generation within
//!   milliseconds.
//!
//! - [`syntax`]: the syntax tree of a rule file's text and where the paths
//!   it names lead, for editors and formatters.
//!
//! `docs/library.md` has a complete example.

mod attributes;
mod diagnostics;
mod error;
mod generate;
mod help;
pub mod lots;
pub mod metadata;
mod model;
pub mod operations;
mod options;
mod pipeline;
mod rules;
mod stack;
pub mod syntax;
mod threads;
mod values;

pub use attributes::{Annotation, Attribute, Range};
pub use cga_engine::Workspaces;
pub use cga_export::Encoder;
pub use cga_export::{ExportOptions, ExportStats, Format, Georeference, Granularity, ModelWriter};
pub use cga_geometry::DVec3;
pub use cga_value::{Array, Value, ValueType};
pub use cga_world::{decode_text, ConfinedWorld, DiskWorld, MemoryWorld, Metadata, World};
pub use diagnostics::{Diagnostic, Location, Severity};
pub use error::{Error, ExportError};
pub use generate::{LotWriters, Scene, Target};
pub use lots::{Axes, CrsOption, GeoOrigin, InvalidPolicy, Lot, LotOptions, LotSet};
pub use model::{
    write_plain, DrawFaces, DrawMesh, DrawModel, DrawNormals, LeafOrigin, LotResult, Material,
    PlainMesh, PlainModel, Provenance, Summary,
};
pub use options::{Cancel, Limits, Options};
pub use rules::{Engine, ProgramSize, RuleInfo, RuleRef, Rules};

/// Default largest asset file read, in MiB ([`Engine::max_asset_mib`]).
pub use cga_engine::assets::DEFAULT_MAX_ASSET_MIB;
/// Default vertex data a glTF/GLB writer holds before writing it out, in MiB.
pub use cga_export::DEFAULT_FLUSH_MIB;
/// The names of a material's ten texture channels, in the order of
/// [`Material::maps`] (and of CGA's UV sets).
pub use cga_geometry::material::TEXTURE_CHANNELS;
pub use values::parse_value;

/// A value's text form, as `print()` and `str()` write it.
pub fn value_text(value: &Value) -> String {
    cga_engine::values::to_text(value)
}

/// The guide `docs/library.md`, whose example is compiled and run as a
/// test.
#[doc = include_str!("../../../docs/library.md")]
#[cfg(doctest)]
pub struct LibraryGuide;
