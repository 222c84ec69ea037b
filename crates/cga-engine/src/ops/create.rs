//! Operations that create new geometry: `extrude`, the primitives, `i`
//! (asset insertion) and `reverseNormals`.

use std::sync::Arc;

use cga_geometry::{DAffine3, DMat3, DVec3, Mesh};

use super::transform::selector;
use super::{CreateOp, Primitive};
use crate::derive::{Arg, Interp, RtError, ShapeState};
use crate::expr::OpCall;
use crate::shape::{local_bounds, Shape};

pub fn exec(
    cx: &mut Interp,
    st: &mut ShapeState,
    op: CreateOp,
    call: &OpCall,
    args: &[Arg],
) -> Result<(), RtError> {
    let shape = &mut st.shape;
    match op {
        CreateOp::Extrude => extrude(shape, args),
        CreateOp::Primitive(kind) => primitive(shape, kind, args, &mut cx.plane_logs),
        CreateOp::Insert => insert(cx, shape, call, args),
    }
}

/// A segment count argument: at least `min`.
fn count(arg: Option<&Arg>, default: usize, min: usize) -> Result<usize, RtError> {
    match arg {
        Some(a) => {
            let n = a.num()?;
            if !n.is_finite() || n < min as f64 {
                return Err(RtError::new(
                    format!("expected at least {min}, found {n}"),
                    a.span,
                ));
            }
            Ok((n as usize).min(1 << 14))
        }
        None => Ok(default),
    }
}

fn primitive(
    shape: &mut Shape,
    op: Primitive,
    args: &[Arg],
    logs: &mut [crate::trim::PlaneLog],
) -> Result<(), RtError> {
    use cga_geometry::primitive as p;
    let unit = DVec3::ONE;
    // With dimensions: that size, centred in x and z, standing on y = 0;
    // without: a unit shape fitted to the scope.
    let (mesh, sized, flat) = match op {
        Primitive::Quad => match args {
            [w, l] => (p::quad(w.num()?, l.num()?), true, true),
            _ => (p::quad(1.0, 1.0), false, true),
        },
        Primitive::Disk => {
            let n = count(args.first(), 16, 3)?;
            match args.get(1) {
                Some(r) => {
                    let d = 2.0 * r.num()?;
                    (p::disk(n, d, d), true, true)
                }
                None => (p::disk(n, 1.0, 1.0), false, true),
            }
        }
        Primitive::Cube => match args {
            [w, h, d] => (
                p::cube(DVec3::new(w.num()?, h.num()?, d.num()?)),
                true,
                false,
            ),
            _ => (p::cube(unit), false, false),
        },
        Primitive::Sphere => {
            let sides = count(args.first(), 16, 3)?;
            let divisions = count(args.get(1), 16, 2)?;
            match args.get(2) {
                Some(r) => (
                    p::sphere(sides, divisions, DVec3::splat(2.0 * r.num()?)),
                    true,
                    false,
                ),
                None => (p::sphere(sides, divisions, unit), false, false),
            }
        }
        Primitive::Cylinder | Primitive::Cone => {
            let sides = count(args.first(), 16, 3)?;
            let size = match (args.get(1), args.get(2)) {
                (Some(r), Some(h)) => {
                    let d = 2.0 * r.num()?;
                    Some(DVec3::new(d, h.num()?, d))
                }
                _ => None,
            };
            let make = if op == Primitive::Cylinder {
                p::cylinder
            } else {
                p::cone
            };
            (make(sides, size.unwrap_or(unit)), size.is_some(), false)
        }
    };
    let mut mesh = mesh;
    if !sized {
        // The unit primitive, as an asset, is centred on its origin in x
        // and z and stands on y = 0: a zero-size scope keeps that position,
        // as `i()` keeps an asset's (measured with CityEngine's runtime: a
        // quad into a point scope is centred on the point).
        cga_geometry::transform::transform(
            &mut mesh,
            &DAffine3::from_translation(DVec3::new(-0.5, 0.0, -0.5)),
        );
    }
    // A flat primitive goes into the plane of the scope's non-zero sizes,
    // and with dimensions it is centred within that plane.
    let plane = if flat {
        orient_flat(&mut mesh, shape.scope.size)
    } else {
        None
    };
    let mode = match (sized, plane) {
        (true, Some(normal_axis)) => {
            let mut centre = [true; 3];
            centre[normal_axis] = false;
            InsertMode::Centred(centre)
        }
        (true, None) => InsertMode::KeepSizeAlign,
        (false, _) => InsertMode::Fit,
    };
    let bounds = local_bounds(&mesh);
    insert_fitted_in(
        shape,
        Arc::new(mesh),
        bounds,
        mode,
        crate::trim::Need::Geometry,
        logs,
    );
    Ok(())
}

