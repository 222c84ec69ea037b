//! `scatter(domain, nPoints, uniform|gaussian[, mean, stddev]) { operations }`
//! (op_scatter.md): point shapes on the surface, in the volume or in the
//! scope of the current shape.
//!
//! Every child is a shape of one vertex (a face of one corner at its scope
//! origin) with a zero-size scope. On the surface its scope's y-axis is the
//! normal of the face the point lies on (x is the current scope's x-axis
//! laid into the face); in the volume and the scope the children keep the
//! current scope's axes. The points come from the current shape's random
//! stream, so a derivation with the same seed scatters the same points.
//!
//! Distributions:
//! - `uniform`: the same density everywhere (surface: per area, faces
//!   chosen by area; volume: per volume).
//! - `gaussian`: a normal distribution around `mean` (a point of the scope:
//!   its center or the middle of one of its sides) with a standard
//!   deviation per scope axis (relative: a fraction of the scope size,
//!   `'0.16` by default). In the volume and the scope, points are drawn from
//!   that distribution and kept if they fall inside; on the surface, points
//!   are drawn uniformly and kept with a probability given by the Gaussian
//!   density there, so the surface density is the Gaussian restricted to
//!   the surface (the reference shows such clusters). When a draw keeps
//!   failing (a mean far from all geometry) the best of the tries is taken,
//!   so `nPoints` points are always made.
//!
//! `volume` on geometry that is not closed falls back to `surface`, as the
//! reference says.

use cga_geometry::measure::{face_normal, is_closed};
use cga_geometry::triangulate::triangulate_face;
use cga_geometry::{DMat3, DVec3, Mesh};
use cga_value::Value;

use super::transform::selector;
use crate::derive::{Arg, Interp, RtError, ShapeState, SizeKind};
use crate::expr::{OpCall, RPart};
use crate::shape::{Frame, Shape};

/// Draws per point before the best try is taken (gaussian on a surface,
/// inside tests of the volume).
const MAX_TRIES: usize = 200;

#[derive(Clone, Copy, PartialEq)]
enum Domain {
    Surface,
    Volume,
    Scope,
}

/// A Gaussian in scope-local coordinates (a zero deviation on an axis: no
/// spread along it).
struct Gauss {
    mean: DVec3,
    sigma: DVec3,
}

impl Gauss {
    /// The density relative to its peak (1 at the mean).
    fn weight(&self, p: DVec3) -> f64 {
        let mut e = 0.0;
        for i in 0..3 {
            if self.sigma[i] > 0.0 {
                let z = (p[i] - self.mean[i]) / self.sigma[i];
                e += z * z;
            }
        }
        (-0.5 * e).exp()
    }

    fn sample(&self, shape: &Shape) -> DVec3 {
        let n = DVec3::new(normal(shape), normal(shape), normal(shape));
        self.mean + self.sigma * n
    }
}

