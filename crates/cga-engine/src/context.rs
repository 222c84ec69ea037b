//! Context queries: `label`, the occlusion queries `inside`, `overlaps` and
//! `touches`, and `contextCount`, `contextCompare`, `minimumDistance`.
//!
//! # Two passes
//!
//! A query asks about geometry that may not be generated yet, and its
//! answer may change what is generated. As CityEngine does, an initial
//! shape whose rules use context queries is derived twice:
//!
//! 1. *Collecting* ([`collect_lot`](crate::generate::collect_lot)): every
//!    query gives its default (`false`, `0`, infinity) and nothing is
//!    emitted. The pass records the shapes later queries test against, in
//!    a [`LotContext`]: labeled shapes (`label`), and, when some occlusion
//!    query has no label, the *automatic occluders*: leaf shapes and shapes
//!    on which `comp` or `offset` runs. Only closed geometry occludes.
//! 2. *Answering*: the derivation starts over and queries are answered
//!    against the records of pass 1: `intra` ones against the lot's own,
//!    `inter` ones against the other lots' (a [`SceneContext`] holds every
//!    lot's records; the `cga` command collects them all before it derives
//!    any lot a second time). So shapes that only a non-default answer
//!    creates are never tested against, and the result does not depend on
//!    the order lots are derived in.
//!
//! Programs without context queries ([`ContextUse::of`]) are derived once,
//! with no bookkeeping at all.
//!
//! # Shape addresses
//!
//! Intra occlusion queries skip the query shape's ancestors and
//! descendants (a facade tile is always inside the mass it was split
//! from). Shapes are told apart across the two passes by their *address*:
//! the ordinals of the successors on the way from the initial shape (the
//! third part of a split of the second shape the initial shape made is
//! `[1, 2]`). A shape's ordinal counts only its parent's successors, so
//! its address does not depend on what the rest of the derivation made
//! before it: lots are derived generation by generation (breadth first),
//! and a query that answers differently in pass 2 changes how many shapes
//! are created before every later shape of the lot, but the address of a
//! shape outside the changed branch stays the one it had in pass 1. An
//! occluder is related to the query shape when one address is a prefix of
//! the other.
//!
//! # Neighbourhood
//!
//! Inter occlusion queries consider lots whose bounding box lies within
//! distance 1 of the query lot's ([`OCCLUSION_NEIGHBOURHOOD`]); the other
//! context queries consider every lot, as CityEngine's defaults do.

use std::collections::HashMap;
use std::sync::{Arc, OnceLock};

use cga_geometry::occlusion::TOLERANCE;
use cga_geometry::occlusion::{box_distance, occlusion, Occlusion, OcclusionMesh, OrientedBox};
use cga_geometry::{DVec3, Mesh};
use cga_value::Value;
use rstar::primitives::{GeomWithData, Rectangle};
use rstar::{Envelope, RTree, AABB};

use crate::derive::{Interp, RtError};
use crate::expr::{RBlock, RBody, RExpr, RExprKind, RPart, RStmt};
use crate::program::Program;
use crate::shape::Shape;
use crate::shape_fns::{ContextFn, ShapeFn};

/// How far (in scene units) from a lot's bounding box the lots that inter
/// occlusion queries test against may lie.
pub const OCCLUSION_NEIGHBOURHOOD: f64 = 1.0;

// ----- what a program asks -----

/// Which context queries a program makes: decides whether lots are derived
/// twice, and what the first pass records.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ContextUse {
    /// Some query looks at the lot's own shapes (`intra` or `all`).
    pub intra: bool,
    /// Some query looks at other lots' shapes (`inter` or `all`).
    pub inter: bool,
    /// Some occlusion query (`inside`, `overlaps`, `touches`).
    pub occlusion: bool,
    /// Some occlusion query without a label: leaves and the shapes `comp`
    /// and `offset` run on are occluders too.
    pub unlabeled: bool,
    /// Some intra occlusion query: shape addresses are kept.
    pub intra_occlusion: bool,
}

impl ContextUse {
    /// Whether the program makes context queries at all.
    pub fn any(&self) -> bool {
        self.intra || self.inter
    }

    /// The context queries of `program`, found in every rule, function and
    /// attribute. A target or label that is not a constant counts as every
    /// possibility.
    pub fn of(program: &Program) -> ContextUse {
        let mut u = ContextUse::default();
        Walker {
            shape_fn: &mut |f, args| {
                if let ShapeFn::Context(c) = f {
                    u.query(*c, args)
                }
            },
            op: &mut |_| {},
            rule: &mut |_| {},
        }
        .program(program);
        u
    }

    fn query(&mut self, f: ContextFn, args: &[RExpr]) {
        let occlusion = matches!(
            f,
            ContextFn::Inside | ContextFn::Overlaps | ContextFn::Touches
        );
        let target = constant(args.first()).and_then(|s| Target::parse(&s));
        let (intra, inter) = match target {
            Some(Target::Intra) => (true, false),
            Some(Target::Inter) => (false, true),
            _ => (true, true),
        };
        self.intra |= intra;
        self.inter |= inter;
        if occlusion {
            self.occlusion = true;
            self.intra_occlusion |= intra;
            let labeled = matches!(constant(args.get(1)), Some(l) if !l.is_empty());
            self.unlabeled |= !labeled;
        }
    }
}

