//! Operations that change the scope or pivot while the geometry stays in
//! place: `alignScopeToAxes`, `alignScopeToGeometry`, `setPivot`,
//! `rotateScope`, `mirrorScope`; and `resetGeometry`.

use cga_geometry::{DMat3, DVec3};

use super::transform::selector;
use super::ScopeOp;
use crate::derive::{Arg, Interp, RtError, ShapeState};
use crate::shape::{euler_to_mat, Frame, Shape};
use cga_geometry::measure as geom;

pub fn exec(
    cx: &mut Interp,
    st: &mut ShapeState,
    op: ScopeOp,
    args: &[Arg],
) -> Result<(), RtError> {
    let shape = &mut st.shape;
    match op {
        ScopeOp::AlignScopeToAxes => {
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
        ScopeOp::AlignScopeToGeometry => {
            // xUp is a selector of the reference that CityEngine does not support yet.
            let up = selector(&args[0], &["yUp", "zUp"])?;
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
        ScopeOp::SetPivot => {
            // `yUp`/`zUp` were dropped in 2010.1 for `xyz`/`yzx`
            // (cga_changelog.md); older files still use them.
            let map = match selector(&args[0], &["xyz", "yzx", "zxy", "yUp", "zUp"])? {
                "yUp" => "xyz",
                "zUp" => "yzx",
                other => other,
            };
            let corner = args[1].num()?.round().clamp(0.0, 7.0) as usize;
            set_pivot(shape, map, corner);
        }
        ScopeOp::RotateScope => {
            let angles = super::transform::vec3(args, DVec3::ONE)?;
            let rot = shape.scope.rot + angles;
            let axes = shape.pivot.axes * euler_to_mat(rot);
            shape.fit_scope(axes);
        }
        ScopeOp::MirrorScope => {
            // The scope is (t, r, s) as in CGA: a mirrored axis cannot be a
            // rotation, so it is a negative size seen from the far side of
            // the box (as `s` with a negative size makes). The box, the
            // axes and scope.r stay; the geometry stays where it is.
            let flips = [args[0].boolean()?, args[1].boolean()?, args[2].boolean()?];
            let mut scope = shape.scope;
            let axes = scope.frame.axes;
            for (i, flip) in flips.into_iter().enumerate() {
                if flip {
                    scope.frame.origin += axes.col(i) * scope.size[i];
                    scope.size[i] = -scope.size[i];
                }
            }
            shape.reframe_scope(scope);
        }
        ScopeOp::ResetGeometry => {
            let init = &cx.initial;
            shape.geometry = init.geometry.clone();
            shape.scope = init.scope;
            shape.pivot = init.pivot;
        }
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
            // `auto` (deprecated since 2010.1, still read): any face, and
            // without an edge argument its lowest edge, the longest of
            // those on one level (cga_changelog.md, 2009.2).
            "any" | "auto" => (0..nf).collect(),
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
        None if matches!(&face_arg.value, cga_value::Value::Str(s) if &**s == "auto") => {
            let mut best: Option<((f64, f64), usize, usize)> = None;
            for &f in &faces {
                for e in 0..n_edges(f) {
                    let (p, q) = edge_len(f, e);
                    let key = (p.y.max(q.y), -(q - p).length());
                    let better = best.is_none_or(|((y, l), _, _)| {
                        key.0 < y - 1e-9 || (key.0 <= y + 1e-9 && key.1 < l - 1e-12)
                    });
                    if better {
                        best = Some((key, f, e));
                    }
                }
            }
            let (_, f, e) = best.unwrap_or(((0.0, 0.0), faces[0], 0));
            Ok((f, e))
        }
        None => Ok((faces[0], 0)),
    }
}

/// `setPivot(axisMap, corner)`: the pivot moves to a corner of the scope,
/// its axes along the scope's (permuted by `map`) and pointing into the
/// scope; the scope becomes the same box seen from that corner, with zero
/// translation and rotation; the geometry stays in place.
///
/// Corner bits: 1 = far in x, 2 = far in z, 4 = far in y (0..3 on the
/// scope's floor, 4..7 on its top). In corner 0 the axes are the scope's
/// (`xyz`), or `z, x, y` (`yzx`) or `y, z, x` (`zxy`). Pointing inside from
/// another corner reverses the axes that lead away from it; a right-handed
/// frame (CGA's pivots are right-handed) then keeps the new y-axis and swaps
/// the new x- and z-axes where the reversal made the frame left-handed.
fn set_pivot(shape: &mut Shape, map: &str, corner: usize) {
    let s = shape.scope;
    let far = [corner & 1 != 0, corner & 4 != 0, corner & 2 != 0];
    let mut origin = s.frame.origin;
    let mut inside = [DVec3::ZERO; 3];
    for (i, &far) in far.iter().enumerate() {
        let a = s.frame.axes.col(i);
        // A negative size (a mirrored scope) extends the box along -a.
        let along = if s.size[i] < 0.0 { -a } else { a };
        if far {
            origin += a * s.size[i];
            inside[i] = -along;
        } else {
            inside[i] = along;
        }
    }
    // Old scope axis of the new x, y and z in corner 0.
    let (mut first, up, mut second) = match map {
        "yzx" => (2, 0, 1),
        "zxy" => (1, 2, 0),
        _ => (0, 1, 2),
    };
    if inside[first].cross(inside[up]).dot(inside[second]) < 0.0 {
        std::mem::swap(&mut first, &mut second);
    }
    let axes = DMat3::from_cols(inside[first], inside[up], inside[second]);
    let size = DVec3::new(s.size[first].abs(), s.size[up].abs(), s.size[second].abs());
    shape.pivot = Frame { origin, axes };
    let mut scope = s;
    scope.frame = Frame { origin, axes };
    scope.size = size;
    scope.rot = DVec3::ZERO;
    shape.reframe_scope(scope);
}
