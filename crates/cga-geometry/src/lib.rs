//! Geometry for the CGA engine, knowing nothing of the language: indexed
//! polygon meshes in f64 (faces with holes, per-face materials, per-corner
//! texture coordinates and normals), and the algorithms the operations need.
//!
//! | module | what |
//! | --- | --- |
//! | [`mesh`], [`material`] | the data |
//! | [`measure`] | normals, areas, volume, bounds, the `geometry.*` measures |
//! | [`topology`] | welding, unique edges with their faces (`comp(e)` order), closedness |
//! | [`uv_carry`] | texture coordinates kept through offsets, setbacks, `convexify` |
//! | [`triangulate`] | faces to triangles for export |
//! | [`cleanup`] | `cleanupGeometry`, `reduceGeometry`, `rectify` |
//! | [`convexify`] | `convexify` |
//! | [`cut`] | plane cuts with caps: `split`, trim planes |
//! | `remembered` | results of cuts and extrusions remembered per thread for replay |
//! | [`boolean`] | `union`, `subtract`, `intersect` (BSP CSG; 2D overlay for planar operands) |
//! | [`area_split`] | the area left of a moving plane and its inverse: `splitArea` |
//! | [`extrude`] | `extrude` |
//! | [`envelope`] | `envelope` |
//! | [`footprint`] | `footprint`, polygon union and difference (`i_overlay`) |
//! | [`inner_rect`] | `innerRectangle` |
//! | [`perimeter`] | `splitAndSetbackPerimeter` |
//! | [`primitive`] | `primitive*` and `builtin:cube` |
//! | [`recompose`] | shape recomposition (`inline(recompose)`, `modify`) |
//! | [`normals`] | `setNormals`, `softenNormals` |
//! | [`obj`] | OBJ + MTL assets |
//! | [`occlusion`] | `inside` / `overlaps` / `touches` between meshes, distance between boxes |
//! | [`transform`] | affine transforms, reversing, merging |
//! | [`roof`] | `roofHip`, `roofGable`, `roofPyramid`, `roofShed`, `roofRidge` |
//! | [`roof_edges`] | `comp(e)`'s roof edge classes of any mesh |
//! | [`setback`] | `offset`, `setback`, `setbackToArea`, `shapeL/U/O` |
//! | [`skeleton`] | weighted straight skeletons and wavefront offsets |
//! | [`tags`] | component tags: tag sets, tag queries, tagging faces, edges, vertices |

pub mod area_split;
pub mod asset_mesh;
pub mod boolean;
pub mod cleanup;
pub mod collada;
pub mod components;
pub mod convexify;
pub mod cut;
pub mod envelope;
pub mod extrude;
pub mod footprint;
pub mod gltf_asset;
pub mod inner_rect;
pub mod material;
pub mod measure;
pub mod mesh;
pub mod normals;
pub mod obj;
pub mod occlusion;
pub mod perimeter;
pub mod primitive;
pub mod recompose;
pub(crate) mod remembered;
pub mod roof;
pub mod roof_edges;
pub mod setback;
pub mod skeleton;
pub mod tags;
pub mod topology;
pub mod transform;
pub mod triangulate;
pub mod uv_carry;

pub use area_split::{split_by_areas, AreaProfile, Flatness};
pub use asset_mesh::load_asset;
pub use cut::{cut_by_plane, part_above_plane, split_along_axis, split_by_parallel_planes};
pub use extrude::{extrude, extrude_with_roles, ExtrudeRole, Extrusion};
pub use glam::{DAffine3, DMat3, DQuat, DVec2, DVec3};
pub use inner_rect::{inner_rectangle, largest_inner_rectangle};
pub use material::{Material, TextureChannel, TEXTURE_CHANNELS};
pub use mesh::{Face, Loop, Mesh, UV_SETS};
pub use obj::{load_obj, parse_obj, ObjAsset, ObjError};
pub use roof::{roof, Roof, RoofEdgeKind, RoofFaceRole, RoofKind, RoofSlope, SourceEdge};
pub use setback::{
    merge_strips, offset, setback, setback_luo, setback_to_area, Offset, OffsetFace, SetbackEdgeTag,
};
pub use skeleton::{skeleton, straight_skeleton, Skeleton, SkeletonError, StopAt, WeightChange};
pub use tags::{TagQuery, TagSet, TagTarget};
pub use topology::Topology;
pub use triangulate::triangulate_face;
