//! `cga`: generate 3D models from CGA rule files, and check rule files.
//!
//! ```text
//! cga generate RULES.cga [--lot SPEC]... [--start-rule NAME] [--attr NAME=VALUE]...
//!                        [--seed N] [-o OUT.glb|OUT.gltf|OUT.obj] [--report OUT.json]
//! cga check RULES.cga
//! ```
//!
//! Standard output carries only the lines of `print()`, in derivation order.
//! Diagnostics go to standard error. Exit status: 0 on success, 1 when a rule
//! file has errors (or derivation stopped on one), 2 on usage errors.

mod report;

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::mpsc;

use clap::{Args, Parser, Subcommand};

use cga_engine::context::{LotContext, SceneContext};
/// Shapes are many small allocations, and leaves made on the deriving
/// threads are freed on the writing one: mimalloc's thread-local heaps do
/// both with fewer instructions than the system allocator (Candler: 227 M
/// to 202 M instructions for the derivation) at the price of more memory
/// held (a 10,000-lot city: 2.1 GB peak instead of 1.3 GB).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// mimalloc's `mi_option_purge_delay` (its `mimalloc.h` option list).
const MI_OPTION_PURGE_DELAY: libmimalloc_sys::mi_option_t = 15;

/// Memory freed is kept for reuse instead of being given back to the
/// system after 10 ms, mimalloc's default. A lot's meshes are freed and the
/// next lot's allocated within moments: given back, the memory came back
/// as fresh (huge) pages the kernel had to zero each time, which took a
/// sixth of the time of 25 Candler buildings (5,800 page faults; 380 when
/// kept). The process ends when its work does, so holding the peak costs
/// nothing.
fn keep_freed_memory() {
    // SAFETY: sets one of mimalloc's documented options to a documented
    // value (-1: never purge) before any other thread runs.
    unsafe { libmimalloc_sys::mi_option_set(MI_OPTION_PURGE_DELAY, -1) };
}

use cga_engine::derive::Leaf;
use cga_engine::generate::collect_lot;
use cga_engine::generate::generate_lot_streaming;
use cga_engine::generate::parse_value;
use cga_engine::geo::GeoOrigin;
use cga_engine::lot::{self, Lot};
use cga_engine::{GenerateOptions, Limits, LotOutput, RtError, Workspaces};
use cga_export::{ExportOptions, Format, Georeference, ModelWriter};
use cga_syntax::{Diagnostic, SourceMap};

#[derive(Parser)]
#[command(
    name = "cga",
    version,
    about = "Generate 3D models from CGA shape grammar rules"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Derive lots with a rule file and write the model.
    Generate(GenerateArgs),
    /// Parse and resolve a rule file; report every error.
    Check {
        /// The rule file.
        rules: PathBuf,
        /// `text` for people, `json` (one object with all diagnostics) for tools.
        #[arg(long, value_enum, default_value_t = CheckFormat::Text)]
        format: CheckFormat,
        /// A CityEngine workspace folder (projects side by side) where paths
        /// such as `/ESRI.lib/rules/x.cga` are looked for after the rule
        /// file's own workspace; repeatable, then `CGA_WORKSPACE`.
        #[arg(long = "workspace", value_name = "DIR")]
        workspaces: Vec<PathBuf>,
    },
}

