//! Edge, face edge, vertex and face vertex component splits, and the roof
//! edge selectors (op_comp.md "Edge Split Details", "Vertex Split Details",
//! "Roof Edges", "Border and Inside Selectors").

use crate::comp_support::*;
use cga_engine::lot::rect;
use cga_geometry::DVec3;

const SHOW: &str = r#"
Show(tag) --> print(tag + " " + scope.sx + " " + scope.sy + " " + scope.sz + " "
                    + pivot.px + " " + pivot.py + " " + pivot.pz)
"#;

#[test]
fn edges_of_an_extruded_lot_in_index_order() {
    // Index 0 is the first edge of the first face (the bottom), shared
    // edges are skipped on their second encounter: 12 edges.
    let text = format!("Lot --> extrude(3) comp(e) {{ all : Show(\"e\" + comp.index) }}\n{SHOW}");
    let r = run("edges_order", &text).ok();
    let lengths: Vec<f64> = (0..12)
        .map(|i| r.numbers(&format!("e{i} "))[0][0])
        .collect();
    assert_eq!(
        lengths,
        vec![20.0, 30.0, 20.0, 30.0, 20.0, 30.0, 20.0, 30.0, 3.0, 3.0, 3.0, 3.0]
    );
    // Scope (length, 0, 0); the bottom's first edge runs from (20,0,0) to
    // the origin (the bottom is the lot reversed, from its second corner).
    assert_close(
        &r.numbers("e0 "),
        &[&[20.0, 0.0, 0.0, 20.0, 0.0, 0.0]],
        1e-9,
    );
    // The front-right vertical edge starts on the ground.
    assert_close(&r.numbers("e8 "), &[&[3.0, 0.0, 0.0, 20.0, 0.0, 0.0]], 1e-9);
}

#[test]
fn edge_frame_follows_the_edge_and_the_average_normal() {
    // op_comp.md "Edge Split Details": x along the edge, z the average of
    // the neighbouring face normals; here the front-right vertical edge
    // (between the front, +z, and the right side, +x).
    let text = "Lot --> extrude(3) comp(e) { 8 : s('1, 0.5, 0.5) primitiveCube() }\n";
    let r = run("edge_frame", text).ok();
    let (lo, hi) = bbox(&r.meshes[0]);
    let h = 0.5 * std::f64::consts::FRAC_1_SQRT_2;
    // y = z × x = (-1, 0, 1)/√2, so the cube spans x ∈ [20 - h, 20 + h], z ∈ [0, 2h].
    assert!(
        (lo - DVec3::new(20.0 - h, 0.0, 0.0)).length() < 1e-9,
        "{lo:?}"
    );
    assert!(
        (hi - DVec3::new(20.0 + h, 3.0, 2.0 * h)).length() < 1e-9,
        "{hi:?}"
    );
}

#[test]
fn vertical_edges_for_pipes() {
    // The Candler building's PipeEdges: comp(e) { vertical : ... } on an
    // extruded polygon takes the four corner edges (their normals are horizontal).
    let text = "Lot --> extrude(0.7) comp(e) { vertical : P | aslant = Q | nutant = R }\nP --> print(\"v \" + scope.sx)\nQ --> print(\"a \" + geometry.nEdges)\nR --> print(\"n \" + geometry.nEdges)\n";
    let r = run("vertical_edges", text).ok();
    assert_eq!(
        r.prints,
        vec!["v 0.7", "v 0.7", "v 0.7", "v 0.7", "a 4", "n 4"]
    );
}

#[test]
fn border_and_inside_edges_and_vertices() {
    // op_comp.md "Border and Inside Selectors": a 3 x 3 grid has 12 border
    // and 12 inside edges, 12 border and 4 inside vertices.
    let text = r#"Lot --> comp(e) { border : P("EBorder") | inside : P("EInside") }
V --> comp(v) { border : P("VBorder") | inside : P("VInside") }
P(t) --> print(t + " " + comp.total)
"#;
    let r = run_on("border_edges", text, &grid_lot(), "Lot").ok();
    assert_eq!(r.lines("EBorder").len(), 12);
    assert_eq!(r.lines("EBorder")[0], "12");
    assert_eq!(r.lines("EInside").len(), 12);
    let r = run_on("border_vertices", text, &grid_lot(), "V").ok();
    assert_eq!(r.lines("VBorder").len(), 12);
    assert_eq!(r.lines("VInside"), vec!["4"; 4]);
    // The seed's cubes on the inside edges: each one unit long.
    let text = r##"Init --> comp(e) { inside : EInside }
EInside --> s('1, 0.01, 0.01) t(0, '-0.5, 0) color("#00ff00") primitiveCube()
"##;
    let r = run_on("border_edge_cubes", text, &grid_lot(), "Init").ok();
    assert_eq!(r.meshes.len(), 12);
    assert!((r.volume() - 12.0 * 0.0001).abs() < 1e-12);
}

