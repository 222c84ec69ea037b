//! The examples of the reference pages of the scope and pivot operations
//! (`alignScopeToAxes`, `alignScopeToGeometry`, `setPivot`, `rotateScope`,
//! `mirrorScope`, `resetGeometry`), the shape attributes `scope`, `pivot`
//! and `initialShape`, and the `convert` function with its printed numbers.

use crate::ops_common::*;
use cga_geometry::{DMat3, DVec3};

const EPS: f64 = 1e-9;

fn scopes(g: &Gen) -> Vec<ScopeLine> {
    g.prints().iter().map(|l| scope_line(l)).collect()
}

/// The corners of the box `origin + R * (size * {0,1}^3)`, R from Euler angles.
fn box_corners(origin: DVec3, angles: [f64; 3], size: DVec3) -> Vec<DVec3> {
    let m = euler_matrix(angles);
    let mut out = Vec::new();
    for i in 0..8 {
        let c = DVec3::new(
            (i & 1) as f64 * size.x,
            ((i >> 1) & 1) as f64 * size.y,
            ((i >> 2) & 1) as f64 * size.z,
        );
        out.push(origin + mat_mul(&m, c));
    }
    out
}

fn min_max(points: &[DVec3]) -> (DVec3, DVec3) {
    points.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    )
}

// ---------------------------------------------------------------------------
// alignScopeToAxes
// ---------------------------------------------------------------------------

const ALIGN_SCENE: &str = "t(5,0,4) s(8,24,8) r(10,20,30) i(\"builtin:cube\")";

/// op_alignScopeToAxes, initial scene and `alignScopeToAxes()` on
/// `rect:20,30`: the scope (t = (5,0,-26), r = (10,20,30), 8x24x8) holds
/// the box; aligning makes scope.t and scope.r zero, turns the pivot to the
/// world axes and puts it at the corner of the world-aligned bounding box;
/// the geometry stays.
#[test]
fn align_scope_to_axes_world() {
    let src = format!("A--> {ALIGN_SCENE} Scope alignScopeToAxes() Scope X\n{SCOPE_PRINTER}");
    let g = gen_with(&src, &Opts::default().start("A")).ok();
    let s = scopes(&g);
    assert_vec_near(s[0].t, [5.0, 0.0, -26.0], EPS);
    assert_vec_near(s[0].r, [10.0, 20.0, 30.0], EPS);
    assert_vec_near(s[0].s, [8.0, 24.0, 8.0], EPS);
    let corners = box_corners(
        DVec3::new(5.0, 0.0, -26.0),
        [10.0, 20.0, 30.0],
        DVec3::new(8.0, 24.0, 8.0),
    );
    let (lo, hi) = min_max(&corners);
    assert_vec_near(s[1].t, [0.0, 0.0, 0.0], EPS);
    assert_vec_near(s[1].r, [0.0, 0.0, 0.0], EPS);
    assert_vec_near(s[1].s, (hi - lo).to_array(), 1e-9);
    assert_vec_near(s[1].p, lo.to_array(), 1e-9);
    assert_vec_near(s[1].o, [0.0, 0.0, 0.0], EPS);
    // the geometry did not move
    let (glo, ghi) = g.bounds();
    assert_vec_near(glo, lo.to_array(), 1e-9);
    assert_vec_near(ghi, hi.to_array(), 1e-9);
}

