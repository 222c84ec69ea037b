//! The face component split: the examples of the comp seed page and of
//! op_comp.md / attr_comp.md, selectors, operators, pivots and scopes.

use crate::comp_support::*;
use cga_engine::lot::{rect, Lot};
use cga_geometry::{DVec3, Mesh};

/// Prints `tag sx sy sz tx ty tz px py pz` of every shape that calls `Show(tag)`:
/// scope size, scope position (relative to the pivot) and pivot position
/// (relative to the initial shape's pivot, i.e. object coordinates for rect lots).
const SHOW: &str = r#"
Show(tag) --> print(tag + " " + scope.sx + " " + scope.sy + " " + scope.sz + " "
                    + scope.tx + " " + scope.ty + " " + scope.tz + " "
                    + pivot.px + " " + pivot.py + " " + pivot.pz)
"#;

/// Inserts a 1 x 2 x 3 cube at the scope origin: its bounding box in
/// object coordinates shows where the scope's axes point.
const AXES: &str = r#"
Axes(tag) --> s(1,2,3) primitiveCube()
"#;

#[test]
fn front_is_the_face_on_the_first_lot_edge_and_is_oriented() {
    // Face split details: x along the first edge, z along the normal
    // (facades of an extruded lot: x along the ground, y up, z out), the
    // pivot on the first vertex of the first edge.
    let text = format!(
        r#"Lot --> extrude(10) comp(f) {{ front : Axes("front") | right : Axes("right") | top : Axes("top") | back : Axes("back") }}
{AXES}"#
    );
    let r = run("front_oriented", &text).ok();
    let boxes: Vec<(DVec3, DVec3)> = r.meshes.iter().map(bbox).collect();
    let expect = [
        // front: pivot (0,0,0), axes x, y, z.
        (DVec3::new(0.0, 0.0, 0.0), DVec3::new(1.0, 2.0, 3.0)),
        // right: pivot (20,0,0), x = -z, y up, z = +x.
        (DVec3::new(20.0, 0.0, -1.0), DVec3::new(23.0, 2.0, 0.0)),
        // top: pivot (0,10,0), x along the first lot edge, z up, y = -z.
        (DVec3::new(0.0, 10.0, -2.0), DVec3::new(1.0, 13.0, 0.0)),
        // back: pivot (20,0,-30), x = -x, z = -z.
        (DVec3::new(19.0, 0.0, -33.0), DVec3::new(20.0, 2.0, -30.0)),
    ];
    assert_eq!(boxes.len(), 4);
    for (b, e) in boxes.iter().zip(expect) {
        assert!(
            (b.0 - e.0).length() < 1e-9 && (b.1 - e.1).length() < 1e-9,
            "{b:?} vs {e:?}"
        );
    }
}

#[test]
fn facade_floors_bottom_to_top() {
    // The facade of the seed page: comp(f) { front : split(y) { 3 : Floor }* }.
    let text = r#"Lot --> extrude(9) comp(f) { front : split(y) { 3 : Floor }* }
Floor --> print("floor " + split.index + " " + scope.ty + " " + scope.elevation + " " + scope.sx + " " + scope.sy)
"#;
    let r = run("facade_floors", text).ok();
    assert_close(
        &r.numbers("floor"),
        &[
            &[0.0, 0.0, 0.0, 20.0, 3.0],
            &[1.0, 3.0, 3.0, 20.0, 3.0],
            &[2.0, 6.0, 6.0, 20.0, 3.0],
        ],
        1e-9,
    );
}

#[test]
fn split_pieces_keep_the_facade_orientation() {
    // Tiles and floors cut from a facade start their outline along the
    // ground like the facade, so comp(f) on them gives x along the ground
    // and y up (scope 5 x 3, not 3 x 5 or turned by 180 degrees).
    let text = r#"Lot --> extrude(9) comp(f) { front : split(y) { 3 : split(x) { 5 : Tile }* }* }
Tile --> comp(f) { 0 : print("tile " + scope.sx + " " + scope.sy + " " + scope.elevation) }
"#;
    let r = run("split_orientation", text).ok();
    let tiles = r.numbers("tile");
    assert_eq!(tiles.len(), 12);
    for (i, t) in tiles.iter().enumerate() {
        assert_close(
            std::slice::from_ref(t),
            &[&[5.0, 3.0, 3.0 * (i / 4) as f64]],
            1e-9,
        );
    }
}

