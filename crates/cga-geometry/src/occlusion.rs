//! Occlusion tests between meshes (CGA's `inside`, `overlaps` and
//! `touches`) and the distance between oriented boxes (`minimumDistance`
//! measures it between scopes).
//!
//! The occluder is always a closed surface (a watertight mesh); the query
//! geometry may be anything: a facade tile (one polygon), a volume, an
//! asset. With `t` the tolerance:
//!
//! - *inside*: every point of the query lies in the occluder's solid or on
//!   its surface (a tile lying on the occluder's face is inside).
//! - *overlaps*: the query has points strictly inside the occluder's solid,
//!   or, for a closed query, the occluder has points strictly inside the
//!   query's solid (or the solids coincide). A tile lying on the surface
//!   does not overlap; two boxes sharing a face do not overlap.
//! - *touches*: overlaps, or inside, or a planar contact: a face of the
//!   query lies in the plane of a face of the occluder and the two share an
//!   area (not just an edge or a point).
//!
//! Three tests decide these, each cheap and tolerant of the rounding of
//! split and comp geometry:
//!
//! 1. *Sample points* of the query (vertices, edge midpoints, triangle
//!    centroids) are classified as in, on or out of the occluder: on within
//!    `t` of the surface, else in or out by the generalised winding number
//!    (the sum of the solid angles of the occluder's triangles), which is
//!    exact for closed meshes and does not care about rays hitting edges.
//! 2. A *proper crossing*: a face of the query and a face of the occluder
//!    whose planes cut each other, each face having vertices strictly on
//!    both sides of the other's plane, along a common piece longer than `t`.
//!    There the query passes through the occluder's surface, so it has
//!    points on both sides: it overlaps and is not inside. This finds the
//!    cases sample points miss (a large quad through a small box).
//! 3. *Planar contact*: coplanar face pairs whose triangles overlap in the
//!    plane by more than `t` (a separating-axis test in 2D).

use glam::{DAffine3, DMat3, DVec2, DVec3};

use crate::mesh::Mesh;
use crate::topology::Topology;
use crate::triangulate::{plane_basis, triangulate_face_at};

/// The tolerance of the occlusion tests in scene units (metres): points
/// closer than this to a surface are on it, planes closer than this
/// coincide. Far below modelling sizes, far above the rounding of the
/// splits and cuts that make adjacent geometry.
pub const TOLERANCE: f64 = 1e-4;

/// Cross products of unit normals shorter than this are parallel planes.
const PARALLEL: f64 = 1e-7;

/// The answers of the three occlusion queries for one pair of geometries.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Occlusion {
    pub inside: bool,
    pub overlaps: bool,
    pub touches: bool,
}

impl Occlusion {
    /// Or of each answer (a query against several occluders).
    pub fn or(self, other: Occlusion) -> Occlusion {
        Occlusion {
            inside: self.inside || other.inside,
            overlaps: self.overlaps || other.overlaps,
            touches: self.touches || other.touches,
        }
    }

    pub fn all(&self) -> bool {
        self.inside && self.overlaps && self.touches
    }
}

/// Where a point is relative to a closed mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PointSide {
    Inside,
    /// Within the tolerance of the surface.
    On,
    Outside,
}

/// One face of an [`OcclusionMesh`]: its plane, triangles and vertices.
#[derive(Clone, Debug)]
struct FaceInfo {
    /// Unit normal (Newell normal of the outer loop).
    normal: DVec3,
    /// `normal · p` for the points of the plane (through the vertex centroid).
    offset: f64,
    tris: std::ops::Range<u32>,
    verts: std::ops::Range<u32>,
    min: DVec3,
    max: DVec3,
}

impl FaceInfo {
    fn distance(&self, p: DVec3) -> f64 {
        self.normal.dot(p) - self.offset
    }
}

/// A mesh prepared for occlusion tests: triangulated, in scene coordinates,
/// with its faces' planes and bounds, and whether it is closed.
#[derive(Clone, Debug, Default)]
pub struct OcclusionMesh {
    positions: Vec<DVec3>,
    tris: Vec<[u32; 3]>,
    faces: Vec<FaceInfo>,
    face_verts: Vec<u32>,
    min: DVec3,
    max: DVec3,
    closed: bool,
    volume: f64,
}

impl OcclusionMesh {
    /// `mesh` placed by `transform` (none: as it is). Closedness is that of
    /// `geometry.isClosedSurface()`: every edge used by exactly two faces in
    /// opposite directions.
    pub fn new(mesh: &Mesh, transform: Option<&DAffine3>) -> OcclusionMesh {
        // One face is never closed; most query geometry (facade tiles) is one.
        let closed = mesh.faces.len() >= 2 && Topology::new(mesh).is_closed(mesh);
        OcclusionMesh::with_closed(mesh, transform, closed)
    }