/// The text of a constant string argument.
fn constant(e: Option<&RExpr>) -> Option<Arc<str>> {
    match e.map(|e| &e.kind) {
        Some(RExprKind::Const(Value::Str(s))) => Some(s.clone()),
        _ => None,
    }
}

/// Per rule of `program`, whether an operation for which `direct` holds
/// can be reached from it: in its own body, or in the body of a rule it
/// calls, at any depth.
pub(crate) fn rules_reaching(
    program: &Program,
    direct: &mut dyn FnMut(&crate::expr::OpCall) -> bool,
) -> Vec<bool> {
    let n = program.rules.len();
    let mut reaches = vec![false; n];
    let mut callers: Vec<Vec<u32>> = vec![Vec::new(); n];
    for (r, def) in program.rules.iter().enumerate() {
        let mut found = false;
        let mut calls = Vec::new();
        Walker {
            shape_fn: &mut |_, _| {},
            op: &mut |call| found |= direct(call),
            rule: &mut |callee| calls.push(callee),
        }
        .body(&def.body);
        reaches[r] = found;
        for c in calls {
            if let Some(list) = callers.get_mut(c as usize) {
                list.push(r as u32);
            }
        }
    }
    // Every caller of a rule that reaches one reaches it too.
    let mut todo: Vec<u32> = (0..n as u32).filter(|&r| reaches[r as usize]).collect();
    while let Some(r) = todo.pop() {
        for &c in &callers[r as usize] {
            if !reaches[c as usize] {
                reaches[c as usize] = true;
                todo.push(c);
            }
        }
    }
    reaches
}

/// Visits every shape function call (context queries among them),
/// operation and rule call of a program's rules, functions and attributes.
pub(crate) struct Walker<'f> {
    pub shape_fn: &'f mut dyn FnMut(&ShapeFn, &[RExpr]),
    pub op: &'f mut dyn FnMut(&crate::expr::OpCall),
    pub rule: &'f mut dyn FnMut(crate::program::RuleId),
}

impl Walker<'_> {
    pub(crate) fn program(&mut self, program: &Program) {
        for r in &program.rules {
            for l in &r.locals {
                self.expr(l);
            }
            self.body(&r.body);
        }
        for f in &program.functions {
            for l in &f.locals {
                self.expr(l);
            }
            self.expr(&f.body);
        }
        for a in &program.attrs {
            self.expr(&a.default);
        }
    }

    fn expr(&mut self, e: &RExpr) {
        if let RExprKind::Shape(f, args) = &e.kind {
            (self.shape_fn)(f, args);
        }
        e.for_each_child(&mut |c| self.expr(c));
    }

    fn block<T>(&mut self, b: &RBlock<T>, f: &mut dyn FnMut(&mut Self, &T)) {
        for p in &b.parts {
            match p {
                RPart::Entry {
                    head, depth, body, ..
                } => {
                    self.expr(head);
                    if let Some(d) = depth {
                        self.expr(d);
                    }
                    f(self, body);
                }
                RPart::Group(g) => self.block(g, f),
                RPart::Unlabeled { body, .. } => f(self, body),
            }
        }
    }

    pub fn body(&mut self, b: &RBody) {
        match b {
            RBody::Ops(stmts) => {
                for s in stmts {
                    match s {
                        RStmt::Op(call) => {
                            (self.op)(call);
                            call.args.iter().for_each(|a| self.expr(a));
                            for block in [&call.block, &call.remainder_block].into_iter().flatten()
                            {
                                self.block(block, &mut |w, b| w.body(b));
                            }
                        }
                        RStmt::Rule(rc) => {
                            (self.rule)(rc.rule);
                            rc.args.iter().for_each(|a| self.expr(a));
                            rc.attr_overrides.iter().for_each(|(_, e)| self.expr(e));
                        }
                        RStmt::Push(body) => self.body(body),
                        RStmt::Leaf(_) | RStmt::Nil | RStmt::Unsupported { .. } => {}
                    }
                }
            }
            RBody::Case {
                branches,
                otherwise,
            }
            | RBody::Stochastic {
                branches,
                otherwise,
            } => {
                for (c, b) in branches {
                    self.expr(c);
                    self.body(b);
                }
                if let Some(o) = otherwise {
                    self.body(o);
                }
            }
        }
    }
}

/// The rules the first, collecting pass has to apply.
///
/// When every occlusion query names a label (so there are no automatic
/// occluders), the first pass records nothing but shapes given a label
/// that some query asks about. A rule from which no such `label` can be
/// reached (through the rules it calls, at any depth) records nothing, nor
/// do the shapes it creates, so the first pass skips it: a building's
/// facade details are not derived just to be thrown away. The records stay
/// exactly the same: a shape's random stream and its address depend only on
/// its ancestors, and the rules that are applied keep their order.
///
/// Rules applied inside `inline` or `modify` are never skipped (their
/// leaves become the geometry of the shape that runs the operation). The
/// entries of a component split that the first pass skips still create
/// their shapes (which draws from the parent's random stream and numbers
/// the shape's address) but do not fill them with geometry.
#[derive(Debug, Default)]
pub struct FirstPass {
    /// Per rule, whether the first pass applies it; empty: every rule.
    applies: Vec<bool>,
    /// The labels queries ask about.
    asked: Vec<Arc<str>>,
}

