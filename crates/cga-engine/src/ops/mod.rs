//! CGA operations: the table the resolver reads (names, arities, which
//! arguments are selector keywords) and the dispatcher the interpreter calls.
//! Each family of operations lives in its own module.

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
mod tags;
pub mod texturing;
mod transform;

use cga_value::Value;

use crate::derive::{Arg, Interp, RtError, ShapeState};
use crate::expr::OpCall;
use crate::program::AttrId;
use crate::shape_fns::ShapeFn;

/// What `set(target, value)` writes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SetTarget {
    Attr(AttrId),
    Shape(ShapeFn),
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Op {
    Extrude,
    T,
    Translate,
    S,
    R,
    Rotate,
    Center,
    PrimitiveQuad,
    PrimitiveDisk,
    PrimitiveCube,
    PrimitiveSphere,
    PrimitiveCylinder,
    PrimitiveCone,
    Insert,
    Color,
    Set(SetTarget),
    SetMaterial,
    ResetMaterial,
    Texture,
    Print,
    Report,
    AlignScopeToAxes,
    AlignScopeToGeometry,
    SetPivot,
    RotateScope,
    MirrorScope,
    ResetGeometry,
    ReverseNormals,
    Split,
    SplitArea,
    Comp,
    Trim,
    RoofHip,
    RoofGable,
    RoofPyramid,
    RoofShed,
    RoofRidge,
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
    Convexify,
    DeleteHoles,
    CleanupGeometry,
    SetNormals,
    SoftenNormals,
    Mirror,
    ReduceGeometry,
    Rectify,
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
    Label,
    /// `inline`: the resolver makes it from `inline X`, `inline(s) split(..)
    /// {..}` and `inline { .. }` (its block holds the operations to derive).
    Inline,
    Modify,
    Scatter,
    AlignScopeToGeometryBBox,
    Tag,
    DeleteTags,
    /// `union`, `subtract`, `intersect` (op_boolOp.md): the block holds the
    /// operands' operation sequences.
    Union,
    Subtract,
    Intersect,
}

/// How an operation's arguments are read by the resolver.
pub struct OpInfo {
    pub op: Op,
    pub min_args: usize,
    pub max_args: usize,
    /// Whether the operation takes a `{ ... }` block.
    pub block: bool,
}

/// Whether argument `pos` of `name` called with `arity` arguments is a
/// selector keyword (`x`, `world.up`, `scopeCenter`, ...). `Maybe` means a
/// name there is a selector if it is a known selector word, else an expression.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ArgMode {
    Expr,
    Selector,
    Maybe,
}

pub fn arg_mode(name: &str, arity: usize, pos: usize) -> ArgMode {
    use ArgMode::*;
    match (name, arity, pos) {
        // The uv split's uv set is a number: `split(u, uvSpace, set)`.
        ("split", 3, 2) => Expr,
        (
            "split"
            | "splitArea"
            | "comp"
            | "modify"
            | "center"
            | "alignScopeToAxes"
            | "alignScopeToGeometryBBox"
            | "resetMaterial",
            _,
            _,
        ) => Selector,
        ("extrude", 2, 0) => Selector,
        ("r", 4, 0) => Selector,
        ("translate" | "rotate", _, 0 | 1) => Selector,
        ("alignScopeToGeometry", _, 0) => Selector,
        ("alignScopeToGeometry", _, 1 | 2) => Maybe,
        ("setPivot", _, 0) => Selector,
        ("i", _, 1..) => Selector,
        ("setupProjection", _, 1) => Selector,
        ("normalizeUV", _, 1 | 2) => Selector,
        ("offset", 2, 1) => Selector,
        // Maybe: the deprecated forms without a direction start with the height.
        ("envelope", _, 0) => Maybe,
        ("setback" | "setbackPerEdge" | "setbackToArea" | "shapeL" | "shapeU" | "shapeO", _, _) => {
            Maybe
        }
        ("innerRectangle" | "innerRect" | "footprint" | "convexify", _, _) => Maybe,
        ("roofGable" | "roofHip" | "roofShed" | "roofPyramid" | "roofRidge", _, 0) => Maybe,
        ("scatter" | "rectify" | "cleanupGeometry" | "setNormals" | "mirror", _, _) => Maybe,
        ("trim" | "taper" | "reduceGeometry" | "insertAlongUV", _, _) => Maybe,
        ("tag" | "deleteTags", 2, 1) => Selector,
        // Operations that are not run: their selector words must not be
        // unknown names.
        ("roof" | "setupUV" | "bakeUV" | "setTagsFromEdgeAttrs", _, _) => Maybe,
        _ => Expr,
    }
}