    /// [`OcclusionMesh::new`] with closedness known by the caller.
    pub fn with_closed(mesh: &Mesh, transform: Option<&DAffine3>, closed: bool) -> OcclusionMesh {
        let positions: Vec<DVec3> = match transform {
            Some(t) => mesh
                .positions
                .iter()
                .map(|&p| t.transform_point3(p))
                .collect(),
            None => mesh.positions.clone(),
        };
        let mut out = OcclusionMesh {
            positions,
            min: DVec3::splat(f64::INFINITY),
            max: DVec3::splat(f64::NEG_INFINITY),
            ..OcclusionMesh::default()
        };
        let mut corner_tris = Vec::new();
        for f in 0..mesh.faces.len() {
            let normal = crate::measure::face_normal_at(mesh, &out.positions, f);
            if normal == DVec3::ZERO {
                continue;
            }
            corner_tris.clear();
            triangulate_face_at(mesh, &out.positions, f, &mut corner_tris);
            let first_tri = out.tris.len() as u32;
            for t in &corner_tris {
                let tri = t.map(|c| mesh.corners[c as usize]);
                let [a, b, c] = tri.map(|i| out.positions[i as usize]);
                // Slivers have no area to test and break the distance formulas.
                if (b - a).cross(c - a).length_squared() > 1e-24 {
                    out.tris.push(tri);
                }
            }
            let first_vert = out.face_verts.len() as u32;
            let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
            let mut sum = DVec3::ZERO;
            for &l in mesh.face_loops(f) {
                for &i in mesh.loop_indices(l) {
                    let p = out.positions[i as usize];
                    out.face_verts.push(i);
                    lo = lo.min(p);
                    hi = hi.max(p);
                    sum += p;
                }
            }
            let count = out.face_verts.len() as u32 - first_vert;
            if out.tris.len() as u32 == first_tri || count == 0 {
                out.face_verts.truncate(first_vert as usize);
                continue;
            }
            out.min = out.min.min(lo);
            out.max = out.max.max(hi);
            out.faces.push(FaceInfo {
                normal,
                offset: normal.dot(sum / count as f64),
                tris: first_tri..out.tris.len() as u32,
                verts: first_vert..out.face_verts.len() as u32,
                min: lo,
                max: hi,
            });
        }
        out.closed = closed && !out.tris.is_empty();
        if out.closed {
            // Relative to a corner of the bounds, for precision far from the origin.
            let o = out.min;
            let six_v: f64 = out
                .tris
                .iter()
                .map(|t| {
                    let [a, b, c] = t.map(|i| out.positions[i as usize] - o);
                    a.dot(b.cross(c))
                })
                .sum();
            out.volume = (six_v / 6.0).abs();
        }
        out
    }

    pub fn is_empty(&self) -> bool {
        self.tris.is_empty()
    }

    pub fn is_closed(&self) -> bool {
        self.closed
    }

    /// The enclosed volume of a closed mesh (0 for an open one).
    pub fn volume(&self) -> f64 {
        self.volume
    }

