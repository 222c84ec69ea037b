//! Where rules run, the model must be CityEngine's: small rule files of our
//! own whose answers were measured with CityEngine's runtime (issue 15,
//! "Fidelity on real packages", and issue 22) or read from the reference
//! pages.

use crate::ops_common::*;
use cga_geometry::{measure, DVec3};

// ----- extrude by (nearly) nothing -----

/// CityEngine leaves the face as it is for |d| below about 1.8e-3
/// (absolute): one face, its 4 vertices, normal up, area 600 on
/// `rect:20,30`.
#[test]
fn extrude_by_nearly_nothing_keeps_the_face() {
    for d in ["0", "0.001", "-0.001", "0.0017"] {
        let g = gen(&format!(
            "Lot --> extrude({d}) print(geometry.nFaces) print(geometry.nVertices) X\n"
        ))
        .ok();
        assert_eq!(g.prints(), ["1", "4"], "extrude({d})");
        assert_eq!(g.meshes().len(), 1);
        let m = &g.meshes()[0];
        assert_eq!(m.faces.len(), 1);
        assert_near(measure::mesh_area(m), 600.0, 1e-9);
        assert_vec_near(measure::face_normal(m, 0), [0.0, 1.0, 0.0], 1e-12);
    }
    // The threshold is absolute: on a 2 x 3 lot as on a 200 x 300 one.
    for (w, d) in [(2.0, 3.0), (200.0, 300.0)] {
        let g = gen_with("Lot --> extrude(0.0015) X\n", &Opts::rect(w, d)).ok();
        assert_eq!(g.meshes()[0].faces.len(), 1);
        assert_near(g.area(), w * d, 1e-6);
    }
    // Above it: a box of six faces.
    let g = gen("Lot --> extrude(0.002) print(geometry.nFaces) X\n").ok();
    assert_eq!(g.prints(), ["6"]);
    assert_near(g.area(), 1200.0 + 0.002 * 100.0, 1e-9);
}

// ----- roof overhangs -----

/// `roofGable(30, 0, -2)` on `rect:20,30`: the gable ends are pulled in by
/// 2 (measured horizontally); roof planes from z = -28 to -2, area 600.444.
#[test]
fn negative_gable_overhang_pulls_the_gable_ends_in() {
    let g = gen("Lot --> roofGable(30, 0, -2) comp(f){ top : X. | all : NIL }\n").ok();
    assert_near(g.area(), 600.444, 1e-3);
    let (lo, hi) = g.bounds();
    assert_near(lo.z, -28.0, 1e-9);
    assert_near(hi.z, -2.0, 1e-9);
    assert_near(lo.x, 0.0, 1e-9);
    assert_near(hi.x, 20.0, 1e-9);
    // The exact figure: two planes 26 long, 10 / cos 30 wide.
    let exact = 2.0 * 26.0 * 10.0 / 30f64.to_radians().cos();
    assert_near(g.area(), exact, 1e-9);
}

/// A negative `overhangX` pulls the eaves in along the roof planes (they
/// stay in their planes, so they rise); a negative hip overhang likewise.
#[test]
fn negative_eave_and_hip_overhangs_pull_the_roof_in() {
    let g = gen("Lot --> roofGable(30, -1, 0) comp(f){ top : X. | all : NIL }\n").ok();
    let (lo, hi) = g.bounds();
    let c = 30f64.to_radians().cos();
    assert_near(lo.x, c, 1e-9);
    assert_near(hi.x, 20.0 - c, 1e-9);
    assert_near(lo.y, 30f64.to_radians().sin(), 1e-9);
    assert_near(g.area(), 2.0 * 30.0 * (10.0 / c - 1.0), 1e-9);

    let g = gen("Lot --> roofHip(45, -1) comp(f){ top : X. | all : NIL }\n").ok();
    let (lo, hi) = g.bounds();
    let c = 45f64.to_radians().cos();
    assert_near(lo.x, c, 1e-9);
    assert_near(hi.x, 20.0 - c, 1e-9);
    assert_near(hi.z, -c, 1e-9);
    assert_near(lo.z, -30.0 + c, 1e-9);
    // The planes cover the inner 18.586 x 28.586 rectangle, at 45 degrees.
    let inner = (20.0 - 2.0 * c) * (30.0 - 2.0 * c);
    assert_near(g.area(), inner / c, 1e-6);

    // Pulled in past the roof itself: no roof planes, a warning.
    let g = gen("Lot --> roofHip(45, -20) comp(f){ top : X. | all : NIL }\n").ok();
    assert_eq!(g.meshes().len(), 0);
    assert!(
        g.warnings().iter().any(|w| w.contains("roofHip")),
        "{:?}",
        g.warnings()
    );
}

