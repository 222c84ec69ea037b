//! The footprint toolkit through the engine: the examples of op_offset,
//! op_setback, op_setbackPerEdge, op_setbackToArea, op_shapeLUO,
//! op_splitAndSetbackPerimeter, op_innerRectangle, op_innerRect,
//! op_envelope, op_taper and op_footprint with their numbers; the scope of
//! the shapes they make; degenerate footprints.

use crate::ops_common::*;
use cga_engine::lot::Lot;
use cga_geometry::{measure, Mesh};

/// The areas printed as `label area` lines, in order.
fn areas(g: &Gen, label: &str) -> Vec<f64> {
    g.prints()
        .iter()
        .filter_map(|l| l.strip_prefix(label).and_then(|r| r.strip_prefix(' ')))
        .map(|r| r.parse::<f64>().unwrap())
        .collect()
}

fn sorted(mut v: Vec<f64>) -> Vec<f64> {
    v.sort_by(f64::total_cmp);
    v
}

// ----- offset -----

/// op_offset, "Offset Polygons and Border Faces" and "Face Orientation" on
/// `rect:20,30`: inwards by 3 the inside is 14 x 24 and the four border
/// faces are trapezoids facing up; outwards by 3 the inside is the mitred
/// 26 x 36 rectangle and the border faces face down, so that inside +
/// border = the original face in signed area.
#[test]
fn offset_inside_and_border() {
    let src = "Lot --> offset(D) A\nA --> comp(f) { inside : print(\"I \" + geometry.area) I. | border : print(\"O \" + geometry.area) O. }\n";
    let g = gen(&src.replace('D', "-3")).ok();
    assert_all_near(&areas(&g, "I"), &[336.0], 1e-9);
    assert_all_near(&sorted(areas(&g, "O")), &[51.0, 51.0, 81.0, 81.0], 1e-9);
    for m in g.meshes() {
        assert!(measure::face_normal(m, 0).y > 0.999);
    }
    let g = gen(&src.replace('D', "3")).ok();
    assert_all_near(&areas(&g, "I"), &[936.0], 1e-9);
    assert_all_near(&sorted(areas(&g, "O")), &[69.0, 69.0, 99.0, 99.0], 1e-9);
    let signed: f64 = g
        .meshes()
        .iter()
        .map(|m| measure::face_area(m, 0) * measure::face_normal(m, 0).y)
        .sum();
    assert_near(signed, 600.0, 1e-9);
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [-3.0, 0.0, -33.0], 1e-9);
    assert_vec_near(hi, [23.0, 0.0, 3.0], 1e-9);
    // Deeper than half the width: no inside, the border is the whole lot.
    let g = gen(&src.replace('D', "-12")).ok();
    assert!(areas(&g, "I").is_empty());
    assert_near(areas(&g, "O").iter().sum(), 600.0, 1e-9);
}

/// op_offset: the keepFaces selector, and the scope fitted to what is
/// kept (orientation unchanged).
#[test]
fn offset_keep_faces_and_scope() {
    let src = format!(
        "Lot --> offset(-3, inside) print(geometry.nFaces) print(geometry.area) Scope\n      offset(-2, border) print(geometry.nFaces) print(geometry.area) Scope X.\n{SCOPE_PRINTER}"
    );
    let g = gen(&src).ok();
    let p = g.prints();
    assert_eq!(p[0], "1");
    assert_eq!(p[1], "336");
    assert_eq!(p[2], "4");
    assert_near(p[3].parse::<f64>().unwrap(), 336.0 - 10.0 * 20.0, 1e-9);
    // The `Scope` rules print a generation later, in the order called.
    // The lot's pivot is at the origin, its scope's z axis along +z.
    let s = scope_line(&p[4]);
    assert_vec_near(s.t, [3.0, 0.0, -27.0], 1e-9);
    assert_vec_near(s.s, [14.0, 0.0, 24.0], 1e-9);
    assert_vec_near(s.r, [0.0, 0.0, 0.0], 1e-9);
    let s = scope_line(&p[5]);
    assert_vec_near(s.s, [14.0, 0.0, 24.0], 1e-9);
}

// ----- setback -----

