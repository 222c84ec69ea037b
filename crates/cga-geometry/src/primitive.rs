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

/// Angle and ring point `k` of `n` on the ellipse inscribed in the
/// `width` × `depth` rectangle, counter-clockwise seen from above starting
/// at +x.
fn ring(k: usize, n: usize, width: f64, depth: f64) -> (f64, DVec3) {
    let a = TAU * k as f64 / n as f64;
    let (rx, rz) = (0.5 * width, 0.5 * depth);
    (a, DVec3::new(rx + rx * a.cos(), 0.0, rz - rz * a.sin()))
}

fn disk_uv(a: f64) -> DVec2 {
    DVec2::new(0.5 + 0.5 * a.cos(), 0.5 + 0.5 * a.sin())
}

/// `primitiveDisk`: a polygon of `n_vertices` (at least 3, default 16) on
/// the ellipse inscribed in `width` × `depth`, in the xz-plane facing +y.
/// UVs map the disk onto the unit square's inscribed circle.
pub fn disk(n_vertices: usize, width: f64, depth: f64) -> Mesh {
    let n = sanitize(n_vertices, 3);
    let mut m = new_mesh();
    let mut c = Vec::with_capacity(n);
    for k in 0..n {
        let (a, p) = ring(k, n, width, depth);
        m.positions.push(p);
        c.push((k as u32, disk_uv(a), DVec3::Y));
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
/// y axis on the ellipse inscribed in the xz extent, and two caps. Faces:
/// bottom, top, then the sides (u around from 0 to 1 starting at +x, v up).
/// Side normals are smooth (radial), cap normals flat.
pub fn cylinder(sides: usize, size: DVec3) -> Mesh {
    let n = sanitize(sides, 3);
    let mut m = new_mesh();
    let mut angles = Vec::with_capacity(n);
    for k in 0..n {
        let (a, p) = ring(k, n, size.x, size.z);
        m.positions.push(p);
        angles.push(a);
    }
    for k in 0..n {
        let p = m.positions[k];
        m.positions.push(p + DVec3::new(0.0, size.y, 0.0));
    }
    let n32 = n as u32;
    // Bottom: the base ring reversed (p1 p0 pn-1 .. p2), as extrude does.
    let bottom: Vec<_> = (0..n)
        .map(|k| {
            let i = (n + 1 - k) % n;
            (i as u32, disk_uv(-angles[i]), -DVec3::Y)
        })
        .collect();
    face(&mut m, &bottom);
    let top: Vec<_> = (0..n)
        .map(|k| (n32 + k as u32, disk_uv(angles[k]), DVec3::Y))
        .collect();
    face(&mut m, &top);
    let radial = |a: f64| {
        DVec3::new(a.cos() / (0.5 * size.x), 0.0, -a.sin() / (0.5 * size.z)).normalize_or_zero()
    };
    for k in 0..n {
        let j = (k + 1) % n;
        let (u0, u1) = (k as f64 / n as f64, (k + 1) as f64 / n as f64);
        let (na, nb) = (radial(angles[k]), radial(angles[j]));
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

/// `primitiveCone`: a base polygon of `sides` (at least 3, default 16) on
/// the ellipse inscribed in the xz extent, and `sides` triangles up to the
/// apex at the top centre. Faces: bottom, then the sides.
pub fn cone(sides: usize, size: DVec3) -> Mesh {
    let n = sanitize(sides, 3);
    let mut m = new_mesh();
    let mut angles = Vec::with_capacity(n);
    for k in 0..n {
        let (a, p) = ring(k, n, size.x, size.z);
        m.positions.push(p);
        angles.push(a);
    }
    let apex = n as u32;
    m.positions
        .push(DVec3::new(0.5 * size.x, size.y, 0.5 * size.z));
    let bottom: Vec<_> = (0..n)
        .map(|k| {
            let i = (n + 1 - k) % n;
            (i as u32, disk_uv(-angles[i]), -DVec3::Y)
        })
        .collect();
    face(&mut m, &bottom);
    // Normal of the cone surface above the ring point at angle a.
    let slope = |a: f64| {
        let up = if size.y != 0.0 { 1.0 / size.y } else { 1.0 };
        DVec3::new(a.cos() / (0.5 * size.x), up, -a.sin() / (0.5 * size.z)).normalize_or_zero()
    };
    for k in 0..n {
        let j = (k + 1) % n;
        let (u0, u1) = (k as f64 / n as f64, (k + 1) as f64 / n as f64);
        let mid = 0.5 * (angles[k] + if j == 0 { TAU } else { angles[j] });
        face(
            &mut m,
            &[
                (k as u32, DVec2::new(u0, 0.0), slope(angles[k])),
                (j as u32, DVec2::new(u1, 0.0), slope(angles[j])),
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
        let d = disk(16, 2.0, 2.0);
        assert_eq!(d.corners.len(), 16);
        let expected = 0.5 * 16.0 * (TAU / 16.0).sin();
        assert!((face_area(&d, 0) - expected).abs() < 1e-12);
        assert_eq!(face_normal(&d, 0), DVec3::Y);
        assert_eq!(disk(2, 1.0, 1.0).corners.len(), 3);
        // primitiveDisk(8, 10): radius 10, an octagon.
        let d = disk(8, 20.0, 20.0);
        assert!((face_area(&d, 0) - 0.5 * 8.0 * 100.0 * (TAU / 8.0).sin()).abs() < 1e-9);
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
        let base = 0.5 * 8.0 * 100.0 * (TAU / 8.0).sin();
        assert!((volume(&c) - base * 15.0).abs() < 1e-9);
        assert_eq!(c.faces.len(), 10);
        assert_eq!(counts(&c, &Topology::new(&c)).vertices, 16);
        assert_eq!(
            bounds(&c),
            Some((DVec3::ZERO, DVec3::new(20.0, 15.0, 20.0)))
        );

        let k = cone(16, DVec3::new(2.0, 3.0, 2.0));
        check_solid(&k);
        let base = 0.5 * 16.0 * (TAU / 16.0).sin();
        assert!((volume(&k) - base * 3.0 / 3.0).abs() < 1e-12);
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
