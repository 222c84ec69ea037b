//! `splitArea` through the interpreter: every example of CGA's `splitArea`
//! reference page (rule files under `tests/rules/split_area/`, kept as the page
//! writes them) run on lots built here, asserting the areas the rules print.
//!
//! The page's figures show lots whose coordinates it does not give, so the
//! lots are made up to have the same character: a concave lot (relative,
//! repeating, nested and adjust examples), a lot with a hole wide enough that
//! the 600 part spans it and comes out in two pieces (floating / absolute
//! example), and an irregular street block of 6200 (block example: 775 per
//! lot, the middle of the page's colour ramp 243..1255).

use std::path::PathBuf;

use cga_engine::assets::Assets;
use cga_engine::lot::Lot;
use cga_engine::{generate_lot, GenerateOptions, LotOutput, Program};
use cga_geometry::measure::{bounds, mesh_area};
use cga_geometry::{DVec3, Mesh};
use cga_syntax::diagnostic::Severity;
use cga_syntax::SourceMap;
use cga_value::Value;

fn rule_file(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/rules/split_area")
        .join(name)
}

fn load(name: &str) -> (Program, Assets) {
    let mut sources = SourceMap::new();
    let loaded = cga_engine::load(&cga_world::DiskWorld, &rule_file(name), &mut sources);
    let errors: Vec<_> = loaded
        .diagnostics
        .iter()
        .filter(|d| d.severity == Severity::Error)
        .map(|d| d.message.clone())
        .collect();
    assert!(errors.is_empty(), "{name}: {errors:?}");
    let assets = Assets::on_disk(&sources);
    (loaded.usable().expect("program"), assets)
}

/// Derives `lot` with rule `start` of rule file `name`.
fn run_with(name: &str, start: &str, lot: &Lot, attrs: &[(&str, Value)]) -> LotOutput {
    let (program, assets) = load(name);
    let rule = program.start_rule(Some(start)).unwrap();
    let mut options = GenerateOptions::default();
    for (attr, v) in attrs {
        let id = program.main_attr(attr).expect("attribute");
        options.attrs.push((id, v.clone()));
    }
    let (out, err) = generate_lot(&program, &assets, rule, lot, 0, &options);
    assert!(err.is_none(), "{name} {start}: {err:?}");
    out
}

fn run(name: &str, start: &str, lot: &Lot) -> LotOutput {
    run_with(name, start, lot, &[])
}

/// A lot from `(x, north)` points (x east, y up, north = -z as GeoJSON lots
/// are), counter-clockwise seen from above; holes clockwise.
fn lot(outer: &[(f64, f64)], holes: &[&[(f64, f64)]]) -> Lot {
    let mut mesh = Mesh::new();
    let mut loops = Vec::new();
    for ring in std::iter::once(outer).chain(holes.iter().copied()) {
        let base = mesh.positions.len() as u32;
        mesh.positions
            .extend(ring.iter().map(|&(x, n)| DVec3::new(x, 0.0, -n)));
        loops.push((base..base + ring.len() as u32).collect::<Vec<u32>>());
    }
    let refs: Vec<&[u32]> = loops.iter().map(|l| l.as_slice()).collect();
    mesh.add_face(&refs, 0);
    Lot {
        name: "test lot".to_string(),
        mesh,
        attrs: Vec::new(),
        geo_origin: None,
    }
}

/// Concave (a notch at (30, 22)), area 1272.
const CONCAVE: &[(f64, f64)] = &[
    (0.0, 0.0),
    (40.0, 0.0),
    (46.0, 18.0),
    (30.0, 22.0),
    (26.0, 40.0),
    (4.0, 34.0),
];
const CONCAVE_AREA: f64 = 1272.0;

/// Outer 3156 minus a hole of 42 x 14 = 588: 2568.
const HOLED: &[(f64, f64)] = &[(0.0, 0.0), (80.0, 0.0), (84.0, 36.0), (-2.0, 40.0)];
const HOLE: &[(f64, f64)] = &[(20.0, 12.0), (20.0, 26.0), (62.0, 26.0), (62.0, 12.0)];
const HOLED_AREA: f64 = 2568.0;