/// Whether `call` is a `label` with a label in `asked` (or one not known
/// before the derivation).
fn labels_asked(call: &crate::expr::OpCall, asked: &[Arc<str>]) -> bool {
    call.op == crate::ops::Op::Label
        && match constant(call.args.first()) {
            Some(l) => asked.contains(&l),
            None => true,
        }
}

impl FirstPass {
    /// The rules of `program` that can reach a `label` some query asks
    /// about (every rule when a query's label is not a constant, when some
    /// occlusion query has no label, or when the program has no queries).
    pub fn of(program: &Program) -> FirstPass {
        let usage = ContextUse::of(program);
        if !usage.any() || usage.unlabeled {
            return FirstPass::default();
        }
        // The labels the queries ask about (`None`: not known).
        let mut asked: Option<Vec<Arc<str>>> = Some(Vec::new());
        Walker {
            shape_fn: &mut |f, args| {
                if !matches!(f, ShapeFn::Context(_)) {
                    return;
                }
                // An explicit target comes first (as `Interp::context_query`
                // reads the arguments); `contextCount("x")` has none.
                let first = args.first().map(|e| &e.kind);
                let label = match first {
                    Some(RExprKind::Const(Value::Str(s))) if Target::parse(s).is_some() => {
                        args.get(1)
                    }
                    Some(RExprKind::Const(Value::Str(_))) => args.first(),
                    _ => None,
                };
                match (label.is_some(), constant(label), &mut asked) {
                    (true, Some(l), Some(list)) => list.push(l),
                    // No label argument: such a query finds nothing.
                    (false, _, _) if matches!(first, Some(RExprKind::Const(_))) => {}
                    _ => asked = None,
                }
            },
            op: &mut |_| {},
            rule: &mut |_| {},
        }
        .program(program);
        let Some(asked) = asked else {
            return FirstPass::default();
        };
        let applies = rules_reaching(program, &mut |call| labels_asked(call, &asked));
        FirstPass { applies, asked }
    }

    /// Whether the first pass has to run `body` (the operations of a
    /// component split's entry): whether a label some query asks about can
    /// be reached from it.
    pub(crate) fn body_applies(&self, body: &RBody) -> bool {
        if self.applies.is_empty() {
            return true;
        }
        let (mut labels, mut calls) = (false, false);
        Walker {
            shape_fn: &mut |_, _| {},
            op: &mut |call| labels |= labels_asked(call, &self.asked),
            rule: &mut |r| calls |= self.applies(r),
        }
        .body(body);
        labels || calls
    }

    /// Whether the first pass applies `rule`.
    pub fn applies(&self, rule: crate::program::RuleId) -> bool {
        self.applies.get(rule as usize).copied().unwrap_or(true)
    }

    /// The first pass of `program` (worked out once per program).
    pub(crate) fn cached(program: &Program) -> &FirstPass {
        program.first_pass.get_or_init(|| FirstPass::of(program))
    }
}

/// The target selector of a query.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Target {
    Intra,
    Inter,
    All,
}

impl Target {
    fn parse(s: &str) -> Option<Target> {
        match s {
            "intra" => Some(Target::Intra),
            "inter" => Some(Target::Inter),
            "all" => Some(Target::All),
            _ => None,
        }
    }

    fn intra(self) -> bool {
        self != Target::Inter
    }

    fn inter(self) -> bool {
        self != Target::Intra
    }
}

/// `contextCompare`'s comparison: each gives a key where larger ranks first.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Compare {
    Northernmost,
    Southernmost,
    Easternmost,
    Westernmost,
    Highest,
    Lowest,
    Largest,
    Smallest,
}

impl Compare {
    const ALL: [Compare; 8] = [
        Compare::Northernmost,
        Compare::Southernmost,
        Compare::Easternmost,
        Compare::Westernmost,
        Compare::Highest,
        Compare::Lowest,
        Compare::Largest,
        Compare::Smallest,
    ];

    fn parse(s: &str) -> Option<Compare> {
        Some(match s {
            "world.northernmost" => Compare::Northernmost,
            "world.southernmost" => Compare::Southernmost,
            "world.easternmost" => Compare::Easternmost,
            "world.westernmost" => Compare::Westernmost,
            "world.highest" => Compare::Highest,
            "world.lowest" => Compare::Lowest,
            "area.largest" => Compare::Largest,
            "area.smallest" => Compare::Smallest,
            _ => return None,
        })
    }

    /// The key of geometry with `bounds` and `area`. The scene is y up,
    /// x east and -z north.
    fn key(self, (lo, hi): (DVec3, DVec3), area: f64) -> f64 {
        match self {
            Compare::Northernmost => -lo.z,
            Compare::Southernmost => hi.z,
            Compare::Easternmost => hi.x,
            Compare::Westernmost => -lo.x,
            Compare::Highest => hi.y,
            Compare::Lowest => -lo.y,
            Compare::Largest => area,
            Compare::Smallest => -area,
        }
    }
}

// ----- what the first pass records -----

