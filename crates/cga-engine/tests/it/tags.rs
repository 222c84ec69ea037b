//! Component tags: the examples of cga_componentTags.md, op_tag.md,
//! op_deleteTags.md, the isTagged sections of op_comp.md, geometry.tags and
//! geometry.hasTags (func_geometry.md), and the auto-tags of extrude,
//! envelope, taper, the roofs and setback.

use std::collections::BTreeMap;

use crate::ops_common::*;
use cga_engine::lot::Lot;
use cga_geometry::{DVec3, Mesh};

/// `P(name)` prints the name and the area of the component; `E(name)` the
/// name and the length of an edge component (its scope's x size), `V(name)`
/// the name and the vertex position.
const PRINTERS: &str = r#"
P(n) --> print(n + " " + geometry.area)
E(n) --> print(n + " " + scope.sx)
V(n) --> print(n + " " + pivot.px + " " + pivot.py + " " + pivot.pz)
"#;

/// The prints grouped by their first word: name -> the numbers after it,
/// one list per print.
fn by_name(g: &Gen) -> BTreeMap<String, Vec<Vec<f64>>> {
    let mut m: BTreeMap<String, Vec<Vec<f64>>> = BTreeMap::new();
    for line in g.prints() {
        let (name, rest) = line.split_once(' ').unwrap_or((&line, ""));
        m.entry(name.to_string()).or_default().push(numbers(rest));
    }
    m
}

fn run(body: &str) -> BTreeMap<String, Vec<Vec<f64>>> {
    run_on(body, &Opts::default())
}

fn run_on(body: &str, opts: &Opts) -> BTreeMap<String, Vec<Vec<f64>>> {
    let opts = opts.clone().start("Init");
    by_name(&gen_with(&format!("{body}\n{PRINTERS}"), &opts).ok())
}

/// The first number of every print of `name`, sorted.
fn firsts(m: &BTreeMap<String, Vec<Vec<f64>>>, name: &str) -> Vec<f64> {
    let mut v: Vec<f64> = m
        .get(name)
        .map(|l| l.iter().map(|x| x[0]).collect())
        .unwrap_or_default();
    v.sort_by(f64::total_cmp);
    v
}

fn count(m: &BTreeMap<String, Vec<Vec<f64>>>, name: &str) -> usize {
    m.get(name).map_or(0, Vec::len)
}

