//! The uv split `split(u|v, uvSpace|unitSpace, uvSet) { ... }`: the
//! examples of the split reference page (facades and streets), nested
//! splits, closed geometry, parts and their texture coordinates.

use crate::texturing_common::*;
use cga_engine::split_layout::{layout, Size, SplitPattern};
use cga_geometry::{DVec2, Mesh};

fn uv(u: f64, v: f64) -> DVec2 {
    DVec2::new(u, v)
}

/// The 20 x 30 lot with u = x / 20 and v = (z + 30) / 30.
const PROJECTED: &str = "Lot --> setupProjection(0, scope.xz, '1, '1) projectUV(0)";

fn x_spans(out: &[Mesh]) -> Vec<(f64, f64)> {
    out.iter().map(|m| span(m, 0)).collect()
}

fn assert_spans(got: &[(f64, f64)], want: &[(f64, f64)]) {
    assert_eq!(got.len(), want.len(), "{got:?}");
    for (g, w) in got.iter().zip(want) {
        assert!(
            (g.0 - w.0).abs() < 1e-9 && (g.1 - w.1).abs() < 1e-9,
            "{got:?} != {want:?}"
        );
    }
}

#[test]
fn u_split_in_uv_space_is_independent_of_size() {
    // Reference: `split(u, uvSpace, 0) { 0.5 : X } *` splits at u = 0.5.
    for w in [20.0, 7.0] {
        let out = run(
            "uvspace",
            &format!(
                "{PROJECTED} texture(\"builtin:uvtest.png\") split(u, uvSpace, 0) {{ 0.5 : X }} *"
            ),
            &rect(w, 30.0),
        );
        assert_spans(&x_spans(&out.meshes), &[(0.0, w / 2.0), (w / 2.0, w)]);
        for m in &out.meshes {
            assert!(close(area(m), w * 15.0));
            // The pieces keep the projected coordinates.
            assert_uvs(m, 0, |p| uv(p.x / w, (p.z + 30.0) / 30.0));
        }
    }
}

#[test]
fn u_split_in_unit_space_depends_on_size() {
    // Reference: `split(u, unitSpace, 0) { 5 : X } *` cuts every 5 units.
    let out = run(
        "unitspace",
        &format!("{PROJECTED} split(u, unitSpace, 0) {{ 5 : X }} *"),
        &rect(20.0, 30.0),
    );
    assert_spans(
        &x_spans(&out.meshes),
        &[(0.0, 5.0), (5.0, 10.0), (10.0, 15.0), (15.0, 20.0)],
    );
    // With a texture of 4 units the u range is [0, 5]: in uv space 0.5 is 2 units.
    let out = run(
        "uvspace_tiled",
        "Lot --> setupProjection(0, scope.xz, 4, 4) projectUV(0) split(u, uvSpace, 0) { 0.5 : X }*",
        &rect(20.0, 30.0),
    );
    assert_eq!(out.meshes.len(), 10);
    assert_spans(&x_spans(&out.meshes)[..2], &[(0.0, 2.0), (2.0, 4.0)]);
}

#[test]
fn v_split_relative_floating_and_nil() {
    // v runs along z: z = -30 + 30 v.
    let out = run(
        "vsplit",
        &format!("{PROJECTED} split(v, unitSpace, 0) {{ '0.1 : X | ~1 : NIL | 6 : Y. }}"),
        &rect(20.0, 30.0),
    );
    assert_eq!(out.meshes.len(), 2);
    let z: Vec<(f64, f64)> = out.meshes.iter().map(|m| span(m, 2)).collect();
    assert!(close(z[0].0, -30.0) && close(z[0].1, -27.0), "{z:?}");
    assert!(close(z[1].0, -6.0) && close(z[1].1, 0.0), "{z:?}");
    assert!(close(area(&out.meshes[0]), 60.0));
    assert!(close(area(&out.meshes[1]), 120.0));
}

#[test]
fn nested_u_and_v_splits_index_and_total() {
    // insertAlongUV page: `split(u, uvSpace, 0) { '0.25 : split(v, uvSpace, 0) { '0.25 : ... }* }*`.
    let out = run(
        "nested",
        &format!(
            "{PROJECTED} split(u, uvSpace, 0) {{ '0.25 : print(split.index) split(v, uvSpace, 0) {{ '0.25 : X }}* }}*"
        ),
        &rect(20.0, 30.0),
    );
    assert_eq!(out.meshes.len(), 16);
    assert_eq!(out.prints, ["0", "1", "2", "3"]);
    for m in &out.meshes {
        assert!(close(area(m), 600.0 / 16.0));
        let (x0, x1) = span(m, 0);
        let (z0, z1) = span(m, 2);
        assert!(close(x1 - x0, 5.0) && close(z1 - z0, 7.5));
    }
}