/// A labeled shape or an automatic occluder, as pass 1 left it.
#[derive(Debug)]
struct Record {
    /// `None`: an automatic occluder (leaf, `comp` or `offset` shape).
    label: Option<Arc<str>>,
    /// The shape's address, a range of [`LotContext::paths`].
    path: std::ops::Range<u32>,
    /// The closed geometry, if closed and occlusion queries need it.
    solid: Option<OcclusionMesh>,
    /// Bounds of the geometry (of the scope when it has none).
    bounds: (DVec3, DVec3),
    scope: OrientedBox,
    area: f64,
}

type BoxItem<T> = GeomWithData<Rectangle<[f64; 3]>, T>;

fn rect<T>((lo, hi): (DVec3, DVec3), data: T) -> BoxItem<T> {
    GeomWithData::new(Rectangle::from_corners(lo.to_array(), hi.to_array()), data)
}

fn envelope((lo, hi): (DVec3, DVec3), margin: f64) -> AABB<[f64; 3]> {
    let m = DVec3::splat(margin);
    AABB::from_corners((lo - m).to_array(), (hi + m).to_array())
}

/// What pass 1 recorded for one lot: its labeled shapes and occluders.
#[derive(Debug, Default)]
pub struct LotContext {
    records: Vec<Record>,
    paths: Vec<u32>,
    labels: HashMap<Arc<str>, Vec<u32>>,
    /// The records with closed geometry, by bounds.
    solids: RTree<BoxItem<u32>>,
    /// The initial shape's bounds (`None` for a skipped lot).
    bounds: Option<(DVec3, DVec3)>,
}

impl LotContext {
    /// An empty record for a lot with `bounds` (its initial shape's).
    pub fn new(bounds: Option<(DVec3, DVec3)>) -> LotContext {
        LotContext {
            bounds,
            ..LotContext::default()
        }
    }

    /// Number of labeled shapes and occluders recorded.
    pub fn len(&self) -> usize {
        self.records.len()
    }

    pub fn is_empty(&self) -> bool {
        self.records.is_empty()
    }

    /// Number of shapes labeled `label`.
    pub fn label_count(&self, label: &str) -> usize {
        self.labels.get(label).map_or(0, Vec::len)
    }

    /// Number of recorded shapes with closed geometry (occluders).
    pub fn occluder_count(&self) -> usize {
        self.solids.size()
    }

    fn finish(&mut self) {
        let items = self
            .records
            .iter()
            .enumerate()
            .filter(|(_, r)| r.solid.is_some())
            .map(|(i, r)| rect(r.bounds, i as u32))
            .collect();
        self.solids = RTree::bulk_load(items);
    }

    fn path(&self, r: &Record) -> &[u32] {
        &self.paths[r.path.start as usize..r.path.end as usize]
    }

    /// Ors the occlusion answers of `probe` against this lot's occluders
    /// matching `label`, skipping those whose address is related to
    /// `related_to` (intra queries).
    fn occlude(
        &self,
        probe: &OcclusionMesh,
        label: Option<&str>,
        related_to: Option<&[u32]>,
        acc: &mut Occlusion,
    ) {
        for item in self
            .solids
            .locate_in_envelope_intersecting(&envelope(probe.bounds(), TOLERANCE))
        {
            let r = &self.records[item.data as usize];
            if label.is_some_and(|l| r.label.as_deref() != Some(l)) {
                continue;
            }
            if related_to.is_some_and(|q| related(self.path(r), q)) {
                continue;
            }
            if let Some(solid) = &r.solid {
                *acc = acc.or(occlusion(probe, solid, TOLERANCE));
                if acc.all() {
                    return;
                }
            }
        }
    }

    /// Number of shapes labeled `label` whose key under `cmp` exceeds `than`.
    fn count_better(&self, label: &str, cmp: Compare, than: f64) -> usize {
        self.labels.get(label).map_or(0, |list| {
            list.iter()
                .filter(|&&i| {
                    let r = &self.records[i as usize];
                    cmp.key(r.bounds, r.area) > than
                })
                .count()
        })
    }

    fn nearest(&self, label: &str, scope: &OrientedBox) -> f64 {
        self.labels.get(label).map_or(f64::INFINITY, |list| {
            list.iter()
                .map(|&i| box_distance(scope, &self.records[i as usize].scope))
                .fold(f64::INFINITY, f64::min)
        })
    }
}

/// Whether one address is a prefix of the other (ancestor, descendant or
/// the same shape).
fn related(a: &[u32], b: &[u32]) -> bool {
    let n = a.len().min(b.len());
    a[..n] == b[..n]
}

/// The shapes labeled with one label in every lot, for inter queries.
#[derive(Debug, Default)]
struct LabelIndex {
    /// (lot, record) of each.
    members: Vec<(u32, u32)>,
    /// Sorted keys of each [`Compare`], made when first asked for.
    keys: [OnceLock<Vec<f64>>; 8],
    /// The scopes' bounds, made when first asked for.
    scopes: OnceLock<RTree<BoxItem<(u32, u32)>>>,
}

