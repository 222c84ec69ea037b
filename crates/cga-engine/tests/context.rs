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

#[track_caller]
fn run_with(src: &str, lots: &[Lot], scene: bool) -> Vec<LotOutput> {
    let mut sources = SourceMap::new();
    let loaded = cga_engine::load_text(
        std::path::Path::new("context.cga"),
        src.to_string(),
        &mut sources,
    );
    let Some(program) = loaded.program else {
        let text: String = loaded
            .diagnostics
            .iter()
            .map(|d| d.render(&sources))
            .collect();
        panic!("rules do not load:\n{text}");
    };
    let rule = program.start_rule(None).unwrap_or_else(|e| panic!("{e}"));
    let assets = Assets::new(&sources);
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
            for w in &out.warnings {
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