// ----- innerRectangle(edge) keeps the face's edge order -----

/// The direction of the first edge of the first face of a leaf.
fn first_edge(g: &Gen) -> DVec3 {
    let m = &g.meshes()[0];
    let pts: Vec<DVec3> = m.loop_points(m.outer_loop(0)).collect();
    (pts[1] - pts[0]).normalize()
}

#[test]
fn inner_rectangle_edge_keeps_the_first_edge_direction() {
    let rule = "Lot --> innerRectangle(edge){ shape : X. | remainder : NIL }\n";
    // A rectangle in each of its 4 vertex rotations: the rectangle's first
    // edge runs like the lot's.
    let corners = [(0.0, 0.0), (20.0, 0.0), (20.0, -30.0), (0.0, -30.0)];
    for k in 0..4 {
        let p: Vec<(f64, f64)> = (0..4).map(|i| corners[(i + k) % 4]).collect();
        let lot = pts(&p);
        let g = gen_with(rule, &Opts::polygon(&lot)).ok();
        let want = (lot[1] - lot[0]).normalize();
        assert_vec_near(first_edge(&g), want.to_array(), 1e-9);
        assert_near(g.area(), 600.0, 1e-6);
    }
    // A square, and a trapezoid whose long first edge is the street.
    let square = pts(&[(0.0, 0.0), (0.0, -10.0), (-10.0, -10.0), (-10.0, 0.0)]);
    let g = gen_with(rule, &Opts::polygon(&square)).ok();
    assert_vec_near(first_edge(&g), [0.0, 0.0, -1.0], 1e-9);
    let trapezoid = pts(&[(0.0, 0.0), (30.0, 0.0), (20.0, -10.0), (10.0, -10.0)]);
    let g = gen_with(rule, &Opts::polygon(&trapezoid)).ok();
    assert_vec_near(first_edge(&g), [1.0, 0.0, 0.0], 1e-9);
    // The L: its first edge is the 12 long front.
    let g = gen_with(rule, &Opts::polygon(&l_lot())).ok();
    assert_vec_near(first_edge(&g), [1.0, 0.0, 0.0], 1e-9);
    // So a following alignScopeToGeometry(yUp, 0, world.lowest) and t move
    // along the lot's first edge.
    let lot = pts(&[(20.0, -30.0), (0.0, -30.0), (0.0, 0.0), (20.0, 0.0)]);
    let g = gen_with(
        "Lot --> innerRectangle(edge){ shape : alignScopeToGeometry(yUp, 0, world.lowest) t(1, 0, 0) X. | remainder : NIL }\n",
        &Opts::polygon(&lot),
    )
    .ok();
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [-1.0, 0.0, -30.0], 1e-9);
    assert_vec_near(hi, [19.0, 0.0, 0.0], 1e-9);
}

// ----- primitives into a zero-size scope -----

