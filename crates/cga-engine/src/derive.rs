//! Derivation: applying rules to shapes, depth first, in the order the rule
//! text gives.
//!
//! A shape that invokes a rule, a leaf (`X.`), a push block or an operation
//! that creates shapes (split, comp, ...) gets *successors*; a shape that ends
//! its rule without successors and without `NIL` is a *leaf* of the shape tree
//! and its geometry is part of the model. A rule call in the middle of an
//! operation sequence gives the successor a copy of the current shape and the
//! sequence goes on with the current shape (`extrude(15) r(..) X. r(..) X.`).

use std::collections::HashSet;
use std::sync::Arc;

use cga_geometry::mesh::SharedVec;
use cga_geometry::{DAffine3, DVec2, DVec3, Material, Mesh};
use cga_syntax::{Diagnostic, Span};
use cga_value::Value;

use crate::assets::Assets;
use crate::expr::{RBody, RExpr, RExprKind, RStmt};
use crate::material_attr::MaterialOverrides;
use crate::ops;
use crate::program::{Program, RuleId};
use crate::shape::Shape;

/// Limits that stop runaway grammars with a clear message.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// Maximum nesting of rule and function invocations.
    pub max_depth: usize,
    /// Maximum number of shapes created for one initial shape.
    pub max_shapes: usize,
    /// Maximum time for one initial shape, in seconds (checked as shapes
    /// are created and rules applied).
    pub max_seconds: f64,
    /// Maximum number of faces of one shape's geometry: a grammar that
    /// multiplies geometry (`Lot --> extrude(5) Lot` extrudes every face of
    /// the last extrusion again) stops here instead of exhausting memory.
    pub max_faces: usize,
}

/// Shapes waiting in a derivation's queue above which it goes depth first
/// (see `derive_all_now`): a shape is about 600 bytes, so 65,536 of them
/// are some 40 MB.
const DEPTH_FIRST_ABOVE: usize = 1 << 16;

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_depth: 1000,
            max_shapes: 5_000_000,
            max_seconds: 300.0,
            max_faces: 5_000_000,
        }
    }
}

/// An error that stops the derivation of one initial shape.
#[derive(Clone, Debug, PartialEq)]
pub struct RtError {
    pub message: String,
    pub span: Option<Span>,
    pub kind: RtErrorKind,
}

/// Why a derivation stopped.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum RtErrorKind {
    /// Something in the rules (a wrong argument, a failed operation).
    #[default]
    Rules,
    /// A limit (depth, shapes, faces, time) was reached.
    Limit,
    /// The caller cancelled the generation.
    Cancelled,
    /// An operation got NaN or an infinity: the operation is skipped with
    /// a warning and the derivation goes on (CityEngine generates such
    /// models); it stops the lot only where no operation can skip it.
    NonFinite,
}

impl RtError {
    pub fn new(message: impl Into<String>, span: Span) -> RtError {
        RtError {
            message: message.into(),
            span: Some(span),
            kind: RtErrorKind::Rules,
        }
    }

    /// An error about a non-finite number (see [`RtErrorKind::NonFinite`]).
    pub fn non_finite(message: impl Into<String>, span: Span) -> RtError {
        RtError::new(message, span).of_kind(RtErrorKind::NonFinite)
    }

    /// The same error, of kind `kind`.
    pub fn of_kind(mut self, kind: RtErrorKind) -> RtError {
        self.kind = kind;
        self
    }

    pub fn to_diagnostic(&self) -> Diagnostic {
        match self.span {
            Some(span) => Diagnostic::error(self.message.clone(), span),
            None => Diagnostic {
                severity: cga_syntax::Severity::Error,
                message: self.message.clone(),
                span: None,
                label: None,
                notes: Vec::new(),
            },
        }
    }
}

/// The first argument of an operation that is NaN or infinite, for the
/// operations that cannot use one (`print`, `report` and `set` take any
/// value).
fn non_finite_arg(op: ops::Op, args: &[Arg]) -> Option<usize> {
    use ops::{AttrOp, Op};
    if matches!(
        op,
        Op::Attr(AttrOp::Print | AttrOp::Report | AttrOp::Set(_))
    ) {
        return None;
    }
    args.iter()
        .position(|a| matches!(a.value, Value::Float(x) if !x.is_finite()))
}

/// Why the operation `name` of the table is not run (the warning's words).
fn not_run_reason(name: &str) -> &'static str {
    match ops::table::find(name).map(|d| d.run) {
        Some(ops::table::Run::Deprecated(why)) => why,
        _ => "is not supported yet",
    }
}

/// How an operation argument was written: `3`, `'0.5` or `~1`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SizeKind {
    Absolute,
    Relative,
    Floating,
}

/// An evaluated operation argument.
#[derive(Clone, Debug)]
pub struct Arg {
    pub value: Value,
    pub kind: SizeKind,
    pub span: Span,
}

impl Arg {
    /// A finite float: no operation can use NaN or infinity (a division by
    /// zero in the rules, say), so they stop the derivation with a message.
    pub fn num(&self) -> Result<f64, RtError> {
        match &self.value {
            Value::Float(x) if x.is_finite() => Ok(*x),
            Value::Float(x) => Err(RtError::non_finite(
                format!(
                    "expected a finite number, found {}",
                    crate::values::to_text(&Value::Float(*x))
                ),
                self.span,
            )),
            Value::Bool(b) => Ok(if *b { 1.0 } else { 0.0 }),
            other => Err(RtError::new(
                format!(
                    "expected a float, found {}",
                    crate::values::type_name(other)
                ),
                self.span,
            )),
        }
    }

    /// A float that may be relative to `base` (`'0.5` = half of `base`).
    pub fn size(&self, base: f64) -> Result<f64, RtError> {
        let x = self.num()?;
        Ok(match self.kind {
            SizeKind::Relative => x * base,
            _ => x,
        })
    }

    pub fn text(&self) -> Result<&str, RtError> {
        match &self.value {
            Value::Str(s) => Ok(s),
            other => Err(RtError::new(
                format!(
                    "expected a string, found {}",
                    crate::values::type_name(other)
                ),
                self.span,
            )),
        }
    }

    pub fn boolean(&self) -> Result<bool, RtError> {
        match &self.value {
            Value::Bool(b) => Ok(*b),
            other => Err(RtError::new(
                format!("expected a bool, found {}", crate::values::type_name(other)),
                self.span,
            )),
        }
    }
}

/// The shape an operation sequence works on, and what became of it.
pub struct ShapeState {
    /// Boxed: a shape is some 500 bytes, and it travels from its parent's
    /// operation through the rule queue into the state of its rule; a box
    /// moves as a pointer.
    pub shape: Box<Shape>,
    pub has_successor: bool,
    pub deleted: bool,
    /// `shape` is a husk from `Interp::husks`: the shape itself went to its
    /// successor (see `Interp::last_child`).
    husked: bool,
    /// The operation running is the last statement of the shape's
    /// operations: it may hand the shape itself on to its last successor.
    pub(crate) at_last: bool,
}

