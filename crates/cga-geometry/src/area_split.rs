//! Cutting planar geometry into parts of given areas: the geometry behind
//! CGA's `splitArea`.
//!
//! # The area profile
//!
//! For a unit direction `d`, let `A(t)` be the area of the part of the mesh
//! where `p · d < t`. [`AreaProfile`] computes this function exactly and
//! inverts it in closed form, so that cutting the mesh with the planes
//! `p · d = t_i` ([`split_by_parallel_planes`]) at the solved `t_i` gives
//! parts of the requested areas to floating-point accuracy.
//!
//! Per face: take the face's own plane (normal `n` from Newell's method, so
//! that slightly non-planar faces are measured in their best-fit plane) and
//! the coordinates `x = p · d`, `y = p · (n × d)`. The map `p -> (x, y)` keeps
//! `x`, the coordinate the cutting planes test, and scales areas of the face
//! by `|n × d|^2` (the planes `x = t` cut the face along lines `|n × d|` apart
//! per unit of `t`, and `n × d` has length `|n × d|`). By Green's theorem the
//! area of the face left of `x = t` is `-∮ y dx` over the boundary of that
//! part; the piece of boundary on the cut line has `dx = 0` and contributes
//! nothing. So `A(t)` is a sum over the face's edges, each contributing
//! `-∫ y dx` over the part of the edge left of `t`: zero before the edge
//! starts, quadratic in `t` along it, constant after. Summed, `A` is
//! piecewise quadratic with breaks at the vertices' `x`, and its derivative
//! (the length of the cross-section, scaled to true area) is piecewise
//! linear.
//!
//! The profile stores, at every distinct vertex coordinate `x_k` (sorted), the
//! area left of it and the derivative just right of `x_k` and just left of
//! `x_{k+1}`, each evaluated directly from the edges crossing that interval
//! (not by accumulating slopes along the sweep: a nearly vertical edge has an
//! enormous slope, and adding and later removing it would leave rounding
//! noise of that size in every later interval). On an interval the area is
//! `A_k + f0 u + (f1 - f0) u^2 / (2h)`; a target area is found by binary
//! search over the `A_k` and the quadratic solved with the cancellation-free
//! form `u = 2d / (f0 + sqrt(f0^2 + 4 c d))`, then polished by one Newton
//! step.
//!
//! Faces perpendicular to `d` (lying in one plane `x = const`) cannot be cut
//! by these planes: their area is a step of `A` at their position (see
//! [`Flatness::perpendicular_area`]). Each face is measured in its own plane,
//! so meshes of several non-coplanar faces (roofs, multi-face lots) are exact
//! too. A face bent out of its plane is measured in its best-fit plane,
//! while each piece cut from it is measured in the piece's own: areas of
//! bent faces are not additive, and the two differ by the square of the
//! bend. [`AreaProfile::cut_positions`] therefore polishes the cuts on such
//! meshes with the measured areas of the actual slabs (all parts but the
//! last then measure exactly; the last takes what is left). Closed meshes
//! are best effort: the cut parts get caps, which the profile does not
//! count.
//!
//! Cost: `O(n log n)` to build for `n` edges plus the sum over the intervals
//! of the edges crossing them (a few per interval for lots), `O(log n)` per
//! position.

use glam::DVec3;

use crate::cut::split_by_parallel_planes;
use crate::measure::{loop_newell, mesh_area};
use crate::mesh::Mesh;

/// Faces with `|n × d|^2` at or below this (within about 1e-6 rad of being
/// perpendicular to the direction) count as lying in one cutting plane.
const PERPENDICULAR_G2: f64 = 1e-12;

/// One edge with an extent along the direction: over `(xa, xb)` it adds
/// `c * y(x)` to the cross-section length, `y` interpolated from `ya` to `yb`.
#[derive(Clone, Copy, Debug)]
struct Edge {
    xa: f64,
    xb: f64,
    ya: f64,
    yb: f64,
    c: f64,
}

