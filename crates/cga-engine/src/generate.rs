//! The entry point for generating one lot: attribute values, seed, start
//! rule, limits, and the derivation itself.

use std::sync::Arc;

use cga_value::Value;

use crate::assets::Assets;
use crate::context::{ContextState, ContextUse, LotContext, SceneContext};
use crate::derive::{InitialInfo, Interp, Leaf, Limits, LotOutput, RtError};
use crate::expr::RExpr;
use crate::lot::{initial_shape, Lot};
use crate::program::{AttrId, Program, RuleId};
use crate::values::to_text;

#[derive(Clone, Debug, Default)]
pub struct GenerateOptions {
    /// `--attr NAME=VALUE` values (resolved to attribute ids).
    pub attrs: Vec<(AttrId, Value)>,
    /// The run's seed: lot `i` derives with [`lot_seed`]`(seed, i)`.
    pub seed: u64,
    /// Every lot's own seed, when given (the initial shapes' `seed`
    /// attribute, as CityEngine's shapes carry one): instead of the one
    /// [`lot_seed`] derives from `seed`.
    pub lot_seed: Option<u64>,
    pub limits: Limits,
    /// Hand leaf geometry out unbaked (`LotOutput::leaves`: each leaf's
    /// mesh shared with its shape, with the map that places it) instead of
    /// as meshes in object coordinates (`LotOutput::meshes`). Exporters
    /// place the leaves while writing, which saves a copy of every leaf.
    pub leaves: bool,
    /// The program's context queries ([`ContextUse::of`]); `None`: found
    /// out from the program on each call. A program with context queries
    /// derives each lot twice (see `crate::context`).
    pub context_use: Option<ContextUse>,
    /// Set by another thread to stop the generation: the derivation ends
    /// with an error of kind [`RtErrorKind::Cancelled`](crate::derive::RtErrorKind)
    /// within moments (it is looked at where the time limit is).
    pub cancel: Option<Arc<std::sync::atomic::AtomicBool>>,
    /// The first-pass records of every lot of the generation, for `inter`
    /// context queries ([`collect_lot`], [`SceneContext::new`]). Without
    /// it, a lot's first pass is run by [`generate_lot`] itself and inter
    /// queries find no other lots.
    pub scene: Option<Arc<SceneContext>>,
    /// The texture coordinate sets the caller does not keep (bit `k`: set
    /// `k`; [`crate::uv_use::ALL_UV_SETS`] for reports only, all but set 0
    /// for plain meshes). Operations that only compute coordinates of such
    /// a set are skipped unless the rules read it (see `crate::uv_use`).
    pub uv_sets_unused: crate::uv_use::UvSets,
    /// Leaves are only counted (`LotOutput::leaf_count`), neither kept nor
    /// handed to a sink: the caller wants reports, prints and diagnostics
    /// alone.
    pub count_leaves_only: bool,
}

/// Derives one lot with `rule`. The output holds everything generated,
/// also when an error stopped the derivation part way.
pub fn generate_lot(
    program: &Program,
    assets: &Assets,
    rule: RuleId,
    lot: &Lot,
    lot_index: usize,
    options: &GenerateOptions,
) -> (LotOutput, Option<RtError>) {
    generate(program, assets, rule, lot, lot_index, options, None)
}

/// [`generate_lot`] handing each leaf to `sink` as soon as it is emitted,
/// in derivation order, unbaked (as `GenerateOptions::leaves` gives them);
/// `LotOutput::leaves` and `LotOutput::meshes` stay empty. A model writer
/// on another thread can write the leaves while the derivation goes on.
pub fn generate_lot_streaming<'a>(
    program: &'a Program,
    assets: &'a Assets,
    rule: RuleId,
    lot: &Lot,
    lot_index: usize,
    options: &GenerateOptions,
    sink: impl FnMut(Leaf) + 'a,
) -> (LotOutput, Option<RtError>) {
    generate(
        program,
        assets,
        rule,
        lot,
        lot_index,
        options,
        Some(Box::new(sink)),
    )
}

fn generate<'a>(
    program: &'a Program,
    assets: &'a Assets,
    rule: RuleId,
    lot: &Lot,
    lot_index: usize,
    options: &GenerateOptions,
    sink: Option<Box<dyn FnMut(Leaf) + 'a>>,
) -> (LotOutput, Option<RtError>) {
    if let Some(why) = crate::lot::degenerate(lot) {
        let mut out = LotOutput::default();
        out.warnings.push(cga_syntax::Diagnostic {
            severity: cga_syntax::Severity::Warning,
            message: format!("lot `{}` is skipped: {why}", lot.name),
            span: None,
            label: None,
            notes: Vec::new(),
        });
        return (out, None);
    }
    let usage = context_use(program, options);
    let context = usage.any().then(|| {
        // Pass 2 answers from pass 1's records: the scene's, or this lot's
        // own first pass.
        let own = match &options.scene {
            Some(scene) => scene.lot(lot_index),
            None => Arc::new(collect(
                program, assets, rule, lot, lot_index, options, usage,
            )),
        };
        ContextState::answering(usage, own, options.scene.clone(), lot_index)
    });
    let (out, error, _) = derive(
        program, assets, rule, lot, lot_index, options, sink, context,
    );
    (out, error)
}