/// op_setback, "Setback on Street Front" on `rect:20,30` (no street data:
/// street.front is object.front): a 20 x 5 garden; the building is the
/// 20 x 25 remainder inset by 3. The garden's scope keeps the lot's
/// orientation and fits the strip.
#[test]
fn setback_street_front() {
    let src = format!(
        "Lot --> setback(5) {{ street.front = Garden | remainder : Building }}\n\
         Garden --> print(\"G \" + geometry.area) Scope color(\"#00ff00\")\n\
         Building --> offset(-3, inside) print(\"B \" + geometry.area) extrude(world.up, rand(5, 15))\n{SCOPE_PRINTER}"
    );
    let g = gen(&src).ok();
    assert_all_near(&areas(&g, "G"), &[100.0], 1e-9);
    assert_all_near(&areas(&g, "B"), &[14.0 * 19.0], 1e-9);
    // Garden and Building print before Garden's `Scope`, a generation later.
    let s = scope_line(&g.prints()[2]);
    // The strip 0 > z > -5 in the lot's scope orientation.
    assert_vec_near(s.t, [0.0, 0.0, -5.0], 1e-9);
    assert_vec_near(s.s, [20.0, 0.0, 5.0], 1e-9);
    assert_vec_near(s.r, [0.0, 0.0, 0.0], 1e-9);
}

/// op_setback: distances per face edge from an array, and the right-handed
/// L of the "Individual distances" example: `comp(fe) { front = 5 | right
/// = 5 }` gives (4)[5,5,0,0] on a rectangle.
#[test]
fn setback_with_distance_arrays() {
    let g = gen("Lot --> setback([1, 2, 3, 4]) { all = print(\"G \" + geometry.area) G. | remainder : print(\"R \" + geometry.area) Scope R. }\n").ok();
    assert_all_near(&areas(&g, "G"), &[600.0 - 14.0 * 26.0], 1e-9);
    assert_all_near(&areas(&g, "R"), &[14.0 * 26.0], 1e-9);
    let (lo, hi) = mesh_bounds(g.meshes().last().unwrap());
    assert_vec_near(lo, [4.0, 0.0, -27.0], 1e-9);
    assert_vec_near(hi, [18.0, 0.0, -1.0], 1e-9);
    let src = "const dists = comp(fe) { front = 5 | right = 5 }\n\
               Lot --> print(dists) setback(dists) { all = print(\"G \" + geometry.area) Garden. | remainder : print(\"B \" + geometry.area) Building. }\n";
    let g = gen(src).ok();
    assert_eq!(g.prints()[0], "(4)[5,5,0,0]");
    assert_all_near(&areas(&g, "G"), &[225.0], 1e-9);
    assert_all_near(&areas(&g, "B"), &[375.0], 1e-9);
    // The remainder is at the left back: x in [0, 15].
    let (lo, hi) = mesh_bounds(g.meshes().last().unwrap());
    assert_vec_near(lo, [0.0, 0.0, -30.0], 1e-9);
    assert_vec_near(hi, [15.0, 0.0, -5.0], 1e-9);
}

/// op_setback, "Individual distances": on a shape of two faces the array
/// runs in face-edge order, 1 and 6 alternating from the first edge of the
/// first face to the last edge of the second.
#[test]
fn setback_distances_over_two_faces() {
    let mut mesh = Mesh::polygon(&pts(&[
        (0.0, 0.0),
        (20.0, 0.0),
        (20.0, -20.0),
        (0.0, -20.0),
    ]));
    let house = Mesh::polygon(&pts(&[
        (25.0, 0.0),
        (45.0, 0.0),
        (45.0, -20.0),
        (35.0, -28.0),
        (25.0, -20.0),
    ]));
    let house_area = measure::face_area(&house, 0);
    cga_geometry::transform::merge(&mut mesh, &house);
    let opts = Opts {
        lots: vec![Lot {
            name: "two".into(),
            mesh,
            attrs: Vec::new(),
            geo_origin: None,
        }],
        ..Opts::default()
    };
    let src = "const dists = comp(fe) { all : case comp.index % 2 == 0 : 1\n else : 6 }\n\
               Lot --> print(dists) setback(dists) { all = print(\"G \" + geometry.area) Garden. | remainder : print(\"B \" + geometry.area) Building. }\n";
    let g = gen_with(src, &opts).ok();
    assert_eq!(g.prints()[0], "(9)[1,6,1,6,1,6,1,6,1]");
    let b = areas(&g, "B");
    // The square: 1 from front and back, 6 from the sides: 8 x 18.
    assert_eq!(b.len(), 2);
    assert_near(b[0], 8.0 * 18.0, 1e-9);
    assert_near(
        areas(&g, "G")[0] + b.iter().sum::<f64>(),
        400.0 + house_area,
        1e-9,
    );
}