/// A primitive into a point scope keeps the asset's position, as `i()`
/// does: the unit quad is centred on the point. CityEngine puts the cube
/// centred on the lot's centre, x from 8.586 to 11.414 on `rect:20,30`.
#[test]
fn primitive_into_a_point_scope_is_centred_on_it() {
    let g = gen(
        "Lot --> alignScopeToAxes() s(0,0,0) center(xz) rotateScope(0,45,0) primitiveQuad() M\n\
         M --> s(2,1,2) center(xz) primitiveCube()\n",
    )
    .ok();
    let (lo, hi) = g.bounds();
    let h = 2f64.sqrt();
    assert_near(lo.x, 10.0 - h, 1e-9);
    assert_near(hi.x, 10.0 + h, 1e-9);
    assert_near(lo.z, -15.0 - h, 1e-9);
    assert_near(hi.z, -15.0 + h, 1e-9);
    assert_near(lo.x, 8.586, 5e-4);
    assert_near(hi.x, 11.414, 5e-4);
    // The quad itself: a unit square centred on the lot's centre.
    let g = gen("Lot --> alignScopeToAxes() s(0,0,0) center(xz) primitiveQuad() X\n").ok();
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [9.5, 0.0, -15.5], 1e-9);
    assert_vec_near(hi, [10.5, 0.0, -14.5], 1e-9);
    // A scope with sizes keeps the fit: the cube fills it.
    let g = gen("Lot --> s(4, 2, 6) primitiveCube() X\n").ok();
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [0.0, 0.0, -30.0], 1e-9);
    assert_vec_near(hi, [4.0, 2.0, -24.0], 1e-9);
}

// ----- ring primitives: vertices half a step off the axes -----

/// `primitiveCylinder(8)`: vertices at 22.5 + k 45 degrees, the flat sides
/// touching the scope: the ring fills it.
#[test]
fn cylinder_disk_and_cone_rings_fill_the_scope() {
    let g = gen("Lot --> s(10, 4, 10) primitiveCylinder(8) X\n").ok();
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [0.0, 0.0, -30.0], 1e-9);
    assert_vec_near(hi, [10.0, 4.0, -20.0], 1e-9);
    // An octagon of apothem 5: area 200 tan(22.5), volume that times 4.
    let octagon = 8.0 * 25.0 * (std::f64::consts::PI / 8.0).tan();
    assert_near(g.volume(), 4.0 * octagon, 1e-9);
    // Every vertex of the ring is 22.5 degrees off an axis.
    let m = &g.meshes()[0];
    for p in &m.positions {
        let (x, z) = (p.x - 5.0, p.z + 25.0);
        let a = z.atan2(x).to_degrees().rem_euclid(45.0);
        assert_near(a, 22.5, 1e-9);
    }
    let g = gen("Lot --> s(10, 0, 10) primitiveDisk(8) X\n").ok();
    assert_near(g.area(), octagon, 1e-9);
    let g = gen("Lot --> s(10, 3, 10) primitiveCone(8) X\n").ok();
    assert_near(g.volume(), octagon * 3.0 / 3.0, 1e-9);
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [0.0, 0.0, -30.0], 1e-9);
    assert_vec_near(hi, [10.0, 3.0, -20.0], 1e-9);
}

// ----- shapeL / shapeU / shapeO component tags -----

/// The edge lengths of a shape by setback tag, each list sorted, and its
/// `geometry.tags`.
fn luo_tags(op: &str, part: &str) -> (Vec<Vec<f64>>, String) {
    let other = if part == "shape" {
        "remainder"
    } else {
        "shape"
    };
    let g = gen(&format!(
        "Lot --> {op} {{ {part} : print(geometry.tags) T | {other} : NIL }}\n\
         T --> comp(e) {{ isTagged(\"setback.front\") : E(\"front\") | isTagged(\"setback.back\") : E(\"back\") \
         | isTagged(\"setback.side\") : E(\"side\") | isTagged(\"setback.remainder\") : E(\"remainder\") | all : E(\"none\") }}\n\
         E(n) --> print(n + \" \" + scope.sx) NIL\n"
    ))
    .ok();
    let p = g.prints();
    let mut out = vec![Vec::new(); 5];
    for line in &p[1..] {
        let (name, len) = line.split_once(' ').unwrap();
        let k = ["front", "back", "side", "remainder", "none"]
            .iter()
            .position(|n| *n == name)
            .unwrap();
        out[k].push(len.parse::<f64>().unwrap());
    }
    for v in &mut out {
        v.sort_by(f64::total_cmp);
    }
    (out, p[0].clone())
}