fn context_use(program: &Program, options: &GenerateOptions) -> ContextUse {
    match (&options.scene, options.context_use) {
        (Some(scene), _) => scene.usage(),
        (None, Some(u)) => u,
        (None, None) => ContextUse::of(program),
    }
}

/// The first pass of lot `lot_index` for context queries: the lot is
/// derived with every query giving its default, nothing is emitted, and
/// the labeled shapes and occluders are recorded. Collect every lot and
/// make a [`SceneContext`] of them for `inter` queries. Empty for
/// programs without context queries and for skipped lots.
pub fn collect_lot(
    program: &Program,
    assets: &Assets,
    rule: RuleId,
    lot: &Lot,
    lot_index: usize,
    options: &GenerateOptions,
) -> LotContext {
    let usage = context_use(program, options);
    if !usage.any() || crate::lot::degenerate(lot).is_some() {
        return LotContext::new(None);
    }
    collect(program, assets, rule, lot, lot_index, options, usage)
}

/// The scene of `lots` for `inter` context queries: the first pass of each
/// ([`collect_lot`], one after the other; the `cga` command runs them on
/// several threads). Give it to [`generate_lot`] in
/// [`GenerateOptions::scene`] for each lot, with the lot's index in `lots`.
pub fn collect_scene(
    program: &Program,
    assets: &Assets,
    rule: RuleId,
    lots: &[Lot],
    options: &GenerateOptions,
) -> SceneContext {
    let usage = context_use(program, options);
    let records = lots
        .iter()
        .enumerate()
        .map(|(i, lot)| collect_lot(program, assets, rule, lot, i, options))
        .collect();
    SceneContext::new(records, usage)
}

fn collect(
    program: &Program,
    assets: &Assets,
    rule: RuleId,
    lot: &Lot,
    lot_index: usize,
    options: &GenerateOptions,
    usage: ContextUse,
) -> LotContext {
    let state = ContextState::collecting(usage, crate::context::lot_bounds(&lot.mesh));
    // Whatever the pass made before an error is recorded; the second pass
    // stops on the same error and reports it.
    let (_, _, state) = derive(
        program,
        assets,
        rule,
        lot,
        lot_index,
        options,
        None,
        Some(state),
    );
    state.map_or_else(|| LotContext::new(None), |s| s.into_lot_context())
}

/// One derivation of a lot (with a context state: one of its two passes).
#[allow(clippy::too_many_arguments)]
fn derive<'a>(
    program: &'a Program,
    assets: &'a Assets,
    rule: RuleId,
    lot: &Lot,
    lot_index: usize,
    options: &GenerateOptions,
    sink: Option<Box<dyn FnMut(Leaf) + 'a>>,
    context: Option<Box<ContextState>>,
) -> (LotOutput, Option<RtError>, Option<Box<ContextState>>) {
    let lot = LotRun {
        lot,
        index: lot_index,
        remember: true,
    };
    derive_lot(program, assets, rule, lot, options, sink, context)
}

/// The lot a derivation runs on, and whether it may count repeated
/// subtrees from memory (`crate::subtree_memo`).
struct LotRun<'l> {
    lot: &'l Lot,
    index: usize,
    remember: bool,
}

