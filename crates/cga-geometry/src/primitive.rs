//! CGA's built-in primitives (`primitiveQuad`, `primitiveDisk`,
//! `primitiveCube`, `primitiveSphere`, `primitiveCylinder`, `primitiveCone`)
//! and the `builtin:cube` asset.
//!
//! Each is generated in a local frame filling the box `[0, size]` (x width,
//! y height, z depth), origin at the min corner as CGA scopes are; the caller
//! fits it into the scope (zero scope sizes, and the xz-centring when a
//! radius or dimensions are given, are the operation's business). All have
//! texture coordinates in UV set 0 and per-corner normals, faces wound
//! counter-clockwise seen from outside; the solids are closed.
//!
//! Conventions shared by all: flat shapes lie in the xz-plane facing +y, and
//! go around counter-clockwise seen from above like a lot, starting on the
//! front (`z = depth`); `u` runs along x and `v` away from the front. Solids
//! list their faces as `extrude` would from their base: bottom, top, then the
//! sides from the front edge on (the sphere: from the top down).

use std::f64::consts::{PI, TAU};

use glam::{DVec2, DVec3};

use crate::mesh::Mesh;

/// Upper bound on segment counts, to keep a typo from allocating gigabytes.
const MAX_SEGMENTS: usize = 1 << 14;

fn sanitize(n: usize, min: usize) -> usize {
    n.clamp(min, MAX_SEGMENTS)
}

/// Adds a face with UVs (set 0) and normals per corner.
fn face(m: &mut Mesh, corners: &[(u32, DVec2, DVec3)]) {
    let idx: Vec<u32> = corners.iter().map(|c| c.0).collect();
    m.add_face(&[&idx], 0);
    let n = m.corners.len();
    let uv = m.uvs[0].as_mut().expect("primitives carry UV set 0");
    let nr = m.normals.as_mut().expect("primitives carry normals");
    for (k, c) in corners.iter().enumerate() {
        uv[n - corners.len() + k] = c.1;
        nr[n - corners.len() + k] = c.2;
    }
}

fn new_mesh() -> Mesh {
    let mut m = Mesh::new();
    m.uvs[0] = Some(Vec::new());
    m.normals = Some(Vec::new());
    m
}

/// `primitiveQuad`: a `width` × `depth` quad in the xz-plane facing +y.
pub fn quad(width: f64, depth: f64) -> Mesh {
    let mut m = new_mesh();
    m.positions.extend([
        DVec3::new(0.0, 0.0, depth),
        DVec3::new(width, 0.0, depth),
        DVec3::new(width, 0.0, 0.0),
        DVec3::new(0.0, 0.0, 0.0),
    ]);
    let uv = [(0., 0.), (1., 0.), (1., 1.), (0., 1.)].map(|(u, v)| DVec2::new(u, v));
    let c: Vec<_> = (0..4).map(|k| (k as u32, uv[k], DVec3::Y)).collect();
    face(&mut m, &c);
    m
}