/// op_shapeLUO: the operations tag "exactly like the setback operation";
/// its figure: original edges in the shape `setback.front` (blue), new
/// setback edges `setback.back` (green), side edges `setback.side`
/// (yellow), original edges in the remainder `setback.remainder` (purple).
#[test]
fn shape_luo_tag_their_edges_like_setback() {
    let e = Vec::<f64>::new();
    // shapeL(4, 4) on 20 x 30: wings along the front (20) and the left (30).
    let (t, tags) = luo_tags("shapeL(4, 4)", "shape");
    assert_eq!(
        t,
        [
            vec![20.0, 30.0],
            vec![16.0, 26.0],
            vec![4.0, 4.0],
            e.clone(),
            e.clone()
        ]
    );
    for name in ["setback.front", "setback.back", "setback.side"] {
        assert!(tags.contains(name), "{tags}");
    }
    assert!(!tags.contains("setback.remainder"), "{tags}");
    let (t, tags) = luo_tags("shapeL(4, 4)", "remainder");
    assert_eq!(
        t,
        [
            e.clone(),
            vec![16.0, 26.0],
            e.clone(),
            vec![16.0, 26.0],
            e.clone()
        ]
    );
    assert!(
        tags.contains("setback.remainder") && !tags.contains("setback.side"),
        "{tags}"
    );

    // shapeU(4, 4, 4): front, right and left wings.
    let (t, _) = luo_tags("shapeU(4, 4, 4)", "shape");
    assert_eq!(
        t,
        [
            vec![20.0, 30.0, 30.0],
            vec![12.0, 26.0, 26.0],
            vec![4.0, 4.0],
            e.clone(),
            e.clone()
        ]
    );
    let (t, _) = luo_tags("shapeU(4, 4, 4)", "remainder");
    assert_eq!(
        t,
        [
            e.clone(),
            vec![12.0, 26.0, 26.0],
            e.clone(),
            vec![12.0],
            e.clone()
        ]
    );

    // shapeO(4, 4, 4, 4): a ring, its hole the new edges; no sides.
    let (t, _) = luo_tags("shapeO(4, 4, 4, 4)", "shape");
    assert_eq!(
        t,
        [
            vec![20.0, 20.0, 30.0, 30.0],
            vec![12.0, 12.0, 22.0, 22.0],
            e.clone(),
            e.clone(),
            e.clone()
        ]
    );
    let (t, _) = luo_tags("shapeO(4, 4, 4, 4)", "remainder");
    assert_eq!(
        t,
        [
            e.clone(),
            vec![12.0, 12.0, 22.0, 22.0],
            e.clone(),
            e.clone(),
            e
        ]
    );
}

// ----- random attribute defaults -----