/// What pass 1 recorded for every lot of a generation, for inter queries:
/// built once ([`SceneContext::new`]) and shared by the threads deriving
/// the lots.
#[derive(Debug, Default)]
pub struct SceneContext {
    usage: ContextUse,
    lots: Vec<Arc<LotContext>>,
    /// For each lot, the other lots within [`OCCLUSION_NEIGHBOURHOOD`].
    neighbours: Vec<Vec<u32>>,
    labels: HashMap<Arc<str>, LabelIndex>,
    /// The lot index of each position, when the scene is a part of a
    /// larger run (see [`SceneContext::numbered`]), and back.
    numbers: Option<HashMap<usize, usize>>,
}

impl SceneContext {
    /// The scene of `lots` (by lot index) for a program making `usage`.
    pub fn new(lots: Vec<LotContext>, usage: ContextUse) -> SceneContext {
        let lots: Vec<Arc<LotContext>> = lots.into_iter().map(Arc::new).collect();
        let tree = RTree::bulk_load(
            lots.iter()
                .enumerate()
                .filter_map(|(i, l)| l.bounds.map(|b| rect(b, i as u32)))
                .collect(),
        );
        let neighbours = lots
            .iter()
            .enumerate()
            .map(|(i, l)| {
                let Some(b) = l.bounds else {
                    return Vec::new();
                };
                let mut near: Vec<u32> = tree
                    .locate_in_envelope_intersecting(&envelope(b, OCCLUSION_NEIGHBOURHOOD))
                    .map(|item| item.data)
                    .filter(|&j| {
                        j as usize != i
                            && lots[j as usize]
                                .bounds
                                .is_some_and(|o| box_gap(b, o) <= OCCLUSION_NEIGHBOURHOOD)
                    })
                    .collect();
                near.sort_unstable();
                near
            })
            .collect();
        let mut labels: HashMap<Arc<str>, LabelIndex> = HashMap::new();
        for (i, lot) in lots.iter().enumerate() {
            for (label, list) in &lot.labels {
                let index = labels.entry(label.clone()).or_default();
                index.members.extend(list.iter().map(|&r| (i as u32, r)));
            }
        }
        SceneContext {
            usage,
            lots,
            neighbours,
            labels,
            numbers: None,
        }
    }

    pub fn usage(&self) -> ContextUse {
        self.usage
    }

    /// The records of lot `index` (empty if there is no such lot).
    pub fn lot(&self, index: usize) -> Arc<LotContext> {
        self.position(index)
            .and_then(|i| self.lots.get(i))
            .cloned()
            .unwrap_or_else(|| Arc::new(LotContext::default()))
    }

    /// The lots inter occlusion queries of lot `index` test against.
    pub fn neighbours(&self, index: usize) -> &[u32] {
        self.position(index)
            .and_then(|i| self.neighbours.get(i))
            .map_or(&[], Vec::as_slice)
    }

    /// The scene with its lots numbered `indices` (the lot indices of a
    /// part of a larger run, by position); neighbours stay positions.
    pub fn numbered(mut self, indices: Vec<usize>) -> SceneContext {
        self.numbers = Some(
            indices
                .into_iter()
                .enumerate()
                .map(|(p, i)| (i, p))
                .collect(),
        );
        self
    }

    /// The position in the scene of lot `index`.
    fn position(&self, index: usize) -> Option<usize> {
        match &self.numbers {
            Some(map) => map.get(&index).copied(),
            None => Some(index),
        }
    }

    fn label_total(&self, label: &str) -> usize {
        self.labels.get(label).map_or(0, |l| l.members.len())
    }

    fn record(&self, (lot, r): (u32, u32)) -> &Record {
        &self.lots[lot as usize].records[r as usize]
    }

    /// Number of shapes labeled `label` in every lot with a key under
    /// `cmp` above `than`.
    fn count_better(&self, label: &str, cmp: Compare, than: f64) -> usize {
        let Some(index) = self.labels.get(label) else {
            return 0;
        };
        let slot = Compare::ALL.iter().position(|&c| c == cmp).unwrap_or(0);
        let keys = index.keys[slot].get_or_init(|| {
            let mut k: Vec<f64> = index
                .members
                .iter()
                .map(|&m| {
                    let r = self.record(m);
                    cmp.key(r.bounds, r.area)
                })
                .collect();
            k.sort_by(f64::total_cmp);
            k
        });
        keys.len() - keys.partition_point(|&k| k <= than)
    }

    /// The least distance from `scope` to the scope of a shape labeled
    /// `label` in a lot other than `own`.
    fn nearest(&self, label: &str, scope: &OrientedBox, own: usize) -> f64 {
        let Some(index) = self.labels.get(label) else {
            return f64::INFINITY;
        };
        let own_position = self.position(own);
        let tree = index.scopes.get_or_init(|| {
            RTree::bulk_load(
                index
                    .members
                    .iter()
                    .map(|&m| rect(self.record(m).scope.bounds(), m))
                    .collect(),
            )
        });
        if tree.size() == 0 {
            return f64::INFINITY;
        }
        // Widen the search until the nearest found lies within the searched
        // margin: anything nearer has its bounds within that margin too.
        let bounds = scope.bounds();
        let all = tree.root().envelope();
        let mut margin = (bounds.1 - bounds.0).max_element().max(1.0);
        loop {
            let env = envelope(bounds, margin);
            let mut best = f64::INFINITY;
            for item in tree.locate_in_envelope_intersecting(&env) {
                if Some(item.data.0 as usize) != own_position {
                    best = best.min(box_distance(scope, &self.record(item.data).scope));
                }
            }
            let covers_all = env.contains_envelope(&all);
            if best <= margin || covers_all {
                return best;
            }
            margin *= 4.0;
        }
    }
}