#[derive(Args)]
struct GenerateArgs {
    /// The rule file (.cga).
    rules: PathBuf,
    /// A lot: `rect:W,D`, an .obj file (each face one lot) or a .geojson
    /// file (each polygon one lot). Repeatable. Default: `rect:20,30`.
    #[arg(long = "lot", value_name = "SPEC")]
    lots: Vec<String>,
    /// The start rule (default: the rule marked @StartRule, else `Lot`).
    #[arg(long, value_name = "NAME")]
    start_rule: Option<String>,
    /// Set a rule attribute: a number, `true`/`false`, or a string. Repeatable.
    #[arg(long = "attr", value_name = "NAME=VALUE")]
    attrs: Vec<String>,
    /// Random seed.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// A CityEngine workspace folder (projects side by side) where paths
    /// such as `/ESRI.lib/rules/x.cga` are looked for after the rule
    /// file's own workspace; repeatable, then `CGA_WORKSPACE`.
    #[arg(long = "workspace", value_name = "DIR")]
    workspaces: Vec<PathBuf>,
    /// Output model: .glb, .gltf or .obj.
    #[arg(short = 'o', long = "output", value_name = "FILE")]
    output: Option<PathBuf>,
    /// Write the values of report() as JSON.
    #[arg(long, value_name = "FILE")]
    report: Option<PathBuf>,
    /// Print timings on standard error: lots/s, shapes/s, triangles/s, peak memory.
    #[arg(long)]
    stats: bool,
    /// Worker threads (default: all cores). The output does not depend on it.
    #[arg(long, value_name = "N")]
    jobs: Option<usize>,
    /// Maximum nesting of rule invocations.
    #[arg(long, default_value_t = Limits::default().max_depth)]
    max_depth: usize,
    /// Maximum number of shapes per lot.
    #[arg(long, default_value_t = Limits::default().max_shapes)]
    max_shapes: usize,
    /// Maximum time per lot, in seconds.
    #[arg(long, default_value_t = Limits::default().max_seconds)]
    max_seconds: f64,
    /// Stop a lot whose shape's geometry exceeds this many faces.
    #[arg(long, default_value_t = Limits::default().max_faces)]
    max_faces: usize,
    /// Largest asset file (OBJ, tables, texts) that is read, in MiB.
    #[arg(long, default_value_t = cga_engine::assets::DEFAULT_MAX_ASSET_MIB)]
    max_asset_mib: u64,
    /// glTF/GLB: vertex data held before it is written out, in MiB (bounds
    /// memory; more is fewer primitives per material).
    #[arg(long, value_name = "MIB", default_value_t = cga_export::DEFAULT_FLUSH_MIB)]
    held_mib: usize,
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum CheckFormat {
    Text,
    Json,
}

/// How a run ended.
enum Failure {
    /// Errors in the rules (already reported): exit 1.
    Rules,
    /// A usage error (bad arguments, unreadable lot file): exit 2.
    Usage(String),
}

/// Stack for the thread that derives: deep but legal grammars (recursion up
/// to `--max-depth` rule invocations) must stop at the limit with a message,
/// not overflow the stack. Only the pages actually used are committed.
const DERIVATION_STACK: usize = 1 << 30;

fn main() -> ExitCode {
    keep_freed_memory();
    let cli = Cli::parse();
    let worker = std::thread::Builder::new()
        .stack_size(DERIVATION_STACK)
        .spawn(move || match cli.command {
            Command::Generate(args) => generate(args),
            Command::Check {
                rules,
                format,
                workspaces,
            } => check(&rules, format, &Workspaces::with_env(&workspaces)),
        });
    let result = match worker.map(|w| w.join()) {
        Ok(Ok(r)) => r,
        _ => {
            eprintln!("error: internal error while generating; please report this rule file");
            return ExitCode::from(1);
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::Rules) => ExitCode::from(1),
        Err(Failure::Usage(message)) => {
            eprintln!("error: {message}");
            ExitCode::from(2)
        }
    }
}

fn report_diagnostics(diags: &[Diagnostic], sources: &SourceMap) {
    for d in diags {
        eprint!("{}", d.render(sources));
    }
}

/// Loads and resolves a rule file, reporting its diagnostics.
fn load(
    path: &Path,
    sources: &mut SourceMap,
    workspaces: &Workspaces,
) -> Result<cga_engine::Program, Failure> {
    if !path.is_file() {
        return Err(Failure::Usage(format!(
            "rule file {} not found",
            path.display()
        )));
    }
    let loaded = cga_engine::load_with(path, sources, workspaces);
    report_diagnostics(&loaded.diagnostics, sources);
    loaded.program.ok_or(Failure::Rules)
}

fn check(path: &Path, format: CheckFormat, workspaces: &Workspaces) -> Result<(), Failure> {
    if format == CheckFormat::Text {
        let mut sources = SourceMap::new();
        let program = load(path, &mut sources, workspaces)?;
        eprintln!(
            "{}: ok ({} rules, {} attributes, {} functions)",
            path.display(),
            program.rules.len(),
            program.attrs.len(),
            program.functions.len()
        );
        return Ok(());
    }
    if !path.is_file() {
        return Err(Failure::Usage(format!(
            "rule file {} not found",
            path.display()
        )));
    }
    let mut sources = SourceMap::new();
    let loaded = cga_engine::load_with(path, &mut sources, workspaces);
    let diagnostics: Vec<serde_json::Value> = loaded
        .diagnostics
        .iter()
        .map(|d| diagnostic_json(d, &sources))
        .collect();
    let ok = loaded.program.is_some();
    let doc = serde_json::json!({ "file": path.display().to_string(), "ok": ok, "diagnostics": diagnostics });
    println!("{}", serde_json::to_string_pretty(&doc).unwrap_or_default());
    if ok {
        Ok(())
    } else {
        Err(Failure::Rules)
    }
}

/// A diagnostic as JSON for tools: severity, message, file, 1-based line and
/// column of the start and end, label and notes.
fn diagnostic_json(d: &Diagnostic, sources: &SourceMap) -> serde_json::Value {
    let severity = if d.is_error() { "error" } else { "warning" };
    let mut v = serde_json::json!({
        "severity": severity,
        "message": d.message,
        "label": d.label,
        "notes": d.notes,
    });
    if let Some(span) = d.span {
        let file = sources.get(span.file);
        let (line, column) = file.line_col(span.start);
        let (end_line, end_column) = file.line_col(span.end);
        v["file"] = file.path.display().to_string().into();
        v["line"] = line.into();
        v["column"] = column.into();
        v["end_line"] = end_line.into();
        v["end_column"] = end_column.into();
    }
    v
}

/// The lots of the `--lot` options, and the geographic origin of their
/// frame when some were given in longitude/latitude (all geographic files
/// are projected about the first one's origin, so they share one frame).
fn read_lots(specs: &[String]) -> Result<(Vec<Lot>, Option<GeoOrigin>), Failure> {
    if specs.is_empty() {
        return Ok((vec![lot::rect(20.0, 30.0)], None));
    }
    let mut lots = Vec::new();
    let mut frame: Option<GeoOrigin> = None;
    for spec in specs {
        if let Some(rect) = spec.strip_prefix("rect:") {
            lots.push(lot::parse_rect(rect).map_err(Failure::Usage)?);
            continue;
        }
        if let Some(grid) = spec.strip_prefix("grid:") {
            lots.extend(grid_lots(grid)?);
            continue;
        }
        let path = Path::new(spec);
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase());
        let more = match ext.as_deref() {
            Some("obj") => lot::from_obj(path),
            Some(ext @ ("geojson" | "json" | "fgb")) => {
                let read = if ext == "fgb" {
                    lot::from_flatgeobuf(path, frame)
                } else {
                    lot::from_geojson_georeferenced(path, frame)
                };
                read.map(|(lots, origin)| {
                    if let Some(o) = origin {
                        eprintln!(
                            "note: {} is in longitude/latitude; lots are in metres east (x) and north (-z) of lon {:.7}, lat {:.7} (recorded in the output)",
                            path.display(),
                            o.lon,
                            o.lat
                        );
                        frame = Some(o);
                    }
                    lots
                })
            }
            _ => {
                return Err(Failure::Usage(format!(
                    "unknown lot `{spec}`: expected rect:W,D, grid:COLSxROWS, an .obj, a .geojson or a .fgb (FlatGeobuf) file"
                )))
            }
        };
        lots.extend(more.map_err(Failure::Usage)?);
    }
    Ok((lots, frame))
}