/// Each `attr` and `const` with a random default draws its own numbers
/// (CityEngine's runtime gives `attr nFloor = ceil(rand(1,15))` and
/// `attr floorHeight = rand(4,5)` the independent draws 0.55 and 0.694 on
/// one lot): different attributes get different values, the same on every
/// run, whichever is read first, and other values on another lot.
#[test]
fn random_attribute_defaults_draw_their_own_numbers() {
    let src = |order: &str| {
        format!(
            "attr height = rand(10, 30)\nattr roofAngle = rand(20, 45)\nconst hue = rand(0, 360)\n\
             attr same = rand(10, 30)\n\
             Lot --> {order} X\n"
        )
    };
    let fwd = "print(height) print(roofAngle) print(hue) print(same)";
    let bwd = "print(same) print(hue) print(roofAngle) print(height)";
    let opts = Opts {
        lots: vec![
            cga_engine::lot::rect(20.0, 30.0),
            cga_engine::lot::rect(20.0, 30.0),
        ],
        ..Opts::default()
    };
    let values = |g: &Gen, lot: usize| -> Vec<f64> {
        g.lots[lot]
            .prints
            .iter()
            .map(|p| p.parse::<f64>().unwrap())
            .collect()
    };
    let g = gen_with(&src(fwd), &opts).ok();
    let a = values(&g, 0);
    let (h, r, c, s) = (a[0], a[1], a[2], a[3]);
    assert!((10.0..30.0).contains(&h) && (20.0..45.0).contains(&r) && (0.0..360.0).contains(&c));
    // Not one point of one stream: the draws differ ((h - 10) / 20 would
    // equal (r - 20) / 25 and c / 360 if they shared it).
    let u = [
        (h - 10.0) / 20.0,
        (r - 20.0) / 25.0,
        c / 360.0,
        (s - 10.0) / 20.0,
    ];
    for i in 0..4 {
        for j in i + 1..4 {
            assert!((u[i] - u[j]).abs() > 1e-9, "draws {i} and {j}: {u:?}");
        }
    }
    // Deterministic, and independent of the order of evaluation.
    let again = gen_with(&src(fwd), &opts).ok();
    assert_eq!(values(&again, 0), a);
    let mut b = values(&gen_with(&src(bwd), &opts).ok(), 0);
    b.reverse();
    assert_eq!(b, a);
    // Another lot (its own seed) draws other values; so does another seed.
    let other = values(&g, 1);
    assert!(other.iter().zip(&a).all(|(x, y)| x != y), "{other:?} {a:?}");
    let seeded = values(&gen_with(&src(fwd), &opts.clone().seed(5)).ok(), 0);
    assert!(seeded.iter().zip(&a).all(|(x, y)| x != y));
    // A rule's own rand() is not one of the attributes' draws either.
    let g = gen("attr height = rand(0, 1)\nLot --> print(height) print(rand(0, 1)) X\n").ok();
    let p = g.prints();
    assert_ne!(p[0], p[1]);
}

// ----- assets in every format the i() page lists -----

/// A folder holding the rule file `src` and the given asset files (made
/// here, by this test code); derives the rule on `rect:20,30`.
fn gen_with_assets(src: &str, files: &[(&str, &[u8])]) -> Gen {
    static N: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = N.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = std::env::temp_dir().join(format!("cga-fidelity-{}-{n}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for (name, bytes) in files {
        let p = dir.join(name);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, bytes).unwrap();
    }
    let path = dir.join("rules.cga");
    std::fs::write(&path, src).unwrap();
    gen_file(&path, &Opts::default())
}

