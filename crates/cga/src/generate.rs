//! Generating lots: one on the calling thread's behalf, or many in
//! parallel and in order, into plain meshes or a model file.

use std::sync::Arc;

use cga_engine::context::{LotContext, SceneContext};
use cga_engine::derive::{Leaf, RtErrorKind};
use cga_engine::generate::{collect_lot, generate_lot_streaming};
use cga_engine::{GenerateOptions, LotOutput, RtError};
use cga_export::{DrawCollector, DrawModel, Encoder, ModelWriter, PlainCollector, PlainModel};
use cga_geometry::{DAffine3, DVec3};

use crate::diagnostics::Diagnostic;
use crate::help::{Handoff, Help, Helping};
use crate::lots::Lot;
use crate::model::{LeafOrigin, LotResult, Summary};
use crate::options::Options;
use crate::pipeline::{run_pipeline, Taken};
use crate::rules::{RuleRef, Rules};
use crate::stack::on_big_stack;
use crate::Error;

/// Where the geometry of generated lots goes.
pub enum Target<'w> {
    /// Nowhere: only prints, reports and diagnostics are wanted.
    Nothing,
    /// Into each lot's [`LotResult::model`], as plain arrays.
    Meshes,
    /// Into each lot's [`LotResult::model`], as positions and triangles
    /// alone: the triangles of [`Target::Meshes`], but the faces of a leaf
    /// that meet at a position of its mesh share one vertex there (per
    /// material), and normals and texture coordinates are left empty (the
    /// rules' texture projections are then skipped, unless they read
    /// texture coordinates).
    Positions,
    /// Into each lot's [`LotResult::drawing`], as a viewer draws them
    /// (see [`DrawModel`]): positions relative to this origin.
    Drawing([f64; 3]),
    /// Into a model file (streamed: memory does not grow with the lots).
    Writer(&'w mut ModelWriter),
    /// Into models that follow one another, each lot wholly into one (the
    /// tiles of a tileset), streamed like [`Target::Writer`]: one run of
    /// the workers over all of them.
    PerLot(&'w mut (dyn LotWriters + Send)),
}

/// The models of [`Target::PerLot`]: which lot goes where, and from which
/// origin its positions are written.
pub trait LotWriters {
    /// An encoder of the writers' format for the deriving threads (for
    /// glTF and GLB, [`Encoder::for_export`] with the writers' options);
    /// `None` has meshes added on the calling thread.
    fn encoder(&self) -> Option<Encoder>;
    /// What lot `i`'s positions are written relative to: the origin of its
    /// writer. Asked for every lot before generating.
    fn origin(&self, i: usize) -> Option<DVec3>;
    /// The writer of lot `i`, asked before each piece of its output, lot
    /// after lot in order (a writer can be closed and the next opened when
    /// `i` moves on).
    fn writer(&mut self, i: usize) -> Result<&mut ModelWriter, Error>;
}

/// Where a call's geometry is written, if anywhere.
enum Out<'w> {
    None,
    One(&'w mut ModelWriter),
    PerLot(&'w mut (dyn LotWriters + Send)),
}

impl Out<'_> {
    /// The writer of lot `i`.
    fn writer(&mut self, i: usize) -> Result<Option<&mut ModelWriter>, Error> {
        match self {
            Out::None => Ok(None),
            Out::One(w) => Ok(Some(&mut **w)),
            Out::PerLot(w) => w.writer(i).map(Some),
        }
    }
}

impl Rules {
    /// Generates one lot, with its geometry as plain meshes. A lot stopped
    /// by an error (in the rules, or a limit) is still a result, with the
    /// error in [`LotResult::error`].
    pub fn generate(&self, lot: &Lot, options: &Options) -> Result<LotResult, Error> {
        let mut out = None;
        self.generate_lots(std::slice::from_ref(lot), options, Target::Meshes, |r| {
            out = Some(r)
        })?;
        Ok(out.unwrap_or_default())
    }

    /// Generates `lots` in parallel, their geometry as plain meshes, and
    /// gives the results in lot order.
    pub fn generate_all(&self, lots: &[Lot], options: &Options) -> Result<Vec<LotResult>, Error> {
        let mut out = Vec::with_capacity(lots.len());
        self.generate_lots(lots, options, Target::Meshes, |r| out.push(r))?;
        Ok(out)
    }

    /// Generates `lots` on [`Options::jobs`] threads, the geometry into
    /// `target`, and hands each lot's result to `each` on the calling
    /// thread in lot order, as lots finish: the output does not depend on
    /// the number of threads, and memory holds only a few lots per thread
    /// at a time. Programs with context queries between lots derive every
    /// lot twice (the first pass records what the queries look at).
    pub fn generate_lots(
        &self,
        lots: &[Lot],
        options: &Options,
        target: Target<'_>,
        each: impl FnMut(LotResult),
    ) -> Result<Summary, Error> {
        self.generate_list(lots, None, options, target, each)
    }

    /// [`generate_lots`](Rules::generate_lots) of the lots `order` names
    /// (each at most once), in that order: `lots[order[0]]` first. Results
    /// carry the lots' indices in `lots` (or what [`Options::lot_indices`]
    /// says of them), and context queries between lots see all of `lots`.
    pub fn generate_lots_in_order(
        &self,
        lots: &[Lot],
        order: &[usize],
        options: &Options,
        target: Target<'_>,
        each: impl FnMut(LotResult),
    ) -> Result<Summary, Error> {
        let mut seen = vec![false; lots.len()];
        for &i in order {
            if i >= lots.len() || std::mem::replace(&mut seen[i], true) {
                return Err(Error::Value(format!(
                    "lot {i} named twice or out of range in the order of {} lots",
                    lots.len()
                )));
            }
        }
        self.generate_list(lots, Some(order), options, target, each)
    }

    fn generate_list(
        &self,
        lots: &[Lot],
        order: Option<&[usize]>,
        options: &Options,
        target: Target<'_>,
        mut each: impl FnMut(LotResult),
    ) -> Result<Summary, Error> {
        self.check_usable()?;
        if let Some(v) = options
            .lot_indices
            .as_ref()
            .filter(|v| v.len() != lots.len())
        {
            return Err(Error::Value(format!(
                "{} lot indices for {} lots",
                v.len(),
                lots.len()
            )));
        }
        // The call's lot `i`, and its index in the run.
        let position = |i: usize| order.map_or(i, |o| o[i]);
        let lot = |i: usize| &lots[position(i)];
        let lot_index = |i: usize| options.lot_index(position(i));
        let count = order.map_or(lots.len(), <[usize]>::len);
        let started = std::time::Instant::now();
        let rule = self.start_rule(options.start_rule.as_deref())?;
        let mut engine_options = self.engine_options(options)?;
        let jobs = options.threads().min(count.max(1));
        let program = &self.inner.program;
        let assets = &self.inner.assets;
        let usage = self.inner.context_use;
        engine_options.context_use = Some(usage);
        if let (true, Some(scene)) = (usage.inter, &options.scene) {
            engine_options.scene = Some(scene.0.clone());
        } else if usage.inter && lots.len() > 1 {
            // The first pass goes over all of `lots`, also those the order
            // leaves out.
            engine_options.scene = Some(Arc::new(self.collect_scene(
                rule,
                lots,
                options,
                &engine_options,
                options.threads().min(lots.len()),
            )?));
        }
        let cancelled = || options.cancel.as_ref().is_some_and(|c| c.is_cancelled());
        if cancelled() {
            return Err(Error::Cancelled);
        }

        let (mut out, keep) = match target {
            Target::Nothing => (Out::None, None),
            Target::Meshes => (Out::None, Some(Keep::Plain)),
            Target::Positions => (Out::None, Some(Keep::Positions)),
            Target::Drawing(origin) => (Out::None, Some(Keep::Drawing(DVec3::from(origin)))),
            Target::Writer(w) => (Out::One(w), None),
            Target::PerLot(w) => (Out::PerLot(w), None),
        };
        // Texture coordinates of sets nobody keeps are not computed (see
        // `cga_engine::uv_use`): reports alone and positions keep none,
        // plain meshes and meshes to draw set 0, model files all.
        engine_options.uv_sets_unused = match (&out, &keep) {
            (Out::None, None | Some(Keep::Positions)) => cga_engine::uv_use::ALL_UV_SETS,
            (Out::None, Some(_)) => cga_engine::uv_use::ALL_UV_SETS & !1,
            _ => 0,
        };
        // Reports alone: the leaves are counted, not made.
        engine_options.count_leaves_only = matches!((&out, &keep), (Out::None, None));
        // Leaves go to the calling thread in batches as they are emitted,
        // so that writing the model overlaps deriving it, even for a single
        // lot. For glTF and GLB the workers encode them into vertex data
        // first, leaving the calling thread the writing alone, also with
        // one job: `--jobs 1` is one thread's work (a Dask task with one
        // thread is one core). Leaves encoded on the calling thread cost
        // more CPU on small leaves (1,250 lots of examples/building.cga,
        // one job: 2.15 s of user time against 1.37 s, and 1.60 s of wall
        // time against 1.40 s): memory freed on another thread than the one
        // that took it, meshes read from another core's cache. Only when
        // more threads are allowed than there are lots (one lot, which one
        // worker derives) does the calling thread encode what it is sent,
        // so that two threads share the lot (one Candler building: 30 ms
        // against 34 ms). Either way a lot's leaves are encoded in the
        // same batches (`Batcher`), so the model is written out at the same
        // points and the file is the same.
        // Plain meshes are made on the workers, per lot.
        let (encoder, origins) = match &out {
            Out::None => (None, Vec::new()),
            Out::One(w) => (w.encoder(), Vec::new()),
            Out::PerLot(w) => (w.encoder(), (0..count).map(|i| w.origin(i)).collect()),
        };
        // Each lot's origin, when lots have origins of their own.
        let origin = |i: usize| origins.get(i).copied();
        let workers_encode = jobs > 1 || options.threads() == 1;
        let has_writer = !matches!(out, Out::None);
        let new_batcher = || match &encoder {
            Some(e) if workers_encode => Batcher::Encode(Box::new(e.another()), 0),
            _ if has_writer => Batcher::Leaves(Vec::new()),
            _ => match keep {
                Some(Keep::Plain) => {
                    Batcher::Plain(Box::new(self.collector(PlainCollector::with_room)), 0)
                }
                Some(Keep::Positions) => {
                    Batcher::Plain(Box::new(self.collector(PlainCollector::positions_only)), 0)
                }
                Some(Keep::Drawing(origin)) => Batcher::Draw(
                    Box::new(self.collector(DrawCollector::with_room)),
                    0,
                    DAffine3::from_translation(-origin),
                ),
                None => Batcher::Drop,
            },
        };
        let mut own_batcher = match &encoder {
            Some(e) if !workers_encode => Some(Batcher::Encode(Box::new(e.another()), 0)),
            _ => None,
        };
        let mut summary = Summary {
            lots: count,
            ..Summary::default()
        };
        // The lot whose output was begun last (a node or group per lot),
        // and the triangles its writer held before it.
        let mut begun: Option<usize> = None;
        let mut triangles_before = 0u64;
        if let Out::One(w) = &mut out {
            w.expect_lots(count);
        }
        let mut take = |i: usize, taken: Taken<Piece, Done>| -> Result<(), Error> {
            let mut writer = out.writer(i)?;
            if begun != Some(i) {
                begun = Some(i);
                if let (Some(o), Some(own)) = (origin(i), &mut own_batcher) {
                    own.set_origin(o);
                }
                if let Some(w) = writer.as_deref_mut() {
                    triangles_before = w.triangles();
                    w.begin_lot(
                        &lot(i).name,
                        Some(crate::metadata::lot_metadata(lot_index(i), lot(i))),
                    )
                    .map_err(Error::Export)?;
                }
            }
            let mut result = Ok(());
            let mut write = |piece| {
                if let (Some(w), Ok(())) = (writer.as_deref_mut(), &result) {
                    result = write_piece(w, piece);
                }
            };
            let done = match (taken, &mut own_batcher) {
                (Taken::Piece(Piece::Leaves(batch)), Some(own)) => {
                    for leaf in batch {
                        own.add(leaf, &mut write);
                    }
                    return result.map_err(Error::Export);
                }
                (Taken::Piece(piece), _) => {
                    write(piece);
                    return result.map_err(Error::Export);
                }
                (Taken::Done(done), own) => {
                    if let Some(own) = own {
                        own.flush(&mut write);
                    }
                    result.map_err(Error::Export)?;
                    done
                }
            };
            if done
                .error
                .as_ref()
                .is_some_and(|e| e.kind == RtErrorKind::Cancelled)
            {
                return Err(Error::Cancelled);
            }
            let mut warnings = self.annotation_warnings(options, lot(i));
            let mut made = self.lot_result(lot_index(i), lot(i), done);
            if let Some(w) = writer {
                // The lot's pieces are all written by its `Done` (in lot
                // order), and no other lot's in between.
                made.triangles_written = Some(w.triangles() - triangles_before);
                if !made.reports.is_empty() {
                    w.annotate_lot("reports", crate::metadata::reports_metadata(&made.reports));
                }
            }
            warnings.append(&mut made.warnings);
            made.warnings = warnings;
            summary.failed += made.error.is_some() as usize;
            summary.shapes += made.shapes;
            summary.leaves += made.leaf_count;
            each(made);
            Ok(())
        };
        // Workers that encode and run out of lots take over the encoding of
        // those still deriving (see `help`).
        let helps_encode = workers_encode && encoder.is_some();
        let help = Help::new();
        let new_worker = || (new_batcher(), Helping::new(&help));
        let generate_one =
            |(batcher, helping): &mut (Batcher, Helping), i: usize, send: &mut dyn FnMut(Piece)| {
                if let Some(o) = origin(i) {
                    batcher.set_origin(o);
                }
                let mut origins = Vec::new();
                let mut handoff: Option<Handoff> = None;
                let (out, error) = generate_lot_streaming(
                    program,
                    assets,
                    rule.0,
                    lot(i),
                    lot_index(i),
                    &engine_options,
                    |leaf| match &mut handoff {
                        // Only encoding batchers are handed over: they
                        // record no leaf origins.
                        Some(h) => h.add(leaf, send),
                        None => {
                            batcher.add_origin(&leaf, program, &mut origins);
                            batcher.add(leaf, send);
                            if helps_encode {
                                handoff = helping.ask(batcher);
                            }
                        }
                    },
                );
                if let Some(h) = handoff {
                    // A helper that failed took the batch with it: the lot's
                    // output is incomplete, and the panic ends the run.
                    *batcher = h.finish(send).unwrap_or_else(new_batcher);
                }
                batcher.flush(send);
                let (model, drawing) = batcher.take_model();
                let kept = match batcher {
                    Batcher::Plain(collector, _) => Some(collector.room()),
                    Batcher::Draw(collector, ..) => Some(collector.room()),
                    _ => None,
                };
                if let Some(kept) = kept {
                    let mut room = self.mesh_room();
                    if room.as_slice() != kept {
                        room.clear();
                        room.extend_from_slice(kept);
                    }
                }
                Done {
                    out,
                    error,
                    model,
                    drawing,
                    origins,
                }
            };
        if count == 1 && !has_writer {
            // One lot and nothing to overlap with: derived here (on a stack
            // with room), without worker threads.
            let mut worker = new_worker();
            let done = on_big_stack(|| generate_one(&mut worker, 0, &mut |_| {}));
            take(0, Taken::Done(done))?;
        } else {
            let idle = |(_, helping): &mut (Batcher, Helping)| {
                if helps_encode {
                    helping.offer();
                }
            };
            run_pipeline(count, jobs, new_worker, generate_one, idle, &mut take)?;
        }
        summary.derived_after = started.elapsed().as_secs_f64();
        Ok(summary)
    }

    /// Whether `options` name only attributes the rules have, with values
    /// they can take (what [`Rules::generate_lots`] would refuse, found
    /// before generating).
    pub fn check_attributes(&self, options: &Options) -> Result<(), Error> {
        self.engine_options(options).map(|_| ())
    }

    /// The room plain meshes of the last lot took (see `Inner::mesh_room`).
    fn mesh_room(&self) -> std::sync::MutexGuard<'_, Vec<(usize, usize)>> {
        self.inner
            .mesh_room
            .lock()
            .unwrap_or_else(|e| e.into_inner())
    }

    /// A collector of meshes for a worker (`with_room` of
    /// [`PlainCollector`] or [`DrawCollector`]), starting with the room the
    /// rules' last lot took, at most [`KEPT_ROOM`] vertices and triangles a
    /// material (one huge lot does not make every later lot reserve its
    /// size).
    fn collector<C>(&self, with_room: impl FnOnce(Vec<(usize, usize)>) -> C) -> C {
        let room = self
            .mesh_room()
            .iter()
            .map(|&(v, t)| (v.min(KEPT_ROOM), t.min(KEPT_ROOM)))
            .collect();
        with_room(room)
    }

    /// The engine's options for `options`: attribute names resolved.
    fn engine_options(&self, options: &Options) -> Result<GenerateOptions, Error> {
        let program = &self.inner.program;
        let mut out = GenerateOptions {
            seed: options.seed,
            limits: options.limits,
            // Leaves are placed where they are written: none is copied into
            // object coordinates first.
            leaves: true,
            cancel: options.cancel.as_ref().map(|c| c.flag()),
            ..GenerateOptions::default()
        };
        for (name, value) in &options.attrs {
            match program.main_attr(name) {
                Some(id) => {
                    let value = match self.attribute(name).and_then(|a| a.ty) {
                        Some(ty) => crate::values::convert(value, ty).map_err(|why| {
                            Error::Value(format!("attribute `{name}` is a {}: {why}", ty.name()))
                        })?,
                        None => value.clone(),
                    };
                    out.attrs.push((id, value))
                }
                // As in CityEngine, `seed` is the initial shapes' own seed
                // unless the rules declare an attribute of that name.
                None if name == "seed" => {
                    out.lot_seed = match value {
                        cga_value::Value::Float(x) if *x >= 0.0 && x.fract() == 0.0 => {
                            Some(*x as u64)
                        }
                        other => {
                            return Err(Error::Value(format!(
                                "the seed must be a whole number, found `{}`",
                                cga_engine::values::to_text(other)
                            )))
                        }
                    }
                }
                None => {
                    return Err(Error::UnknownAttribute {
                        name: name.clone(),
                        known: program.main_attrs.iter().map(|(n, _)| n.clone()).collect(),
                    })
                }
            }
        }
        Ok(out)
    }

    /// The first pass of every lot (see `cga_engine::context`), for programs
    /// with `inter` context queries, on `jobs` threads. Each lot's records
    /// are put at its index, so the scene, and with it the output, does not
    /// depend on the number of threads.
    fn collect_scene(
        &self,
        rule: RuleRef,
        lots: &[Lot],
        indices: &Options,
        options: &GenerateOptions,
        jobs: usize,
    ) -> Result<SceneContext, Error> {
        use std::sync::atomic::{AtomicUsize, Ordering};
        let (program, assets) = (&self.inner.program, &self.inner.assets);
        let next = AtomicUsize::new(0);
        let work = || {
            let mut done = Vec::new();
            loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                if i >= lots.len() {
                    break;
                }
                done.push((
                    i,
                    collect_lot(
                        program,
                        assets,
                        rule.0,
                        &lots[i],
                        indices.lot_index(i),
                        options,
                    ),
                ));
            }
            done
        };
        let mut slots: Vec<Option<LotContext>> =
            std::iter::repeat_with(|| None).take(lots.len()).collect();
        crate::threads::scope(|scope| {
            let mut workers = Vec::new();
            for _ in 0..jobs.min(lots.len()) {
                let worker = scope.spawn(work).map_err(Error::Threads)?;
                workers.push(worker);
            }
            for w in workers {
                // A worker that panicked leaves its lots empty: their second
                // pass runs again and reports what went wrong there.
                for (i, records) in w.join().unwrap_or_default() {
                    slots[i] = Some(records);
                }
            }
            Ok::<(), Error>(())
        })?;
        let records = slots
            .into_iter()
            .map(|r| r.unwrap_or_else(|| LotContext::new(None)))
            .collect();
        let scene = SceneContext::new(records, options.context_use.unwrap_or_default());
        Ok(match &indices.lot_indices {
            Some(v) => scene.numbered(v.to_vec()),
            None => scene,
        })
    }

    /// Warnings for the values `options` and `lot` give attributes that
    /// their `@Range` or `@Enum` do not allow.
    fn annotation_warnings(&self, options: &Options, lot: &Lot) -> Vec<Diagnostic> {
        let given = lot
            .attrs
            .iter()
            .map(|(n, v)| (&**n, v))
            .filter(|(n, _)| !options.attrs.iter().any(|(o, _)| o.as_str() == *n))
            .chain(options.attrs.iter().map(|(n, v)| (n.as_str(), v)));
        let mut out = Vec::new();
        for (name, value) in given {
            let Some(attr) = self.attribute(name) else {
                continue;
            };
            let value = attr
                .ty
                .and_then(|ty| crate::values::convert(value, ty).ok())
                .unwrap_or_else(|| value.clone());
            if let Some(why) = crate::values::outside_annotations(attr, &value) {
                let Some(id) = self.inner.program.main_attr(name) else {
                    continue;
                };
                let span = self.inner.program.attrs[id as usize].span;
                let d =
                    cga_syntax::Diagnostic::warning(format!("{why}, in lot `{}`", lot.name), span);
                out.push(Diagnostic::new(&d, &self.inner.sources));
            }
        }
        out
    }

    fn lot_result(&self, index: usize, lot: &Lot, done: Done) -> LotResult {
        let sources = &self.inner.sources;
        let Done {
            out,
            error,
            model,
            drawing,
            origins,
        } = done;
        let LotOutput {
            prints,
            reports,
            warnings,
            shapes,
            leaf_count,
            ..
        } = out;
        LotResult {
            index,
            name: lot.name.clone(),
            model,
            drawing,
            leaves: origins,
            leaf_count,
            prints,
            reports,
            warnings: warnings
                .iter()
                .map(|w| Diagnostic::new(w, sources))
                .collect(),
            error: error.map(|e| Diagnostic::new(&e.to_diagnostic(), sources)),
            shapes,
            triangles_written: None,
        }
    }
}