/// [`derive`] of `run`.
fn derive_lot<'a>(
    program: &'a Program,
    assets: &'a Assets,
    rule: RuleId,
    run: LotRun<'_>,
    options: &GenerateOptions,
    sink: Option<Box<dyn FnMut(Leaf) + 'a>>,
    context: Option<Box<ContextState>>,
) -> (LotOutput, Option<RtError>, Option<Box<ContextState>>) {
    let (lot, lot_index) = (run.lot, run.index);
    let seed = options
        .lot_seed
        .or_else(|| own_seed(program, lot))
        .unwrap_or_else(|| lot_seed(options.seed, lot_index));
    let shape = initial_shape(lot, seed, program.rule_symbol(rule));
    let info = InitialInfo {
        name: lot.name.clone(),
        start_rule: program.rules[rule as usize].name.clone(),
        geo_origin: lot.geo_origin,
    };
    let mut interp = Interp::new(program, assets, options.limits, info, shape, &[]);
    interp.cancel = options.cancel.clone();
    interp.keep_leaves = options.leaves || sink.is_some();
    interp.leaf_sink = sink;
    interp.context = context;
    // The first pass of context queries keeps no geometry at all.
    let unused = match interp.context_collecting() {
        true => crate::uv_use::ALL_UV_SETS,
        false => options.uv_sets_unused,
    };
    interp.uv_skip = unused & !program.uv_sets_read();
    interp.count_leaves_only = options.count_leaves_only;
    // Without a model the counts of repeated subtrees are remembered.
    if run.remember
        && options.count_leaves_only
        && interp.context.is_none()
        && program.subtree_memo().any()
    {
        interp.subtrees = Some(Default::default());
    }
    let mut error = None;
    // Lot attributes (GeoJSON properties) first, command-line values win.
    let lot_attrs = lot
        .attrs
        .iter()
        .filter_map(|(name, v)| program.main_attr(name).map(|id| (id, v.clone())));
    for (id, raw) in lot_attrs.chain(options.attrs.iter().cloned()) {
        let def = &program.attrs[id as usize];
        match interp.attr_default(id, &RExpr::constant(raw.clone(), def.span)) {
            Ok(default) => interp.set_attr_default(id, coerce(&raw, &default)),
            Err(e) => {
                error = Some(e);
                break;
            }
        }
    }
    if error.is_none() {
        if let Err(e) = interp.run(rule) {
            error = Some(e);
        }
    }
    // A lot that failed with subtrees counted from memory is derived again
    // without: where it stops (and what it had counted by then) follows
    // the order of the derivation, which remembered subtrees change.
    // Not after cancellation or the time limit.
    if let Some(e) = &error {
        let again = interp.subtrees.is_some()
            && e.kind != crate::derive::RtErrorKind::Cancelled
            && !interp.out_of_time();
        if again {
            let sink = interp.leaf_sink.take();
            let run = LotRun {
                remember: false,
                ..run
            };
            return derive_lot(program, assets, rule, run, options, sink, None);
        }
    }
    let context = interp.context.take();
    (std::mem::take(&mut interp.out), error, context)
}

/// The seed of lot `index` in a run with seed `seed`: the run's seed for
/// the first lot (one lot generated with seed 666 has `seedian` 666), a hash
/// of the seed and the index for the others, so that every seed gives a
/// different city (not the same buildings shifted by a lot) and
/// neighbouring lots are unrelated. Below 2^31, as CityEngine's seeds are.
pub fn lot_seed(seed: u64, index: usize) -> u64 {
    if index == 0 {
        return seed;
    }
    let mut state = seed;
    let mut state = crate::shape::splitmix64(&mut state) ^ index as u64;
    crate::shape::splitmix64(&mut state) & 0x7FFF_FFFF
}

/// A lot's own seed: its `seed` property (GIS data), when the rules have no
/// attribute of that name.
fn own_seed(program: &Program, lot: &Lot) -> Option<u64> {
    if program.main_attr("seed").is_some() {
        return None;
    }
    lot.attrs
        .iter()
        .find(|(n, _)| &**n == "seed")
        .and_then(|(_, v)| match v {
            Value::Float(x) if *x >= 0.0 && x.is_finite() => Some(*x as u64),
            Value::Str(s) => s.trim().parse().ok(),
            _ => None,
        })
}

/// The values the attributes `ids` take on `lot` before any rule runs
/// (their defaults, evaluated on the initial shape, or the lot's own
/// values), in the order of `ids`.
pub fn attribute_values(
    program: &Program,
    assets: &Assets,
    lot: &Lot,
    seed: u64,
    ids: &[AttrId],
) -> Vec<Result<Value, RtError>> {
    let shape = initial_shape(lot, seed, 0);
    let info = InitialInfo {
        name: lot.name.clone(),
        start_rule: String::new(),
        geo_origin: lot.geo_origin,
    };
    let limits = crate::derive::Limits {
        max_seconds: 10.0,
        ..Default::default()
    };
    let mut interp = Interp::new(program, assets, limits, info, shape, &[]);
    for (name, raw) in &lot.attrs {
        if let Some(id) = program.main_attr(name) {
            let def = &program.attrs[id as usize];
            if let Ok(default) = interp.attr_default(id, &RExpr::constant(raw.clone(), def.span)) {
                interp.set_attr_default(id, coerce(raw, &default));
            }
        }
    }
    ids.iter()
        .map(|&id| {
            let at = RExpr::constant(Value::Float(0.0), program.attrs[id as usize].span);
            interp.attr_default(id, &at)
        })
        .collect()
}