/// op_shapeLUO: shapeL is setback(comp(fe) { front = w1 | left = w2 });
/// the examples' L, U and O on a 34 x 24 lot (a 40 x 30 lot inset by 3).
#[test]
fn shape_l_u_o() {
    let g = gen("Lot --> shapeL(5, 5) { shape = print(\"S \" + geometry.area) S. | remainder : print(\"R \" + geometry.area) R. }\n").ok();
    assert_all_near(&areas(&g, "S"), &[225.0], 1e-9);
    assert_all_near(&areas(&g, "R"), &[375.0], 1e-9);
    // Left-handed: the remainder is at the right back.
    let (lo, hi) = mesh_bounds(g.meshes().last().unwrap());
    assert_vec_near(lo, [5.0, 0.0, -30.0], 1e-9);
    assert_vec_near(hi, [20.0, 0.0, -5.0], 1e-9);
    let lot = Opts::rect(40.0, 30.0);
    let run = |op: &str| {
        let src = format!(
            "Lot --> offset(-3, inside) {op} {{ shape : print(\"S \" + geometry.area) print(\"H \" + geometry.nHoles) Footprint | remainder : print(\"R \" + geometry.area) NIL }}\nFootprint --> extrude(rand(10, 20))\n"
        );
        gen_with(&src, &lot).ok()
    };
    let g = run("shapeL(5, 11)");
    assert_all_near(&areas(&g, "S"), &[34.0 * 5.0 + 24.0 * 11.0 - 55.0], 1e-9);
    let g = run("shapeU(5, 3, 11)");
    assert_all_near(&areas(&g, "S"), &[436.0], 1e-9);
    assert_all_near(&areas(&g, "R"), &[20.0 * 19.0], 1e-9);
    let g = run("shapeO(5, 3, 2, 11)");
    assert_all_near(&areas(&g, "S"), &[816.0 - 20.0 * 17.0], 1e-9);
    assert_all_near(&areas(&g, "H"), &[1.0], 0.0);
    assert_all_near(&areas(&g, "R"), &[340.0], 1e-9);
    // Wings that meet: nothing remains, the O is the whole lot.
    let g = gen("Lot --> shapeO(5, 10, 5, 10) { shape : print(\"S \" + geometry.area) S. | remainder : print(\"R \" + geometry.area) R. }\n").ok();
    assert_all_near(&areas(&g, "S"), &[600.0], 1e-9);
    assert!(areas(&g, "R").is_empty());
}

/// op_setbackPerEdge: the distance is evaluated on every face edge, with
/// the face edge as the current shape (`scope.sx` its length, `comp.index`
/// its index): four evaluations on a rectangle even if one edge is
/// selected.
#[test]
fn setback_per_edge() {
    let g =
        gen("Lot --> setbackPerEdge(scope.sx / 7.5) { all = print(\"G \" + geometry.area) G. }\n")
            .ok();
    let d = 20.0 / 7.5;
    assert_near(
        areas(&g, "G").iter().sum(),
        600.0 - (20.0 - 8.0) * (30.0 - 2.0 * d),
        1e-9,
    );
    let g =
        gen("debug = print(comp.index + 5)\nLot --> setbackPerEdge(debug) { front = Green. }\n")
            .ok();
    assert_eq!(g.prints(), ["5", "6", "7", "8"]);
    let g = gen("const dists = [3,2,1,0,0,1,2,3]\ndist = dists[comp.index]\n\
                 Lot --> setbackPerEdge(dist) { all = print(\"G \" + geometry.area) G. | remainder = print(\"R \" + geometry.area) R. }\n")
        .ok();
    assert_all_near(&areas(&g, "R"), &[18.0 * 26.0], 1e-9);
    // setback evaluates once: equal margins; setbackPerEdge per edge.
    let g = gen("Lot --> setback(rand(5)) { all = G. | remainder = R. }\n").ok();
    let (lo, hi) = mesh_bounds(g.meshes().last().unwrap());
    assert_near(lo.x, 20.0 - hi.x, 1e-9);
    assert_near(-hi.z, 30.0 + lo.z, 1e-9);
    assert_near(lo.x, -hi.z, 1e-9);
}