/// The distance between two axis-aligned boxes (0 if they meet).
fn box_gap(a: (DVec3, DVec3), b: (DVec3, DVec3)) -> f64 {
    let gap = (a.0 - b.1).max(b.0 - a.1).max(DVec3::ZERO);
    gap.length()
}

// ----- the state of one derivation -----

/// One node of the shape tree: the parent and the ordinal among its
/// successors, and how many successors it has so far.
#[derive(Clone, Copy, Debug)]
struct Node {
    parent: u32,
    ordinal: u32,
    children: u32,
}

enum Pass {
    /// Pass 1: queries give defaults; shapes are recorded here.
    Collect(Box<LotContext>),
    /// Pass 2: queries are answered from the records of pass 1.
    Answer {
        own: Arc<LotContext>,
        scene: Option<Arc<SceneContext>>,
        lot: usize,
    },
}

/// The query geometry of the last shape asked about, and the answers
/// given for it (`touches(..) || inside(..) || overlaps(..)` asks three
/// times about one shape).
struct Probe {
    node: u32,
    mesh: Arc<Mesh>,
    transform: [u64; 12],
    geometry: OcclusionMesh,
    answers: Vec<(Target, Option<Arc<str>>, Occlusion)>,
}

/// The context state of one derivation pass of one lot (in [`Interp`]).
pub struct ContextState {
    usage: ContextUse,
    pass: Pass,
    nodes: Vec<Node>,
    path: Vec<u32>,
    probe: Option<Probe>,
    /// Closedness of recently recorded shared meshes (inserted assets).
    closed_memo: Vec<(Arc<Mesh>, bool)>,
}

impl ContextState {
    fn new(usage: ContextUse, pass: Pass) -> ContextState {
        ContextState {
            usage,
            pass,
            nodes: vec![Node {
                parent: u32::MAX,
                ordinal: 0,
                children: 0,
            }],
            path: Vec::new(),
            probe: None,
            closed_memo: Vec::new(),
        }
    }

    /// Pass 1 of a lot with initial shape bounds `bounds`.
    pub fn collecting(usage: ContextUse, bounds: Option<(DVec3, DVec3)>) -> Box<ContextState> {
        Box::new(ContextState::new(
            usage,
            Pass::Collect(Box::new(LotContext::new(bounds))),
        ))
    }

    /// Pass 2 of lot `lot`, answering from its own records `own` and
    /// other lots' in `scene`.
    pub fn answering(
        usage: ContextUse,
        own: Arc<LotContext>,
        scene: Option<Arc<SceneContext>>,
        lot: usize,
    ) -> Box<ContextState> {
        Box::new(ContextState::new(usage, Pass::Answer { own, scene, lot }))
    }

    /// The records of pass 1.
    pub fn into_lot_context(self) -> LotContext {
        match self.pass {
            Pass::Collect(mut lot) => {
                lot.finish();
                *lot
            }
            Pass::Answer { .. } => LotContext::default(),
        }
    }

    pub fn collecting_now(&self) -> bool {
        matches!(self.pass, Pass::Collect(_))
    }

    /// A new successor node of `parent` (only when addresses are needed).
    fn child_node(&mut self, parent: u32) -> u32 {
        if !self.usage.intra_occlusion {
            return 0;
        }
        let Some(p) = self.nodes.get_mut(parent as usize) else {
            return 0;
        };
        let ordinal = p.children;
        p.children += 1;
        self.nodes.push(Node {
            parent,
            ordinal,
            children: 0,
        });
        (self.nodes.len() - 1) as u32
    }

    /// The address of `node` into `self.path`.
    fn address(&mut self, mut node: u32) {
        self.path.clear();
        while node != 0 {
            let Some(n) = self.nodes.get(node as usize) else {
                break;
            };
            self.path.push(n.ordinal);
            node = n.parent;
        }
        self.path.reverse();
    }

    fn is_closed(&mut self, mesh: &Arc<Mesh>) -> bool {
        if mesh.faces.len() < 2 {
            return false;
        }
        if Arc::strong_count(mesh) == 1 {
            return cga_geometry::measure::is_closed(mesh);
        }
        if let Some((_, c)) = self.closed_memo.iter().find(|(m, _)| Arc::ptr_eq(m, mesh)) {
            return *c;
        }
        let c = cga_geometry::measure::is_closed(mesh);
        if self.closed_memo.len() >= 8 {
            self.closed_memo.remove(0);
        }
        self.closed_memo.push((mesh.clone(), c));
        c
    }