/// `grid:COLSxROWS` (20 x 30 lots) or `grid:COLSxROWS:LOTS.obj` (copies of
/// the OBJ's lots): a synthetic city of lots in a grid, for benchmarks.
fn grid_lots(spec: &str) -> Result<Vec<Lot>, Failure> {
    let (dims, source) = match spec.split_once(':') {
        Some((d, s)) => (d, Some(s)),
        None => (spec, None),
    };
    let bad = || {
        Failure::Usage(format!(
            "expected grid:COLSxROWS[:LOTS.obj], found `grid:{spec}`"
        ))
    };
    let (c, r) = dims.split_once('x').ok_or_else(bad)?;
    let cols: usize = c.trim().parse().map_err(|_| bad())?;
    let rows: usize = r.trim().parse().map_err(|_| bad())?;
    if cols == 0 || rows == 0 || cols.saturating_mul(rows) > 10_000_000 {
        return Err(bad());
    }
    let base = match source {
        Some(path) => lot::from_obj(Path::new(path)).map_err(Failure::Usage)?,
        None => vec![lot::rect(20.0, 30.0)],
    };
    let (lo, hi) = base
        .iter()
        .filter_map(|l| cga_geometry::measure::bounds(&l.mesh))
        .fold(
            (
                cga_geometry::DVec3::splat(f64::INFINITY),
                cga_geometry::DVec3::splat(f64::NEG_INFINITY),
            ),
            |(lo, hi), (a, b)| (lo.min(a), hi.max(b)),
        );
    let step = (hi - lo) + cga_geometry::DVec3::splat(10.0);
    let mut lots = Vec::with_capacity(cols * rows * base.len());
    for row in 0..rows {
        for col in 0..cols {
            let shift = cga_geometry::DVec3::new(col as f64 * step.x, 0.0, -(row as f64) * step.z);
            for b in &base {
                let mut l = b.clone();
                l.mesh.map_positions(|p| p + shift);
                l.name = format!("grid {col},{row} {}", b.name);
                lots.push(l);
            }
        }
    }
    Ok(lots)
}