/// A flat primitive (quad, disk; made in the xz-plane facing +y) goes into
/// the plane of the scope's two non-zero sizes when exactly one size is
/// zero; returns the axis it then faces (`None`: left in the xz-plane).
fn orient_flat(mesh: &mut Mesh, size: DVec3) -> Option<usize> {
    let eps = 1e-12;
    let zero = [size.x.abs() < eps, size.y.abs() < eps, size.z.abs() < eps];
    if zero.iter().filter(|&&z| z).count() != 1 || zero[1] {
        return None;
    }
    let rot = if zero[0] {
        // Facing +x: the yz-plane.
        DMat3::from_rotation_z(-std::f64::consts::FRAC_PI_2)
    } else {
        // Facing +z: the xy-plane.
        DMat3::from_rotation_x(std::f64::consts::FRAC_PI_2)
    };
    cga_geometry::transform::transform(mesh, &DAffine3::from_mat3(rot));
    Some(if zero[0] { 0 } else { 2 })
}

fn insert(cx: &mut Interp, shape: &mut Shape, call: &OpCall, args: &[Arg]) -> Result<(), RtError> {
    let path = args[0].text()?;
    let up_z = match args.get(1) {
        Some(a) => selector(a, &["yUp", "zUp"])? == "zUp",
        None => false,
    };
    let mode = match args.get(2) {
        Some(a) => match selector(
            a,
            &[
                "alignSizeAndPosition",
                "keepSizeAndPosition",
                "keepSizeAlignPosition",
            ],
        )? {
            "keepSizeAndPosition" => InsertMode::Keep,
            "keepSizeAlignPosition" => InsertMode::KeepSizeAlign,
            _ => InsertMode::Fit,
        },
        None => InsertMode::Fit,
    };
    if let Some(a) = args.get(3) {
        selector(a, &["numericalCleanup", "noCleanup"])?;
    }
    let asset = cx.memo.asset(cx.assets, call.span.file, path);
    match asset {
        Ok(mut mesh) => {
            if up_z {
                let rot = DAffine3::from_mat3(DMat3::from_rotation_x(-std::f64::consts::FRAC_PI_2));
                let mut m = (*mesh).clone();
                cga_geometry::transform::transform(&mut m, &rot);
                mesh = Arc::new(m);
            }
            let bounds = cx.memo.bounds(&mesh);
            let need = cx.trim_need(call);
            insert_fitted_in(shape, mesh, bounds, mode, need, &mut cx.plane_logs);
        }
        Err(message) => {
            // A missing asset must not lose the model: warn and go on.
            cx.warn_once(args[0].span, || {
                format!("{message}; the shape keeps its geometry")
            });
        }
    }
    Ok(())
}

#[derive(Clone, Copy, PartialEq, Eq)]
pub enum InsertMode {
    /// Fit the geometry's bounding box to the scope (zero sizes taken from the asset).
    Fit,
    /// Keep the asset's size and position (as a zero-size scope would).
    Keep,
    /// Keep the asset's size, centred in x and z, standing on y = 0.
    KeepSizeAlign,
    /// Keep the asset's size, centred along the marked scope axes.
    Centred([bool; 3]),
}

/// Places `asset` (in its own coordinates, with `bounds`: its
/// `local_bounds`) into the scope as CGA's insert does, including the
/// rules for scope sizes that are zero.
fn insert_fitted_in(
    shape: &mut Shape,
    asset: Arc<Mesh>,
    bounds: Option<(DVec3, DVec3)>,
    mode: InsertMode,
    trim: crate::trim::Need,
    logs: &mut [crate::trim::PlaneLog],
) {
    let Some((lo, hi)) = bounds else {
        shape.set_local_mesh(Mesh::new());
        return;
    };
    let a = hi - lo;
    let mut s = shape.scope.size;
    let mut shift = DVec3::ZERO;
    match mode {
        InsertMode::Keep => {
            s = a;
            shift = lo;
        }
        InsertMode::KeepSizeAlign => {
            shift = DVec3::new((s.x - a.x) * 0.5, 0.0, (s.z - a.z) * 0.5);
            s = a;
        }
        InsertMode::Centred(axes) => {
            for k in 0..3 {
                if axes[k] {
                    shift[k] = (s[k] - a[k]) * 0.5;
                }
            }
            s = a;
        }
        InsertMode::Fit => {
            let eps = 1e-12;
            let zero = [s.x.abs() < eps, s.y.abs() < eps, s.z.abs() < eps];
            match zero.iter().filter(|&&z| z).count() {
                3 => {
                    s = a;
                    shift = lo;
                }
                2 => {
                    let k = (0..3).find(|&i| !zero[i]).unwrap_or(0);
                    let scale = if a[k].abs() > eps { s[k] / a[k] } else { 1.0 };
                    for i in 0..3 {
                        if zero[i] {
                            s[i] = scale * a[i];
                            shift[i] = scale * lo[i];
                        }
                    }
                }
                1 => {
                    let k = (0..3).find(|&i| zero[i]).unwrap_or(0);
                    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
                    let ratio = |n: usize| if a[n].abs() > eps { s[n] / a[n] } else { 1.0 };
                    s[k] = (ratio(i) + ratio(j)) * 0.5 * a[k];
                }
                _ => {}
            }
        }
    }
    let factor = DVec3::new(
        if a.x.abs() > 1e-12 { s.x / a.x } else { 1.0 },
        if a.y.abs() > 1e-12 { s.y / a.y } else { 1.0 },
        if a.z.abs() > 1e-12 { s.z / a.z } else { 1.0 },
    );
    shape.scope.frame.origin += shape.scope.frame.axes * shift;
    shape.scope.size = s;
    let to_local = DAffine3::from_scale(factor) * DAffine3::from_translation(-lo);
    let mut g = crate::shape::Geometry::new(asset);
    g.transform(to_local);
    shape.geometry = g;
    if shape.trim.planes.is_some() {
        // Inserted geometry is cut by the trim planes of a component split
        // (op_i.md); it fills the box [0, size] of the new scope.
        let box_ = Some((DVec3::ZERO.min(s), DVec3::ZERO.max(s)));
        crate::trim::apply(shape, box_, trim, logs);
    }
}

