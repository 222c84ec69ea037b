//! Subtrees derived once, for generations that keep no model (report
//! tables: `GenerateOptions::count_leaves_only`).
//!
//! There a rule applied to a shape adds only shapes and leaves to the
//! counts. The windows of a facade are the same rule applied to shapes
//! that differ only in where they stand: same size, same orientation,
//! same geometry in scope coordinates. When nothing the rule and the rules
//! it calls can read depends on where a shape stands, the second window
//! adds what the first did, and need not be derived.
//!
//! [`SubtreeMemo::of`] works out, per rule, whether its subtree can be
//! remembered that way and what its key must hold ([`Needs`]). A rule
//! qualifies when it and every rule it can call use only operations that
//! work in scope coordinates (`split`, `comp` by faces, edges, vertices or
//! holes, `t`, `s`, `r`, `center`, `extrude`, `i()`, the primitives,
//! `trim`, `set` of attributes, materials, trim switches, scope sizes and
//! angles, the texture operations when no rule reads texture
//! coordinates, `reverseNormals`, `convexify`), and read of the shape only
//! its size and angles, its geometry's measures, split and component
//! information, the trim switches and the random stream. Reports, prints,
//! positions (`scope.t*`, `pivot.*`, `scope.elevation`, `convert`), file
//! functions, materials, tags and groups disqualify it. Programs with
//! context queries, tree keys, texture coordinates read, or attributes and
//! constants that read the shape are left alone.
//!
//! The random stream counts only where its values matter: in a
//! condition, a split size, an operation's argument, a stochastic rule;
//! not in the arguments of `color`, `texture`, material settings and the
//! texture coordinate operations (which then compute nothing), nor in a
//! rule's parameter used only there. Where a value does not matter it can
//! still make an operation warn (a texture size of 0, a colour that is
//! none), so a random value is left out of the key only in `translateUV`
//! and `rotateUV`, and only as a number made by arithmetic and rounding
//! (so that whether the operation warns is the same for every draw).
//! Candler's windows pick a random tile of their texture (a `translateUV`
//! by a random whole number of tiles): their counts do not depend on it.
//!
//! Extrusions and geometry measures are computed around the scope's origin
//! (`Shape::oriented_transform`), not in object coordinates, so that two
//! shapes alike but for their place give the same sizes and areas to the
//! last bit; which projections are set up is in the key (`projectUV`
//! warns without one).
//!
//! The key (built by the interpreter, `derive.rs`) holds the rule, its
//! arguments, the scope's size, angles and axes, the pivot's axes, the
//! geometry in scope coordinates, the attributes set on the shape, the
//! trim switches and the orientation of its trim planes, and what
//! [`Needs`] asks for. Trim planes stand where the building's corners are:
//! their distance from the shape is not in the key. Instead the first
//! derivation records, per plane, how far it could move towards the shape
//! before one of its trims would cut something (`trim::apply` logs it); a
//! later shape uses the remembered counts only if its planes stay that
//! far away, or stand exactly where they stood.

use crate::expr::{OpCall, RBlock, RBody, RExpr, RExprKind, RPart, RStmt};
use crate::ops::{AttrOp, CleanupOp, Op, SetTarget, TextureOp, TransformOp};
use crate::program::Program;
use crate::selectors::Selector;
use crate::shape::Shape;
use crate::shape_fns::{GeometryFn, ShapeFn};
use cga_geometry::DVec3;
use cga_syntax::ast::BinaryOp;
use cga_value::Value;

/// What the key of a rule's subtree must hold beyond what every key does.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Needs {
    /// The random stream's state and `seedian`: a random value matters.
    pub rng: bool,
    /// `split.index` and `split.total`.
    pub split: bool,
    /// `comp.sel`, `comp.index` and `comp.total`.
    pub comp: bool,
    /// Where the parent's scope centre is (`center`).
    pub center: bool,
}

/// Per rule, whether its subtree may be remembered, and with what key.
#[derive(Debug, Default)]
pub struct SubtreeMemo {
    rules: Vec<Option<Needs>>,
}

