//! `cga`: generate 3D models from CGA rule files, and check rule files.
//!
//! ```text
//! cga generate RULES.cga [--lot SPEC]... [--start-rule NAME] [--attr NAME=VALUE]...
//!                        [--seed N] [-o OUT.glb|OUT.gltf|OUT.obj] [--report OUT.json]
//! cga check RULES.cga
//! cga serve RULES.cga [--lot SPEC]... [--port N] [--host H]
//! ```
//!
//! Standard output carries only the lines of `print()`, in derivation order.
//! Diagnostics go to standard error. Exit status: 0 on success, 1 when a rule
//! file has errors (or derivation stopped on one), 2 on usage errors.

mod report;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand};

/// The engine's allocator (`cga_alloc`): mimalloc's thread-local heaps,
/// at the price of more memory held (a 10,000-lot city: 2.1 GB peak
/// instead of 1.3 GB with the system allocator).
#[global_allocator]
static ALLOCATOR: cga_alloc::Allocator = cga_alloc::Allocator;

use cga::{
    Diagnostic, Engine, Error, ExportOptions, Format, Georeference, LotResult, ModelWriter,
    Options, Rules, Target, Workspaces,
};
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
    Generate(Box<GenerateArgs>),
    /// Parse and resolve a rule file; report every error.
    Check {
        /// The rule file.
        rules: PathBuf,
        /// `text` for people, `json` (one object with all diagnostics) for tools.
        #[arg(long, value_enum, default_value_t = CheckFormat::Text)]
        format: CheckFormat,
        /// The style of the rule file to check (default: its default style).
        #[arg(long, value_name = "NAME")]
        style: Option<String>,
        /// A CityEngine workspace folder (projects side by side) where paths
        /// such as `/ESRI.lib/rules/x.cga` are looked for after the rule
        /// file's own workspace; repeatable, then `CGA_WORKSPACE`.
        #[arg(long = "workspace", value_name = "DIR")]
        workspaces: Vec<PathBuf>,
    },
    /// Format rule files in place (indentation, trailing spaces, blank lines).
    Fmt {
        /// The rule files.
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// Change nothing: list the files that formatting would change,
        /// and exit with status 1 if there are any.
        #[arg(long)]
        check: bool,
    },
    /// Live preview in the browser: serves a page that shows the model,
    /// regenerates when a file of the workspace changes or an attribute
    /// is moved.
    Serve {
        /// The rule file.
        rules: PathBuf,
        /// A lot, as for `generate`; repeatable. Default: `rect:20,30`.
        #[arg(long = "lot", value_name = "SPEC")]
        lots: Vec<String>,
        /// The port to listen on (0: any free port).
        #[arg(long, default_value_t = cga_serve::DEFAULT_PORT)]
        port: u16,
        /// The address to listen on; only this machine by default.
        #[arg(long, default_value = "127.0.0.1")]
        host: String,
        /// Further folders the rules may read (as for `generate`).
        #[arg(long = "workspace", value_name = "DIR")]
        workspaces: Vec<PathBuf>,
        /// Maximum time per lot, in seconds: a runaway rule is stopped and
        /// reported, and the preview goes on.
        #[arg(long, default_value_t = cga_serve::DEFAULT_MAX_SECONDS)]
        max_seconds: f64,
    },
    /// Language server for editors, on standard input and output.
    Lsp {
        /// Accepted for editor clients that pass it; stdio is the only transport.
        #[arg(long)]
        stdio: bool,
        /// Where `/Project/...` paths are looked for (as for `check`).
        #[arg(long = "workspace", value_name = "DIR")]
        workspaces: Vec<PathBuf>,
    },
}