/// An irregular street block of 6200, its first edge not along a world axis.
const BLOCK: &[(f64, f64)] = &[
    (0.0, 0.0),
    (95.0, -4.0),
    (100.0, 30.0),
    (70.0, 62.0),
    (10.0, 70.0),
    (-6.0, 35.0),
];
const BLOCK_AREA: f64 = 6200.0;

/// The `area(X) = v` lines of the colour rules, as (X, v).
fn colour_areas(out: &LotOutput) -> Vec<(String, f64)> {
    out.prints
        .iter()
        .filter_map(|p| {
            let rest = p.strip_prefix("area(")?;
            let (label, value) = rest.split_once(") = ")?;
            Some((label.to_string(), value.parse().unwrap()))
        })
        .collect()
}

fn total_area(out: &LotOutput) -> f64 {
    out.prints
        .iter()
        .find_map(|p| p.strip_prefix("total area = "))
        .expect("total area printed")
        .parse()
        .unwrap()
}

fn assert_rel(got: f64, want: f64, what: &str) {
    assert!(
        (got - want).abs() <= 1e-9 * want.abs(),
        "{what}: {got} instead of {want}"
    );
}

/// Asserts the printed colour areas, in order.
fn assert_areas(out: &LotOutput, want: &[(&str, f64)]) {
    let got = colour_areas(out);
    let labels: Vec<&str> = got.iter().map(|(l, _)| l.as_str()).collect();
    let want_labels: Vec<&str> = want.iter().map(|(l, _)| *l).collect();
    assert_eq!(labels, want_labels);
    for ((label, g), (_, w)) in got.iter().zip(want) {
        assert_rel(*g, *w, label);
    }
}

fn no_warnings(out: &LotOutput) {
    assert!(out.warnings.is_empty(), "{:?}", out.warnings);
}

#[test]
fn relative_split() {
    let out = run("relative.cga", "Lot", &lot(CONCAVE, &[]));
    assert_eq!(total_area(&out), CONCAVE_AREA);
    assert_areas(
        &out,
        &[("G", 0.7 * CONCAVE_AREA), ("Y", 0.3 * CONCAVE_AREA)],
    );
    no_warnings(&out);
    // The cut is perpendicular to the scope's x (world x here): green ends
    // where yellow starts.
    let (g, y) = (&out.meshes[0], &out.meshes[1]);
    let (g_lo, g_hi) = bounds(g).unwrap();
    let (y_lo, y_hi) = bounds(y).unwrap();
    assert_eq!(g_lo.x, 0.0);
    assert!((g_hi.x - y_lo.x).abs() < 1e-9);
    assert_eq!(y_hi.x, 46.0);
    assert_rel(mesh_area(g), 0.7 * CONCAVE_AREA, "green mesh");
}

#[test]
fn repeating_split_gives_five_equal_parts() {
    let out = run("repeat.cga", "Lot", &lot(CONCAVE, &[]));
    assert_eq!(total_area(&out), CONCAVE_AREA);
    let fifth = 0.2 * CONCAVE_AREA;
    assert_areas(
        &out,
        &[
            ("R", fifth),
            ("Y", fifth),
            ("G", fifth),
            ("C", fifth),
            ("B", fifth),
        ],
    );
    no_warnings(&out);
}

#[test]
fn repeating_split_of_0_3_gives_30_30_30_10() {
    let out = run("repeat_03.cga", "Lot", &lot(CONCAVE, &[]));
    let a = CONCAVE_AREA;
    assert_areas(
        &out,
        &[
            ("R", 0.3 * a),
            ("Y", 0.3 * a),
            ("G", 0.3 * a),
            ("C", 0.1 * a),
        ],
    );
}

#[test]
fn floating_and_absolute_areas_around_a_hole() {
    let out = run("floating_absolute.cga", "Lot", &lot(HOLED, &[HOLE]));
    assert_eq!(total_area(&out), HOLED_AREA);
    let side = (HOLED_AREA - 600.0) / 2.0;
    assert_areas(&out, &[("G", side), ("Y", 600.0), ("B", side)]);
    no_warnings(&out);
    // The yellow part lies across the hole: two pieces, above and below it.
    assert_eq!(out.meshes[1].faces.len(), 2);
    let (lo, hi) = bounds(&out.meshes[1]).unwrap();
    assert!(lo.x > 20.0 && hi.x < 62.0, "{lo} {hi}");
    assert_eq!(out.meshes[0].faces.len(), 1);
    assert_eq!(out.meshes[2].faces.len(), 1);
}

