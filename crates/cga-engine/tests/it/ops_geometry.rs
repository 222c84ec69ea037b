//! The `geometry.*` functions of the reference page func_geometry (area,
//! volume, nVertices, nFaces, nHoles, isClosedSurface, isPlanar,
//! isRectangular, isConcave, boundaryLength, height) on shapes whose
//! numbers are known by hand: lots, extrusions, a lot with a hole, an L,
//! a warped and a skewed quad, a tilted shape, scaled shapes.

use crate::ops_common::*;
use cga_engine::lot::Lot;
use cga_geometry::{DVec3, Mesh};

/// Prints every measure of the page for the shape reached by `ops`.
fn measures(ops: &str, opts: &Opts) -> Vec<String> {
    let src = format!(
        "Lot --> {ops} M\n\
         M --> print(geometry.area) print(geometry.volume) print(geometry.nVertices) print(geometry.nFaces) \
         print(geometry.nHoles) print(geometry.isClosedSurface) print(geometry.isPlanar(0.25)) \
         print(geometry.isRectangular(0.5)) print(geometry.isConcave) print(geometry.boundaryLength) \
         print(geometry.height) NIL\n"
    );
    gen_with(&src, opts).ok().prints()
}

#[track_caller]
fn check(got: &[String], expected: [&str; 11]) {
    let names = [
        "area",
        "volume",
        "nVertices",
        "nFaces",
        "nHoles",
        "isClosedSurface",
        "isPlanar",
        "isRectangular",
        "isConcave",
        "boundaryLength",
        "height",
    ];
    for ((g, e), n) in got.iter().zip(expected).zip(names) {
        // numbers are compared to 1e-9, text exactly
        match (g.parse::<f64>(), e.parse::<f64>()) {
            (Ok(a), Ok(b)) => assert!((a - b).abs() < 1e-9, "{n}: expected {e}, got {g}"),
            _ => assert_eq!(g, e, "{n}"),
        }
    }
    assert_eq!(got.len(), 11);
}

/// A 10 x 10 lot with a 2 x 2 hole in its middle.
fn lot_with_hole() -> Opts {
    let mut mesh = Mesh::new();
    mesh.positions = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(10.0, 0.0, 0.0),
        DVec3::new(10.0, 0.0, -10.0),
        DVec3::new(0.0, 0.0, -10.0),
        // the hole, clockwise seen from above
        DVec3::new(4.0, 0.0, -4.0),
        DVec3::new(4.0, 0.0, -6.0),
        DVec3::new(6.0, 0.0, -6.0),
        DVec3::new(6.0, 0.0, -4.0),
    ];
    mesh.add_face(&[&[0, 1, 2, 3], &[4, 5, 6, 7]], 0);
    Opts {
        lots: vec![Lot {
            name: "holed".into(),
            mesh,
            attrs: Vec::new(),
            geo_origin: None,
        }],
        ..Opts::default()
    }
}

/// A flat lot: one rectangular face, open, planar, 4 boundary edges.
#[test]
fn measures_of_a_lot() {
    check(
        &measures("", &Opts::default()),
        [
            "600", "0", "4", "1", "0", "false", "true", "true", "false", "100", "0",
        ],
    );
}

/// An extruded lot: a closed box (no boundary), volume 20 * 10 * 30.
#[test]
fn measures_of_an_extrusion() {
    check(
        &measures("extrude(10)", &Opts::default()),
        [
            "2200", "6000", "8", "6", "0", "true", "true", "true", "false", "0", "10",
        ],
    );
}

/// A lot with a hole: area 100 - 4, one hole, the hole's edges are
/// boundary edges too; extruded, its top and bottom have a hole each, the
/// hole adds 4 inner walls (2 * 96 + 400 + 80), the solid is closed.
#[test]
fn measures_with_holes() {
    check(
        &measures("", &lot_with_hole()),
        [
            "96", "0", "8", "1", "1", "false", "true", "false", "true", "48", "0",
        ],
    );
    check(
        &measures("extrude(10)", &lot_with_hole()),
        [
            "672", "960", "16", "10", "2", "true", "true", "false", "true", "0", "10",
        ],
    );
}