/// op_setbackToArea, "Setback to area": a 20 x 20 square set back to 100
/// (10 x 10 in the middle), and to its area minus 300 (setback faces of
/// 300); with front and left only, each strip gets 150.
#[test]
fn setback_to_area() {
    let sq = Opts::rect(20.0, 20.0);
    let g = gen_with(
        "Lot --> setbackToArea(100) { all = NIL | remainder = print(\"R \" + geometry.area) R. }\n",
        &sq,
    )
    .ok();
    assert_all_near(&areas(&g, "R"), &[100.0], 1e-6);
    let (lo, hi) = mesh_bounds(&g.meshes()[0]);
    assert_vec_near(lo, [5.0, 0.0, -15.0], 1e-6);
    assert_vec_near(hi, [15.0, 0.0, -5.0], 1e-6);
    let g = gen_with(
        "Lot --> setbackToArea(geometry.area - 300) { all = print(\"G \" + geometry.area) G. }\n",
        &sq,
    )
    .ok();
    assert_near(areas(&g, "G").iter().sum(), 300.0, 1e-6);
    let g = gen_with("attr area = 100\nLot --> setbackToArea(area) { front = print(\"B \" + geometry.area) B. | left = print(\"L \" + geometry.area) L. | remainder = print(\"R \" + geometry.area) R. }\n", &sq).ok();
    assert_all_near(&areas(&g, "B"), &[150.0], 1e-6);
    assert_all_near(&areas(&g, "L"), &[150.0], 1e-6);
    assert_all_near(&areas(&g, "R"), &[100.0], 1e-6);
    // Minimum and maximum distances: the front stays at exactly 4.
    let g = gen_with("Lot --> setbackToArea(100, [4, 0, 0, 0], [4, 10, 10, 10]) { all = NIL | remainder = print(\"R \" + geometry.area) R. }\n", &sq).ok();
    assert_all_near(&areas(&g, "R"), &[100.0], 1e-6);
    assert_near(mesh_bounds(&g.meshes()[0]).1.z, -4.0, 1e-9);
    // An area that cannot be reached: a warning, the nearest setback.
    let g = gen_with("Lot --> setbackToArea(1000) { all = NIL | remainder = print(\"R \" + geometry.area) R. }\n", &sq).ok();
    assert_all_near(&areas(&g, "R"), &[400.0], 1e-9);
    assert!(g.warnings().iter().any(|w| w.contains("setbackToArea")));
}

// ----- splitAndSetbackPerimeter -----

/// op_splitAndSetbackPerimeter, "Basic" on a 40 x 30 lot: from 6 m on, 40
/// m set back by 5 (34 along the front, 6 up the right side), then 20 m
/// by 10 up the right side.
#[test]
fn perimeter_basic() {
    let src = "Lot --> splitAndSetbackPerimeter(6)\n  { 40 : 5 : print(\"Y \" + geometry.area + \" \" + split.index) Yellow |\n    20 : 10 : print(\"B \" + geometry.area) Blue }\n  { remainder : print(\"G \" + geometry.area) Grey }\n\
               Yellow --> color(\"#F2BB1D\")\nBlue --> color(\"#3957A5\")\nGrey --> color(\"#CAC9C6\")\n";
    let g = gen_with(src, &Opts::rect(40.0, 30.0)).ok();
    assert_eq!(g.prints()[0], "Y 175 0");
    assert_all_near(&areas(&g, "B"), &[200.0], 1e-9);
    assert_all_near(&areas(&g, "G"), &[825.0], 1e-9);
}

/// op_splitAndSetbackPerimeter, "Setback distances": 28 m sections (five
/// floating ~30 on 140 m), each set back by its split.index: the first has
/// no depth and no shape; the deeper section keeps the corner it shares.
#[test]
fn perimeter_split_index_depths() {
    let src = "Lot --> splitAndSetbackPerimeter(0)\n  { ~30 : split.index : print(\"S \" + geometry.area) extrude(split.index) Yellow }*\n  { remainder : print(\"G \" + geometry.area) Grey }\n";
    let g = gen_with(src, &Opts::rect(40.0, 30.0)).ok();
    assert_all_near(&areas(&g, "S"), &[27.0, 52.0, 74.0, 112.0], 1e-9);
    assert_all_near(&areas(&g, "G"), &[935.0], 1e-9);
}