impl SubtreeMemo {
    pub fn of(program: &Program) -> SubtreeMemo {
        let off = SubtreeMemo::default();
        if crate::context::ContextUse::of(program).any()
            || program.uses_tree_key
            || program.uv_sets_read() != 0
        {
            return off;
        }
        let functions = function_facts(program);
        let none = Params::default();
        // Attributes and constants are evaluated where first used: one that
        // reads the shape would take its value from whichever shape that is.
        let reads_shape = |e: &RExpr| {
            let mut s = Scan::new(&functions, &none, usize::MAX);
            s.expr(e, true);
            s.facts.reads_shape()
        };
        if program.attrs.iter().any(|a| reads_shape(&a.default))
            || program
                .functions
                .iter()
                .filter(|f| f.is_const)
                .any(|f| f.locals.iter().any(reads_shape) || reads_shape(&f.body))
        {
            return off;
        }
        let params = relevant_params(program, &functions);
        // Each rule's own facts, then those of everything it can call.
        let mut facts: Vec<Facts> = Vec::with_capacity(program.rules.len());
        let mut callees: Vec<Vec<u32>> = Vec::with_capacity(program.rules.len());
        for (r, def) in program.rules.iter().enumerate() {
            let mut s = Scan::new(&functions, &params, r);
            s.rule(def);
            facts.push(s.facts);
            callees.push(s.callees);
        }
        loop {
            let mut changed = false;
            for r in 0..facts.len() {
                let mut f = facts[r];
                for &c in &callees[r] {
                    f = f.or(facts[c as usize]);
                }
                if f != facts[r] {
                    facts[r] = f;
                    changed = true;
                }
            }
            if !changed {
                break;
            }
        }
        SubtreeMemo {
            rules: facts
                .iter()
                .map(|f| {
                    (!f.bad && f.creates).then_some(Needs {
                        rng: f.rng,
                        split: f.split,
                        comp: f.comp,
                        center: f.center,
                    })
                })
                .collect(),
        }
    }

    /// What the key of `rule`'s subtree holds, if it may be remembered
    /// (rules that create no shape are cheaper to apply than to look up).
    pub fn rule(&self, rule: u32) -> Option<Needs> {
        self.rules.get(rule as usize).copied().flatten()
    }

    /// Whether any rule's subtree may be remembered.
    pub fn any(&self) -> bool {
        self.rules.iter().any(Option::is_some)
    }
}

/// What a rule, a function or an expression can do or read.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Facts {
    /// Something that depends on where the shape stands, or shows
    /// otherwise than in the counts.
    bad: bool,
    rng: bool,
    split: bool,
    comp: bool,
    center: bool,
    /// Creates shapes (a rule call, `split`, `comp`).
    creates: bool,
    /// Reads anything of the shape (attributes and constants must not).
    shape: bool,
}

impl Facts {
    fn or(self, o: Facts) -> Facts {
        Facts {
            bad: self.bad || o.bad,
            rng: self.rng || o.rng,
            split: self.split || o.split,
            comp: self.comp || o.comp,
            center: self.center || o.center,
            creates: self.creates || o.creates,
            shape: self.shape || o.shape,
        }
    }

    fn reads_shape(&self) -> bool {
        self.shape || self.bad || self.rng
    }
}

/// Per user function, what its value can read (through its body, its
/// locals and the functions it calls); a random value counts wherever the
/// call's value matters.
fn function_facts(program: &Program) -> Vec<Facts> {
    let mut facts = vec![Facts::default(); program.functions.len()];
    loop {
        let next: Vec<Facts> = program
            .functions
            .iter()
            .map(|f| {
                let none = Params::default();
                let mut s = Scan::new(&facts, &none, usize::MAX);
                for l in &f.locals {
                    s.expr(l, true);
                }
                s.expr(&f.body, true);
                s.facts
            })
            .collect();
        if next == facts {
            return facts;
        }
        facts = next;
    }
}

/// Per rule and parameter, whether the parameter's value can matter to
/// the counts (see the module docs), and whether a value that depends on
/// the random stream can reach it (through a parameter that does not
/// matter), until nothing changes.
fn relevant_params(program: &Program, functions: &[Facts]) -> Params {
    let blank =
        || -> Vec<Vec<bool>> { program.rules.iter().map(|r| vec![false; r.arity]).collect() };
    let mut params = Params {
        relevant: blank(),
        random: blank(),
    };
    loop {
        let mut next = Params {
            relevant: blank(),
            random: params.random.clone(),
        };
        for (r, def) in program.rules.iter().enumerate() {
            let mut s = Scan::new(functions, &params, r);
            s.rule(def);
            next.relevant[r] = s.relevant;
            for (c, i) in s.random_args {
                if let Some(slot) = next.random.get_mut(c as usize).and_then(|p| p.get_mut(i)) {
                    *slot = true;
                }
            }
        }
        if next.relevant == params.relevant && next.random == params.random {
            return params;
        }
        params = next;
    }
}