/// A value given from outside (command line, GIS properties) in the type of
/// the attribute's default: `--attr height=20` for a string attribute is "20".
pub fn coerce(raw: &Value, like: &Value) -> Value {
    match (raw, like) {
        (Value::Float(_), Value::Float(_))
        | (Value::Bool(_), Value::Bool(_))
        | (Value::Str(_), Value::Str(_)) => raw.clone(),
        (_, Value::Str(_)) => Value::Str(Arc::from(to_text(raw).as_str())),
        (Value::Str(s), Value::Float(_)) => s
            .trim()
            .parse::<f64>()
            .map(Value::Float)
            .unwrap_or_else(|_| raw.clone()),
        (Value::Bool(b), Value::Float(_)) => Value::Float(if *b { 1.0 } else { 0.0 }),
        (Value::Float(x), Value::Bool(_)) => Value::Bool(*x != 0.0),
        (Value::Str(s), Value::Bool(_)) => match &**s {
            "true" => Value::Bool(true),
            "false" => Value::Bool(false),
            _ => raw.clone(),
        },
        _ => raw.clone(),
    }
}

/// Parses a command-line value: a number, `true`/`false`, else a string.
pub fn parse_value(text: &str) -> Value {
    match text {
        "true" => Value::Bool(true),
        "false" => Value::Bool(false),
        _ => match text.trim().parse::<f64>() {
            Ok(x) => Value::Float(x),
            Err(_) => Value::Str(Arc::from(text)),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Leaves handed out unbaked (collected or streamed) bake to exactly
    /// the meshes the derivation gives otherwise: positions, normals, UVs,
    /// faces and materials, also under mirroring, rotation and inserts.
    #[test]
    fn lot_seeds_differ_per_seed_and_lot() {
        assert_eq!(lot_seed(666, 0), 666);
        let a: Vec<u64> = (0..100).map(|i| lot_seed(0, i)).collect();
        let b: Vec<u64> = (0..100).map(|i| lot_seed(1, i)).collect();
        // Seed 1 is not seed 0 shifted by a lot.
        assert_ne!(&a[1..], &b[..99]);
        let mut all: Vec<u64> = a.iter().chain(&b).copied().collect();
        all.sort();
        all.dedup();
        // All different: lot 0 keeps the run's seed (0 and 1), the others
        // are hashes.
        assert_eq!(all.len(), 200);
        assert!(all.iter().all(|&s| s < 1 << 31));
    }

    #[test]
    fn leaves_bake_to_the_meshes() {
        let dir = std::env::temp_dir().join(format!("cga-engine-leaves-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("leaves.cga");
        std::fs::write(
            &path,
            r##"
Lot --> extrude(10) comp(f) { side : Facade | top : Roof }
Facade --> setupProjection(0, scope.xy, 2, 2) split(y) { ~3 : Floor }*
Floor --> split(x) { ~2 : Tile | 0.5 : Mirror }*
Tile --> projectUV(0) color("#806040") texture("bricks.jpg") Wall.
Mirror --> s(-scope.sx, '1, '1) r(0, 30, 0) i("builtin:cube") set(material.shininess, 12) M.
Roof --> reverseNormals t(0, 1, 0) primitiveCube() color(0.5, 0.5, 0.9) R.
"##,
        )
        .unwrap();
        let mut sources = cga_syntax::SourceMap::new();
        let program = crate::load(&cga_world::DiskWorld, &path, &mut sources)
            .usable()
            .expect("rules load");
        let assets = Assets::on_disk(&sources);
        let rule = program.start_rule(Some("Lot")).unwrap();
        let lot = crate::lot::rect(12.0, 7.0);
        let baked = generate_lot(
            &program,
            &assets,
            rule,
            &lot,
            0,
            &GenerateOptions::default(),
        );
        assert!(baked.1.is_none());
        let meshes = baked.0.meshes;
        assert!(meshes.len() > 40, "{} leaves", meshes.len());
        let options = GenerateOptions {
            leaves: true,
            ..GenerateOptions::default()
        };
        let (kept, error) = generate_lot(&program, &assets, rule, &lot, 0, &options);
        assert!(error.is_none() && kept.meshes.is_empty());
        let mut streamed = Vec::new();
        let (out, error) =
            generate_lot_streaming(&program, &assets, rule, &lot, 0, &options, |l| {
                streamed.push(l)
            });
        assert!(error.is_none() && out.leaves.is_empty() && out.meshes.is_empty());
        for leaves in [&kept.leaves, &streamed] {
            assert_eq!(leaves.len(), meshes.len());
            for (leaf, mesh) in leaves.iter().zip(&meshes) {
                assert_eq!(&leaf.to_mesh(), mesh);
            }
        }
        // Some leaves were mirrored, and some share their mesh (the cube).
        assert!(kept
            .leaves
            .iter()
            .any(|l| l.transform.matrix3.determinant() < 0.0));
        assert!(kept.leaves.iter().any(|l| Arc::strong_count(&l.mesh) > 2));
        let _ = std::fs::remove_dir_all(&dir);
    }
}