/// A 2 x 1 x 3 m box written in centimetres with z up, placed by its node
/// 1 m along x: its top two triangles red, its other five faces quads of a
/// brick texture (through an effect's sampler and surface).
const BOX_DAE: &str = r##"<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="centimeter" meter="0.01"/><up_axis>Z_UP</up_axis></asset>
  <library_images><image id="brick-img"><init_from>tex/brick%20wall.png</init_from></image></library_images>
  <library_effects>
    <effect id="red-fx"><profile_COMMON><technique sid="t"><lambert>
      <diffuse><color>1 0 0 1</color></diffuse></lambert></technique></profile_COMMON></effect>
    <effect id="brick-fx"><profile_COMMON>
      <newparam sid="surf"><surface type="2D"><init_from>brick-img</init_from></surface></newparam>
      <newparam sid="samp"><sampler2D><source>surf</source></sampler2D></newparam>
      <technique sid="t"><phong><diffuse><texture texture="samp" texcoord="UV"/></diffuse></phong></technique>
    </profile_COMMON></effect>
  </library_effects>
  <library_materials>
    <material id="red" name="Red"><instance_effect url="#red-fx"/></material>
    <material id="brick" name="Brick"><instance_effect url="#brick-fx"/></material>
  </library_materials>
  <library_geometries>
    <geometry id="box" name="box"><mesh>
      <source id="pos">
        <float_array id="pos-a" count="24">0 0 0 200 0 0 200 300 0 0 300 0 0 0 100 200 0 100 200 300 100 0 300 100</float_array>
        <technique_common><accessor source="#pos-a" count="8" stride="3"/></technique_common>
      </source>
      <source id="uv">
        <float_array id="uv-a" count="8">0 0 1 0 1 1 0 1</float_array>
        <technique_common><accessor source="#uv-a" count="4" stride="2"/></technique_common>
      </source>
      <vertices id="verts"><input semantic="POSITION" source="#pos"/></vertices>
      <triangles material="top" count="2">
        <input semantic="VERTEX" source="#verts" offset="0"/>
        <input semantic="TEXCOORD" source="#uv" offset="1" set="0"/>
        <p>4 0 5 1 6 2  4 0 6 2 7 3</p>
      </triangles>
      <polylist material="walls" count="5">
        <input semantic="VERTEX" source="#verts" offset="0"/>
        <vcount>4 4 4 4 4</vcount>
        <p>0 3 2 1  0 1 5 4  1 2 6 5  2 3 7 6  3 0 4 7</p>
      </polylist>
    </mesh></geometry>
  </library_geometries>
  <library_visual_scenes><visual_scene id="scene">
    <node id="n" name="Box"><translate>100 0 0</translate>
      <instance_geometry url="#box"><bind_material><technique_common>
        <instance_material symbol="top" target="#red"/>
        <instance_material symbol="walls" target="#brick"/>
      </technique_common></bind_material></instance_geometry>
    </node>
  </visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#scene"/></scene>
</COLLADA>
"##;

#[test]
fn collada_assets_are_inserted_with_their_scene_graph_units_and_up_axis() {
    let g = gen_with_assets(
        "Lot --> i(\"box.dae\", yUp, keepSizeAndPosition) print(geometry.nFaces) X\n",
        &[("box.dae", BOX_DAE.as_bytes())],
    )
    .ok();
    assert!(g.warnings().is_empty(), "{:?}", g.warnings());
    assert_eq!(g.prints(), ["7"]);
    // Centimetres to metres, z up to y up (the file's y becomes -z), the
    // node's translation of 100 cm along x; placed at the lot's scope
    // origin (0, 0, -30).
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [1.0, 0.0, -33.0], 1e-9);
    assert_vec_near(hi, [3.0, 1.0, -30.0], 1e-9);
    assert_near(g.area(), 22.0, 1e-9);
    assert_near(g.volume(), 6.0, 1e-9);
    let mats = g.face_materials();
    let red = mats.iter().filter(|m| rgb255(m) == [255, 0, 0]).count();
    assert_eq!(red, 2);
    let bricks = mats
        .iter()
        .filter(|m| m.colormap().ends_with("tex/brick wall.png"))
        .count();
    assert_eq!(bricks, 5);
    // Fitted into a scope like any asset.
    let g = gen_with_assets(
        "Lot --> s(4, 2, 6) i(\"box.dae\") X\n",
        &[("box.dae", BOX_DAE.as_bytes())],
    )
    .ok();
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [0.0, 0.0, -30.0], 1e-9);
    assert_vec_near(hi, [4.0, 2.0, -24.0], 1e-9);
    assert_near(g.volume(), 48.0, 1e-9);
}