impl Edge {
    /// Its contribution to the cross-section length at `x` (within its
    /// range, so the interpolation never extrapolates a steep edge).
    #[inline]
    fn length_at(&self, x: f64) -> f64 {
        let s = ((x - self.xa) / (self.xb - self.xa)).clamp(0.0, 1.0);
        self.c * (self.ya + (self.yb - self.ya) * s)
    }
}

/// How planar the measured geometry is (see [`AreaProfile::flatness`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Flatness {
    /// `|Σ a_f n_f| / Σ a_f` over the faces (area `a_f`, unit normal
    /// `n_f`): 1 when all faces face the same way, 0 for a closed surface.
    pub normal_agreement: f64,
    /// Largest distance of a vertex from its face's plane, relative to the
    /// square root of the face's area.
    pub out_of_plane: f64,
    /// Area of the faces perpendicular to the direction: each lies in one
    /// cutting plane and goes to one part whole, so areas near it cannot be
    /// matched.
    pub perpendicular_area: f64,
    /// Total area of the faces.
    pub area: f64,
}

impl Flatness {
    /// Whether the faces do not lie in one plane: they face different ways
    /// (by more than about 1 degree on average; a closed surface faces all
    /// ways) or bend out of their planes by more than 1% of their size.
    pub fn is_bent(&self) -> bool {
        const COS_1_DEGREE: f64 = 0.999_847_695_156_391_3;
        self.normal_agreement < COS_1_DEGREE || self.out_of_plane > 1e-2
    }

    /// Whether the geometry is planar enough for exact area splits: not
    /// [bent](Self::is_bent), and no face is perpendicular to the direction.
    pub fn is_nearly_planar(&self) -> bool {
        !self.is_bent() && self.perpendicular_area <= 1e-9 * self.area
    }
}

/// The area of a mesh on the low side of a moving plane, `A(t)` (see the
/// module documentation), and its inverse.
///
/// Reuse one profile ([`AreaProfile::build`]) to avoid allocating per mesh.
#[derive(Clone, Debug, Default)]
pub struct AreaProfile {
    /// Distinct vertex coordinates along the direction, ascending.
    xs: Vec<f64>,
    /// `A(x_k)`: the area strictly left of `x_k`.
    a_left: Vec<f64>,
    /// Area of perpendicular faces at `x_k`.
    jump: Vec<f64>,
    /// Cross-section length just right of `x_k` and just left of
    /// `x_{k+1}` (one entry per interval).
    f_start: Vec<f64>,
    f_end: Vec<f64>,
    total: f64,
    /// The unit direction the profile was built for.
    dir: DVec3,
    weighted_normal: DVec3,
    face_area: f64,
    out_of_plane: f64,
    perpendicular: f64,
    // Scratch.
    edges: Vec<Edge>,
    jumps: Vec<(f64, f64)>,
    active: Vec<u32>,
}

impl AreaProfile {
    /// An empty profile (total area 0).
    pub fn new() -> AreaProfile {
        AreaProfile::default()
    }

    /// The profile of `mesh` along `dir` (any length; a zero or non-finite
    /// direction gives an empty profile).
    pub fn of_mesh(mesh: &Mesh, dir: DVec3) -> AreaProfile {
        let mut p = AreaProfile::new();
        p.build(mesh, dir);
        p
    }

    /// Recomputes the profile for `mesh` along `dir`, keeping the buffers.
    pub fn build(&mut self, mesh: &Mesh, dir: DVec3) {
        self.xs.clear();
        self.a_left.clear();
        self.jump.clear();
        self.f_start.clear();
        self.f_end.clear();
        self.edges.clear();
        self.jumps.clear();
        self.active.clear();
        self.total = 0.0;
        self.dir = DVec3::ZERO;
        self.weighted_normal = DVec3::ZERO;
        self.face_area = 0.0;
        self.out_of_plane = 0.0;
        self.perpendicular = 0.0;
        let len = dir.length();
        if !(len > 0.0 && len.is_finite()) {
            return;
        }
        let dir = dir / len;
        self.dir = dir;
        for face in 0..mesh.faces.len() {
            self.add_face(mesh, face, dir);
        }
        self.sweep();
    }

