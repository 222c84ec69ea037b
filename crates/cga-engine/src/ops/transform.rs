//! Scope transformations that carry the geometry along: `t`, `translate`,
//! `s`, `r`, `rotate`, `center`. All O(1): the geometry is scope-local.

use cga_geometry::{DMat3, DVec3};

use super::TransformOp;
use crate::derive::{Arg, Interp, RtError, ShapeState};
use crate::shape::{euler_to_mat, mat_to_euler, Shape};

pub fn exec(
    cx: &mut Interp,
    st: &mut ShapeState,
    op: TransformOp,
    args: &[Arg],
) -> Result<(), RtError> {
    let shape = &mut st.shape;
    match op {
        TransformOp::T => {
            let v = vec3(args, shape.scope.size)?;
            shape.scope.frame.origin += shape.scope.frame.axes * v;
        }
        TransformOp::Translate => {
            let mode = selector(&args[0], &["abs", "rel"])?;
            let system = selector(&args[1], &["scope", "pivot", "object", "world"])?;
            let v = vec3(&args[2..], shape.scope.size)?;
            let axes = system_axes(cx, shape, system);
            let f = &mut shape.scope.frame;
            match (mode, system) {
                ("rel", _) | ("abs", "scope") => f.origin += axes * v,
                ("abs", "pivot") => f.origin = shape.pivot.to_object(v),
                ("abs", "object") => f.origin = cx.initial.pivot.to_object(v),
                _ => f.origin = v,
            }
        }
        TransformOp::S => {
            let size = vec3(args, shape.scope.size)?;
            shape.resize(size);
        }
        TransformOp::R => {
            let (center, angles) = match args.len() {
                4 => (
                    selector(&args[0], &["scopeOrigin", "scopeCenter"])?,
                    &args[1..],
                ),
                _ => ("scopeOrigin", args),
            };
            // `r` adds to the scope's Euler angles (relative to the pivot).
            let angles = vec3(angles, DVec3::ONE)?;
            let rot = shape.scope.rot + angles;
            let target = shape.pivot.axes * euler_to_mat(rot);
            let delta = target * shape.scope.frame.axes.transpose();
            rotate_about(shape, delta, center == "scopeCenter");
            shape.scope.rot = rot;
        }
        TransformOp::Rotate => {
            let mode = selector(&args[0], &["abs", "rel"])?;
            let system = selector(&args[1], &["scope", "pivot", "object", "world"])?;
            let angles = vec3(&args[2..], DVec3::ONE)?;
            let axes = system_axes(cx, shape, system);
            // The scope's orientation as Euler angles in the system: `abs`
            // sets them, `rel` adds to them (so `rotate(rel, pivot, ..)` is
            // `r(..)`, as the reference says). In the pivot system these are
            // the stored scope.r, which keep what `r` accumulated.
            let current = if system == "pivot" {
                shape.scope.rot
            } else {
                mat_to_euler(&(axes.transpose() * shape.scope.frame.axes))
            };
            let target_angles = match mode {
                "abs" => angles,
                _ => current + angles,
            };
            let target = axes * euler_to_mat(target_angles);
            let delta = target * shape.scope.frame.axes.transpose();
            rotate_about(shape, delta, false);
            if system == "pivot" {
                shape.scope.rot = target_angles;
            } else {
                let pivot_axes = shape.pivot.axes;
                let axes = shape.scope.frame.axes;
                shape.scope.set_axes(&pivot_axes, axes);
            }
        }
        TransformOp::Center => {
            let which = selector(&args[0], &["x", "y", "z", "xy", "xz", "yz", "xyz"])?;
            let parent = shape.parent_center;
            let own = shape.scope.center();
            let axes = shape.scope.frame.axes;
            let mut d = axes.transpose() * (parent - own);
            if !which.contains('x') {
                d.x = 0.0;
            }
            if !which.contains('y') {
                d.y = 0.0;
            }
            if !which.contains('z') {
                d.z = 0.0;
            }
            shape.scope.frame.origin += axes * d;
        }
    }
    Ok(())
}

/// Turns the scope (and the geometry with it) by `rotation` (object
/// coordinates) about its origin or its center.
fn rotate_about(shape: &mut Shape, rotation: DMat3, about_center: bool) {
    let f = &mut shape.scope.frame;
    let pivot_point = if about_center {
        f.to_object(shape.scope.size * 0.5)
    } else {
        f.origin
    };
    f.origin = pivot_point + rotation * (f.origin - pivot_point);
    f.axes = orthonormalize(rotation * f.axes);
}

/// Removes the drift of repeated rotations.
pub fn orthonormalize(m: DMat3) -> DMat3 {
    let x = m.x_axis.normalize_or(DVec3::X);
    let y = (m.y_axis - x * x.dot(m.y_axis)).normalize_or(DVec3::Y);
    let z = if m.determinant() >= 0.0 {
        x.cross(y)
    } else {
        -x.cross(y)
    };
    DMat3::from_cols(x, y, z)
}

fn system_axes(cx: &Interp, shape: &Shape, system: &str) -> DMat3 {
    match system {
        "scope" => shape.scope.frame.axes,
        "pivot" => shape.pivot.axes,
        "object" => cx.initial.pivot.axes,
        _ => DMat3::IDENTITY,
    }
}

/// Three numbers, each possibly relative (`'0.5` = half of the scope size).
pub fn vec3(args: &[Arg], base: DVec3) -> Result<DVec3, RtError> {
    Ok(DVec3::new(
        args[0].size(base.x)?,
        args[1].size(base.y)?,
        args[2].size(base.z)?,
    ))
}

/// A selector argument that must be one of `allowed`.
pub fn selector<'a>(arg: &'a Arg, allowed: &[&str]) -> Result<&'a str, RtError> {
    let s = arg.text()?;
    if allowed.contains(&s) {
        Ok(s)
    } else {
        Err(RtError::new(
            format!(
                "unknown selector `{s}`: expected one of {}",
                allowed.join(", ")
            ),
            arg.span,
        ))
    }
}
