//! `inline Rule`, `inline subdivision`, `inline { operations }`, each with an
//! optional merge strategy `(append|unify|recompose)` (op_inline.md), and
//! the recomposition machinery `modify` shares.
//!
//! The operations are derived at once on a copy of the current shape; the
//! leaf shapes they end in are collected instead of emitted
//! (`Interp::collected`) and merged into the current shape:
//!
//! - one leaf: it replaces the current shape as it is (scope, pivot,
//!   attributes and all; the current shape keeps its random stream);
//! - several: their geometries are merged by the strategy into the current
//!   shape, whose scope keeps its orientation and is fitted to the result.
//!   Material attributes that differ between the leaves are written into
//!   each leaf's geometry (all materials are preserved) and the shape's own
//!   material attributes are cleared; attributes that all leaves agree on
//!   are taken, others keep the current shape's value.
//!
//! Strategies: `append` puts the meshes side by side; `recompose` reconnects
//! the pieces (`cga_geometry::recompose`); `unify` appends, welds
//! coincident vertices and removes the faces where pieces touch (pairs of coincident faces facing each
//! other: the cut faces between the parts of a split volume). There is no
//! 3D Boolean union in this engine: pieces that overlap stay overlapping,
//! with a warning.
//!
//! # Tracking vertices through a derivation
//!
//! Recomposition needs, for every vertex of every leaf, the point of the
//! original geometry it came from (its *rest position*). It is written into
//! texture coordinate sets 8 and 9 of the geometry before the derivation:
//! set 8 holds (x, y), set 9 (z, 1) of the rest position in object
//! coordinates. Every operation that keeps or cuts geometry carries texture
//! coordinates along (a split interpolates them along the edge a new vertex
//! lies on), so the leaves come back with their rest positions; geometry
//! made anew (assets, primitives, roofs) has none (the 1 in set 9 tells a
//! tracked corner from a zero-filled one) and is appended unconnected, as
//! CityEngine does for the operations it cannot track. The sets are removed
//! when the outermost recomposition ends. A recomposition nested in another
//! (a `modify` inside an inlined rule) tracks with its own rest positions
//! and converts them back to the outer ones at its end. Rules that use UV
//! sets 8 and 9 themselves lose them inside a recomposition.

use std::sync::Arc;

use cga_geometry::recompose::{recompose, Part, SurfaceMap};
use cga_geometry::{DVec2, DVec3, Mesh};
use cga_value::Value;

use super::transform::selector;
use crate::derive::{Arg, Collected, Interp, RtError, ShapeState};
use crate::expr::{OpCall, RPart};
use crate::material_attr::MaterialOverrides;
use crate::shape::Shape;

/// The texture coordinate sets holding rest positions while recomposing.
const REST_XY: usize = 8;
const REST_Z: usize = 9;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Strategy {
    Append,
    Unify,
    Recompose,
}