impl ShapeState {
    pub fn new(shape: Box<Shape>) -> ShapeState {
        ShapeState {
            shape,
            has_successor: false,
            deleted: false,
            husked: false,
            at_last: false,
        }
    }
}

/// A leaf shape's geometry as the derivation left it: the shape's mesh
/// (shared with the shape, never copied), the map that places it in
/// object coordinates, and the final materials of its slots. Baking it
/// ([`Leaf::to_mesh`]) gives the mesh [`LotOutput::meshes`] would hold;
/// exporters can place it while writing instead
/// (`cga_export::ModelWriter::add_placed`).
#[derive(Clone, Debug)]
pub struct Leaf {
    pub mesh: Arc<Mesh>,
    /// From the mesh's coordinates to object coordinates. A map that
    /// mirrors (negative determinant) also reverses the faces.
    pub transform: DAffine3,
    /// The materials of the mesh's slots: its own with the shape's material
    /// attributes applied and texture paths resolved to files.
    pub materials: SharedVec<Material>,
    /// The mesh is an inserted asset as loaded (`i()` and nothing that
    /// changed its geometry since), shared with every other insert of it:
    /// a writer may write it once and place it as instances.
    pub asset: bool,
    /// The rule whose application made this leaf (`None`: the initial
    /// shape itself, when no rule ran).
    pub rule: Option<RuleId>,
    /// The shape's name: its rule's, or the leaf's (`Window.`), as an index
    /// into `Program::symbols`.
    pub name: u32,
}

impl Leaf {
    /// The geometry in object coordinates with its final materials.
    pub fn to_mesh(&self) -> Mesh {
        let mut m = crate::shape::transformed(&self.mesh, &self.transform);
        m.materials = self.materials.clone();
        m
    }
}

/// What the derivation of one initial shape produced.
#[derive(Default)]
pub struct LotOutput {
    /// Leaf geometry in object coordinates, with final materials (empty when
    /// the leaves were asked for as [`LotOutput::leaves`]).
    pub meshes: Vec<Mesh>,
    /// Leaf geometry unbaked, when asked for (`GenerateOptions::leaves`),
    /// in derivation order.
    pub leaves: Vec<Leaf>,
    pub prints: Vec<String>,
    pub reports: Vec<(String, Value)>,
    pub warnings: Vec<Diagnostic>,
    /// Number of shapes created.
    pub shapes: usize,
    /// Number of leaves emitted (leaves without geometry are not).
    pub leaf_count: usize,
}

/// Facts about the initial shape that rules can read.
#[derive(Clone, Debug)]
pub struct InitialInfo {
    pub name: String,
    pub start_rule: String,
    /// The geographic origin of the lot's frame (`getGeoCoord(lon|lat)`).
    pub geo_origin: Option<crate::geo::GeoOrigin>,
}

pub(crate) enum AttrSlot {
    Unevaluated,
    InProgress,
    Done(Value),
}

/// A rule call waiting for its turn.
pub(crate) struct PendingRule {
    rule: RuleId,
    args: Vec<Value>,
    shape: Box<Shape>,
    span: Span,
    /// Rule invocations from the initial shape to this one.
    generation: usize,
    /// The shape's tree key (`getTreeKey`), when the program asks for it.
    key: Option<Arc<str>>,
}

thread_local! {
    /// The rule queue's room, kept per thread from one initial shape to the
    /// next: a building's queue holds thousands of pending rules, and
    /// growing it anew for every lot copied them over and over.
    static QUEUES: std::cell::RefCell<std::collections::VecDeque<PendingRule>> =
        const { std::cell::RefCell::new(std::collections::VecDeque::new()) };
}

/// A rule queue with room from the thread's pool.
fn pooled_queue() -> std::collections::VecDeque<PendingRule> {
    QUEUES
        .try_with(|q| {
            q.try_borrow_mut()
                .map(|mut q| std::mem::take(&mut *q))
                .unwrap_or_default()
        })
        .unwrap_or_default()
}

/// Rule calls' room kept per thread between initial shapes: a building
/// needs thousands; the room of an exceptional lot (a runaway grammar's
/// millions) is given back, so a long-running host does not keep it.
const KEPT_QUEUE: usize = 1 << 16;

/// Gives a queue's room back to the thread's pool (the larger room is kept,
/// up to [`KEPT_QUEUE`]).
fn return_queue(mut queue: std::collections::VecDeque<PendingRule>) {
    queue.clear();
    if queue.capacity() > KEPT_QUEUE {
        return;
    }
    // `try_with`: nothing to keep while the thread shuts down.
    let _ = QUEUES.try_with(|q| {
        if let Ok(mut q) = q.try_borrow_mut() {
            if q.capacity() < queue.capacity() {
                *q = queue;
            }
        }
    });
}