#[derive(Args)]
struct GenerateArgs {
    /// The rule file (.cga).
    rules: PathBuf,
    /// A lot: `rect:W,D`, `grid:COLSxROWS`, an .obj file (each face one
    /// lot) or a .geojson, .fgb, .gpkg or .shp file (each feature one lot).
    /// Repeatable. Default: `rect:20,30`.
    #[arg(long = "lot", value_name = "SPEC")]
    lots: Vec<String>,
    /// The coordinate reference system of every lot file, whatever they
    /// declare: `EPSG:N`, or `local` (metres of a plane, not georeferenced).
    #[arg(long, value_name = "EPSG:N")]
    crs: Option<cga::CrsOption>,
    /// Invalid lots (crossing rings, stray holes, slivers): `repair` them,
    /// `skip` them or stop with an `error`; each is named in a warning.
    #[arg(long, value_name = "WHAT", default_value = "repair")]
    invalid: cga::InvalidPolicy,
    /// Each polygon of a GIS feature (a MultiPolygon's parts) is a lot of
    /// its own, named ID, ID.1, ...; by default a feature is one lot whose
    /// polygons are the faces of one initial shape.
    #[arg(long)]
    split_multipolygons: bool,
    /// The start rule (default: the rule marked @StartRule, else `Lot`).
    #[arg(long, value_name = "NAME")]
    start_rule: Option<String>,
    /// The style of the rule file to generate with (`style NAME` in the
    /// file; default: its default style).
    #[arg(long, value_name = "NAME")]
    style: Option<String>,
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
    #[arg(long, default_value_t = cga::Limits::default().max_depth)]
    max_depth: usize,
    /// Maximum number of shapes per lot.
    #[arg(long, default_value_t = cga::Limits::default().max_shapes)]
    max_shapes: usize,
    /// Maximum time per lot, in seconds.
    #[arg(long, default_value_t = cga::Limits::default().max_seconds)]
    max_seconds: f64,
    /// Stop a lot whose shape's geometry exceeds this many faces.
    #[arg(long, default_value_t = cga::Limits::default().max_faces)]
    max_faces: usize,
    /// Largest asset file (OBJ, tables, texts) that is read, in MiB.
    #[arg(long, default_value_t = cga::DEFAULT_MAX_ASSET_MIB)]
    max_asset_mib: u64,
    /// glTF/GLB: vertex data held before it is written out, in MiB (bounds
    /// memory; more is fewer primitives per material).
    #[arg(long, value_name = "MIB", default_value_t = cga::DEFAULT_FLUSH_MIB)]
    held_mib: usize,
    /// How lots are kept apart in the model: `lot` (a glTF node per lot,
    /// named by it, its index and attributes in `extras`; an OBJ group per
    /// lot) or `material` (everything merged by material). Default: `lot`
    /// up to 10,000 lots, `material` above, where a node per lot makes the
    /// glTF JSON large.
    #[arg(long, value_name = "lot|material")]
    granularity: Option<cga::Granularity>,
    /// glTF/GLB: the point positions are written relative to, kept in
    /// double precision in the node translation (32-bit floats lose
    /// millimetres beyond 16 km): `X,Y` in the lots' metres (x east, y
    /// north), `auto` (the lots' centre, when more than 1 km from 0) or
    /// `none`. 3D Tiles: each tile is written from its own centre unless
    /// `none`. OBJ keeps full coordinates.
    #[arg(long, value_name = "X,Y|auto|none", default_value = "auto")]
    origin: OriginArg,
    /// glTF/GLB/3D Tiles: write every inserted asset as geometry of its
    /// own, instead of once per file placed as instances
    /// (EXT_mesh_gpu_instancing), for viewers without that extension.
    #[arg(long)]
    no_instances: bool,
    /// 3D Tiles: triangles in a tile's content at most (a leaf's lots that
    /// make more are written as several contents; more only where a lot
    /// is larger than the average by itself).
    #[arg(long, value_name = "N", default_value_t = 300_000)]
    tile_triangles: u64,
}

/// `--origin`.
#[derive(Clone, Copy, Debug, PartialEq)]
enum OriginArg {
    Auto,
    None,
    At(f64, f64),
}