/// Per rule and parameter: whether its value matters, and whether it can
/// carry a random value (to places where it does not matter).
#[derive(Default)]
struct Params {
    relevant: Vec<Vec<bool>>,
    random: Vec<Vec<bool>>,
}

/// Built-in functions that give a finite number for finite numbers, and
/// fail for no value of one: a random value through them still cannot
/// make an operation warn or fail where another would not.
const SAFE_BUILTINS: &[&str] = &["floor", "ceil", "round", "rint", "abs", "min", "max"];

/// One pass over a rule or an expression.
struct Scan<'a> {
    functions: &'a [Facts],
    /// Parameters of every rule, as known so far.
    params: &'a Params,
    /// The rule scanned (`usize::MAX`: an attribute or a function).
    rule: usize,
    facts: Facts,
    /// The parameters of the rule scanned whose values matter.
    relevant: Vec<bool>,
    /// (rule, parameter) that a random value reaches from here.
    random_args: Vec<(u32, usize)>,
    callees: Vec<u32>,
}

impl<'a> Scan<'a> {
    fn new(functions: &'a [Facts], params: &'a Params, rule: usize) -> Scan<'a> {
        let arity = params.relevant.get(rule).map_or(0, Vec::len);
        Scan {
            functions,
            params,
            rule,
            facts: Facts::default(),
            relevant: vec![false; arity],
            random_args: Vec::new(),
            callees: Vec::new(),
        }
    }

    /// Whether `e` depends on the random stream (a random function, a
    /// parameter that can carry a random value, a function that draws),
    /// and if so whether it is safe where its value does not matter: a
    /// number or a truth value made from it by arithmetic (a division
    /// only by something that does not depend on it), comparisons and the
    /// built-ins of [`SAFE_BUILTINS`], so that whether the operation
    /// taking it warns or fails is the same for every draw. Strings
    /// (`+` with a string names another texture), conditional values and
    /// anything else are not safe.
    fn random(&self, e: &RExpr) -> (bool, bool) {
        let all = |es: &[RExpr]| {
            es.iter()
                .map(|x| self.random(x))
                .fold((false, true), |(t, s), (t2, s2)| (t || t2, s && s2))
        };
        match &e.kind {
            RExprKind::Const(_) | RExprKind::Attr(_) => (false, true),
            RExprKind::Local(k) => {
                let random = self
                    .params
                    .random
                    .get(self.rule)
                    .and_then(|p| p.get(*k as usize))
                    .copied()
                    .unwrap_or(false);
                (random, true)
            }
            // A number (or a truth value) of the stream.
            RExprKind::Shape(ShapeFn::Rand | ShapeFn::P | ShapeFn::Seedian, args) => {
                let (_, s) = all(args);
                (true, s)
            }
            RExprKind::Shape(_, args) => {
                let (t, s) = all(args);
                (t, s && !t)
            }
            RExprKind::Pure(b, args) => {
                let (t, s) = all(args);
                (t, s && (!t || SAFE_BUILTINS.contains(&b.name)))
            }
            RExprKind::Func(f, args) => {
                let draws = self.functions.get(*f as usize).is_none_or(|f| f.rng);
                let (t, _) = all(args);
                (t || draws, !(t || draws))
            }
            RExprKind::Unary { operand, .. } => self.random(operand),
            RExprKind::Binary { op, lhs, rhs, .. } => {
                let (lt, ls) = self.random(lhs);
                let (rt, rs) = self.random(rhs);
                let t = lt || rt;
                // `+` of a string and a random number is a random string.
                let numeric = |x: &RExpr, random: bool| {
                    random || matches!(x.kind, RExprKind::Const(cga_value::Value::Float(_)))
                };
                let safe = ls
                    && rs
                    && match op {
                        BinaryOp::Add => !t || (numeric(lhs, lt) && numeric(rhs, rt)),
                        BinaryOp::Div | BinaryOp::Rem => !rt,
                        _ => true,
                    };
                (t, safe)
            }
            RExprKind::Relative(inner) | RExprKind::Floating(inner) => self.random(inner),
            _ => {
                let any = self.walk_random(e);
                (any, !any)
            }
        }
    }

    /// Whether anything in `e` depends on the random stream.
    fn walk_random(&self, e: &RExpr) -> bool {
        match &e.kind {
            RExprKind::Stochastic { .. } | RExprKind::CompFn { .. } => true,
            RExprKind::Case { .. }
            | RExprKind::Index { .. }
            | RExprKind::Range { .. }
            | RExprKind::WithLocals { .. }
            | RExprKind::CompSelector(..)
            | RExprKind::Array(_)
            | RExprKind::CompHead { .. } => e.any_child(|c| self.walk_random(c)),
            _ => self.random(e).0,
        }
    }

    /// An expression in a place where its value does not matter: only if
    /// it is safe there (see [`random`](Self::random)) is the random
    /// stream left out of the key.
    fn inert(&mut self, e: &RExpr) {
        let (random, safe) = self.random(e);
        if random && !safe {
            self.facts.rng = true;
        }
        self.expr(e, false);
    }

    fn rule(&mut self, def: &crate::program::RuleDef) {
        // `with` locals: taken as mattering.
        for l in &def.locals {
            self.expr(l, true);
        }
        self.body(&def.body);
    }

    /// `relevant`: whether the expression's value can matter.
    fn expr(&mut self, e: &RExpr, relevant: bool) {
        match &e.kind {
            RExprKind::Local(k) if relevant => {
                if let Some(r) = self.relevant.get_mut(*k as usize) {
                    *r = true;
                }
            }
            RExprKind::Func(f, _) => {
                let mut f = self.functions.get(*f as usize).copied().unwrap_or(Facts {
                    bad: true,
                    ..Facts::default()
                });
                f.rng &= relevant;
                f.creates = false;
                self.facts = self.facts.or(f);
            }
            RExprKind::Shape(f, _) => self.shape_fn(*f, relevant),
            RExprKind::Stochastic { .. } => self.facts.rng |= relevant,
            RExprKind::CompSelector(sel, _) => self.facts.bad |= *sel == Selector::IsTagged,
            // The comp function reads faces by any selector: not worth telling apart.
            RExprKind::CompFn { .. } => {
                self.facts.bad = true;
                return;
            }
            _ => {}
        }
        e.for_each_child(&mut |c| self.expr(c, relevant));
    }

    fn shape_fn(&mut self, f: ShapeFn, relevant: bool) {
        self.facts.shape |= !matches!(
            f,
            ShapeFn::InitialShapeName
                | ShapeFn::InitialShapeStartRule
                | ShapeFn::InitialShapeOrigin(_)
        );
        match f {
            // Size and angles are in the key; the position is not.
            ShapeFn::Scope(i) => self.facts.bad |= i < 3,
            ShapeFn::SplitIndex | ShapeFn::SplitTotal => self.facts.split = true,
            ShapeFn::CompSel | ShapeFn::CompIndex | ShapeFn::CompTotal => self.facts.comp = true,
            ShapeFn::Seedian | ShapeFn::Rand | ShapeFn::P => self.facts.rng |= relevant,
            ShapeFn::TrimHorizontal | ShapeFn::TrimVertical => {}
            // The same for every shape of the lot.
            ShapeFn::InitialShapeName
            | ShapeFn::InitialShapeStartRule
            | ShapeFn::InitialShapeOrigin(_) => {}
            ShapeFn::Geometry(g) => {
                self.facts.bad |= g.reads_uvs()
                    || matches!(
                        g,
                        GeometryFn::Materials
                            | GeometryFn::Tags
                            | GeometryFn::HasTags
                            | GeometryFn::Groups
                            | GeometryFn::IsInstanced
                    )
            }
            ShapeFn::ScopeElevation
            | ShapeFn::Pivot(_)
            | ShapeFn::Material(_)
            | ShapeFn::Print
            | ShapeFn::Context(_)
            | ShapeFn::File(_) => self.facts.bad = true,
        }
    }

    fn body(&mut self, b: &RBody) {
        match b {
            RBody::Ops(stmts) => {
                for s in stmts {
                    self.stmt(s);
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
                if matches!(b, RBody::Stochastic { .. }) {
                    self.facts.rng = true;
                }
                for (c, body) in branches {
                    self.expr(c, true);
                    self.body(body);
                }
                if let Some(o) = otherwise {
                    self.body(o);
                }
            }
        }
    }

    fn stmt(&mut self, s: &RStmt) {
        match s {
            RStmt::Op(call) => self.op(call),
            RStmt::Rule(rc) => {
                self.facts.creates = true;
                self.facts.bad |= rc.dynamic;
                self.callees.push(rc.rule);
                let relevant = self.params.relevant.get(rc.rule as usize);
                for (i, a) in rc.args.iter().enumerate() {
                    // Before the parameters are known (functions, attributes): all matter.
                    let r = relevant.is_none_or(|p| p.get(i).copied().unwrap_or(true));
                    if r {
                        self.expr(a, true);
                        continue;
                    }
                    // A random value passed where it does not matter: the
                    // parameter carries it on, if it is safe to.
                    let (random, safe) = self.random(a);
                    if random && safe {
                        self.random_args.push((rc.rule, i));
                    }
                    if random && !safe {
                        self.facts.rng = true;
                    }
                    self.expr(a, false);
                }
                for (_, e) in &rc.attr_overrides {
                    self.expr(e, true);
                }
            }
            RStmt::Leaf(_) | RStmt::Nil => {}
            RStmt::Push(body) => self.body(body),
            RStmt::Unsupported { .. } => self.facts.bad = true,
        }
    }

    fn op(&mut self, call: &OpCall) {
        // Whether the arguments' values matter: not for operations whose
        // effect nothing counted can see.
        let relevant = match call.op {
            Op::Split | Op::Trim => true,
            Op::Comp => {
                let kind = call.args.first().and_then(|a| match &a.kind {
                    RExprKind::Const(cga_value::Value::Str(s)) => Some(s.clone()),
                    _ => None,
                });
                self.facts.bad |=
                    !kind.is_some_and(|k| matches!(&*k, "f" | "e" | "fe" | "v" | "fv" | "h"));
                true
            }
            Op::Transform(TransformOp::T | TransformOp::S | TransformOp::R) => true,
            Op::Transform(TransformOp::Center) => {
                self.facts.center = true;
                true
            }
            Op::Create(_) => true,
            Op::Attr(AttrOp::Color | AttrOp::SetMaterial | AttrOp::ResetMaterial) => false,
            Op::Attr(AttrOp::Set(target)) => match target {
                SetTarget::Attr(_) => true,
                SetTarget::Shape(ShapeFn::Material(_)) => false,
                SetTarget::Shape(ShapeFn::TrimHorizontal | ShapeFn::TrimVertical) => true,
                SetTarget::Shape(ShapeFn::Scope(i)) if i >= 3 => true,
                SetTarget::Shape(_) => {
                    self.facts.bad = true;
                    true
                }
            },
            // Computes nothing when no rule reads texture coordinates
            // (`SubtreeMemo::of` leaves other programs alone).
            Op::Texturing(TextureOp::InsertAlongUV) => {
                self.facts.bad = true;
                true
            }
            Op::Texturing(_) => false,
            Op::Cleanup(CleanupOp::ReverseNormals | CleanupOp::Convexify) => true,
            _ => {
                self.facts.bad = true;
                true
            }
        };
        if matches!(call.op, Op::Split | Op::Comp) {
            self.facts.creates = true;
        }
        // Where a value does not matter, a random one still can make an
        // operation warn (a texture size of 0, a colour that is none):
        // only moving and turning texture coordinates takes any number.
        let any_number = matches!(
            call.op,
            Op::Texturing(TextureOp::TranslateUV | TextureOp::RotateUV)
        );
        for a in &call.args {
            match (relevant, any_number) {
                (true, _) => self.expr(a, true),
                (false, true) => self.inert(a),
                (false, false) => {
                    self.facts.rng |= self.random(a).0;
                    self.expr(a, false);
                }
            }
        }
        for block in [&call.block, &call.remainder_block].into_iter().flatten() {
            self.block(block);
        }
    }

    fn block(&mut self, block: &RBlock<RBody>) {
        for p in &block.parts {
            match p {
                RPart::Entry {
                    head, depth, body, ..
                } => {
                    self.expr(head, true);
                    if let Some(d) = depth {
                        self.expr(d, true);
                    }
                    self.body(body);
                }
                RPart::Group(g) => self.block(g),
                RPart::Unlabeled { body, .. } => {
                    self.facts.bad = true;
                    self.body(body);
                }
            }
        }
    }
}