    /// Adds the edges (or the step) of one face.
    fn add_face(&mut self, mesh: &Mesh, face: usize, dir: DVec3) {
        let loops = mesh.face_loops(face);
        let newell = loop_newell(mesh, loops[0]);
        let len = newell.length();
        if !(len > 0.0 && len.is_finite()) {
            return; // no area (edges, points, collapsed polygons)
        }
        let n = newell / len;
        // The face's area as `measure::face_area` gives it: outer loop in its
        // own plane minus the holes projected onto it.
        let mut twice_area = len;
        for &h in &loops[1..] {
            twice_area -= loop_newell(mesh, h).dot(n).abs();
        }
        let area = (0.5 * twice_area).max(0.0);
        if area == 0.0 {
            return;
        }
        self.weighted_normal += n * area;
        self.face_area += area;

        // Relative to a vertex of the face, for precision far from the origin.
        let origin = mesh.positions[mesh.loop_indices(loops[0])[0] as usize];
        let mut deviation = 0.0f64;
        for &l in loops {
            for p in mesh.loop_points(l) {
                deviation = deviation.max((p - origin).dot(n).abs());
            }
        }
        self.out_of_plane = self.out_of_plane.max(deviation / area.sqrt());

        let w = n.cross(dir);
        let g2 = w.length_squared();
        if g2 <= PERPENDICULAR_G2 {
            let (lo, hi) = mesh.loop_points(loops[0]).fold(
                (f64::INFINITY, f64::NEG_INFINITY),
                |(lo, hi), p| {
                    let x = p.dot(dir);
                    (lo.min(x), hi.max(x))
                },
            );
            self.jumps.push((0.5 * (lo + hi), area));
            self.perpendicular += area;
            return;
        }
        let scale = 1.0 / g2;
        for (li, &l) in loops.iter().enumerate() {
            let idx = mesh.loop_indices(l);
            if idx.len() < 3 {
                continue;
            }
            let coords = |i: u32| {
                let p = mesh.positions[i as usize];
                let r = p - origin;
                (p.dot(dir), r.dot(dir), r.dot(w))
            };
            // Orientation of the loop in (x, y): the outer loop counts
            // positively, holes negatively, however they are wound.
            let mut twice_signed = 0.0;
            let (_, mut px, mut py) = coords(idx[idx.len() - 1]);
            for &i in idx {
                let (_, x, y) = coords(i);
                twice_signed += (px - x) * (py + y);
                (px, py) = (x, y);
            }
            if twice_signed == 0.0 || !twice_signed.is_finite() {
                continue;
            }
            let sign = if (twice_signed > 0.0) == (li == 0) {
                scale
            } else {
                -scale
            };
            let (mut x0, _, mut y0) = coords(idx[idx.len() - 1]);
            for &i in idx {
                let (x1, _, y1) = coords(i);
                // An edge going +x is on the low side of the area (it adds
                // -y), one going -x on the high side (+y); edges parallel to
                // the cutting planes add nothing.
                if x0 < x1 {
                    self.edges.push(Edge {
                        xa: x0,
                        xb: x1,
                        ya: y0,
                        yb: y1,
                        c: -sign,
                    });
                } else if x1 < x0 {
                    self.edges.push(Edge {
                        xa: x1,
                        xb: x0,
                        ya: y1,
                        yb: y0,
                        c: sign,
                    });
                }
                (x0, y0) = (x1, y1);
            }
        }
    }