#[test]
fn vertices_in_position_order_with_averaged_normals() {
    // op_comp.md "Vertex Split Details": the pivot on the vertex, z the
    // average of the neighbouring face normals, all sizes zero.
    let text = format!(
        "Lot --> extrude(3) comp(v) {{ all : Show(\"v\" + comp.index) t(0, 0, 1) print(\"up\" + comp.index + \" \" + scope.elevation) }}\n{SHOW}"
    );
    let r = run("vertices", &text).ok();
    let mut rows = Vec::new();
    for i in 0..8 {
        rows.push(r.numbers(&format!("v{i} "))[0].clone());
    }
    assert_close(
        &rows,
        &[
            &[0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            &[0.0, 0.0, 0.0, 20.0, 0.0, 0.0],
            &[0.0, 0.0, 0.0, 20.0, 0.0, -30.0],
            &[0.0, 0.0, 0.0, 0.0, 0.0, -30.0],
            &[0.0, 0.0, 0.0, 0.0, 3.0, 0.0],
            &[0.0, 0.0, 0.0, 20.0, 3.0, 0.0],
            &[0.0, 0.0, 0.0, 20.0, 3.0, -30.0],
            &[0.0, 0.0, 0.0, 0.0, 3.0, -30.0],
        ],
        1e-9,
    );
    // A unit step along z leaves a bottom corner by -1/√3 in y, a top one by +1/√3.
    let s = 1.0 / 3f64.sqrt();
    assert_close(&r.numbers("up0 "), &[&[-s]], 1e-9);
    assert_close(&r.numbers("up4 "), &[&[3.0 + s]], 1e-9);
}

#[test]
fn face_edges_and_face_vertices_of_a_lot() {
    // Face edges: x in face orientation, y the face normal, z out of the
    // face. Face vertices: x the tangent, z out of the polygon.
    let text = r#"Lot --> comp(fe) { front : F("front") | right : F("right") | all : F("other") }
FV --> comp(fv) { all : print("fv " + comp.index + " " + scope.sx) | 0 : X }
FV0 --> comp(fv) { 0 : t(0, 0, 1) s(0.1, 0.1, 0.1) primitiveCube() }
F(t) --> print(t + " " + comp.index + " " + scope.sx + " " + pivot.px + " " + pivot.pz)
"#;
    let r = run("face_edges", text).ok();
    assert_eq!(
        r.prints,
        vec![
            "front 0 20 0 0",
            "right 0 30 20 0",
            "other 0 20 20 -30",
            "other 1 30 0 -30"
        ]
    );
    let r = run_on("face_vertices", text, &rect(20.0, 30.0), "FV").ok();
    assert_eq!(r.prints, vec!["fv 0 0", "fv 1 0", "fv 2 0", "fv 3 0"]);
    // Corner (0,0,0): x the tangent (1, 0, 1)/√2, y up, z out of the lot
    // (-1, 0, 1)/√2. A small cube one unit out along z is centred at
    // z + 0.05 (x + y + z).
    let r = run_on("face_vertex_frame", text, &rect(20.0, 30.0), "FV0").ok();
    let h = std::f64::consts::FRAC_1_SQRT_2;
    let (lo, hi) = bbox(&r.meshes[0]);
    let centre = 0.5 * (lo + hi);
    assert!(
        (centre - DVec3::new(-h, 0.05, 1.1 * h)).length() < 1e-9,
        "{centre:?}"
    );
}

#[test]
fn roof_edges_of_a_hip_roof() {
    // Eaves: the four horizontal bottom edges (anti-clockwise); hips: the
    // four edges up to the ridge (oriented upwards); the ridge.
    let text = format!(
        r#"Lot --> s(10,3,6) i("{{DIR}}/hip_roof.obj") comp(e) {{ eave : Show("eave") | hip : Show("hip") | ridge : Show("ridge") | valley : Show("valley") }}
{SHOW}"#
    );
    let r = run_on("hip_roof", &text, &rect(10.0, 6.0), "Lot").ok();
    assert_close(
        &r.numbers("eave"),
        &[
            &[10.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            &[6.0, 0.0, 0.0, 10.0, 0.0, 0.0],
            &[10.0, 0.0, 0.0, 10.0, 0.0, -6.0],
            &[6.0, 0.0, 0.0, 0.0, 0.0, -6.0],
        ],
        1e-9,
    );
    let hip = 27f64.sqrt();
    assert_close(
        &r.numbers("hip"),
        &[
            &[hip, 0.0, 0.0, 10.0, 0.0, 0.0],
            &[hip, 0.0, 0.0, 0.0, 0.0, 0.0],
            &[hip, 0.0, 0.0, 10.0, 0.0, -6.0],
            &[hip, 0.0, 0.0, 0.0, 0.0, -6.0],
        ],
        1e-9,
    );
    assert_eq!(r.numbers("ridge").len(), 1);
    assert!((r.numbers("ridge")[0][0] - 4.0).abs() < 1e-9);
    assert!(r.lines("valley").is_empty());
}

#[test]
fn valley_of_a_v_roof() {
    let text = format!(
        r#"Lot --> s(10,2,4) i("{{DIR}}/valley.obj") comp(e) {{ valley : Show("valley") | eave : Show("eave") | ridge = Show("ridge") | hip = Show("hip") }}
{SHOW}"#
    );
    let r = run_on("valley_roof", &text, &rect(10.0, 4.0), "Lot").ok();
    assert_close(
        &r.numbers("valley"),
        &[&[4.0, 0.0, 0.0, 5.0, 0.0, 0.0]],
        1e-9,
    );
    // The lowest edge is inside (the valley): no eaves; border edges are
    // neither ridges nor hips.
    assert!(r.lines("eave").is_empty());
    assert!(r.lines("ridge").is_empty());
    assert!(r.lines("hip").is_empty());
}

#[test]
fn connected_edges() {
    // `=:` on edges: connected through shared vertices. The top ring and
    // the bottom ring of a box are two sets; the vertical edges join them.
    let text = "Lot --> extrude(3) comp(e) { horizontal =: P | aslant =: P | nutant =: P }\nP --> print(comp.sel + \" \" + comp.index + \" \" + comp.total + \" \" + geometry.nEdges)\n";
    let r = run("connected_edges", text).ok();
    // Edge normals of the top ring are aslant (45 degrees up), of the bottom ring nutant.
    assert_eq!(r.prints, vec!["aslant 0 1 4", "nutant 0 1 4"]);
}

#[test]
fn seed_edge_and_vertex_examples() {
    // The seed's "Edge Split Details": a cube in every edge, scaled to
    // (length, 0.8, 0.8). The 12 edges of the 20 x 30 x 3 mass are 212 long.
    let text = "Lot --> extrude(3) comp(e) { all : primitiveCube() s('1, 0.8, 0.8) X }\n";
    let r = run("seed_edges", text).ok();
    assert_eq!(r.meshes.len(), 12);
    assert!((r.volume() - 212.0 * 0.64).abs() < 1e-9, "{}", r.volume());
    // op_comp.md's version: s('1, 0.25, 1).
    let text = "Lot --> extrude(3) comp(e) { all : primitiveCube() s('1, 0.25, 1) X. }\n";
    let r = run("ref_edges", text).ok();
    assert!((r.volume() - 212.0 * 0.25).abs() < 1e-9, "{}", r.volume());
    // The seed's "Border Selector Vertex Split": small cubes on the 12
    // border and the 4 inside vertices of the grid.
    let text = r##"Init --> comp(v) { border : VBorder | inside : VInside }
VBorder --> s(0.05, 0.05, 0.05) t(-0.025, -0.025, -0.025) color("#ff0000") primitiveCube()
VInside --> s(0.05, 0.05, 0.05) t(-0.025, -0.025, -0.025) color("#00ff00") primitiveCube()
"##;
    let r = run_on("seed_vertices", text, &grid_lot(), "Init").ok();
    assert_eq!(r.meshes.len(), 16);
    let red = r
        .meshes
        .iter()
        .filter(|m| m.materials[0].color == [1.0, 0.0, 0.0])
        .count();
    assert_eq!(red, 12);
    // Each cube is centred on its vertex.
    for m in &r.meshes {
        let (lo, hi) = bbox(m);
        let c = 0.5 * (lo + hi);
        assert!(
            (c.x - c.x.round()).abs() < 1e-9 && (c.z - c.z.round()).abs() < 1e-9,
            "{c:?}"
        );
        assert!(c.y.abs() < 1e-9, "{c:?}");
    }
}
