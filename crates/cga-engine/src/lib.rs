//! The CGA interpreter: resolves rule files into a program, derives initial
//! shapes with it, and hands leaf geometry to the exporters.

pub mod assets;
pub mod context;
pub mod derive;
mod eval;
pub mod expr;
pub mod file_fns;
pub mod generate;
pub mod geo;
pub mod geometry_use;
pub mod gis;
pub mod locate;
pub mod lot;
pub mod material_attr;
pub mod ops;
pub mod program;
pub mod resolve;
pub mod selectors;
pub mod shape;
pub mod shape_fns;
pub mod split_layout;
pub mod subtree_memo;
pub mod trim;
pub mod uv_use;
pub mod values;

pub use derive::{InitialInfo, Interp, Limits, LotOutput, RtError};
pub use generate::{generate_lot, GenerateOptions};
pub use locate::Workspaces;
pub use program::Program;
pub use resolve::{load, load_text, load_text_with, load_with, LoadOptions, Loaded};
