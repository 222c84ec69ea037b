//! Context queries through the engine: every example of the reference
//! pages cga_context, func_occlusion, op_label, func_contextCount,
//! func_contextCompare and func_minimumDistance (scatter placements are
//! replaced by fixed ones where noted).

use std::sync::Arc;

use cga_engine::assets::Assets;
use cga_engine::generate::collect_scene;
use cga_engine::lot::{self, Lot};
use cga_engine::{generate_lot, GenerateOptions, LotOutput};
use cga_geometry::{measure, DVec3, Mesh};
use cga_syntax::SourceMap;
use cga_value::Value;

/// Derives `src` on `lots` as the `cga` command does: with the first pass
/// of every lot collected into a scene first.
#[track_caller]
fn run(src: &str, lots: &[Lot]) -> Vec<LotOutput> {
    run_with(src, lots, true)
}

/// `src` loaded as `context.cga`; panics with the diagnostics if it has
/// errors.
#[track_caller]
fn load(src: &str) -> (cga_engine::Program, SourceMap) {
    let mut sources = SourceMap::new();
    let loaded = cga_engine::load_text(
        &cga_world::DiskWorld,
        std::path::Path::new("context.cga"),
        src.to_string(),
        &mut sources,
    );
    if loaded.has_errors() {
        let text: String = loaded
            .diagnostics
            .iter()
            .map(|d| d.render(&sources))
            .collect();
        panic!("rules do not load:\n{text}");
    }
    (loaded.program, sources)
}

/// [`run`], with or without the scene (without: each lot's first pass is
/// its own, inter queries find nothing). The start rule is `Lot`, else the
/// first rule of the text.
#[track_caller]
fn run_with(src: &str, lots: &[Lot], scene: bool) -> Vec<LotOutput> {
    let (program, sources) = load(src);
    let first = src
        .split("-->")
        .next()
        .and_then(|head| head.lines().last())
        .unwrap_or("")
        .trim();
    let rule = program
        .start_rule(None)
        .or_else(|_| program.start_rule(Some(first)))
        .unwrap_or_else(|e| panic!("{e}"));
    let assets = Assets::on_disk(&sources);
    let mut options = GenerateOptions::default();
    if scene {
        options.scene = Some(Arc::new(collect_scene(
            &program, &assets, rule, lots, &options,
        )));
    }
    lots.iter()
        .enumerate()
        .map(|(i, l)| {
            let (out, err) = generate_lot(&program, &assets, rule, l, i, &options);
            if let Some(e) = err {
                panic!("derivation failed: {} at {:?}", e.message, e.span);
            }
            if let Some(w) = out.warnings.first() {
                panic!("warning: {}", w.message);
            }
            out
        })
        .collect()
}

fn prints(outs: &[LotOutput]) -> Vec<String> {
    outs.iter().flat_map(|o| o.prints.clone()).collect()
}

/// The colour (0..255) of each leaf.
fn colours(out: &LotOutput) -> Vec<[u8; 3]> {
    out.meshes
        .iter()
        .map(|m| {
            let f = &m.faces[0];
            m.materials[f.material as usize]
                .color
                .map(|c| (c * 255.0).round() as u8)
        })
        .collect()
}

fn count(out: &LotOutput, rgb: [u8; 3]) -> usize {
    colours(out).iter().filter(|&&c| c == rgb).count()
}

const RED: [u8; 3] = [255, 0, 0];
const GREEN: [u8; 3] = [0, 255, 0];
const WHITE: [u8; 3] = [255, 255, 255];

/// A rectangular lot `w` by `d` with its front left corner at (x, 0, z).
fn rect_at(x: f64, z: f64, w: f64, d: f64) -> Lot {
    let mut l = lot::rect(w, d);
    l.mesh.map_positions(|p| p + DVec3::new(x, 0.0, z));
    l.name = format!("rect at {x},{z}");
    l
}

/// cga_context, "Labels": each label operation makes a labeled copy; the
/// second pass counts both.
#[test]
fn label_example_prints_two() {
    let src = "Lot --> label(\"label\")\n        print(contextCount(intra, \"label\"))\n        label(\"label\")\n";
    let outs = run(src, &[lot::rect(10.0, 10.0)]);
    assert_eq!(prints(&outs), ["2"]);
}

