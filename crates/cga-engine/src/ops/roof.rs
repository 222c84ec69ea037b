//! The roof operations `roofHip`, `roofGable`, `roofPyramid`, `roofShed`
//! and `roofRidge`: argument forms, the geometry (`cga_geometry::roof`) and
//! the scope of the roof shape.
//!
//! Every face of the current geometry is a footprint; its roof is built in
//! the face's plane, "up" being the face normal. The shape keeps one mesh:
//! per footprint the base (`roof.bottom`), the roof planes (`roof.top`) and
//! the pediments or side walls (`roof.side*`), in the order documented in
//! `cga_geometry::roof`. The scope follows the reference pages: y along
//! the normal of the first face, x the old x axis projected onto the face
//! plane, z normal to both, sizes fitted to the roof.
//!
//! `comp(e)` on a roof selects `eave`, `hip`, `valley` and `ridge` from the
//! geometry (`ops::comp` classifies the edges of any mesh the way
//! `cga_geometry::roof` classifies the roof it builds), so the classes
//! survive transformations, `comp(f)` and re-assembly of the roof faces.

use cga_geometry::roof::{roof, RoofKind, RoofSlope};
use cga_geometry::{measure, DMat3, DVec3, Mesh};

use super::transform::selector;
use super::RoofOp;
use crate::derive::{Arg, Interp, RtError, ShapeState};
use crate::expr::OpCall;
use crate::shape::Shape;

pub fn exec(
    cx: &mut Interp,
    st: &mut ShapeState,
    op: RoofOp,
    call: &OpCall,
    args: &[Arg],
) -> Result<(), RtError> {
    let (slope, rest) = slope_args(args)?;
    let name = op_name(op);
    let mesh = st.shape.geometry.local().clone();
    if mesh.faces.is_empty() {
        return Ok(());
    }
    let kind = match op {
        RoofOp::Hip => RoofKind::Hip {
            overhang: opt_num(rest.first(), 0.0)?,
            even: opt_bool(rest.get(1), false)?,
        },
        RoofOp::Gable => {
            // The angle form has the index as fifth argument; the
            // valueType form has no index (its fifth argument is `even`).
            let index = match (args[0].value.as_str().is_some(), rest.get(3)) {
                (false, Some(a)) => Some(edge_index(a, &mesh)?),
                _ => None,
            };
            RoofKind::Gable {
                overhang_x: opt_num(rest.first(), 0.0)?,
                overhang_y: opt_num(rest.get(1), 0.0)?,
                even: opt_bool(rest.get(2), false)?,
                index,
            }
        }
        RoofOp::Pyramid => RoofKind::Pyramid,
        RoofOp::Shed => RoofKind::Shed {
            index: match rest.first() {
                Some(a) => edge_index(a, &mesh)?,
                None => 0,
            },
        },
        RoofOp::Ridge => RoofKind::Ridge { ridge: DVec3::X },
    };
    let too_many = match op {
        RoofOp::Hip => 2,
        RoofOp::Gable => 4,
        RoofOp::Shed => 1,
        _ => 0,
    };
    if rest.len() > too_many {
        return Err(RtError::new(
            format!("`{name}` takes at most {too_many} argument(s) after the angle or height"),
            rest[too_many].span,
        ));
    }
    let r = roof(&mesh, slope, kind);
    if let Some((f, e)) = r.failed.first() {
        let (f, e, n) = (*f, e.clone(), r.failed.len());
        cx.warn_once(call.span, || {
            format!(
                "{name}: the roof of face {f} could not be built ({e}){}; such faces keep only their base",
                if n > 1 { format!(" nor that of {} other face(s)", n - 1) } else { String::new() }
            )
        });
    }
    let up = first_normal(&mesh);
    let mut out = r.mesh;
    cga_geometry::tags::set_face_auto_tags(&mut out, "roof", |f| {
        r.roles.get(f).map_or("roof.bottom", |role| role.tag())
    });
    set_mesh_y_up(&mut st.shape, out, up);
    Ok(())
}

fn op_name(op: RoofOp) -> &'static str {
    match op {
        RoofOp::Hip => "roofHip",
        RoofOp::Gable => "roofGable",
        RoofOp::Pyramid => "roofPyramid",
        RoofOp::Shed => "roofShed",
        RoofOp::Ridge => "roofRidge",
    }
}

/// `(angle, ...)` or `(byAngle|byHeight, value, ...)`: the slope and the
/// arguments after it.
fn slope_args(args: &[Arg]) -> Result<(RoofSlope, &[Arg]), RtError> {
    if args[0].value.as_str().is_some() {
        let how = selector(&args[0], &["byAngle", "byHeight"])?;
        let Some(v) = args.get(1) else {
            return Err(RtError::new(
                format!("`{how}` needs a value after it"),
                args[0].span,
            ));
        };
        let x = v.num()?;
        let slope = if how == "byAngle" {
            RoofSlope::Angle(x)
        } else {
            RoofSlope::Height(x)
        };
        Ok((slope, &args[2..]))
    } else {
        Ok((RoofSlope::Angle(args[0].num()?), &args[1..]))
    }
}

fn opt_num(a: Option<&Arg>, default: f64) -> Result<f64, RtError> {
    a.map_or(Ok(default), Arg::num)
}

fn opt_bool(a: Option<&Arg>, default: bool) -> Result<bool, RtError> {
    match a {
        None => Ok(default),
        Some(a) => match a.value {
            cga_value::Value::Float(x) => Ok(x != 0.0),
            _ => a.boolean(),
        },
    }
}

/// An edge index of the first face's outer loop, modulo wrapped (negative
/// indices count from the end).
fn edge_index(a: &Arg, mesh: &Mesh) -> Result<usize, RtError> {
    let x = a.num()?.floor();
    let n = mesh
        .faces
        .first()
        .map_or(1, |_| mesh.outer_loop(0).len.max(1)) as f64;
    Ok(x.rem_euclid(n) as usize)
}

/// The normal of the first face with an area (scope-local), if any.
pub(crate) fn first_normal(mesh: &Mesh) -> Option<DVec3> {
    (0..mesh.faces.len())
        .map(|f| measure::face_normal(mesh, f))
        .find(|n| n.length_squared() > 0.5)
}

/// Replaces the geometry by `mesh` (scope-local) and sets the scope as the
/// roof, taper and envelope pages prescribe: y along `up` (scope-local; the
/// old y if `None`), x the old x axis projected onto the plane normal to y
/// (another axis of that plane if the old x is parallel to y), z normal to
/// both, sizes fitted to the geometry.
pub(crate) fn set_mesh_y_up(shape: &mut Shape, mesh: Mesh, up: Option<DVec3>) {
    let local_y = up.unwrap_or(DVec3::Y);
    let x = (DVec3::X - local_y * local_y.x)
        .try_normalize()
        .unwrap_or_else(|| local_y.any_orthonormal_vector());
    let local_axes = DMat3::from_cols(x, local_y, x.cross(local_y));
    let axes = shape.scope.frame.axes * local_axes;
    shape.set_local_mesh(mesh);
    shape.fit_scope(axes);
}