/// op_alignScopeToAxes(y): only the y-axis is aligned (to the world's);
/// the x-axis is the old one projected to the xz-plane. Again scope.t and
/// scope.r are zero and the pivot is at the scope's origin.
#[test]
fn align_scope_to_axes_y() {
    let src = format!("A--> {ALIGN_SCENE} alignScopeToAxes(y) Scope X\n{SCOPE_PRINTER}");
    let g = gen_with(&src, &Opts::default().start("A")).ok();
    let s = scopes(&g)[0];
    assert_vec_near(s.t, [0.0, 0.0, 0.0], EPS);
    assert_vec_near(s.r, [0.0, 0.0, 0.0], EPS);
    let old_x = mat_mul(&euler_matrix([10.0, 20.0, 30.0]), DVec3::X);
    let angle = (-old_x.z).atan2(old_x.x).to_degrees();
    assert_vec_near(s.o, [0.0, angle, 0.0], 1e-9);
    // the size is the bounding box in the turned frame
    let corners = box_corners(
        DVec3::new(5.0, 0.0, -26.0),
        [10.0, 20.0, 30.0],
        DVec3::new(8.0, 24.0, 8.0),
    );
    let m = euler_matrix([0.0, angle, 0.0]);
    let local: Vec<DVec3> = corners
        .iter()
        .map(|c| {
            // transpose(m) * c
            DVec3::new(
                m[0][0] * c.x + m[1][0] * c.y + m[2][0] * c.z,
                m[0][1] * c.x + m[1][1] * c.y + m[2][1] * c.z,
                m[0][2] * c.x + m[1][2] * c.y + m[2][2] * c.z,
            )
        })
        .collect();
    let (lo, hi) = min_max(&local);
    assert_vec_near(s.s, (hi - lo).to_array(), 1e-9);
    assert_vec_near(s.p, mat_mul(&m, lo).to_array(), 1e-9);
}

/// op_alignScopeToAxes with `object.*` on a lot turned by 30 degrees: the
/// axes are the object's (the lot's first edge), pivot.o is zero relative to
/// the object; `world.xyz` gives pivot.o = (0,-30,0) relative to it.
#[test]
fn align_scope_to_object_and_world_axes() {
    let (s, c) = 30f64.to_radians().sin_cos();
    let rot = |x: f64, z: f64| DVec3::new(c * x + s * z, 0.0, -s * x + c * z);
    let lot = Opts::polygon(&[
        rot(0.0, 0.0),
        rot(10.0, 0.0),
        rot(10.0, -10.0),
        rot(0.0, -10.0),
    ]);
    let src = format!(
        "Lot --> extrude(5) r(0,45,0) [ alignScopeToAxes(object.xyz) Scope ] [ alignScopeToAxes(world.xyz) Scope ] \
         [ alignScopeToAxes() Scope ]\n{SCOPE_PRINTER}"
    );
    let g = gen_with(&src, &lot).ok();
    let p = scopes(&g);
    assert_vec_near(p[0].o, [0.0, 0.0, 0.0], EPS);
    assert_vec_near(p[0].r, [0.0, 0.0, 0.0], EPS);
    assert_vec_near(p[1].o, [0.0, -30.0, 0.0], 1e-9);
    assert_vec_near(p[2].o, [0.0, -30.0, 0.0], 1e-9);
    // The 10x5x10 block turned by 45 degrees in the object's frame: its
    // object-aligned box is 10*sqrt(2) wide and deep.
    let d = 10.0 * 2f64.sqrt();
    assert_vec_near(p[0].s, [d, 5.0, d], 1e-9);
}

// ---------------------------------------------------------------------------
// alignScopeToGeometry
// ---------------------------------------------------------------------------

