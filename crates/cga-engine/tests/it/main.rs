//! The engine's integration tests, one binary (each module was a test
//! binary of its own; one binary links the engine once). The rule files,
//! lots and assets they read are in `tests/rules/`.

mod comp_support;
mod ops_common;
mod texturing_common;

mod cleanup_ops;
mod comp_candler;
mod comp_edges;
mod comp_faces;
mod comp_fn;
mod comp_trim;
mod compat;
mod context;
mod fidelity;
mod footprint_ops;
mod gis;
mod ops_boolean;
mod ops_functions;
mod ops_geometry;
mod ops_insert;
mod ops_language;
mod ops_lot;
mod ops_material;
mod ops_moreops;
mod ops_scope;
mod ops_structure;
mod ops_transform;
mod roof_candler;
mod roof_ops;
mod split_area;
mod split_area_props;
mod split_layout;
mod split_props;
mod split_seeds;
mod tags;
mod texturing;
mod texturing_examples;
mod texturing_insert;
mod texturing_paths;
mod texturing_split;