/// The area of the leaves whose vertices all lie in the plane x = `x`.
fn area_in_plane_x(out: &LotOutput, x: f64) -> f64 {
    out.meshes
        .iter()
        .filter(|m| m.positions.iter().all(|p| (p.x - x).abs() < 1e-9))
        .map(measure::mesh_area)
        .sum()
}

/// A lot of two faces, 5 by 5 each, side by side along x.
fn two_face_lot() -> Lot {
    let mut m = Mesh::new();
    m.positions = [
        (0.0, 0.0),
        (5.0, 0.0),
        (10.0, 0.0),
        (10.0, -5.0),
        (5.0, -5.0),
        (0.0, -5.0),
    ]
    .iter()
    .map(|&(x, z)| DVec3::new(x, 0.0, z))
    .collect();
    m.add_face(&[&[0, 1, 4, 5]], 0);
    m.add_face(&[&[1, 2, 3, 4]], 0);
    Lot {
        name: "two faces".into(),
        mesh: m,
        attrs: Vec::new(),
        geo_origin: None,
    }
}

/// cga_context, "Conditions": the default (false) case enlarges the
/// volumes, so in the second pass each overlaps its neighbour's enlarged
/// pass-1 volume and turns red; the enlarged shapes are not in the model.
#[test]
fn conditional_default_case_enlarges() {
    let src = "Lot   --> comp(f) { all : extrude(10) Test }\n\
               Test  --> case overlaps(intra): Red\n          else: s('2,'1,'2) center(xyz) Green\n\
               Red   --> color(1,0,0)\nGreen --> color(0,1,0)\n";
    let outs = run(src, &[two_face_lot()]);
    let out = &outs[0];
    assert_eq!(colours(out), [RED, RED]);
    // The red boxes are the plain extrusions: 5 x 10 x 5.
    for m in &out.meshes {
        assert!((measure::volume(m).abs() - 250.0).abs() < 1e-6);
    }
}

/// cga_context, "Conditions", second rule: enlarging in the non-default
/// case does not feed back; the plain volumes only share a face.
#[test]
fn conditional_non_default_case_is_not_an_occluder() {
    let src = "Lot   --> comp(f) { all : extrude(10) Test }\n\
               Test --> case overlaps(intra) : s('2,'1,'2) center(xyz) Red\n         else : Green\n\
               Red   --> color(1,0,0)\nGreen --> color(0,1,0)\n";
    let outs = run(src, &[two_face_lot()]);
    assert_eq!(colours(&outs[0]), [GREEN, GREEN]);
}

const STEPS: &str = "Init --> extrude(15)
         split(x) { ~5 : Step }*