impl std::str::FromStr for OriginArg {
    type Err = String;

    fn from_str(s: &str) -> Result<OriginArg, String> {
        match s.trim() {
            "auto" => Ok(OriginArg::Auto),
            "none" => Ok(OriginArg::None),
            xy => {
                let parse = |v: &str| v.trim().parse::<f64>().ok().filter(|v| v.is_finite());
                match xy.split_once(',') {
                    Some((x, y)) => match (parse(x), parse(y)) {
                        (Some(x), Some(y)) => Ok(OriginArg::At(x, y)),
                        _ => Err(format!(
                            "expected --origin X,Y with two numbers, found `{xy}`"
                        )),
                    },
                    None => Err(format!("expected --origin X,Y, auto or none, found `{xy}`")),
                }
            }
        }
    }
}

#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum CheckFormat {
    Text,
    Json,
}

/// How a run ended.
enum Failure {
    /// Errors in the rules, or lots that stopped on one, or a model that
    /// could not be written (already reported): exit 1.
    Reported,
    /// An error to report: exit 1.
    Error(String),
    /// A usage error (bad arguments, unreadable lot file): exit 2.
    Usage(String),
}

impl From<Error> for Failure {
    fn from(e: Error) -> Failure {
        match e {
            // Already reported with the rules' diagnostics.
            Error::Rules { .. } => Failure::Reported,
            Error::StartRule(_)
            | Error::UnknownAttribute { .. }
            | Error::Value(_)
            | Error::Lot(_) => Failure::Usage(e.to_string()),
            Error::Export(_) | Error::Cancelled | Error::Threads(_) => {
                Failure::Error(e.to_string())
            }
        }
    }
}

/// Stack for the thread that parses and resolves: the library grows the
/// stack where it needs to, but the first frames of a deep parse are
/// cheaper on a thread that starts with room.
const MAIN_STACK: usize = 64 << 20;

/// Lots up to which a model gets a node (group) per lot by default.
const NODES_PER_LOT_UP_TO: usize = 10_000;

fn main() -> ExitCode {
    // The process ends when its work does: holding the peak costs nothing.
    cga_alloc::keep_freed_memory(None);
    let cli = Cli::parse();
    let worker = std::thread::Builder::new()
        .stack_size(MAIN_STACK)
        .spawn(move || match cli.command {
            Command::Generate(args) => generate(*args),
            Command::Check {
                rules,
                format,
                style,
                workspaces,
            } => check(&rules, format, style.as_deref(), &workspaces),
            Command::Fmt { files, check } => fmt(&files, check),
            Command::Serve {
                rules,
                lots,
                port,
                host,
                workspaces,
                max_seconds,
            } => {
                // Edits are answered in a few hundred milliseconds: no
                // stalls for the kernel's compaction of huge pages.
                cga_alloc::allow_huge_pages(false);
                let mut config = cga_serve::Config::new(rules);
                config.lots = lots;
                config.port = port;
                config.host = host;
                config.workspaces = workspaces;
                config.limits.max_seconds = max_seconds;
                cga_serve::run(config).map_err(Failure::Error)
            }
            Command::Lsp { workspaces, .. } => {
                cga_lsp::run_stdio(&workspaces).map_err(|e| Failure::Error(e.to_string()))
            }
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
        Err(Failure::Reported) => ExitCode::from(1),
        Err(Failure::Error(message)) => {
            eprintln!("error: {message}");
            ExitCode::from(1)
        }
        Err(Failure::Usage(message)) => {
            eprintln!("error: {message}");
            ExitCode::from(2)
        }
    }
}

/// `cga fmt`: each file through the formatter of `cga_lsp::format`.
fn fmt(files: &[PathBuf], check: bool) -> Result<(), Failure> {
    let mut unformatted = false;
    for path in files {
        let bytes = std::fs::read(path)
            .map_err(|e| Failure::Usage(format!("cannot read {}: {e}", path.display())))?;
        let text = cga::decode_text(&bytes);
        let formatted = cga_lsp::format::format(&text);
        if formatted.as_bytes() == bytes.as_slice() {
            continue;
        }
        if check {
            eprintln!("{}: not formatted", path.display());
            unformatted = true;
        } else {
            std::fs::write(path, formatted)
                .map_err(|e| Failure::Error(format!("cannot write {}: {e}", path.display())))?;
        }
    }
    if unformatted {
        return Err(Failure::Reported);
    }
    Ok(())
}

fn report_diagnostics<'a>(diags: impl IntoIterator<Item = &'a Diagnostic>) {
    for d in diags {
        eprint!("{}", d.render());
    }
}

