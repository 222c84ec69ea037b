//! Lots that are not `rect:W,D`, where the pages leave it open what an
//! extrusion and the geometry functions give: the expectations were asked
//! from CityEngine's runtime (the oracle in `../shared/prt-oracle`, outside the repository), with
//! its rule packages `extrusion_rule` (heights pinned by
//! `--attr minBuildingHeight=7 --attr maxBuildingHeight=7`) and
//! `FacesHolesVerticesrule`, on the lots of tests/rules/ops/lots:
//!
//! ```text
//! python3 oracle.py rpk/extrusion_rule.rpk --lot L.obj --attr minBuildingHeight=7 --attr maxBuildingHeight=7 --out o
//! python3 oracle.py rpk/FacesHolesVerticesrule.rpk --lot cw.obj --out o
//! ```
//!
//! The rule files are the packages' own, read from the oracle; without it
//! the tests say they are skipped.

use std::path::PathBuf;

use crate::ops_common::*;
use cga_engine::lot;
use cga_value::Value;

/// The FacesHolesVerticesrule package's rule (prints the counts of
/// vertices, faces and holes after `extrude(10)`).
fn fhv() -> Option<PathBuf> {
    cga_testkit::oracle_rule("FacesHolesVerticesrule", "FacesHolesVerticesrule.cga")
}

fn obj_lot(name: &str) -> Opts {
    Opts {
        lots: lot::from_obj(&rules_dir().join("lots").join(name)).unwrap(),
        ..Opts::default()
    }
}

/// The extrusion rule with a height of 7: (reports, model bounds, area).
fn extrusion(lot_file: &str) -> Option<(Vec<(String, Value)>, Gen)> {
    let rule = cga_testkit::oracle_rule("extrusion_rule", "extrusion_rule.cga")?;
    let opts = obj_lot(lot_file)
        .attr("minBuildingHeight", "7")
        .attr("maxBuildingHeight", "7");
    let g = gen_file(&rule, &opts).ok();
    Some((g.out().reports.clone(), g))
}

fn report(reports: &[(String, Value)], key: &str) -> f64 {
    match reports.iter().find(|(k, _)| k == key) {
        Some((_, Value::Float(x))) => *x,
        other => panic!("{key}: {other:?}"),
    }
}

/// An L-shaped lot (concave, 64 m2): the oracle reports parcel area 64 and
/// volume / area = 7; the model's area is 408 (2 * 64 + 40 * 7), and the
/// extrusion has 12 vertices, 8 faces and no hole.
#[test]
fn l_shaped_lot() {
    let Some((r, g)) = extrusion("L.obj") else {
        return;
    };
    assert_near(report(&r, "Parcel Area.0"), 64.0, 1e-9);
    assert_near(report(&r, "Building Height.0"), 7.0, 1e-9);
    assert_near(g.area(), 408.0, 1e-9);
    let g = gen_file(&fhv().unwrap(), &obj_lot("L.obj")).ok();
    assert_eq!(g.prints(), ["12", "8", "0"]);
}

/// A triangle lot at y = 1 (not at the origin): parcel area 40, extruded
/// from y 1 to 8, bounds x 3..13, z -6..2, model area 282.0757.
#[test]
fn triangle_lot_above_the_origin() {
    let Some((r, g)) = extrusion("tri.obj") else {
        return;
    };
    assert_near(report(&r, "Parcel Area.0"), 40.0, 1e-9);
    assert_near(report(&r, "Building Height.0"), 7.0, 1e-9);
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [3.0, 1.0, -6.0], 1e-9);
    assert_vec_near(hi, [13.0, 8.0, 2.0], 1e-9);
    assert_near(g.area(), 282.0757, 1e-4);
}

/// A 10 x 10 lot turned by 30 degrees: the oracle's bounds are x 2..15.66,
/// z -7.66..6, y 0..7, area 480 (its 479.985 is single precision).
#[test]
fn turned_lot() {
    let Some((r, g)) = extrusion("turned.obj") else {
        return;
    };
    assert_near(report(&r, "Parcel Area.0"), 100.0, 1e-9);
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [2.0, 0.0, -7.660254037844386], 1e-9);
    assert_vec_near(hi, [15.660254037844386, 7.0, 6.0], 1e-9);
    assert_near(g.area(), 480.0, 1e-9);
}

/// A clockwise lot (its normal points down) is not turned up: the oracle
/// extrudes it downwards, y from -7 to 0 (and -10 to 0 with the 10 m
/// extrusion of FacesHolesVerticesrule, which counts 8, 6, 0).
#[test]
fn clockwise_lot_extrudes_down() {
    let Some((r, g)) = extrusion("cw.obj") else {
        return;
    };
    assert_near(report(&r, "Parcel Area.0"), 100.0, 1e-9);
    assert_near(report(&r, "Building Height.0"), 7.0, 1e-9);
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [0.0, -7.0, -10.0], 1e-9);
    assert_vec_near(hi, [10.0, 0.0, 0.0], 1e-9);
    assert_near(g.area(), 480.0, 1e-9);
    let g = gen_file(&fhv().unwrap(), &obj_lot("cw.obj")).ok();
    assert_eq!(g.prints(), ["8", "6", "0"]);
    let (lo, hi) = g.bounds();
    assert_near(lo.y, -10.0, 1e-9);
    assert_near(hi.y, 0.0, 1e-9);
}

/// A lot with a vertex in the middle of an edge keeps it (the oracle counts
/// 10 vertices and 7 faces after extrude(10)); a repeated vertex is dropped
/// (8 vertices, 6 faces).
#[test]
fn collinear_and_repeated_vertices() {
    let Some(rule) = fhv() else { return };
    let g = gen_file(&rule, &obj_lot("col.obj")).ok();
    assert_eq!(g.prints(), ["10", "7", "0"]);
    assert_near(g.area(), 600.0, 1e-9);
    let g = gen_file(&rule, &obj_lot("dup.obj")).ok();
    assert_eq!(g.prints(), ["8", "6", "0"]);
    assert_near(g.area(), 600.0, 1e-9);
}