#[test]
fn comp_attributes_per_selector() {
    // attr_comp.md: primitiveCube() comp(f) { front : Front | side : Side | all = All }.
    let text = r#"Lot --> s(2,2,2) primitiveCube() comp(f) { front : P | side : P | all = P }
P --> print(comp.sel + " " + comp.index + " " + comp.total + " " + geometry.nFaces)
"#;
    let r = run("comp_attributes", text).ok();
    assert_eq!(
        r.prints,
        vec![
            "front 0 1 1",
            "side 0 3 1",
            "side 1 3 1",
            "side 2 3 1",
            "all 0 1 2"
        ]
    );
}

#[test]
fn comp_sel_is_the_selector_as_written() {
    let text = r#"attr k = 1
Lot --> extrude(4) comp(f) { 0 : P | k : P | top && !side : P | world.south || world.north : P | object.left : P | street.right : P }
P --> print("[" + comp.sel + "] " + comp.index + " " + comp.total)
"#;
    let r = run("comp_sel_text", text).ok();
    // Faces: bottom (0), top (1), front, right, back, left.
    assert_eq!(
        r.prints,
        vec![
            "[0] 0 1",
            "[k] 0 1",
            "[world.south || world.north] 0 2",
            "[world.south || world.north] 1 2",
            "[object.left] 0 1",
            "[street.right] 0 1",
        ]
    );
}

#[test]
fn selection_is_exclusive_left_to_right() {
    let text = r#"Lot --> extrude(4) comp(f) { side : A | all : B | front : C }
A --> print("A " + comp.index)
B --> print("B " + comp.index + " " + geometry.area)
C --> print("C")
"#;
    let r = run("exclusive", text).ok();
    // `all` only gets what `side` left (bottom and top); `front` gets nothing.
    assert_eq!(
        r.prints,
        vec!["A 0", "A 1", "A 2", "A 3", "B 0 600", "B 1 600"]
    );
}

#[test]
fn colon_equals_and_connected_sets() {
    // An L-shaped lot: its extrusion has two separate groups of front faces.
    let l = Lot {
        name: "L".into(),
        mesh: Mesh::polygon(&[
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(10.0, 0.0, 0.0),
            DVec3::new(10.0, 0.0, -10.0),
            DVec3::new(20.0, 0.0, -10.0),
            DVec3::new(20.0, 0.0, -20.0),
            DVec3::new(0.0, 0.0, -20.0),
        ]),
        attrs: Vec::new(),
        geo_origin: None,
    };
    let text = r#"Lot --> extrude(5) comp(f) { front : P("sep") | all = P("mass") }
Eq --> extrude(5) comp(f) { front = P("one") | all = P("mass") }
Con --> extrude(5) comp(f) { side =: P("con") | all = P("mass") }
P(t) --> print(t + " " + comp.index + " " + comp.total + " " + geometry.nFaces + " " + scope.sx)
"#;
    // Two front faces (x in [0,10] at z = 0 and x in [10,20] at z = -10).
    let r = run_on("operators_sep", text, &l, "Lot").ok();
    assert_eq!(
        r.prints,
        vec!["sep 0 2 1 10", "sep 1 2 1 10", "mass 0 1 6 20"]
    );
    // One shape of both, pivot and scope from the first front face: its
    // scope spans both faces along x.
    let r = run_on("operators_eq", text, &l, "Eq").ok();
    assert_eq!(r.prints, vec!["one 0 1 2 20", "mass 0 1 6 20"]);
    // The six sides are one ring of faces connected by edges: one shape.
    let r = run_on("operators_con", text, &l, "Con").ok();
    assert_eq!(r.prints, vec!["con 0 1 6 20", "mass 0 1 2 20"]);
    // Front faces alone are not connected: two shapes.
    let text2 = "Lot --> extrude(5) comp(f) { front =: P }\nP --> print(\"con \" + comp.index + \" \" + comp.total + \" \" + geometry.nFaces)\n";
    let r = run_on("operators_con2", text2, &l, "Lot").ok();
    assert_eq!(r.prints, vec!["con 0 2 1", "con 1 2 1"]);
}