/// A glTF quad: two triangles in a base64 buffer, placed by a node's
/// translation (1, 2, 3) and scale 2, with a grey material whose linear
/// factor is 0.5^2.2 (CGA colour 0.5).
fn quad_gltf(uri: &str, buffer_len: usize) -> String {
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
 "nodes":[{{"name":"Quad","mesh":0,"translation":[1,2,3],"scale":[2,2,2]}}],
 "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"TEXCOORD_0":1}},"indices":2,"material":0}}]}}],
 "materials":[{{"name":"Grey","pbrMetallicRoughness":{{"baseColorFactor":[0.21763764,0.21763764,0.21763764,1]}}}}],
 "buffers":[{{"byteLength":{buffer_len}{uri}}}],
 "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":48}},{{"buffer":0,"byteOffset":48,"byteLength":32}},{{"buffer":0,"byteOffset":80,"byteLength":12}}],
 "accessors":[{{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,-1],"max":[1,0,0]}},
  {{"bufferView":1,"componentType":5126,"count":4,"type":"VEC2"}},
  {{"bufferView":2,"componentType":5123,"count":6,"type":"SCALAR"}}]}}"#
    )
}

/// The binary buffer of [`quad_gltf`]: positions, texture coordinates,
/// 16-bit indices.
fn quad_buffer() -> Vec<u8> {
    let mut b = Vec::new();
    for v in [
        0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, -1.0, 0.0, 0.0, -1.0,
    ] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    for v in [0.0f32, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        b.extend_from_slice(&i.to_le_bytes());
    }
    b
}

/// A GLB container of `json` and `bin` (both padded to 4 bytes).
fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut j = json.as_bytes().to_vec();
    while !j.len().is_multiple_of(4) {
        j.push(b' ');
    }
    let mut b = bin.to_vec();
    while !b.len().is_multiple_of(4) {
        b.push(0);
    }
    let total = 12 + 8 + j.len() + 8 + b.len();
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(j.len() as u32).to_le_bytes());
    out.extend_from_slice(&0x4E4F_534Au32.to_le_bytes());
    out.extend_from_slice(&j);
    out.extend_from_slice(&(b.len() as u32).to_le_bytes());
    out.extend_from_slice(&0x004E_4942u32.to_le_bytes());
    out.extend_from_slice(&b);
    out
}