    /// Records `shape` in pass 1: with a label, or as an automatic
    /// occluder (kept only if closed).
    fn record(&mut self, shape: &Shape, label: Option<Arc<str>>) {
        if !self.collecting_now() {
            return;
        }
        if label.is_none() && !self.usage.unlabeled {
            return;
        }
        let (mesh, _) = shape.geometry.raw();
        let closed = self.is_closed(mesh);
        if label.is_none() && !closed {
            return;
        }
        let geometry = OcclusionMesh::with_closed(mesh, Some(&shape.object_transform()), closed);
        let s = &shape.scope;
        let scope = OrientedBox::new(s.frame.origin, s.frame.axes, s.size);
        let bounds = if geometry.is_empty() {
            scope.bounds()
        } else {
            geometry.bounds()
        };
        let area = geometry.area();
        let solid = (self.usage.occlusion && geometry.is_closed()).then_some(geometry);
        if label.is_none() && solid.is_none() {
            return;
        }
        if self.usage.intra_occlusion {
            self.address(shape.ctx);
        }
        let Pass::Collect(lot) = &mut self.pass else {
            return;
        };
        let start = lot.paths.len() as u32;
        if self.usage.intra_occlusion {
            lot.paths.extend_from_slice(&self.path);
        }
        let index = lot.records.len() as u32;
        if let Some(l) = &label {
            lot.labels.entry(l.clone()).or_default().push(index);
        }
        lot.records.push(Record {
            label,
            path: start..lot.paths.len() as u32,
            solid,
            bounds,
            scope,
            area,
        });
    }

    /// The probe of `shape`, built unless it is the last one asked about.
    fn probe(&mut self, shape: &Shape) -> &mut Probe {
        let (mesh, _) = shape.geometry.raw();
        let transform = shape.object_transform();
        let key = transform.to_cols_array().map(f64::to_bits);
        let hit = self.probe.as_ref().is_some_and(|p| {
            p.node == shape.ctx && Arc::ptr_eq(&p.mesh, mesh) && p.transform == key
        });
        if !hit {
            self.probe = Some(Probe {
                node: shape.ctx,
                mesh: mesh.clone(),
                transform: key,
                geometry: OcclusionMesh::new(mesh, Some(&transform)),
                answers: Vec::new(),
            });
        }
        self.probe.as_mut().expect("set above")
    }

    /// The occlusion answers for `shape` against the occluders `target`
    /// and `label` select.
    fn occlusion(&mut self, shape: &Shape, target: Target, label: Option<&str>) -> Occlusion {
        let (own, scene, lot) = match &self.pass {
            Pass::Collect(_) => return Occlusion::default(),
            Pass::Answer { own, scene, lot } => (own.clone(), scene.clone(), *lot),
        };
        let self_addresses = self.usage.intra_occlusion;
        if self_addresses && target.intra() {
            self.address(shape.ctx);
        }
        let path = std::mem::take(&mut self.path);
        let probe = self.probe(shape);
        if let Some((.., a)) = probe
            .answers
            .iter()
            .find(|(t, l, _)| *t == target && l.as_deref() == label)
        {
            let a = *a;
            self.path = path;
            return a;
        }
        let mut acc = Occlusion::default();
        if !probe.geometry.is_empty() {
            if target.intra() {
                let related_to = self_addresses.then_some(path.as_slice());
                own.occlude(&probe.geometry, label, related_to, &mut acc);
            }
            if let (true, Some(scene)) = (target.inter(), &scene) {
                for &n in scene.neighbours(lot) {
                    if acc.all() {
                        break;
                    }
                    scene.lots[n as usize].occlude(&probe.geometry, label, None, &mut acc);
                }
            }
        }
        probe.answers.push((target, label.map(Arc::from), acc));
        self.path = path;
        acc
    }

    fn count(&self, target: Target, label: &str) -> usize {
        let Pass::Answer { own, scene, .. } = &self.pass else {
            return 0;
        };
        let mine = own.label_count(label);
        let mut n = 0;
        if target.intra() {
            n += mine;
        }
        if let (true, Some(scene)) = (target.inter(), scene) {
            n += scene.label_total(label).saturating_sub(mine);
        }
        n
    }

    fn compare(&mut self, shape: &Shape, target: Target, label: &str, cmp: Compare) -> usize {
        let (own, scene) = match &self.pass {
            Pass::Collect(_) => return 0,
            Pass::Answer { own, scene, .. } => (own.clone(), scene.clone()),
        };
        let probe = &self.probe(shape).geometry;
        let (bounds, area) = if probe.is_empty() {
            let s = &shape.scope;
            (
                OrientedBox::new(s.frame.origin, s.frame.axes, s.size).bounds(),
                0.0,
            )
        } else {
            (probe.bounds(), probe.area())
        };
        // Equal values share the lowest rank: only keys clearly above count.
        let than = cmp.key(bounds, area) + TOLERANCE;
        let mine = own.count_better(label, cmp, than);
        let mut rank = 0;
        if target.intra() {
            rank += mine;
        }
        if let (true, Some(scene)) = (target.inter(), &scene) {
            rank += scene.count_better(label, cmp, than).saturating_sub(mine);
        }
        rank
    }

    fn distance(&self, shape: &Shape, target: Target, label: &str) -> f64 {
        let Pass::Answer { own, scene, lot } = &self.pass else {
            return f64::INFINITY;
        };
        let s = &shape.scope;
        let scope = OrientedBox::new(s.frame.origin, s.frame.axes, s.size);
        let mut d = f64::INFINITY;
        if target.intra() {
            d = d.min(own.nearest(label, &scope));
        }
        if let (true, Some(scene)) = (target.inter(), scene) {
            d = d.min(scene.nearest(label, &scope, *lot));
        }
        d
    }
}