    /// Sorts the break points and integrates the cross-section length.
    fn sweep(&mut self) {
        self.xs.reserve(2 * self.edges.len() + self.jumps.len());
        for e in &self.edges {
            self.xs.push(e.xa);
            self.xs.push(e.xb);
        }
        self.xs.extend(self.jumps.iter().map(|&(x, _)| x));
        self.xs.retain(|x| x.is_finite());
        self.xs.sort_unstable_by(f64::total_cmp);
        self.xs.dedup();
        let n = self.xs.len();
        if n == 0 {
            return;
        }
        self.jump.resize(n, 0.0);
        for &(x, a) in &self.jumps {
            if let Ok(k) = self.xs.binary_search_by(|p| p.total_cmp(&x)) {
                self.jump[k] += a;
            }
        }
        self.edges
            .retain(|e| e.xa.is_finite() && e.xb.is_finite() && e.c.is_finite());
        self.edges.sort_unstable_by(|a, b| a.xa.total_cmp(&b.xa));

        self.a_left.reserve(n);
        self.a_left.push(0.0);
        self.f_start.reserve(n - 1);
        self.f_end.reserve(n - 1);
        let mut next = 0;
        for k in 0..n - 1 {
            let (x0, x1) = (self.xs[k], self.xs[k + 1]);
            let edges = &self.edges;
            self.active.retain(|&e| edges[e as usize].xb > x0);
            while next < edges.len() && edges[next].xa <= x0 {
                self.active.push(next as u32);
                next += 1;
            }
            let (mut f0, mut f1) = (0.0, 0.0);
            for &e in &self.active {
                let e = &edges[e as usize];
                f0 += e.length_at(x0);
                f1 += e.length_at(x1);
            }
            // A cross-section has no negative length: what is below zero is
            // rounding (or an invalid, self-overlapping face). Clamping keeps
            // `A` non-decreasing, which the inversion relies on.
            let (f0, f1) = (f0.max(0.0), f1.max(0.0));
            self.f_start.push(f0);
            self.f_end.push(f1);
            let a = self.a_left[k] + self.jump[k] + 0.5 * (x1 - x0) * (f0 + f1);
            self.a_left.push(a);
        }
        self.total = self.a_left[n - 1] + self.jump[n - 1];
    }

    /// The total area: `A(t)` for `t` beyond the geometry.
    pub fn total(&self) -> f64 {
        self.total
    }

    /// The smallest and largest vertex coordinate along the direction, or
    /// `None` if the mesh has no area.
    pub fn range(&self) -> Option<(f64, f64)> {
        Some((*self.xs.first()?, *self.xs.last()?))
    }

    /// How planar the geometry is (for warnings: the inversion is exact on
    /// planar faces not perpendicular to the direction).
    pub fn flatness(&self) -> Flatness {
        Flatness {
            normal_agreement: if self.face_area > 0.0 {
                self.weighted_normal.length() / self.face_area
            } else {
                1.0
            },
            out_of_plane: self.out_of_plane,
            perpendicular_area: self.perpendicular,
            area: self.face_area,
        }
    }

    /// `A(t)`: the area where `p · dir < t`.
    pub fn area_below(&self, t: f64) -> f64 {
        let n = self.xs.len();
        if n == 0 || t.is_nan() || t <= self.xs[0] {
            return 0.0;
        }
        let k = self.xs.partition_point(|&x| x < t) - 1;
        if k == n - 1 {
            return self.total;
        }
        let h = self.xs[k + 1] - self.xs[k];
        let (f0, f1) = (self.f_start[k], self.f_end[k]);
        let u = (t - self.xs[k]).min(h);
        self.a_left[k] + self.jump[k] + u * (f0 + 0.5 * (f1 - f0) / h * u)
    }

    /// The length of the cross-section at `t` (the derivative of `A`),
    /// scaled to true area per unit of `t`.
    pub fn cross_section(&self, t: f64) -> f64 {
        let n = self.xs.len();
        if n < 2 || t.is_nan() || t < self.xs[0] || t > self.xs[n - 1] {
            return 0.0;
        }
        let k = self.xs.partition_point(|&x| x <= t).clamp(1, n - 1) - 1;
        let h = self.xs[k + 1] - self.xs[k];
        let s = ((t - self.xs[k]) / h).clamp(0.0, 1.0);
        self.f_start[k] + (self.f_end[k] - self.f_start[k]) * s
    }