/// Below this distance (absolute, in metres) `extrude` does nothing.
const NEGLIGIBLE_EXTRUSION: f64 = 1.8e-3;

fn extrude(shape: &mut Shape, args: &[Arg]) -> Result<(), RtError> {
    use cga_geometry::Extrusion;
    let (kind, dist) = match args {
        [d] => ("face.normal", d.num()?),
        [k, d] => (
            selector(
                k,
                &[
                    "world.up",
                    "world.up.flatTop",
                    "face.normal",
                    "vertex.normal",
                    // Older forms (cga_changelog.md, 2009.2): `world.x|y|z`
                    // extrude along a world axis, and the deprecated `x|y|z`
                    // are read the same way.
                    "world.x",
                    "world.y",
                    "world.z",
                    "x",
                    "y",
                    "z",
                ],
            )?,
            d.num()?,
        ),
        _ => unreachable!("arity checked by the resolver"),
    };
    // Extrude in object coordinates, where "world up" is +y.
    // CityEngine leaves the face as it is when the distance is (nearly)
    // nothing: one face, no zero-height box (measured with its runtime on
    // lots from 2 x 3 to 200 x 300: the threshold is absolute). A flat top's
    // distance counts from the highest vertex: 0 still builds a solid.
    let negligible = kind != "world.up.flatTop" && dist.abs() < NEGLIGIBLE_EXTRUSION;
    if shape.geometry.is_empty() || negligible {
        return Ok(());
    }
    // Extruded around the scope's origin (see `Shape::oriented_transform`).
    let mesh = shape.take_oriented_mesh();
    let how = match kind {
        "world.up" | "world.y" | "y" => Extrusion::Direction(DVec3::Y),
        "world.x" | "x" => Extrusion::Direction(DVec3::X),
        "world.z" | "z" => Extrusion::Direction(DVec3::Z),
        "world.up.flatTop" => Extrusion::DirectionFlatTop(DVec3::Y),
        "vertex.normal" => Extrusion::VertexNormal,
        _ => Extrusion::FaceNormal,
    };
    let dir = match how {
        Extrusion::Direction(d) | Extrusion::DirectionFlatTop(d) => d,
        // The first face with an area gives the direction; geometry without
        // area (an edge, a collapsed polygon) is extruded along the scope's y.
        _ => (0..mesh.faces.len())
            .map(|f| cga_geometry::measure::face_normal(&mesh, f))
            .find(|n| n.length_squared() > 0.5)
            .unwrap_or(shape.scope.frame.axes.y_axis),
    };
    let (mut out, roles) = cga_geometry::extrude_with_roles(&mesh, how, dist);
    cga_geometry::tags::set_face_auto_tags(&mut out, "extrude", |f| {
        roles.get(f).map_or("extrude.side.outer", |r| r.tag())
    });
    // New scope: y along the extrusion, x the old x made orthogonal to it.
    let y = dir;
    let old_x = shape.scope.frame.axes.x_axis;
    let x = (old_x - y * old_x.dot(y))
        .try_normalize()
        .unwrap_or_else(|| y.any_orthonormal_vector());
    let axes = DMat3::from_cols(x, y, x.cross(y));
    let to_scope = DAffine3::from_mat3(shape.scope.frame.axes).inverse();
    crate::shape::transform_in_place(&mut out, &to_scope);
    shape.set_local_mesh(out);
    shape.fit_scope(axes);
    if dist < 0.0 {
        // A negative extrusion keeps the base at the scope origin with sy < 0.
        let sy = shape.scope.size.y;
        shape.scope.frame.origin += y * sy;
        shape
            .geometry
            .transform(DAffine3::from_translation(DVec3::new(0.0, -sy, 0.0)));
        shape.scope.size.y = -sy;
    }
    Ok(())
}
