//! Where a shape's geometry can still be read, for generations that keep
//! no model (report tables: `GenerateOptions::count_leaves_only`).
//!
//! There a leaf's geometry is only asked whether it is empty (an empty
//! leaf is not counted), so an operation whose result nothing reads later
//! need not be computed in full. The one that matters is the trim of an
//! inserted asset (`i()` on a face of a component split, `trim()`): a
//! ledge cut at a building's corner is a cut of a closed mesh by a plane
//! or two, and it is often the last thing done to its shape before the
//! texture. [`GeometryUse::read_after`] tells whether anything after an
//! operation can read the geometry it leaves.
//!
//! Reading is anything but a short list of operations that leave the
//! geometry alone or only replace it (`t`, `s`, `r`, `center`, `set`,
//! `color`, `report`, `print`, `texture`, `setupProjection`, `i()`, the
//! primitives, `NIL`, leaves), and, when the rules read no texture
//! coordinates, the texture coordinate operations (which then do nothing:
//! see `crate::uv_use`). An expression reads geometry through the
//! `geometry.*` functions, context queries and the `comp` function, or a
//! user function that does. A rule reads if its operations, its
//! expressions or the rules it calls do. Programs with an attribute whose
//! value reads geometry, and programs with context queries, are taken as
//! reading everywhere.

use crate::expr::{OpCall, RBlock, RBody, RExpr, RExprKind, RPart, RStmt};
use crate::ops::{AttrOp, CleanupOp, CreateOp, Op, TextureOp};
use crate::program::Program;
use crate::shape_fns::ShapeFn;

/// Which operations leave geometry that nothing reads afterwards.
#[derive(Debug, Default)]
pub struct GeometryUse {
    /// Addresses of the `i()`, primitive and `trim()` operations after
    /// which the shape's geometry is not read (only whether it is empty),
    /// sorted: a rule file has a few dozen, asked at every insert.
    unread_after: Vec<usize>,
    /// Per user function and per rule, whether it can read anything of its
    /// shape's geometry, scope or pivot (empty: not worked out, as in
    /// programs with context queries; then everything reads).
    functions_shape: Vec<bool>,
    rules_shape: Vec<bool>,
    uv_ops_read: bool,
}

impl GeometryUse {
    pub fn of(program: &Program) -> GeometryUse {
        let mut out = GeometryUse::default();
        if crate::context::ContextUse::of(program).any() {
            return out;
        }
        let uv_ops_read = program.uv_sets_read() != 0;
        let Some((functions, rules)) = analyse(program, uv_ops_read, false) else {
            return out;
        };
        let reads = Reads {
            functions: &functions,
            rules: &rules,
            uv_ops_read,
            shape: false,
        };
        for rule in &program.rules {
            out.visit(&reads, &rule.body);
        }
        out.unread_after.sort_unstable();
        // The same for anything of the shape: geometry, scope and pivot.
        if let Some((functions, rules)) = analyse(program, uv_ops_read, true) {
            out.functions_shape = functions;
            out.rules_shape = rules;
        }
        out.uv_ops_read = uv_ops_read;
        out
    }

    /// Whether `body` (the operations of a component split's entry), and
    /// the rules it calls, can read anything of its shape's geometry, scope
    /// or pivot: if not, nothing but the part's count, its component or
    /// split information, its material and its attributes shows.
    pub fn body_reads_shape(&self, body: &RBody) -> bool {
        if self.rules_shape.is_empty() {
            return true;
        }
        Reads {
            functions: &self.functions_shape,
            rules: &self.rules_shape,
            uv_ops_read: self.uv_ops_read,
            shape: true,
        }
        .body(body)
    }

    /// Whether the geometry `call` leaves on its shape can be read after
    /// it (by a later operation or rule, an expression, or the model); only
    /// asked of `i()`, the primitives and `trim()`.
    pub fn read_after(&self, call: &OpCall) -> bool {
        self.unread_after
            .binary_search(&(call as *const OpCall as usize))
            .is_err()
    }