pub fn exec(
    cx: &mut Interp,
    st: &mut ShapeState,
    call: &OpCall,
    args: &[Arg],
    frame: &[Value],
) -> Result<(), RtError> {
    let strategy = match args.first() {
        Some(a) => match selector(a, &["append", "unify", "recompose"])? {
            "unify" => Strategy::Unify,
            "recompose" => Strategy::Recompose,
            _ => Strategy::Append,
        },
        None => Strategy::Append,
    };
    let body = match call.block.as_ref().and_then(|b| b.parts.first()) {
        Some(RPart::Unlabeled { body, .. }) => body,
        _ => {
            return Err(RtError::new(
                "`inline` needs operations to derive",
                call.span,
            ))
        }
    };
    // Only recomposition follows the vertices through the derivation; a
    // union works on where the geometry ends up.
    let tracking = match strategy {
        Strategy::Recompose => Some(Tracking::begin(&mut st.shape)),
        _ => None,
    };
    let work = cx.child(&st.shape, call.span)?;
    let saved = begin_collect(cx);
    // The inlined operations and every rule they call are derived now, to
    // the end, before the current shape goes on.
    let r = cx.derive_all_now(|cx| {
        let mut wst = ShapeState::new(work);
        cx.exec_body(body, frame, &mut wst)?;
        cx.finish(wst);
        Ok(())
    });
    let collected = end_collect(cx, saved);
    r?;
    let kept = collected.iter().filter(|c| !c.deleted).count();
    if kept == 1 {
        // "In case it results in a single shape, it is taken as is."
        let Some(mut one) = collected.into_iter().find(|c| !c.deleted).map(|c| c.shape) else {
            return Ok(());
        };
        if let Some(t) = &tracking {
            let m = one.geometry.local_mut();
            t.end(m);
        }
        one.name = st.shape.name;
        one.rng.set(st.shape.rng.get());
        one.parent_center = st.shape.parent_center;
        *st.shape = one;
        return Ok(());
    }
    let uniform = uniform_material(&collected);
    let mut meshes: Vec<(Mesh, bool)> = collected
        .iter()
        .map(|c| {
            let mut m = c.shape.object_mesh();
            if uniform.is_none() && !c.deleted {
                bake_material(&mut m, &c.shape.material);
            }
            (m, c.deleted)
        })
        .collect();
    let mut merged = match strategy {
        // Closed volumes are united with the 3D Boolean union; other
        // pieces (surfaces) are appended, welded and freed of the faces
        // where they touch.
        Strategy::Unify
            if meshes.iter().filter(|(_, d)| !*d).count() > 1
                && meshes
                    .iter()
                    .filter(|(_, d)| !*d)
                    .all(|(m, _)| cga_geometry::measure::is_closed(m)) =>
        {
            let mut pieces = meshes.iter_mut().filter(|(_, d)| !*d).map(|(m, _)| m);
            let mut out = pieces.next().map(std::mem::take).unwrap_or_default();
            for m in pieces {
                use cga_geometry::boolean::{boolean_within, BoolOp};
                out = boolean_within(&out, m, BoolOp::Union, cx.stop())
                    .map_err(|_| cx.time_limit_error(call.span))?
                    .mesh;
            }
            out
        }
        Strategy::Append | Strategy::Unify => {
            let mut out = Mesh::new();
            let mut first = true;
            for (m, _) in meshes.iter_mut().filter(|(_, deleted)| !*deleted) {
                if first {
                    out = std::mem::take(m);
                    first = false;
                } else {
                    cga_geometry::transform::merge(&mut out, m);
                }
            }
            if strategy == Strategy::Unify {
                let (united, overlaps) = cga_geometry::recompose::unify_touching(&out);
                out = united;
                if overlaps {
                    cx.warn_once(call.span, || {
                        "inline(unify): open surfaces are not united by a Boolean union; overlapping pieces are kept as they are (only faces where they touch are removed)".to_string()
                    });
                }
            }
            out
        }
        Strategy::Recompose => {
            let rests: Vec<Vec<Option<DVec3>>> = meshes.iter().map(|(m, _)| read_rest(m)).collect();
            let parts: Vec<Part> = meshes
                .iter()
                .zip(&rests)
                .map(|((m, deleted), rest)| Part {
                    mesh: m,
                    rest,
                    keep_faces: !deleted,
                    keep_points: true,
                })
                .collect();
            recompose(&parts).mesh
        }
    };
    if let Some(t) = &tracking {
        t.end(&mut merged);
    }
    set_object_mesh(&mut st.shape, merged);
    st.shape.material = match uniform {
        Some(m) => m,
        None => Arc::new(MaterialOverrides::default()),
    };
    merge_attrs(&mut st.shape, &collected);
    Ok(())
}

/// Starts collecting leaves; returns what an enclosing collection had
/// (give it back to [`end_collect`]).
pub(crate) fn begin_collect(cx: &mut Interp) -> Option<Vec<Collected>> {
    cx.collected.replace(Vec::new())
}

/// Stops collecting and returns the collected shapes.
pub(crate) fn end_collect(cx: &mut Interp, saved: Option<Vec<Collected>>) -> Vec<Collected> {
    std::mem::replace(&mut cx.collected, saved).unwrap_or_default()
}

/// The material attributes all collected leaves share, if they do.
fn uniform_material(collected: &[Collected]) -> Option<Arc<MaterialOverrides>> {
    let mut leaves = collected.iter().filter(|c| !c.deleted);
    let first = &leaves.next()?.shape.material;
    leaves
        .all(|c| Arc::ptr_eq(&c.shape.material, first) || *c.shape.material == **first)
        .then(|| first.clone())
}

/// Writes material attributes into a mesh's own materials.
pub(crate) fn bake_material(mesh: &mut Mesh, overrides: &MaterialOverrides) {
    if overrides.is_empty() {
        return;
    }
    for m in &mut mesh.materials {
        *m = overrides.apply(m);
    }
}

/// Attributes after inlining several leaves: a value all leaves agree on
/// is taken, others keep the current shape's.
fn merge_attrs(shape: &mut Shape, collected: &[Collected]) {
    let leaves: Vec<&Shape> = collected
        .iter()
        .filter(|c| !c.deleted)
        .map(|c| &c.shape)
        .collect();
    let Some(first) = leaves.first() else {
        return;
    };
    let Some(list) = first.attrs.clone() else {
        return;
    };
    for (id, v) in list.iter() {
        if shape.attr_override(*id) == Some(v) {
            continue;
        }
        if leaves.iter().all(|l| l.attr_override(*id) == Some(v)) {
            shape.set_attr(*id, v.clone());
        }
    }
}

