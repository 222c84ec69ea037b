//! Which texture coordinate sets a derivation has to compute.
//!
//! Texture coordinates change nothing else a derivation does: every cut,
//! component split, extrusion and clean-up decides by positions, faces and
//! planes alone and only carries the coordinates along. So a set that the
//! caller does not keep (a report table keeps none; plain meshes and the
//! preview keep set 0; model files keep all) and that no rule can read is
//! not worth computing: the texture coordinate operations on it
//! (`projectUV`, `tileUV`, `scaleUV`, ...) are skipped, and the meshes
//! carry one array less through every later cut.
//!
//! A rule reads a set through `geometry.hasUVs`, `geometry.uMin` and the
//! other coordinate functions, `copyUV` (its source), `insertAlongUV` and a
//! split along `u` or `v`. [`sets_read`] finds them; a set given by an
//! expression that is not a constant counts as every set.

use cga_geometry::mesh::UV_SETS;
use cga_value::Value;

use crate::context::Walker;
use crate::expr::{OpCall, RExpr, RExprKind};
use crate::ops::{Op, TextureOp};
use crate::program::Program;
use crate::shape_fns::{GeometryFn, ShapeFn};

/// A set of texture coordinate sets: bit `k` stands for set `k`.
pub type UvSets = u16;

/// Every texture coordinate set.
pub const ALL_UV_SETS: UvSets = (1 << UV_SETS) - 1;

/// The texture coordinate sets the rules of `program` can read (in any
/// rule, function or attribute, whether or not it is applied).
pub fn sets_read(program: &Program) -> UvSets {
    let mut read: UvSets = 0;
    // A set read by an op or a function: `arg` is its set argument (None:
    // set 0, the default).
    let set_of = |arg: Option<&RExpr>| -> UvSets {
        match arg.map(|e| &e.kind) {
            None => 1,
            Some(RExprKind::Const(Value::Float(k))) if (0.0..UV_SETS as f64).contains(k) => {
                1 << (*k as usize)
            }
            _ => ALL_UV_SETS,
        }
    };
    let mut op = |call: &OpCall| {
        read |= match call.op {
            Op::Texturing(TextureOp::CopyUV) => set_of(call.args.first()),
            Op::Texturing(TextureOp::InsertAlongUV) => set_of(call.args.first()),
            // A split along `u` or `v` names its set third; one along x, y
            // or z reads none.
            Op::Split => match call.args.first().map(|e| &e.kind) {
                Some(RExprKind::Const(Value::Str(axis))) if !matches!(&**axis, "u" | "v") => 0,
                Some(RExprKind::Const(Value::Str(_))) => set_of(call.args.get(2)),
                _ => ALL_UV_SETS,
            },
            _ => 0,
        };
    };
    let mut fns: UvSets = 0;
    let mut shape_fn = |f: &ShapeFn, args: &[RExpr]| {
        let ShapeFn::Geometry(g) = f else {
            return;
        };
        fns |= match g {
            // Without a set: whether any set is there.
            GeometryFn::HasUVs if args.is_empty() => ALL_UV_SETS,
            g if g.reads_uvs() => set_of(args.first()),
            _ => 0,
        };
    };
    Walker {
        shape_fn: &mut shape_fn,
        op: &mut op,
        rule: &mut |_| {},
    }
    .program(program);
    read | fns
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sets_read_by_functions_copies_and_uv_splits() {
        let p = Program::from_text("Lot --> projectUV(0) scaleUV(2, 1, 1) X\nX --> NIL");
        assert_eq!(sets_read(&p), 0);
        let p = Program::from_text("Lot --> report(\"u\", geometry.uMax(3)) X\nX --> NIL");
        assert_eq!(sets_read(&p), 1 << 3);
        let p = Program::from_text("Lot --> report(\"u\", geometry.vMin) X\nX --> NIL");
        assert_eq!(sets_read(&p), 1);
        let p = Program::from_text("Lot --> report(\"t\", geometry.hasUVs) X\nX --> NIL");
        assert_eq!(sets_read(&p), ALL_UV_SETS);
        let p = Program::from_text("Lot --> copyUV(5, 0) X\nX --> NIL");
        assert_eq!(sets_read(&p), 1 << 5);
        let p = Program::from_text("attr k = 2\nLot --> copyUV(k, 0) X\nX --> NIL");
        assert_eq!(sets_read(&p), ALL_UV_SETS);
        let p = Program::from_text("Lot --> split(v, unitSpace, 4) { 0.5 : X }*\nX --> NIL");
        assert_eq!(sets_read(&p), 1 << 4);
        let p = Program::from_text("Lot --> split(x) { 0.5 : X }*\nX --> NIL");
        assert_eq!(sets_read(&p), 0);
        let p = Program::from_text("f = geometry.du(1, unitSpace)\nLot --> print(f) X\nX --> NIL");
        assert_eq!(sets_read(&p), 1 << 1);
    }
}