pub fn lookup(name: &str) -> Option<OpInfo> {
    let info = |op, min_args, max_args| {
        Some(OpInfo {
            op,
            min_args,
            max_args,
            block: false,
        })
    };
    let with_block = |op, min_args, max_args| {
        Some(OpInfo {
            op,
            min_args,
            max_args,
            block: true,
        })
    };
    match name {
        "extrude" => info(Op::Extrude, 1, 2),
        "t" => info(Op::T, 3, 3),
        "translate" => info(Op::Translate, 5, 5),
        "s" => info(Op::S, 3, 3),
        "r" => info(Op::R, 3, 4),
        "rotate" => info(Op::Rotate, 5, 5),
        "center" => info(Op::Center, 1, 1),
        "primitiveQuad" => info(Op::PrimitiveQuad, 0, 2),
        "primitiveDisk" => info(Op::PrimitiveDisk, 0, 2),
        "primitiveCube" => info(Op::PrimitiveCube, 0, 3),
        "primitiveSphere" => info(Op::PrimitiveSphere, 0, 3),
        "primitiveCylinder" => info(Op::PrimitiveCylinder, 0, 3),
        "primitiveCone" => info(Op::PrimitiveCone, 0, 3),
        "i" | "insert" => info(Op::Insert, 1, 4),
        "color" => info(Op::Color, 1, 4),
        "setMaterial" => info(Op::SetMaterial, 1, 1),
        "resetMaterial" => info(Op::ResetMaterial, 0, 1),
        "texture" => info(Op::Texture, 1, 1),
        "print" => info(Op::Print, 1, 1),
        "report" => info(Op::Report, 2, 2),
        "alignScopeToAxes" => info(Op::AlignScopeToAxes, 0, 1),
        "alignScopeToGeometry" => info(Op::AlignScopeToGeometry, 2, 3),
        "setPivot" => info(Op::SetPivot, 2, 2),
        "rotateScope" => info(Op::RotateScope, 3, 3),
        "mirrorScope" => info(Op::MirrorScope, 3, 3),
        "resetGeometry" => info(Op::ResetGeometry, 0, 0),
        "reverseNormals" => info(Op::ReverseNormals, 0, 0),
        "setupProjection" => info(Op::SetupProjection, 4, 7),
        "projectUV" => info(Op::ProjectUV, 1, 1),
        // `offsetUV` is translateUV's name before 2009.3 (cga_changelog.md).
        "translateUV" | "offsetUV" => info(Op::TranslateUV, 3, 3),
        "scaleUV" => info(Op::ScaleUV, 3, 3),
        "rotateUV" => info(Op::RotateUV, 2, 2),
        "normalizeUV" => info(Op::NormalizeUV, 3, 3),
        "tileUV" => info(Op::TileUV, 3, 3),
        "deleteUV" => info(Op::DeleteUV, 1, 1),
        "copyUV" => info(Op::CopyUV, 2, 2),
        "insertAlongUV" => info(Op::InsertAlongUV, 3, 5),
        "split" => Some(OpInfo {
            op: Op::Split,
            min_args: 1,
            max_args: 3,
            block: true,
        }),
        "splitArea" => Some(OpInfo {
            op: Op::SplitArea,
            min_args: 1,
            max_args: 2,
            block: true,
        }),
        "comp" => Some(OpInfo {
            op: Op::Comp,
            min_args: 1,
            max_args: 2,
            block: true,
        }),
        "modify" => with_block(Op::Modify, 1, 2),
        "scatter" => with_block(Op::Scatter, 3, 5),
        "union" => with_block(Op::Union, 0, 0),
        "subtract" => with_block(Op::Subtract, 0, 0),
        "intersect" => with_block(Op::Intersect, 0, 0),
        "alignScopeToGeometryBBox" => info(Op::AlignScopeToGeometryBBox, 1, 1),
        "trim" => info(Op::Trim, 0, 0),
        "roofHip" => info(Op::RoofHip, 1, 4),
        "roofGable" => info(Op::RoofGable, 1, 5),
        "roofPyramid" => info(Op::RoofPyramid, 1, 2),
        "roofShed" => info(Op::RoofShed, 1, 3),
        "roofRidge" => info(Op::RoofRidge, 1, 2),
        "offset" => info(Op::Offset, 1, 2),
        "setback" => with_block(Op::Setback, 1, 2),
        "setbackPerEdge" => with_block(Op::SetbackPerEdge, 1, 2),
        "setbackToArea" => with_block(Op::SetbackToArea, 1, 4),
        "shapeL" => with_block(Op::ShapeL, 2, 2),
        "shapeU" => with_block(Op::ShapeU, 3, 3),
        "shapeO" => with_block(Op::ShapeO, 4, 4),
        "splitAndSetbackPerimeter" => with_block(Op::SplitAndSetbackPerimeter, 1, 3),
        "innerRectangle" => with_block(Op::InnerRectangle, 1, 1),
        "innerRect" => info(Op::InnerRect, 0, 0),
        "envelope" => info(Op::Envelope, 3, 10),
        "taper" => info(Op::Taper, 1, 1),
        "footprint" => info(Op::Footprint, 0, 0),
        "convexify" => info(Op::Convexify, 0, 1),
        "deleteHoles" => info(Op::DeleteHoles, 0, 0),
        "cleanupGeometry" => info(Op::CleanupGeometry, 2, 2),
        "setNormals" => info(Op::SetNormals, 1, 1),
        "softenNormals" => info(Op::SoftenNormals, 1, 1),
        "mirror" => info(Op::Mirror, 3, 3),
        "reduceGeometry" => info(Op::ReduceGeometry, 1, 1),
        "rectify" => info(Op::Rectify, 1, 1),
        "label" => info(Op::Label, 1, 1),
        "tag" => info(Op::Tag, 1, 2),
        "deleteTags" => info(Op::DeleteTags, 0, 2),
        _ => None,
    }
}