#[test]
fn nested_split_gives_six_equal_parts() {
    let out = run("nested.cga", "Lot", &lot(CONCAVE, &[]));
    let sixth = CONCAVE_AREA / 6.0;
    assert_areas(
        &out,
        &[
            ("R", sixth),
            ("Y", sixth),
            ("G", sixth),
            ("C", sixth),
            ("B", sixth),
            ("M", sixth),
        ],
    );
    no_warnings(&out);
}

/// `leaf tx tz sx sz area` lines of the adjust example.
fn leaves(out: &LotOutput) -> Vec<[f64; 5]> {
    out.prints
        .iter()
        .filter_map(|p| p.strip_prefix("leaf "))
        .map(|p| {
            let v: Vec<f64> = p.split(' ').map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2], v[3], v[4]]
        })
        .collect()
}

#[test]
fn adjust_and_no_adjust_scopes() {
    let l = lot(CONCAVE, &[]);
    // The lot's scope: x in [0, 46], z in [-40, 0] (scope z points south).
    for start in ["SplitAdjust", "SplitNoAdjust"] {
        let all = leaves(&run("adjust.cga", start, &l));
        assert_eq!(all.len(), 25, "{start}");
        for leaf in &all {
            assert_rel(leaf[4], 0.04 * CONCAVE_AREA, start);
        }
    }

    // noAdjust: five columns tiling x in [0, 46], each cut into five rows
    // tiling the whole depth.
    let tiles = leaves(&run("adjust.cga", "SplitNoAdjust", &l));
    let mut x = 0.0;
    for column in tiles.chunks(5) {
        assert!((column[0][0] - x).abs() < 1e-9);
        let mut z = -40.0;
        for leaf in column {
            assert_eq!((leaf[0], leaf[2]), (column[0][0], column[0][2]));
            assert!((leaf[1] - z).abs() < 1e-9, "{leaf:?} starts at {z}");
            z = leaf[1] + leaf[3];
        }
        assert!(z.abs() < 1e-9);
        x = column[0][0] + column[0][2];
    }
    assert!((x - 46.0).abs() < 1e-9);

    // adjust: every scope is the bounding box of its part, inside the lot's
    // scope, and smaller than the noAdjust one at least somewhere.
    let adjusted = leaves(&run("adjust.cga", "SplitAdjust", &l));
    let mut smaller = 0;
    for (a, n) in adjusted.iter().zip(&tiles) {
        assert!(a[0] >= n[0] - 1e-9 && a[0] + a[2] <= n[0] + n[2] + 1e-9);
        assert!(a[1] >= -40.0 - 1e-9 && a[1] + a[3] <= 1e-9);
        assert!(a[2] * a[3] >= a[4] - 1e-9);
        if a[2] * a[3] < n[2] * n[3] - 1e-6 {
            smaller += 1;
        }
    }
    assert!(smaller > 0);
}

#[test]
fn block_divided_into_equal_lots_with_split_area() {
    let out = run("block.cga", "Lot", &lot(BLOCK, &[]));
    let areas = colour_areas(&out);
    assert_eq!(areas.len(), 8);
    for (label, a) in &areas {
        assert_eq!(label, "A");
        assert_rel(*a, BLOCK_AREA / 8.0, "lot");
    }
    no_warnings(&out);
}

#[test]
fn block_divided_with_split_gives_unequal_lots() {
    let out = run("block.cga", "Lot2", &lot(BLOCK, &[]));
    let areas: Vec<f64> = colour_areas(&out).into_iter().map(|(_, a)| a).collect();
    assert_eq!(areas.len(), 8);
    assert_rel(areas.iter().sum(), BLOCK_AREA, "sum");
    let max = areas.iter().cloned().fold(f64::MIN, f64::max);
    let min = areas.iter().cloned().fold(f64::MAX, f64::min);
    // On this block split's halves of the scope differ by far more than
    // rounding: the corner lots are cut off by the oblique edges.
    assert!(max - min > 100.0, "{areas:?}");
}