    /// Records the unread trimming operations of `body` and of the bodies
    /// nested in it.
    fn visit(&mut self, reads: &Reads, body: &RBody) {
        match body {
            RBody::Ops(stmts) => {
                // Whether a statement after the i-th reads.
                let mut later = false;
                for s in stmts.iter().rev() {
                    match s {
                        RStmt::Op(call) => {
                            let trims = matches!(
                                call.op,
                                Op::Trim | Op::Create(CreateOp::Insert | CreateOp::Primitive(_))
                            );
                            if trims && !later {
                                self.unread_after.push(call as *const OpCall as usize);
                            }
                            for block in [&call.block, &call.remainder_block].into_iter().flatten()
                            {
                                self.visit_block(reads, block);
                            }
                        }
                        RStmt::Push(inner) => self.visit(reads, inner),
                        _ => {}
                    }
                    later |= reads.stmt(s);
                }
            }
            RBody::Case {
                branches,
                otherwise,
            }
            | RBody::Stochastic {
                branches,
                otherwise,
            } => {
                for (_, b) in branches {
                    self.visit(reads, b);
                }
                if let Some(b) = otherwise {
                    self.visit(reads, b);
                }
            }
        }
    }

    fn visit_block(&mut self, reads: &Reads, block: &RBlock<RBody>) {
        for p in &block.parts {
            match p {
                RPart::Entry { body, .. } | RPart::Unlabeled { body, .. } => {
                    self.visit(reads, body)
                }
                RPart::Group(g) => self.visit_block(reads, g),
            }
        }
    }
}

/// What reads geometry: per user function and per rule (empty while the
/// rules are being worked out: then a rule call reads nothing by itself).
struct Reads<'a> {
    functions: &'a [bool],
    rules: &'a [bool],
    /// Whether the texture coordinate operations count as reading (the
    /// rules read some set, so they are computed).
    uv_ops_read: bool,
    /// Whether reading the scope or the pivot counts too (and operations
    /// count by whether anything of the shape shows after them).
    shape: bool,
}

impl Reads<'_> {
    fn expr(&self, e: &RExpr) -> bool {
        match &e.kind {
            RExprKind::Func(f, _) if self.functions.get(*f as usize).copied().unwrap_or(true) => {
                true
            }
            RExprKind::Shape(f, _) => {
                let scope = matches!(
                    f,
                    ShapeFn::Scope(_) | ShapeFn::ScopeElevation | ShapeFn::Pivot(_)
                );
                matches!(f, ShapeFn::Geometry(_) | ShapeFn::Context(_))
                    || (self.shape && scope)
                    || e.any_child(|c| self.expr(c))
            }
            RExprKind::CompFn { .. } | RExprKind::CompSelector(..) => true,
            // `'x` is relative to the scope.
            RExprKind::Relative(_) if self.shape => true,
            _ => e.any_child(|c| self.expr(c)),
        }
    }

    fn body(&self, b: &RBody) -> bool {
        match b {
            RBody::Ops(stmts) => stmts.iter().any(|s| self.stmt(s)),
            RBody::Case {
                branches,
                otherwise,
            }
            | RBody::Stochastic {
                branches,
                otherwise,
            } => {
                branches.iter().any(|(c, b)| self.expr(c) || self.body(b))
                    || otherwise.as_deref().is_some_and(|b| self.body(b))
            }
        }
    }

    fn stmt(&self, s: &RStmt) -> bool {
        match s {
            RStmt::Op(call) => {
                !self.leaves_geometry_alone(call.op)
                    || call.block.is_some()
                    || call.args.iter().any(|a| self.expr(a))
            }
            RStmt::Rule(rc) => {
                self.rules.get(rc.rule as usize).copied().unwrap_or(false)
                    || rc.args.iter().any(|a| self.expr(a))
                    || rc.attr_overrides.iter().any(|(_, e)| self.expr(e))
            }
            RStmt::Push(body) => self.body(body),
            RStmt::Leaf(_) | RStmt::Nil => false,
            RStmt::Unsupported { .. } => true,
        }
    }

    /// Operations that neither read the shape's geometry nor change it in
    /// a way a later reader could see other than by reading it.
    fn leaves_geometry_alone(&self, op: Op) -> bool {
        if self.shape {
            // Changes of the scope and of the faces' winding show only to
            // a reader; texture coordinates nobody reads are not made.
            return match op {
                Op::Transform(_)
                | Op::Attr(AttrOp::Color | AttrOp::Set(_) | AttrOp::Print | AttrOp::Report)
                | Op::Texturing(TextureOp::Texture)
                | Op::Cleanup(CleanupOp::ReverseNormals) => true,
                Op::Texturing(TextureOp::InsertAlongUV) => false,
                Op::Texturing(_) => !self.uv_ops_read,
                _ => false,
            };
        }
        match op {
            Op::Transform(_)
            | Op::Attr(AttrOp::Color | AttrOp::Set(_) | AttrOp::Print | AttrOp::Report) => true,
            Op::Create(CreateOp::Insert | CreateOp::Primitive(_)) => true,
            Op::Texturing(TextureOp::Texture | TextureOp::SetupProjection) => true,
            Op::Texturing(TextureOp::InsertAlongUV) => false,
            Op::Texturing(_) => !self.uv_ops_read,
            _ => false,
        }
    }
}