fn generate(args: GenerateArgs) -> Result<(), Failure> {
    let started = std::time::Instant::now();
    let format = match &args.output {
        Some(path) => Some(Format::from_path(path).ok_or_else(|| {
            Failure::Usage(format!(
                "cannot tell the output format of {}: use .glb, .gltf or .obj",
                path.display()
            ))
        })?),
        None => None,
    };
    let (lots, geo_origin) = read_lots(&args.lots)?;
    let mut sources = SourceMap::new();
    let workspaces = Workspaces::with_env(&args.workspaces);
    let program = load(&args.rules, &mut sources, &workspaces)?;
    let rule = program
        .start_rule(args.start_rule.as_deref())
        .map_err(Failure::Usage)?;
    let mut options = GenerateOptions {
        seed: args.seed,
        limits: Limits {
            max_depth: args.max_depth,
            max_shapes: args.max_shapes,
            max_seconds: args.max_seconds,
            max_faces: args.max_faces,
        },
        // The writer places each leaf's shared mesh while writing: no leaf
        // is copied into object coordinates first.
        leaves: true,
        ..GenerateOptions::default()
    };
    for a in &args.attrs {
        let (name, value) = a
            .split_once('=')
            .ok_or_else(|| Failure::Usage(format!("expected --attr NAME=VALUE, found `{a}`")))?;
        if name == "seed" && program.main_attr("seed").is_none() {
            // As in CityEngine, `seed` is the initial shapes' random seed.
            options.seed = value.trim().parse().map_err(|_| {
                Failure::Usage(format!("the seed must be a whole number, found `{value}`"))
            })?;
            continue;
        }
        let id = program.main_attr(name).ok_or_else(|| {
            let known: Vec<&str> = program.main_attrs.iter().map(|(n, _)| n.as_str()).collect();
            Failure::Usage(format!(
                "the rule file has no attribute `{name}` (attributes: {})",
                if known.is_empty() {
                    "none".to_string()
                } else {
                    known.join(", ")
                }
            ))
        })?;
        options.attrs.push((id, parse_value(value)));
    }

    let assets = cga_engine::assets::Assets::new(&sources)
        .with_max_file_mib(args.max_asset_mib)
        .with_workspaces(workspaces);
    let mut writer = match (&args.output, format) {
        (Some(path), Some(format)) => {
            let root = args
                .rules
                .parent()
                .map(Path::to_path_buf)
                .unwrap_or_default();
            let export = ExportOptions {
                texture_roots: project_roots(&root),
                georeference: geo_origin.map(|o| Georeference {
                    longitude: o.lon,
                    latitude: o.lat,
                    earth_radius: cga_engine::geo::EARTH_RADIUS,
                }),
                flush_mib: args.held_mib,
                ..ExportOptions::default()
            };
            Some(
                ModelWriter::create(path, format, export)
                    .map_err(|e| Failure::Usage(format!("cannot write {}: {e}", path.display())))?,
            )
        }
        _ => None,
    };

    let jobs = args.jobs.unwrap_or_else(|| {
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
    });
    // Context queries: found once here rather than for every lot. `inter`
    // queries need every lot's first pass before any lot's second one.
    let usage = cga_engine::context::ContextUse::of(&program);
    options.context_use = Some(usage);
    if usage.inter && lots.len() > 1 {
        options.scene = Some(std::sync::Arc::new(collect_scene(
            &program,
            &assets,
            rule,
            &lots,
            &options,
            jobs.max(1),
        )?));
    }
    let progress = progress_bar(lots.len());

    let mut failed_lots = 0usize;
    let mut reports = report::Reports::default();
    let mut shapes = 0usize;
    let mut leaves = 0usize;
    let mut seen_warnings = std::collections::HashSet::new();
    // Leaves go to the writing thread in batches as they are emitted, so
    // writing the model overlaps deriving it even for a single lot. For
    // glTF and GLB with several workers, the workers encode them into
    // vertex data first, leaving the writing thread little to do; with one
    // (one job, or one lot), the writing thread encodes the leaves it is
    // sent, so that two threads share the work. Either way a lot's leaves
    // are encoded in the same batches (`Batcher`), so the model is written
    // out at the same points and the output is the same. Without an output
    // leaves are dropped where they were made.
    let encoder = writer.as_ref().and_then(ModelWriter::encoder);
    let workers_encode = jobs.max(1).min(lots.len()) > 1;
    let has_writer = writer.is_some();
    let new_batcher = || match &encoder {
        Some(e) if workers_encode => Batcher::Encode(Box::new(e.another()), 0),
        _ if has_writer => Batcher::Leaves(Vec::new()),
        _ => Batcher::Drop,
    };
    // With one worker, the batches the writing thread encodes itself.
    let mut own_batcher = match &encoder {
        Some(e) if !workers_encode => Some(Batcher::Encode(Box::new(e.another()), 0)),
        _ => None,
    };
    // Takes what the lots produce, in lot order: each batch into the writer
    // as it comes, then the lot's prints, diagnostics and reports.
    let mut take = |i: usize, taken: Taken<Piece, (LotOutput, Option<RtError>)>| {
        let export = |e| Failure::Usage(format!("export failed: {e}"));
        let mut result = Ok(());
        let mut write = |piece| {
            if let (Some(w), Ok(())) = (writer.as_mut(), &result) {
                result = write_piece(w, piece, &mut leaves);
            }
        };
        let (out, error) = match (taken, &mut own_batcher) {
            (Taken::Piece(Piece::Leaves(batch)), Some(own)) => {
                for leaf in batch {
                    own.add(leaf, &mut write);
                }
                return result.map_err(export);
            }
            (Taken::Piece(piece), _) => {
                write(piece);
                return result.map_err(export);
            }
            (Taken::Done(r), own) => {
                if let Some(own) = own {
                    own.flush(&mut write);
                }
                result.map_err(export)?;
                r
            }
        };
        {
            use std::io::Write;
            let mut stdout = std::io::stdout().lock();
            for line in &out.prints {
                let _ = writeln!(stdout, "{line}");
            }
        }
        for w in &out.warnings {
            if seen_warnings.insert((w.message.clone(), w.span)) {
                progress.suspend(|| report_diagnostics(std::slice::from_ref(w), &sources));
            }
        }
        if let Some(e) = error {
            let mut d = e.to_diagnostic();
            if lots.len() > 1 {
                d = d.with_note(format!("in lot `{}`", lots[i].name));
            }
            progress.suspend(|| report_diagnostics(&[d], &sources));
            failed_lots += 1;
        }
        reports.add(&out.reports);
        shapes += out.shapes;
        progress.inc(1);
        Ok(())
    };
    let generate_one = |batcher: &mut Batcher, i: usize, send: &mut dyn FnMut(Piece)| {
        let r = generate_lot_streaming(&program, &assets, rule, &lots[i], i, &options, |leaf| {
            batcher.add(leaf, send)
        });
        batcher.flush(send);
        r
    };
    run_pipeline(
        lots.len(),
        jobs.max(1),
        new_batcher,
        generate_one,
        &mut take,
    )?;
    let derived_after = started.elapsed().as_secs_f64();
    progress.finish_and_clear();
    let failed = failed_lots > 0;
    if failed && lots.len() > 1 {
        eprintln!(
            "error: {failed_lots} of {} lots stopped on an error; the others were generated",
            lots.len()
        );
    }
    let mut triangles = 0u64;
    if let Some(w) = writer {
        let stats = w
            .finish()
            .map_err(|e| Failure::Usage(format!("export failed: {e}")))?;
        triangles = stats.triangles;
        for warning in &stats.warnings {
            eprintln!("warning: {warning}");
        }
        if let Some(path) = &args.output {
            eprintln!(
                "wrote {}: {} lots, {} shapes, {} leaf shapes, {} faces, {} triangles",
                path.display(),
                lots.len(),
                shapes,
                leaves,
                stats.faces,
                stats.triangles
            );
        }
    }
    if args.stats {
        let secs = started.elapsed().as_secs_f64().max(1e-9);
        eprintln!(
            "stats: {} lots, {} shapes, {} triangles written in {:.3} s (all lots derived after {:.3} s): {:.1} lots/s, {:.0} shapes/s, {:.0} triangles/s, peak memory {}",
            lots.len(),
            shapes,
            triangles,
            secs,
            derived_after,
            lots.len() as f64 / secs,
            shapes as f64 / secs,
            triangles as f64 / secs,
            peak_memory().map_or("unknown".to_string(), |kb| format!("{:.1} MiB", kb as f64 / 1024.0))
        );
    }
    if let Some(path) = &args.report {
        std::fs::write(path, reports.to_json())
            .map_err(|e| Failure::Usage(format!("cannot write {}: {e}", path.display())))?;
    }
    if failed {
        Err(Failure::Rules)
    } else {
        Ok(())
    }
}

