//! Trim planes of the face component split (op_comp.md "Trim Planes",
//! attr_trim.md, op_trim.md): made at shared edges by `:`, applied by `i`,
//! the primitives and `trim()`, switched by `trim.vertical` (on) and
//! `trim.horizontal` (off).

use crate::comp_support::*;
use cga_engine::lot::rect;
use cga_geometry::DVec3;

/// op_comp.md's trim plane figures: a 15 x 10 x 2 beam centred on a side
/// of a 10-unit cube (x in [-2.5, 12.5], y in [0, 10], z in [-1, 1] in the
/// side's scope). The vertical planes at the side's vertical edges keep
/// x in [-z, 10 + z], the horizontal ones y in [-z, 10 + z]. Cuts are left
/// open, as CityEngine leaves them (compared on the Candler building's
/// ledges and cornices): the areas below count the beam's remaining faces.
#[test]
fn beam_on_a_cube_face() {
    let rules = |settings: &str| {
        format!(
            "Start --> s(10,10,10) primitiveCube() {settings} comp(f) {{ 5 : X }}\nX --> s(15,'1, 2) center(xyz) primitiveCube()\n"
        )
    };
    let lot = rect(20.0, 30.0);
    let area =
        |name: &str, settings: &str| run_on(name, &rules(settings), &lot, "Start").ok().area();
    // Front 12 x 10, back 8 x 10, top and bottom trapezoids of 20, no ends.
    assert!((area("beam_default", "") - 240.0).abs() < 1e-9);
    // Front 12 x 10, back 8 x 8, top and bottom 11 each (z >= 0 only).
    assert!((area("beam_h", "set(trim.horizontal, true)") - 206.0).abs() < 1e-9);
    // Uncut: 2 (15 x 10 + 15 x 2 + 10 x 2).
    assert!((area("beam_off", "set(trim.vertical, false)") - 400.0).abs() < 1e-9);
    // Horizontal only: front 150, back 120, top and bottom 15, ends 19 each.
    assert!(
        (area(
            "beam_h_only",
            "set(trim.vertical, false) set(trim.horizontal, true)"
        ) - 338.0)
            .abs()
            < 1e-9
    );
}

/// The trimmed beam is open where it was cut: every vertex lies in the
/// kept region, and the cut-off ends are gone.
#[test]
fn trimmed_beam_stays_in_the_kept_region() {
    let text = "Start --> s(10,10,10) primitiveCube() comp(f) { 5 : X }\nX --> s(15,'1, 2) center(xyz) primitiveCube()\n";
    let r = run_on("beam_region", text, &rect(20.0, 30.0), "Start").ok();
    assert_eq!(r.meshes.len(), 1);
    let m = &r.meshes[0];
    // Face 5 of the cube is its left side (x = 0, facing -x, first edge
    // from the back corner to the front): scope x = +z, z = -x, origin
    // (0, 0, -30) on the lot rect:20,30 (the cube spans z in [-30, -20]).
    for &c in &m.corners {
        let p = m.positions[c as usize];
        let (x, z) = (p.z + 30.0, -p.x);
        assert!(x >= -z - 1e-9 && x <= 10.0 + z + 1e-9, "{p:?}");
    }
}

/// A wide elliptic cylinder on each of the four sides of a cube: trimmed,
/// each piece stays in its side's wedge (between the diagonal planes
/// through the cube's vertical edges), so neighbours meet without
/// overlapping; switched off, nothing is cut.
#[test]
fn cylinders_on_four_sides_are_mitred() {
    let rules = |settings: &str| {
        format!(
            "Lot --> s(10,10,10) primitiveCube() {settings} comp(f) {{ side : Cyl }}\nCyl --> s('1.4, '1, 2) center(xz) primitiveCylinder()\n"
        )
    };
    let lot = rect(10.0, 10.0);
    let cut = run_on("cyl_trim", &rules(""), &lot, "Lot").ok();
    let uncut = run_on(
        "cyl_no_trim",
        &rules("set(trim.vertical, false)"),
        &lot,
        "Lot",
    )
    .ok();
    assert_eq!(cut.meshes.len(), 4);
    assert_eq!(uncut.meshes.len(), 4);
    let (a_cut, a_uncut) = (cut.area(), uncut.area());
    assert!(a_cut < 0.9 * a_uncut, "{a_cut} vs {a_uncut}");
    // The cube spans x in [0, 10], z in [-10, 0]; its centre (5, -5).
    let centre = DVec3::new(5.0, 0.0, -5.0);
    let mut out_of_wedge = 0;
    for (cut, whole) in [(&cut, false), (&uncut, true)] {
        for m in &cut.meshes {
            let (lo, hi) = bbox(m);
            let c = 0.5 * (lo + hi) - centre;
            let d = if c.x.abs() > c.z.abs() {
                DVec3::new(c.x.signum(), 0.0, 0.0)
            } else {
                DVec3::new(0.0, 0.0, c.z.signum())
            };
            let across = DVec3::new(-d.z, 0.0, d.x);
            for &ci in &m.corners {
                let u = m.positions[ci as usize] - centre;
                if u.dot(d) < u.dot(across).abs() - 1e-9 {
                    assert!(whole, "a trimmed vertex leaves its wedge: {u:?}");
                    out_of_wedge += 1;
                }
            }
        }
    }
    assert!(
        out_of_wedge > 0,
        "the uncut cylinders reach past the corners"
    );
}