/// A standard normal number from the shape's random stream (Box-Muller).
fn normal(shape: &Shape) -> f64 {
    let u1 = 1.0 - shape.next_random(); // (0, 1]
    let u2 = shape.next_random();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

pub fn exec(
    cx: &mut Interp,
    st: &mut ShapeState,
    call: &OpCall,
    args: &[Arg],
    frame: &[Value],
) -> Result<(), RtError> {
    let body = match call.block.as_ref().map(|b| b.parts.as_slice()) {
        Some([RPart::Unlabeled { body, .. }]) => body,
        _ => {
            return Err(RtError::new(
                "`scatter` needs one `{ operations }` block",
                call.span,
            ))
        }
    };
    let mut domain = match selector(&args[0], &["surface", "volume", "scope"])? {
        "surface" => Domain::Surface,
        "volume" => Domain::Volume,
        _ => Domain::Scope,
    };
    let n = args[1].num()?;
    if !n.is_finite() {
        return Err(RtError::new(
            format!("scatter: the number of points must be finite, found {n}"),
            args[1].span,
        ));
    }
    let n = n.round().max(0.0) as usize;
    let gaussian = selector(&args[2], &["uniform", "gaussian"])? == "gaussian";
    if !gaussian && args.len() > 3 {
        return Err(RtError::new(
            "scatter: a mean and a deviation only go with `gaussian`",
            args[3].span,
        ));
    }
    let size = st.shape.scope.size;
    let gauss = if gaussian {
        let mean_sel = match args.get(3) {
            Some(a) => selector(
                a,
                &["center", "front", "back", "left", "right", "top", "bottom"],
            )?,
            None => "center",
        };
        let half = size * 0.5;
        let mean = match mean_sel {
            "front" => DVec3::new(half.x, half.y, size.z),
            "back" => DVec3::new(half.x, half.y, 0.0),
            "left" => DVec3::new(0.0, half.y, half.z),
            "right" => DVec3::new(size.x, half.y, half.z),
            "top" => DVec3::new(half.x, size.y, half.z),
            "bottom" => DVec3::new(half.x, 0.0, half.z),
            _ => half,
        };
        let sigma = match args.get(4) {
            Some(a) => {
                let v = a.num()?;
                if !(v.is_finite() && v >= 0.0) {
                    return Err(RtError::new(
                        format!("scatter: the deviation must be 0 or more, found {v}"),
                        a.span,
                    ));
                }
                match a.kind {
                    SizeKind::Relative => size.abs() * v,
                    _ => DVec3::splat(v),
                }
            }
            None => size.abs() * 0.16,
        };
        Some(Gauss { mean, sigma })
    } else {
        None
    };

    st.has_successor = true;
    if n == 0 {
        return Ok(());
    }
    // Every point is a shape: more than the limit allows fails here, before
    // room for them is made.
    cx.check_shape_budget(n, call.span)?;
    let mesh = st.shape.geometry.local().clone();
    if domain == Domain::Volume && (mesh.faces.is_empty() || !is_closed(&mesh)) {
        domain = Domain::Surface;
    }
    let surface = Surface::new(&mesh);
    if domain == Domain::Surface && surface.total <= 0.0 {
        cx.warn_once(call.span, || {
            "scatter: the shape has no surface to scatter on; no points are made".to_string()
        });
        return Ok(());
    }
    let volume = (domain == Domain::Volume).then(|| Volume::new(&mesh, &surface));

    // Points first (all from the current shape's stream), then the shapes.
    let shape = &st.shape;
    let mut points: Vec<(DVec3, Option<usize>)> = Vec::with_capacity(n);
    for _ in 0..n {
        let p = match domain {
            Domain::Surface => {
                let (p, f) = match &gauss {
                    None => surface.sample(shape),
                    Some(g) => best_of(shape, |s| surface.sample(s), |&(p, _)| g.weight(p)),
                };
                (p, Some(f))
            }
            Domain::Volume => {
                let v = volume.as_ref().expect("made for the volume domain");
                let p = match &gauss {
                    None => v.sample_uniform(shape, size),
                    Some(g) => best_of(
                        shape,
                        |s| g.sample(s),
                        |&p| if v.contains(p) { 1.0 } else { 0.0 },
                    ),
                };
                (p, None)
            }
            Domain::Scope => {
                let p = match &gauss {
                    None => uniform_in_box(shape, size),
                    Some(g) => {
                        // Kept inside the scope box.
                        let p = best_of(
                            shape,
                            |s| g.sample(s),
                            |&p| if in_box(p, size) { 1.0 } else { 0.0 },
                        );
                        clamp_box(p, size)
                    }
                };
                (p, None)
            }
        };
        points.push(p);
    }

    let parent_axes = shape.scope.frame.axes;
    for (p, face) in points {
        let mut child = cx.child(&st.shape, call.span)?;
        let axes = match face {
            Some(f) => surface_axes(parent_axes, parent_axes * face_normal(&mesh, f)),
            None => parent_axes,
        };
        let origin = st.shape.scope.frame.to_object(p);
        let pivot_axes = child.pivot.axes;
        child.scope.frame = Frame { origin, axes };
        child.scope.size = DVec3::ZERO;
        child.scope.set_axes(&pivot_axes, axes);
        let mut m = Mesh::new();
        m.materials = mesh.materials.clone();
        m.groups = mesh.groups.clone();
        m.positions.push(DVec3::ZERO);
        let (material, group) = face
            .and_then(|f| mesh.faces.get(f))
            .map_or((0, 0), |f| (f.material, f.group));
        let fi = m.add_face(&[&[0]], material);
        m.faces[fi].group = group;
        child.set_local_mesh(m);
        let mut cst = ShapeState::new(child);
        cx.exec_body(body, frame, &mut cst)?;
        cx.finish(cst);
    }
    Ok(())
}

/// Draws up to [`MAX_TRIES`] candidates and keeps each with probability
/// `weight` (in [0, 1]); if none is kept, the heaviest candidate.
fn best_of<T>(shape: &Shape, mut draw: impl FnMut(&Shape) -> T, weight: impl Fn(&T) -> f64) -> T {
    let mut best: Option<(f64, T)> = None;
    for _ in 0..MAX_TRIES {
        let c = draw(shape);
        let w = weight(&c);
        if shape.next_random() < w {
            return c;
        }
        if best.as_ref().is_none_or(|(bw, _)| w > *bw) {
            best = Some((w, c));
        }
    }
    match best {
        Some((_, c)) => c,
        None => draw(shape),
    }
}

fn uniform_in_box(shape: &Shape, size: DVec3) -> DVec3 {
    DVec3::new(
        shape.next_random() * size.x,
        shape.next_random() * size.y,
        shape.next_random() * size.z,
    )
}

/// Whether `p` lies in the scope box of size `size` (sizes may be negative).
fn in_box(p: DVec3, size: DVec3) -> bool {
    (0..3).all(|i| {
        let (lo, hi) = (size[i].min(0.0), size[i].max(0.0));
        p[i] >= lo && p[i] <= hi
    })
}

fn clamp_box(p: DVec3, size: DVec3) -> DVec3 {
    p.clamp(size.min(DVec3::ZERO), size.max(DVec3::ZERO))
}

/// The scope axes of a point on a face of normal `n` (object coordinates):
/// y along `n`, x the parent's x-axis laid into the face (or its z-axis
/// where x is the normal).
fn surface_axes(parent: DMat3, n: DVec3) -> DMat3 {
    let Some(y) = n.try_normalize() else {
        return parent;
    };
    let lay = |v: DVec3| (v - y * v.dot(y)).try_normalize();
    let x = lay(parent.x_axis)
        .or_else(|| lay(-parent.z_axis))
        .unwrap_or_else(|| y.any_orthonormal_vector());
    DMat3::from_cols(x, y, x.cross(y))
}

/// The triangles of a mesh with their cumulated areas, for drawing points
/// uniformly on it.
struct Surface {
    /// (face, three positions).
    tris: Vec<(usize, [DVec3; 3])>,
    /// Area of triangles 0..=i.
    cumulated: Vec<f64>,
    total: f64,
}

impl Surface {
    fn new(mesh: &Mesh) -> Surface {
        let mut tris = Vec::new();
        let mut cumulated = Vec::new();
        let mut total = 0.0;
        let mut buf = Vec::new();
        for f in 0..mesh.faces.len() {
            buf.clear();
            triangulate_face(mesh, f, &mut buf);
            for t in &buf {
                let p = t.map(|c| {
                    mesh.corners
                        .get(c as usize)
                        .and_then(|&i| mesh.positions.get(i as usize))
                        .copied()
                        .unwrap_or(DVec3::NAN)
                });
                let a = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length();
                if !(a > 0.0 && a.is_finite()) {
                    continue;
                }
                total += a;
                tris.push((f, p));
                cumulated.push(total);
            }
        }
        Surface {
            tris,
            cumulated,
            total,
        }
    }

    /// A point drawn uniformly (by area) and the face it lies on.
    fn sample(&self, shape: &Shape) -> (DVec3, usize) {
        let r = shape.next_random() * self.total;
        let i = self
            .cumulated
            .partition_point(|&c| c <= r)
            .min(self.tris.len().saturating_sub(1));
        let (f, [a, b, c]) = self.tris[i];
        let (mut u, mut v) = (shape.next_random(), shape.next_random());
        if u + v > 1.0 {
            u = 1.0 - u;
            v = 1.0 - v;
        }
        (a + (b - a) * u + (c - a) * v, f)
    }
}

/// A closed mesh, for inside tests (ray parity over its triangles).
struct Volume {
    tris: Vec<[DVec3; 3]>,
    lo: DVec3,
    hi: DVec3,
}

impl Volume {
    fn new(_mesh: &Mesh, surface: &Surface) -> Volume {
        let tris: Vec<[DVec3; 3]> = surface.tris.iter().map(|t| t.1).collect();
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for t in &tris {
            for p in t {
                lo = lo.min(*p);
                hi = hi.max(*p);
            }
        }
        Volume { tris, lo, hi }
    }

    /// Whether `p` is inside: the number of triangles a ray from `p` crosses
    /// is odd. The ray's direction is skewed so that it rarely meets an edge.
    fn contains(&self, p: DVec3) -> bool {
        if p.cmplt(self.lo).any() || p.cmpgt(self.hi).any() {
            return false;
        }
        let d = DVec3::new(0.5773, 0.6089, 0.5441).normalize();
        let mut inside = false;
        for [a, b, c] in &self.tris {
            // Möller-Trumbore.
            let e1 = *b - *a;
            let e2 = *c - *a;
            let h = d.cross(e2);
            let det = e1.dot(h);
            if det.abs() < 1e-15 {
                continue;
            }
            let s = p - *a;
            let u = s.dot(h) / det;
            if !(0.0..=1.0).contains(&u) {
                continue;
            }
            let q = s.cross(e1);
            let v = d.dot(q) / det;
            if v < 0.0 || u + v > 1.0 {
                continue;
            }
            if e2.dot(q) / det > 0.0 {
                inside = !inside;
            }
        }
        inside
    }

    /// A point drawn uniformly in the volume: uniform in the bounding box
    /// until one is inside (the best try otherwise, which is then on the
    /// box: only for meshes with almost no volume).
    fn sample_uniform(&self, shape: &Shape, _size: DVec3) -> DVec3 {
        let ext = self.hi - self.lo;
        best_of(
            shape,
            |s| self.lo + ext * DVec3::new(s.next_random(), s.next_random(), s.next_random()),
            |&p| if self.contains(p) { 1.0 } else { 0.0 },
        )
    }
}