/// The first pass of every lot (see `cga_engine::context`), for programs
/// with `inter` context queries, on `jobs` threads. Each lot's records are
/// put at its index, so the scene, and with it the output, does not depend
/// on the number of threads.
fn collect_scene(
    program: &cga_engine::Program,
    assets: &cga_engine::assets::Assets,
    rule: cga_engine::program::RuleId,
    lots: &[Lot],
    options: &GenerateOptions,
    jobs: usize,
) -> Result<SceneContext, Failure> {
    use std::sync::atomic::{AtomicUsize, Ordering};
    let next = AtomicUsize::new(0);
    let work = || {
        let mut done = Vec::new();
        loop {
            let i = next.fetch_add(1, Ordering::Relaxed);
            if i >= lots.len() {
                break;
            }
            done.push((i, collect_lot(program, assets, rule, &lots[i], i, options)));
        }
        done
    };
    let mut slots: Vec<Option<LotContext>> =
        std::iter::repeat_with(|| None).take(lots.len()).collect();
    std::thread::scope(|scope| {
        let mut workers = Vec::new();
        for _ in 0..jobs.min(lots.len()) {
            let worker = std::thread::Builder::new()
                .stack_size(DERIVATION_STACK)
                .spawn_scoped(scope, work)
                .map_err(|e| Failure::Usage(format!("cannot start worker threads: {e}")))?;
            workers.push(worker);
        }
        for w in workers {
            // A worker that panicked leaves its lots empty: their second
            // pass runs again and reports what went wrong there.
            for (i, records) in w.join().unwrap_or_default() {
                slots[i] = Some(records);
            }
        }
        Ok::<(), Failure>(())
    })?;
    let records = slots
        .into_iter()
        .map(|r| r.unwrap_or_else(|| LotContext::new(None)))
        .collect();
    Ok(SceneContext::new(
        records,
        options.context_use.unwrap_or_default(),
    ))
}