/// Loads a rule file, reporting its diagnostics.
fn load(engine: &Engine, path: &Path) -> Result<Rules, Failure> {
    if !engine.world().is_file(path) {
        return Err(Failure::Usage(format!(
            "rule file {} not found",
            path.display()
        )));
    }
    Ok(engine.load(path))
}

fn check(
    path: &Path,
    format: CheckFormat,
    style: Option<&str>,
    workspaces: &[PathBuf],
) -> Result<(), Failure> {
    let engine = Engine::on_disk()
        .workspaces(Workspaces::with_env(workspaces))
        .style(style);
    let rules = load(&engine, path)?;
    if format == CheckFormat::Text {
        report_diagnostics(rules.diagnostics());
        if rules.has_errors() {
            return Err(Failure::Reported);
        }
        let size = rules.size();
        let count =
            |n: usize, one: &str, many: &str| format!("{n} {}", if n == 1 { one } else { many });
        eprintln!(
            "{}: ok ({}, {}, {})",
            path.display(),
            count(size.rules, "rule", "rules"),
            count(size.attributes, "attribute", "attributes"),
            count(size.functions, "function or const", "functions and consts")
        );
        eprintln!("styles: {}", rules.styles().join(", "));
        eprintln!("start rules: {}", rules.start_rules().join(", "));
        return Ok(());
    }
    let diagnostics: Vec<serde_json::Value> =
        rules.diagnostics().iter().map(diagnostic_json).collect();
    let ok = !rules.has_errors();
    let doc = serde_json::json!({
        "file": path.display().to_string(),
        "ok": ok,
        "diagnostics": diagnostics,
        "styles": rules.styles(),
        "start_rules": rules.start_rules(),
    });
    println!("{}", serde_json::to_string_pretty(&doc).unwrap_or_default());
    if ok {
        Ok(())
    } else {
        Err(Failure::Reported)
    }
}

/// A diagnostic as JSON for tools: severity, message, file, 1-based line and
/// column of the start and end, label and notes.
fn diagnostic_json(d: &Diagnostic) -> serde_json::Value {
    let severity = if d.is_error() { "error" } else { "warning" };
    let mut v = serde_json::json!({
        "severity": severity,
        "message": d.message,
        "label": d.label,
        "notes": d.notes,
    });
    if let Some(l) = &d.location {
        v["file"] = l.file.display().to_string().into();
        v["line"] = l.line.into();
        v["column"] = l.column.into();
        v["end_line"] = l.end_line.into();
        v["end_column"] = l.end_column.into();
    }
    v
}