/// Per user function and per rule, whether it reads geometry (with
/// `shape`, anything of the shape); `None` when an attribute's value does
/// (attributes are evaluated where first used, so everything reads).
fn analyse(program: &Program, uv_ops_read: bool, shape: bool) -> Option<(Vec<bool>, Vec<bool>)> {
    let functions = functions_reading(program, shape);
    let reads = Reads {
        functions: &functions,
        rules: &[],
        uv_ops_read,
        shape,
    };
    if program.attrs.iter().any(|a| reads.expr(&a.default)) {
        return None;
    }
    let rules = rules_reading(program, &reads);
    Some((functions, rules))
}

/// Per user function, whether its value reads geometry (through its body,
/// its locals or the functions it calls).
fn functions_reading(program: &Program, shape: bool) -> Vec<bool> {
    let n = program.functions.len();
    let mut reading = vec![false; n];
    // Until nothing changes: a function reads if its body reads with the
    // functions found so far.
    loop {
        let reads = Reads {
            functions: &reading,
            rules: &[],
            uv_ops_read: true,
            shape,
        };
        let next: Vec<bool> = program
            .functions
            .iter()
            .map(|f| f.locals.iter().any(|l| reads.expr(l)) || reads.expr(&f.body))
            .collect();
        if next == reading {
            return reading;
        }
        reading = next;
    }
}

/// Per rule, whether applying it can read the geometry of its shape.
fn rules_reading(program: &Program, base: &Reads) -> Vec<bool> {
    let mut reading = vec![false; program.rules.len()];
    loop {
        let reads = Reads {
            functions: base.functions,
            rules: &reading,
            uv_ops_read: base.uv_ops_read,
            shape: base.shape,
        };
        let next: Vec<bool> = program
            .rules
            .iter()
            .map(|r| r.locals.iter().any(|l| reads.expr(l)) || reads.body(&r.body))
            .collect();
        if next == reading {
            return reading;
        }
        reading = next;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// For each rule of `src` whose body starts with `i()` or `trim()`, its
    /// name and whether the geometry that operation leaves can be read.
    fn first_ops(src: &str) -> Vec<(String, bool)> {
        let p = Program::from_text(src);
        let usage = p.geometry_use();
        p.rules
            .iter()
            .filter_map(|r| match &r.body {
                RBody::Ops(stmts) => match stmts.first() {
                    Some(RStmt::Op(call))
                        if matches!(call.op, Op::Trim | Op::Create(CreateOp::Insert)) =>
                    {
                        Some((r.name.clone(), usage.read_after(call)))
                    }
                    _ => None,
                },
                _ => None,
            })
            .collect()
    }

    #[test]
    fn inserts_whose_geometry_nothing_reads() {
        let got = first_ops(
            "f = geometry.nFaces\n\
             Leaf --> i(\"builtin:cube\") s('1, '1, 2) T.\n\
             Measured --> i(\"builtin:cube\") report(\"a\", geometry.area) T.\n\
             Split --> i(\"builtin:cube\") Parts\n\
             Parts --> split(x) { 1 : X. }*\n\
             Textured --> i(\"builtin:cube\") Paint\n\
             Paint --> texture(\"a.png\") color(\"#ffffff\") tileUV(0, 1, 1) P.\n\
             ByFunction --> i(\"builtin:cube\") print(f) T.\n\
             Trimmed --> trim() NIL\n\
             Replaced --> i(\"builtin:cube\") i(\"builtin:cube\") extrude(1) X.\n",
        );
        let want = [
            ("Leaf", false),
            ("Measured", true),
            ("Split", true),
            ("Textured", false),
            ("ByFunction", true),
            ("Trimmed", false),
            // Replaced before the extrusion reads: taken as read (a later
            // statement reads), which is safe.
            ("Replaced", true),
        ];
        let want: Vec<(String, bool)> = want.iter().map(|(n, r)| (n.to_string(), *r)).collect();
        assert_eq!(got, want);
        // A rule read the texture coordinates: the texture operations are
        // computed, and they read the positions.
        let got = first_ops(
            "A --> i(\"builtin:cube\") tileUV(0, 1, 1) T.\n\
             B --> report(\"u\", geometry.uMax(0)) X.\n",
        );
        assert_eq!(got, [("A".to_string(), true)]);
    }
}
