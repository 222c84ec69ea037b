//! Operations that change the scope or pivot while the geometry stays in
//! place: `alignScopeToAxes`, `alignScopeToGeometry`, `setPivot`,
//! `rotateScope`, `mirrorScope`; and `resetGeometry`.

use cga_geometry::{DMat3, DVec3};

use super::transform::selector;
use super::Op;
use crate::derive::{Arg, Interp, RtError, ShapeState};
use crate::expr::OpCall;
use crate::shape::{euler_to_mat, Frame, Shape};
use cga_geometry::measure as geom;

pub fn exec(
    cx: &mut Interp,
    st: &mut ShapeState,
    call: &OpCall,
    args: &[Arg],
) -> Result<(), RtError> {
    let shape = &mut st.shape;
    match call.op {
        Op::AlignScopeToAxes => {
            let which = match args.first() {
                Some(a) => selector(
                    a,
                    &[
                        "x",
                        "y",
                        "z",
                        "world.x",
                        "world.y",
                        "world.z",
                        "world.xyz",
                        "object.x",
                        "object.y",
                        "object.z",
                        "object.xyz",
                    ],
                )?,
                None => "world.xyz",
            };
            let (base, axis) = match which.split_once('.') {
                Some((system, axis)) => (
                    if system == "object" {
                        cx.initial.pivot.axes
                    } else {
                        DMat3::IDENTITY
                    },
                    axis,
                ),
                None => (DMat3::IDENTITY, which),
            };
            let cur = shape.scope.frame.axes;
            let axes = match axis {
                "xyz" => base,
                "x" => {
                    // x fixed; z projected onto the yz plane.
                    let x = base.x_axis;
                    let z = project_out(cur.z_axis, x, base.z_axis);
                    DMat3::from_cols(x, z.cross(x), z)
                }
                "y" => {
                    let y = base.y_axis;
                    let x = project_out(cur.x_axis, y, base.x_axis);
                    DMat3::from_cols(x, y, x.cross(y))
                }
                _ => {
                    let z = base.z_axis;
                    let x = project_out(cur.x_axis, z, base.x_axis);
                    DMat3::from_cols(x, z.cross(x), z)
                }
            };
            align_pivot_and_scope(shape, axes);
        }
        Op::AlignScopeToGeometry => {
            let up = selector(&args[0], &["yUp", "zUp", "xUp"])?;
            let mesh = shape.object_mesh();
            if mesh.faces.is_empty() {
                return Ok(());
            }
            let (face, edge) = pick_face_edge(&mesh, &args[1], args.get(2))?;
            let l = mesh.outer_loop(face);
            let idx = mesh.loop_indices(l);
            let a = mesh.positions[idx[edge] as usize];
            let b = mesh.positions[idx[(edge + 1) % idx.len()] as usize];
            let n = geom::face_normal(&mesh, face);
            let x = (b - a).normalize_or(DVec3::X);
            let x = (x - n * x.dot(n)).normalize_or(x);
            let axes = match up {
                "zUp" => DMat3::from_cols(x, n.cross(x), n),
                _ => DMat3::from_cols(x, n, x.cross(n)),
            };
            align_pivot_and_scope(shape, axes);
        }
        Op::SetPivot => {
            let map = selector(&args[0], &["xyz", "yzx", "zxy"])?;
            let corner = args[1].num()?.round().clamp(0.0, 7.0) as usize;
            set_pivot(shape, map, corner);
        }
        Op::RotateScope => {
            let angles = super::transform::vec3(args, DVec3::ONE)?;
            let rot = shape.scope.rot + angles;
            let axes = shape.pivot.axes * euler_to_mat(rot);
            shape.fit_scope(axes);
        }
        Op::MirrorScope => {
            let flips = [args[0].boolean()?, args[1].boolean()?, args[2].boolean()?];
            let mut scope = shape.scope;
            let mut cols = [
                scope.frame.axes.x_axis,
                scope.frame.axes.y_axis,
                scope.frame.axes.z_axis,
            ];
            for i in 0..3 {
                if flips[i] {
                    scope.frame.origin += cols[i] * scope.size[i];
                    cols[i] = -cols[i];
                }
            }
            scope.frame.axes = DMat3::from_cols(cols[0], cols[1], cols[2]);
            shape.reframe_scope(scope);
            let pivot_axes = shape.pivot.axes;
            let axes = shape.scope.frame.axes;
            shape.scope.set_axes(&pivot_axes, axes);
        }
        Op::ResetGeometry => {
            let init = &cx.initial;
            shape.geometry = init.geometry.clone();
            shape.scope = init.scope;
            shape.pivot = init.pivot;
        }
        _ => unreachable!("not a scope operation"),
    }
    Ok(())
}