    /// The surface area (of the faces that have one).
    pub fn area(&self) -> f64 {
        (0..self.tris.len())
            .map(|k| {
                let [a, b, c] = self.tri(k);
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }

    /// Axis-aligned bounds `(min, max)`; inverted (min > max) when empty.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        (self.min, self.max)
    }

    fn tri(&self, t: usize) -> [DVec3; 3] {
        self.tris[t].map(|i| self.positions[i as usize])
    }

    /// Where `p` is relative to this mesh, taken as a solid (meaningful for
    /// closed meshes; an open one has no inside).
    pub fn classify(&self, p: DVec3, tol: f64) -> PointSide {
        let t = DVec3::splat(tol);
        if p.cmplt(self.min - t).any() || p.cmpgt(self.max + t).any() {
            return PointSide::Outside;
        }
        let tol2 = tol * tol;
        let mut solid_angle = 0.0;
        for k in 0..self.tris.len() {
            let [a, b, c] = self.tri(k);
            let lo = a.min(b).min(c) - t;
            let hi = a.max(b).max(c) + t;
            if p.cmpge(lo).all()
                && p.cmple(hi).all()
                && point_triangle_distance2(p, a, b, c) <= tol2
            {
                return PointSide::On;
            }
            if self.closed {
                solid_angle += triangle_solid_angle(a - p, b - p, c - p);
            }
        }
        // The winding number is ±1 inside (by orientation), 0 outside.
        if (solid_angle / (4.0 * std::f64::consts::PI)).abs() > 0.5 {
            PointSide::Inside
        } else {
            PointSide::Outside
        }
    }

    /// Calls `f` with the sample points of the mesh (vertices first, then
    /// edge midpoints and triangle centroids) until it returns false.
    fn for_samples(&self, mut f: impl FnMut(DVec3) -> bool) {
        let mut seen = vec![false; self.positions.len()];
        for t in &self.tris {
            for &i in t {
                if !std::mem::replace(&mut seen[i as usize], true) && !f(self.positions[i as usize])
                {
                    return;
                }
            }
        }
        for k in 0..self.tris.len() {
            let [a, b, c] = self.tri(k);
            if !f((a + b) * 0.5) || !f((b + c) * 0.5) || !f((c + a) * 0.5) {
                return;
            }
            if !f((a + b + c) / 3.0) {
                return;
            }
        }
    }

    /// Whether any sample point of `self` is strictly inside `solid`, and
    /// whether any is strictly outside. Stops as soon as both are known, or
    /// when `stop_at_inside` and one is inside.
    fn sample_sides(&self, solid: &OcclusionMesh, tol: f64, stop_at_inside: bool) -> (bool, bool) {
        let (mut any_in, mut any_out) = (false, false);
        self.for_samples(|p| {
            match solid.classify(p, tol) {
                PointSide::Inside => any_in = true,
                PointSide::Outside => any_out = true,
                PointSide::On => {}
            }
            !(any_in && (any_out || stop_at_inside))
        });
        (any_in, any_out)
    }
}

fn boxes_touch(amin: DVec3, amax: DVec3, bmin: DVec3, bmax: DVec3, tol: f64) -> bool {
    let t = DVec3::splat(tol);
    (amin - t).cmple(bmax).all() && (bmin - t).cmple(amax).all()
}

/// The three occlusion answers for `query` against the closed `occluder`
/// (all false if the occluder is not closed or either is empty).
pub fn occlusion(query: &OcclusionMesh, occluder: &OcclusionMesh, tol: f64) -> Occlusion {
    let none = Occlusion::default();
    if !occluder.closed || query.is_empty() || occluder.is_empty() {
        return none;
    }
    if !boxes_touch(query.min, query.max, occluder.min, occluder.max, tol) {
        return none;
    }
    let mut crossing = false;
    let mut contact = false;
    let mut scratch = (Vec::new(), Vec::new());
    'faces: for qf in &query.faces {
        if !boxes_touch(qf.min, qf.max, occluder.min, occluder.max, tol) {
            continue;
        }
        for of in &occluder.faces {
            if !boxes_touch(qf.min, qf.max, of.min, of.max, tol) {
                continue;
            }
            if !contact && planar_contact(query, qf, occluder, of, tol) {
                contact = true;
            } else if !crossing && crosses(query, qf, occluder, of, tol, &mut scratch) {
                crossing = true;
            }
            if crossing && contact {
                break 'faces;
            }
        }
    }
    let (any_in, any_out) = if crossing {
        (true, true)
    } else {
        query.sample_sides(occluder, tol, false)
    };
    let inside = !crossing && !any_out;
    let mut overlaps = crossing || any_in;
    if !overlaps && query.closed && query.volume > tol * tol * tol {
        // A solid query: its solid lies within the occluder's if its surface
        // does; else the occluder may lie (partly) within the query's.
        overlaps = inside || {
            let (o_in, o_out) = occluder.sample_sides(query, tol, true);
            o_in || !o_out
        };
    }
    Occlusion {
        inside,
        overlaps,
        touches: overlaps || inside || contact,
    }
}

/// Whether face `qf` of `q` and face `of` of `o` lie in one plane and share
/// an area wider than `tol`.
fn planar_contact(
    q: &OcclusionMesh,
    qf: &FaceInfo,
    o: &OcclusionMesh,
    of: &FaceInfo,
    tol: f64,
) -> bool {
    if qf.normal.cross(of.normal).length() > PARALLEL.max(tol * 1e-2) {
        return false;
    }
    let on_plane = |m: &OcclusionMesh, f: &FaceInfo, plane: &FaceInfo| {
        m.face_verts[f.verts.start as usize..f.verts.end as usize]
            .iter()
            .all(|&i| plane.distance(m.positions[i as usize]).abs() <= tol)
    };
    if !on_plane(q, qf, of) || !on_plane(o, of, qf) {
        return false;
    }
    let (u, v) = plane_basis(of.normal);
    let flat = |p: DVec3| DVec2::new(u.dot(p), v.dot(p));
    for a in qf.tris.clone() {
        let ta = q.tri(a as usize).map(flat);
        for b in of.tris.clone() {
            let tb = o.tri(b as usize).map(flat);
            if triangles_overlap_2d(&ta, &tb, tol) {
                return true;
            }
        }
    }
    false
}

/// Separating axes in 2D: the triangles overlap by more than `tol` along
/// every edge normal of both.
fn triangles_overlap_2d(a: &[DVec2; 3], b: &[DVec2; 3], tol: f64) -> bool {
    for tri in [a, b] {
        for i in 0..3 {
            let e = tri[(i + 1) % 3] - tri[i];
            let len = e.length();
            if len <= 1e-12 {
                continue;
            }
            let axis = DVec2::new(-e.y, e.x) / len;
            let span = |t: &[DVec2; 3]| {
                let d = t.map(|p| axis.dot(p));
                (d[0].min(d[1]).min(d[2]), d[0].max(d[1]).max(d[2]))
            };
            let (a0, a1) = span(a);
            let (b0, b1) = span(b);
            if a1.min(b1) - a0.max(b0) <= tol {
                return false;
            }
        }
    }
    true
}