Step --> s('1, '0.7 * (split.index + 1), '1)
         comp(f) { side : Facade | top : X. }

Facade --> split(y) { 4 : Tile }*

Tile --> case touches(intra) : color(1,0,0) X.
         else : X.
";

/// func_occlusion, "Intra occlusion": the stepped building. Steps 10.5,
/// 21 and 31.5 high; tiles 4 high (and a rest). Red are the tiles in
/// planar contact with another step's volume (never their own, an
/// ancestor): the whole side of a step facing a taller one (3 + 6 tiles),
/// and the tiles of a taller step's side that reach below the lower step's
/// top (3 beside the 10.5 step, 6 beside the 21 step).
#[test]
fn stepped_building_red_tiles() {
    let outs = run(STEPS, &[lot::rect(15.0, 10.0)]);
    let out = &outs[0];
    // 4 sides x (3 + 6 + 8) tiles and 3 tops.
    assert_eq!(out.meshes.len(), 71);
    assert_eq!(count(out, RED), 18);
    // Where: on x = 5 the lower step's whole side (10.5 x 10) and the
    // middle step's tiles up to 12 m; on x = 10 the middle step's whole
    // side (21 x 10) and the top step's tiles up to 24 m.
    let red_area_at = |x: f64| -> f64 {
        out.meshes
            .iter()
            .zip(colours(out))
            .filter(|(m, c)| *c == RED && m.positions.iter().all(|p| (p.x - x).abs() < 1e-9))
            .map(|(m, _)| measure::mesh_area(m))
            .sum()
    };
    assert!((red_area_at(5.0) - (10.5 + 12.0) * 10.0).abs() < 1e-6);
    assert!((red_area_at(10.0) - (21.0 + 24.0) * 10.0).abs() < 1e-6);
    // No red on the front and back or the outer sides.
    assert!((red_area_at(0.0)).abs() < 1e-9 && red_area_at(15.0).abs() < 1e-9);
}

/// Without the first pass's occluders (a rule set queried on one shape
/// only), nothing is touched: the first pass answers every query `false`.
#[test]
fn single_step_touches_nothing() {
    let outs = run(STEPS, &[lot::rect(5.0, 10.0)]);
    assert_eq!(count(&outs[0], RED), 0);
    assert_eq!(outs[0].meshes.len(), 4 * 3 + 1);
}

const HOUSES: &str = "House --> extrude(5+rand(20))
          comp(f) { side : Facade | top : Roof }

Roof --> roofGable(20) color(1,0,0)

Facade --> split(y) { ~5 : split(x) { ~5 : Tile }* }*

Tile --> case inside(inter) : NIL
         case touches(inter) : Wall.
         else : setback(1) { all : Wall. | remainder : NIL }
";

/// func_occlusion, "Inter occlusion", with the heights fixed (8 and 16
/// instead of `5+rand(20)`) by a lot attribute. The lower house's tiles on
/// the shared wall are inside the taller block: none is left. On the
/// taller house's side of that wall the first row (0 to 5.33) lies on the
/// lower block (inside: none), the second (5.33 to 10.67) touches the lower
/// block's top edge and its roof (plain walls), the third has windows (a
/// 1 m frame).
#[test]
fn inter_occlusion_two_houses() {
    let src = format!(
        "attr height = 10\n{}",
        HOUSES.replace("extrude(5+rand(20))", "extrude(height)")
    );
    let mut a = rect_at(0.0, 0.0, 10.0, 10.0);
    a.attrs.push(("height".into(), Value::Float(8.0)));
    let mut b = rect_at(10.0, 0.0, 10.0, 10.0);
    b.attrs.push(("height".into(), Value::Float(16.0)));
    let lots = [a, b];
    let outs = run(&src, &lots);
    assert!(area_in_plane_x(&outs[0], 10.0).abs() < 1e-9);
    let row = 16.0 / 3.0;
    let walls = 2.0 * 5.0 * row;
    let frames = 2.0 * (5.0 * row - 3.0 * (row - 2.0));
    assert!((area_in_plane_x(&outs[1], 10.0) - (walls + frames)).abs() < 1e-6);
    // The outer walls have windows everywhere: tiles of 5 x 4 (lower
    // house) with a 1 m frame, 4 per face.
    let frame = 5.0 * 4.0 - 3.0 * 2.0;
    assert!((area_in_plane_x(&outs[0], 0.0) - 4.0 * frame).abs() < 1e-6);
    // Without the other lot, nothing is occluded.
    let alone = run_with(&src, &lots, false);
    assert!((area_in_plane_x(&alone[0], 10.0) - 4.0 * frame).abs() < 1e-6);
}

/// The example as written (random heights): whichever house is lower
/// keeps no tile on the shared wall, and the taller one keeps some.
#[test]
fn inter_occlusion_random_heights() {
    let lots = [
        rect_at(0.0, 0.0, 10.0, 10.0),
        rect_at(10.0, 0.0, 10.0, 10.0),
    ];
    let outs = run(HOUSES, &lots);
    let height = |o: &LotOutput| {
        o.meshes
            .iter()
            .filter_map(measure::bounds)
            .fold(0.0f64, |h, (_, hi)| h.max(hi.y))
    };
    let (low, high) = if height(&outs[0]) < height(&outs[1]) {
        (&outs[0], &outs[1])
    } else {
        (&outs[1], &outs[0])
    };
    assert!(area_in_plane_x(low, 10.0).abs() < 1e-9);
    assert!(area_in_plane_x(high, 10.0) > 1.0);
}

/// func_contextCount: 4 x 4 tiles count 16 (red), 3 x 3 count 9 (green).
#[test]
fn context_count_tiles() {
    let src = "Lot --> split(x) { ~1 : Split }*\n\
               Split --> split(z) { ~1 : Tile }*\n\
               Tile --> label(\"Tile\") Color\n\
               Color --> case contextCount(intra, \"Tile\") <= 9 : color(0,1,0)\n          else : color(1,0,0)\n";
    let big = run(src, &[lot::rect(4.0, 4.0)]);
    assert_eq!(colours(&big[0]), vec![RED; 16]);
    let small = run(src, &[lot::rect(3.0, 3.0)]);
    assert_eq!(colours(&small[0]), vec![GREEN; 9]);
    // Intra counts are per initial shape: both lots at once change nothing.
    let both = run(
        src,
        &[rect_at(0.0, 0.0, 4.0, 4.0), rect_at(10.0, 0.0, 3.0, 3.0)],
    );
    assert_eq!(count(&both[0], RED), 16);
    assert_eq!(count(&both[1], GREEN), 9);
}

/// contextCount's targets: `inter` counts the other lots' labels, `all`
/// both; an empty label counts nothing.
#[test]
fn context_count_targets() {
    let src = "Lot --> label(\"x\") label(\"x\") print(contextCount(intra, \"x\") + \" \" + contextCount(inter, \"x\") + \" \" + contextCount(all, \"x\") + \" \" + contextCount(all, \"\") + \" \" + contextCount(all, \"y\"))\n";
    let lots = [
        rect_at(0.0, 0.0, 1.0, 1.0),
        rect_at(5.0, 0.0, 1.0, 1.0),
        rect_at(500.0, 0.0, 1.0, 1.0),
    ];
    assert_eq!(prints(&run(src, &lots)), ["2 4 6 0 0"; 3]);
}

/// func_contextCompare: lots extruded to random heights; the highest is
/// red, the rest share the lowest rank (0) and are green.
#[test]
fn context_compare_highest() {
    let src = "Lot --> extrude(rand(10)) label(\"label\") Color\n\
               Color -->\n    case contextCompare(inter, \"label\", world.highest) == 0 :\n        color(1,0,0)\n    case contextCompare(inter, \"label\", world.lowest) == 0 :\n        color(0,1,0)\n    else :\n        color(0,0,1)\n";
    let lots: Vec<Lot> = (0..7)
        .map(|i| rect_at(12.0 * i as f64, 0.0, 10.0, 10.0))
        .collect();
    let outs = run(src, &lots);
    let heights: Vec<f64> = outs
        .iter()
        .map(|o| measure::bounds(&o.meshes[0]).unwrap().1.y)
        .collect();
    let top = heights
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .map(|(i, _)| i)
        .unwrap();
    for (i, o) in outs.iter().enumerate() {
        assert_eq!(colours(o), [if i == top { RED } else { GREEN }], "lot {i}");
    }
}

/// contextCompare's ranks: the number of labeled shapes strictly better,
/// for every comparison.
#[test]
fn context_compare_ranks() {
    // Four tiles of 1 x 1 and one of 2 x 1 along x, each lifted by its index.
    let src = "Lot --> split(x) { 1 : T | 1 : T | 2 : T | 1 : T }\n\
               T --> t(0, split.index, 0) label(\"t\") R\n\
               R --> print(split.index + \": \" + contextCompare(intra, \"t\", world.easternmost) + \" \" + contextCompare(intra, \"t\", world.westernmost) + \" \" + contextCompare(intra, \"t\", world.highest) + \" \" + contextCompare(intra, \"t\", world.lowest) + \" \" + contextCompare(intra, \"t\", area.largest) + \" \" + contextCompare(intra, \"t\", area.smallest) + \" \" + contextCompare(intra, \"t\", world.northernmost) + \" \" + contextCompare(intra, \"t\", world.southernmost))\n";
    let outs = run(src, &[lot::rect(5.0, 1.0)]);
    assert_eq!(
        prints(&outs),
        [
            "0: 3 0 3 0 1 0 0 0",
            "1: 2 1 2 1 1 0 0 0",
            "2: 1 2 1 2 0 3 0 0",
            "3: 0 3 0 3 1 0 0 0",
        ]
    );
}

/// func_minimumDistance, "Split rule": a 25 x 25 grid of 0.1 cells, the
/// centre one labeled; each cell is extruded by 1 minus its scope's
/// distance to the centre cell's scope, if that is below 1.
#[test]
fn minimum_distance_grid() {
    let src = "Lot --> split(x) { ~0.1 : Lot(split.index) }*\n\
               Lot(x) --> split(z) { ~0.1 : Lot(x, split.index) }*\n\
               Lot(x, z) --> [ case (x == 12) && (z == 12) : label(\"label\")\n                else : NIL ]\n              Extrude(minimumDistance(intra, \"label\"))\n\
               Extrude(dist) --> case dist < 1 : extrude(1-dist) X.\n                  else : NIL\n";
    let outs = run(src, &[lot::rect(2.5, 2.5)]);
    let out = &outs[0];
    // The gap between cell (i, j) and the centre cell.
    let gap = |i: i32, j: i32| {
        let g = |k: i32| 0.1 * ((k - 12).abs() - 1).max(0) as f64;
        (g(i).powi(2) + g(j).powi(2)).sqrt()
    };
    let mut expected = Vec::new();
    for i in 0..25 {
        for j in 0..25 {
            if gap(i, j) < 1.0 - 1e-9 {
                expected.push(1.0 - gap(i, j));
            }
        }
    }
    // (Cells exactly 1 away may come out a rounding error nearer, and flat.)
    let mut heights: Vec<f64> = out
        .meshes
        .iter()
        .map(|m| {
            let (lo, hi) = measure::bounds(m).unwrap();
            hi.y - lo.y
        })
        .filter(|&h| h > 1e-9)
        .collect();
    assert_eq!(heights.len(), expected.len());
    heights.sort_by(f64::total_cmp);
    expected.sort_by(f64::total_cmp);
    for (h, e) in heights.iter().zip(&expected) {
        assert!((h - e).abs() < 1e-6, "{h} vs {e}");
    }
    // The centre and its eight neighbours reach 1.
    assert_eq!(
        heights.iter().filter(|&&h| (h - 1.0).abs() < 1e-9).count(),
        9
    );
}

/// minimumDistance's targets: `inter` measures to other lots' labeled
/// scopes only; nothing labeled gives infinity.
#[test]
fn minimum_distance_targets() {
    let src = "Lot --> label(\"p\") print(minimumDistance(intra, \"p\") + \" \" + minimumDistance(inter, \"p\") + \" \" + minimumDistance(all, \"p\") + \" \" + minimumDistance(all, \"q\"))\n";
    let lots = [
        rect_at(0.0, 0.0, 1.0, 1.0),
        rect_at(4.0, 0.0, 1.0, 1.0),
        rect_at(4.0, -104.0, 1.0, 1.0),
    ];
    let outs = run(src, &lots);
    assert_eq!(prints(&outs), ["0 3 0 inf", "0 3 0 inf", "0 103 0 inf"]);
}

/// func_minimumDistance, "Scatter rule", with the 500 scattered points
/// replaced by a fixed row of 0.5 spaced places (scatter is not run by
/// this engine), every tenth labeled: a place gets a small cylinder only
/// if it is at least 1 away from a labeled one.
#[test]
fn minimum_distance_places() {
    let src = "Lot --> split(x) { ~0.5 : Scattered }*\n\
               Scattered --> case split.index % 10 == 0 : Label\n              else : Check\n\
               Label --> primitiveCylinder(16, 0.1, 1) color(1,0,0) label(\"label\")\n\
               Check --> case minimumDistance(intra,\"label\") < 1 : NIL\n          else : primitiveCylinder(16, 0.05, 0.5)\n";
    let outs = run(src, &[lot::rect(20.0, 0.5)]);
    let out = &outs[0];
    // 40 places; labeled: 0, 10, 20, 30. A labeled cylinder's scope is
    // 0.2 wide in the middle of its place (x 0.15..0.35 of place 0); a
    // place's scope is 0.5 wide: the places 1 and 2 away from a labeled one
    // are within 1 (gaps 0.15 and 0.65), those 3 away are not (1.15).
    assert_eq!(count(out, RED), 4);
    let plain = out.meshes.len() - 4;
    assert_eq!(plain, 40 - 4 - 4 * 2 - 3 * 2);
}

/// The scene of func_occlusion's "Labels" examples with the scattered
/// houses and trees placed by hand (scatter is not run by this engine) and
/// the trees made boxes (`builtin:cube`, closed like the tree assets):
///
/// - house A, 10 x 10 x 10, at x 2..12, z 2..12 of the lot's scope;
///   house B, 10 x 10 x 5, beside it at x 12..22 (sharing the wall x = 12);
/// - tree T1 (2 x 4 x 2) standing against A's front (z 12..14, x 3..5);
/// - tree T2 standing half in A's front (z 11..13, x 8..10);
/// - trees T3 and T4 overlapping each other (x 30..32 and 31..33);
/// - tree T5 alone (x 40..42).
///
/// Facades are tiles of 5 x 5 (A: 2 x 2 per side, B: 1 x 2); the tile
/// rule is the example's, with a red wall for `touches` and a green
/// window for the setback. `{tile}` and `{check}` are the query rules.
fn labels_scene(tile: &str, check: &str, house_label: bool) -> String {
    format!(
        "Field --> [ t(2, 0, 2) s(10, 0, 10) primitiveQuad() House(10) ]\n\
         [ t(12, 0, 2) s(10, 0, 10) primitiveQuad() House(5) ]\n\
         [ t(3, 0, 12) PlaceTree ] [ t(8, 0, 11) PlaceTree ]\n\
         [ t(30, 0, 6) PlaceTree ] [ t(31, 0, 7) PlaceTree ] [ t(40, 0, 6) PlaceTree ]\n\
         Ground\n\
         Ground --> color(0, 0, 1)\n\
         PlaceTree --> s(2, 4, 2) i(\"builtin:cube\") CheckOverlap\n\
         House(h) --> extrude(h) {label} comp(f) {{ side : Facade | top : Roof. }}\n\
         Facade --> split(y) {{ ~5 : split(x) {{ ~5 : Tile }}* }}*\n\
         Tile --> {tile}\n\
         CheckOverlap --> {check}\n\
         Wall --> color(1, 0, 0)\n\
         Window --> color(0, 1, 0)\n\
         Tree --> color(0.5, 0.25, 0)\n",
        label = if house_label { "label(\"block\")" } else { "" },
    )
}

const BROWN: [u8; 3] = [128, 64, 0];

/// (walls, windows, trees) of a labels scene.
fn labels_outcome(tile: &str, check: &str, house_label: bool) -> (usize, usize, usize) {
    let outs = run(
        &labels_scene(tile, check, house_label),
        &[lot::rect(50.0, 20.0)],
    );
    let out = &outs[0];
    // The lot (blue) and the two roofs (white) are the other leaves.
    assert_eq!(count(out, [0, 0, 255]), 1);
    assert_eq!(count(out, WHITE), 2);
    (count(out, RED), count(out, GREEN), count(out, BROWN))
}

const UNLABELED_TILE: &str = "case inside(intra) : NIL\n         \
                              case touches(intra) : Wall\n         \
                              else : Window";
const LABELED_TILE: &str = "case inside(all, \"block\") : NIL\n         \
                            case touches(all, \"block\") : Wall\n         \
                            else : Window";

/// func_occlusion, "Labels" 1: the trees are leaves, closed, so automatic
/// occluders. Of A's 16 tiles the two low ones on the wall shared with B
/// lie on B's block (inside: none), the low front ones touch T1 and T2
/// (walls); of B's 8 the two on the shared wall lie on A's block. Every
/// tree stays.
#[test]
fn labels_trees_are_occluders() {
    assert_eq!(
        labels_outcome(UNLABELED_TILE, "Tree", false),
        (2, 12 + 6, 5)
    );
}

/// func_occlusion, "Labels" 2: every tree overlapping something goes, T2
/// (in house A) and both of T3 and T4 (in each other), though removing
/// one of them would do; T1 only touches A and stays. The front tiles
/// still become walls: they test against the first pass's trees, T2
/// included.
#[test]
fn labels_overlapping_trees_are_removed() {
    let check = "case overlaps(intra) : NIL\n                 else : Tree";
    assert_eq!(labels_outcome(UNLABELED_TILE, check, false), (2, 18, 2));
}

/// func_occlusion, "Labels" 3: the blocks labeled "block" and the tiles
/// asking about that label only: the trees no longer turn windows into
/// walls; the tiles on the shared wall still lie on the other block.
#[test]
fn labels_tiles_test_only_blocks() {
    let check = "case overlaps(intra) : NIL\n                 else : Tree";
    assert_eq!(labels_outcome(LABELED_TILE, check, true), (0, 20, 2));
}

/// func_occlusion, "Labels" 4: the trees test against the blocks only, so
/// T3 and T4 stay; T2 in house A still goes.
#[test]
fn labels_trees_test_only_blocks() {
    let check = "case overlaps(intra, \"block\") : NIL\n                 else : Tree";
    assert_eq!(labels_outcome(LABELED_TILE, check, true), (0, 20, 4));
}

/// func_occlusion, "Concrete example": a U-shaped mass of a main block
/// (30 x 8) and two wings (8 x 12) from a subdivision split, 9 high, with
/// window openings of 2 x 3. `touches(intra)` turns the openings where a
/// wing meets the main block into walls: 4 x 3 on each wing's back and on
/// the main block's front behind each wing (48 in all); the 7 x 3 openings
/// of the main front between the wings stay windows.
#[test]
fn u_shaped_building_windows() {
    let src = "Lot --> split(z) { 8 : Mass | ~1 : split(x) { 8 : Mass | ~1 : NIL | 8 : Mass } }\n\
               Mass --> extrude(9) comp(f) { side : Facade | top : Roof. }\n\
               Facade --> split(y) { 3 : split(x) { 2 : WindowOpening }* }*\n\
               WindowOpening --> case touches(intra) : color(1, 0, 0) Wall.\n                 \
               else : color(0, 1, 0) Window.\n";
    let outs = run(src, &[lot::rect(30.0, 20.0)]);
    let out = &outs[0];
    // Openings: main 2 x 15 x 3 + 2 x 4 x 3, wings 2 x (2 x 4 x 3 + 2 x 6 x 3).
    assert_eq!(out.meshes.len(), 114 + 120 + 3);
    assert_eq!(count(out, RED), 48);
    assert_eq!(count(out, GREEN), 234 - 48);
    // The walls all lie in the plane where the wings meet the main block.
    let z = -12.0;
    for (m, c) in out.meshes.iter().zip(colours(out)) {
        if c == RED {
            assert!(m.positions.iter().all(|p| (p.z - z).abs() < 1e-9));
        }
    }
    let windows_there = out
        .meshes
        .iter()
        .zip(colours(out))
        .filter(|(m, c)| *c == GREEN && m.positions.iter().all(|p| (p.z - z).abs() < 1e-9))
        .count();
    assert_eq!(windows_there, 21);
}

/// Shapes are matched across the two passes by their address (ordinals
/// from the initial shape), not by creation order: here the second pass
/// makes far fewer shapes in the first branch (the side of the low mass
/// against the tall one ends at once instead of being split in 40) before
/// the tall mass is even created (`Wait` puts it two generations later),
/// and the tall mass's tiles still skip their own mass and find the low
/// one: only its two lowest tiles on the shared wall touch.
#[test]
fn addresses_survive_a_diverging_branch() {
    let src = "Lot --> split(x) { 5 : A | 5 : B }\n\
               A --> extrude(2) comp(f) { all : APiece }\n\
               APiece --> case touches(intra) : color(0, 0, 1) X.\n          \
               else : split(x) { 0.25 : Y }*\n\
               Y --> color(1, 1, 0) Y.\n\
               B --> Wait\n\
               Wait --> Mass\n\
               Mass --> extrude(10) comp(f) { side : Tile | top : X. }\n\
               Tile --> split(y) { 1 : T }*\n\
               T --> case touches(intra) : color(1, 0, 0) X.\n     else : color(0, 1, 0) X.\n";
    let outs = run(src, &[lot::rect(10.0, 10.0)]);
    let out = &outs[0];
    // The low mass's side on the shared wall touches the tall mass.
    assert_eq!(count(out, [0, 0, 255]), 1);
    assert_eq!(count(out, RED), 2);
    assert_eq!(count(out, GREEN), 38);
    let red_area: f64 = out
        .meshes
        .iter()
        .zip(colours(out))
        .filter(|(m, c)| *c == RED && m.positions.iter().all(|p| (p.x - 5.0).abs() < 1e-9))
        .map(|(m, _)| measure::mesh_area(m))
        .sum();
    assert!((red_area - 2.0 * 10.0).abs() < 1e-9, "{red_area}");
}

/// The first pass of `src` on a 10 x 10 lot (start rule `Lot`).
fn first_pass(src: &str) -> (cga_engine::Program, cga_engine::context::LotContext) {
    let (program, sources) = load(src);
    let rule = program.start_rule(Some("Lot")).unwrap();
    let assets = Assets::on_disk(&sources);
    let lot = lot::rect(10.0, 10.0);
    let records = cga_engine::generate::collect_lot(
        &program,
        &assets,
        rule,
        &lot,
        0,
        &GenerateOptions::default(),
    );
    (program, records)
}

fn rule_id(program: &cga_engine::Program, name: &str) -> u32 {
    program
        .main_rules
        .iter()
        .find(|(n, _)| n == name)
        .map(|&(_, id)| id)
        .unwrap()
}

/// The first pass skips rules from which no label a query asks about can
/// be reached: `Detail` (which only labels "other") records nothing, while
/// `Wall`, two rules away from its label, is applied. The second pass
/// still derives everything, with the same answers.
#[test]
fn first_pass_skips_rules_without_asked_labels() {
    let src = "Lot --> split(x) { 5 : Left | 5 : Right }\n\
               Left --> Mid\n\
               Mid --> extrude(4) Wall\n\
               Wall --> label(\"wall\") X.\n\
               Right --> extrude(2) split(y) { 0.5 : Detail }*\n\
               Detail --> label(\"other\") Tile\n\
               Tile --> case contextCount(intra, \"wall\") == 1 : color(1, 0, 0) X.\n     \
               else : color(0, 1, 0) X.\n";
    let (program, records) = first_pass(src);
    let pass = cga_engine::context::FirstPass::of(&program);
    for (name, applies) in [
        ("Lot", true),
        ("Left", true),
        ("Mid", true),
        ("Wall", true),
        ("Right", false),
        ("Detail", false),
        ("Tile", false),
    ] {
        assert_eq!(pass.applies(rule_id(&program, name)), applies, "{name}");
    }
    assert_eq!(records.label_count("wall"), 1);
    assert_eq!(records.label_count("other"), 0);
    let outs = run(src, &[lot::rect(10.0, 10.0)]);
    assert_eq!(count(&outs[0], RED), 4);
    assert_eq!(count(&outs[0], GREEN), 0);
}

/// A query whose label is not a constant may ask about any label, and an
/// occlusion query without a label makes every leaf an occluder: then the
/// first pass applies every rule.
#[test]
fn first_pass_applies_every_rule_for_unknown_labels() {
    let dynamic = "attr which = \"wall\"\n\
                   Lot --> split(x) { 5 : Left | 5 : Right }\n\
                   Left --> label(\"wall\") X.\n\
                   Right --> label(\"other\") print(contextCount(intra, which))\n";
    let (program, records) = first_pass(dynamic);
    assert!(cga_engine::context::FirstPass::of(&program).applies(rule_id(&program, "Right")));
    assert_eq!(records.label_count("other"), 1);
    let unlabeled = "Lot --> split(x) { 5 : Left | 5 : Right }\n\
                     Left --> label(\"wall\") X.\n\
                     Right --> extrude(1) Box\n\
                     Box --> print(inside(intra)) X.\n";
    let (program, _) = first_pass(unlabeled);
    assert!(cga_engine::context::FirstPass::of(&program).applies(rule_id(&program, "Box")));
}

/// A component split's entries that lead to no asked label are not filled
/// in the first pass; the entries after them still are, with the same
/// random streams: the roof is labeled where a random split put it, and
/// every facade tile of the second pass sees it.
#[test]
fn first_pass_skips_component_entries_without_asked_labels() {
    let src = "Lot --> extrude(10) comp(f) { side : Facade | top : Roof }\n\
               Facade --> split(x) { 2 : Tile }*\n\
               Tile --> case contextCount(intra, \"roof\") == 1 : color(1, 0, 0) X.\n     \
               else : color(0, 1, 0) X.\n\
               Roof --> split(x) { rand(2, 8) : label(\"roof\") R. | ~1 : X. }\n";
    let (_, records) = first_pass(src);
    assert_eq!(records.label_count("roof"), 1);
    assert_eq!(records.len(), 1);
    let outs = run(src, &[lot::rect(10.0, 10.0)]);
    assert_eq!(count(&outs[0], RED), 20);
    assert_eq!(count(&outs[0], GREEN), 0);
}