/// A 20 x 30 lot with a 10 x 10 hole in its middle.
fn holed_lot() -> Opts {
    let p = |x: f64, z: f64| DVec3::new(x, 0.0, z);
    let mut mesh = Mesh::new();
    mesh.positions = vec![
        p(0.0, 0.0),
        p(20.0, 0.0),
        p(20.0, -30.0),
        p(0.0, -30.0),
        // The hole, clockwise seen from above.
        p(5.0, -10.0),
        p(5.0, -20.0),
        p(15.0, -20.0),
        p(15.0, -10.0),
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

const EXTRUDE_TAGS: &str = r#"Init -->
    extrude(4)
    comp(f) { isTagged("extrude.bottom")     : P("bottom")
            | isTagged("extrude.side.outer") : P("outer")
            | isTagged("extrude.side.inner") : P("inner")
            | isTagged("extrude.top")        : P("top") }"#;

#[test]
fn extrude_auto_tags() {
    let m = run(EXTRUDE_TAGS);
    assert_eq!(firsts(&m, "bottom"), [600.0]);
    assert_eq!(firsts(&m, "top"), [600.0]);
    assert_eq!(firsts(&m, "outer"), [80.0, 80.0, 120.0, 120.0]);
    assert_eq!(count(&m, "inner"), 0);
}

#[test]
fn extrude_auto_tags_of_a_lot_with_a_hole() {
    let m = run_on(EXTRUDE_TAGS, &holed_lot());
    assert_eq!(firsts(&m, "bottom"), [500.0]);
    assert_eq!(firsts(&m, "top"), [500.0]);
    assert_eq!(firsts(&m, "outer"), [80.0, 80.0, 120.0, 120.0]);
    assert_eq!(firsts(&m, "inner"), [40.0; 4]);
}

#[test]
fn extrude_auto_tags_colour_the_faces() {
    // The colour rules of the reference's examples.
    let g = gen_with(
        r##"Init -->
    extrude(4)
    comp(f) { isTagged("extrude.bottom")    : Blue
            | isTagged("extrude.side.outer"): Yellow
            | isTagged("extrude.side.inner"): Red
            | isTagged("extrude.top")       : Green }
Blue   --> color("#0399F5")
Green  --> color("#09DE1F")
Yellow --> color("#FADB19")
Red    --> color("#FF360A")
"##,
        &Opts::default().start("Init"),
    )
    .ok();
    let mut colours: Vec<[u8; 3]> = g.face_materials().iter().map(|m| rgb255(m)).collect();
    colours.sort();
    let (blue, green, yellow) = ([3, 153, 245], [9, 222, 31], [250, 219, 25]);
    let mut expect = vec![blue, green, yellow, yellow, yellow, yellow];
    expect.sort();
    assert_eq!(colours, expect);
}

#[test]
fn extrude_again_replaces_its_auto_tags() {
    // The top of the first extrusion, extruded again: its faces carry the
    // second extrusion's tags only (the first's are replaced).
    let m = run(r#"Init --> extrude(4) comp(f) { top : X }
X --> extrude(2)
    comp(f) { isTagged("extrude.top") && isTagged("extrude.bottom") : P("both")
            | isTagged("extrude.top")    : P("top")
            | isTagged("extrude.bottom") : P("bottom")
            | isTagged("extrude.side")   : P("side") }"#);
    assert_eq!(count(&m, "both"), 0);
    assert_eq!(firsts(&m, "top"), [600.0]);
    assert_eq!(firsts(&m, "bottom"), [600.0]);
    assert_eq!(firsts(&m, "side"), [40.0, 40.0, 60.0, 60.0]);
}

const ENVELOPE: &str = "envelope(normal, 4, 2.5, 45, 3, 45, 2, 50, 2, 50)";

#[test]
fn envelope_auto_tags() {
    let m = run(&format!(
        r#"Init --> {ENVELOPE}
    comp(f) {{ isTagged("envelope.bottom")     : P("bottom")
             | isTagged("envelope.side.base")  : P("base")
             | isTagged("envelope.side.slope") : P("slope")
             | isTagged("envelope.side.inner") : P("inner")
             | isTagged("envelope.top")        : P("top")
             | all                             : P("untagged") }}"#
    ));
    assert_eq!(firsts(&m, "bottom"), [600.0]);
    // Base walls: front 2.5, back 3, sides 2 m high (20 and 30 m long).
    let base = firsts(&m, "base");
    assert_eq!(base.len(), 4);
    assert_near(base[3], 60.0, 1e-9);
    assert_eq!(count(&m, "slope"), 4);
    assert_eq!(count(&m, "top"), 1);
    assert_eq!(count(&m, "inner"), 0);
    assert_eq!(count(&m, "untagged"), 0);
    // "envelope.side" selects base and slope faces at once.
    let all = run(&format!(
        r#"Init --> {ENVELOPE} comp(f) {{ isTagged("envelope.side") : P("side") | all : P("other") }}"#
    ));
    assert_eq!(count(&all, "side"), 8);
    assert_eq!(count(&all, "other"), 2);
}

#[test]
fn envelope_side_inner_on_a_lot_with_a_hole() {
    let m = run_on(
        &format!(
            r#"Init --> {ENVELOPE}
    comp(f) {{ isTagged("envelope.side.inner") : P("inner") | isTagged("envelope.bottom") : P("bottom") }}"#
        ),
        &holed_lot(),
    );
    assert_eq!(firsts(&m, "bottom"), [500.0]);
    // A base wall and a slope on each of the hole's 4 edges.
    assert_eq!(count(&m, "inner"), 8);
}

/// The envelope of the isTagged examples of op_comp.md (front base 0).
const COMP_ENVELOPE: &str = "envelope(normal,4, 0,45, 3,45, 2.5,50, 2,50)";

#[test]
fn is_tagged_edges_and_vertices_of_a_tagged_face() {
    // Edges of the face tagged "envelope.top"; then its vertices.
    let m = run(&format!(
        r#"Init --> {COMP_ENVELOPE} T
T --> comp(f) {{ isTagged("envelope.top") : P("top") }}
      comp(e) {{ isTagged("envelope.top") : E("edge") }}
      comp(v) {{ isTagged("envelope.top") : V("vertex") }}"#
    ));
    assert_eq!(count(&m, "top"), 1);
    // The top face is a quadrilateral (the roof flat at max height).
    assert_eq!(count(&m, "edge"), 4);
    assert_eq!(count(&m, "vertex"), 4);
    for v in &m["vertex"] {
        assert_near(v[1], 4.0, 1e-9);
    }
}

#[test]
fn is_tagged_with_subcomponents() {
    // Faces sharing an edge with the bottom face (and the bottom itself):
    // with front base 0 the front slope touches the bottom, the other
    // three sides touch it with their base walls.
    let m = run(&format!(
        r#"Init --> {COMP_ENVELOPE}
    comp(f) {{ isTagged("envelope.bottom", e) : P("adjacent") | all : P("other") }}"#
    ));
    assert_eq!(count(&m, "adjacent"), 5);
    let m = run(&format!(
        r#"Init --> {COMP_ENVELOPE}
    comp(f) {{ isTagged("envelope.bottom", e) && isTagged("envelope.side.slope") : P("slope") }}"#
    ));
    assert_eq!(count(&m, "slope"), 1);
    // The front slope: 20 m along the front edge.
    let m = run(&format!(
        r#"Init --> {COMP_ENVELOPE}
    comp(e) {{ isTagged("envelope.bottom", v) : E("edge") | all : E("other") }}"#
    ));
    // The bottom's 4 edges, and the 4 edges rising from its corners: the
    // front slope's (45 degrees up to the 2 m side walls: 2 sqrt 2 long)
    // and the back's base walls (2 m).
    let edges = firsts(&m, "edge");
    assert_all_near(
        &edges,
        &[2.0, 2.0, 8f64.sqrt(), 8f64.sqrt(), 20.0, 20.0, 30.0, 30.0],
        1e-9,
    );
    // Edges with both ends off the ground are not selected.
    assert_eq!(count(&m, "other"), 19);
    // Default: an edge matches by the tags of its faces only.
    let m = run(&format!(
        r#"Init --> {COMP_ENVELOPE}
    comp(e) {{ isTagged("envelope.bottom") : E("edge") }}"#
    ));
    assert_eq!(firsts(&m, "edge"), [20.0, 20.0, 30.0, 30.0]);
}

#[test]
fn taper_auto_tags() {
    let m = run(r#"Init --> taper(4)
    comp(f) { isTagged("taper.bottom") : P("bottom") | isTagged("taper.side") : P("side") | all : P("other") }"#);
    assert_eq!(firsts(&m, "bottom"), [600.0]);
    assert_eq!(count(&m, "side"), 4);
    assert_eq!(count(&m, "other"), 0);
}

const ROOF_TAGS_1: &str = r#"
RoofAutoTags1 -->
    comp(f) { isTagged("roof.bottom") : P("bottom")
            | isTagged("roof.side")   : P("side")
            | isTagged("roof.top")    : P("top")
            | all                     : P("other") }"#;

const ROOF_TAGS_2: &str = r#"
RoofAutoTags2 -->
    comp(f) { isTagged("roof.bottom")     : P("bottom")
            | isTagged("roof.side.outer") : P("outer")
            | isTagged("roof.side.inner") : P("inner")
            | isTagged("roof.top")        : P("top")
            | all                         : P("other") }"#;

#[test]
fn roof_gable_hip_pyramid_auto_tags() {
    let m = run(&format!(
        "Init --> roofGable(byHeight, 4) RoofAutoTags1\n{ROOF_TAGS_1}"
    ));
    assert_eq!(firsts(&m, "bottom"), [600.0]);
    // Two gable triangles (20 m wide, 4 m high) and two roof planes.
    assert_eq!(firsts(&m, "side"), [40.0, 40.0]);
    assert_eq!(count(&m, "top"), 2);
    assert_eq!(count(&m, "other"), 0);
    for op in ["roofHip", "roofPyramid"] {
        let m = run(&format!(
            "Init --> {op}(byHeight, 4) RoofAutoTags1\n{ROOF_TAGS_1}"
        ));
        assert_eq!(firsts(&m, "bottom"), [600.0], "{op}");
        assert_eq!(count(&m, "side"), 0, "{op}");
        assert_eq!(count(&m, "top"), 4, "{op}");
        assert_eq!(count(&m, "other"), 0, "{op}");
    }
}

#[test]
fn roof_ridge_and_shed_auto_tags() {
    let m = run(&format!(
        "Init --> roofShed(byHeight, 4) RoofAutoTags2\n{ROOF_TAGS_2}"
    ));
    assert_eq!(firsts(&m, "bottom"), [600.0]);
    assert_eq!(count(&m, "top"), 1);
    assert_eq!(count(&m, "inner"), 0);
    assert_eq!(count(&m, "other"), 0);
    // The shed rises from the front edge: two triangles and the back wall.
    assert_eq!(count(&m, "outer"), 3);
    let m = run_on(
        &format!("Init --> roofRidge(byHeight, 4) RoofAutoTags2\n{ROOF_TAGS_2}"),
        &holed_lot(),
    );
    assert_eq!(firsts(&m, "bottom"), [500.0]);
    // Two outer side walls (60 m2 each), one wall per hole edge inside.
    assert_eq!(firsts(&m, "outer"), [60.0, 60.0]);
    assert_eq!(count(&m, "inner"), 4);
    assert_eq!(count(&m, "top"), 2);
    assert_eq!(count(&m, "other"), 0);
}

#[test]
fn setback_edge_auto_tags_of_the_shape() {
    let m = run(r#"Init --> setback(4) { front : ShapeAutoTags }
ShapeAutoTags -->
    comp(e) { isTagged("setback.front") : E("front")
            | isTagged("setback.side")  : E("side")
            | isTagged("setback.back")  : E("back") }"#);
    // The front strip is a 20 x 4 rectangle (the other edges stay).
    assert_eq!(firsts(&m, "front"), [20.0]);
    assert_eq!(firsts(&m, "back"), [20.0]);
    assert_eq!(firsts(&m, "side"), [4.0, 4.0]);
}

#[test]
fn setback_edge_auto_tags_of_the_remainder() {
    let m = run(
        r#"Init --> setback(4) { front : NIL | remainder : RemainderAutoTags }
RemainderAutoTags -->
    comp(e) { isTagged("setback.side")      : E("side")
            | isTagged("setback.back")      : E("back")
            | isTagged("setback.remainder") : E("remainder") }"#,
    );
    assert_eq!(firsts(&m, "back"), [20.0]);
    assert_eq!(firsts(&m, "side"), [26.0, 26.0]);
    assert_eq!(firsts(&m, "remainder"), [20.0]);
}

#[test]
fn setback_selects_edges_by_tags() {
    // Edge tags as setback selectors: the tagged edge (the front) is set
    // back; tags stay on the geometry and are copied to the setback edges.
    let m = run(r#"Init --> split(z) { 10 : X | ~1 : Y }
X --> tag("Front", edges) setback(2) { isTagged("Front") : Strip | remainder : Rest }
Y --> NIL
Strip --> P("strip") comp(e) { isTagged("Front") : E("front") }
Rest --> P("rest")"#);
    // Every edge of the 20 x 10 piece is tagged: the whole border goes.
    assert_eq!(count(&m, "strip"), 4);
    let rest = firsts(&m, "rest");
    assert_eq!(rest.len(), 1);
    assert_near(rest[0], 16.0 * 6.0, 1e-9);
    // Each strip's front and back edges come from a tagged edge.
    assert_eq!(count(&m, "front"), 8);
}

#[test]
fn split_keeps_face_edge_and_vertex_tags() {
    // roofGable's face tags, plus edge and vertex tags, kept through
    // split; the new cap faces, cut edges and cut vertices get none.
    let m = run(r#"Init -->
    roofGable(byHeight, 4)
    tag("EdgeTag", edges)
    tag("VertexTag", vertices)
    split(x) { '0.25: VisualizeTags }*
VisualizeTags -->
    comp(f) { isTagged("roof") : P("tagged") | all : P("cap") }
    comp(e) { isTagged("EdgeTag") : E("edge") | all : E("newedge") }
    comp(v) { isTagged("VertexTag") : V("vertex") | all : V("newvertex") }"#);
    // Four pieces; each has two cap faces (none at the lot's ends: the
    // outer pieces have one).
    assert_eq!(count(&m, "cap"), 6);
    // Tagged vertices are the roof's original corners only: 4 eave corners
    // (x = 0 and 20) and the 2 ridge ends (x = 10, on the middle cut: in
    // both pieces there).
    assert_eq!(count(&m, "vertex"), 8);
    for v in &m["vertex"] {
        assert!(
            [0.0, 10.0, 20.0].iter().any(|c| (v[0] - c).abs() < 1e-9),
            "{v:?}"
        );
    }
    assert_eq!(
        m["vertex"]
            .iter()
            .filter(|v| (v[0] - 10.0).abs() < 1e-9)
            .count(),
        4
    );
    // New vertices lie on the cut planes x = 5, 10, 15.
    for v in &m["newvertex"] {
        let x = v[0];
        assert!(
            [5.0, 10.0, 15.0].iter().any(|c| (x - c).abs() < 1e-9),
            "{v:?}"
        );
    }
    // Every piece of an original edge keeps its tag: 30 m long, the 2
    // eaves along z (in the outer pieces) and the ridge (on the cut at
    // x = 10: in both middle pieces); 5 m long, the pieces of the front
    // and back eaves. Edges along the cuts have none.
    let edges = firsts(&m, "edge");
    assert_eq!(edges.iter().filter(|&&l| l == 30.0).count(), 4, "{edges:?}");
    assert_eq!(edges.iter().filter(|&&l| l == 5.0).count(), 8, "{edges:?}");
    assert!(count(&m, "newedge") > 0);
}

#[test]
fn new_faces_keep_their_source_face_tags() {
    // roofGable then extrude(1): every face has both roof and extrude tags.
    let m = run(r#"Init --> roofGable(byHeight, 4) extrude(1)
    comp(f) { isTagged("roof") && isTagged("extrude") : P("both") | all : P("other") }"#);
    // 5 roof faces (bottom, 2 gables, 2 planes), each extruded into a
    // bottom, a top and one side per edge (4 + 3 + 3 + 4 + 4 sides): 28.
    assert_eq!(count(&m, "both"), 28);
    assert_eq!(count(&m, "other"), 0);
}

#[test]
fn extrude_propagates_edge_and_vertex_tags() {
    // A side face emanates from a tagged edge and gets its tags; vertical
    // edges emanate from tagged vertices and get theirs.
    let m = run(r#"Init --> comp(f) { 0 : A }
A --> tag("e.A", edges) tag("v.A", vertices) extrude(4) Show
Show -->
    comp(f) { geometry.hasTags("e.A", faces) : P("side") | all : P("cap") }
    comp(e) { geometry.hasTags("e.A", edges) : E("edge")
            | geometry.hasTags("v.A", edges) : E("vertical") }
    comp(v) { geometry.hasTags("v.A", vertices) : V("vertex") }"#);
    assert_eq!(firsts(&m, "side"), [80.0, 80.0, 120.0, 120.0]);
    assert_eq!(firsts(&m, "cap"), [600.0, 600.0]);
    assert_eq!(
        firsts(&m, "edge"),
        [20.0, 20.0, 20.0, 20.0, 30.0, 30.0, 30.0, 30.0]
    );
    assert_eq!(firsts(&m, "vertical"), [4.0; 4]);
    assert_eq!(count(&m, "vertex"), 8);
}

#[test]
fn tag_names_and_wildcard_queries() {
    let m = run(r#"Init --> extrude(4)
    comp(f) { front : tag("Facade.Front") X | back : tag("Facade.Back.Left") X | all : tag("Ro*of?") X }
X --> comp(f) { isTagged("?.Front")       : P("oneFront") }
      comp(f) { isTagged("Facade")        : P("facade") }
      comp(f) { isTagged("Facade.*.Left") : P("deepLeft") }
      comp(f) { isTagged("*.Left")        : P("starLeft") }
      comp(f) { isTagged("?.Left")        : P("oneLeft") }
      comp(f) { isTagged("Facade.Back.Left.X") : P("deeper") }
      comp(f) { isTagged("Roof")          : P("roof") }
      comp(f) { isTagged("*")             : P("any") }"#);
    assert_eq!(firsts(&m, "oneFront"), [80.0]);
    assert_eq!(firsts(&m, "facade"), [80.0, 80.0]);
    assert_eq!(firsts(&m, "deepLeft"), [80.0]);
    assert_eq!(firsts(&m, "starLeft"), [80.0]);
    assert_eq!(count(&m, "oneLeft"), 0);
    assert_eq!(count(&m, "deeper"), 0);
    // "Ro*of?" is stored as "Roof": on the sides, the top and the bottom.
    assert_eq!(firsts(&m, "roof"), [120.0, 120.0, 600.0, 600.0]);
    assert_eq!(count(&m, "any"), 6);
}

#[test]
fn geometry_tags_and_has_tags() {
    let g = gen_with(
        r#"Init --> extrude(4) comp(f) { front : tag("Facade.Front") X }
X --> print(geometry.tags)
      print(geometry.tags("extrude"))
      print(geometry.tags("Facade", faces))
      print(geometry.tags("Facade", edges))
      print(geometry.hasTags)
      print(geometry.hasTags("extrude.top"))
      print(geometry.hasTags("extrude.side", faces))
      print(geometry.hasTags("extrude", vertices))
      tag("E", edges)
      print(geometry.tags("", edges))
      print(geometry.hasTags("E", edges))
      deleteTags()
      print(geometry.hasTags)
      print(geometry.tags)"#,
        &Opts::default().start("Init"),
    )
    .ok();
    assert_eq!(
        g.prints(),
        [
            "(2)[Facade.Front,extrude.side.outer]",
            "(1)[extrude.side.outer]",
            "(1)[Facade.Front]",
            "(0)[]",
            "true",
            "false",
            "true",
            "false",
            "(1)[E]",
            "true",
            "false",
            "(0)[]",
        ]
    );
}

#[test]
fn delete_tags_by_query_and_component() {
    let body = |del: &str| {
        run(&format!(
            r#"Init --> extrude(4) tag("EdgeTag", edges) tag("Mine") {del}
    comp(f) {{ isTagged("extrude.side") : P("side") | isTagged("extrude") : P("cap") | isTagged("Mine") : P("mine") | all : P("none") }}
    comp(e) {{ isTagged("EdgeTag") : E("edge") }}"#
        ))
    };
    let m = body("");
    assert_eq!(
        (count(&m, "side"), count(&m, "cap"), count(&m, "edge")),
        (4, 2, 12)
    );
    // All tags of all components.
    let m = body("deleteTags()");
    assert_eq!((count(&m, "none"), count(&m, "edge")), (6, 0));
    // Only the side tags: sides keep "Mine".
    let m = body(r#"deleteTags("extrude.side")"#);
    assert_eq!(
        (count(&m, "side"), count(&m, "cap"), count(&m, "mine")),
        (0, 2, 4)
    );
    assert_eq!(count(&m, "edge"), 12);
    // Only face tags: edges keep theirs.
    let m = body(r#"deleteTags("*", faces)"#);
    assert_eq!((count(&m, "none"), count(&m, "edge")), (6, 12));
    // Only edge tags.
    let m = body(r#"deleteTags("EdgeTag", edges)"#);
    assert_eq!(
        (count(&m, "side"), count(&m, "cap"), count(&m, "edge")),
        (4, 2, 0)
    );
    // A query matching nothing deletes nothing.
    let m = body(r#"deleteTags("Facade", all)"#);
    assert_eq!(
        (count(&m, "side"), count(&m, "cap"), count(&m, "edge")),
        (4, 2, 12)
    );
}

#[test]
fn is_tagged_edges_and_vertices_by_their_own_tags() {
    let m = run(r#"Init --> comp(f) { 0 : A }
A --> tag("Border", edges) tag("Corner", vertices) extrude(3)
    comp(e) { isTagged("Border") : E("border") | all : E("other") }
    comp(e) { geometry.hasTags("Border", edges) : E("own") | all : E("vertical") }
    comp(v) { isTagged("Corner") : V("corner") | all : V("plain") }
    comp(f) { isTagged("Border", e) : P("byEdge") | all : P("none") }"#);
    // The lot's four edges and their copies at the top (the top face is a
    // copy of the lot) keep "Border"; the vertical edges emanate from
    // vertices and carry "Corner", not "Border".
    // isTagged also matches an edge by its faces' tags: the sides carry
    // "Border" as emanating from a Border edge, so all 12 edges match.
    assert_eq!(count(&m, "border"), 12);
    assert_eq!(count(&m, "other"), 0);
    // By their own tags: the lot's edges and their copies at the top; the
    // vertical edges emanate from vertices and carry "Corner" instead.
    assert_eq!(
        firsts(&m, "own"),
        [20.0, 20.0, 20.0, 20.0, 30.0, 30.0, 30.0, 30.0]
    );
    assert_eq!(firsts(&m, "vertical"), [3.0; 4]);
    assert_eq!(count(&m, "corner"), 8);
    // Every face has a Border edge (sides too: they are tagged as
    // emanating from a Border edge).
    assert_eq!(count(&m, "byEdge"), 6);
}

#[test]
fn operations_replacing_the_geometry_clear_tags() {
    for op in [
        "primitiveCube()",
        "resetGeometry()",
        "primitiveQuad()",
        "splitArea(x) { '0.5 : X | '0.5 : X }",
    ] {
        let next = if op.starts_with("splitArea") { "" } else { "X" };
        let prints = gen_with(
            &format!(
                "Init --> extrude(4) tag(\"Mine\") tag(\"E\", edges) {op} {next}\nX --> print(geometry.hasTags)"
            ),
            &Opts::default().start("Init"),
        )
        .ok()
        .prints();
        assert!(!prints.is_empty(), "{op}");
        assert!(prints.iter().all(|p| p == "false"), "{op}: {prints:?}");
    }
    // Operations changing the geometry keep them.
    for op in [
        "t(1,0,0)",
        "s(5,5,5)",
        "cleanupGeometry(all, 0)",
        "convexify()",
        "trim()",
    ] {
        let prints = gen_with(
            &format!("Init --> extrude(4) tag(\"Mine\") {op} print(geometry.hasTags(\"Mine\"))"),
            &Opts::default().start("Init"),
        )
        .ok()
        .prints();
        assert_eq!(prints, ["true"], "{op}");
    }
}

#[test]
fn cleanup_keeps_tagged_edges() {
    // After the cleanup example of cga_componentTags.md: after offset the
    // edges between the strips and the inside carry the tags of the lot
    // edges they come from, so cleanupGeometry cannot join the inside to
    // the strips; once those tags are deleted it can.
    let faces = |body: &str| {
        gen_with(
            &format!("Init --> {body} print(geometry.nFaces)"),
            &Opts::default().start("Init"),
        )
        .ok()
        .prints()
    };
    let untagged = faces("offset(-2) cleanupGeometry(edges, 0)");
    assert_ne!(untagged, ["5"]);
    assert_eq!(faces(r#"tag("E", edges) offset(-2)"#), ["5"]);
    // The strips still join each other across their untagged mitre edges
    // (which emanate from the lot's untagged corners): one ring and the
    // inside remain.
    assert_eq!(
        faces(r#"tag("E", edges) offset(-2) cleanupGeometry(edges, 0)"#),
        ["2"]
    );
    assert_eq!(
        faces(r#"tag("E", edges) offset(-2) deleteTags("E", edges) cleanupGeometry(edges, 0)"#),
        untagged
    );
}