/// The subtrees remembered while one initial shape is derived: their
/// shape, leaf and depth counts, by key.
#[derive(Default)]
pub(crate) struct Remembered {
    table: std::collections::HashMap<u64, Vec<Entry>>,
    entries: usize,
    /// Per rule: keys built and keys found. A rule whose shapes rarely
    /// repeat stops being looked up.
    tries: Vec<(u32, u32)>,
    /// The keys stored, in order (see [`forget_since`](Self::forget_since)).
    stored: Vec<u64>,
}

/// Remembered counts of one subtree.
pub(crate) struct Entry {
    words: Box<[u64]>,
    /// The distances of the root's trim planes from its scope origin
    /// (along their normals), and how far each could come closer before a
    /// trim of the subtree would change (+∞: no trim met it; -∞: one cut
    /// by it, so only the same distance will do).
    offsets: Box<[f64]>,
    slack: Box<[f64]>,
    pub shapes: usize,
    pub leaves: usize,
    /// Generations below the root.
    pub depth: usize,
}

/// A key built for a shape about to be derived.
pub(crate) struct Key {
    hash: u64,
    words: Vec<u64>,
    offsets: Vec<f64>,
}

/// Entries kept for one initial shape at most (a city lot with
/// thousands of different windows stops remembering, it does not grow).
const MAX_ENTRIES: usize = 1 << 12;
/// Entries with one key but trim planes at other distances.
const MAX_PER_KEY: usize = 8;
/// Geometry with more vertices is not worth a key.
const MAX_KEY_VERTICES: usize = 256;
/// A rule stops being looked up after this many keys with fewer than a
/// quarter found.
const TRIAL: u32 = 32;