    /// The position `t` where `A(t) = area`: the smallest such `t` where
    /// several qualify (a gap in the geometry), the start of the geometry
    /// for `area <= 0` and its end for `area >= total`. Where the area lies
    /// in the step of a perpendicular face, that face's position. An empty
    /// profile gives 0. Non-decreasing in `area`.
    pub fn position_of(&self, area: f64) -> f64 {
        let n = self.xs.len();
        if n == 0 {
            return 0.0;
        }
        if area.is_nan() || area <= 0.0 {
            return self.xs[0];
        }
        // First break point with at least `area` left of it (`a_left[0] = 0`,
        // so j >= 1).
        let j = self.a_left.partition_point(|&a| a < area);
        if j == n {
            return self.xs[n - 1];
        }
        let k = j - 1;
        let start = self.a_left[k] + self.jump[k];
        if area <= start {
            return self.xs[k];
        }
        let h = self.xs[k + 1] - self.xs[k];
        let u = solve_quadratic(self.f_start[k], self.f_end[k], h, area - start);
        self.xs[k] + u
    }

    /// [`position_of`](Self::position_of) for each of `areas` into `out`
    /// (cleared first).
    pub fn positions_of(&self, areas: &[f64], out: &mut Vec<f64>) {
        out.clear();
        out.extend(areas.iter().map(|&a| self.position_of(a)));
    }

    /// Where to cut `mesh` (the mesh this profile was built from) so that
    /// the slab between the cuts for `bounds[i - 1]` and `bounds[i]` has
    /// area `bounds[i] - bounds[i - 1]` as [`mesh_area`] measures it, and
    /// the part below the first cut `bounds[0]`. `bounds` are cumulative
    /// areas, ascending; the positions go to `out` (cleared first),
    /// non-decreasing.
    ///
    /// For planar faces these are [`position_of`](Self::position_of)
    /// exactly. A face bent out of its plane is measured by the profile in
    /// its best-fit plane, but each cut piece of it is measured in the
    /// piece's own best-fit plane, which differs by the square of the bend
    /// (for a narrow piece of a bent face, 1e-5 of its area is common). So
    /// when some face is not planar, each cut is polished by a few Newton
    /// steps on the measured area of the actual slab, with the profile's
    /// cross-section as the derivative (a cut of the whole mesh per step).
    /// Closed meshes are not polished: their parts get caps the profile does
    /// not count, so no cut can match.
    pub fn cut_positions(&self, mesh: &Mesh, bounds: &[f64], out: &mut Vec<f64>) {
        self.positions_of(bounds, out);
        let flat = self.flatness();
        if flat.out_of_plane <= 1e-10 || flat.normal_agreement < 0.5 || self.xs.is_empty() {
            return;
        }
        let end = self.xs[self.xs.len() - 1];
        let tol = 1e-13 * self.total;
        let mut prev_t = f64::NEG_INFINITY;
        let mut prev_area = 0.0;
        for (i, &bound) in bounds.iter().enumerate() {
            if bound >= self.total || bound <= 0.0 {
                prev_t = prev_t.max(out[i]);
                prev_area = bound;
                continue;
            }
            let want = bound - prev_area;
            let measure = |t: f64| -> f64 {
                let offsets = [prev_t, t];
                let planes = if prev_t.is_finite() {
                    &offsets[..]
                } else {
                    &offsets[1..]
                };
                let slabs = split_by_parallel_planes(mesh, self.dir, planes);
                mesh_area(&slabs[planes.len() - 1])
            };
            // Start from the profile's answer for this slab (relative to
            // where the previous cut actually is).
            let start_area = if prev_t.is_finite() {
                self.area_below(prev_t)
            } else {
                0.0
            };
            let mut t = self.position_of(start_area + want).max(prev_t);
            let mut r = measure(t) - want;
            for _ in 0..6 {
                if r.abs() <= tol {
                    break;
                }
                let slope = self.cross_section(t);
                if slope.is_nan() || slope <= 0.0 {
                    break;
                }
                let next = (t - r / slope).clamp(prev_t.max(self.xs[0]), end);
                let next_r = measure(next) - want;
                if next_r.abs() >= r.abs() {
                    break;
                }
                (t, r) = (next, next_r);
            }
            out[i] = t;
            prev_t = t;
            prev_area = bound;
        }
    }
}