type Intervals = (Vec<(f64, f64)>, Vec<(f64, f64)>);

/// Whether face `qf` of `q` properly crosses face `of` of `o` (see the
/// module documentation).
fn crosses(
    q: &OcclusionMesh,
    qf: &FaceInfo,
    o: &OcclusionMesh,
    of: &FaceInfo,
    tol: f64,
    scratch: &mut Intervals,
) -> bool {
    let dir = qf.normal.cross(of.normal);
    let len = dir.length();
    if len <= PARALLEL {
        return false;
    }
    let dir = dir / len;
    if !straddles(q, qf, of, tol) || !straddles(o, of, qf, tol) {
        return false;
    }
    let (qi, oi) = scratch;
    qi.clear();
    oi.clear();
    plane_intervals(q, qf, of, dir, tol, qi);
    plane_intervals(o, of, qf, dir, tol, oi);
    let mut common = 0.0;
    for &(a0, a1) in qi.iter() {
        for &(b0, b1) in oi.iter() {
            common += (a1.min(b1) - a0.max(b0)).max(0.0);
        }
    }
    common > tol
}

/// Whether face `f` of `m` has vertices farther than `tol` on both sides of
/// the plane of `plane`.
fn straddles(m: &OcclusionMesh, f: &FaceInfo, plane: &FaceInfo, tol: f64) -> bool {
    let (mut above, mut below) = (false, false);
    for &i in &m.face_verts[f.verts.start as usize..f.verts.end as usize] {
        let d = plane.distance(m.positions[i as usize]);
        above |= d > tol;
        below |= d < -tol;
    }
    above && below
}

/// The pieces of the triangles of face `f` in the plane of `plane`, as
/// intervals of the coordinate along `dir` (the planes' common line).
/// Vertices within `tol` of the plane count as on it.
fn plane_intervals(
    m: &OcclusionMesh,
    f: &FaceInfo,
    plane: &FaceInfo,
    dir: DVec3,
    tol: f64,
    out: &mut Vec<(f64, f64)>,
) {
    for t in f.tris.clone() {
        let p = m.tri(t as usize);
        let d = p.map(|x| {
            let d = plane.distance(x);
            if d.abs() <= tol {
                0.0
            } else {
                d
            }
        });
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for i in 0..3 {
            let j = (i + 1) % 3;
            let mut add = |x: DVec3| {
                let s = dir.dot(x);
                lo = lo.min(s);
                hi = hi.max(s);
            };
            if d[i] == 0.0 {
                add(p[i]);
            }
            if d[i] * d[j] < 0.0 {
                let s = d[i] / (d[i] - d[j]);
                add(p[i] + (p[j] - p[i]) * s);
            }
        }
        if lo <= hi {
            out.push((lo, hi));
        }
    }
}

/// Squared distance from `p` to the triangle `abc` (Ericson, Real-Time
/// Collision Detection, 5.1.5).
fn point_triangle_distance2(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return ap.length_squared();
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return bp.length_squared();
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (p - (a + ab * v)).length_squared();
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return cp.length_squared();
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (p - (a + ac * w)).length_squared();
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (p - (b + (c - b) * w)).length_squared();
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    (p - (a + ab * v + ac * w)).length_squared()
}

/// The signed solid angle of the triangle `abc` seen from the origin (Van
/// Oosterom and Strackee).
fn triangle_solid_angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let (la, lb, lc) = (a.length(), b.length(), c.length());
    let num = a.dot(b.cross(c));
    let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    2.0 * num.atan2(den)
}

// ----- oriented boxes -----

/// A box with orthonormal axes (a scope); half sizes are never negative.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrientedBox {
    pub center: DVec3,
    /// Unit axes.
    pub axes: [DVec3; 3],
    pub half: DVec3,
}

impl OrientedBox {
    /// The box from `origin` along the columns of `axes` (orthonormal) by
    /// `size`; a negative size extends backwards along its axis (a scope
    /// mirrored by `s`), a zero size makes a flat box.
    pub fn new(origin: DVec3, axes: DMat3, size: DVec3) -> OrientedBox {
        let axes = [axes.x_axis, axes.y_axis, axes.z_axis];
        let center =
            origin + axes[0] * (size.x * 0.5) + axes[1] * (size.y * 0.5) + axes[2] * (size.z * 0.5);
        OrientedBox {
            center,
            axes,
            half: size.abs() * 0.5,
        }
    }

    pub fn corners(&self) -> [DVec3; 8] {
        let mut out = [DVec3::ZERO; 8];
        for (k, c) in out.iter_mut().enumerate() {
            let s = |bit: usize| if k & bit != 0 { 1.0 } else { -1.0 };
            *c = self.center
                + self.axes[0] * (s(1) * self.half.x)
                + self.axes[1] * (s(2) * self.half.y)
                + self.axes[2] * (s(4) * self.half.z);
        }
        out
    }