impl Remembered {
    /// Whether `rule`'s shapes have repeated often enough to go on looking.
    pub fn worth_trying(&mut self, rule: u32, rules: usize) -> bool {
        if self.tries.is_empty() {
            self.tries = vec![(0, 0); rules];
        }
        let (built, found) = self.tries[rule as usize];
        built < TRIAL || found * 4 >= built
    }

    pub fn find(&mut self, key: &Key) -> Option<&Entry> {
        let (built, found) = &mut self.tries[key.words[0] as usize];
        *built += 1;
        let entry =
            self.table.get(&key.hash)?.iter().find(|e| {
                *e.words == *key.words
                    && e.offsets.iter().zip(&key.offsets).zip(&e.slack).all(
                        |((&o, &now), &slack)| {
                            // Margin for the rounding of the positions derived
                            // from a scope elsewhere.
                            slack == f64::INFINITY || now - o <= slack - (1e-6 + 1e-9 * now.abs())
                        },
                    )
            })?;
        *found += 1;
        Some(entry)
    }

    pub fn store(&mut self, key: Key, slack: Vec<f64>, shapes: usize, leaves: usize, depth: usize) {
        if self.entries >= MAX_ENTRIES {
            return;
        }
        let list = self.table.entry(key.hash).or_default();
        if list.len() >= MAX_PER_KEY {
            return;
        }
        list.push(Entry {
            words: key.words.into_boxed_slice(),
            offsets: key.offsets.into_boxed_slice(),
            slack: slack.into_boxed_slice(),
            shapes,
            leaves,
            depth,
        });
        self.entries += 1;
        self.stored.push(key.hash);
    }