/// The scene of a whole run for context queries between lots: what the
/// first pass recorded of every lot (see [`Options::scene`]).
#[derive(Clone)]
pub struct Scene(Arc<SceneContext>);

impl std::fmt::Debug for Scene {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Scene")
    }
}

impl Rules {
    /// The scene of `lots` (a whole run) for parts of it generated apart
    /// ([`Options::scene`]); `None` when the rules ask no `inter` context
    /// query, or for a single lot.
    pub fn scene(&self, lots: &[Lot], options: &Options) -> Result<Option<Scene>, Error> {
        self.check_usable()?;
        if !self.inner.context_use.inter || lots.len() < 2 {
            return Ok(None);
        }
        let rule = self.start_rule(options.start_rule.as_deref())?;
        let mut engine_options = self.engine_options(options)?;
        engine_options.context_use = Some(self.inner.context_use);
        let whole = Options {
            lot_indices: None,
            ..options.clone()
        };
        let jobs = options.threads().min(lots.len());
        let scene = self.collect_scene(rule, lots, &whole, &engine_options, jobs)?;
        Ok(Some(Scene(Arc::new(scene))))
    }
}

/// What a worker hands over at the end of a lot.
struct Done {
    out: LotOutput,
    error: Option<RtError>,
    model: PlainModel,
    drawing: DrawModel,
    origins: Vec<LeafOrigin>,
}