/// Writes a piece of a lot's output, counting its leaves.
fn write_piece(
    w: &mut ModelWriter,
    piece: Piece,
    leaves: &mut usize,
) -> Result<(), cga_export::ExportError> {
    match piece {
        Piece::Leaves(batch) => {
            *leaves += batch.len();
            batch.iter().try_for_each(|leaf| {
                w.add_placed(&leaf.mesh, Some(&leaf.transform), &leaf.materials)
            })
        }
        Piece::Encoded(batch, n) => {
            *leaves += n;
            w.append(batch)
        }
    }
}

/// A piece of a lot's output on its way to the writing thread.
enum Piece {
    /// Leaves, for writers that take meshes (OBJ).
    Leaves(Vec<Leaf>),
    /// Leaves encoded into vertex data (glTF, GLB), and how many.
    Encoded(cga_export::Encoded, usize),
}

/// Leaves per piece at most: a message per leaf would wake the writing
/// thread for each (a system call apiece).
const LEAF_BATCH: usize = 512;

/// Encoded vertex data per piece at most, in bytes: large enough that the
/// writing thread is seldom woken, small enough to keep little in flight.
const ENCODED_BATCH_BYTES: usize = 1 << 20;

/// How a worker gathers its leaves into pieces.
enum Batcher {
    /// No output: leaves are dropped where they are made.
    Drop,
    Leaves(Vec<Leaf>),
    /// The leaves encoded so far into the encoder's batch, and their count.
    Encode(Box<cga_export::Encoder>, usize),
}

impl Batcher {
    fn add(&mut self, leaf: Leaf, send: &mut dyn FnMut(Piece)) {
        match self {
            Batcher::Drop => {}
            Batcher::Leaves(batch) => {
                batch.push(leaf);
                if batch.len() == LEAF_BATCH {
                    let full = std::mem::replace(batch, Vec::with_capacity(LEAF_BATCH));
                    send(Piece::Leaves(full));
                }
            }
            Batcher::Encode(encoder, n) => {
                encoder.add_placed(&leaf.mesh, Some(&leaf.transform), &leaf.materials);
                *n += 1;
                if *n == LEAF_BATCH || encoder.bytes() >= ENCODED_BATCH_BYTES {
                    send(Piece::Encoded(encoder.take(), std::mem::take(n)));
                }
            }
        }
    }