    /// How many entries have been stored so far.
    pub fn mark(&self) -> usize {
        self.stored.len()
    }

    /// Drops the entries stored since `mark`: those of a copy derived to
    /// be remembered and then dropped. One of them may have given no
    /// warning only because the dropped copy had given it just before.
    pub fn forget_since(&mut self, mark: usize) {
        while self.stored.len() > mark {
            let Some(hash) = self.stored.pop() else {
                break;
            };
            if let Some(list) = self.table.get_mut(&hash) {
                list.pop();
            }
            self.entries -= 1;
        }
    }
}

impl Key {
    /// The distances of the shape's trim planes from its scope origin.
    pub fn offsets(&self) -> &[f64] {
        &self.offsets
    }
}

impl Entry {
    /// The entry's slack per trim plane for a root whose planes stand at
    /// `offsets`: how far they can still come closer.
    pub fn slack_at<'e>(&'e self, offsets: &'e [f64]) -> impl Iterator<Item = f64> + 'e {
        self.slack
            .iter()
            .zip(&self.offsets)
            .zip(offsets)
            .map(|((&s, &o), &now)| if s.is_finite() { s - (now - o) } else { s })
    }
}

/// The key of `rule` applied with `args` to `shape` (see the module docs),
/// if it can have one (array arguments, large geometry: not).
pub(crate) fn key(rule: u32, needs: Needs, args: &[Value], shape: &Shape) -> Option<Key> {
    let mut w: Vec<u64> = Vec::with_capacity(64);
    w.push(rule as u64);
    w.push(args.len() as u64);
    for a in args {
        value_words(&mut w, a)?;
    }
    let f = |w: &mut Vec<u64>, v: DVec3| w.extend(v.to_array().map(f64::to_bits));
    f(&mut w, shape.scope.size);
    f(&mut w, shape.scope.rot);
    for m in [&shape.scope.frame.axes, &shape.pivot.axes] {
        for c in m.to_cols_array() {
            w.push(c.to_bits());
        }
    }
    w.push(shape.trim.horizontal as u64 | (shape.trim.vertical as u64) << 1);
    // Which texture projections are set up (`projectUV` warns without).
    let projections = shape.projections.as_ref().map_or(0u64, |p| {
        p.iter()
            .enumerate()
            .fold(0, |m, (k, x)| m | ((x.is_some() as u64) << k))
    });
    w.push(projections);
    let mut offsets = Vec::new();
    if let Some(planes) = &shape.trim.planes {
        w.push(planes.len() as u64);
        for p in planes.iter() {
            f(&mut w, p.normal);
            f(&mut w, p.edge);
            offsets.push(p.normal.dot(p.point - shape.scope.frame.origin));
        }
    }
    if needs.center {
        f(&mut w, shape.parent_center - shape.scope.frame.origin);
    }
    if needs.split {
        w.extend([shape.split_index.to_bits(), shape.split_total.to_bits()]);
    }
    if needs.comp {
        match &shape.comp {
            Some(c) => {
                w.push(1);
                str_words(&mut w, &c.sel);
                w.extend([c.index.to_bits(), c.total.to_bits()]);
            }
            None => w.push(0),
        }
    }
    if needs.rng {
        w.extend([shape.rng.get(), shape.seedian.to_bits()]);
    }
    match &shape.attrs {
        Some(list) => {
            w.push(list.len() as u64);
            for (id, v) in list.iter() {
                w.push(*id as u64);
                value_words(&mut w, v)?;
            }
        }
        None => w.push(u64::MAX),
    }
    let (mesh, to_scope) = shape.geometry.raw();
    if mesh.positions.len() > MAX_KEY_VERTICES {
        return None;
    }
    match to_scope {
        Some(t) => {
            w.push(1);
            w.extend(t.to_cols_array().map(f64::to_bits));
        }
        None => w.push(0),
    }
    w.push(mesh.positions.len() as u64);
    for &p in &mesh.positions {
        f(&mut w, p);
    }
    w.push(mesh.corners.len() as u64);
    w.extend(mesh.corners.iter().map(|&c| c as u64));
    w.push(mesh.loops.len() as u64);
    w.extend(
        mesh.loops
            .iter()
            .map(|l| (l.start as u64) << 32 | l.len as u64),
    );
    w.push(mesh.faces.len() as u64);
    w.extend(
        mesh.faces
            .iter()
            .map(|f| (f.first_loop as u64) << 32 | f.loop_count as u64),
    );
    match &mesh.normals {
        Some(normals) => {
            w.push(normals.len() as u64);
            for &n in normals {
                f(&mut w, n);
            }
        }
        None => w.push(u64::MAX),
    }
    let hash = w.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &x| {
        (h.rotate_left(5) ^ x).wrapping_mul(0x517c_c1b7_2722_0a95)
    });
    Some(Key {
        hash,
        words: w,
        offsets,
    })
}

