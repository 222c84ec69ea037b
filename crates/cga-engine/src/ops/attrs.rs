//! Operations on attributes and output: `color`, `set`, `setMaterial`,
//! `resetMaterial`, `texture`, `print`, `report`.

use std::sync::Arc;

use cga_value::Value;

use super::{AttrOp, SetTarget};
use crate::derive::{Arg, Interp, MaterialEdit, RtError, ShapeState};
use crate::expr::OpCall;
use crate::material_attr::{parse_hex_color, MatField, MaterialOverrides};
use crate::shape::{euler_to_mat, Shape};
use crate::shape_fns::ShapeFn;
use crate::values::{to_text, type_name};

pub fn exec(
    cx: &mut Interp,
    st: &mut ShapeState,
    op: AttrOp,
    call: &OpCall,
    args: &[Arg],
) -> Result<(), RtError> {
    let shape = &mut st.shape;
    match op {
        AttrOp::Color => match args {
            [hex] => {
                let s = hex.text()?;
                if parse_hex_color(s).is_none() {
                    // A colour that is not one (often an empty attribute
                    // value) leaves the colour as it was, with a warning,
                    // rather than stopping the lot.
                    cx.warn_once(hex.span, || {
                        format!("\"{s}\" is not a colour (expected \"#rrggbb\" or \"#rrggbboo\"); the colour is left unchanged")
                    });
                    return Ok(());
                }
                let edit = MaterialEdit::ColorHex(match &hex.value {
                    Value::Str(s) => s.clone(),
                    _ => Arc::from(s),
                });
                cx.edit_material(shape, edit, |_, m| {
                    let (rgb, o) = parse_hex_color(s).ok_or_else(|| {
                        RtError::new(
                            format!(
                                "\"{s}\" is not a colour: expected \"#rrggbb\" or \"#rrggbboo\""
                            ),
                            hex.span,
                        )
                    })?;
                    for (i, c) in rgb.iter().enumerate() {
                        set_field(m, MatField::Color(i as u8), &Value::Float(*c), hex)?;
                    }
                    if let Some(o) = o {
                        set_field(m, MatField::Opacity, &Value::Float(o), hex)?;
                    }
                    Ok(())
                })?;
            }
            [r, g, b, rest @ ..] => {
                let mut key = [0u64; 4];
                let given = [Some(r), Some(g), Some(b), rest.first()];
                for (k, a) in key.iter_mut().zip(given) {
                    if let Some(a) = a {
                        *k = a.num()?.to_bits();
                    }
                }
                let edit = MaterialEdit::Color(key, 3 + rest.len().min(1));
                cx.edit_material(shape, edit, |_, m| {
                    for (i, a) in [r, g, b].into_iter().enumerate() {
                        set_field(m, MatField::Color(i as u8), &Value::Float(a.num()?), a)?;
                    }
                    if let Some(o) = rest.first() {
                        set_field(m, MatField::Opacity, &Value::Float(o.num()?), o)?;
                    }
                    Ok(())
                })?;
            }
            _ => {
                return Err(RtError::new(
                    "`color` takes a \"#rrggbb\" string or 3 or 4 numbers",
                    call.span,
                ))
            }
        },
        AttrOp::Set(target) => set(cx, shape, target, &args[0])?,
        AttrOp::SetMaterial => {
            let pairs: Vec<Arc<str>> = match &args[0].value {
                Value::StrArray(a) => a.data.clone(),
                other => {
                    return Err(RtError::new(
                        format!(
                            "`setMaterial` expects a string array of name/value pairs, found {}",
                            type_name(other)
                        ),
                        args[0].span,
                    ))
                }
            };
            let m = Arc::make_mut(&mut shape.material);
            for kv in pairs.chunks(2) {
                let [k, v] = kv else { break };
                let name = format!("material.{k}");
                let field = MatField::parse(&name).ok_or_else(|| {
                    RtError::new(format!("unknown material attribute `{k}`"), args[0].span)
                })?;
                set_field(m, field, &Value::Str(v.clone()), &args[0])?;
            }
        }
        AttrOp::ResetMaterial => {
            let target = match args.first() {
                Some(a) => super::transform::selector(a, &["shape", "geometry", "all"])?,
                None => "shape",
            };
            if target != "geometry" {
                shape.material = Arc::new(MaterialOverrides::default());
            }
            if target != "shape" {
                for m in &mut shape.geometry.local_mut().materials {
                    *m = cga_geometry::Material::default();
                }
            }
        }
        AttrOp::Print => cx.out.prints.push(to_text(&args[0].value)),
        AttrOp::Report => {
            let key = match &args[0].value {
                Value::Str(s) => s.to_string(),
                other => to_text(other),
            };
            match &args[1].value {
                v @ (Value::Float(_) | Value::Bool(_) | Value::Str(_)) => {
                    cx.out.reports.push((key, v.clone()))
                }
                other => {
                    return Err(RtError::new(
                        format!(
                            "`report` takes a float, bool or string value, found {}",
                            type_name(other)
                        ),
                        args[1].span,
                    ))
                }
            }
        }
    }
    Ok(())
}