/// The interpreter for one initial shape.
pub struct Interp<'a> {
    pub program: &'a Program,
    pub assets: &'a Assets,
    pub limits: Limits,
    pub info: InitialInfo,
    pub initial: Shape,
    pub out: LotOutput,
    pub(crate) attr_values: Vec<AttrSlot>,
    pub(crate) const_values: Vec<Option<Value>>,
    /// Nesting of function calls (the evaluation depth limit).
    pub(crate) depth: usize,
    /// Rule calls waiting to be derived, oldest first.
    pub(crate) queue: std::collections::VecDeque<PendingRule>,
    /// Generation of the rule being applied (the derivation depth limit).
    pub(crate) generation: usize,
    warned: HashSet<(u32, u32, u32)>,
    /// Texture files found so far (see `ops::texturing`).
    pub(crate) textures: ops::texturing::TextureFiles,
    /// The rule file of the rule being applied: texture paths of the shapes
    /// it emits are resolved from there.
    pub(crate) current_file: cga_syntax::FileId,
    /// The rule being applied (the provenance of the leaves it emits).
    current_rule: Option<RuleId>,
    /// Set by another thread to stop the derivation (checked where the
    /// time limit is).
    pub cancel: Option<Arc<std::sync::atomic::AtomicBool>>,
    /// Emit leaves unbaked into `out.leaves` instead of `out.meshes`.
    pub keep_leaves: bool,
    /// Texture coordinate sets not computed: nobody keeps or reads them
    /// (see `crate::uv_use`; bit `k`: set `k`).
    pub uv_skip: crate::uv_use::UvSets,
    /// Leaves are only counted (`LotOutput::leaf_count`): nobody keeps
    /// their geometry.
    pub count_leaves_only: bool,
    /// With `keep_leaves`: hand each leaf to this as it is emitted instead
    /// of collecting them (an exporter on another thread writes the model
    /// while the derivation goes on).
    pub leaf_sink: Option<Box<dyn FnMut(Leaf) + 'a>>,
    /// Empty argument lists and rule frames to reuse: every operation and
    /// rule call needs one, and allocating each is a measurable part of a
    /// derivation.
    arg_pool: Vec<Vec<Arg>>,
    frame_pool: Vec<Vec<Value>>,
    /// The room of splits, one per level of splits in progress (see
    /// `ops::split::SplitScratch`).
    pub(crate) split_scratch: Vec<crate::ops::split::SplitScratch>,
    /// Boxes holding an empty shape, put in place of a shape whose box went
    /// to its successor (`last_child`), and taken back when its state ends.
    /// Boxed: the boxes themselves are what is reused.
    #[allow(clippy::vec_box)]
    husks: Vec<Box<Shape>>,
    pub(crate) memo: MeshMemo,
    pub(crate) material_memo: MaterialMemo,
    /// The final materials of recently emitted leaves (see `leaf_materials`).
    emitted: EmitCache,
    /// Context queries: the shape tree and the records of the first pass,
    /// or what the second pass answers from (`None` in programs without
    /// context queries).
    pub(crate) context: Option<Box<crate::context::ContextState>>,
    /// When the derivation of this initial shape started (time limit).
    started: std::time::Instant,
    /// While `inline` or `modify` derives: the leaf shapes (and the shapes
    /// ended by `NIL`), collected here instead of emitted (`ops::inline`).
    pub(crate) collected: Option<Vec<Collected>>,
    /// The tree key of the rule being applied (`getTreeKey`: "0;0;1;"),
    /// and how many shapes it has created so far (the next child's index).
    /// Kept only when the program calls `getTreeKey`.
    pub(crate) tree_key: Arc<str>,
    tree_children: u32,
    /// Rule applications so far (the time limit is checked every 64).
    rules_applied: u64,
    /// Subtrees remembered by key, in generations that only count leaves
    /// (see `crate::subtree_memo`; `None`: not remembering).
    pub(crate) subtrees: Option<Box<crate::subtree_memo::Remembered>>,
    /// Subtrees being derived to be remembered, outermost first.
    subtrees_open: u32,
    /// What the trims have met of the trim planes of the subtrees being
    /// remembered (see `trim::PlaneLog`).
    pub(crate) plane_logs: Vec<crate::trim::PlaneLog>,
    /// The deepest generation applied so far (how deep a remembered
    /// subtree goes: the depth limit).
    deepest: usize,
    /// The lot's own copies of the program's string and array literals, by
    /// the address of the program's (see `Interp::own_literal`).
    pub(crate) literals: cga_geometry::topology::FxHashMap<usize, Value>,
}

/// Subtrees being remembered inside one another at most (see
/// `Interp::remembered`).
const MAX_OPEN_SUBTREES: u32 = 8;

/// A shape that ended while leaves were being collected (`Interp::collected`).
pub(crate) struct Collected {
    pub shape: Shape,
    /// Ended by `NIL`: its geometry is not part of the result, but shape
    /// recomposition still follows how it moved its vertices.
    pub deleted: bool,
}

/// The last few (material attributes, geometry materials, rule file) →
/// final materials of emitted leaves. Sibling leaves (the walls of a
/// facade) set equal attributes on pieces of one mesh, so most leaves reuse
/// a result: no materials are built, and the shared list lets the exporter
/// recognise it by address.
#[derive(Default)]
struct EmitCache {
    entries: Vec<EmitEntry>,
    next: usize,
}

struct EmitEntry {
    overrides: Arc<crate::material_attr::MaterialOverrides>,
    base: SharedVec<Material>,
    file: cga_syntax::FileId,
    result: SharedVec<Material>,
}

const EMIT_CACHE_SIZE: usize = 8;

/// Facts about shared meshes (inserted assets), computed once per lot
/// instead of once per insertion: the asset a path names, the asset's
/// bounding box, and the texture measures `tileUV` needs of it placed by a
/// given map. Entries hold their mesh, so an address names the same mesh
/// as long as it is here.
#[derive(Default)]
pub(crate) struct MeshMemo {
    /// Assets found by rule file and path as written: the lot's inserts
    /// ask the shared [`Assets`] (two locks each, whose cache lines the
    /// deriving threads pass between them) once per asset.
    assets: Vec<(cga_syntax::FileId, Arc<str>, Arc<Mesh>)>,
    bounds: Vec<(Arc<Mesh>, Bounds)>,
    uv: Vec<UvMemo>,
    next_asset: usize,
    next_bounds: usize,
    next_uv: usize,
}

/// A bounding box (`None`: nothing to bound).
type Bounds = Option<(DVec3, DVec3)>;

/// `uv_bounds` and `uv_unit_scale` of UV set `set` of `mesh` placed by `to_scope`.
pub(crate) type UvMeasures = (Option<(DVec2, DVec2)>, Option<DVec2>);

struct UvMemo {
    mesh: Arc<Mesh>,
    to_scope: Option<DAffine3>,
    set: usize,
    measures: UvMeasures,
}

const MEMO_SIZE: usize = 16;

impl MeshMemo {
    /// [`Assets::mesh`] of `path` written in rule file `from`, asked once
    /// per lot for each asset found (a missing asset is asked every time:
    /// it warns once per place anyway).
    pub(crate) fn asset(
        &mut self,
        assets: &Assets,
        from: cga_syntax::FileId,
        path: &str,
    ) -> Result<Arc<Mesh>, String> {
        if let Some((_, _, m)) = self
            .assets
            .iter()
            .find(|(f, p, _)| *f == from && **p == *path)
        {
            return Ok(m.clone());
        }
        let mesh = assets.mesh(from, path)?;
        let entry = (from, Arc::from(path), mesh.clone());
        remember(&mut self.assets, &mut self.next_asset, entry);
        Ok(mesh)
    }

    /// Whether `mesh` is an asset this lot found (see [`Assets::is_asset`],
    /// which the others ask): told without its lock.
    pub(crate) fn is_asset(&self, mesh: &Arc<Mesh>) -> bool {
        self.assets.iter().any(|(_, _, m)| Arc::ptr_eq(m, mesh))
    }

    /// The bounding box of the positions `mesh`'s faces use.
    pub(crate) fn bounds(&mut self, mesh: &Arc<Mesh>) -> Bounds {
        if Arc::strong_count(mesh) == 1 {
            // Nobody else has it: it will not come again.
            return crate::shape::local_bounds(mesh);
        }
        if let Some((_, b)) = self.bounds.iter().find(|(m, _)| Arc::ptr_eq(m, mesh)) {
            return *b;
        }
        let b = crate::shape::local_bounds(mesh);
        remember(&mut self.bounds, &mut self.next_bounds, (mesh.clone(), b));
        b
    }

    /// The UV measures of a shared `mesh` placed by `to_scope`, if known.
    pub(crate) fn uv(
        &self,
        mesh: &Arc<Mesh>,
        to_scope: Option<&DAffine3>,
        set: usize,
    ) -> Option<UvMeasures> {
        self.uv
            .iter()
            .find(|e| Arc::ptr_eq(&e.mesh, mesh) && e.to_scope.as_ref() == to_scope && e.set == set)
            .map(|e| e.measures)
    }

