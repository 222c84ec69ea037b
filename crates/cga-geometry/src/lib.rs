//! Geometry for the CGA engine, knowing nothing of the language: indexed
//! polygon meshes in f64 (faces with holes, per-face materials, per-corner
//! texture coordinates and normals), and the algorithms the operations need.

pub mod cut;
pub mod extrude;
pub mod material;
pub mod measure;
pub mod mesh;
pub mod obj;
pub mod primitive;
pub mod topology;
pub mod transform;
pub mod triangulate;

pub use glam::{DAffine3, DMat3, DQuat, DVec2, DVec3};
pub use material::{Material, TextureChannel, TEXTURE_CHANNELS};
pub use mesh::{Face, Loop, Mesh, UV_SETS};
pub use triangulate::triangulate_face;