    /// Sends what was gathered (at the end of a lot).
    fn flush(&mut self, send: &mut dyn FnMut(Piece)) {
        match self {
            Batcher::Drop => {}
            Batcher::Leaves(batch) => {
                if !batch.is_empty() {
                    send(Piece::Leaves(std::mem::take(batch)));
                }
            }
            Batcher::Encode(encoder, n) => {
                if *n > 0 {
                    send(Piece::Encoded(encoder.take(), std::mem::take(n)));
                }
            }
        }
    }
}

/// What the writing thread is handed for a lot, in order: the pieces of
/// its output as they are sent, then its result.
enum Taken<L, R> {
    Piece(L),
    Done(R),
}

/// What a worker sends for a lot: the channel its pieces will come
/// through (when it starts), then its result.
enum Delivery<L, R> {
    Pieces(mpsc::Receiver<L>),
    Done(R),
}

/// Derives lots `0..count` on `jobs` worker threads while the calling
/// thread hands what they produce to `take` in lot order: the pieces of a
/// lot's output as they come (`generate` sends them through its sink, each
/// piece a message: batches, not single leaves, so that the writing thread
/// is not woken for every leaf), then its result. So writing overlaps
/// deriving, even within one lot, and the output does not depend on the
/// number of threads. Each worker has a state of its own, made by `init`,
/// that `generate` uses for all its lots. A worker starts a lot only while
/// fewer than a few lots per worker wait to be taken, so memory holds a
/// bounded number of lots, not the whole city. An error from `take` stops
/// the workers and is returned.
fn run_pipeline<W, L: Send, R: Send>(
    count: usize,
    jobs: usize,
    init: impl Fn() -> W + Sync,
    generate: impl Fn(&mut W, usize, &mut dyn FnMut(L)) -> R + Sync,
    take: &mut dyn FnMut(usize, Taken<L, R>) -> Result<(), Failure>,
) -> Result<(), Failure> {
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
    use std::sync::{Condvar, Mutex};

    /// Stops the other workers if this one panics (they would otherwise
    /// wait for a lot that never comes).
    struct StopOnPanic<'a>(&'a dyn Fn());
    impl Drop for StopOnPanic<'_> {
        fn drop(&mut self) {
            if std::thread::panicking() {
                (self.0)();
            }
        }
    }

    let window = jobs * 4;
    let next = AtomicUsize::new(0);
    let stop = AtomicBool::new(false);
    // Lots taken so far, and a signal when it grows or work stops.
    let taken = (Mutex::new(0usize), Condvar::new());
    let lock = || taken.0.lock().unwrap_or_else(|e| e.into_inner());
    let halt = || {
        // Under the lock, so that no worker misses the signal.
        let _done = lock();
        stop.store(true, Ordering::Relaxed);
        taken.1.notify_all();
    };
    std::thread::scope(|scope| {
        let (tx, rx) = mpsc::channel::<(usize, Delivery<L, R>)>();
        for _ in 0..jobs.min(count) {
            let tx = tx.clone();
            let (next, stop, taken, init, generate, lock, halt) =
                (&next, &stop, &taken, &init, &generate, &lock, &halt);
            let worker = move || {
                let _guard = StopOnPanic(halt);
                let mut state = init();
                loop {
                    let i = next.fetch_add(1, Ordering::Relaxed);
                    if i >= count {
                        break;
                    }
                    {
                        let mut done = lock();
                        while i >= *done + window && !stop.load(Ordering::Relaxed) {
                            done = taken.1.wait(done).unwrap_or_else(|e| e.into_inner());
                        }
                    }
                    let (piece_tx, piece_rx) = mpsc::channel();
                    if stop.load(Ordering::Relaxed)
                        || tx.send((i, Delivery::Pieces(piece_rx))).is_err()
                    {
                        break;
                    }
                    let r = generate(&mut state, i, &mut |piece| {
                        // A closed channel means the writing stopped.
                        let _ = piece_tx.send(piece);
                    });
                    drop(piece_tx);
                    if tx.send((i, Delivery::Done(r))).is_err() {
                        break;
                    }
                }
            };
            if let Err(e) = std::thread::Builder::new()
                .stack_size(DERIVATION_STACK)
                .spawn_scoped(scope, worker)
            {
                halt();
                return Err(Failure::Usage(format!("cannot start worker threads: {e}")));
            }
        }
        drop(tx);
        let mut pieces = std::collections::BTreeMap::new();
        let mut results = std::collections::BTreeMap::new();
        // The next message for lot `i` of the kind asked for, out of the
        // waiting ones; `None` when the workers are gone.
        let mut wait_for = |i: usize, want_pieces: bool| loop {
            if want_pieces {
                if let Some(r) = pieces.remove(&i) {
                    return Some(Delivery::Pieces(r));
                }
            } else if let Some(r) = results.remove(&i) {
                return Some(Delivery::Done(r));
            }
            match rx.recv() {
                Ok((j, Delivery::Pieces(r))) => {
                    pieces.insert(j, r);
                }
                Ok((j, Delivery::Done(r))) => {
                    results.insert(j, r);
                }
                Err(_) => return None,
            }
        };
        let mut result = Ok(());
        'lots: for i in 0..count {
            let Some(Delivery::Pieces(piece_rx)) = wait_for(i, true) else {
                break;
            };
            for piece in piece_rx.iter() {
                result = take(i, Taken::Piece(piece));
                if result.is_err() {
                    break 'lots;
                }
            }
            let Some(Delivery::Done(r)) = wait_for(i, false) else {
                break;
            };
            result = take(i, Taken::Done(r));
            if result.is_err() {
                break;
            }
            *lock() = i + 1;
            taken.1.notify_all();
        }
        halt();
        result
    })
}

