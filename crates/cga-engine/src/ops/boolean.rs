//! `union { operationsA | operationsB }`, `subtract { .. | .. }`,
//! `intersect { .. | .. }`: Boolean operations between two operands derived
//! from the current shape (op_boolOp.md).
//!
//! Each operand is built like `inline(unify) { operations }`: its
//! operations are derived at once, to the end, on a copy of the current
//! shape, and the leaves they end in are collected (`Interp::collected`);
//! several leaves are first united with the Boolean union. The geometry is
//! then combined by `cga_geometry::boolean` in object coordinates.
//!
//! The first operand A determines the resulting shape: its scope
//! orientation (fitted to the result), pivot, attributes and material
//! attributes. If the operands' material attributes differ, both are
//! written into their geometry first, so that every face keeps the look it
//! had in its operand (the faces of B that bound a subtraction keep B's
//! material); where faces of both coincide, A's face is kept.
//!
//! More than two operands (`{ A | B | C }`) are combined from the left:
//! `(A op B) op C`.

use std::sync::Arc;

use cga_geometry::boolean::{boolean_within, BoolOp, FaceSource};
use cga_geometry::Mesh;
use cga_value::Value;

use super::inline::{bake_material, begin_collect, end_collect, set_object_mesh};
use crate::derive::{Collected, Interp, RtError, ShapeState};
use crate::expr::{OpCall, RBody, RPart};
use crate::material_attr::MaterialOverrides;
use crate::shape::Shape;

/// An operand: the shape that stands for it and its geometry in object
/// coordinates (empty if its operations left no geometry).
struct Operand {
    shape: Shape,
    mesh: Mesh,
}

pub fn exec(
    cx: &mut Interp,
    st: &mut ShapeState,
    call: &OpCall,
    op: BoolOp,
    frame: &[Value],
) -> Result<(), RtError> {
    let name = match op {
        BoolOp::Union => "union",
        BoolOp::Subtract => "subtract",
        BoolOp::Intersect => "intersect",
    };
    let mut bodies: Vec<&RBody> = Vec::new();
    for part in call.block.iter().flat_map(|b| &b.parts) {
        match part {
            RPart::Unlabeled { body, .. } => bodies.push(body),
            _ => {
                return Err(RtError::new(
                    format!(
                        "`{name} {{ A | B }}` takes operation sequences, not `head : ...` entries"
                    ),
                    call.span,
                ))
            }
        }
    }
    if bodies.len() < 2 {
        return Err(RtError::new(
            format!("`{name}` needs two operands: `{name} {{ operationsA | operationsB }}`"),
            call.span,
        ));
    }
    let mut acc: Option<Operand> = None;
    for body in bodies {
        let b = derive_operand(cx, st, call, body, frame)?;
        acc = Some(match acc {
            None => b,
            Some(a) => combine(cx, call, a, b, op)?,
        });
    }
    let Some(result) = acc else { return Ok(()) };
    let mut shape = result.shape;
    shape.name = st.shape.name;
    shape.rng.set(st.shape.rng.get());
    shape.parent_center = st.shape.parent_center;
    set_object_mesh(&mut shape, result.mesh);
    *st.shape = shape;
    Ok(())
}

/// Derives one operand's operations on a copy of the current shape and
/// unites the leaves they end in.
fn derive_operand(
    cx: &mut Interp,
    st: &ShapeState,
    call: &OpCall,
    body: &RBody,
    frame: &[Value],
) -> Result<Operand, RtError> {
    let work = cx.child(&st.shape, call.span)?;
    let saved = begin_collect(cx);
    let r = cx.derive_all_now(|cx| {
        let mut wst = ShapeState::new(work);
        cx.exec_body(body, frame, &mut wst)?;
        cx.finish(wst);
        Ok(())
    });
    let collected = end_collect(cx, saved);
    r?;
    let leaves: Vec<Collected> = collected.into_iter().filter(|c| !c.deleted).collect();
    let mut it = leaves.into_iter();
    let Some(first) = it.next() else {
        // Nothing left (`NIL`): an operand without geometry, standing for
        // the current shape.
        let mut shape = st.shape.clone();
        shape.material = Arc::new(MaterialOverrides::default());
        return Ok(Operand {
            shape: *shape,
            mesh: Mesh::new(),
        });
    };
    let mut acc = Operand {
        mesh: first.shape.object_mesh(),
        shape: first.shape,
    };
    let mut agreed: Vec<Shape> = Vec::new();
    for c in it {
        // "The shapes resulting from the derivation of operationsA (or
        // operationsB) are first merged using a Boolean union" — as
        // `inline(unify)` does, the merged operand stands for the current
        // shape with the attributes all leaves agree on.
        agreed.push(c.shape.clone());
        let mesh = c.shape.object_mesh();
        acc = combine(
            cx,
            call,
            acc,
            Operand {
                shape: c.shape,
                mesh,
            },
            BoolOp::Union,
        )?;
    }
    if !agreed.is_empty() {
        let mut shape = st.shape.clone();
        shape.material = acc.shape.material.clone();
        if let Some(list) = acc.shape.attrs.clone() {
            for (id, v) in list.iter() {
                if agreed.iter().all(|l| l.attr_override(*id) == Some(v)) {
                    shape.set_attr(*id, v.clone());
                }
            }
        }
        acc.shape = *shape;
    }
    Ok(acc)
}

/// `a op b`: A's shape with the combined geometry. Differing material
/// attributes are written into the geometry first. Stops at the time limit.
fn combine(
    cx: &Interp,
    call: &OpCall,
    mut a: Operand,
    mut b: Operand,
    op: BoolOp,
) -> Result<Operand, RtError> {
    let same =
        Arc::ptr_eq(&a.shape.material, &b.shape.material) || *a.shape.material == *b.shape.material;
    if !same {
        bake_material(&mut a.mesh, &a.shape.material);
        bake_material(&mut b.mesh, &b.shape.material);
        a.shape.material = Arc::new(MaterialOverrides::default());
    }
    let mut r = boolean_within(&a.mesh, &b.mesh, op, cx.stop())
        .map_err(|_| cx.time_limit_error(call.span))?;
    // Auto-tags: `bool.A` on the faces from A (or both operands), `bool.B`
    // on those from B (or both). The edges where faces of different
    // sources meet (`bool.cut`) are not tagged yet.
    let sources = &r.sources;
    let source = |f: usize| sources.get(f).copied().unwrap_or(FaceSource::A);
    cga_geometry::tags::set_face_auto_tags(&mut r.mesh, "bool", |f| match source(f) {
        FaceSource::B => "bool.B",
        _ => "bool.A",
    });
    let both_tag: Arc<str> = Arc::from("bool.B");
    for f in 0..r.mesh.faces.len() {
        if source(f) == FaceSource::Both {
            let set = r.mesh.tag_set(r.mesh.faces[f].tags).with(&both_tag);
            let i = r.mesh.intern_tags(set);
            r.mesh.faces[f].tags = i;
        }
    }
    Ok(Operand {
        shape: a.shape,
        mesh: r.mesh,
    })
}