#[test]
fn no_align_keeps_pivot_and_scope_orientation() {
    // op_comp.md, "Facade selection c": comp(f, noAlign).
    let text = format!(
        r#"Lot --> extrude(5) comp(f, noAlign) {{ right : Show("right") Axes("rax") | front : Show("front") }}
{SHOW}{AXES}"#
    );
    let r = run("no_align", &text).ok();
    // The cube in the right facade's scope (after the facade itself, a
    // leaf of `Show`): the lot's axes, at (20, 0, -30).
    let b = bbox(&r.meshes[1]);
    assert!(
        (b.0 - DVec3::new(20.0, 0.0, -30.0)).length() < 1e-9,
        "{b:?}"
    );
    assert!(
        (b.1 - DVec3::new(21.0, 2.0, -27.0)).length() < 1e-9,
        "{b:?}"
    );
    // The right facade (x = 20) in the lot's orientation: sx = 0, sz = 30;
    // the pivot stays on the lot's first vertex.
    assert_close(
        &r.numbers("right"),
        &[&[0.0, 5.0, 30.0, 20.0, 0.0, -30.0, 0.0, 0.0, 0.0]],
        1e-9,
    );
    assert_close(
        &r.numbers("front"),
        &[&[20.0, 5.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]],
        1e-9,
    );
}

#[test]
fn index_selectors() {
    // op_comp.md "Index-based Selection": faces 0, 2 and 4 of a cylinder,
    // plus an index from an attribute and an index out of range.
    let text = r#"attr which = 3
Lot --> s(2,4,2) primitiveCylinder() comp(f) { 0 : P | 2 : P | 4 : P | which : P | 99 : P | -1 : P }
P --> print(comp.sel + " " + geometry.nVertices)
"#;
    let r = run("index_selectors", text).ok();
    // Face 0 is the bottom (16 vertices), the others are side quads.
    assert_eq!(r.prints, vec!["0 16", "2 4", "4 4", "which 4"]);
}

/// The expected classification of a `primitiveSphere()` (16 x 16) face
/// from the direction of its centre (not from the engine's code): faces of
/// band `i` from the top are centred at polar angle (i + 0.5) * 11.25
/// degrees, face `k` around at azimuth (k + 0.5) * 22.5 degrees.
fn sphere_counts() -> (usize, usize, usize, usize, [usize; 4]) {
    let (mut top, mut side, mut horizontal, mut vertical) = (0, 0, 0, 0);
    let mut slopes = [0usize; 4];
    for i in 0..16 {
        let elevation = 90.0 - (i as f64 + 0.5) * 11.25;
        for k in 0..16 {
            let az = ((k as f64 + 0.5) * 22.5f64).to_radians();
            let e = elevation.to_radians();
            let (y, h) = (e.sin(), e.cos() * az.cos().abs().max(az.sin().abs()));
            if y.abs() >= h {
                if y > 0.0 {
                    top += 1;
                }
            } else {
                side += 1;
            }
            let s = match elevation {
                x if x > 78.75 || x <= -78.75 => 0,
                x if x > 11.25 => 1,
                x if x > -11.25 => 2,
                _ => 3,
            };
            slopes[s] += 1;
            if s == 0 {
                horizontal += 1;
            }
            if s == 2 {
                vertical += 1;
            }
        }
    }
    (top, side, horizontal, vertical, slopes)
}

#[test]
fn quadrant_selectors_on_a_sphere() {
    // op_comp.md "Selectors 1": the quadrants relative to the scope.
    let text = r#"Lot --> s(10,10,10) primitiveSphere() comp(f) { top : P | bottom : P | front : P | back : P | left : P | right : P }
P --> print(comp.sel + " " + comp.total)
"#;
    let r = run("sphere_quadrants", text).ok();
    let (top, side, _, _, _) = sphere_counts();
    assert_eq!((top, side), (64, 128));
    let mut seen: Vec<String> = r.prints.clone();
    seen.dedup();
    assert_eq!(
        seen,
        vec![
            format!("top {top}"),
            format!("bottom {top}"),
            format!("front {}", side / 4),
            format!("back {}", side / 4),
            format!("left {}", side / 4),
            format!("right {}", side / 4),
        ]
    );
    assert_eq!(r.prints.len(), 256);
}