/// op_alignScopeToGeometry, "Basic usage", on `bent2.obj` (face 1 is the
/// square rising at 45 degrees; its edge 0 goes from (10,0,-30) up to
/// (17.07,7.07,-30) once inserted at the lot's scope origin): the new
/// x-axis runs along the edge, the up-axis is the face normal
/// (-1,1,0)/sqrt(2), the scope is the geometry's bounding box in those axes
/// with the pivot at its origin, scope.t and scope.r zero.
#[test]
fn align_scope_to_geometry_face_and_edge() {
    let src = format!(
        "A--> i(\"bent2.obj\", yUp, keepSizeAndPosition) B\n\
         B--> [ alignScopeToGeometry(yUp, 1, 0) Scope ] [ alignScopeToGeometry(zUp, 1, 0) Scope ] \
              [ alignScopeToGeometry(yUp, -1, -4) Scope ] [ alignScopeToGeometry(yUp, 0, 1) Scope ]\n{SCOPE_PRINTER}"
    );
    let g = gen_with(&src, &Opts::default().start("A")).ok();
    let p = scopes(&g);
    let diag = 50f64.sqrt();
    // yUp: x = (1,1,0)/sqrt2, y = normal, z = (0,0,1): a turn of 45 about z
    assert_vec_near(p[0].o, [0.0, 0.0, 45.0], 1e-9);
    assert_vec_near(p[0].t, [0.0, 0.0, 0.0], EPS);
    assert_vec_near(p[0].r, [0.0, 0.0, 0.0], EPS);
    assert_vec_near(p[0].s, [10.0 + diag, diag, 10.0], 1e-9);
    // the box's origin: local (0, -7.07, -40) -> object (5, -5, -40)
    assert_vec_near(p[0].p, [5.0, -5.0, -40.0], 1e-9);
    // zUp: z = normal, y = normal x x = (0,0,-1)
    let axes_zup = {
        let x = DVec3::new(1.0, 1.0, 0.0).normalize();
        let z = DVec3::new(-1.0, 1.0, 0.0).normalize();
        DMat3::from_cols(x, z.cross(x), z)
    };
    let m = euler_matrix(p[1].o.to_array());
    for (k, col) in [axes_zup.x_axis, axes_zup.y_axis, axes_zup.z_axis]
        .into_iter()
        .enumerate()
    {
        let e = [DVec3::X, DVec3::Y, DVec3::Z][k];
        assert_vec_near(mat_mul(&m, e), col.to_array(), 1e-9);
    }
    assert_vec_near(p[1].s, [10.0 + diag, 10.0, diag], 1e-9);
    // negative indices are modulo-adjusted: face -1 is face 1, edge -4 is edge 0
    assert_all_near(&array(&g.prints()[2]), &array(&g.prints()[0]), 1e-9);
    // face 0 (flat), edge 1 runs along -z: x = (0,0,-1), y up
    assert_vec_near(p[3].o, [0.0, 90.0, 0.0], 1e-9);
}

/// op_alignScopeToGeometry, "Aligning to the lowest edge": with `any` and
/// `world.lowest` the scope's up-axis is the normal of a face holding the
/// lowest edge, here the flat face: y points up again after the scope was
/// turned upside down (rotateScope keeps the geometry).
#[test]
fn align_scope_to_geometry_lowest_edge() {
    let src = format!(
        "A--> i(\"bent2.obj\", yUp, keepSizeAndPosition) rotateScope(180,0,0) alignScopeToGeometry(yUp, any, world.lowest) Scope\n\
         {SCOPE_PRINTER}"
    );
    let g = gen_with(&src, &Opts::default().start("A")).ok();
    let s = scopes(&g)[0];
    let m = euler_matrix(s.o.to_array());
    assert_vec_near(mat_mul(&m, DVec3::Y), [0.0, 1.0, 0.0], 1e-9);
    assert!(s.s.y > 0.0);
    // largest / world.lowest faces are accepted too
    let src = "A--> i(\"bent2.obj\", yUp, keepSizeAndPosition) alignScopeToGeometry(zUp, largest, longest) \
               alignScopeToGeometry(yUp, world.lowest, 0) print(pivot.oy) NIL\n";
    let g = gen_with(src, &Opts::default().start("A")).ok();
    assert_eq!(g.prints(), ["0"]);
}

/// op_alignScopeToGeometry, page example with comp(f) on the cylinder.
#[test]
fn align_scope_to_geometry_after_comp() {
    // The page's scene is an inserted mesh of many faces; a sphere serves.
    let src = "A--> primitiveSphere() comp(f){ 25 : Faces }\nFaces --> alignScopeToGeometry(zUp, any, world.lowest) print(scope.sz) X\n";
    let g = gen_with(src, &Opts::default().start("A")).ok();
    assert_eq!(g.prints().len(), 1);
}

// ---------------------------------------------------------------------------
// setPivot
// ---------------------------------------------------------------------------