/// `name index/total area` lines of features.cga.
fn named(out: &LotOutput) -> Vec<(String, String, f64)> {
    out.prints
        .iter()
        .map(|p| {
            let v: Vec<&str> = p.split(' ').collect();
            (v[0].to_string(), v[1].to_string(), v[2].parse().unwrap())
        })
        .collect()
}

#[test]
fn split_index_and_total_over_a_repeated_group() {
    // 100 | { ~1 | 200 }* | '0.1 on 1272: the group fits five times
    // (5 x 200 of the 1044.8 left), the floating parts share 44.8.
    let out = run("features.cga", "Lot", &lot(CONCAVE, &[]));
    let got = named(&out);
    let mut want = vec![("A".to_string(), "0/12".to_string(), 100.0)];
    for r in 0..5 {
        want.push(("B".into(), format!("{}/12", 1 + 2 * r), 44.8 / 5.0));
        want.push(("C".into(), format!("{}/12", 2 + 2 * r), 200.0));
    }
    want.push(("D".into(), "11/12".into(), 127.2));
    assert_eq!(got.len(), want.len());
    for (g, w) in got.iter().zip(&want) {
        assert_eq!((&g.0, &g.1), (&w.0, &w.1));
        assert_rel(g.2, w.2, &g.0);
    }
    no_warnings(&out);
}

#[test]
fn sums_below_the_whole_leave_the_rest_and_beyond_it_are_cut() {
    let l = lot(CONCAVE, &[]);
    let out = run("features.cga", "Partial", &l);
    let got = named(&out);
    assert_eq!(got.len(), 2);
    assert_rel(got[0].2, 0.5 * CONCAVE_AREA, "A");
    assert_rel(got[1].2, 0.2 * CONCAVE_AREA, "B");
    let used: f64 = out.meshes.iter().map(mesh_area).sum();
    assert_rel(used, 0.7 * CONCAVE_AREA, "used");

    let out = run("features.cga", "Beyond", &l);
    let got = named(&out);
    assert_eq!(got.len(), 2);
    assert_eq!(got[1].1, "1/2");
    assert_rel(got[0].2, 0.5 * CONCAVE_AREA, "A");
    assert_rel(got[1].2, 0.5 * CONCAVE_AREA, "B");
}

#[test]
fn mirrored_scope_runs_from_the_other_end() {
    let out = run("features.cga", "Mirrored", &lot(CONCAVE, &[]));
    let got = named(&out);
    assert_rel(got[0].2, 0.25 * CONCAVE_AREA, "A");
    assert_rel(got[1].2, 0.75 * CONCAVE_AREA, "B");
    // A is at the high-x end now.
    let (a_lo, a_hi) = bounds(&out.meshes[0]).unwrap();
    let (b_lo, b_hi) = bounds(&out.meshes[1]).unwrap();
    assert_eq!(a_hi.x, 46.0);
    assert_eq!(b_lo.x, 0.0);
    assert!((a_lo.x - b_hi.x).abs() < 1e-9);
}

#[test]
fn volumes_and_perpendicular_geometry_warn_but_split() {
    let l = lot(CONCAVE, &[]);
    let out = run("features.cga", "Mass", &l);
    assert_eq!(named(&out).len(), 2);
    assert_eq!(out.warnings.len(), 1);
    assert!(out.warnings[0].message.contains("not planar"));

    let out = run("features.cga", "Normal", &l);
    let got = named(&out);
    assert_eq!(got.len(), 2);
    // The whole lot lies in one cutting plane: it goes to one part whole.
    assert_rel(got[0].2 + got[1].2, CONCAVE_AREA, "sum");
    assert_eq!(got[0].2 * got[1].2, 0.0);
    assert_eq!(out.warnings.len(), 1);
    assert!(out.warnings[0].message.contains("perpendicular"));
}

/// `name tx tz sx sz area` lines.
fn scopes(out: &LotOutput) -> Vec<[f64; 5]> {
    out.prints
        .iter()
        .map(|p| {
            let v: Vec<f64> = p.split(' ').skip(1).map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2], v[3], v[4]]
        })
        .collect()
}