#[test]
fn slope_selectors_on_a_sphere() {
    // op_comp.md "Selectors 2": the angle to the xz-plane; the poles are horizontal.
    let text = r#"Lot --> s(10,10,10) primitiveSphere() comp(f) { horizontal = P | aslant = P | vertical = P | nutant = P }
P --> print(comp.sel + " " + geometry.nFaces)
"#;
    let r = run("sphere_slopes", text).ok();
    let (_, _, _, _, s) = sphere_counts();
    assert_eq!(s, [32, 96, 32, 96]);
    assert_eq!(
        r.prints,
        vec![
            format!("horizontal {}", s[0]),
            format!("aslant {}", s[1]),
            format!("vertical {}", s[2]),
            format!("nutant {}", s[3]),
        ]
    );
    // `side` is all but horizontal.
    let r = run(
        "sphere_side",
        "Lot --> s(10,10,10) primitiveSphere() comp(f) { side = P }\nP --> print(geometry.nFaces)\n",
    )
    .ok();
    assert_eq!(r.prints, vec![(256 - s[0]).to_string()]);
}

#[test]
fn logical_selector_expressions() {
    // op_comp.md "Logical selection expressions".
    let text = r#"mySelectorFunc = geometry.isOriented(top) || geometry.nVertices == 3
Lot --> s(10,10,10) primitiveSphere() comp(f) { top || front = P("topfront") }
Custom --> s(10,10,10) primitiveSphere() comp(f) { mySelectorFunc = P("custom") }
NotSide --> s(10,10,10) primitiveSphere() comp(f) { top && !side = P("flat") | !(top || bottom) && world.east = P("east") }
P(t) --> print(t + " " + geometry.nFaces)
"#;
    let lot = rect(20.0, 30.0);
    let (top, side, horizontal, _, _) = sphere_counts();
    let r = run_on("logic_or", text, &lot, "Lot").ok();
    assert_eq!(r.prints, vec![format!("topfront {}", top + side / 4)]);
    // Top faces and all triangles (the 16 at the south pole are new).
    let r = run_on("logic_fn", text, &lot, "Custom").ok();
    assert_eq!(r.prints, vec![format!("custom {}", top + 16)]);
    // Top and not side: the horizontal faces at the north pole.
    let r = run_on("logic_not", text, &lot, "NotSide").ok();
    assert_eq!(
        r.prints,
        vec![
            format!("flat {}", horizontal / 2),
            format!("east {}", side / 4)
        ]
    );
}

#[test]
fn conditions_on_the_component_shape() {
    // "geometry.area() > 1 && !inside" and a condition without keywords on
    // the grid (9 unit squares; the grid's faces are areas 1 each).
    let text = r#"Lot --> comp(f) { geometry.area() >= 1 && !inside : P("a") | scope.sx > 3 : P("b") | all = P("rest") }
Big --> s(3,0,6) comp(f) { scope.sx > 1.5 : P("wide") | all = P("rest") }
P(t) --> print(t + " " + comp.index + " " + comp.total)
"#;
    let r = run_on("conditions", text, &grid_lot(), "Lot").ok();
    assert_eq!(r.prints.len(), 9);
    assert_eq!(r.prints[0], "a 0 8");
    assert_eq!(r.prints[8], "rest 0 1");
    // Scaled 3 x 6: every face is 1 wide and 2 deep; none is wider than 1.5.
    let r = run_on("conditions_scaled", text, &grid_lot(), "Big").ok();
    assert_eq!(r.prints, vec!["rest 0 1"]);
}

#[test]
fn border_and_inside_faces() {
    // op_comp.md "Border and Inside Selectors" on a subdivided plane.
    let text = r#"Lot --> comp(f) { border : P("FBorder") | inside : P("FInside") }
P(t) --> print(t + " " + comp.total + " " + scope.tx + " " + pivot.px + " " + pivot.pz)
"#;
    let r = run_on("border_faces", text, &grid_lot(), "Lot").ok();
    assert_eq!(r.lines("FBorder").len(), 8);
    // The middle square, pivot on its first corner (1, 0, -1).
    assert_close(&r.numbers("FInside"), &[&[1.0, 0.0, 1.0, -1.0]], 1e-9);
}

