//! Operations that rework the current geometry in place: `convexify`,
//! `deleteHoles`, `cleanupGeometry`, `reverseNormals`, `setNormals`,
//! `softenNormals`, `mirror`, `reduceGeometry` and `rectify`. None of them creates shapes;
//! the scope stays where it is (its size is refitted by `convexify` only if
//! nothing changes it: splitting a face keeps its bounding box).

use cga_geometry::{DAffine3, DVec3, Mesh};

use super::transform::selector;
use super::CleanupOp;
use crate::derive::{Arg, Interp, RtError, ShapeState};

pub fn exec(
    cx: &mut Interp,
    st: &mut ShapeState,
    op: CleanupOp,
    args: &[Arg],
) -> Result<(), RtError> {
    let shape = &mut st.shape;
    match op {
        CleanupOp::Convexify => {
            let max = match args.first() {
                Some(a) => {
                    let m = a.num()?;
                    (m >= 0.0).then_some(m)
                }
                None => None,
            };
            let mesh = shape.geometry.local().clone();
            if !mesh.faces.is_empty() {
                let mut out = cga_geometry::convexify::convexify(&mesh, max);
                cga_geometry::uv_carry::carry_uvs(&mesh, &mut out);
                shape.set_local_mesh(out);
            }
        }
        CleanupOp::DeleteHoles => {
            let mesh = shape.geometry.local().clone();
            if mesh.loops.len() > mesh.faces.len() {
                shape.set_local_mesh(delete_holes(&mesh));
            }
        }
        // Edited in place: a mesh no other shape shares (a component just
        // made, most often) is not copied first.
        CleanupOp::ReverseNormals => reverse_keeping_first_edge(shape.geometry.local_mut()),
        CleanupOp::SetNormals => {
            let mode = selector(&args[0], &["hard", "conform", "soft", "auto"])?;
            let mesh = shape.geometry.local_mut();
            match mode {
                "hard" => cga_geometry::normals::soften_normals(mesh, 0.0),
                "conform" => {
                    cga_geometry::normals::conform_orientation(mesh);
                    cga_geometry::normals::soften_normals(mesh, 0.0);
                }
                "soft" => cga_geometry::normals::soften_normals(mesh, 180.0),
                _ => cga_geometry::normals::soften_normals(mesh, 30.0),
            }
        }
        CleanupOp::SoftenNormals => {
            let angle = args[0].num()?;
            cga_geometry::normals::soften_normals(shape.geometry.local_mut(), angle);
        }
        CleanupOp::Mirror => {
            // Mirror inside the scope box: x -> sx - x along flipped axes.
            // The scope stays; a mirror that turns the geometry inside out
            // (an odd number of flips) reverses the faces so that they keep
            // facing outwards (the lazy map does that for negative
            // determinants).
            let mut scale = DVec3::ONE;
            let mut shift = DVec3::ZERO;
            for k in 0..3 {
                if flag(&args[k])? {
                    scale[k] = -1.0;
                    shift[k] = shape.scope.size[k];
                }
            }
            if scale != DVec3::ONE {
                shape
                    .geometry
                    .transform(DAffine3::from_translation(shift) * DAffine3::from_scale(scale));
            }
        }
        CleanupOp::CleanupGeometry => {
            let what = selector(&args[0], &["vertices", "edges", "faces", "all"])?;
            let tol = args[1].num()?;
            if !(0.0..=1.0).contains(&tol) {
                cx.warn_once(args[1].span, || {
                    format!("cleanupGeometry: the tolerance {tol} is outside [0, 1]; it is clamped")
                });
            }
            let mesh = shape.geometry.local().clone();
            let out =
                cga_geometry::cleanup::cleanup(&mesh, cleanup_parts(what), tol.clamp(0.0, 1.0));
            shape.set_local_mesh(out);
        }
        CleanupOp::ReduceGeometry => {
            let r = args[0].num()?;
            let mesh = shape.geometry.local().clone();
            let out = cga_geometry::cleanup::reduce(&mesh, r.clamp(0.0, 1.0));
            shape.set_local_mesh(out);
        }
        CleanupOp::Rectify => {
            let angle = args[0].num()?;
            let mesh = shape.geometry.local().clone();
            let out = cga_geometry::cleanup::rectify(&mesh, angle.clamp(0.0, 45.0));
            shape.set_local_mesh(out);
        }
    }
    Ok(())
}