/// The meshes a generation keeps of each lot.
enum Keep {
    Plain,
    Positions,
    /// Positions relative to this origin.
    Drawing(DVec3),
}

/// Writes a piece of a lot's output.
fn write_piece(w: &mut ModelWriter, piece: Piece) -> Result<(), cga_export::ExportError> {
    match piece {
        Piece::Leaves(batch) => batch.iter().try_for_each(|leaf| match leaf.asset {
            true => w.add_asset(&leaf.mesh, &leaf.transform, &leaf.materials),
            false => w.add_placed(&leaf.mesh, Some(&leaf.transform), &leaf.materials),
        }),
        Piece::Encoded(batch) => w.append(batch),
    }
}

/// A piece of a lot's output on its way to the calling thread.
pub(crate) enum Piece {
    /// Leaves, for writers that take meshes (OBJ).
    Leaves(Vec<Leaf>),
    /// Leaves encoded into vertex data (glTF, GLB).
    Encoded(cga_export::Encoded),
}

/// Vertices or triangles of a material's plain mesh that a new collector
/// reserves at most from the rules' last lot (a quarter of a million
/// vertices are 16 MB of arrays; Candler's largest mesh has 116,000).
const KEPT_ROOM: usize = 1 << 18;

/// Leaves per piece at most: a message per leaf would wake the calling
/// thread for each (a system call apiece).
const LEAF_BATCH: usize = 512;