/// Why an operation of [`ALL_OPERATIONS`] that [`lookup`] does not know is
/// not run (the warning's wording).
pub fn not_run_reason(name: &str) -> &'static str {
    match name {
        // cga_changelog.md, 2009.3: `roof` gave way to roofGable/roofHip/
        // roofPyramid/roofShed, setupUV/bakeUV to setupProjection/projectUV.
        "roof" | "setupUV" | "bakeUV" => "was deprecated in CGA 2009.3 and is not run",
        _ => "is not supported yet",
    }
}

/// Every operation of CGA, implemented here or not: a call of one of these
/// that the engine does not run yet is a warning, not an error.
pub const ALL_OPERATIONS: &[&str] = &[
    "alignScopeToAxes",
    "bakeUV",
    "alignScopeToGeometry",
    "alignScopeToGeometryBBox",
    "center",
    "cleanupGeometry",
    "color",
    "comp",
    "convexify",
    "copyUV",
    "deleteHoles",
    "deleteTags",
    "deleteUV",
    "envelope",
    "extrude",
    "footprint",
    "i",
    "inline",
    "innerRect",
    "innerRectangle",
    "insert",
    "insertAlongUV",
    "intersect",
    "label",
    "mirror",
    "mirrorScope",
    "modify",
    "normalizeUV",
    "offset",
    "offsetUV",
    "primitiveCone",
    "primitiveCube",
    "primitiveCylinder",
    "primitiveDisk",
    "primitiveQuad",
    "primitiveSphere",
    "print",
    "projectUV",
    "r",
    "rectify",
    "reduceGeometry",
    "report",
    "resetGeometry",
    "resetMaterial",
    "reverseNormals",
    "roof",
    "roofGable",
    "roofHip",
    "roofPyramid",
    "roofRidge",
    "roofShed",
    "rotate",
    "rotateScope",
    "rotateUV",
    "s",
    "scaleUV",
    "scatter",
    "set",
    "setMaterial",
    "setNormals",
    "setPivot",
    "setTagsFromEdgeAttrs",
    "setupUV",
    "setback",
    "setbackPerEdge",
    "setbackToArea",
    "setupProjection",
    "shapeL",
    "shapeO",
    "shapeU",
    "softenNormals",
    "split",
    "splitAndSetbackPerimeter",
    "splitArea",
    "subtract",
    "t",
    "tag",
    "taper",
    "texture",
    "tileUV",
    "translate",
    "translateUV",
    "trim",
    "union",
];

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
        Op::T | Op::Translate | Op::S | Op::R | Op::Rotate | Op::Center => {
            transform::exec(cx, st, call, args)
        }
        Op::Extrude
        | Op::PrimitiveQuad
        | Op::PrimitiveDisk
        | Op::PrimitiveCube
        | Op::PrimitiveSphere
        | Op::PrimitiveCylinder
        | Op::PrimitiveCone
        | Op::Insert => create::exec(cx, st, call, args),
        Op::Color | Op::Set(_) | Op::SetMaterial | Op::ResetMaterial | Op::Print | Op::Report => {
            attrs::exec(cx, st, call, args)
        }
        Op::SetupProjection
        | Op::ProjectUV
        | Op::TranslateUV
        | Op::ScaleUV
        | Op::RotateUV
        | Op::NormalizeUV
        | Op::TileUV
        | Op::DeleteUV
        | Op::CopyUV
        | Op::InsertAlongUV
        | Op::Texture => texturing::exec(cx, st, call, args),
        Op::AlignScopeToAxes
        | Op::AlignScopeToGeometry
        | Op::SetPivot
        | Op::RotateScope
        | Op::MirrorScope
        | Op::ResetGeometry => scope_ops::exec(cx, st, call, args),
        Op::AlignScopeToGeometryBBox => align_bbox::exec(st, call, args),
        Op::Inline => inline::exec(cx, st, call, args, frame),
        Op::Modify => modify::exec(cx, st, call, args, frame),
        Op::Scatter => scatter::exec(cx, st, call, args, frame),
        Op::Union => boolean::exec(cx, st, call, cga_geometry::boolean::BoolOp::Union, frame),
        Op::Subtract => boolean::exec(cx, st, call, cga_geometry::boolean::BoolOp::Subtract, frame),
        Op::Intersect => boolean::exec(
            cx,
            st,
            call,
            cga_geometry::boolean::BoolOp::Intersect,
            frame,
        ),
        Op::RoofHip | Op::RoofGable | Op::RoofPyramid | Op::RoofShed | Op::RoofRidge => {
            roof::exec(cx, st, call, args)
        }
        Op::Offset
        | Op::Setback
        | Op::SetbackPerEdge
        | Op::SetbackToArea
        | Op::ShapeL
        | Op::ShapeU
        | Op::ShapeO
        | Op::SplitAndSetbackPerimeter
        | Op::InnerRectangle
        | Op::InnerRect
        | Op::Envelope
        | Op::Taper
        | Op::Footprint => footprint::exec(cx, st, call, args, frame),
        Op::Convexify
        | Op::ReverseNormals
        | Op::DeleteHoles
        | Op::CleanupGeometry
        | Op::SetNormals
        | Op::SoftenNormals
        | Op::Mirror
        | Op::ReduceGeometry
        | Op::Rectify => cleanup::exec(cx, st, call, args),
        Op::Tag | Op::DeleteTags => tags::exec(st, call, args),
    }
}