// ----- the interpreter's side -----

fn text_arg<'v>(v: &'v Value, what: &str, at: &RExpr) -> Result<&'v str, RtError> {
    match v {
        Value::Str(s) => Ok(s),
        other => Err(RtError::new(
            format!(
                "{what} must be a string, found {}",
                crate::values::type_name(other)
            ),
            at.span,
        )),
    }
}

impl Interp<'_> {
    /// The shape-tree node of a new successor of a shape at node `parent`.
    pub(crate) fn context_child(&mut self, parent: u32) -> u32 {
        match self.context.as_deref_mut() {
            Some(c) => c.child_node(parent),
            None => 0,
        }
    }

    /// Whether the first pass of context queries skips `rule` ([`FirstPass`]).
    pub(crate) fn context_skips(&self, rule: crate::program::RuleId) -> bool {
        self.first_pass_runs() && !FirstPass::cached(self.program).applies(rule)
    }

    /// Whether the first pass of context queries skips `body`, a component
    /// split's entry ([`FirstPass::body_applies`]).
    pub(crate) fn context_skips_body(&self, body: &RBody) -> bool {
        self.first_pass_runs() && !FirstPass::cached(self.program).body_applies(body)
    }

    /// A first pass outside `inline` and `modify` (whose rules are never
    /// skipped).
    fn first_pass_runs(&self) -> bool {
        self.collected.is_none() && self.context_collecting()
    }

    /// Whether this is a first, collecting pass (nothing is emitted).
    pub(crate) fn context_collecting(&self) -> bool {
        self.context
            .as_deref()
            .is_some_and(ContextState::collecting_now)
    }

    /// A leaf, or a shape `comp` or `offset` runs on: an automatic
    /// occluder if its geometry is closed.
    pub(crate) fn context_occluder(&mut self, shape: &Shape) {
        if let Some(c) = self.context.as_deref_mut() {
            c.record(shape, None);
        }
    }

    /// `label(name)`: records a labeled copy of the shape.
    pub(crate) fn context_label(&mut self, shape: &Shape, label: &str) {
        if let Some(c) = self.context.as_deref_mut() {
            c.record(shape, Some(Arc::from(label)));
        }
    }

    /// Evaluates a context query on `shape`.
    pub(crate) fn context_query(
        &mut self,
        f: ContextFn,
        args: &[Value],
        shape: &Shape,
        at: &RExpr,
    ) -> Result<Value, RtError> {
        // An explicit target comes first; `contextCount("x")` has none.
        let (target, rest) = match args.first() {
            Some(Value::Str(s)) if Target::parse(s).is_some() => {
                (Target::parse(s).unwrap_or(Target::All), &args[1..])
            }
            Some(_)
                if matches!(
                    f,
                    ContextFn::Inside | ContextFn::Overlaps | ContextFn::Touches
                ) =>
            {
                return Err(RtError::new(
                    "the target of an occlusion query is intra, inter or all",
                    at.span,
                ))
            }
            _ => (Target::All, args),
        };
        let label = match rest.first() {
            Some(v) => text_arg(v, "the label", at)?,
            None => "",
        };
        let state = self.context.as_deref_mut();
        Ok(match f {
            ContextFn::Inside | ContextFn::Overlaps | ContextFn::Touches => {
                let label = (!label.is_empty()).then_some(label);
                let r = state.map_or(Occlusion::default(), |c| c.occlusion(shape, target, label));
                Value::Bool(match f {
                    ContextFn::Inside => r.inside,
                    ContextFn::Overlaps => r.overlaps,
                    _ => r.touches,
                })
            }
            ContextFn::ContextCount => Value::Float(match state {
                Some(c) if !label.is_empty() => c.count(target, label) as f64,
                _ => 0.0,
            }),
            ContextFn::ContextCompare => {
                let cmp = match rest.get(1) {
                    Some(v) => {
                        let name = text_arg(v, "the comparison", at)?;
                        Compare::parse(name).ok_or_else(|| {
                            RtError::new(
                                format!("`{name}` is not a comparison of contextCompare (world.northernmost, world.southernmost, world.easternmost, world.westernmost, world.highest, world.lowest, area.largest, area.smallest)"),
                                at.span,
                            )
                        })?
                    }
                    None => {
                        return Err(RtError::new(
                            "contextCompare needs a comparison (world.highest, area.largest, ...)",
                            at.span,
                        ))
                    }
                };
                Value::Float(match state {
                    Some(c) if !label.is_empty() => c.compare(shape, target, label, cmp) as f64,
                    _ => 0.0,
                })
            }
            ContextFn::MinimumDistance => Value::Float(match state {
                Some(c) if !label.is_empty() => c.distance(shape, target, label),
                _ => f64::INFINITY,
            }),
        })
    }
}

/// The bounds of the initial shape of a lot with `mesh` (scene coordinates).
pub(crate) fn lot_bounds(mesh: &Mesh) -> Option<(DVec3, DVec3)> {
    cga_geometry::measure::bounds(mesh)
}

/// Scenes are shared by the threads that derive lots.
const _: fn() = || {
    fn check<T: Send + Sync>() {}
    check::<SceneContext>();
    check::<LotContext>();
};