/// op_setPivot, "Visual Guide": for every axis map and corner the new
/// pivot is at a corner of the old scope, its axes are scope axes pointing
/// into the scope (right-handed), the scope has zero translation and
/// rotation and is the same box; in corner 0 the axes are the old ones
/// (xyz), or z, x, y (yzx), or y, z, x (zxy); with xyz the new y-axis is
/// always the old y-axis or its negative.
#[test]
fn set_pivot_corners() {
    // a 1x2x3 scope at (0,0,-30), axes = world
    let old_axes = [DVec3::X, DVec3::Y, DVec3::Z];
    let size = DVec3::new(1.0, 2.0, 3.0);
    let origin = DVec3::new(0.0, 0.0, -30.0);
    let mut seen = std::collections::HashSet::new();
    for map in ["xyz", "yzx", "zxy"] {
        for corner in 0..8 {
            let src = format!(
                "Lot --> extrude(3) s(1,2,3) setPivot({map}, {corner}) Scope print(geometry.volume) X\n{SCOPE_PRINTER}"
            );
            let g = gen(&src).ok();
            // Lot prints the volume before `Scope`, a generation later, runs.
            let p = g.prints();
            let s = scope_line(&p[1]);
            assert_vec_near(s.t, [0.0, 0.0, 0.0], EPS);
            assert_vec_near(s.r, [0.0, 0.0, 0.0], EPS);
            // the pivot is a corner of the old box
            let rel = s.p - origin;
            let bits: Vec<bool> = (0..3)
                .map(|i| {
                    let v = rel[i] / size[i];
                    assert!(
                        v.abs() < EPS || (v - 1.0).abs() < EPS,
                        "{map} {corner}: {rel:?}"
                    );
                    v > 0.5
                })
                .collect();
            seen.insert((map, bits.clone()));
            // axes: scope axes, pointing inside, right-handed
            let m = euler_matrix(s.o.to_array());
            let axes: Vec<DVec3> = [DVec3::X, DVec3::Y, DVec3::Z]
                .iter()
                .map(|e| mat_mul(&m, *e))
                .collect();
            let mut extent = DVec3::ZERO;
            for (k, a) in axes.iter().enumerate() {
                let i = (0..3)
                    .find(|&i| a.dot(old_axes[i]).abs() > 1.0 - 1e-9)
                    .expect("a scope axis");
                let inward = if bits[i] { -old_axes[i] } else { old_axes[i] };
                assert!(
                    a.dot(inward) > 0.0,
                    "{map} {corner}: axis {k} points inside"
                );
                extent[k] = size[i];
            }
            assert!(axes[0].cross(axes[1]).dot(axes[2]) > 0.0);
            assert_vec_near(s.s, extent.to_array(), EPS);
            if map == "xyz" {
                assert!(axes[1].dot(DVec3::Y).abs() > 1.0 - 1e-9);
            }
            if corner == 0 {
                let expected = match map {
                    "xyz" => [DVec3::X, DVec3::Y, DVec3::Z],
                    "yzx" => [DVec3::Z, DVec3::X, DVec3::Y],
                    _ => [DVec3::Y, DVec3::Z, DVec3::X],
                };
                for k in 0..3 {
                    assert_vec_near(axes[k], expected[k].to_array(), 1e-9);
                }
            }
            // the geometry stayed
            assert_near(numbers(&p[0])[0], 6.0, 1e-9);
            let (lo, hi) = g.bounds();
            assert_vec_near(lo, [0.0, 0.0, -30.0], 1e-9);
            assert_vec_near(hi, [1.0, 2.0, -27.0], 1e-9);
        }
    }
    assert_eq!(seen.len(), 24, "8 distinct corners per axis map");
}

// ---------------------------------------------------------------------------
// rotateScope, mirrorScope
// ---------------------------------------------------------------------------

