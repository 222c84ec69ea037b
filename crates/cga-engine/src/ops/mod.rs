//! CGA operations: the [`Op`]s the interpreter runs, one enum per family,
//! and the dispatcher. Each family lives in its own module; the table of
//! every operation's names, argument lists and descriptions is
//! [`table`].

mod align_bbox;
mod attrs;
mod boolean;
mod cleanup;
pub mod comp;
mod create;
mod footprint;
mod inline;
mod label;
mod modify;
mod roof;
mod scatter;
mod scope_ops;
pub mod split;
pub mod split_area;
pub mod table;
mod tags;
pub mod texturing;
mod transform;

use cga_value::Value;

use crate::derive::{Arg, Interp, RtError, ShapeState};
use crate::expr::OpCall;
use crate::program::AttrId;
use crate::shape_fns::ShapeFn;

pub use table::ArgMode;

/// What `set(target, value)` writes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SetTarget {
    Attr(AttrId),
    Shape(ShapeFn),
}

/// An operation the interpreter runs: operations of one family share a
/// module, which takes its family's variant, so no module is handed an
/// operation of another.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Op {
    Split,
    SplitArea,
    Comp,
    Trim,
    Label,
    /// `inline`: the resolver makes it from `inline X`, `inline(s) split(..)
    /// {..}` and `inline { .. }` (its block holds the operations to derive).
    Inline,
    Modify,
    Scatter,
    AlignScopeToGeometryBBox,
    Transform(TransformOp),
    Create(CreateOp),
    Attr(AttrOp),
    Texturing(TextureOp),
    Scope(ScopeOp),
    Roof(RoofOp),
    Footprint(FootprintOp),
    Cleanup(CleanupOp),
    Tags(TagOp),
    /// `union`, `subtract`, `intersect` (op_boolOp.md): the block holds the
    /// operands' operation sequences.
    Boolean(cga_geometry::boolean::BoolOp),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TransformOp {
    T,
    Translate,
    S,
    R,
    Rotate,
    Center,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CreateOp {
    Extrude,
    Primitive(Primitive),
    Insert,
}

/// The primitive a `primitive...` operation makes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Primitive {
    Quad,
    Disk,
    Cube,
    Sphere,
    Cylinder,
    Cone,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AttrOp {
    Color,
    Set(SetTarget),
    SetMaterial,
    ResetMaterial,
    Print,
    Report,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TextureOp {
    SetupProjection,
    ProjectUV,
    TranslateUV,
    ScaleUV,
    RotateUV,
    NormalizeUV,
    TileUV,
    DeleteUV,
    CopyUV,
    InsertAlongUV,
    Texture,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ScopeOp {
    AlignScopeToAxes,
    AlignScopeToGeometry,
    SetPivot,
    RotateScope,
    MirrorScope,
    ResetGeometry,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RoofOp {
    Hip,
    Gable,
    Pyramid,
    Shed,
    Ridge,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FootprintOp {
    Offset,
    Setback,
    SetbackPerEdge,
    SetbackToArea,
    ShapeL,
    ShapeU,
    ShapeO,
    SplitAndSetbackPerimeter,
    InnerRectangle,
    InnerRect,
    Envelope,
    Taper,
    Footprint,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CleanupOp {
    Convexify,
    ReverseNormals,
    DeleteHoles,
    CleanupGeometry,
    SetNormals,
    SoftenNormals,
    Mirror,
    ReduceGeometry,
    Rectify,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TagOp {
    Tag,
    DeleteTags,
}

/// Runs one operation on the current shape.
pub fn exec(
    cx: &mut Interp,
    st: &mut ShapeState,
    call: &OpCall,
    args: &[Arg],
    frame: &[Value],
) -> Result<(), RtError> {
    match call.op {
        Op::Split => split::exec(cx, st, call, args, frame),
        Op::SplitArea => split_area::exec(cx, st, call, args, frame),
        Op::Comp => comp::exec(cx, st, call, args, frame),
        Op::Trim => crate::trim::exec(cx, st, call),
        Op::Label => label::exec(cx, st, call, args),
        Op::Transform(op) => transform::exec(cx, st, op, args),
        Op::Create(op) => create::exec(cx, st, op, call, args),
        Op::Attr(op) => attrs::exec(cx, st, op, call, args),
        Op::Texturing(op) => texturing::exec(cx, st, op, call, args),
        Op::Scope(op) => scope_ops::exec(cx, st, op, args),
        Op::AlignScopeToGeometryBBox => align_bbox::exec(st, call, args),
        Op::Inline => inline::exec(cx, st, call, args, frame),
        Op::Modify => modify::exec(cx, st, call, args, frame),
        Op::Scatter => scatter::exec(cx, st, call, args, frame),
        Op::Boolean(op) => boolean::exec(cx, st, call, op, frame),
        Op::Roof(op) => roof::exec(cx, st, op, call, args),
        Op::Footprint(op) => footprint::exec(cx, st, op, call, args, frame),
        Op::Cleanup(op) => cleanup::exec(cx, st, op, args),
        Op::Tags(op) => tags::exec(st, op, args),
    }
}