/// op_splitAndSetbackPerimeter, "Handling overlaps" on a 6 x 10 lot: the
/// overlap belongs to the deeper section.
#[test]
fn perimeter_overlaps() {
    let run = |d1: f64, d2: f64| {
        let src = format!(
            "Lot --> splitAndSetbackPerimeter(3)\n  {{ 2 : {d1} : print(\"Y \" + geometry.area) Y. | 2 : 0 : NIL | 2 : {d2} : print(\"B \" + geometry.area) B. }}\n  {{ remainder : print(\"G \" + geometry.area) G. }}\n"
        );
        gen_with(&src, &Opts::rect(6.0, 10.0)).ok()
    };
    let g = run(6.0, 4.0);
    assert_all_near(&areas(&g, "Y"), &[12.0], 1e-9);
    assert_all_near(&areas(&g, "B"), &[4.0], 1e-9);
    assert_all_near(&areas(&g, "G"), &[44.0], 1e-9);
    let g = run(4.0, 6.0);
    assert_all_near(&areas(&g, "Y"), &[4.0], 1e-9);
    assert_all_near(&areas(&g, "B"), &[12.0], 1e-9);
    assert_all_near(&areas(&g, "G"), &[44.0], 1e-9);
}

/// op_splitAndSetbackPerimeter, "Relative splitOffset" and "Using
/// context-based functions to select edges": sections wrap around the
/// perimeter's start; a mask restricts the chain to the front edges.
#[test]
fn perimeter_offset_and_mask() {
    let src = "Lot --> splitAndSetbackPerimeter('0.1)\n  { '0.5 : 10 : print(\"Y \" + geometry.area) extrude(15) Yellow |\n    ~1 : 0 : NIL |\n    '0.4 : 8 : print(\"B \" + geometry.area) extrude(10) Blue |\n    ~1 : 0 : NIL }\n  { remainder : print(\"G \" + geometry.area) Grey }\n";
    let g = gen_with(src, &Opts::rect(40.0, 30.0)).ok();
    let (y, b, r) = (areas(&g, "Y"), areas(&g, "B"), areas(&g, "G"));
    assert_eq!((y.len(), b.len(), r.len()), (1, 1, 1));
    assert_near(y[0] + b[0] + r[0], 1200.0, 1e-9);
    // Yellow: 26 m of front, the right side, 14 m of back, 10 deep.
    assert_near(y[0], 26.0 * 10.0 + 30.0 * 10.0 + 14.0 * 10.0 - 200.0, 1e-9);
    // Only the front edge (mask), 70 % of it in the middle, 10 deep.
    let src = "Lot --> splitAndSetbackPerimeter(0, 0, [true, false, false, false])\n  { ~1 : 0 : NIL | '0.7 : 10 : print(\"Y \" + geometry.area) Y. | ~1 : 0 : NIL }\n  { remainder : print(\"G \" + geometry.area) G. }\n";
    let g = gen(src).ok();
    assert_all_near(&areas(&g, "Y"), &[14.0 * 10.0], 1e-9);
    assert_all_near(&areas(&g, "G"), &[600.0 - 140.0], 1e-9);
    let (lo, hi) = mesh_bounds(&g.meshes()[0]);
    assert_vec_near(lo, [3.0, 0.0, -10.0], 1e-9);
    assert_vec_near(hi, [17.0, 0.0, 0.0], 1e-9);
}

// ----- innerRectangle, innerRect -----