    /// Axis-aligned bounds `(min, max)`.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        let ext = self.axes[0].abs() * self.half.x
            + self.axes[1].abs() * self.half.y
            + self.axes[2].abs() * self.half.z;
        (self.center - ext, self.center + ext)
    }

    /// Distance from `p` to the box (0 inside).
    pub fn distance_to_point(&self, p: DVec3) -> f64 {
        let d = p - self.center;
        let mut out = DVec3::ZERO;
        for i in 0..3 {
            let x = self.axes[i].dot(d);
            out[i] = (x.abs() - self.half[i]).max(0.0);
        }
        out.length()
    }

    /// The twelve edges as segments.
    fn edges(&self) -> [(DVec3, DVec3); 12] {
        let c = self.corners();
        let mut out = [(DVec3::ZERO, DVec3::ZERO); 12];
        let mut n = 0;
        for k in 0..8usize {
            for bit in [1usize, 2, 4] {
                if k & bit == 0 {
                    out[n] = (c[k], c[k | bit]);
                    n += 1;
                }
            }
        }
        out
    }

    /// Whether the boxes are separated along some axis (separating axis
    /// theorem: the 3 + 3 face normals and the 9 edge cross products).
    fn separated(&self, other: &OrientedBox) -> bool {
        let d = other.center - self.center;
        let apart = |axis: DVec3| {
            let len = axis.length();
            if len < 1e-9 {
                return false;
            }
            let axis = axis / len;
            let r = |b: &OrientedBox| {
                (0..3)
                    .map(|i| b.half[i] * b.axes[i].dot(axis).abs())
                    .sum::<f64>()
            };
            d.dot(axis).abs() > r(self) + r(other)
        };
        for i in 0..3 {
            if apart(self.axes[i]) || apart(other.axes[i]) {
                return true;
            }
        }
        for i in 0..3 {
            for j in 0..3 {
                if apart(self.axes[i].cross(other.axes[j])) {
                    return true;
                }
            }
        }
        false
    }
}

/// The smallest distance between two boxes (0 when they touch or
/// intersect). For disjoint convex polytopes the closest points lie on a
/// vertex of one and anything of the other, or on two edges: so the
/// distance is the least of the corner-to-box and edge-to-edge distances.
pub fn box_distance(a: &OrientedBox, b: &OrientedBox) -> f64 {
    if !a.separated(b) {
        return 0.0;
    }
    let mut best = f64::INFINITY;
    for p in a.corners() {
        best = best.min(b.distance_to_point(p));
    }
    for p in b.corners() {
        best = best.min(a.distance_to_point(p));
    }
    let eb = b.edges();
    for (p0, p1) in a.edges() {
        for &(q0, q1) in &eb {
            best = best.min(segment_distance2(p0, p1, q0, q1).sqrt());
        }
    }
    best
}