/// op_rotateScope: the scope turns about the pivot axes, the geometry does
/// not; the scope becomes the geometry's bounding box in the new axes.
#[test]
fn rotate_scope_keeps_the_geometry() {
    let src = format!(
        "Lot --> extrude(10) rotateScope(0, 90, 0) Scope rotateScope(0, -45, 0) Scope X\n{SCOPE_PRINTER}"
    );
    let g = gen(&src).ok();
    let p = scopes(&g);
    assert_vec_near(p[0].r, [0.0, 90.0, 0.0], 1e-9);
    // x now along -z (30 long), z along +x (20 long)
    assert_vec_near(p[0].s, [30.0, 10.0, 20.0], 1e-9);
    assert_vec_near(p[0].t, [0.0, 0.0, 0.0], 1e-9);
    assert_vec_near(p[1].r, [0.0, 45.0, 0.0], 1e-9);
    let d = 50.0 * std::f64::consts::FRAC_1_SQRT_2;
    assert_vec_near(p[1].s, [d, 10.0, d], 1e-9);
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [0.0, 0.0, -30.0], 1e-9);
    assert_vec_near(hi, [20.0, 10.0, 0.0], 1e-9);
}

/// op_mirrorScope: the scope is mirrored, the geometry stays the same. The
/// mirrored scope is the same box seen from its far side: negative sizes
/// along the flipped axes, unchanged axes and scope.r. A following `r` of
/// zero changes nothing, and sizes set by `s` then mirror the geometry.
#[test]
fn mirror_scope_keeps_the_geometry() {
    let src = format!(
        "Lot --> extrude(3) s(1,2,3) mirrorScope(true, false, false) Scope r(0,0,0) Scope \
         mirrorScope(true, true, true) Scope X\n{SCOPE_PRINTER}"
    );
    let g = gen(&src).ok();
    let p = scopes(&g);
    assert_vec_near(p[0].t, [1.0, 0.0, -30.0], EPS);
    assert_vec_near(p[0].s, [-1.0, 2.0, 3.0], EPS);
    assert_vec_near(p[0].r, [0.0, 0.0, 0.0], EPS);
    assert_all_near(&array(&g.prints()[1]), &array(&g.prints()[0]), EPS);
    assert_vec_near(p[2].t, [0.0, 2.0, -27.0], EPS);
    assert_vec_near(p[2].s, [1.0, -2.0, -3.0], EPS);
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [0.0, 0.0, -30.0], 1e-9);
    assert_vec_near(hi, [1.0, 2.0, -27.0], 1e-9);
    // an asset inserted into the mirrored scope is mirrored
    let src = "Lot --> extrude(3) s(1,2,3) mirrorScope(true, false, false) i(\"bent2.obj\") X\n";
    let a = gen(src).ok();
    let b = gen("Lot --> extrude(3) s(1,2,3) i(\"bent2.obj\") X\n").ok();
    let (alo, ahi) = a.bounds();
    let (blo, bhi) = b.bounds();
    assert_vec_near(alo, blo.to_array(), 1e-9);
    assert_vec_near(ahi, bhi.to_array(), 1e-9);
    // bent2's high edge is at its far x end; mirrored, at the near end
    let high_x = |g: &Gen| {
        let m = &g.meshes()[0];
        m.positions
            .iter()
            .filter(|p| p.y > 1.0)
            .map(|p| p.x)
            .fold(f64::NAN, f64::max)
    };
    assert_near(high_x(&b), 1.0, 1e-9);
    assert_near(high_x(&a), 0.0, 1e-9);
}

// ---------------------------------------------------------------------------
// resetGeometry
// ---------------------------------------------------------------------------

/// op_resetGeometry: the geometry, scope and pivot go back to the initial
/// shape's; shape attributes (the colour) and generic attributes stay.
#[test]
fn reset_geometry_keeps_attributes() {
    let src = format!(
        "attr level = 0\nLot --> color(\"#FFAA00\") set(level, 3) extrude(10) t(1,2,3) r(0,30,0) resetGeometry() Scope \
         print(level) print(geometry.area) X\n{SCOPE_PRINTER}"
    );
    let g = gen(&src).ok();
    let p = g.prints();
    assert_eq!(p[..2], ["3", "600"]);
    let s = scope_line(&p[2]);
    assert_vec_near(s.t, [0.0, 0.0, -30.0], EPS);
    assert_vec_near(s.r, [0.0, 0.0, 0.0], EPS);
    assert_vec_near(s.s, [20.0, 0.0, 30.0], EPS);
    assert_eq!(rgb255(g.face_materials()[0]), [0xff, 0xaa, 0x00]);
}