/// Peak resident memory of this process in KiB (Linux: `VmHWM`).
fn peak_memory() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// A progress bar on standard error for long runs; hidden when standard
/// error is not a terminal or there is a single lot.
fn progress_bar(lots: usize) -> indicatif::ProgressBar {
    use std::io::IsTerminal;
    if lots < 2 || !std::io::stderr().is_terminal() {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(lots as u64);
    if let Ok(style) = indicatif::ProgressStyle::with_template(
        "{elapsed_precise} [{bar:40}] {pos}/{len} lots ({per_sec}, {eta} left)",
    ) {
        bar.set_style(style.progress_chars("=> "));
    }
    bar
}

/// Where textures named in the rules may be: the rule file's folder and its
/// ancestors (project roots), with their `assets/` folders.
fn project_roots(rule_dir: &Path) -> Vec<PathBuf> {
    let mut roots = Vec::new();
    for dir in rule_dir.ancestors() {
        roots.push(dir.join("assets"));
        roots.push(dir.to_path_buf());
    }
    roots
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs the pipeline where lot `i` emits `i % 5` leaves `(i, k)` and
    /// results in `10 i`; returns what was taken, in order.
    fn run(count: usize, jobs: usize, fail_at: Option<usize>) -> (Vec<String>, bool) {
        let mut seen = Vec::new();
        // Each worker counts the lots it derived in its own state.
        let generate = |lots: &mut usize, i: usize, sink: &mut dyn FnMut((usize, usize))| {
            *lots += 1;
            assert!(*lots <= count);
            for k in 0..i % 5 {
                sink((i, k));
            }
            10 * i
        };
        let r = run_pipeline(count, jobs, || 0usize, generate, &mut |i, taken| {
            match taken {
                Taken::Piece((j, k)) => seen.push(format!("{i}:{j}.{k}")),
                Taken::Done(r) => seen.push(format!("{i}={r}")),
            }
            if Some(i) == fail_at {
                return Err(Failure::Usage("stop".into()));
            }
            Ok(())
        });
        (seen, r.is_ok())
    }

    #[test]
    fn pipeline_takes_everything_in_lot_order() {
        let mut want = Vec::new();
        for i in 0..60 {
            for k in 0..i % 5 {
                want.push(format!("{i}:{i}.{k}"));
            }
            want.push(format!("{i}={}", 10 * i));
        }
        for jobs in [1, 2, 3, 8] {
            let (seen, ok) = run(60, jobs, None);
            assert!(ok);
            assert_eq!(seen, want, "{jobs} jobs");
        }
        assert_eq!(run(0, 2, None), (Vec::new(), true));
    }

    #[test]
    fn pipeline_stops_on_an_error() {
        let (seen, ok) = run(100, 3, Some(6));
        assert!(!ok);
        // Lot 6 has one leaf: taking it failed, nothing after it is taken.
        assert_eq!(seen.last().map(String::as_str), Some("6:6.0"));
        assert_eq!(seen.len(), 17);
    }

    #[test]
    fn a_worker_panic_does_not_hang_the_pipeline() {
        let r = std::panic::catch_unwind(|| {
            let generate = |_: &mut (), i: usize, _: &mut dyn FnMut(())| {
                assert!(i != 3, "lot 3 fails");
                i
            };
            run_pipeline(40, 2, || (), generate, &mut |_, _| Ok(()))
        });
        assert!(r.is_err());
    }
}
