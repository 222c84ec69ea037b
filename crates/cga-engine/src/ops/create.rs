//! Operations that create new geometry: `extrude`, the primitives, `i`
//! (asset insertion) and `reverseNormals`.

use std::sync::Arc;

use cga_geometry::{DAffine3, DMat3, DVec3, Mesh};

use super::transform::selector;
use super::Op;
use crate::derive::{Arg, Interp, RtError, ShapeState};
use crate::expr::OpCall;
use crate::geom_shim;
use crate::shape::{local_bounds, reverse_faces, Shape};

pub fn exec(
    cx: &mut Interp,
    st: &mut ShapeState,
    call: &OpCall,
    args: &[Arg],
) -> Result<(), RtError> {
    let shape = &mut st.shape;
    match call.op {
        Op::Extrude => extrude(shape, args),
        Op::PrimitiveCube => {
            insert_fitted(shape, Arc::new(unit_cube()), InsertMode::Fit);
            Ok(())
        }
        Op::PrimitiveQuad => {
            insert_fitted(shape, Arc::new(unit_quad()), InsertMode::Fit);
            Ok(())
        }
        Op::Insert => {
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
            let asset = if path == "builtin:cube" {
                Ok(Arc::new(unit_cube()))
            } else {
                cx.assets.mesh(call.span.file, path)
            };
            match asset {
                Ok(mut mesh) => {
                    if up_z {
                        let rot = DAffine3::from_mat3(DMat3::from_rotation_x(-std::f64::consts::FRAC_PI_2));
                        mesh = Arc::new(crate::shape::transformed(&mesh, &rot));
                    }
                    insert_fitted(shape, mesh, mode);
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
        Op::ReverseNormals => {
            let mut mesh = (**shape.geometry.local()).clone();
            reverse_faces(&mut mesh);
            shape.set_local_mesh(mesh);
            Ok(())
        }
        _ => {
            cx.warn_once(call.span, || "this primitive is not supported yet".to_string());
            Ok(())
        }
    }
}

#[derive(Clone, Copy, PartialEq, Eq)]
pub enum InsertMode {
    /// Fit the geometry's bounding box to the scope (zero sizes taken from the asset).
    Fit,
    /// Keep the asset's size and position (as a zero-size scope would).
    Keep,
    /// Keep the asset's size, centred in x and z, standing on y = 0.
    KeepSizeAlign,
}

/// Places `asset` (in its own coordinates) into the scope as CGA's insert
/// does, including the rules for scope sizes that are zero.
pub fn insert_fitted(shape: &mut Shape, asset: Arc<Mesh>, mode: InsertMode) {
    let Some((lo, hi)) = local_bounds(&asset) else {
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
}

fn extrude(shape: &mut Shape, args: &[Arg]) -> Result<(), RtError> {
    let (kind, dist) = match args {
        [d] => ("face.normal", d.num()?),
        [k, d] => (
            selector(
                k,
                &["world.up", "world.up.flatTop", "face.normal", "vertex.normal"],
            )?,
            d.num()?,
        ),
        _ => unreachable!("arity checked by the resolver"),
    };
    let mesh = shape.object_mesh();
    if mesh.faces.is_empty() {
        return Ok(());
    }
    let dir = match kind {
        "world.up" | "world.up.flatTop" => DVec3::Y,
        _ => geom_shim::face_normal(&mesh, 0),
    };
    let out = extrude_mesh(&mesh, kind, dist);
    // New scope: y along the extrusion, x the old x made orthogonal to it.
    let y = dir;
    let old_x = shape.scope.frame.axes.x_axis;
    let x = (old_x - y * old_x.dot(y))
        .try_normalize()
        .unwrap_or_else(|| y.any_orthonormal_vector());
    let axes = DMat3::from_cols(x, y, x.cross(y));
    let frame = shape.scope.frame;
    let to_scope = frame.affine().inverse();
    shape.set_local_mesh(crate::shape::transformed(&out, &to_scope));
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

/// Extrudes each face of `mesh` (object coordinates) into a closed prism:
/// faces in the order bottom (the original face, reversed), top, then one
/// side per boundary edge in edge order (outer boundary, then holes), each
/// side starting with its bottom edge in the face's edge direction.
fn extrude_mesh(mesh: &Mesh, kind: &str, dist: f64) -> Mesh {
    let mut out = Mesh::new();
    out.materials = mesh.materials.clone();
    for f in 0..mesh.faces.len() {
        let n = match kind {
            "world.up" | "world.up.flatTop" => DVec3::Y,
            _ => geom_shim::face_normal(mesh, f),
        };
        let offset = n * dist;
        let material = mesh.faces[f].material;
        let loops: Vec<Vec<DVec3>> = mesh
            .face_loops(f)
            .iter()
            .map(|&l| mesh.loop_points(l).collect())
            .collect();
        let mut bottom_idx: Vec<Vec<u32>> = Vec::new();
        let mut top_idx: Vec<Vec<u32>> = Vec::new();
        for l in &loops {
            let b0 = out.positions.len() as u32;
            out.positions.extend(l.iter().copied());
            let t0 = out.positions.len() as u32;
            out.positions.extend(l.iter().map(|&p| p + offset));
            bottom_idx.push((0..l.len() as u32).map(|i| b0 + i).collect());
            top_idx.push((0..l.len() as u32).map(|i| t0 + i).collect());
        }
        let (bottom, top): (Vec<Vec<u32>>, Vec<Vec<u32>>) = if dist >= 0.0 {
            (
                bottom_idx.iter().map(|l| reversed_keep_first(l)).collect(),
                top_idx.clone(),
            )
        } else {
            (
                bottom_idx.clone(),
                top_idx.iter().map(|l| reversed_keep_first(l)).collect(),
            )
        };
        let refs: Vec<&[u32]> = bottom.iter().map(|l| l.as_slice()).collect();
        out.add_face(&refs, material);
        let refs: Vec<&[u32]> = top.iter().map(|l| l.as_slice()).collect();
        out.add_face(&refs, material);
        for (b, t) in bottom_idx.iter().zip(&top_idx) {
            let k = b.len();
            for i in 0..k {
                let j = (i + 1) % k;
                let quad = if dist >= 0.0 {
                    [b[i], b[j], t[j], t[i]]
                } else {
                    [b[j], b[i], t[i], t[j]]
                };
                out.add_face(&[&quad], material);
            }
        }
    }
    out
}

fn reversed_keep_first(l: &[u32]) -> Vec<u32> {
    let mut v = l.to_vec();
    v[1..].reverse();
    v
}

fn unit_cube() -> Mesh {
    let mut m = Mesh::new();
    for z in [0.0, 1.0] {
        for y in [0.0, 1.0] {
            for x in [0.0, 1.0] {
                m.positions.push(DVec3::new(x, y, z));
            }
        }
    }
    // Vertex i = x + 2y + 4z; faces counter-clockwise seen from outside.
    for f in [
        [0u32, 2, 3, 1], // back (z = 0)
        [4, 5, 7, 6],    // front (z = 1)
        [0, 1, 5, 4],    // bottom
        [2, 6, 7, 3],    // top
        [0, 4, 6, 2],    // left
        [1, 3, 7, 5],    // right
    ] {
        m.add_face(&[&f], 0);
    }
    m
}

fn unit_quad() -> Mesh {
    Mesh::polygon(&[
        DVec3::new(0.0, 0.0, 1.0),
        DVec3::new(1.0, 0.0, 1.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, 0.0, 0.0),
    ])
}