    pub(crate) fn remember_uv(
        &mut self,
        mesh: Arc<Mesh>,
        to_scope: Option<DAffine3>,
        set: usize,
        measures: UvMeasures,
    ) {
        let entry = UvMemo {
            mesh,
            to_scope,
            set,
            measures,
        };
        remember(&mut self.uv, &mut self.next_uv, entry);
    }
}

/// What an operation does to a shape's material attributes, as far as it
/// decides the result: `color("#fcefe2")`, `set(material.shininess, 20)`,
/// `texture("bricks.jpg")` (read from a rule file).
#[derive(Clone, Debug)]
pub(crate) enum MaterialEdit {
    ColorHex(Arc<str>),
    Color([u64; 4], usize),
    Field(crate::material_attr::MatField, Value),
    Texture(Arc<str>, cga_syntax::FileId),
}

impl MaterialEdit {
    fn same(&self, other: &MaterialEdit) -> bool {
        use MaterialEdit::*;
        let same_str = |a: &Arc<str>, b: &Arc<str>| Arc::ptr_eq(a, b) || a == b;
        match (self, other) {
            (ColorHex(a), ColorHex(b)) => same_str(a, b),
            (Color(a, n), Color(b, m)) => a == b && n == m,
            (Field(f, a), Field(g, b)) => {
                f == g
                    && match (a, b) {
                        (Value::Float(x), Value::Float(y)) => x.to_bits() == y.to_bits(),
                        (Value::Bool(x), Value::Bool(y)) => x == y,
                        (Value::Str(x), Value::Str(y)) => same_str(x, y),
                        _ => false,
                    }
            }
            (Texture(a, f), Texture(b, g)) => f == g && same_str(a, b),
            _ => false,
        }
    }
}

/// Recent material edits: (attributes before, edit) → attributes after.
/// Sibling shapes make the same edits on the attributes they inherited
/// (every wall of a facade sets the wall colour and texture), so most
/// edits reuse a result: no copy of the attributes, and the siblings share
/// one `Arc`, which `leaf_materials` then recognises by address. Entries
/// hold both `Arc`s, so neither changes while it is here.
#[derive(Default)]
pub(crate) struct MaterialMemo {
    entries: Vec<(Arc<MaterialOverrides>, MaterialEdit, Arc<MaterialOverrides>)>,
    next: usize,
}

impl Interp<'_> {
    /// Applies `edit` to the shape's material attributes with `apply`, or
    /// reuses the result of the same edit on the same attributes.
    pub(crate) fn edit_material(
        &mut self,
        shape: &mut Shape,
        edit: MaterialEdit,
        apply: impl FnOnce(&mut Interp, &mut MaterialOverrides) -> Result<(), RtError>,
    ) -> Result<(), RtError> {
        let memo = &self.material_memo.entries;
        if let Some((_, _, after)) = memo
            .iter()
            .find(|(before, e, _)| Arc::ptr_eq(before, &shape.material) && e.same(&edit))
        {
            shape.material = after.clone();
            return Ok(());
        }
        let before = shape.material.clone();
        apply(self, Arc::make_mut(&mut shape.material))?;
        let entry = (before, edit, shape.material.clone());
        let memo = &mut self.material_memo;
        remember(&mut memo.entries, &mut memo.next, entry);
        Ok(())
    }
}

/// Adds `entry` to a memo of at most `MEMO_SIZE` entries, replacing the
/// oldest when full.
fn remember<T>(list: &mut Vec<T>, next: &mut usize, entry: T) {
    if list.len() < MEMO_SIZE {
        list.push(entry);
    } else {
        list[*next] = entry;
        *next = (*next + 1) % MEMO_SIZE;
    }
}