fn set_field(m: &mut MaterialOverrides, f: MatField, v: &Value, at: &Arg) -> Result<(), RtError> {
    m.set(f, v).map_err(|e| RtError::new(e, at.span))
}

fn set(cx: &mut Interp, shape: &mut Shape, target: SetTarget, arg: &Arg) -> Result<(), RtError> {
    let v = &arg.value;
    match target {
        SetTarget::Attr(id) => {
            // Keep the attribute's type: a float attribute set from a string is an error.
            let current = match shape.attr_override(id) {
                Some(v) => v.clone(),
                None => cx.attr_default(id, &crate::expr::RExpr::constant(v.clone(), arg.span))?,
            };
            if std::mem::discriminant(&current) != std::mem::discriminant(v) {
                return Err(RtError::new(
                    format!(
                        "attribute `{}` is a {}, it cannot be set to a {}",
                        cx.program.attrs[id as usize].name,
                        type_name(&current),
                        type_name(v)
                    ),
                    arg.span,
                ));
            }
            shape.set_attr(id, v.clone());
        }
        SetTarget::Shape(f) => match f {
            ShapeFn::Material(field) => match v {
                Value::Float(_) | Value::Bool(_) | Value::Str(_) => {
                    let edit = MaterialEdit::Field(field, v.clone());
                    cx.edit_material(shape, edit, |_, m| set_field(m, field, v, arg))?
                }
                _ => set_field(Arc::make_mut(&mut shape.material), field, v, arg)?,
            },
            ShapeFn::TrimHorizontal => shape.trim.horizontal = arg.boolean()?,
            ShapeFn::TrimVertical => shape.trim.vertical = arg.boolean()?,
            ShapeFn::Seedian => {
                shape.seedian = arg.num()?;
                shape.rng.set(crate::lot::seed_stream(shape.seedian));
            }
            ShapeFn::Scope(i) => {
                let x = arg.num()?;
                let k = (i % 3) as usize;
                match i / 3 {
                    0 => {
                        let mut t = shape.pivot.to_local(shape.scope.frame.origin);
                        t[k] = x;
                        shape.scope.frame.origin = shape.pivot.to_object(t);
                    }
                    1 => {
                        let mut rot = shape.scope.rot;
                        rot[k] = x;
                        let axes = shape.pivot.axes * euler_to_mat(rot);
                        shape.scope.frame.axes = axes;
                        shape.scope.rot = rot;
                    }
                    _ => {
                        let mut s = shape.scope.size;
                        s[k] = x;
                        shape.resize(s);
                    }
                }
            }
            ShapeFn::Pivot(i) => {
                let x = arg.num()?;
                let k = (i % 3) as usize;
                let init = cx.initial.pivot;
                if i < 3 {
                    let mut p = init.to_local(shape.pivot.origin);
                    p[k] = x;
                    shape.pivot.origin = init.to_object(p);
                } else {
                    let mut o =
                        crate::shape::mat_to_euler(&(init.axes.transpose() * shape.pivot.axes));
                    o[k] = x;
                    shape.pivot.axes = init.axes * euler_to_mat(o);
                }
                // The scope keeps its place in object coordinates.
                let pivot_axes = shape.pivot.axes;
                let axes = shape.scope.frame.axes;
                shape.scope.set_axes(&pivot_axes, axes);
            }
            other => return Err(RtError::new(format!("{other:?} cannot be set"), arg.span)),
        },
    }
    Ok(())
}