/// Encoded vertex data per piece at most, in bytes: large enough that the
/// calling thread is seldom woken, small enough to keep little in flight.
const ENCODED_BATCH_BYTES: usize = 1 << 20;

/// How a worker gathers its leaves.
pub(crate) enum Batcher {
    /// No geometry wanted: leaves are dropped where they are made.
    Drop,
    Leaves(Vec<Leaf>),
    /// The leaves encoded so far into the encoder's batch, and their count.
    Encode(Box<cga_export::Encoder>, usize),
    /// Plain meshes of the lot, and the number of leaves added so far.
    Plain(Box<PlainCollector>, u32),
    /// Meshes to draw, the number of leaves added so far, and the move
    /// from the frame to the origin the positions are relative to.
    Draw(Box<DrawCollector>, u32, DAffine3),
}

impl Batcher {
    /// Writes the positions of the leaves added from now on relative to
    /// `origin` (encoding only).
    fn set_origin(&mut self, origin: Option<DVec3>) {
        if let Batcher::Encode(encoder, _) = self {
            encoder.set_origin(origin);
        }
    }

    pub(crate) fn add(&mut self, leaf: Leaf, send: &mut dyn FnMut(Piece)) {
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
                match leaf.asset {
                    true => encoder.add_asset(&leaf.mesh, &leaf.transform, &leaf.materials),
                    false => encoder.add_placed(&leaf.mesh, Some(&leaf.transform), &leaf.materials),
                }
                *n += 1;
                if *n == LEAF_BATCH || encoder.bytes() >= ENCODED_BATCH_BYTES {
                    *n = 0;
                    send(Piece::Encoded(encoder.take()));
                }
            }
            Batcher::Plain(collector, added) => {
                // A leaf whose mesh cannot be placed (invalid indices) adds
                // nothing; the writers report such meshes.
                let _ = collector.add_placed(
                    &leaf.mesh,
                    Some(&leaf.transform),
                    &leaf.materials,
                    *added,
                );
                *added += 1;
            }
            Batcher::Draw(collector, added, shift) => {
                // Moved to the origin before rounding to `f32`.
                let placed = *shift * leaf.transform;
                let _ = collector.add_placed(&leaf.mesh, Some(&placed), &leaf.materials, *added);
                *added += 1;
            }
        }
    }

    /// Records where a leaf comes from, when plain meshes are kept (their
    /// triangles name the leaf by its number).
    fn add_origin(
        &self,
        leaf: &Leaf,
        program: &cga_engine::Program,
        origins: &mut Vec<LeafOrigin>,
    ) {
        if let Batcher::Plain(..) | Batcher::Draw(..) = self {
            origins.push(LeafOrigin {
                rule: leaf.rule.map(RuleRef),
                shape: program.symbols[leaf.name as usize].clone(),
            });
        }
    }

    /// Sends what was gathered (at the end of a lot).
    pub(crate) fn flush(&mut self, send: &mut dyn FnMut(Piece)) {
        match self {
            Batcher::Drop | Batcher::Plain(..) | Batcher::Draw(..) => {}
            Batcher::Leaves(batch) => {
                if !batch.is_empty() {
                    send(Piece::Leaves(std::mem::take(batch)));
                }
            }
            Batcher::Encode(encoder, n) => {
                if *n > 0 {
                    *n = 0;
                    send(Piece::Encoded(encoder.take()));
                }
            }
        }
    }

    /// The plain meshes and the meshes to draw of the lot that ended
    /// (empty unless kept).
    fn take_model(&mut self) -> (PlainModel, DrawModel) {
        match self {
            Batcher::Plain(collector, added) => {
                *added = 0;
                (collector.take(), DrawModel::default())
            }
            Batcher::Draw(collector, added, _) => {
                *added = 0;
                (PlainModel::default(), collector.take())
            }
            _ => Default::default(),
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::{lots, Engine, MemoryWorld, Options, Target};

    /// Positions alone are the plain meshes' triangles on the same places,
    /// with the vertices of a leaf's faces shared where they meet, without
    /// normals or texture coordinates (whose projections are skipped), and
    /// the same reports.
    #[test]
    fn positions_alone_are_the_plain_meshes_triangles() {
        let rules = Engine::new(MemoryWorld::new()).load_text(
            "/p/rules/r.cga",
            "Lot --> extrude(10) comp(f) { side : setupProjection(0, scope.xy, 2, 2) projectUV(0) \
             split(x) { ~2 : color(\"#a04020\") report(\"w\", scope.sx) W. }* | all : Top. }\n",
        );
        let lots = [lots::rect(30.0, 12.0), lots::rect(7.0, 5.0)];
        let run = |target: Target<'static>| {
            let mut out = Vec::new();
            rules
                .generate_lots(&lots, &Options::default(), target, |r| out.push(r))
                .unwrap();
            out.sort_by_key(|r| r.index);
            out
        };
        let (plain, alone) = (run(Target::Meshes), run(Target::Positions));
        let by_position = |m: &crate::PlainModel| -> Vec<[[f64; 3]; 3]> {
            m.meshes
                .iter()
                .flat_map(|k| k.indices.iter().map(|t| t.map(|i| k.positions[i as usize])))
                .collect()
        };
        for (p, a) in plain.iter().zip(&alone) {
            assert_eq!(by_position(&a.model), by_position(&p.model));
            assert_eq!(a.reports, p.reports);
            assert_eq!(a.leaves, p.leaves);
            assert!(p
                .model
                .meshes
                .iter()
                .all(|m| m.uvs.len() == m.positions.len()));
            assert!(a
                .model
                .meshes
                .iter()
                .all(|m| m.normals.is_empty() && m.uvs.is_empty()));
        }
        // 30 x 12 x 10: 15 + 6 wall pieces of 4 corners each side twice
        // (every piece its own leaf: no sharing between them), the top
        // and bottom 4 each.
        let vertices = |r: &crate::LotResult| {
            r.model
                .meshes
                .iter()
                .map(|m| m.positions.len())
                .sum::<usize>()
        };
        assert_eq!(vertices(&alone[0]), 2 * (15 + 6) * 4 + 4 + 4);
        assert_eq!(vertices(&alone[0]), vertices(&plain[0]));
        assert_eq!(alone[0].model.triangles(), 2 * (2 * (15 + 6) + 2));
        // A box is one leaf: its six faces share its eight corners.
        let mass = Engine::new(MemoryWorld::new())
            .load_text("/p/rules/m.cga", "Lot --> extrude(10) Mass.\n");
        let count = |target: Target<'static>| {
            let mut out = Vec::new();
            mass.generate_lots(&lots[..1], &Options::default(), target, |r| out.push(r))
                .unwrap();
            let m = &out[0].model;
            (
                m.meshes.iter().map(|m| m.positions.len()).sum::<usize>(),
                m.triangles(),
            )
        };
        assert_eq!(count(Target::Positions), (8, 12));
        assert_eq!(count(Target::Meshes), (24, 12));
    }

    /// Meshes to draw hold the plain meshes' vertices relative to the
    /// origin asked for, in `f32`, and name the same leaves.
    #[test]
    fn meshes_to_draw_are_the_plain_meshes_moved_and_rounded() {
        let rules = Engine::new(MemoryWorld::new()).load_text(
            "/p/rules/r.cga",
            "Lot --> extrude(10) comp(f) { side : split(x) { ~2 : color(\"#a04020\") W. }* | all : Top. }\n",
        );
        let lot = lots::rect(30.0, 12.0);
        let plain = rules.generate(&lot, &Options::default()).unwrap();
        let origin = [1000.0, 0.0, -500.0];
        let mut drawn = Vec::new();
        rules
            .generate_lots(
                std::slice::from_ref(&lot),
                &Options::default(),
                Target::Drawing(origin),
                |r| drawn.push(r),
            )
            .unwrap();
        let drawn = drawn.pop().unwrap();
        assert!(drawn.model.meshes.is_empty());
        assert_eq!(drawn.drawing.materials, plain.model.materials);
        assert_eq!(drawn.drawing.triangles(), plain.model.triangles());
        assert_eq!(drawn.leaves, plain.leaves);
        for (p, d) in plain.model.meshes.iter().zip(&drawn.drawing.meshes) {
            assert_eq!(p.indices, d.indices());
            for (p, d) in p.positions.iter().zip(&d.positions) {
                for a in 0..3 {
                    // Within a step of `f32` (the leaves' transforms are
                    // composed with the move before rounding).
                    let want = (p[a] - origin[a]) as f32;
                    assert!((want - d[a]).abs() <= f32::EPSILON * want.abs().max(1.0));
                }
            }
            for t in 0..p.indices.len() {
                let m = p.material;
                assert_eq!(
                    plain.provenance(&rules, m, t),
                    drawn.provenance(&rules, m, t)
                );
            }
        }
        assert_eq!(
            drawn.provenance(&rules, 0, 0).unwrap().rule.as_deref(),
            Some("Lot")
        );
    }

    /// The rules keep the room of the last lot collected as plain meshes,
    /// for the next call's collectors; generating without meshes keeps it.
    #[test]
    fn rules_keep_the_room_of_the_last_lot_collected() {
        let rules = Engine::new(MemoryWorld::new()).load_text(
            "/p/rules/r.cga",
            "Lot --> extrude(10) comp(f) { side : split(x) { ~2 : color(\"#a04020\") W. }* | all : X. }\n",
        );
        let room = || rules.mesh_room().clone();
        // Vertices and triangles of each mesh of the one lot generated.
        let sizes_of = |results: Vec<crate::LotResult>| -> Vec<(usize, usize)> {
            let meshes = &results[0].model.meshes;
            meshes
                .iter()
                .map(|m| (m.positions.len(), m.indices.len()))
                .collect()
        };
        assert!(room().is_empty());
        let big = rules.generate_all(&[lots::rect(40.0, 40.0)], &Options::default());
        let sizes = sizes_of(big.unwrap());
        assert_eq!(sizes.iter().map(|s| s.1).sum::<usize>(), 2 * (4 * 20 + 2));
        assert_eq!(room(), sizes);
        // The next call's collectors start with it.
        assert_eq!(
            rules
                .collector(cga_export::PlainCollector::with_room)
                .room(),
            sizes.as_slice()
        );
        let small = lots::rect(4.0, 4.0);
        rules
            .generate_lots(
                std::slice::from_ref(&small),
                &Options::default(),
                crate::Target::Nothing,
                |_| {},
            )
            .unwrap();
        assert_eq!(room(), sizes);
        let sizes = sizes_of(rules.generate_all(&[small], &Options::default()).unwrap());
        assert_eq!(sizes.iter().map(|s| s.1).sum::<usize>(), 2 * (4 * 2 + 2));
        assert_eq!(room(), sizes);
        // A huge lot's room is kept only up to a bound.
        *rules.mesh_room() = vec![(10, 20), (usize::MAX, 1 << 30)];
        let capped = [(10, 20), (super::KEPT_ROOM, super::KEPT_ROOM)];
        assert_eq!(
            rules
                .collector(cga_export::PlainCollector::with_room)
                .room(),
            capped.as_slice()
        );
    }
}