impl<'a> Interp<'a> {
    pub fn new(
        program: &'a Program,
        assets: &'a Assets,
        limits: Limits,
        info: InitialInfo,
        initial: Shape,
        attr_values: &[(u32, Value)],
    ) -> Interp<'a> {
        let mut slots: Vec<AttrSlot> = (0..program.attrs.len())
            .map(|_| AttrSlot::Unevaluated)
            .collect();
        for (id, v) in attr_values {
            slots[*id as usize] = AttrSlot::Done(v.own_copy());
        }
        Interp {
            program,
            assets,
            limits,
            info,
            initial,
            out: LotOutput::default(),
            attr_values: slots,
            const_values: vec![None; program.functions.len()],
            depth: 0,
            queue: std::collections::VecDeque::new(),
            generation: 0,
            warned: HashSet::new(),
            textures: Default::default(),
            current_file: cga_syntax::FileId(0),
            current_rule: None,
            cancel: None,
            keep_leaves: false,
            uv_skip: 0,
            count_leaves_only: false,
            leaf_sink: None,
            emitted: EmitCache::default(),
            arg_pool: Vec::new(),
            frame_pool: Vec::new(),
            split_scratch: Vec::new(),
            husks: Vec::new(),
            memo: MeshMemo::default(),
            material_memo: MaterialMemo::default(),
            context: None,
            started: std::time::Instant::now(),
            collected: None,
            tree_key: Arc::from(""),
            tree_children: 0,
            rules_applied: 0,
            subtrees: None,
            subtrees_open: 0,
            plane_logs: Vec::new(),
            deepest: 0,
            literals: Default::default(),
        }
    }

    /// Replaces an attribute's value for this initial shape (outside values).
    pub fn set_attr_default(&mut self, id: crate::program::AttrId, v: Value) {
        self.attr_values[id as usize] = AttrSlot::Done(v.own_copy());
    }

    /// Derives the initial shape with `rule`. Whatever was generated before
    /// an error is kept in `self.out`.
    pub fn run(&mut self, rule: RuleId) -> Result<(), RtError> {
        let shape = self.initial.clone();
        self.out.shapes += 1;
        let span = self.program.rules[rule as usize].span;
        self.derive_now(rule, Vec::new(), shape, span)
    }

    /// Derives `shape` with `rule` and everything that follows from it,
    /// before returning. Rule calls met on the way wait in a queue of their
    /// own, so this also serves a derivation nested in another (`inline`).
    pub fn derive_now(
        &mut self,
        rule: RuleId,
        args: Vec<Value>,
        shape: Shape,
        span: Span,
    ) -> Result<(), RtError> {
        let generation = self.generation + 1;
        let key = self.next_tree_key();
        self.derive_all_now(|cx| {
            cx.queue.push_back(PendingRule {
                rule,
                args,
                shape: Box::new(shape),
                span,
                generation,
                key,
            });
            Ok(())
        })
    }

    /// The tree key of the next shape the current rule creates (its
    /// children are numbered from 0 in the order they are created).
    fn next_tree_key(&mut self) -> Option<Arc<str>> {
        if !self.program.uses_tree_key {
            return None;
        }
        let key = format!("{}{};", self.tree_key, self.tree_children);
        self.tree_children += 1;
        Some(Arc::from(key))
    }

    /// Runs `start` (which may queue rule calls) and derives everything it
    /// queued to completion before returning, with a queue of its own
    /// (`inline { operations }`, `modify`).
    pub(crate) fn derive_all_now(
        &mut self,
        start: impl FnOnce(&mut Self) -> Result<(), RtError>,
    ) -> Result<(), RtError> {
        let outer = std::mem::replace(&mut self.queue, pooled_queue());
        let mut result = start(self);
        if result.is_ok() {
            // Breadth first (the order of leaves, prints and reports), until
            // the queue holds more shapes than any building needs: then
            // depth first, so that rules that multiply shapes without end
            // (`A --> A A`) meet the depth limit within milliseconds instead
            // of filling gigabytes on the way to the shape limit, and a huge
            // lot's tiles are finished one by one.
            while let Some(p) = if self.queue.len() > DEPTH_FIRST_ABOVE {
                self.queue.pop_back()
            } else {
                self.queue.pop_front()
            } {
                if let Err(e) = self.run_rule(p) {
                    result = Err(e);
                    break;
                }
            }
        }
        return_queue(std::mem::replace(&mut self.queue, outer));
        result
    }

    pub fn warn_once(&mut self, span: Span, message: impl FnOnce() -> String) {
        if self.warned.insert((span.file.0, span.start, span.end)) {
            self.out.warnings.push(Diagnostic::warning(message(), span));
        }
    }

    /// Applies a rule to its shape: the rule's operations run now, the rule
    /// calls among them are queued behind everything already waiting.
    fn run_rule(&mut self, p: PendingRule) -> Result<(), RtError> {
        match self.remembered(p)? {
            Some(p) => self.apply_rule(p),
            None => Ok(()),
        }
    }

    /// Adds the counts of `p`'s subtree when one was derived before for a
    /// shape with the same key (`crate::subtree_memo`) and returns `None`.
    /// Else, if its rule may be remembered, derives a copy of it to its end
    /// at once, and if that gave no warning, takes and remembers its counts
    /// (`None` again). `Some(p)`: `p` is to be applied as usual.
    fn remembered(&mut self, p: PendingRule) -> Result<Option<PendingRule>, RtError> {
        let Some(table) = self.subtrees.as_deref_mut() else {
            return Ok(Some(p));
        };
        let Some(needs) = self.program.subtree_memo().rule(p.rule) else {
            return Ok(Some(p));
        };
        // Each subtree being remembered nests a derivation (and a stack
        // frame or two): a handful is plenty.
        if self.subtrees_open >= MAX_OPEN_SUBTREES
            || self.collected.is_some()
            || !table.worth_trying(p.rule, self.program.rules.len())
        {
            return Ok(Some(p));
        }
        let Some(key) = crate::subtree_memo::key(p.rule, needs, &p.args, &p.shape) else {
            return Ok(Some(p));
        };
        if let Some(e) = table.find(&key) {
            // To meet a limit where it is met: derived as usual.
            if p.generation + e.depth > self.limits.max_depth
                || self.out.shapes.saturating_add(e.shapes) > self.limits.max_shapes
            {
                return Ok(Some(p));
            }
            let (shapes, leaves, depth) = (e.shapes, e.leaves, e.depth);
            if let Some(planes) = &p.shape.trim.planes {
                for (i, slack) in e.slack_at(key.offsets()).enumerate() {
                    for log in self.plane_logs.iter_mut() {
                        log.met(planes, i, slack);
                    }
                }
            }
            self.out.shapes += shapes;
            self.out.leaf_count += leaves;
            self.deepest = self.deepest.max(p.generation + depth);
            self.pool_frame(p.args);
            return Ok(None);
        }
        // Derived to its end now, on a copy, into outputs of its own. If
        // that gave a warning (or failed), the shape is derived as usual
        // instead, in its turn, so that warnings come in the order they
        // always do (and the next shape with its key tries again).
        let copy = PendingRule {
            rule: p.rule,
            args: p.args.clone(),
            shape: p.shape.clone(),
            span: p.span,
            generation: p.generation,
            key: None,
        };
        let counts = LotOutput {
            shapes: self.out.shapes,
            leaf_count: self.out.leaf_count,
            ..LotOutput::default()
        };
        let outer = std::mem::replace(&mut self.out, counts);
        let warned = self.warned.clone();
        let mark = self.subtrees.as_deref().map_or(0, |t| t.mark());
        let generation = p.generation;
        let outer_deepest = std::mem::replace(&mut self.deepest, generation);
        self.plane_logs
            .push(crate::trim::PlaneLog::new(p.shape.trim.planes.clone()));
        self.subtrees_open += 1;
        let r = self.derive_all_now(|cx| cx.apply_rule(copy));
        self.subtrees_open -= 1;
        let log = self.plane_logs.pop().map(|l| l.slack).unwrap_or_default();
        let depth = self.deepest - generation;
        let copied = std::mem::replace(&mut self.out, outer);
        let quiet =
            copied.warnings.is_empty() && copied.prints.is_empty() && copied.reports.is_empty();
        if r.is_err() || !quiet {
            // Dropped, with what it remembered of its parts.
            self.deepest = outer_deepest;
            self.warned = warned;
            if let Some(table) = self.subtrees.as_deref_mut() {
                table.forget_since(mark);
            }
            // Cancelled, or out of time: so is the shape's own derivation.
            if let Err(e) = &r {
                if e.kind == RtErrorKind::Cancelled || self.out_of_time() {
                    return Err(self.time_limit_error(p.span));
                }
            }
            return Ok(Some(p));
        }
        self.deepest = self.deepest.max(outer_deepest);
        let shapes = copied.shapes - self.out.shapes;
        let leaves = copied.leaf_count - self.out.leaf_count;
        self.out.shapes = copied.shapes;
        self.out.leaf_count = copied.leaf_count;
        if let Some(table) = self.subtrees.as_deref_mut() {
            table.store(key, log, shapes, leaves, depth);
        }
        self.pool_frame(p.args);
        Ok(None)
    }

    /// Keeps a rule's argument frame for the next rule call.
    fn pool_frame(&mut self, mut frame: Vec<Value>) {
        frame.clear();
        self.frame_pool.push(frame);
    }

    /// Applies a rule to its shape (see `run_rule`).
    fn apply_rule(&mut self, p: PendingRule) -> Result<(), RtError> {
        let PendingRule {
            rule,
            args: mut frame,
            mut shape,
            span: call_span,
            generation,
            key,
        } = p;
        if self.context.is_some() && self.context_skips(rule) {
            self.pool_frame(frame);
            return Ok(());
        }
        let program = self.program;
        let def = &program.rules[rule as usize];
        if generation > self.limits.max_depth {
            return Err(RtError::new(
                format!(
                    "derivation depth limit ({}) reached in rule `{}`: the rules recurse without end (raise the limit with --max-depth)",
                    self.limits.max_depth, def.name
                ),
                call_span,
            ).of_kind(crate::derive::RtErrorKind::Limit));
        }
        // Few shapes can still take long (each rule multiplying the
        // geometry): the clock is also read every 64 rule applications.
        self.rules_applied += 1;
        if self.rules_applied.is_multiple_of(64) {
            self.check_time(call_span)?;
        }
        self.deepest = self.deepest.max(generation);
        let outer_generation = std::mem::replace(&mut self.generation, generation);
        let outer_key = key.map(|k| {
            (
                std::mem::replace(&mut self.tree_key, k),
                std::mem::replace(&mut self.tree_children, 0),
            )
        });
        shape.name = program.rule_symbol(rule);
        let mut r = Ok(());
        for local in &def.locals {
            match self.eval(local, &frame, &shape) {
                Ok(v) => frame.push(v),
                Err(e) => {
                    r = Err(e);
                    break;
                }
            }
        }
        if r.is_ok() {
            let mut st = ShapeState::new(shape);
            let caller_file = std::mem::replace(&mut self.current_file, def.span.file);
            let caller_rule = self.current_rule.replace(rule);
            r = self.exec_body(&def.body, &frame, &mut st);
            if r.is_ok() {
                self.finish(st);
            }
            self.current_file = caller_file;
            self.current_rule = caller_rule;
        }
        self.generation = outer_generation;
        if let Some((k, n)) = outer_key {
            self.tree_key = k;
            self.tree_children = n;
        }
        self.pool_frame(frame);
        r
    }

    /// A shape ends its operations: a leaf if it created nothing.
    pub fn finish(&mut self, st: ShapeState) {
        if st.husked {
            // A husk never holds a leaf: its shape went on as a successor.
            self.husks.push(st.shape);
            return;
        }
        if !st.deleted && !st.has_successor {
            self.emit(&st.shape);
        } else if st.deleted && !st.has_successor {
            if let Some(list) = &mut self.collected {
                list.push(Collected {
                    shape: *st.shape,
                    deleted: true,
                });
            }
        }
    }

    /// A successor of `parent`: a copy with its own random stream and the
    /// parent's scope remembered for `center`.
    pub fn child(&mut self, parent: &Shape, span: Span) -> Result<Box<Shape>, RtError> {
        self.count_shape(span)?;
        Ok(self.successor(parent))
    }

    /// [`child`](Interp::child) with `geometry` in place of the parent's
    /// (a split part's piece).
    pub(crate) fn child_with(
        &mut self,
        parent: &Shape,
        geometry: crate::shape::Geometry,
        span: Span,
    ) -> Result<Box<Shape>, RtError> {
        self.count_shape(span)?;
        Ok(self.successor_with(parent, geometry))
    }

    /// [`child`](Interp::child) of a shape used no more after it (its last
    /// statement; see `exec_stmt`): the shape becomes its own successor, in
    /// its own box, and the state keeps a husk (an empty shape from
    /// `husks`) until it ends. What the shape shares by reference count
    /// (its geometry, material, attributes, component and projection info)
    /// moves with it: the geometry can then be edited without a copy and is
    /// not mistaken for an inserted asset. Cloning the shape into a new box
    /// and dropping the old one cost an allocation, a free, a copy of its
    /// 480 bytes and two atomic operations per shared part.
    pub(crate) fn last_child(
        &mut self,
        st: &mut ShapeState,
        span: Span,
    ) -> Result<Box<Shape>, RtError> {
        self.count_shape(span)?;
        let husk = match self.husks.pop() {
            Some(h) => h,
            None => Box::new(Shape::blank()),
        };
        let mut c = std::mem::replace(&mut st.shape, husk);
        st.husked = true;
        // Messages about the statement name the shape's rule.
        st.shape.name = c.name;
        // What `successor` does to its copy of the parent, in the same order
        // (the parent's stream moves on before the child's is derived).
        let rng = c.child_rng(c.next_random().to_bits());
        c.parent_center = c.scope.center();
        c.rng.set(rng);
        if self.context.is_some() {
            c.ctx = self.context_child(c.ctx);
        }
        Ok(c)
    }

    /// [`child`](Interp::child) without counting it.
    fn successor(&mut self, parent: &Shape) -> Box<Shape> {
        self.successor_with(parent, parent.geometry.clone())
    }

    /// [`successor`](Interp::successor) with `geometry` in place of the
    /// parent's.
    fn successor_with(&mut self, parent: &Shape, geometry: crate::shape::Geometry) -> Box<Shape> {
        let rng = parent.child_rng(parent.next_random().to_bits());
        // Written straight into its box: `Box::new(parent.clone())` made
        // the clone on the stack and copied its 480 bytes into the box.
        let mut c = Box::write(Box::new_uninit(), parent.clone_with_geometry(geometry));
        c.parent_center = parent.scope.center();
        c.rng.set(rng);
        if self.context.is_some() {
            c.ctx = self.context_child(parent.ctx);
        }
        c
    }

    /// What the trim of the geometry `call` leaves (`i()`, a primitive,
    /// `trim()`) has to give: without a model, and with nothing reading
    /// that geometry afterwards (`crate::geometry_use`), only whether it is
    /// empty. Leaves collected by `inline`, `modify` and the booleans, and
    /// shapes of programs with context queries, are read.
    pub(crate) fn trim_need(&self, call: &crate::expr::OpCall) -> crate::trim::Need {
        if self.count_leaves_only
            && self.collected.is_none()
            && self.context.is_none()
            && !self.program.geometry_use().read_after(call)
        {
            crate::trim::Need::Emptiness
        } else {
            crate::trim::Need::Geometry
        }
    }

    /// Whether the parts of a split entry running `body` need their
    /// geometry and scope: not without a model when nothing in `body` and
    /// the rules it calls reads anything of them (`crate::geometry_use`);
    /// then only their count, their split or component information and
    /// whether they are empty shows.
    pub(crate) fn builds_parts(&self, body: &crate::expr::RBody) -> bool {
        !(self.count_leaves_only
            && self.collected.is_none()
            && self.context.is_none()
            && !self.program.geometry_use().body_reads_shape(body))
    }

    /// Fails with the shape limit's error if `n` more shapes would exceed
    /// it: an operation about to create that many parts (a split into
    /// hundreds of thousands of slabs) stops before doing the work.
    pub fn check_shape_budget(&self, n: usize, span: Span) -> Result<(), RtError> {
        if self.out.shapes.saturating_add(n) > self.limits.max_shapes {
            return Err(RtError::new(
                format!(
                    "shape limit ({}) reached for one initial shape: the rules create shapes without end (raise the limit with --max-shapes)",
                    self.limits.max_shapes
                ),
                span,
            ).of_kind(crate::derive::RtErrorKind::Limit));
        }
        Ok(())
    }

    /// Fails with the time limit's error once the initial shape has taken
    /// longer than allowed, and with the cancellation error once the
    /// generation was cancelled.
    fn check_time(&self, span: Span) -> Result<(), RtError> {
        if self.started.elapsed().as_secs_f64() > self.limits.max_seconds || self.is_cancelled() {
            return Err(self.time_limit_error(span));
        }
        Ok(())
    }

    /// Whether the initial shape has taken longer than its time limit.
    pub(crate) fn out_of_time(&self) -> bool {
        self.started.elapsed().as_secs_f64() > self.limits.max_seconds
    }

    fn is_cancelled(&self) -> bool {
        self.cancel
            .as_ref()
            .is_some_and(|c| c.load(std::sync::atomic::Ordering::Relaxed))
    }

    /// When operations long enough to look at the clock themselves should
    /// give up: the time limit of the initial shape, or cancellation.
    pub fn stop(&self) -> cga_geometry::boolean::Stop<'_> {
        cga_geometry::boolean::Stop {
            deadline: std::time::Duration::try_from_secs_f64(self.limits.max_seconds)
                .ok()
                .and_then(|d| self.started.checked_add(d)),
            cancel: self.cancel.as_deref(),
        }
    }

    /// The error of a derivation stopped by the time limit (or, if that is
    /// why it stopped, by cancellation).
    pub fn time_limit_error(&self, span: Span) -> RtError {
        if self.is_cancelled() {
            return RtError::new("the generation was cancelled", span)
                .of_kind(RtErrorKind::Cancelled);
        }
        RtError::new(
            format!(
                "time limit ({} s) reached for one initial shape (raise the limit with --max-seconds)",
                self.limits.max_seconds
            ),
            span,
        )
        .of_kind(RtErrorKind::Limit)
    }

    pub fn count_shape(&mut self, span: Span) -> Result<(), RtError> {
        self.out.shapes += 1;
        self.check_shape_budget(0, span)?;
        // The clock is read every 1024 shapes: cheap, and soon enough.
        if self.out.shapes.is_multiple_of(1024) {
            self.check_time(span)?;
        }
        Ok(())
    }

    /// Adds a leaf shape's geometry to the model.
    pub fn emit(&mut self, shape: &Shape) {
        if let Some(list) = &mut self.collected {
            list.push(Collected {
                shape: shape.clone(),
                deleted: false,
            });
            return;
        }
        if shape.geometry.is_empty() {
            return;
        }
        if self.context.is_some() {
            // Leaves are occluders; the first pass of a program with context
            // queries only records them (its model is not kept).
            self.context_occluder(shape);
            if self.context_collecting() {
                return;
            }
        }
        self.out.leaf_count += 1;
        if self.count_leaves_only {
            return;
        }
        let (mesh, _) = shape.geometry.raw();
        let materials = self.leaf_materials(shape, &mesh.materials);
        if self.keep_leaves {
            let leaf = Leaf {
                asset: self.memo.is_asset(mesh) || self.assets.is_asset(mesh),
                mesh: mesh.clone(),
                transform: shape.object_transform(),
                materials,
                rule: self.current_rule,
                name: shape.name,
            };
            match &mut self.leaf_sink {
                Some(sink) => sink(leaf),
                None => self.out.leaves.push(leaf),
            }
        } else {
            let mut mesh = shape.object_mesh();
            mesh.materials = materials;
            self.out.meshes.push(mesh);
        }
    }

    /// The final materials of a leaf whose geometry has the slots `base`:
    /// the shape's material attributes applied, texture paths as written
    /// replaced by the files they name.
    fn leaf_materials(&mut self, shape: &Shape, base: &SharedVec<Material>) -> SharedVec<Material> {
        let file = self.current_file;
        let overrides = &shape.material;
        let hit = self.emitted.entries.iter().find(|e| {
            e.file == file
                && SharedVec::ptr_eq(&e.base, base)
                && (Arc::ptr_eq(&e.overrides, overrides) || *e.overrides == **overrides)
        });
        if let Some(e) = hit {
            return e.result.clone();
        }
        let mut result = base.clone();
        if !overrides.is_empty() {
            for m in &mut result {
                *m = overrides.apply(m);
            }
        }
        self.textures
            .resolve_materials(self.assets, file, &mut result);
        let entry = EmitEntry {
            overrides: overrides.clone(),
            base: base.clone(),
            file,
            result: result.clone(),
        };
        let cache = &mut self.emitted;
        if cache.entries.len() < EMIT_CACHE_SIZE {
            cache.entries.push(entry);
        } else {
            cache.entries[cache.next] = entry;
            cache.next = (cache.next + 1) % EMIT_CACHE_SIZE;
        }
        result
    }

    /// Runs `body` on the shape of `st`. Callers finish the state right
    /// after (`finish`) and use nothing else of its shape: a rule called as
    /// the body's last statement takes the shape's geometry (see
    /// `exec_stmt`), leaving it empty.
    pub fn exec_body(
        &mut self,
        body: &RBody,
        frame: &[Value],
        st: &mut ShapeState,
    ) -> Result<(), RtError> {
        match body {
            RBody::Ops(stmts) => {
                // `NIL` in the middle of a sequence does not end it: as in
                // CityEngine, the operations after it still run on the
                // shape (`comp(f){ top : report(..) NIL report(..) NIL }`
                // reports twice), which is then not part of the model.
                for (i, s) in stmts.iter().enumerate() {
                    self.exec_stmt(s, frame, st, i + 1 == stmts.len())?;
                }
                Ok(())
            }
            RBody::Case {
                branches,
                otherwise,
            } => {
                for (cond, b) in branches {
                    if self.eval_condition(cond, frame, &st.shape)? {
                        return self.exec_body(b, frame, st);
                    }
                }
                match otherwise {
                    Some(b) => self.exec_body(b, frame, st),
                    None => Ok(()),
                }
            }
            RBody::Stochastic {
                branches,
                otherwise,
            } => {
                let pick =
                    self.stochastic_pick(branches.iter().map(|(p, _)| p), frame, &st.shape)?;
                match pick {
                    Some(i) => self.exec_body(&branches[i].1, frame, st),
                    None => match otherwise {
                        Some(b) => self.exec_body(b, frame, st),
                        None => Ok(()),
                    },
                }
            }
        }
    }

    /// Chooses a stochastic branch: the index whose cumulative percentage
    /// covers a random draw, or `None` for `else`.
    pub fn stochastic_pick<'e>(
        &mut self,
        percents: impl Iterator<Item = &'e RExpr>,
        frame: &[Value],
        shape: &Shape,
    ) -> Result<Option<usize>, RtError> {
        let r = shape.next_random() * 100.0;
        let mut acc = 0.0;
        for (i, p) in percents.enumerate() {
            acc += self.eval_num(p, frame, shape)?;
            if r < acc {
                return Ok(Some(i));
            }
        }
        Ok(None)
    }

    /// Runs one statement. `last`: nothing runs on `st` after it but
    /// `finish` (every caller of `exec_body` finishes the state right
    /// after), so a rule called last takes the shape's geometry instead of
    /// sharing it, and can edit it without a copy.
    fn exec_stmt(
        &mut self,
        s: &RStmt,
        frame: &[Value],
        st: &mut ShapeState,
        last: bool,
    ) -> Result<(), RtError> {
        match s {
            RStmt::Op(call) => {
                // Argument lists come from a pool (operations nest: a split
                // runs its parts' operations while its own arguments live).
                let mut args = self.arg_pool.pop().unwrap_or_default();
                for a in &call.args {
                    match self.eval_arg(a, frame, &st.shape) {
                        Ok(v) => args.push(v),
                        Err(e) => {
                            args.clear();
                            self.arg_pool.push(args);
                            return Err(e);
                        }
                    }
                }
                st.at_last = last;
                let skip = non_finite_arg(call.op, &args);
                let r = match skip {
                    Some(k) => Err(RtError::non_finite(
                        format!(
                            "argument {} is {}",
                            k + 1,
                            crate::values::to_text(&args[k].value)
                        ),
                        args[k].span,
                    )),
                    None => ops::exec(self, st, call, &args, frame),
                };
                args.clear();
                self.arg_pool.push(args);
                if let Err(e) = r {
                    if e.kind != RtErrorKind::NonFinite {
                        return Err(e);
                    }
                    // CityEngine generates the model: the operation is
                    // skipped, the shape goes on as it was.
                    let rule = self.program.symbol(st.shape.name).to_string();
                    let op = ops::table::name_of(call.op);
                    let at = e.span.unwrap_or(call.span);
                    self.warn_once(at, || {
                        format!(
                            "`{op}` in rule `{rule}` skipped: {} (a division by zero, or a missing asset's size?)",
                            e.message
                        )
                    });
                    return Ok(());
                }
                let faces = st.shape.geometry.raw().0.faces.len();
                if faces > self.limits.max_faces {
                    return Err(RtError::new(
                        format!(
                            "geometry limit ({} faces) reached: this operation made {faces} faces (raise the limit with --max-faces)",
                            self.limits.max_faces
                        ),
                        call.span,
                    ).of_kind(crate::derive::RtErrorKind::Limit));
                }
                Ok(())
            }
            RStmt::Rule(rc) => {
                let mut args = self.frame_pool.pop().unwrap_or_default();
                for a in &rc.args {
                    args.push(self.eval(a, frame, &st.shape)?);
                }
                let mut child = if last && !rc.dynamic {
                    // The successor is the shape's last use (a dynamic
                    // import still evaluates its overrides on the shape).
                    self.last_child(st, rc.span)?
                } else {
                    self.child(&st.shape, rc.span)?
                };
                if rc.dynamic {
                    self.reinitialize_import(rc, frame, &st.shape, &mut child)?;
                }
                st.has_successor = true;
                let key = self.next_tree_key();
                // As in CityEngine, the successor's rule runs after every
                // rule already waiting: shapes are derived generation by
                // generation, in the order they were created.
                self.queue.push_back(PendingRule {
                    rule: rc.rule,
                    args,
                    shape: child,
                    span: rc.span,
                    generation: self.generation + 1,
                    key,
                });
                Ok(())
            }
            RStmt::Leaf(sym) => {
                // A leaf is a shape of the tree too: it takes a child index.
                self.next_tree_key();
                let mut child = match last {
                    true => self.last_child(st, Span::default())?,
                    false => self.child(&st.shape, Span::default())?,
                };
                child.name = *sym;
                st.has_successor = true;
                self.emit(&child);
                Ok(())
            }
            RStmt::Nil => {
                st.deleted = true;
                Ok(())
            }
            RStmt::Push(body) => {
                let child = self.child(&st.shape, Span::default())?;
                let mut cst = ShapeState::new(child);
                self.exec_body(body, frame, &mut cst)?;
                self.finish(cst);
                st.has_successor = true;
                Ok(())
            }
            RStmt::Unsupported { name, span } => {
                let name = name.clone();
                self.warn_once(*span, || {
                    format!(
                        "operation `{name}` {}; the shape is left unchanged",
                        not_run_reason(&name)
                    )
                });
                Ok(())
            }
        }
    }

    /// A dynamic import `imp(height = 20).Lot`: the overrides are evaluated
    /// in the caller, then every other attribute of the imported rule set is
    /// re-initialized, as at the start of the generation but seeing the new
    /// values (`attr angle = case height > 10 : 0 else : 30` follows the
    /// call's height), and values set on the shape before (`set(imp.x, ..)`)
    /// are dropped. Attributes are re-evaluated in declaration order, so a
    /// default that reads an attribute declared after it sees that one's
    /// start value. Attributes propagated from the importer are the
    /// importer's and keep their values.
    fn reinitialize_import(
        &mut self,
        rc: &crate::expr::RuleCall,
        frame: &[Value],
        caller: &Shape,
        child: &mut Shape,
    ) -> Result<(), RtError> {
        let program = self.program;
        let ruleset = program.rules[rc.rule as usize].ruleset;
        let mut values = Vec::with_capacity(rc.attr_overrides.len());
        for (id, e) in &rc.attr_overrides {
            values.push((*id, self.eval(e, frame, caller)?));
        }
        if let Some(list) = child.attrs.as_mut() {
            let list = std::sync::Arc::make_mut(list);
            list.retain(|(id, _)| program.attrs[*id as usize].ruleset != ruleset);
        }
        for (id, v) in values {
            child.set_attr(id, v);
        }
        // The initial shape, carrying the values so far, is the context of
        // the defaults (they are evaluated on the initial shape at start).
        let mut context = self.initial.clone();
        context.attrs = child.attrs.clone();
        for (i, def) in program.attrs.iter().enumerate() {
            let id = i as crate::program::AttrId;
            if def.ruleset != ruleset || rc.attr_overrides.iter().any(|(o, _)| *o == id) {
                continue;
            }
            let v = self.eval(&def.default, &[], &context)?;
            context.set_attr(id, v.clone());
            child.set_attr(id, v);
        }
        Ok(())
    }

    /// Evaluates an operation argument, noting a `'` or `~` prefix.
    pub fn eval_arg(&mut self, e: &RExpr, frame: &[Value], shape: &Shape) -> Result<Arg, RtError> {
        let (inner, kind) = match &e.kind {
            RExprKind::Relative(inner) => (&**inner, SizeKind::Relative),
            RExprKind::Floating(inner) => (&**inner, SizeKind::Floating),
            _ => (e, SizeKind::Absolute),
        };
        Ok(Arg {
            value: self.eval(inner, frame, shape)?,
            kind,
            span: e.span,
        })
    }
}
