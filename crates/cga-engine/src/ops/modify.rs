//! `modify(component[, scopeAlignment]) { selector operator operations | ... }`
//! (op_modify.md, cga_shapeRecomposition.md).
//!
//! The component split of `comp` (`ops::comp::run`: same components,
//! selectors, operators, alignment and `comp.*` attributes) runs on a copy
//! of the shape while its leaves are collected; then the edited components
//! are recomposed with the geometry no entry touched, and the result
//! replaces the current shape's geometry (its scope keeps its axes and is
//! fitted to the result). The shape gets no successors.
//!
//! "The geometry no entry touched": for face, group and material
//! components, the faces of the unselected components; for edges, vertices
//! and holes, the whole geometry, whose faces then follow what the edited
//! edges and vertices did (the edge and vertex shapes themselves are not
//! part of the result). A component deleted with `NIL` takes its faces
//! away but still moves the vertices it shares ("all split pieces are
//! deleted, yet the modifications are still applied to the side faces").

use std::sync::Arc;

use cga_geometry::recompose::{recompose, Part};
use cga_geometry::{DVec3, Mesh};
use cga_value::Value;

use super::inline::{
    bake_material, begin_collect, end_collect, read_rest, set_object_mesh, Tracking,
};
use crate::derive::{Arg, Interp, RtError, ShapeState};
use crate::expr::OpCall;
use crate::material_attr::MaterialOverrides;

pub fn exec(
    cx: &mut Interp,
    st: &mut ShapeState,
    call: &OpCall,
    args: &[Arg],
    frame: &[Value],
) -> Result<(), RtError> {
    let whole_faces = !matches!(args.first().map(|a| a.text()), Some(Ok("f" | "g" | "m")));
    let tracking = Tracking::begin(&mut st.shape);
    let start = st.shape.object_mesh();
    // The comp runs on a copy: its `has_successor` is not this shape's.
    let mut wst = ShapeState::new(st.shape.clone());
    let saved = begin_collect(cx);
    let mut used = Vec::new();
    let r = cx.derive_all_now(|cx| {
        used = super::comp::run(cx, &mut wst, call, args, frame)?;
        Ok(())
    });
    let collected = end_collect(cx, saved);
    r?;
    st.shape.rng.set(wst.shape.rng.get());

    let mut untouched = if whole_faces {
        start
    } else {
        without_faces(&start, &used)
    };
    let current = st.shape.material.clone();
    let uniform = collected
        .iter()
        .filter(|c| !c.deleted)
        .all(|c| Arc::ptr_eq(&c.shape.material, &current) || *c.shape.material == *current);
    let mut meshes: Vec<(Mesh, bool)> = Vec::with_capacity(collected.len());
    for c in &collected {
        let mut m = c.shape.object_mesh();
        if !uniform && !c.deleted {
            bake_material(&mut m, &c.shape.material);
        }
        meshes.push((m, c.deleted));
    }
    if !uniform {
        bake_material(&mut untouched, &current);
    }
    let rest_untouched = read_rest(&untouched);
    let rests: Vec<Vec<Option<DVec3>>> = meshes.iter().map(|(m, _)| read_rest(m)).collect();
    let mut parts = Vec::with_capacity(meshes.len() + 1);
    parts.push(Part {
        mesh: &untouched,
        rest: &rest_untouched,
        keep_faces: true,
        keep_points: true,
    });
    for ((m, deleted), rest) in meshes.iter().zip(&rests) {
        parts.push(Part {
            mesh: m,
            rest,
            keep_faces: !deleted,
            keep_points: false,
        });
    }
    let mut merged = recompose(&parts).mesh;
    tracking.end(&mut merged);
    set_object_mesh(&mut st.shape, merged);
    if !uniform {
        st.shape.material = Arc::new(MaterialOverrides::default());
    }
    Ok(())
}

/// `mesh` without the faces marked in `drop` (positions kept as they are).
fn without_faces(mesh: &Mesh, drop: &[bool]) -> Mesh {
    let mut out = Mesh::new();
    out.positions = mesh.positions.clone();
    out.materials = mesh.materials.clone();
    out.groups = mesh.groups.clone();
    let keep_uv: Vec<bool> = mesh.uvs.iter().map(|u| u.is_some()).collect();
    for (s, k) in keep_uv.iter().enumerate() {
        if *k {
            out.uvs[s] = Some(Vec::new());
        }
    }
    if mesh.normals.is_some() {
        out.normals = Some(Vec::new());
    }
    for f in 0..mesh.faces.len() {
        if drop.get(f).copied().unwrap_or(false) {
            continue;
        }
        let first_loop = out.loops.len() as u32;
        for &l in mesh.face_loops(f) {
            let start = out.corners.len() as u32;
            for c in mesh.loop_corners(l) {
                out.corners.push(mesh.corners[c]);
                for (s, dst) in out.uvs.iter_mut().enumerate() {
                    if let (Some(dst), Some(src)) = (dst.as_mut(), &mesh.uvs[s]) {
                        dst.push(src.get(c).copied().unwrap_or_default());
                    }
                }
                if let (Some(dst), Some(src)) = (out.normals.as_mut(), &mesh.normals) {
                    dst.push(src.get(c).copied().unwrap_or_default());
                }
            }
            out.loops.push(cga_geometry::Loop { start, len: l.len });
        }
        let mut face = mesh.faces[f];
        face.first_loop = first_loop;
        out.faces.push(face);
    }
    out
}