/// op_innerRectangle, "Inner Rectangles of Lot Shapes": on the L the
/// largest scope-aligned rectangle is a 12 x 5 wing; the remainder is the
/// rest of the L (`:` one shape per polygon; a U leaves two). A
/// rectangular lot is its own inner rectangle and leaves no remainder.
#[test]
fn inner_rectangle() {
    let src = "Lot --> innerRectangle(A) { shape : print(\"S \" + geometry.area) S. | remainder : print(\"R \" + geometry.area) R. }\n";
    let l = Opts::polygon(&l_lot());
    for align in ["scope", "edge"] {
        let g = gen_with(&src.replace('A', align), &l).ok();
        assert_all_near(&areas(&g, "S"), &[60.0], 1e-9);
        assert_all_near(&areas(&g, "R"), &[35.0], 1e-9);
        assert!(measure::is_rectangular(&g.meshes()[0], 1e-9));
        // The rest of the L is the other wing's 5 x 7 rectangle.
        assert!(measure::is_rectangular(&g.meshes()[1], 1e-9));
    }
    let u = Opts::polygon(&pts(&[
        (0.0, 0.0),
        (15.0, 0.0),
        (15.0, -12.0),
        (10.0, -12.0),
        (10.0, -5.0),
        (5.0, -5.0),
        (5.0, -12.0),
        (0.0, -12.0),
    ]));
    let g = gen_with(&src.replace('A', "scope"), &u).ok();
    assert_all_near(&areas(&g, "S"), &[75.0], 1e-9);
    assert_all_near(&areas(&g, "R"), &[35.0, 35.0], 1e-9);
    let g = gen_with(
        &src.replace('A', "scope")
            .replace("remainder :", "remainder ="),
        &u,
    )
    .ok();
    assert_all_near(&areas(&g, "R"), &[70.0], 1e-9);
    let g = gen(&src.replace('A', "scope")).ok();
    assert_all_near(&areas(&g, "S"), &[600.0], 1e-9);
    assert!(areas(&g, "R").is_empty());
    // A square turned by 45 degrees: along an edge it is whole; along the
    // scope axes (x kept along its first edge here) too.
    let diamond = Opts::polygon(&pts(&[(0.0, 0.0), (5.0, -5.0), (0.0, -10.0), (-5.0, -5.0)]));
    let g = gen_with(&src.replace('A', "edge"), &diamond).ok();
    assert_all_near(&areas(&g, "S"), &[50.0], 1e-9);
    // Aligned with the world axes instead: the inscribed square of half
    // the area (the grid search is exact to a cell: 1 %).
    let g = gen_with(
        &src.replace(
            "innerRectangle(A)",
            "alignScopeToAxes() innerRectangle(scope)",
        ),
        &diamond,
    )
    .ok();
    assert_near(areas(&g, "S")[0], 25.0, 0.3);
}

/// op_innerRect (deprecated): the geometry becomes the rectangle.
#[test]
fn inner_rect() {
    let g = gen_with(
        "Lot --> innerRect print(geometry.area) X.\n",
        &Opts::polygon(&l_lot()),
    )
    .ok();
    assert_eq!(g.prints(), ["60"]);
    assert_eq!(g.meshes()[0].faces.len(), 1);
}

// ----- envelope -----

/// op_envelope, "Street-facing Slope" on `rect:20,30`: after a 10 m front
/// yard, a 20 x 20 building: 15 m walls, the front plane at 30 degrees
/// until it meets the back wall at 15 + 20 tan 30 < 50; the other sides
/// are vertical. The scope keeps its orientation, fitted.
#[test]
fn envelope_street_facing_slope() {
    let src = format!(
        "Lot -->\n   setback(10) {{ street.front : color(0,1,0) FrontYard. | remainder : Building }}\nBuilding --> envelope(normal, 50, 15, 30) print(geometry.volume) Scope E.\n{SCOPE_PRINTER}"
    );
    let g = gen(&src).ok();
    let t = 30f64.to_radians().tan();
    let p = g.prints();
    assert_near(
        p[0].parse::<f64>().unwrap(),
        400.0 * 15.0 + 20.0 * 20.0 * 20.0 * t / 2.0,
        1e-6,
    );
    let s = scope_line(&p[1]);
    assert_vec_near(s.s, [20.0, 15.0 + 20.0 * t, 20.0], 1e-9);
    assert_vec_near(s.r, [0.0, 0.0, 0.0], 1e-9);
    let m = g.meshes().last().unwrap();
    assert!(measure::is_closed(m));
}

/// The Candler rule's ventilation box: 0.45 m walls then 45-degree slopes
/// on every side, cut at 0.6 m (sides given as front, back and side).
#[test]
fn envelope_cut_at_max_height() {
    let src = "Lot --> envelope(world.up, 0.6, 0.45, 45, 0.45, 45, 0.45, 45) print(geometry.volume) print(geometry.nFaces) X.\n";
    let g = gen_with(src, &Opts::rect(8.2, 2.5)).ok();
    let p = g.prints();
    let prism = 8.2 * 2.5 * 0.45;
    let top = 7.9 * 2.2;
    let mid = 8.05 * 2.35;
    assert_near(
        p[0].parse::<f64>().unwrap(),
        prism + 0.15 / 6.0 * (8.2 * 2.5 + top + 4.0 * mid),
        1e-9,
    );
    // Base, four walls, four slopes, the top.
    assert_eq!(p[1], "10");
    // Per-edge arrays: a gable-like envelope (slopes front and back).
    let g = gen(
        "Lot --> envelope(normal, 100, [3, 0, 3, 0], [45, 90, 45, 90]) print(geometry.volume) X.\n",
    )
    .ok();
    assert_near(
        g.prints()[0].parse::<f64>().unwrap(),
        600.0 * 3.0 + 20.0 * 30.0 * 15.0 / 2.0,
        1e-6,
    );
}