#[test]
fn gltf_and_glb_assets_are_inserted_with_their_node_transforms() {
    use base64::Engine as _;
    let bin = quad_buffer();
    let data = base64::engine::general_purpose::STANDARD.encode(&bin);
    let embedded = quad_gltf(
        &format!(r#","uri":"data:application/octet-stream;base64,{data}""#),
        bin.len(),
    );
    let external = quad_gltf(r#","uri":"quad%20data.bin""#, bin.len());
    let binary = glb(&quad_gltf("", bin.len()), &bin);
    type Files<'a> = Vec<(&'a str, &'a [u8])>;
    let cases: [(&str, Files); 3] = [
        ("quad.gltf", vec![("quad.gltf", embedded.as_bytes())]),
        (
            "quad.gltf",
            vec![("quad.gltf", external.as_bytes()), ("quad data.bin", &bin)],
        ),
        ("quad.glb", vec![("quad.glb", &binary)]),
    ];
    for (name, files) in cases {
        let g = gen_with_assets(
            &format!("Lot --> i(\"{name}\", yUp, keepSizeAndPosition) print(geometry.nFaces) X\n"),
            &files,
        )
        .ok();
        assert!(g.warnings().is_empty(), "{name}: {:?}", g.warnings());
        assert_eq!(g.prints(), ["2"], "{name}");
        // At the lot's scope origin (0, 0, -30).
        let (lo, hi) = g.bounds();
        assert_vec_near(lo, [1.0, 2.0, -29.0], 1e-6);
        assert_vec_near(hi, [3.0, 2.0, -27.0], 1e-6);
        assert_near(g.area(), 4.0, 1e-9);
        let m = &g.meshes()[0];
        assert_vec_near(measure::face_normal(m, 0), [0.0, 1.0, 0.0], 1e-9);
        let mat = g.face_materials()[0].clone();
        assert_eq!(&*mat.name, "Grey");
        for c in mat.color {
            assert_near(c, 0.5, 1e-6);
        }
        // glTF's texture origin is the top left, CGA's the bottom left.
        let uv = m.uvs[0].as_ref().expect("texture coordinates");
        assert_near(uv[0].y, 0.0, 1e-9);
        assert_near(uv[1].x, 1.0, 1e-9);
        assert_near(uv[1].y, 0.0, 1e-9);
    }
}

/// An asset that cannot be read is always a warning naming it; the shape
/// keeps its geometry and the model goes on.
#[test]
fn unreadable_assets_are_warnings_naming_them() {
    let cases: [(&str, &[u8], &str); 5] = [
        ("model.fbx", b"Kaydara FBX Binary  \0", "FBX"),
        ("model.usdz", b"PK", "USD"),
        ("broken.dae", b"<COLLADA><library_geometries>", "broken.dae"),
        (
            "empty.dae",
            b"<COLLADA version=\"1.4.1\"><asset><up_axis>Y_UP</up_axis></asset></COLLADA>",
            "no polygons",
        ),
        ("model.xyz", b"1 2 3", "unknown asset format"),
    ];
    for (name, bytes, what) in cases {
        let g = gen_with_assets(
            &format!("Lot --> i(\"{name}\") print(geometry.area) X\n"),
            &[(name, bytes)],
        )
        .ok();
        let w = g.warnings();
        assert_eq!(w.len(), 1, "{name}: {w:?}");
        assert!(w[0].contains(name) && w[0].contains(what), "{name}: {w:?}");
        assert_eq!(g.prints(), ["600"], "{name}");
    }
}

// ----- trim planes -----

/// Trim planes are classified when they are applied, against the xz-plane
/// of the pivot then in force. CityEngine keeps the cube beside the top
/// face whole (area 28): `alignScopeToAxes(y)` levels the pivot, so all
/// four edges of the flat top face are horizontal (off by default).
#[test]
fn trim_planes_are_classified_against_the_pivot_when_applied() {
    let rule = |t_ops: &str, settings: &str| {
        format!(
            "Lot --> s(4,0,2) center(xz) extrude(3) comp(f){{ top : T | all : NIL }}\n\
             T --> {settings} extrude(1) {t_ops} t(4,0,0) primitiveCube()\n"
        )
    };
    let g = gen(&rule("alignScopeToAxes(y)", "")).ok();
    assert_near(g.area(), 28.0, 1e-9);
    let (lo, hi) = g.bounds();
    assert_vec_near(lo, [12.0, 3.0, -16.0], 1e-9);
    assert_vec_near(hi, [16.0, 4.0, -14.0], 1e-9);
    // With horizontal planes on, the plane bisecting the top face and its
    // side at x = 12 keeps the wedge x - 12 <= y - 3 (an open cut): two
    // triangles of 0.5, the top 1 x 2 and the side 1 x 2.
    let g = gen(&rule("alignScopeToAxes(y)", "set(trim.horizontal, true)")).ok();
    assert_near(g.area(), 5.0, 1e-9);
    // Without the alignment the pivot is the top face's (its y-axis level,
    // across the first edge): the edges at x = 8 and x = 12 run along it
    // and are vertical, so the same wedge is all that is left.
    let g = gen(&rule("", "")).ok();
    assert_near(g.area(), 5.0, 1e-9);
    // Switched off, nothing is cut.
    let g = gen(&rule("", "set(trim.vertical, false)")).ok();
    assert_near(g.area(), 28.0, 1e-9);
    // trim() after the alignment applies nothing either.
    let g = gen(
        "Lot --> s(4,0,2) center(xz) extrude(3) comp(f){ top : T | all : NIL }\n\
         T --> extrude(1) alignScopeToAxes(y) t(4,0,0) trim() X\n",
    )
    .ok();
    assert_near(g.area(), 28.0, 1e-9);
}