fn value_words(w: &mut Vec<u64>, v: &Value) -> Option<()> {
    match v {
        Value::Float(x) => w.extend([0, x.to_bits()]),
        Value::Bool(b) => w.extend([1, *b as u64]),
        Value::Str(s) => {
            w.push(2);
            str_words(w, s);
        }
        _ => return None,
    }
    Some(())
}

/// A string as its length and bytes, eight to a word.
fn str_words(w: &mut Vec<u64>, s: &str) {
    w.push(s.len() as u64);
    for chunk in s.as_bytes().chunks(8) {
        let mut b = [0u8; 8];
        b[..chunk.len()].copy_from_slice(chunk);
        w.push(u64::from_le_bytes(b));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn needs(src: &str) -> Vec<(String, Option<Needs>)> {
        let p = Program::from_text(src);
        let memo = SubtreeMemo::of(&p);
        p.rules
            .iter()
            .enumerate()
            .map(|(i, r)| (r.name.clone(), memo.rule(i as u32)))
            .collect()
    }

    fn get(list: &[(String, Option<Needs>)], name: &str) -> Option<Needs> {
        list.iter().find(|(n, _)| n == name).and_then(|(_, n)| *n)
    }

    #[test]
    fn which_subtrees_are_remembered() {
        let n = needs(
            "Tile(n) --> split(x) { 1 : Wall | ~1 : Win(n, floor(rand(0, 9))) | 1 : Wall }\n\
             Win(n, tex) --> extrude(-0.3) comp(f) { front : Glass(tex) | side : Wall }\n\
             Glass(tex) --> translateUV(0, tex / 10, 0) texture(\"g.jpg\") G.\n\
             Wall --> color(\"#ffffff\") W.\n\
             Random --> split(x) { rand(1, 2) : A. }*\n\
             Chosen(k) --> case k > 0.5 : A. else : split(x) { 1 : B. }*\n\
             CallsChosen --> split(y) { 1 : Chosen(rand) }*\n\
             Indexed --> split(x) { 1 : case split.index > 2 : A. else : B. }*\n\
             Placed --> split(x) { 1 : case scope.tx > 2 : A. else : B. }*\n\
             Reported --> split(x) { 1 : report(\"n\", 1) A. }*\n\
             Centered --> s(1, 1, 1) center(x) split(x) { 1 : A. }*\n\
             Stochastic --> 50% : split(x) { 1 : A. }* else : B.\n",
        );
        let plain = Needs::default();
        // The random tile of the texture does not matter.
        assert_eq!(get(&n, "Tile"), Some(plain));
        assert_eq!(get(&n, "Win"), Some(plain));
        // Rules creating nothing are not remembered.
        assert_eq!(get(&n, "Glass"), None);
        assert_eq!(get(&n, "Wall"), None);
        let rng = Needs { rng: true, ..plain };
        assert_eq!(get(&n, "Random"), Some(rng));
        assert_eq!(get(&n, "Chosen"), Some(plain));
        assert_eq!(get(&n, "CallsChosen"), Some(rng));
        assert_eq!(
            get(&n, "Indexed"),
            Some(Needs {
                split: true,
                ..plain
            })
        );
        assert_eq!(get(&n, "Placed"), None);
        assert_eq!(get(&n, "Reported"), None);
        assert_eq!(
            get(&n, "Centered"),
            Some(Needs {
                center: true,
                ..plain
            })
        );
        assert_eq!(get(&n, "Stochastic"), Some(rng));
    }

    #[test]
    fn programs_left_alone() {
        // An attribute whose value reads the shape.
        let n = needs("attr w = scope.sx\nA --> split(x) { w : B. }*\n");
        assert_eq!(get(&n, "A"), None);
        // Texture coordinates read.
        let n =
            needs("A --> split(x) { 1 : case geometry.du(0, unitSpace) > 1 : B. else : C. }*\n");
        assert_eq!(get(&n, "A"), None);
        // Materials by name, tags.
        let n = needs("A --> comp(m) { all : B. }\nC --> comp(f) { isTagged(\"x\") : B. }\n");
        assert_eq!(get(&n, "A"), None);
        assert_eq!(get(&n, "C"), None);
    }
}