/// An L-shaped lot is concave and not rectangular.
#[test]
fn measures_of_an_l() {
    let l = Opts::polygon(&[
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(10.0, 0.0, 0.0),
        DVec3::new(10.0, 0.0, -4.0),
        DVec3::new(4.0, 0.0, -4.0),
        DVec3::new(4.0, 0.0, -10.0),
        DVec3::new(0.0, 0.0, -10.0),
    ]);
    check(
        &measures("", &l),
        [
            "64", "0", "6", "1", "0", "false", "true", "false", "true", "40", "0",
        ],
    );
}

/// isPlanar: a quad with one corner lifted by 1 m (5.7 degrees) is not
/// planar within 0.25 degrees, but is within 10.
#[test]
fn is_planar_tolerance() {
    let src = "Lot --> i(\"warped.obj\", yUp, keepSizeAndPosition) print(geometry.isPlanar(0.25)) print(geometry.isPlanar(10)) NIL\n";
    let g = gen(src).ok();
    assert_eq!(g.prints(), ["false", "true"]);
}

/// isRectangular: "Angles in the range [90-tolerance, 90+tolerance] are
/// considered to be right": a parallelogram 1 degree off.
#[test]
fn is_rectangular_tolerance() {
    let src = "Lot --> i(\"skewed.obj\", yUp, keepSizeAndPosition) print(geometry.isRectangular(0.5)) print(geometry.isRectangular(1.5)) NIL\n";
    let g = gen(src).ok();
    assert_eq!(g.prints(), ["false", "true"]);
}

/// geometry.height: the height in world coordinates, whatever the scope:
/// the bent shape rises to 7.07 m; turned upright by r it is 10 m high.
#[test]
fn height_is_in_world_coordinates() {
    let src = "Lot --> i(\"bent2.obj\", yUp, keepSizeAndPosition) print(geometry.height) r(90,0,0) print(geometry.height) \
               print(scope.sy) NIL\n";
    let g = gen(src).ok();
    let p = g.prints();
    assert_near(numbers(&p[0])[0], 50f64.sqrt(), 1e-9);
    assert_near(numbers(&p[1])[0], 10.0, 1e-9);
    assert_near(numbers(&p[2])[0], 50f64.sqrt(), 1e-9);
}

/// The measures follow the transformations: scaling, negative sizes and
/// rotations change area and volume as they should.
#[test]
fn measures_follow_transformations() {
    let src = "Lot --> extrude(10) s('2,'1,'0.5) print(geometry.volume) print(geometry.area) \
               r(10,20,30) print(geometry.volume) s(-10,10,10) print(geometry.volume) print(geometry.area) NIL\n";
    let g = gen(src).ok();
    let p: Vec<f64> = g.prints().iter().map(|l| numbers(l)[0]).collect();
    assert_near(p[0], 40.0 * 10.0 * 15.0, 1e-9);
    assert_near(p[1], 2.0 * (40.0 * 10.0 + 10.0 * 15.0 + 40.0 * 15.0), 1e-9);
    assert_near(p[2], 6000.0, 1e-6);
    assert_near(p[3], 1000.0, 1e-6);
    assert_near(p[4], 600.0, 1e-6);
}

/// geometry.area() of split parts.
#[test]
fn area_of_split_parts() {
    let src = "Lot --> split(x) { 5 : A | ~1 : A }\nA --> print(geometry.area) NIL\n";
    let g = gen(src).ok();
    assert_eq!(g.prints(), ["150", "450"]);
}

/// The oracle's rule FacesHolesVerticesrule (extrude(10), then print
/// nVertices, nFaces, nHoles) on `rect:20,30` printed 8, 6, 0 in
/// CityEngine (the golden prints of the oracle, `../shared/prt-oracle`).
#[test]
fn faces_holes_vertices_like_the_oracle() {
    let src = "Footprint --> extrude(10) A\nA --> print(geometry.nVertices) print(geometry.nFaces) print(geometry.nHoles) X.\n";
    let g = gen_with(src, &Opts::default().start("Footprint")).ok();
    assert_eq!(g.prints(), ["8", "6", "0"]);
}