/// The `u` in `[0, h]` with `f0 u + (f1 - f0) u^2 / (2h) = d`, for a
/// cross-section going linearly from `f0 >= 0` to `f1 >= 0` over `h`, and
/// `0 < d <= h (f0 + f1) / 2`.
fn solve_quadratic(f0: f64, f1: f64, h: f64, d: f64) -> f64 {
    if h.is_nan() || h <= 0.0 {
        return 0.0;
    }
    let c = 0.5 * (f1 - f0) / h;
    // The root of c u^2 + f0 u - d on the rising side of the parabola, in the
    // form without cancellation (f0 >= 0 and the square root >= 0).
    let disc = (f0 * f0 + 4.0 * c * d).max(0.0);
    let denom = f0 + disc.sqrt();
    let mut u = if denom > 0.0 { 2.0 * d / denom } else { h };
    u = u.clamp(0.0, h);
    // One Newton step on the residual removes the last rounding of the
    // closed form where the discriminant lost digits.
    let residual = |u: f64| u * (f0 + c * u) - d;
    let slope = f0 + 2.0 * c * u;
    if slope > 0.0 {
        let r = residual(u);
        let v = (u - r / slope).clamp(0.0, h);
        if residual(v).abs() < r.abs() {
            u = v;
        }
    }
    u
}