// ----- taper, footprint -----

/// op_taper: a pyramid over the lot with its apex 10 above the centroid;
/// the scope's y along the normal, sized 10 (or -10 downwards).
#[test]
fn taper() {
    let src = format!("Lot --> taper(H) print(geometry.volume) Scope T.\n{SCOPE_PRINTER}");
    let g = gen(&src.replace('H', "10")).ok();
    let p = g.prints();
    assert_near(p[0].parse::<f64>().unwrap(), 2000.0, 1e-9);
    assert_vec_near(scope_line(&p[1]).s, [20.0, 10.0, 30.0], 1e-9);
    let apex = g.meshes()[0]
        .positions
        .iter()
        .copied()
        .find(|p| p.y > 9.0)
        .unwrap();
    assert_vec_near(apex, [10.0, 10.0, -15.0], 1e-9);
    let g = gen(&src.replace('H', "-10")).ok();
    assert_near(scope_line(&g.prints()[1]).s.y, -10.0, 1e-9);
    assert_near(g.bounds().0.y, -10.0, 1e-9);
}

/// op_footprint: the projection of a building (here an extruded L with a
/// hip roof) onto its scope's xz-plane is the L. (The walls and floor of a
/// comp split have their scope on the first face, the floor, whose y axis
/// is horizontal: they are aligned to the world first.)
#[test]
fn footprint() {
    let src = "Lot --> extrude(10) comp(f) { top : roofHip(30, 1) R | all = B }\n\
               B --> alignScopeToAxes(y) footprint() print(\"B \" + geometry.area) print(\"B \" + scope.sy) X.\n\
               R --> footprint() print(\"R \" + geometry.area) X.\n";
    let g = gen_with(src, &Opts::polygon(&l_lot())).ok();
    let b = areas(&g, "B");
    assert_all_near(&b, &[95.0, 0.0], 1e-6);
    // The roof with its overhang of 1 (cos 30 outwards).
    let o = 30f64.to_radians().cos();
    let grown = (12.0 + 2.0 * o) * (12.0 + 2.0 * o) - (7.0 - 0.0) * (7.0 - 0.0);
    assert_near(areas(&g, "R")[0], grown, 1e-6);
}

// ----- degenerate footprints -----

/// Degenerate polygons give a result or a warning, never an error.
#[test]
fn degenerate_footprints() {
    let lots = [
        pts(&[(0.0, 0.0), (5.0, 0.0), (10.0, 0.0)]),
        pts(&[
            (0.0, 0.0),
            (10.0, 0.0),
            (10.0, 0.0),
            (10.0, -8.0),
            (0.0, -8.0),
        ]),
        pts(&[
            (0.0, 0.0),
            (5.0, 0.0),
            (5.0, -5.0),
            (10.0, -5.0),
            (10.0, -10.0),
            (5.0, -10.0),
            (5.0, -5.0),
            (0.0, -5.0),
        ]),
        pts(&[(0.0, 0.0), (1e-9, 0.0), (0.0, -1e-9)]),
    ];
    let ops = [
        "offset(-1) X.",
        "offset(2) X.",
        "setback(2) { front : A. | remainder : B. }",
        "setbackPerEdge(1) { all = A. | remainder = B. }",
        "setbackToArea(10) { all = A. | remainder = B. }",
        "shapeU(1, 1, 1) { shape : A. | remainder : B. }",
        "innerRectangle(edge) { shape : A. | remainder : B. }",
        "innerRect X.",
        "envelope(normal, 5, 1, 30) X.",
        "taper(3) X.",
        "footprint() X.",
        "splitAndSetbackPerimeter(1) { 3 : 1 : A. }* { remainder : B. }",
    ];
    for lot in &lots {
        for op in ops {
            let g = gen_with(&format!("Lot --> {op}\n"), &Opts::polygon(lot));
            assert!(g.errors.is_empty(), "{op} on {lot:?}: {:?}", g.errors);
        }
    }
}