#[test]
fn uv_set_from_a_constant_and_other_sets() {
    let out = run(
        "const_set",
        "const dirt = 2
         Lot --> setupProjection(dirt, scope.xz, '1, '1) projectUV(dirt)
                 split(u, uvSpace, dirt) { '0.5 : X }*",
        &rect(20.0, 30.0),
    );
    assert_spans(&x_spans(&out.meshes), &[(0.0, 10.0), (10.0, 20.0)]);
}

#[test]
fn part_scopes_fit_their_geometry() {
    let out = run(
        "scopes",
        &format!(
            "{PROJECTED} split(u, unitSpace, 0) {{ 6 : print(scope.sx + \",\" + scope.sz + \",\" + scope.tx) X }}*"
        ),
        &rect(20.0, 30.0),
    );
    assert_eq!(out.prints, ["6,30,0", "6,30,6", "6,30,12", "2,30,18"]);
}

#[test]
fn closed_box_is_cut_as_a_surface() {
    // Projected from above, the box's top and bottom and its faces along x
    // are cut at u = 0.5 (x = 10); the end walls are not crossed. The cut is
    // not capped: it follows the surface's parameterisation.
    let out = run(
        "box",
        "Lot --> extrude(10) setupProjection(0, scope.xz, '1, '1) projectUV(0) split(u, uvSpace, 0) { 0.5 : X }*",
        &rect(20.0, 30.0),
    );
    assert_eq!(out.meshes.len(), 2);
    for m in &out.meshes {
        assert_eq!(m.faces.len(), 5);
        assert!(close(area(m), 300.0 + 300.0 + 100.0 + 100.0 + 300.0));
    }
    assert_spans(&x_spans(&out.meshes), &[(0.0, 10.0), (10.0, 20.0)]);
}

#[test]
fn shape_without_uvs_is_left_unchanged() {
    let out = run(
        "no_uvs",
        "Lot --> split(u, uvSpace, 0) { 0.5 : NIL }*",
        &rect(20.0, 30.0),
    );
    assert_eq!(out.meshes.len(), 1);
    assert!(close(area(&out.meshes[0]), 600.0));
    assert!(out.warnings.iter().any(|w| w.message.contains("uv set 0")));
}

/// Derives `rules` on a street segment (see `street_asset`).
fn on_street(name: &str, rules: &str, front: f64, back0: f64, back1: f64, w: f64) -> Vec<Mesh> {
    let dir = project(name);
    street_asset(&dir, front, back0, back1, w);
    let out = run_in(&dir, rules, &rect(front, w));
    assert!(out.warnings.is_empty(), "{:?}", out.warnings);
    out.meshes
}

const BANDS: &str = r##"Lot --> i("street.obj") Street
Street --> split(u, unitSpace, 0) { ~10 : NIL | ~3 : color("#ff0000") X | ~10 : NIL }*"##;

#[test]
fn street_bands_in_unit_space() {
    // Reference: "Every 20 meters a 3 meter wide band is drawn across the
    // street." A 47 m segment takes the 23 m pattern twice, stretched to
    // 23.5 m: bands at [10.217, 13.283] and [33.717, 36.783].
    let meshes = on_street("street_straight", BANDS, 47.0, 0.0, 47.0, 8.0);
    let k = 47.0 / 46.0;
    assert_spans(
        &x_spans(&meshes),
        &[(10.0 * k, 13.0 * k), (33.0 * k, 36.0 * k)],
    );
    for m in &meshes {
        assert!(close(area(m), 3.0 * k * 8.0));
        assert_eq!(m.materials[0].color, [1.0, 0.0, 0.0]);
        // The band keeps the street's coordinates: u = x / 47.
        assert_uvs(m, 0, |p| uv(p.x / 47.0, -p.z / 8.0));
    }
}

#[test]
fn street_bands_follow_the_parameterisation_of_a_bent_segment() {
    // The second segment is a trapezoid: its front edge is 36 m long, its
    // back edge 30 m, both covering u in [0, 1]. The u lines join the points
    // of equal u on both edges, so a band is wider at the front than at the
    // back. Metres per u, averaged by area over the two triangles (36 m on
    // the front one of 144 m², 30 m on the back one of 120 m²), give the
    // length the pattern is laid out on.
    let meshes = on_street("street_bent", BANDS, 36.0, 3.0, 33.0, 8.0);
    let length = (36.0 * 144.0 + 30.0 * 120.0) / 264.0;
    let mut pattern = SplitPattern::new(true);
    for s in [10.0, 3.0, 10.0] {
        pattern.push(Size::Floating(s));
    }
    let bands: Vec<(f64, f64)> = layout(&pattern, length)
        .unwrap()
        .iter()
        .filter(|p| p.part == 1)
        .map(|p| (p.start / length, p.end / length))
        .collect();
    assert!(!bands.is_empty());
    assert_eq!(meshes.len(), bands.len());
    for (m, &(u0, u1)) in meshes.iter().zip(&bands) {
        let mut front = Vec::new();
        let mut back = Vec::new();
        for (p, t) in corners(m, 0) {
            if close(p.z, 0.0) {
                front.push(p.x);
                assert!(close(t.x * 36.0, p.x), "{p:?} {t:?}");
            } else {
                assert!(close(p.z, -8.0), "{p:?}");
                back.push(p.x);
                assert!(close(3.0 + t.x * 30.0, p.x), "{p:?} {t:?}");
            }
        }
        front.sort_by(f64::total_cmp);
        back.sort_by(f64::total_cmp);
        assert!(
            close(front[0], 36.0 * u0) && close(front[1], 36.0 * u1),
            "{front:?}"
        );
        assert!(
            close(back[0], 3.0 + 30.0 * u0) && close(back[1], 3.0 + 30.0 * u1),
            "{back:?}"
        );
        let expect = 0.5 * (36.0 + 30.0) * (u1 - u0) * 8.0;
        assert!(close(area(m), expect), "{} {expect}", area(m));
    }
}