/// Replaces the shape's geometry by `mesh` (object coordinates); the scope
/// keeps its axes and is fitted to the new geometry.
pub(crate) fn set_object_mesh(shape: &mut Shape, mut mesh: Mesh) {
    let to_scope = shape.scope.frame.affine().inverse();
    crate::shape::transform_in_place(&mut mesh, &to_scope);
    shape.set_local_mesh(mesh);
    let axes = shape.scope.frame.axes;
    shape.fit_scope(axes);
}

// ----- rest positions -----

/// The rest position of every corner (`None`: not tracked).
pub(crate) fn read_rest(mesh: &Mesh) -> Vec<Option<DVec3>> {
    match (&mesh.uvs[REST_XY], &mesh.uvs[REST_Z]) {
        (Some(xy), Some(z)) => (0..mesh.corners.len())
            .map(|c| {
                let (a, b) = (xy.get(c)?, z.get(c)?);
                ((b.y - 1.0).abs() < 1e-6).then(|| DVec3::new(a.x, a.y, b.x))
            })
            .collect(),
        _ => vec![None; mesh.corners.len()],
    }
}

/// Writes rest positions (one per corner) into the mesh.
fn write_rest(mesh: &mut Mesh, rest: impl Iterator<Item = Option<DVec3>>) {
    let n = mesh.corners.len();
    let mut xy = Vec::with_capacity(n);
    let mut z = Vec::with_capacity(n);
    for r in rest.take(n) {
        match r {
            Some(p) => {
                xy.push(DVec2::new(p.x, p.y));
                z.push(DVec2::new(p.z, 1.0));
            }
            None => {
                xy.push(DVec2::ZERO);
                z.push(DVec2::ZERO);
            }
        }
    }
    xy.resize(n, DVec2::ZERO);
    z.resize(n, DVec2::ZERO);
    mesh.uvs[REST_XY] = Some(xy);
    mesh.uvs[REST_Z] = Some(z);
}

/// How the rest positions of a recomposition relate to those of the
/// recomposition around it.
enum Outer {
    /// None around: remove the rest positions at the end.
    None,
    /// The geometry had not moved since the outer one began: the rest
    /// positions are the outer ones.
    Same,
    /// The outer rest positions of the starting geometry (object
    /// coordinates), per position.
    Map(Box<(Mesh, Vec<Option<DVec3>>)>),
}

/// One recomposition level (see the module docs).
pub(crate) struct Tracking {
    outer: Outer,
}

impl Tracking {
    /// Marks the vertices of the shape's geometry with their rest
    /// positions: where they are now, in object coordinates.
    pub(crate) fn begin(shape: &mut Shape) -> Tracking {
        shape.geometry.local();
        let to_object = shape.scope.frame.affine();
        let mesh = shape.geometry.local_mut();
        let here: Vec<DVec3> = mesh
            .positions
            .iter()
            .map(|p| to_object.transform_point3(*p))
            .collect();
        let old = read_rest(mesh);
        let outer = if old.iter().all(|r| r.is_none()) {
            Outer::None
        } else {
            let tol = 1e-7
                * here
                    .iter()
                    .fold(1.0f64, |m, p| m.max(p.abs().max_element()));
            let same = old.iter().zip(&mesh.corners).all(|(r, &p)| {
                r.is_some_and(|r| (r - here[p as usize]).abs().max_element() <= tol)
            });
            if same {
                Outer::Same
            } else {
                let mut values = vec![None; here.len()];
                for (r, &p) in old.iter().zip(&mesh.corners) {
                    if let (Some(r), Some(slot)) = (r, values.get_mut(p as usize)) {
                        if slot.is_none() {
                            *slot = Some(*r);
                        }
                    }
                }
                let mut start = Mesh::new();
                start.positions = here.clone();
                start.corners = mesh.corners.clone();
                start.loops = mesh.loops.clone();
                start.faces = mesh.faces.clone();
                Outer::Map(Box::new((start, values)))
            }
        };
        let corners = mesh.corners.clone();
        write_rest(mesh, corners.iter().map(|&p| Some(here[p as usize])));
        Tracking { outer }
    }

    /// Ends the level on its result: removes the rest positions, or turns
    /// them back into the enclosing level's.
    pub(crate) fn end(&self, mesh: &mut Mesh) {
        match &self.outer {
            Outer::None => {
                mesh.uvs[REST_XY] = None;
                mesh.uvs[REST_Z] = None;
            }
            Outer::Same => {}
            Outer::Map(b) => {
                let (start, values) = &**b;
                let map = SurfaceMap::new(start, values);
                let rest = read_rest(mesh);
                let mut memo: Vec<Option<Option<DVec3>>> = vec![None; mesh.positions.len()];
                let outer: Vec<Option<DVec3>> = rest
                    .iter()
                    .zip(&mesh.corners)
                    .map(|(r, &p)| {
                        let r = (*r)?;
                        let slot = memo.get_mut(p as usize)?;
                        *slot.get_or_insert_with(|| map.value_at(r))
                    })
                    .collect();
                write_rest(mesh, outer.into_iter());
            }
        }
    }
}