/// op_resetGeometry, "Recursive setbacks": each setback is applied to the
/// initial shape again.
#[test]
fn reset_geometry_recursive_setbacks() {
    let src = "const maxGFA      = 5000\nconst floorHeight = 10\n\
               Example -->\n    color(\"#FFAA00\")\n    SetBackRec(0, 0)\n\
               SetBackRec(sumGFA, iFloor) -->\n    resetGeometry()\n    setback(iFloor*3) {\n        all : NIL |\n        remainder : Floor(sumGFA + geometry.area, iFloor)\n    }\n\
               Floor(sumGFA, iFloor) -->\n    CreateFloor(sumGFA, iFloor)\n    SetBackRec(sumGFA, iFloor + 1)\n\
               CreateFloor(sumGFA, iFloor) -->\n    set(material.opacity,\n        case sumGFA > maxGFA : 0.1 else : 1)\n    t(0, iFloor*floorHeight, 0)\n    extrude(floorHeight)\n";
    let g = gen_with(src, &Opts::rect(60.0, 40.0).start("Example")).ok();
    // Floors shrink by 3 m per side and level until nothing is left: 60 x
    // 40, 54 x 34, ..., 24 x 4, then a setback of 21 m leaves no remainder.
    assert_eq!(g.meshes().len(), 7);
    let mut sum = 0.0;
    for (k, m) in g.meshes().iter().enumerate() {
        let (w, d) = (60.0 - 6.0 * k as f64, 40.0 - 6.0 * k as f64);
        let (lo, hi) = mesh_bounds(m);
        assert_vec_near(hi - lo, [w, 10.0, d], 1e-9);
        assert_near(lo.y, 10.0 * k as f64, 1e-9);
        sum += w * d;
        // The floors above the maximal floor area are transparent.
        let opacity = m.materials[m.faces[0].material as usize].opacity;
        assert_near(opacity, if sum > 5000.0 { 0.1 } else { 1.0 }, 1e-12);
    }
}

// ---------------------------------------------------------------------------
// scope, pivot, initialShape attributes
// ---------------------------------------------------------------------------

/// attr_scope, the examples on `rect:20,30`.
#[test]
fn scope_attribute_examples() {
    let g = gen_with(
        "Wall --> print(scope.sx)\n         s(10, '1, '1)\n         print(scope.sx)\n",
        &Opts::default().start("Wall"),
    )
    .ok();
    assert_eq!(g.prints(), ["20", "10"]);
    let g = gen_with(
        "Wall --> set(scope.rz, 87.3) print(scope.rz)\n",
        &Opts::default().start("Wall"),
    )
    .ok();
    assert_eq!(g.prints(), ["87.3"]);
    let g = gen_with(
        "Wall --> print(scope.ty)\n         t(0, 10, 0)\n         print(scope.ty)\n",
        &Opts::default().start("Wall"),
    )
    .ok();
    assert_eq!(g.prints(), ["0", "10"]);
}

/// attr_scope: the width of the front facade (the lot's first edge, 20 m).
#[test]
fn scope_attribute_front_facade() {
    let g = gen("Lot --> extrude(10)\n        comp(f) {front: print(scope.sx) FrontFacade}\n").ok();
    assert_eq!(g.prints(), ["20"]);
}