fn generate(args: GenerateArgs) -> Result<(), Failure> {
    let started = std::time::Instant::now();
    // `.json`: a 3D Tiles tileset (its tiles are written beside it).
    let tileset = args.output.as_ref().filter(|p| {
        p.extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("json"))
    });
    let format = match &args.output {
        Some(_) if tileset.is_some() => None,
        Some(path) => Some(Format::from_path(path).ok_or_else(|| {
            Failure::Usage(format!(
                "cannot tell the output format of {}: use .glb, .gltf, .obj or tileset.json (3D Tiles)",
                path.display()
            ))
        })?),
        None => None,
    };
    if let (Some(_), OriginArg::At(..)) = (tileset, args.origin) {
        return Err(Failure::Usage(
            "--origin X,Y is for GLB and glTF: a tileset's tiles are each written from their own centre (--origin none turns that off)".into(),
        ));
    }
    let lot_options = cga::LotOptions {
        crs: args.crs.clone(),
        invalid: args.invalid,
        split_multipolygons: args.split_multipolygons,
    };
    let lots = cga::lots::read_with(&args.lots, &lot_options)?;
    for note in &lots.notes {
        eprintln!("note: {note}");
    }
    for warning in &lots.warnings {
        eprintln!("warning: {warning}");
    }
    let engine = Engine::on_disk()
        .max_asset_mib(args.max_asset_mib)
        .workspaces(Workspaces::with_env(&args.workspaces))
        .style(args.style.as_deref());
    let rules = load(&engine, &args.rules)?;
    report_diagnostics(rules.diagnostics());
    let mut options = Options {
        seed: args.seed,
        start_rule: args.start_rule.clone(),
        limits: cga::Limits {
            max_depth: args.max_depth,
            max_shapes: args.max_shapes,
            max_seconds: args.max_seconds,
            max_faces: args.max_faces,
        },
        jobs: args.jobs,
        ..Options::default()
    };
    for a in &args.attrs {
        let (name, value) = a
            .split_once('=')
            .ok_or_else(|| Failure::Usage(format!("expected --attr NAME=VALUE, found `{a}`")))?;
        options = options.attr(name, cga::parse_value(value));
    }
    if rules.has_errors() {
        return Err(Failure::Reported);
    }
    // Usage errors (start rule, attribute names) before any file is made.
    rules.start_rule(options.start_rule.as_deref())?;
    rules.check_attributes(&options)?;

    let mut writer = match (&args.output, format) {
        (Some(path), Some(format)) => {
            let export = ExportOptions {
                georeference: lots.origin.map(|o| Georeference {
                    longitude: o.lon,
                    latitude: o.lat,
                    projection: o.proj_string(),
                }),
                // GIS y north is the model's -z.
                origin: match args.origin {
                    OriginArg::Auto => cga::lots::local_origin(&lots.lots),
                    OriginArg::None => None,
                    OriginArg::At(x, y) => Some(cga::DVec3::new(x, 0.0, -y)),
                },
                instances: !args.no_instances,
                flush_mib: args.held_mib,
                granularity: args.granularity.unwrap_or_else(|| {
                    if lots.lots.len() > NODES_PER_LOT_UP_TO {
                        eprintln!(
                            "note: {} lots: the model is merged by material (--granularity lot for a node per lot)",
                            lots.lots.len()
                        );
                        cga::Granularity::Material
                    } else {
                        cga::Granularity::Lot
                    }
                }),
                ..rules.export_options()
            };
            Some(
                ModelWriter::create(path, format, export)
                    .map_err(|e| Failure::Usage(format!("cannot write {}: {e}", path.display())))?,
            )
        }
        _ => None,
    };

    let progress = progress_bar(lots.lots.len());
    let mut reports = args.report.as_ref().map(|_| report::ReportFile::default());
    let mut seen_warnings = std::collections::HashSet::new();
    let many = lots.lots.len() > 1;
    let each = |lot: LotResult| {
        {
            use std::io::Write;
            let mut stdout = std::io::stdout().lock();
            for line in &lot.prints {
                let _ = writeln!(stdout, "{line}");
            }
        }
        for w in &lot.warnings {
            if seen_warnings.insert((w.message.clone(), w.location.clone())) {
                progress.suspend(|| report_diagnostics([w]));
            }
        }
        if let Some(e) = lot.error {
            let e = if many {
                e.with_note(format!("in lot `{}`", lot.name))
            } else {
                e
            };
            progress.suspend(|| report_diagnostics([&e]));
        }
        if let Some(r) = &mut reports {
            r.add_lot(lot.index, &lot.name, &lot.reports);
        }
        // A tileset counts lots as they are generated, not as they are
        // handed over in lot order.
        if tileset.is_none() {
            progress.inc(1);
        }
    };
    let mut tiles_written = None;
    let summary = match tileset {
        Some(path) => {
            let tiles = cga_tiles::TilesetOptions {
                export: ExportOptions {
                    georeference: cga_tiles::georeference(lots.origin),
                    instances: !args.no_instances,
                    flush_mib: args.held_mib,
                    ..rules.export_options()
                },
                tile_origins: args.origin != OriginArg::None,
                max_triangles_per_tile: args.tile_triangles.max(1),
                ..Default::default()
            };
            let generated = |n: usize| progress.set_position(n as u64);
            let stats = cga_tiles::write_tileset(
                &rules, &lots.lots, &options, &tiles, path, each, generated,
            )?;
            let summary = stats.summary.clone();
            tiles_written = Some(stats);
            summary
        }
        None => {
            let target = match &mut writer {
                Some(w) => Target::Writer(w),
                None => Target::Nothing,
            };
            rules.generate_lots(&lots.lots, &options, target, each)?
        }
    };
    progress.finish_and_clear();
    if summary.failed > 0 && many {
        eprintln!(
            "error: {} of {} lots stopped on an error; the others were generated",
            summary.failed, summary.lots
        );
    }
    let mut triangles = 0u64;
    if let (Some(stats), Some(path)) = (&tiles_written, tileset) {
        triangles = stats.triangles;
        for warning in &stats.warnings {
            eprintln!("warning: {warning}");
        }
        eprintln!(
            "wrote {}: {} lots, {} shapes, {} leaf shapes, {} tiles ({} leaves), {} triangles (and {} in the parents' massing)",
            path.display(),
            summary.lots,
            summary.shapes,
            summary.leaves,
            stats.tiles,
            stats.leaves,
            stats.triangles,
            stats.massing_triangles
        );
    }
    match (writer, &args.output) {
        (Some(w), Some(path)) => {
            let stats = w
                .finish()
                .map_err(|e| Failure::Error(format!("writing the model failed: {e}")))?;
            triangles = stats.triangles;
            for warning in &stats.warnings {
                eprintln!("warning: {warning}");
            }
            eprintln!(
                "wrote {}: {} lots, {} shapes, {} leaf shapes, {} faces, {} triangles",
                path.display(),
                summary.lots,
                summary.shapes,
                summary.leaves,
                stats.faces,
                stats.triangles
            );
        }
        _ if tiles_written.is_some() => {}
        _ => eprintln!(
            "derived {} lot{}: {} shapes, {} leaf shapes; no model written (write one with -o OUT.glb, .gltf or .obj)",
            summary.lots,
            if summary.lots == 1 { "" } else { "s" },
            summary.shapes,
            summary.leaves
        ),
    }
    if args.stats {
        let secs = started.elapsed().as_secs_f64().max(1e-9);
        eprintln!(
            "stats: {} lots, {} shapes, {} triangles written in {:.3} s (all lots derived after {:.3} s): {:.1} lots/s, {:.0} shapes/s, {:.0} triangles/s, peak memory {}",
            summary.lots,
            summary.shapes,
            triangles,
            secs,
            summary.derived_after,
            summary.lots as f64 / secs,
            summary.shapes as f64 / secs,
            triangles as f64 / secs,
            peak_memory().map_or("unknown".to_string(), |kb| format!("{:.1} MiB", kb as f64 / 1024.0))
        );
    }
    if let (Some(path), Some(reports)) = (&args.report, &reports) {
        std::fs::write(path, reports.to_json())
            .map_err(|e| Failure::Usage(format!("cannot write {}: {e}", path.display())))?;
    }
    if summary.failed > 0 {
        Err(Failure::Reported)
    } else {
        Ok(())
    }
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
