//! The comp function (func_comp.md): arrays of per-component values.

use crate::comp_support::*;
use cga_engine::lot::Lot;
use cga_geometry::{DVec3, Mesh};

fn l_lot() -> Lot {
    Lot {
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
    }
}

/// Two quads sharing an edge: 7 edges, 8 face edges. The second starts at
/// its front-right corner, so its front edge is its last.
fn two_quads() -> Lot {
    multi_face_lot(&[
        &[
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(7.0, 0.0, 0.0),
            DVec3::new(7.0, 0.0, -15.0),
            DVec3::new(0.0, 0.0, -15.0),
        ],
        &[
            DVec3::new(7.0, 0.0, -15.0),
            DVec3::new(7.0, 0.0, -25.0),
            DVec3::new(0.0, 0.0, -25.0),
            DVec3::new(0.0, 0.0, -15.0),
        ],
    ])
}

#[test]
fn vertices_comp_index() {
    // "Vertices | Comp shape attributes": comp(v) { all : comp.index }.
    let text = "const array = comp(v) { all : comp.index }\nLot --> print(array)\n";
    let r = run_on("fn_vertices", text, &l_lot(), "Lot").ok();
    assert_eq!(r.prints, vec!["(6)[0,1,2,3,4,5]"]);
}

#[test]
fn edges_scope_sizes_with_defaults() {
    // "Edges | Scope shape attributes": border edge lengths; the shared
    // (inside) edge 2 gets the default 0.
    let text = "edgeLength = scope.sx\nconst array = comp(e) { border : edgeLength }\nLot --> print(array)\n";
    let r = run_on("fn_edges", text, &two_quads(), "Lot").ok();
    assert_eq!(r.prints, vec!["(7)[7,15,0,15,10,7,10]"]);
}

#[test]
fn face_edges_combined_operator() {
    // "Face edges | Combine shape operator": the combined expression is
    // evaluated once and copied to every back edge; unselected are "".
    let text = "const array = comp(fe) { front : comp.sel + comp.index | back = str(comp.index) }\nLot --> print(array)\n";
    let r = run_on("fn_face_edges", text, &two_quads(), "Lot").ok();
    assert_eq!(r.prints, vec!["(8)[front0,,0,,,0,,front1]"]);
}

#[test]
fn faces_bool_array() {
    // "Faces": one value for the combined side faces, false elsewhere. (The
    // reference's box lists its top last; this engine's cube lists bottom,
    // top, then the sides, so the sides are at 2..5 here.)
    let text = "Lot --> s(3,3,3) primitiveCube() print(comp(f) { side = geometry.area > 0 })\n";
    let r = run("fn_faces", text).ok();
    assert_eq!(r.prints, vec!["(6)[false,false,true,true,true,true]"]);
}

#[test]
fn function_creates_no_shapes() {
    // The shape stays a leaf with its own geometry; comp.* of the function's
    // components do not leak out.
    let text = "Lot --> extrude(2) print(comp(f) { all : geometry.area }) print(\"[\" + comp.sel + \"]\")\n";
    let r = run("fn_no_shapes", text).ok();
    assert_eq!(r.prints, vec!["(6)[600,600,40,60,40,60]", "[]"]);
    assert_eq!(r.meshes.len(), 1);
    assert_eq!(r.meshes[0].faces.len(), 6);
}

#[test]
fn nothing_selected_gives_zeros() {
    let text = "Lot --> extrude(2) print(comp(f) { isTagged(\"x\") : 1 })\n";
    let r = run("fn_nothing", text).ok();
    assert_eq!(r.prints, vec!["(6)[0,0,0,0,0,0]"]);
}

#[test]
fn mixed_types_are_an_error() {
    let text = "Lot --> extrude(2) print(comp(f) { top : 1 | all : \"x\" })\n";
    let r = run("fn_mixed", text);
    assert!(r.error.unwrap().contains("same type"));
    let text = "Lot --> extrude(2) print(comp(f) { top : [1, 2] })\n";
    let r = run("fn_array_value", text);
    assert!(r.error.unwrap().contains("float, string or bool"));
}