/// attr_scope: scope.elevation is the world y of the scope origin.
#[test]
fn scope_elevation() {
    let lot = Opts::polygon(&[
        DVec3::new(0.0, 5.0, 0.0),
        DVec3::new(10.0, 5.0, 0.0),
        DVec3::new(10.0, 5.0, -10.0),
        DVec3::new(0.0, 5.0, -10.0),
    ]);
    let g = gen_with(
        "Lot --> print(scope.elevation) t(0,3,0) print(scope.elevation) print(scope.ty)\n",
        &lot,
    )
    .ok();
    assert_eq!(g.prints(), ["5", "8", "3"]);
}

/// attr_pivot: pivot.p and pivot.o are relative to initialShape.origin; the
/// initial pivot is that origin. On a lot turned by 30 degrees, aligning to
/// the world axes turns the pivot by -30 degrees relative to the object.
#[test]
fn pivot_attribute() {
    let (s, c) = 30f64.to_radians().sin_cos();
    let base = DVec3::new(3.0, 0.0, 4.0);
    let rot = |x: f64, z: f64| base + DVec3::new(c * x + s * z, 0.0, -s * x + c * z);
    let lot = Opts::polygon(&[
        rot(0.0, 0.0),
        rot(10.0, 0.0),
        rot(10.0, -10.0),
        rot(0.0, -10.0),
    ]);
    let src = "Lot --> print([pivot.px, pivot.py, pivot.pz, pivot.ox, pivot.oy, pivot.oz]) \
               print([initialShape.origin.px, initialShape.origin.py, initialShape.origin.pz]) \
               print([initialShape.origin.ox, initialShape.origin.oy, initialShape.origin.oz]) \
               extrude(2) alignScopeToAxes() print([pivot.ox, pivot.oy, pivot.oz])\n";
    let g = gen_with(src, &lot).ok();
    let p = g.prints();
    assert_all_near(&array(&p[0]), &[0.0; 6], EPS);
    assert_all_near(&array(&p[1]), &[3.0, 0.0, 4.0], 1e-9);
    assert_all_near(&array(&p[2]), &[0.0, 30.0, 0.0], 1e-9);
    assert_all_near(&array(&p[3]), &[0.0, -30.0, 0.0], 1e-9);
}

/// attr_pivot: set(pivot.*) moves the pivot; the scope stays in place, so
/// its translation relative to the pivot changes.
#[test]
fn set_pivot_attributes() {
    let src = "Lot --> set(pivot.px, 4) print([pivot.px, scope.tx, scope.tz]) set(pivot.oy, 90) \
               print([pivot.oy, scope.ry]) print(convert(scope, world, pos, [0,0,0])) X\n";
    let g = gen(src).ok();
    let p = g.prints();
    assert_all_near(&array(&p[0]), &[4.0, -4.0, -30.0], EPS);
    assert_all_near(&array(&p[1]), &[90.0, -90.0], 1e-9);
    assert_all_near(&array(&p[2]), &[0.0, 0.0, -30.0], 1e-9);
}

/// attr_initialShape, example: the name and the start rule.
#[test]
fn initial_shape_attribute() {
    let g = gen_with(
        "Wall --> print(\"initialShape.name: \" + initialShape.name) \n         print(\"initialShape.startRule: \" + initialShape.startRule)\n",
        &Opts::default().start("Wall"),
    )
    .ok();
    assert_eq!(
        g.prints(),
        [
            "initialShape.name: rect 20x30",
            "initialShape.startRule: Wall"
        ]
    );
}

// ---------------------------------------------------------------------------
// convert
// ---------------------------------------------------------------------------