/// Texture coordinates projected before an offset, a setback or a
/// convexify stay where the projection put them (the new polygons take
/// them from the face they were cut from).
#[test]
fn texture_coordinates_survive() {
    let src = "Lot --> setupProjection(0, scope.xz, '1, '1) projectUV(0) OP print(geometry.uMin(0)) print(geometry.uMax(0)) print(geometry.vMin(0)) print(geometry.vMax(0)) X.\n";
    let g = gen(&src.replace("OP", "offset(-3, inside)")).ok();
    let p: Vec<f64> = g.prints().iter().map(|x| x.parse().unwrap()).collect();
    assert_all_near(&p, &[0.15, 0.85, 0.1, 0.9], 1e-9);
    let g = gen("Lot --> setupProjection(0, scope.xz, '1, '1) projectUV(0) setback(5) { front : NIL | remainder : Rest }\n\
                 Rest --> print(geometry.uMin(0)) print(geometry.uMax(0)) print(geometry.vMin(0)) print(geometry.vMax(0)) X.\n")
        .ok();
    let p: Vec<f64> = g.prints().iter().map(|x| x.parse().unwrap()).collect();
    // The remainder lies 5 m behind the front: v up to 25 / 30.
    assert_all_near(&p, &[0.0, 1.0, 0.0, 25.0 / 30.0], 1e-9);
}

/// op_setback's selectors: an index wraps around (-1 is the last edge), a
/// logical expression combines keywords, a condition is evaluated on each
/// face edge as a shape (as `comp` evaluates conditions: the component in
/// the current scope's orientation, so `scope.sz` is an edge's extent
/// along z); an edge goes to the first entry that selects it; `remainder`
/// is the same wherever it stands.
#[test]
fn setback_selectors() {
    let src = "Lot --> setback(2) { remainder : print(\"R \" + geometry.area) R. | -1 : print(\"L \" + geometry.area) L. | front || back : print(\"FB \" + geometry.area) FB. | scope.sz > 25 : print(\"S \" + geometry.area) S. }\n";
    let g = gen(src).ok();
    // Edge 3 (left, 30 m), front and back (20 m), then the right side.
    assert_all_near(&areas(&g, "R"), &[16.0 * 26.0], 1e-9);
    // The left strip: 30 long, its ends mitred with front and back.
    assert_all_near(&areas(&g, "L"), &[(30.0 + 26.0) / 2.0 * 2.0], 1e-9);
    assert_all_near(
        &sorted(areas(&g, "FB")),
        &[(20.0 + 16.0) / 2.0 * 2.0, (20.0 + 16.0) / 2.0 * 2.0],
        1e-9,
    );
    assert_all_near(&areas(&g, "S"), &[(30.0 + 26.0) / 2.0 * 2.0], 1e-9);
    // The order of creation follows the entries, remainder first here.
    assert!(g.prints()[0].starts_with("R "));
}

// ----- many-sided footprints -----

/// A round footprint of thousands of edges. `envelope` changes every
/// edge's slope at one height: the skeleton renews its wavefront once for
/// all of them (it used to renew it once per edge, quadratic in the edge
/// count: 16 s for the 2,000 edges here). `innerRectangle(edge)` tries
/// each edge direction once, at most 24 of them, on a grid of at most 400
/// lines per axis (it used to try every edge on a grid of every vertex
/// coordinate, and searched the grid in cubic time). Both give sound
/// results.
#[test]
fn many_sided_footprints_stay_fast() {
    // Walls of 10 m on every edge, then 45° slopes: a cone of height 10 on
    // a prism of height 10 (the apex a hair lower: the polygon's inradius).
    let src = "Lot --> s(20, 0, 20) primitiveDisk(2000) A\nA --> envelope(normal, 100, comp(fe) { all = 10 }, comp(fe) { all = 45 }) print(\"V \" + geometry.volume) X.\n";
    let g = gen(src).ok();
    let v = areas(&g, "V");
    let base = 2000.0 / 2.0 * 100.0 * (std::f64::consts::TAU / 2000.0).sin();
    assert_eq!(v.len(), 1);
    let want = base * (10.0 + 10.0 / 3.0);
    assert!((v[0] - want).abs() < 1e-4 * want, "{v:?} vs {want}");

    let src = "Lot --> s(20, 0, 20) primitiveDisk(2000) innerRectangle(edge) { shape : print(\"R \" + geometry.area) R. | remainder : NIL }\n";
    let g = gen(src).ok();
    let r = areas(&g, "R");
    // The largest rectangle in a circle of radius 10 is the square of area
    // 200; the grid of 400 lines finds it to within a few percent.
    assert_eq!(r.len(), 1);
    assert!(r[0] > 190.0 && r[0] <= 200.0 + 1e-6, "{r:?}");
}