/// Squared distance between the segments `p0 p1` and `q0 q1` (Ericson,
/// Real-Time Collision Detection, 5.1.9), degenerate segments included.
fn segment_distance2(p0: DVec3, p1: DVec3, q0: DVec3, q1: DVec3) -> f64 {
    let d1 = p1 - p0;
    let d2 = q1 - q0;
    let r = p0 - q0;
    let a = d1.length_squared();
    let e = d2.length_squared();
    let f = d2.dot(r);
    const EPS: f64 = 1e-18;
    let (s, t);
    if a <= EPS && e <= EPS {
        return r.length_squared();
    }
    if a <= EPS {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(r);
        if e <= EPS {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            let mut s0 = if denom > EPS {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t0 = (b * s0 + f) / e;
            if t0 < 0.0 {
                t0 = 0.0;
                s0 = (-c / a).clamp(0.0, 1.0);
            } else if t0 > 1.0 {
                t0 = 1.0;
                s0 = ((b - c) / a).clamp(0.0, 1.0);
            }
            s = s0;
            t = t0;
        }
    }
    ((p0 + d1 * s) - (q0 + d2 * t)).length_squared()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::primitive::cube;

    /// A box from `min` of `size`.
    fn boxed(min: DVec3, size: DVec3) -> OcclusionMesh {
        let t = DAffine3::from_translation(min);
        OcclusionMesh::new(&cube(size), Some(&t))
    }

    /// A rectangle with corners `o`, `o + a`, `o + a + b`, `o + b`.
    fn quad(o: DVec3, a: DVec3, b: DVec3) -> OcclusionMesh {
        OcclusionMesh::new(&Mesh::polygon(&[o, o + a, o + a + b, o + b]), None)
    }

    fn unit() -> OcclusionMesh {
        boxed(DVec3::ZERO, DVec3::ONE)
    }

    fn answers(q: &OcclusionMesh, o: &OcclusionMesh) -> (bool, bool, bool) {
        let r = occlusion(q, o, TOLERANCE);
        (r.touches, r.overlaps, r.inside)
    }

    const X: DVec3 = DVec3::X;
    const Y: DVec3 = DVec3::Y;
    const Z: DVec3 = DVec3::Z;

    #[test]
    fn closedness_and_volume() {
        let c = boxed(DVec3::new(5.0, 0.0, 0.0), DVec3::new(2.0, 3.0, 4.0));
        assert!(c.is_closed());
        assert!((c.volume() - 24.0).abs() < 1e-9);
        assert!((c.area() - 52.0).abs() < 1e-9);
        assert_eq!(
            c.bounds(),
            (DVec3::new(5.0, 0.0, 0.0), DVec3::new(7.0, 3.0, 4.0))
        );
        let q = quad(DVec3::ZERO, X, Y);
        assert!(!q.is_closed());
        assert_eq!(q.volume(), 0.0);
    }

    #[test]
    fn points_are_classified() {
        let c = unit();
        let t = TOLERANCE;
        assert_eq!(c.classify(DVec3::splat(0.5), t), PointSide::Inside);
        assert_eq!(c.classify(DVec3::new(0.5, 0.5, 1.0), t), PointSide::On);
        assert_eq!(c.classify(DVec3::new(1.0, 1.0, 1.0), t), PointSide::On);
        assert_eq!(
            c.classify(DVec3::new(0.5, 0.5, 1.0 + 0.5 * t), t),
            PointSide::On
        );
        assert_eq!(
            c.classify(DVec3::new(0.5, 0.5, 1.0 + 2.0 * t), t),
            PointSide::Outside
        );
        assert_eq!(
            c.classify(DVec3::new(0.5, 0.5, 1.0 - 2.0 * t), t),
            PointSide::Inside
        );
        assert_eq!(c.classify(DVec3::new(1.5, 0.5, 0.5), t), PointSide::Outside);
        // Mirrored placement (faces inwards): still inside.
        let m = OcclusionMesh::new(
            &cube(DVec3::ONE),
            Some(&DAffine3::from_scale(DVec3::new(-1.0, 1.0, 1.0))),
        );
        assert_eq!(m.classify(DVec3::new(-0.5, 0.5, 0.5), t), PointSide::Inside);
    }

    /// The first column of the reference figure: planar contact only.
    #[test]
    fn partial_planar_contact_only_touches() {
        let o = unit();
        // A quad in the plane of the front face, half of it beyond the box.
        let q = quad(DVec3::new(0.5, 0.3, 1.0), X, Y * 0.5);
        assert_eq!(answers(&q, &o), (true, false, false));
        // A box on top of the box, offset by half its width.
        let b = boxed(DVec3::new(0.5, 1.0, 0.2), DVec3::splat(0.6));
        assert_eq!(answers(&b, &o), (true, false, false));
    }

    /// Second column: apart.
    #[test]
    fn apart_is_nothing() {
        let o = unit();
        let q = quad(DVec3::new(0.2, 1.5, 0.2), X * 0.5, Z * 0.5);
        assert_eq!(answers(&q, &o), (false, false, false));
        let b = boxed(DVec3::new(0.2, 1.2, 0.2), DVec3::splat(0.5));
        assert_eq!(answers(&b, &o), (false, false, false));
    }

    /// Third column: partly in, partly out; and a query around the occluder.
    #[test]
    fn partly_inside_overlaps() {
        let o = unit();
        let q = quad(DVec3::new(0.5, 0.2, 0.5), X, Y * 0.6);
        assert_eq!(answers(&q, &o), (true, true, false));
        let b = boxed(DVec3::splat(0.5), DVec3::ONE);
        assert_eq!(answers(&b, &o), (true, true, false));
        let around = boxed(DVec3::splat(-0.5), DVec3::splat(2.0));
        assert_eq!(answers(&around, &o), (true, true, false));
    }

    /// Fourth column: on the surface is inside and touches, no overlap.
    #[test]
    fn on_the_surface_is_inside() {
        let o = unit();
        let q = quad(DVec3::new(0.2, 0.2, 1.0), X * 0.5, Y * 0.5);
        assert_eq!(answers(&q, &o), (true, false, true));
        // Facing into the box, and the whole face.
        let q = quad(DVec3::new(0.0, 0.0, 1.0), Y, X);
        assert_eq!(answers(&q, &o), (true, false, true));
    }

    /// Fifth column: inside.
    #[test]
    fn inside_is_everything() {
        let o = boxed(DVec3::ZERO, DVec3::splat(2.0));
        let q = quad(DVec3::new(0.5, 0.5, 1.0), X * 0.5, Y * 0.5);
        assert_eq!(answers(&q, &o), (true, true, true));
        // A box inside, flush with the front face.
        let b = boxed(DVec3::new(0.5, 0.5, 1.0), DVec3::ONE);
        assert_eq!(answers(&b, &o), (true, true, true));
        // The same box.
        assert_eq!(answers(&o, &o), (true, true, true));
    }

    #[test]
    fn shared_faces_edges_and_corners() {
        let o = unit();
        let face = boxed(DVec3::new(1.0, 0.0, 0.0), DVec3::ONE);
        assert_eq!(answers(&face, &o), (true, false, false));
        let edge = boxed(DVec3::new(1.0, 1.0, 0.0), DVec3::ONE);
        assert_eq!(answers(&edge, &o), (false, false, false));
        let corner = boxed(DVec3::ONE, DVec3::ONE);
        assert_eq!(answers(&corner, &o), (false, false, false));
        // A quad standing on the top face along an edge: line contact.
        let q = quad(DVec3::new(0.0, 1.0, 0.5), X, Y);
        assert_eq!(answers(&q, &o), (false, false, false));
        // A quad beside the box, sharing its edge.
        let q = quad(DVec3::new(1.0, 0.0, 1.0), X, Y);
        assert_eq!(answers(&q, &o), (false, false, false));
        // A gap of 1 mm is no contact.
        let near = boxed(DVec3::new(1.001, 0.0, 0.0), DVec3::ONE);
        assert_eq!(answers(&near, &o), (false, false, false));
    }

    /// A large quad through a small box, all its vertices outside: found by
    /// the crossing of faces, not by sample points.
    #[test]
    fn crossing_without_samples_inside() {
        let o = boxed(DVec3::new(4.9, 4.9, -0.1), DVec3::splat(0.2));
        let q = quad(DVec3::ZERO, X * 10.0, Y * 10.0);
        // The quad's centroid (5, 5, 0) is inside the box: move the box off it.
        let o2 = boxed(DVec3::new(2.1, 7.3, -0.1), DVec3::splat(0.2));
        assert_eq!(answers(&q, &o), (true, true, false));
        assert_eq!(answers(&q, &o2), (true, true, false));
    }

    /// A quad coplanar with the side face of a taller box and higher than
    /// it: touches, neither inside nor overlapping (the facade tile of a
    /// stepped building next to the lower step).
    #[test]
    fn tile_beside_a_lower_step() {
        let step = boxed(DVec3::ZERO, DVec3::new(5.0, 10.5, 10.0));
        let tile = quad(DVec3::new(5.0, 8.0, 10.0), Z * -10.0, Y * 4.0);
        assert_eq!(answers(&tile, &step), (true, false, false));
        let above = quad(DVec3::new(5.0, 12.0, 10.0), Z * -10.0, Y * 4.0);
        assert_eq!(answers(&above, &step), (false, false, false));
        let below = quad(DVec3::new(5.0, 4.0, 10.0), Z * -10.0, Y * 4.0);
        assert_eq!(answers(&below, &step), (true, false, true));
    }

    /// An L-shaped occluder: a quad spanning its notch has its vertices on
    /// the surface but its middle outside.
    #[test]
    fn concave_occluder() {
        let mut m = Mesh::new();
        // The L (outline in xz, counter-clockwise from above) extruded by 1.
        let outline = [
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, -1.0),
            (1.0, -1.0),
            (1.0, -2.0),
            (0.0, -2.0),
        ];
        for &(x, z) in &outline {
            m.positions.push(DVec3::new(x, 0.0, z));
        }
        for &(x, z) in &outline {
            m.positions.push(DVec3::new(x, 1.0, z));
        }
        let n = outline.len() as u32;
        let bottom: Vec<u32> = (0..n).rev().collect();
        let top: Vec<u32> = (n..2 * n).collect();
        m.add_face(&[&bottom], 0);
        m.add_face(&[&top], 0);
        for i in 0..n {
            let j = (i + 1) % n;
            m.add_face(&[&[i, j, j + n, i + n]], 0);
        }
        let l = OcclusionMesh::new(&m, None);
        assert!(l.is_closed());
        assert!((l.volume() - 3.0).abs() < 1e-9);
        // From one arm into the other across the notch: the ends are
        // inside, the middle is not.
        let q = quad(
            DVec3::new(1.8, 0.2, -0.5),
            DVec3::new(-1.3, 0.0, -1.3),
            Y * 0.5,
        );
        assert_eq!(answers(&q, &l), (true, true, false));
        // From the tip of one arm to the tip of the other: through the
        // notch, meeting the L only along its two vertical edges.
        let q = quad(
            DVec3::new(2.0, 0.2, -1.0),
            DVec3::new(-1.0, 0.0, -1.0),
            Y * 0.5,
        );
        assert_eq!(answers(&q, &l), (false, false, false));
        let inner = quad(DVec3::new(0.2, 0.2, -0.5), X * 1.5, Y * 0.5);
        assert_eq!(answers(&inner, &l), (true, true, true));
    }

    #[test]
    fn open_occluders_occlude_nothing() {
        let mut open = cube(DVec3::ONE);
        open.faces.pop();
        let o = OcclusionMesh::new(&open, None);
        assert!(!o.is_closed());
        let q = quad(DVec3::splat(0.25), X * 0.5, Y * 0.5);
        assert_eq!(answers(&q, &o), (false, false, false));
    }

    #[test]
    fn box_distances() {
        let a = OrientedBox::new(DVec3::ZERO, DMat3::IDENTITY, DVec3::ONE);
        let b = OrientedBox::new(DVec3::new(3.0, 0.0, 0.0), DMat3::IDENTITY, DVec3::ONE);
        assert!((box_distance(&a, &b) - 2.0).abs() < 1e-12);
        // Corner to corner.
        let c = OrientedBox::new(DVec3::splat(2.0), DMat3::IDENTITY, DVec3::ONE);
        assert!((box_distance(&a, &c) - 3f64.sqrt()).abs() < 1e-12);
        // Touching and overlapping.
        let d = OrientedBox::new(DVec3::new(1.0, 0.5, 0.0), DMat3::IDENTITY, DVec3::ONE);
        assert_eq!(box_distance(&a, &d), 0.0);
        let e = OrientedBox::new(DVec3::splat(0.5), DMat3::IDENTITY, DVec3::ONE);
        assert_eq!(box_distance(&a, &e), 0.0);
        // Mirrored size: the same box as from the other corner.
        let m = OrientedBox::new(DVec3::new(4.0, 1.0, 1.0), DMat3::IDENTITY, -DVec3::ONE);
        assert!((box_distance(&a, &m) - 2.0).abs() < 1e-12);
        // Flat boxes (scopes of faces): two parallel unit squares 0.5 apart.
        let f = OrientedBox::new(
            DVec3::new(0.0, 0.0, 0.0),
            DMat3::IDENTITY,
            DVec3::new(1.0, 0.0, 1.0),
        );
        let g = OrientedBox::new(
            DVec3::new(1.5, 0.0, 0.0),
            DMat3::IDENTITY,
            DVec3::new(1.0, 0.0, 1.0),
        );
        assert!((box_distance(&f, &g) - 0.5).abs() < 1e-12);
        // A box turned by 45 degrees about y, its edge facing the cube's face.
        let r = DMat3::from_rotation_y(std::f64::consts::FRAC_PI_4);
        let h = OrientedBox::new(DVec3::new(3.0, 0.0, 0.5), r, DVec3::ONE);
        // Its corner nearest to the cube is the origin corner at x = 3.
        assert!(
            (box_distance(&a, &h) - 2.0).abs() < 1e-12,
            "{}",
            box_distance(&a, &h)
        );
    }

    /// Edge against edge: two boxes whose nearest points are the middles of
    /// crossing edges, not corners.
    #[test]
    fn edge_to_edge_distance() {
        let a = OrientedBox::new(
            DVec3::new(-1.0, -1.0, -0.5),
            DMat3::IDENTITY,
            DVec3::new(2.0, 1.0, 1.0),
        );
        // Turned 90 degrees about y (its long side along z) and 45 about z
        // (an edge pointing down), above the first box's top.
        let r = DMat3::from_rotation_z(std::f64::consts::FRAC_PI_4);
        let s = 0.5 * 2f64.sqrt();
        let b = OrientedBox::new(DVec3::new(0.0, 1.0, -1.0), r, DVec3::new(s, s, 2.0));
        // b's lowest edge runs along z at x = 0, y = 1: the top of a is at y = 0.
        let d = box_distance(&a, &b);
        assert!((d - 1.0).abs() < 1e-9, "{d}");
    }

    /// Against sampled surface points: the distance is never more than the
    /// sampled one, and never less by more than the sampling step allows.
    #[test]
    fn box_distance_matches_sampling() {
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..40 {
            let mk = |rnd: &mut dyn FnMut() -> f64| {
                let rot =
                    DMat3::from_euler(glam::EulerRot::YXZ, rnd() * 6.0, rnd() * 6.0, rnd() * 6.0);
                let o = DVec3::new(rnd() * 4.0, rnd() * 4.0, rnd() * 4.0);
                let s = DVec3::new(rnd() * 2.0, rnd() * 2.0, rnd() * 2.0);
                OrientedBox::new(o, rot, s)
            };
            let a = mk(&mut rnd);
            let b = mk(&mut rnd);
            let samples = |bx: &OrientedBox| {
                let n = 8;
                let mut pts = Vec::new();
                for i in 0..=n {
                    for j in 0..=n {
                        for k in 0..=n {
                            let f = DVec3::new(i as f64, j as f64, k as f64) / n as f64 * 2.0 - 1.0;
                            pts.push(
                                bx.center
                                    + bx.axes[0] * f.x * bx.half.x
                                    + bx.axes[1] * f.y * bx.half.y
                                    + bx.axes[2] * f.z * bx.half.z,
                            );
                        }
                    }
                }
                pts
            };
            let (pa, pb) = (samples(&a), samples(&b));
            let mut sampled = f64::INFINITY;
            for p in &pa {
                for q in &pb {
                    sampled = sampled.min(p.distance(*q));
                }
            }
            let d = box_distance(&a, &b);
            let step = (a.half.length() + b.half.length()) * 2.0 / 8.0;
            assert!(d <= sampled + 1e-9, "{d} > {sampled}");
            assert!(d >= sampled - step, "{d} << {sampled}");
        }
    }
}