fn cleanup_parts(what: &str) -> cga_geometry::cleanup::Parts {
    use cga_geometry::cleanup::Parts;
    match what {
        "vertices" => Parts {
            vertices: true,
            ..Parts::default()
        },
        "edges" => Parts {
            edges: true,
            ..Parts::default()
        },
        "faces" => Parts {
            faces: true,
            ..Parts::default()
        },
        _ => Parts {
            vertices: true,
            edges: true,
            faces: true,
        },
    }
}

/// A boolean argument (a float counts as true when not zero).
fn flag(a: &Arg) -> Result<bool, RtError> {
    match a.value {
        cga_value::Value::Float(x) => Ok(x != 0.0),
        _ => a.boolean(),
    }
}

/// The mesh with the hole loops of every face removed (per-corner
/// attributes of the outer loops kept).
fn delete_holes(mesh: &Mesh) -> Mesh {
    let mut out = mesh.clone();
    out.corners.clear();
    out.loops.clear();
    out.faces.clear();
    for set in out.uvs.iter_mut().flatten() {
        set.clear();
    }
    if let Some(n) = &mut out.normals {
        n.clear();
    }
    for f in 0..mesh.faces.len() {
        let l = mesh.outer_loop(f);
        let r = mesh.loop_corners(l);
        let start = out.corners.len() as u32;
        out.corners.extend_from_slice(&mesh.corners[r.clone()]);
        for (k, set) in out.uvs.iter_mut().enumerate() {
            if let (Some(dst), Some(src)) = (set.as_mut(), mesh.uvs[k].as_ref()) {
                dst.extend_from_slice(&src[r.clone()]);
            }
        }
        if let (Some(dst), Some(src)) = (out.normals.as_mut(), mesh.normals.as_ref()) {
            dst.extend_from_slice(&src[r.clone()]);
        }
        out.loops.push(cga_geometry::Loop { start, len: l.len });
        let mut face = mesh.faces[f];
        face.first_loop = (out.loops.len() - 1) as u32;
        face.loop_count = 1;
        out.faces.push(face);
    }
    out
}

/// `reverseNormals`: every loop runs the other way and keeps its first edge
/// (op_reverseNormals.md: "the First Edge is retained"): `c0 c1 .. cn-1`
/// becomes `c1 c0 cn-1 .. c2`, per-corner attributes along; normals are
/// negated.
fn reverse_keeping_first_edge(mesh: &mut Mesh) {
    fn reorder<T: Copy>(v: &mut [T]) {
        // c0 c1 .. cn-1 -> c1 c0 cn-1 .. c2: reverse all, then rotate so
        // that c1 comes first.
        v.reverse();
        let n = v.len();
        v.rotate_left(n - 2);
    }
    for l in mesh.loops.clone() {
        let r = mesh.loop_corners(l);
        if r.len() < 3 {
            continue;
        }
        reorder(&mut mesh.corners[r.clone()]);
        for uv in mesh.uvs.iter_mut().flatten() {
            reorder(&mut uv[r.clone()]);
        }
        if let Some(n) = &mut mesh.normals {
            reorder(&mut n[r.clone()]);
        }
        if let Some(t) = &mut mesh.vertex_tags {
            reorder(&mut t[r.clone()]);
        }
        if let Some(t) = &mut mesh.edge_tags {
            // The edge that started at ci now starts at ci+1: e0 en-1 .. e1.
            let e = &mut t[r.clone()];
            e.reverse();
            e.rotate_left(e.len() - 1);
        }
    }
    if let Some(n) = &mut mesh.normals {
        for v in n {
            *v = -*v;
        }
    }
}