#[test]
fn trim_planes_stay_in_place_and_are_inherited() {
    // Planes do not move with the scope: a cube moved past the front's
    // right corner (x - z > 20 everywhere) is cut away entirely.
    let text = "Lot --> extrude(10) comp(f) { front : t(30, 0, 0) s(5, 5, 5) primitiveCube() }\n";
    let r = run("trim_fixed", text).ok();
    assert!(r.meshes.is_empty());
    // Floors split from a front facade keep the facade's planes: a ledge
    // 1.4 times the facade's width (x in [-4, 24], z in [0, 1]) is cut back
    // to x in [-z, 20 + z] on each floor: front 22 x 3, back 20 x 3, top
    // and bottom 21 each.
    let text = "Lot --> extrude(9) comp(f) { front : split(y) { 3 : s('1.4, '1, 1) center(x) primitiveCube() }* }\n";
    let r = run("trim_floors", text).ok();
    assert_eq!(r.meshes.len(), 3);
    assert!((r.area() - 3.0 * 168.0).abs() < 1e-9, "{}", r.area());
}

#[test]
fn only_the_colon_operator_makes_trim_planes() {
    let text = "Lot --> extrude(9) comp(f) { front = s('1.4, '1, 1) center(x) primitiveCube() }\n";
    let r = run("trim_equals", text).ok();
    assert!((r.volume() - 28.0 * 9.0).abs() < 1e-9);
    // Edges and vertices have none, and a new split replaces the planes.
    let text =
        "Lot --> extrude(9) comp(f) { front : comp(e) { 0 : s('1, 1, 1) primitiveCube() } }\n";
    let r = run("trim_edges", text).ok();
    assert!((r.volume() - 20.0).abs() < 1e-9);
}

#[test]
fn trim_operation() {
    // op_trim.md: extruded geometry is not trimmed until trim() is called.
    // The box 15 x 10 x 0.5 on face 5 keeps x in [-z, 10 + z]: front
    // 11 x 10, back 10 x 10, top and bottom 5.25 each.
    let text = "Lot --> s(10,10,10) primitiveCube() comp(f) { 5 : Face(true) }\nFace(t) --> s('1.5, '1, 0.5) center(x) extrude(0.5) Trim(t)\nTrim(t) --> case t : trim() else : NoOp\nNoOp --> print(\"not trimmed\")\nNoTrim --> s(10,10,10) primitiveCube() comp(f) { 5 : Face(false) }\n";
    let lot = rect(10.0, 10.0);
    let r = run_on("trim_op", text, &lot, "Lot").ok();
    assert!((r.area() - 220.5).abs() < 1e-9, "{}", r.area());
    let r = run_on("trim_op_none", text, &lot, "NoTrim").ok();
    assert!((r.area() - 325.0).abs() < 1e-9, "{}", r.area());
}

#[test]
fn trim_attributes_read_back() {
    let text = "Lot --> print(trim.vertical + \" \" + trim.horizontal) set(trim.horizontal, true) set(trim.vertical, false) extrude(1) comp(f) { 0 : print(trim.vertical + \" \" + trim.horizontal) }\n";
    let r = run("trim_attrs", text).ok();
    assert_eq!(r.prints, vec!["true false", "false true"]);
}

/// Trim planes are only made for components whose operations can reach
/// `i`, a primitive or `trim()` (finding them needs the mesh's topology);
/// reached through rule calls and nested blocks, they still cut: the beam
/// of `beam_on_a_cube_face` placed two rules and a split away from the
/// component split has the same area, and a sibling component that only
/// colours itself does not disturb it.
#[test]
fn trim_planes_reach_through_rule_calls() {
    let text = "Start --> s(10,10,10) primitiveCube() comp(f) { 5 : A | 4 : color(1,0,0) Y. }\n\
                A --> split(y) { '1 : B }\n\
                B --> Beam\n\
                Beam --> s(15,'1, 2) center(xyz) primitiveCube()\n";
    let r = run_on("beam_through_rules", text, &rect(20.0, 30.0), "Start").ok();
    assert_eq!(r.meshes.len(), 2);
    // Front 12 x 10, back 8 x 10, top and bottom trapezoids of 20 (as in
    // `beam_on_a_cube_face`), plus the 10 x 10 face 4.
    assert!((r.area() - 340.0).abs() < 1e-9, "{}", r.area());
}