#[test]
fn world_and_object_selectors_on_a_turned_lot() {
    // A lot whose street front faces east (+x): `front` is world.east and
    // object.front; world.south is the lot's right side.
    let lot = Lot {
        name: "turned".into(),
        mesh: Mesh::polygon(&[
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.0, 0.0, -20.0),
            DVec3::new(-30.0, 0.0, -20.0),
            DVec3::new(-30.0, 0.0, 0.0),
        ]),
        attrs: Vec::new(),
        geo_origin: None,
    };
    let text = r#"Lot --> extrude(5) comp(f) { world.east : P("east") | world.south : P("south") | world.up : P("up") | world.down : P("down") | world.side = P("side") }
Obj --> extrude(5) comp(f) { object.front : P("ofront") | street.back : P("sback") | object.top : P("otop") | object.side = P("oside") }
P(t) --> print(t + " " + comp.total + " " + geometry.nFaces + " " + scope.sx)
"#;
    let r = run_on("world_sel", text, &lot, "Lot").ok();
    // The front (first edge, going north) faces east; side 1 faces north,
    // side 2 west, side 3 south. world.side takes north and west.
    assert_eq!(
        r.prints,
        vec![
            "east 1 1 20",
            "south 1 1 30",
            "up 1 1 20",
            "down 1 1 20",
            "side 1 2 30"
        ]
    );
    let r = run_on("object_sel", text, &lot, "Obj").ok();
    assert_eq!(
        r.prints,
        vec![
            "ofront 1 1 20",
            "sback 1 1 20",
            "otop 1 1 20",
            "oside 1 2 30"
        ]
    );
}

#[test]
fn orientation_functions() {
    // geometry.area(selector) and geometry.isOriented(selector).
    let text = r#"Lot --> extrude(10)
    print(geometry.area(top) + " " + geometry.area(side) + " " + geometry.area(front) + " " + geometry.area(world.north) + " " + geometry.area(all))
    print(geometry.isOriented(world.up) + " " + geometry.isOriented(nutant))
    comp(f) { front : print("front " + geometry.isOriented(front) + " " + geometry.isOriented(top)) }
"#;
    let r = run("orientation_fns", text).ok();
    assert_eq!(r.prints[0], "600 1000 200 200 2200");
    assert_eq!(r.prints[1], "true false");
    // The front face in its own scope faces +z: front, not top.
    assert_eq!(r.prints[2], "front true false");
}

#[test]
fn holes_and_faces_of_a_lot_with_a_hole() {
    // A 20 x 30 lot with a 4 x 6 courtyard: extruded, its sides are the 4
    // outer and the 4 inner walls; comp(h) gives the courtyard.
    let mut mesh = Mesh::new();
    mesh.positions.extend([
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(20.0, 0.0, 0.0),
        DVec3::new(20.0, 0.0, -30.0),
        DVec3::new(0.0, 0.0, -30.0),
        DVec3::new(8.0, 0.0, -12.0),
        DVec3::new(8.0, 0.0, -18.0),
        DVec3::new(12.0, 0.0, -18.0),
        DVec3::new(12.0, 0.0, -12.0),
    ]);
    mesh.add_face(&[&[0, 1, 2, 3], &[4, 5, 6, 7]], 0);
    let lot = Lot {
        name: "court".into(),
        mesh,
        attrs: Vec::new(),
        geo_origin: None,
    };
    let text = r#"Lot --> extrude(3) comp(f) { side : P("side") | top : P("top") }
Holes --> comp(h) { all : P("hole") }
P(t) --> print(t + " " + scope.sx + " " + scope.sy + " " + geometry.area + " " + geometry.nHoles)
"#;
    let r = run_on("holes_faces", text, &lot, "Lot").ok();
    assert_eq!(r.lines("side").len(), 8);
    assert_close(&r.numbers("top"), &[&[20.0, 30.0, 576.0, 1.0]], 1e-9);
    let r = run_on("holes", text, &lot, "Holes").ok();
    // The hole as a face facing up like the lot: 4 x 6.
    assert_close(&r.numbers("hole"), &[&[4.0, 6.0, 24.0, 0.0]], 1e-9);
}