/// func_convert, the page's example with its printed numbers. The page's
/// lot is not given, but the numbers fix it: scope.t relative to the pivot
/// ends at (0.4, 0, -0.6) after t('0.2, 0, '0.7), so the lot is 2 x 2 with
/// its scope at (0,0,-2) like `rect:2,2`; the scope's world orientation is
/// (-10, 23.46, 0) after r(-10, 70, 0), so the lot is turned by -46.54
/// degrees about y; and its pivot sits where the scope origin lands at the
/// printed world position. With that lot the page's prints come out (to the
/// float precision CityEngine printed them with).
#[test]
fn convert_page_example() {
    let theta: f64 = 23.45978546142578 - 70.0;
    let (s, c) = theta.to_radians().sin_cos();
    let rot = |v: DVec3| DVec3::new(c * v.x + s * v.z, v.y, -s * v.x + c * v.z);
    let printed = DVec3::new(1.0452611297369, 0.0, 2.183733612298965);
    let o = printed - rot(DVec3::new(0.4, 0.0, -0.6));
    let lot = Opts::polygon(&[
        o,
        o + rot(DVec3::new(2.0, 0.0, 0.0)),
        o + rot(DVec3::new(2.0, 0.0, -2.0)),
        o + rot(DVec3::new(0.0, 0.0, -2.0)),
    ]);
    let src = "Init -->\n   extrude(3)\n   t('0.2, 0, '0.7)\n   s('0.5, '1, '0.5)\n   r(-10, 70, 0)\n\
               \n   // position of scope origin in world coordinates\n   print(convert(scope, world, pos, [0,0,0]))\n\
               \n   // x-position of scope origin in world coordinates\n   print(convert(x, scope, world, pos, 0, 0, 0))\n\
               \n   // position of scope origin in pivot coordinates\n   print(convert(scope, pivot, pos, [0,0,0]))\n\
               \n   // orientation of scope origin relative to world axes\n   print(convert(scope, world, orient, [0,0,0]))\n\
               \n   // position of scope center in world coordinates\n   print(convert(scope, world, pos,\n                 [scope.sx/2,scope.sy/2,scope.sz/2]))\n";
    let g = gen_with(src, &lot.start("Init")).ok();
    let p = g.prints();
    assert_eq!(p.len(), 5);
    // CityEngine computes in single precision: its 0.3999996185302735 is 0.4.
    let tol = 1e-6;
    assert_all_near(
        &array(&p[0]),
        &[1.0452611297369, 0.0, 2.183733612298965],
        tol,
    );
    assert_near(numbers(&p[1])[0], 1.0452611297369, tol);
    assert_all_near(
        &array(&p[2]),
        &[0.3999996185302735, 0.0, -0.6000001430511476],
        tol,
    );
    assert_all_near(&array(&p[3]), &[-10.0, 23.45978546142578, 0.0], tol);
    // the centre: origin + R * (0.5, 1.5, 0.5) with the world angles
    let m = euler_matrix([-10.0, 23.45978546142578, 0.0]);
    let center = printed + mat_mul(&m, DVec3::new(0.5, 1.5, 0.5));
    assert_all_near(&array(&p[4]), &center.to_array(), tol);
}

/// func_convert: converting there and back gives the input; positions and
/// orientations between all four systems agree with each other.
#[test]
fn convert_round_trips() {
    let src = "Lot --> extrude(4) t(1,2,3) r(10,20,30) setPivot(yzx, 3) r(5,0,0) \
               print(convert(world, scope, pos, convert(scope, world, pos, [1,2,3]))) \
               print(convert(object, pivot, orient, convert(pivot, object, orient, [10,20,30]))) \
               print(convert(pivot, world, pos, convert(scope, pivot, pos, [0,0,0])) .- convert(scope, world, pos, [0,0,0])) \
               print(convert(y, world, object, pos, 1, 2, 3))\n";
    let g = gen(src).ok();
    let p = g.prints();
    assert_all_near(&array(&p[0]), &[1.0, 2.0, 3.0], 1e-9);
    assert_all_near(&array(&p[1]), &[10.0, 20.0, 30.0], 1e-9);
    assert_all_near(&array(&p[2]), &[0.0, 0.0, 0.0], 1e-9);
    // rect lots: object = world
    assert_eq!(p[3], "2");
}

/// op_alignScopeToGeometry: "xUp not supported yet": an error, not a
/// silent yUp.
#[test]
fn align_scope_to_geometry_x_up_is_an_error() {
    let g = gen("Lot --> extrude(2) alignScopeToGeometry(xUp, 0, 0) X\n");
    assert_eq!(g.errors.len(), 1);
    assert!(g.errors[0].message.contains("xUp"));
}