#[test]
fn part_scopes() {
    let l = lot(CONCAVE, &[]);
    // noAdjust: [0, c] and [c, 46] along x, the whole depth.
    let n = scopes(&run("features.cga", "Scopes", &l));
    assert_eq!(n.len(), 2);
    assert_eq!(n[0][0], 0.0);
    assert!((n[1][0] - n[0][2]).abs() < 1e-12);
    assert!((n[1][0] + n[1][2] - 46.0).abs() < 1e-12);
    for s in &n {
        assert_eq!((s[1], s[3]), (-40.0, 40.0));
    }
    // The cut: 0.3 of 1272 = 381.6 left of x = c, c = 12.905452846018727
    // (found independently by bisection on the clipped polygon's area).
    assert_rel(n[0][2], 12.905452846018727, "cut");
    assert_rel(n[0][4], 0.3 * CONCAVE_AREA, "left");
    // adjust: the bounding boxes. At x = c the left edge (4, 34)-(26, 40)
    // is at north 34 + 6 (c - 4) / 22; the right part holds the apex (26, 40).
    let j = scopes(&run("features.cga", "Scopes2", &l));
    assert_eq!(j[0][0], 0.0);
    assert!((j[0][2] - n[0][2]).abs() < 1e-9);
    let depth = 34.0 + 6.0 * (12.905452846018727 - 4.0) / 22.0;
    assert!(
        (j[0][1] - -depth).abs() < 1e-9 && (j[0][3] - depth).abs() < 1e-9,
        "{:?}",
        j[0]
    );
    assert!((j[1][0] - n[1][0]).abs() < 1e-9);
    assert_eq!((j[1][1], j[1][3]), (-40.0, 40.0));
}

/// A lot bent out of its plane by a few centimetres (terrain). Areas of a bent
/// face are not additive (each piece is measured in its own best-fit plane),
/// so not every part can match: every cut but a split's last is placed so
/// that the part before it measures exactly what was asked, and the last part
/// takes what is left, off by the bend's second order.
#[test]
fn nearly_planar_lot() {
    let mut l = lot(CONCAVE, &[]);
    for (p, dy) in l
        .mesh
        .positions
        .iter_mut()
        .zip([0.0, 0.03, -0.02, 0.05, 0.01, -0.04])
    {
        p.y += dy;
    }
    let out = run("nested.cga", "Lot", &l);
    let total = total_area(&out);
    assert!((total - CONCAVE_AREA).abs() < 1e-2);
    let areas = colour_areas(&out);
    assert_eq!(areas.len(), 6);
    for (label, a) in &areas {
        // R and G are the first halves of the first two columns, which are
        // exact thirds: exact. The others within the bend's second order
        // (here (5 cm / 7 m)^2 ~ 5e-5 at most; they come out within 4e-6).
        let tol = if matches!(label.as_str(), "R" | "G") {
            1e-9
        } else {
            1e-5
        };
        assert!(
            (a - total / 6.0).abs() <= tol * total / 6.0,
            "{label}: {a} instead of {}",
            total / 6.0
        );
    }
    no_warnings(&out);
}

/// A lot of several faces (the concave lot as a fan of triangles from an
/// inner point): the same parts.
#[test]
fn multi_face_lot() {
    let mut mesh = Mesh::new();
    mesh.positions.push(DVec3::new(20.0, 0.0, -18.0));
    mesh.positions
        .extend(CONCAVE.iter().map(|&(x, n)| DVec3::new(x, 0.0, -n)));
    let k = CONCAVE.len() as u32;
    for i in 0..k {
        mesh.add_face(&[&[0, 1 + i, 1 + (i + 1) % k]], 0);
    }
    assert_eq!(mesh_area(&mesh), CONCAVE_AREA);
    let l = Lot {
        name: "fan".into(),
        mesh,
        attrs: Vec::new(),
        geo_origin: None,
    };
    let out = run("repeat.cga", "Lot", &l);
    let fifth = 0.2 * CONCAVE_AREA;
    assert_areas(
        &out,
        &[
            ("R", fifth),
            ("Y", fifth),
            ("G", fifth),
            ("C", fifth),
            ("B", fifth),
        ],
    );
    no_warnings(&out);
}