/// `v` without its component along `axis`, normalised (or `fallback`).
fn project_out(v: DVec3, axis: DVec3, fallback: DVec3) -> DVec3 {
    (v - axis * v.dot(axis)).try_normalize().unwrap_or(fallback)
}

/// Pivot and scope on the geometry's bounding box in `axes`, scope.t and
/// scope.r zero, geometry in place.
fn align_pivot_and_scope(shape: &mut Shape, axes: DMat3) {
    shape.pivot.axes = axes;
    shape.fit_scope(axes);
    shape.pivot.origin = shape.scope.frame.origin;
    shape.scope.rot = DVec3::ZERO;
}

fn pick_face_edge(
    mesh: &cga_geometry::Mesh,
    face_arg: &Arg,
    edge_arg: Option<&Arg>,
) -> Result<(usize, usize), RtError> {
    let nf = mesh.faces.len();
    let edge_len = |f: usize, e: usize| {
        let idx = mesh.loop_indices(mesh.outer_loop(f));
        let a = mesh.positions[idx[e] as usize];
        let b = mesh.positions[idx[(e + 1) % idx.len()] as usize];
        (a, b)
    };
    let n_edges = |f: usize| mesh.loop_indices(mesh.outer_loop(f)).len();
    let modulo = |i: f64, n: usize| ((i.round() as i64).rem_euclid(n.max(1) as i64)) as usize;
    let edge_sel = edge_arg.map(|a| (a, matches!(a.value, cga_value::Value::Str(_))));
    // Candidate faces.
    let faces: Vec<usize> = match &face_arg.value {
        cga_value::Value::Str(s) => match &**s {
            "largest" => vec![(0..nf)
                .max_by(|&a, &b| geom::face_area(mesh, a).total_cmp(&geom::face_area(mesh, b)))
                .unwrap_or(0)],
            "world.lowest" => vec![(0..nf)
                .min_by(|&a, &b| {
                    let low = |f: usize| {
                        mesh.loop_points(mesh.outer_loop(f))
                            .map(|p| p.y)
                            .fold(f64::INFINITY, f64::min)
                    };
                    low(a).total_cmp(&low(b))
                })
                .unwrap_or(0)],
            "any" => (0..nf).collect(),
            other => {
                return Err(RtError::new(
                    format!(
                        "unknown face selector `{other}`: expected largest, world.lowest or any"
                    ),
                    face_arg.span,
                ))
            }
        },
        _ => vec![modulo(face_arg.num()?, nf)],
    };
    match edge_sel {
        Some((a, true)) => {
            let which = selector(a, &["world.lowest", "longest"])?;
            let mut best: Option<(f64, usize, usize)> = None;
            for &f in &faces {
                for e in 0..n_edges(f) {
                    let (p, q) = edge_len(f, e);
                    let key = if which == "longest" {
                        -(q - p).length()
                    } else {
                        p.y.min(q.y) + 1e-9 * (p.y.max(q.y))
                    };
                    if best.is_none_or(|(k, _, _)| key < k - 1e-12) {
                        best = Some((key, f, e));
                    }
                }
            }
            let (_, f, e) = best.unwrap_or((0.0, faces[0], 0));
            Ok((f, e))
        }
        Some((a, false)) => {
            let f = faces[0];
            Ok((f, modulo(a.num()?, n_edges(f))))
        }
        None => Ok((faces[0], 0)),
    }
}

/// `setPivot(axisMap, corner)`: the pivot moves to a corner of the scope
/// with axes along the scope's (permuted by `map`), pointing into the scope.
fn set_pivot(shape: &mut Shape, map: &str, corner: usize) {
    let s = shape.scope;
    let a = [
        s.frame.axes.x_axis,
        s.frame.axes.y_axis,
        s.frame.axes.z_axis,
    ];
    // Corner bits: 1 = far in x, 2 = far in z, 4 = far in y.
    let far = [corner & 1 != 0, corner & 4 != 0, corner & 2 != 0];
    let mut origin = s.frame.origin;
    let mut dirs = a;
    for i in 0..3 {
        if far[i] {
            origin += a[i] * s.size[i];
            dirs[i] = -a[i];
        }
    }
    let (x, y) = match map {
        "yzx" => (dirs[2], dirs[0]),
        "zxy" => (dirs[1], dirs[2]),
        _ => (dirs[0], dirs[1]),
    };
    // Keep the frame right-handed: z follows from x and y.
    let axes = DMat3::from_cols(x, y, x.cross(y));
    shape.pivot = Frame { origin, axes };
    shape.fit_scope(axes);
    shape.scope.rot = DVec3::ZERO;
}