/// Cuts `mesh` with planes perpendicular to `dir` into consecutive parts of
/// the given areas, from the low end of `dir`: part `i` has area `areas[i]`
/// (negative areas count as 0), and one more part holds the rest. Areas
/// beyond the mesh's total give empty parts. Returns `areas.len() + 1`
/// meshes. A zero or non-finite `dir` returns the whole mesh as the rest.
pub fn split_by_areas(mesh: &Mesh, dir: DVec3, areas: &[f64]) -> Vec<Mesh> {
    let len = dir.length();
    if !(len > 0.0 && len.is_finite()) {
        let mut out: Vec<Mesh> = areas.iter().map(|_| Mesh::new()).collect();
        out.push(mesh.clone());
        return out;
    }
    let dir = dir / len;
    let profile = AreaProfile::of_mesh(mesh, dir);
    let mut sum = 0.0;
    let bounds: Vec<f64> = areas
        .iter()
        .map(|&a| {
            sum += a.max(0.0);
            sum
        })
        .collect();
    let mut positions = Vec::with_capacity(bounds.len());
    profile.cut_positions(mesh, &bounds, &mut positions);
    split_by_parallel_planes(mesh, dir, &positions)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(size: f64) -> Mesh {
        Mesh::polygon(&[
            DVec3::ZERO,
            DVec3::new(size, 0.0, 0.0),
            DVec3::new(size, size, 0.0),
            DVec3::new(0.0, size, 0.0),
        ])
    }

    #[test]
    fn square_profile_is_linear() {
        let p = AreaProfile::of_mesh(&square(10.0), DVec3::X);
        assert_eq!(p.total(), 100.0);
        assert_eq!(p.area_below(2.5), 25.0);
        assert_eq!(p.position_of(30.0), 3.0);
        assert_eq!(p.cross_section(4.0), 10.0);
        assert_eq!(p.range(), Some((0.0, 10.0)));
    }

    #[test]
    fn triangle_profile_is_quadratic() {
        // Apex at x = 0, base of height 4 at x = 4: A(t) = t^2 / 2.
        let tri = Mesh::polygon(&[
            DVec3::ZERO,
            DVec3::new(4.0, -2.0, 0.0),
            DVec3::new(4.0, 2.0, 0.0),
        ]);
        let p = AreaProfile::of_mesh(&tri, DVec3::X);
        assert!((p.total() - 8.0).abs() < 1e-14);
        assert!((p.area_below(2.0) - 2.0).abs() < 1e-14);
        assert!((p.position_of(4.5) - 3.0).abs() < 1e-14);
        // From the other side: A(t) = 8 - (4 + t)^2 / 2 for t in [-4, 0].
        let q = AreaProfile::of_mesh(&tri, -DVec3::X);
        assert!((q.position_of(8.0 - 4.5) - -3.0).abs() < 1e-14);
    }

    #[test]
    fn tilted_face_counts_true_area() {
        // The unit square tilted 60 degrees about x: area 1, spanning 0.5 in y.
        let (s, c) = (60f64.to_radians().sin(), 60f64.to_radians().cos());
        let m = Mesh::polygon(&[
            DVec3::ZERO,
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, c, s),
            DVec3::new(0.0, c, s),
        ]);
        let p = AreaProfile::of_mesh(&m, DVec3::Y);
        assert!((p.total() - 1.0).abs() < 1e-14);
        assert!((p.position_of(0.5) - 0.25).abs() < 1e-14);
        let q = AreaProfile::of_mesh(&m, DVec3::X);
        assert!((q.position_of(0.25) - 0.25).abs() < 1e-14);
    }

    #[test]
    fn perpendicular_face_is_a_step() {
        let p = AreaProfile::of_mesh(&square(2.0), DVec3::Z);
        assert_eq!(p.total(), 4.0);
        assert_eq!(p.area_below(0.0), 0.0);
        assert_eq!(p.area_below(1e-9), 4.0);
        assert_eq!(p.position_of(2.0), 0.0);
        assert!(!p.flatness().is_nearly_planar());
    }

    #[test]
    fn gap_gives_the_smallest_position() {
        let mut m = square(1.0);
        let mut other = square(1.0);
        other.map_positions(|p| p + DVec3::new(3.0, 0.0, 0.0));
        crate::transform::merge(&mut m, &other);
        let p = AreaProfile::of_mesh(&m, DVec3::X);
        assert_eq!(p.total(), 2.0);
        assert_eq!(p.position_of(1.0), 1.0);
        assert_eq!(p.area_below(2.0), 1.0);
        assert!((p.position_of(1.5) - 3.5).abs() < 1e-15);
    }

    #[test]
    fn empty_and_degenerate_inputs() {
        let p = AreaProfile::of_mesh(&Mesh::new(), DVec3::X);
        assert_eq!(p.total(), 0.0);
        assert_eq!(p.position_of(1.0), 0.0);
        assert_eq!(p.range(), None);
        let q = AreaProfile::of_mesh(&square(1.0), DVec3::ZERO);
        assert_eq!(q.total(), 0.0);
        let r = AreaProfile::of_mesh(&square(1.0), DVec3::new(f64::NAN, 0.0, 0.0));
        assert_eq!(r.total(), 0.0);
        let parts = split_by_areas(&square(1.0), DVec3::ZERO, &[0.5]);
        assert_eq!(parts.len(), 2);
        assert!(parts[0].is_empty());
        assert_eq!(parts[1].faces.len(), 1);
    }

    #[test]
    fn solve_quadratic_cases() {
        // Constant density.
        assert_eq!(solve_quadratic(2.0, 2.0, 5.0, 4.0), 2.0);
        // Rising from zero: u^2 / 2 = d with f = u.
        assert!((solve_quadratic(0.0, 4.0, 4.0, 2.0) - 2.0).abs() < 1e-15);
        // Falling to zero: 4u - u^2 / 2 = 6 at u = 2.
        assert!((solve_quadratic(4.0, 0.0, 4.0, 6.0) - 2.0).abs() < 1e-15);
        // Everything: the end.
        assert!((solve_quadratic(4.0, 0.0, 4.0, 8.0) - 4.0).abs() < 1e-7);
    }
}