/// The `n` points of a disk, cylinder or cone ring, filling the `width` ×
/// `depth` rectangle: as CityEngine places them, half a step off the axes
/// (8 sides: at 22.5° + k·45°), counter-clockwise seen from above starting
/// just after +x, scaled so that the polygon's bounding box is the
/// rectangle (with 8 sides the flat sides touch it). Each point comes with
/// its angle and its position in the unit square (for texture coordinates).
fn ring(n: usize, width: f64, depth: f64) -> Vec<RingPoint> {
    let unit: Vec<(f64, DVec2)> = (0..n)
        .map(|k| {
            let a = TAU * (k as f64 + 0.5) / n as f64;
            (a, DVec2::new(a.cos(), -a.sin()))
        })
        .collect();
    let (mut lo, mut hi) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
    for (_, p) in &unit {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let ext = hi - lo;
    unit.into_iter()
        .map(|(a, p)| {
            let t = (p - lo) / ext;
            RingPoint {
                angle: a,
                unit: t,
                pos: DVec3::new(t.x * width, 0.0, t.y * depth),
                radii: DVec2::new(width, depth) / ext,
            }
        })
        .collect()
}

/// A point of [`ring`].
struct RingPoint {
    /// Its angle from +x, counter-clockwise seen from above.
    angle: f64,
    /// Its position in the unit square (x, z).
    unit: DVec2,
    /// Its position in the `width` × `depth` rectangle.
    pos: DVec3,
    /// The radii of the ellipse the ring lies on (x, z).
    radii: DVec2,
}

impl RingPoint {
    /// Texture coordinates mapping the rectangle onto the unit square, seen
    /// from above (`mirrored`: seen from below).
    fn uv(&self, mirrored: bool) -> DVec2 {
        let v = 1.0 - self.unit.y;
        DVec2::new(self.unit.x, if mirrored { 1.0 - v } else { v })
    }

    /// The horizontal outward normal of the ellipse through the point.
    fn radial(&self) -> DVec3 {
        let a = self.angle;
        DVec3::new(a.cos() / self.radii.x, 0.0, -a.sin() / self.radii.y).normalize_or_zero()
    }
}

/// `primitiveDisk`: a polygon of `n_vertices` (at least 3, default 16)
/// filling `width` × `depth` ([`ring`]), in the xz-plane facing +y. UVs map
/// the rectangle onto the unit square.
pub fn disk(n_vertices: usize, width: f64, depth: f64) -> Mesh {
    let n = sanitize(n_vertices, 3);
    let mut m = new_mesh();
    let mut c = Vec::with_capacity(n);
    for (k, p) in ring(n, width, depth).iter().enumerate() {
        m.positions.push(p.pos);
        c.push((k as u32, p.uv(false), DVec3::Y));
    }
    face(&mut m, &c);
    m
}

/// `primitiveCube` and `builtin:cube`: a box of `size` with 8 shared
/// positions and 6 faces (bottom, top, front, right, back, left), each
/// mapped to the full unit UV square (`u` along the face's first edge).
pub fn cube(size: DVec3) -> Mesh {
    let (w, h, d) = (size.x, size.y, size.z);
    let mut m = new_mesh();
    let base = [
        DVec3::new(0.0, 0.0, d),
        DVec3::new(w, 0.0, d),
        DVec3::new(w, 0.0, 0.0),
        DVec3::new(0.0, 0.0, 0.0),
    ];
    m.positions.extend(base);
    m.positions
        .extend(base.map(|p| p + DVec3::new(0.0, h, 0.0)));
    let uv = [(0., 0.), (1., 0.), (1., 1.), (0., 1.)].map(|(u, v)| DVec2::new(u, v));
    let with = |idx: [u32; 4], n: DVec3| -> Vec<(u32, DVec2, DVec3)> {
        (0..4).map(|k| (idx[k], uv[k], n)).collect()
    };
    face(&mut m, &with([3, 2, 1, 0], -DVec3::Y));
    face(&mut m, &with([4, 5, 6, 7], DVec3::Y));
    let outward = [DVec3::Z, DVec3::X, -DVec3::Z, -DVec3::X];
    for i in 0..4u32 {
        let j = (i + 1) % 4;
        face(&mut m, &with([i, j, j + 4, i + 4], outward[i as usize]));
    }
    m
}

/// `builtin:cube`: the unit cube.
pub fn builtin_cube() -> Mesh {
    cube(DVec3::ONE)
}

/// `primitiveCylinder`: `sides` (at least 3, default 16) quads around the
/// y axis filling the xz extent ([`ring`]), and two caps. Faces:
/// bottom, top, then the sides (u around from 0 to 1 starting just after
/// +x, v up).
/// Side normals are smooth (radial), cap normals flat.
pub fn cylinder(sides: usize, size: DVec3) -> Mesh {
    let n = sanitize(sides, 3);
    let mut m = new_mesh();
    let pts = ring(n, size.x, size.z);
    m.positions.extend(pts.iter().map(|p| p.pos));
    m.positions
        .extend(pts.iter().map(|p| p.pos + DVec3::new(0.0, size.y, 0.0)));
    let n32 = n as u32;
    // Bottom: the base ring reversed (p1 p0 pn-1 .. p2), as extrude does.
    let bottom: Vec<_> = (0..n)
        .map(|k| {
            let i = (n + 1 - k) % n;
            (i as u32, pts[i].uv(true), -DVec3::Y)
        })
        .collect();
    face(&mut m, &bottom);
    let top: Vec<_> = (0..n)
        .map(|k| (n32 + k as u32, pts[k].uv(false), DVec3::Y))
        .collect();
    face(&mut m, &top);
    for k in 0..n {
        let j = (k + 1) % n;
        let (u0, u1) = (k as f64 / n as f64, (k + 1) as f64 / n as f64);
        let (na, nb) = (pts[k].radial(), pts[j].radial());
        face(
            &mut m,
            &[
                (k as u32, DVec2::new(u0, 0.0), na),
                (j as u32, DVec2::new(u1, 0.0), nb),
                (n32 + j as u32, DVec2::new(u1, 1.0), nb),
                (n32 + k as u32, DVec2::new(u0, 1.0), na),
            ],
        );
    }
    m
}

/// `primitiveCone`: a base polygon of `sides` (at least 3, default 16)
/// filling the xz extent ([`ring`]), and `sides` triangles up to the apex
/// at the top centre. Faces: bottom, then the sides.
pub fn cone(sides: usize, size: DVec3) -> Mesh {
    let n = sanitize(sides, 3);
    let mut m = new_mesh();
    let pts = ring(n, size.x, size.z);
    m.positions.extend(pts.iter().map(|p| p.pos));
    let apex = n as u32;
    m.positions
        .push(DVec3::new(0.5 * size.x, size.y, 0.5 * size.z));
    let bottom: Vec<_> = (0..n)
        .map(|k| {
            let i = (n + 1 - k) % n;
            (i as u32, pts[i].uv(true), -DVec3::Y)
        })
        .collect();
    face(&mut m, &bottom);
    // Normal of the cone surface above the ring point at angle a.
    let (rx, rz) = (pts[0].radii.x, pts[0].radii.y);
    let slope = |a: f64| {
        let up = if size.y != 0.0 { 1.0 / size.y } else { 1.0 };
        DVec3::new(a.cos() / rx, up, -a.sin() / rz).normalize_or_zero()
    };
    for k in 0..n {
        let j = (k + 1) % n;
        let (u0, u1) = (k as f64 / n as f64, (k + 1) as f64 / n as f64);
        let (ak, aj) = (pts[k].angle, pts[j].angle);
        let mid = 0.5 * (ak + if j == 0 { aj + TAU } else { aj });
        face(
            &mut m,
            &[
                (k as u32, DVec2::new(u0, 0.0), slope(ak)),
                (j as u32, DVec2::new(u1, 0.0), slope(aj)),
                (apex, DVec2::new(0.5 * (u0 + u1), 1.0), slope(mid)),
            ],
        );
    }
    m
}

/// `primitiveSphere`: `sides` (at least 3, default 16) segments around the
/// y axis and `divisions` (at least 2, default 16) bands from pole to pole,
/// an ellipsoid filling `size`. Faces from the top down: triangles around
/// the north pole, quad bands, triangles around the south pole. UVs: u
/// around (from +x), v from 0 at the south pole to 1 at the north pole;
/// normals smooth.
pub fn sphere(sides: usize, divisions: usize, size: DVec3) -> Mesh {
    let n = sanitize(sides, 3);
    let d = sanitize(divisions, 2);
    let r = 0.5 * size;
    let mut m = new_mesh();
    let normal_at = |p: DVec3| {
        let q = p - r;
        DVec3::new(q.x / (r.x * r.x), q.y / (r.y * r.y), q.z / (r.z * r.z)).normalize_or_zero()
    };
    let north = 0u32;
    m.positions.push(DVec3::new(r.x, size.y, r.z));
    // Rings 1..d-1 from the top, n vertices each.
    for i in 1..d {
        let phi = PI * i as f64 / d as f64;
        for k in 0..n {
            let a = TAU * k as f64 / n as f64;
            m.positions.push(DVec3::new(
                r.x + r.x * phi.sin() * a.cos(),
                r.y + r.y * phi.cos(),
                r.z - r.z * phi.sin() * a.sin(),
            ));
        }
    }
    let south = m.positions.len() as u32;
    m.positions.push(DVec3::new(r.x, 0.0, r.z));
    let at = |i: usize, k: usize| 1 + ((i - 1) * n + k % n) as u32;
    let uv = |i: usize, k: usize| DVec2::new(k as f64 / n as f64, 1.0 - i as f64 / d as f64);
    let pos = m.positions.clone();
    let nrm = |v: u32| normal_at(pos[v as usize]);
    for k in 0..n {
        let (a, b) = (at(1, k), at(1, k + 1));
        face(
            &mut m,
            &[
                (a, uv(1, k), nrm(a)),
                (b, uv(1, k + 1), nrm(b)),
                (
                    north,
                    DVec2::new((k as f64 + 0.5) / n as f64, 1.0),
                    DVec3::Y,
                ),
            ],
        );
    }
    for i in 1..d - 1 {
        for k in 0..n {
            let (a, b) = (at(i + 1, k), at(i + 1, k + 1));
            let (c, e) = (at(i, k + 1), at(i, k));
            face(
                &mut m,
                &[
                    (a, uv(i + 1, k), nrm(a)),
                    (b, uv(i + 1, k + 1), nrm(b)),
                    (c, uv(i, k + 1), nrm(c)),
                    (e, uv(i, k), nrm(e)),
                ],
            );
        }
    }
    for k in 0..n {
        let (a, b) = (at(d - 1, k), at(d - 1, k + 1));
        face(
            &mut m,
            &[
                (b, uv(d - 1, k + 1), nrm(b)),
                (a, uv(d - 1, k), nrm(a)),
                (
                    south,
                    DVec2::new((k as f64 + 0.5) / n as f64, 0.0),
                    -DVec3::Y,
                ),
            ],
        );
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::{bounds, counts, face_area, face_normal, mesh_area, volume};
    use crate::topology::Topology;

    fn check_solid(m: &Mesh) {
        let topo = Topology::new(m);
        assert!(topo.is_closed(m));
        assert!(volume(m) > 0.0);
        assert_eq!(m.uvs[0].as_ref().unwrap().len(), m.corners.len());
        let normals = m.normals.as_ref().unwrap();
        // Corner normals agree with the face normals' side.
        for f in 0..m.faces.len() {
            let n = face_normal(m, f);
            for c in m.loop_corners(m.outer_loop(f)) {
                assert!(normals[c].dot(n) > 0.0, "face {f} corner {c}");
            }
        }
    }

    #[test]
    fn quad_and_disk() {
        let q = quad(10.0, 20.0);
        assert_eq!(face_area(&q, 0), 200.0);
        assert_eq!(face_normal(&q, 0), DVec3::Y);
        assert_eq!(bounds(&q), Some((DVec3::ZERO, DVec3::new(10.0, 0.0, 20.0))));
        // 16 sides half a step off the axes: the flat sides touch the
        // 2 x 2 square, the polygon's apothem is 1.
        let d = disk(16, 2.0, 2.0);
        assert_eq!(d.corners.len(), 16);
        let expected = 16.0 * (PI / 16.0).tan();
        assert!((face_area(&d, 0) - expected).abs() < 1e-12);
        assert_eq!(face_normal(&d, 0), DVec3::Y);
        assert_eq!(bounds(&d), Some((DVec3::ZERO, DVec3::new(2.0, 0.0, 2.0))));
        assert_eq!(disk(2, 1.0, 1.0).corners.len(), 3);
        // primitiveDisk(8, 10): an octagon of apothem 10, its first vertex at
        // 22.5 degrees from +x (counter-clockwise seen from above: -z).
        let d = disk(8, 20.0, 20.0);
        assert!((face_area(&d, 0) - 8.0 * 100.0 * (PI / 8.0).tan()).abs() < 1e-9);
        let p0 = d.positions[0] - DVec3::new(10.0, 0.0, 10.0);
        assert!((p0.z.atan2(p0.x) + PI / 8.0).abs() < 1e-12, "{p0}");
        // A triangle fills its box too: vertices at 60, 180 and 300 degrees.
        let t = disk(3, 3.0, 2.0);
        assert_eq!(bounds(&t), Some((DVec3::ZERO, DVec3::new(3.0, 0.0, 2.0))));
        assert!((face_area(&t, 0) - 3.0).abs() < 1e-12);
    }

    #[test]
    fn cube_is_closed_with_unit_uvs() {
        let m = cube(DVec3::new(10.0, 15.0, 20.0));
        check_solid(&m);
        assert!((volume(&m) - 3000.0).abs() < 1e-9);
        let c = counts(&m, &Topology::new(&m));
        assert_eq!((c.vertices, c.faces, c.edges), (8, 6, 12));
        let normals: Vec<DVec3> = (0..6).map(|f| face_normal(&m, f)).collect();
        assert_eq!(
            normals,
            vec![
                -DVec3::Y,
                DVec3::Y,
                DVec3::Z,
                DVec3::X,
                -DVec3::Z,
                -DVec3::X
            ]
        );
        let b = builtin_cube();
        assert_eq!(mesh_area(&b), 6.0);
        assert_eq!(
            &b.uvs[0].as_ref().unwrap()[8..12],
            &[DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y]
        );
    }

    #[test]
    fn cylinder_cone_sphere() {
        // primitiveCylinder(8, 10, 15): radius 10, height 15.
        let c = cylinder(8, DVec3::new(20.0, 15.0, 20.0));
        check_solid(&c);
        let base = 8.0 * 100.0 * (PI / 8.0).tan();
        assert!((volume(&c) - base * 15.0).abs() < 1e-9);
        assert_eq!(c.faces.len(), 10);
        assert_eq!(counts(&c, &Topology::new(&c)).vertices, 16);
        assert_eq!(
            bounds(&c),
            Some((DVec3::ZERO, DVec3::new(20.0, 15.0, 20.0)))
        );

        let k = cone(16, DVec3::new(2.0, 3.0, 2.0));
        check_solid(&k);
        let base = 16.0 * (PI / 16.0).tan();
        assert!((volume(&k) - base * 3.0 / 3.0).abs() < 1e-12);
        assert_eq!(bounds(&k), Some((DVec3::ZERO, DVec3::new(2.0, 3.0, 2.0))));
        assert_eq!(k.faces.len(), 17);

        // primitiveSphere(8, 4, 10).
        let s = sphere(8, 4, DVec3::splat(20.0));
        check_solid(&s);
        assert_eq!(s.faces.len(), 8 * 4);
        assert_eq!(counts(&s, &Topology::new(&s)).vertices, 8 * 3 + 2);
        let (lo, hi) = bounds(&s).unwrap();
        assert_eq!((lo.y, hi.y), (0.0, 20.0));
        // The default sphere is close to a ball's volume.
        let s = sphere(16, 16, DVec3::splat(2.0));
        check_solid(&s);
        let ball = 4.0 / 3.0 * PI;
        assert!(volume(&s) < ball && volume(&s) > 0.9 * ball);
    }
}