#[test]
fn groups_and_materials_of_an_asset() {
    // op_comp.md "Group Split" / "Material Split" with a small tree asset:
    // groups trunk (4 faces, Bark), foliage and oranges (1 face each).
    let text = r#"Lot --> i("{DIR}/tree.obj") comp(g) { 0 : P("trunk") | all = P("crown") }
Mat --> i("{DIR}/tree.obj") comp(m) { 2 : P("oranges") | 0 : P("bark") }
Sel --> i("{DIR}/tree.obj") comp(g) { top : P("top") | side = P("side") }
P(t) --> print(t + " " + geometry.nFaces + " " + material.color.r + " " + comp.total)
"#;
    let r = run_on("groups", text, &rect(3.0, 3.0), "Lot").ok();
    assert_eq!(r.prints, vec!["trunk 4 0.4 1", "crown 2 0.1 1"]);
    let r = run_on("materials", text, &rect(3.0, 3.0), "Mat").ok();
    assert_eq!(r.prints, vec!["oranges 1 1 1", "bark 4 0.4 1"]);
    // A group satisfies a keyword if one of its faces does: both crowns
    // face up; the trunk has side faces.
    let r = run_on("groups_sel", text, &rect(3.0, 3.0), "Sel").ok();
    assert_eq!(r.prints, vec!["top 1 0.1 2", "top 1 1 2", "side 4 0.4 1"]);
}

#[test]
fn is_tagged_selects_by_auto_tags() {
    // extrude tags its top "extrude.top"; nothing is tagged "x", and the
    // top is already taken by the first entry.
    let text = r#"Lot --> extrude(3) comp(f) { isTagged("extrude.top") : P("tagged") | isTagged("x", e) || top : P("top") | all = P("rest") }
P(t) --> print(t + " " + geometry.nFaces)
"#;
    let r = run("is_tagged", text).ok();
    assert_eq!(r.prints, vec!["tagged 1", "rest 5"]);
    let r = run("is_tagged_bad", "Lot --> comp(f) { isTagged(3) : X }\n");
    assert!(r.error.unwrap().contains("tag query"));
}

#[test]
fn comp_on_faces_split_earlier() {
    // A facade split into tiles, each tile split into its single face. (The
    // first corner of a split piece, and so the pivot corner, is the cut's
    // business; sizes and places are checked here.)
    let text = r#"Lot --> extrude(6) comp(f) { front : split(x) { 5 : T }* }
T --> comp(f) { all : print("tile " + split.index + " " + scope.sx + " " + scope.sy + " " + scope.sz) X. }
"#;
    let r = run("split_then_comp", text).ok();
    assert_close(
        &r.numbers("tile"),
        &[
            &[0.0, 5.0, 6.0, 0.0],
            &[1.0, 5.0, 6.0, 0.0],
            &[2.0, 5.0, 6.0, 0.0],
            &[3.0, 5.0, 6.0, 0.0],
        ],
        1e-9,
    );
    for (i, m) in r.meshes.iter().enumerate() {
        let b = bbox(m);
        let x = 5.0 * i as f64;
        assert!((b.0 - DVec3::new(x, 0.0, 0.0)).length() < 1e-9, "{b:?}");
        assert!(
            (b.1 - DVec3::new(x + 5.0, 6.0, 0.0)).length() < 1e-9,
            "{b:?}"
        );
    }
}

#[test]
fn comp_replaces_the_shape() {
    // The comp'd shape is not a leaf; unselected faces disappear.
    let r = run("replaces", "Lot --> extrude(10) comp(f) { top : X. }\n").ok();
    assert_eq!(r.meshes.len(), 1);
    assert!((r.area() - 600.0).abs() < 1e-9);
}

#[test]
fn resolver_errors_in_comp_heads() {
    let errs = load_errors("bad_head", "Lot --> comp(f) { frontt : X }\n");
    assert!(errs.iter().any(|e| e.contains("frontt")), "{errs:?}");
    let errs = load_errors("bad_istagged", "Lot --> comp(f) { isTagged() : X }\n");
    assert!(errs.iter().any(|e| e.contains("isTagged")), "{errs:?}");
}

#[test]
fn bad_component_and_alignment_are_errors() {
    let r = run("bad_kind", "Lot --> comp(q) { all : X }\n");
    assert!(r.error.unwrap().contains("unknown selector `q`"));
    let r = run("bad_align", "Lot --> comp(f, yUp) { all : X }\n");
    assert!(r.error.unwrap().contains("unknown selector `yUp`"));
    let r = run(
        "bad_sel_type",
        "attr s = \"front\"\nLot --> comp(f) { s : X }\n",
    );
    assert!(r.error.unwrap().contains("found string"));
}
