//! The syntax tree of one `.cga` file.
//!
//! The tree is deliberately close to the text: names are kept as written
//! (dotted names such as `scope.sx`, `imp.Lot` or `material.color.r` are one
//! [`Ident`]), and nothing is resolved here. Deciding whether `X(1)` is a rule
//! call or an operation, whether `front` is a selector or an attribute, and
//! whether a `'` size is legal where it stands is the resolver's job
//! (`cga-engine`), which has the spans to report on.
//!
//! Spans: a declaration's span runs from its keyword or name to its last
//! token (annotations have their own spans and are not included); a
//! [`Call`]'s from its name to the end of its arguments or blocks; an
//! [`Expr`]'s over the whole expression including `'`/`~` prefixes and
//! parentheses.
//!
//! Operations that take the next operation (`inline Volumes`,
//! `inline(recompose) split(x) { ... }`) are plain statements in sequence:
//! `inline` is a [`Call`] and the operation it applies to is the next
//! [`Stmt`].

use crate::span::Span;

/// A name as written, possibly dotted (`scope.sx`, `imp.Lot`, `comp.sel`).
#[derive(Clone, Debug, PartialEq)]
pub struct Ident {
    pub name: String,
    pub span: Span,
}

/// One parsed `.cga` file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Module {
    pub items: Vec<Item>,
}

/// A top-level definition. Items after a `style` item belong to that style
/// until the next `style` item (the parser keeps them flat, in file order).
#[derive(Clone, Debug, PartialEq)]
pub enum Item {
    /// `version "2023.0"`
    Version {
        value: String,
        span: Span,
        /// Annotations written before it (kept, without meaning).
        annotations: Vec<Annotation>,
    },
    Import(ImportDecl),
    Attr(AttrDecl),
    /// `const` and plain functions: `const h = 3`, `f(a) = a * 2`, `g = rand()`.
    Function(FunctionDecl),
    Rule(RuleDecl),
    /// `style Name` or `style Name extends Base`.
    Style {
        name: Ident,
        extends: Option<Ident>,
        span: Span,
        /// `@Description("...") style Night`: annotations of the style.
        annotations: Vec<Annotation>,
    },
}

/// `@Name`, `@Name(args)`; unknown annotations are kept, not rejected.
#[derive(Clone, Debug, PartialEq)]
pub struct Annotation {
    pub name: Ident,
    pub args: Vec<AnnotationArg>,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum AnnotationArg {
    /// `@Range(1, 10)`, `@Enum("a", "b")`
    Positional(Expr),
    /// `@Range(min=1, max=10)`, `@Handle(shape=Solid)`
    Named(Ident, Expr),
    /// An argument that is no CGA expression (`shape=Mass^1`,
    /// `translate={.1,0,0}` of `@Handle`), kept as written: annotations
    /// are metadata for tools, never an error.
    Verbatim {
        key: Option<Ident>,
        text: String,
        span: Span,
    },
}

/// `import id : "file.cga"` with every combination of the optional parts.
#[derive(Clone, Debug, PartialEq)]
pub struct ImportDecl {
    pub annotations: Vec<Annotation>,
    /// The prefix (`imp` in `imp.Lot`). `None` for the bare `import "file.cga"` form.
    pub alias: Option<Ident>,
    /// `import id ( style1, style2 ) : "file"`: the styles to import.
    pub styles: Option<Vec<Ident>>,
    pub path: String,
    pub path_span: Span,
    /// The parenthesised list after the path, if any (`( )` gives `Some(vec![])`).
    pub overrides: Option<Vec<ImportOverride>>,
    pub span: Span,
}

/// One entry of an import's or a dynamic import call's parenthesised list.
#[derive(Clone, Debug, PartialEq)]
pub enum ImportOverride {
    /// `height`: protect the attribute from propagation.
    Protect(Ident),
    /// `height = 20`: set the attribute.
    Attr(Ident, Expr),
    /// `Roof --> roofHip(30)` or `Roof(angle) --> roofGable(angle)`: redefine an extension rule.
    Rule {
        name: Ident,
        params: Vec<Param>,
        body: Body,
    },
}

/// `attr name = expr`, with optional `with ( ... )` locals.
#[derive(Clone, Debug, PartialEq)]
pub struct AttrDecl {
    pub annotations: Vec<Annotation>,
    pub name: Ident,
    /// `attr streetWidth(i) = ...`: attributes with parameters, which CGA
    /// allowed before 2019.1 (and still allows for `streetWidth`); the
    /// resolver decides from the file's `version`.
    pub params: Vec<Param>,
    pub locals: Vec<LocalVar>,
    pub value: Expr,
    pub span: Span,
}

/// `const c = e`, `const f(x) = e`, `f = e`, `f(x, y) = e` (the value may be a
/// `case`/stochastic chain, which is an ordinary [`ExprKind`]).
#[derive(Clone, Debug, PartialEq)]
pub struct FunctionDecl {
    pub annotations: Vec<Annotation>,
    pub is_const: bool,
    pub name: Ident,
    pub params: Vec<Param>,
    pub locals: Vec<LocalVar>,
    pub value: Expr,
    pub span: Span,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RuleKind {
    Plain,
    /// `start Name --> ...`
    Start,
    /// `extension Name --> ...`
    Extension,
}

/// `Name --> body`, `Name(a, b) --> body`, `start Name --> ...`, `extension Name --> ...`.
#[derive(Clone, Debug, PartialEq)]
pub struct RuleDecl {
    pub annotations: Vec<Annotation>,
    pub kind: RuleKind,
    pub name: Ident,
    pub params: Vec<Param>,
    pub locals: Vec<LocalVar>,
    pub body: Body,
    pub span: Span,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TypeName {
    Float,
    Bool,
    String,
    FloatArray,
    BoolArray,
    StringArray,
}

/// A rule or function parameter, optionally typed (`float x`, `string[] names`).
#[derive(Clone, Debug, PartialEq)]
pub struct Param {
    pub ty: Option<TypeName>,
    pub name: Ident,
}

/// `x := expr` inside `with ( ... )`.
#[derive(Clone, Debug, PartialEq)]
pub struct LocalVar {
    pub name: Ident,
    pub value: Expr,
}

/// What a rule (or a split/comp part, a push block, a case branch) does.
///
/// Conditional and stochastic chains stand at the start of a body ("must not
/// have preceding operations"); each branch is a body of its own.
#[derive(Clone, Debug, PartialEq)]
pub enum Body {
    Ops(Vec<Stmt>),
    Case(CaseChain<Body>),
    Stochastic(StochasticChain<Body>),
}

/// `case c1 : a  case c2 : b  else : c`
#[derive(Clone, Debug, PartialEq)]
pub struct CaseChain<T> {
    pub branches: Vec<(Expr, T)>,
    pub otherwise: Option<Box<T>>,
    pub span: Span,
}

/// `30% : a  20% : b  else : c`; the percentage expression is kept as written
/// (`30` for `30%`).
#[derive(Clone, Debug, PartialEq)]
pub struct StochasticChain<T> {
    pub branches: Vec<(Expr, T)>,
    pub otherwise: Option<Box<T>>,
    pub span: Span,
}

/// One element of an operation sequence.
#[derive(Clone, Debug, PartialEq)]
pub enum Stmt {
    /// An operation or a rule invocation: `extrude(10)`, `reverseNormals`,
    /// `Window`, `Tile(2)`, `imp.Lot`, `split(x) { ... }*`, `comp(f) { ... }`.
    Call(Call),
    /// `Name.`: a leaf shape named `Name`.
    Leaf(Ident),
    /// `NIL`
    Nil(Span),
    /// `[ body ]`: push a copy of the current shape, run body on it, pop.
    Push(Body, Span),
}

#[derive(Clone, Debug, PartialEq)]
pub struct Call {
    pub name: Ident,
    /// `imp(height = 20).Lot`: the dynamic import overrides (name is then
    /// `imp.Lot`, spanning `imp( ... ).Lot`); `imp().Lot` gives `Some(vec![])`.
    /// Arguments may follow: `imp(h = 1).Lot(2)`.
    pub import_overrides: Option<Vec<ImportOverride>>,
    /// `None` when written without parentheses (`reverseNormals`, `Window`).
    pub args: Option<Vec<Expr>>,
    /// The `{ ... }` after `split(..)`, `comp(..)`, `splitArea(..)`, ...
    pub block: Option<Block<Body>>,
    /// A second block right after the first: only
    /// `splitAndSetbackPerimeter(..) { 2 : 4 : X }* { remainder : Y }` has one.
    pub remainder_block: Option<Block<Body>>,
    pub span: Span,
}

/// `{ head op body | head op body | { ... }* | ... }` with an optional `*`.
///
/// Used with `T = Body` after operations (split, comp, ...) and with `T = Expr`
/// for the comp function (`comp(e) { all : scope.sx }`).
#[derive(Clone, Debug, PartialEq)]
pub struct Block<T> {
    pub parts: Vec<BlockPart<T>>,
    /// `}*`
    pub repeat: bool,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum BlockPart<T> {
    Entry(BlockEntry<T>),
    /// A nested `{ ... }` or `{ ... }*` group (split patterns).
    Group(Block<T>),
    /// A part without head: the operands of `union { A | B }` and
    /// `subtract { Mass. | t(1,0,0) Hole }`, the body of
    /// `scatter(surface, 10, uniform) { Leaf }` or `inline { A B }`.
    /// Only blocks after operations have these (never the comp function).
    Unlabeled {
        body: T,
        span: Span,
    },
}

#[derive(Clone, Debug, PartialEq)]
pub struct BlockEntry<T> {
    /// A split size (`3`, `'0.5`, `~1`) or a comp selector (`front`, `0`,
    /// `isTagged("x")`, `top && !side`): an expression either way.
    pub head: Expr,
    /// The setback depth of a `splitAndSetbackPerimeter` entry
    /// (`length : depth : operations`); `None` everywhere else.
    pub depth: Option<Expr>,
    pub op: BlockOp,
    pub body: T,
    pub span: Span,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlockOp {
    /// `:` one shape per component / the split part
    Colon,
    /// `=` one shape for all selected components
    Equals,
    /// `=:` one shape per connected set of selected components
    EqualsColon,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    pub kind: ExprKind,
    pub span: Span,
}

#[derive(Clone, Debug, PartialEq)]
pub enum ExprKind {
    Float(f64),
    Bool(bool),
    Str(String),
    /// A name: attribute, const, parameter, local, zero-argument function,
    /// shape attribute (`scope.sx`), or a selector keyword (`x`, `front`, `world.up`).
    /// An empty name stands for an expression missing after a syntax error
    /// (such a module comes with an error diagnostic and is never evaluated).
    Name(Ident),
    /// `f(a, b)`, `geometry.area()`, `imp.f(1)`.
    Call {
        name: Ident,
        args: Vec<Expr>,
    },
    /// The comp function: `comp(e) { all : scope.sx }`.
    CompFn {
        args: Vec<Expr>,
        block: Block<Expr>,
    },
    /// `-a`, `!a`; `elementwise` for the dotted array forms `.-a`, `.!a`.
    Unary {
        op: UnaryOp,
        elementwise: bool,
        operand: Box<Expr>,
    },
    /// `a + b`; `elementwise` for the dotted array forms `a .+ b`, `a .== b`, ...
    Binary {
        op: BinaryOp,
        elementwise: bool,
        lhs: Box<Expr>,
        rhs: Box<Expr>,
    },
    /// `[a, b; c, d]`: rows separated by `;`, elements by `,`.
    Array(Vec<Vec<Expr>>),
    /// `base : limit` or `base : step : limit` (inside `[ ]` only).
    Range {
        base: Box<Expr>,
        step: Option<Box<Expr>>,
        limit: Box<Expr>,
    },
    /// `a[i]`, `a[i, j]`.
    Index {
        base: Box<Expr>,
        indices: Vec<Expr>,
    },
    Case(CaseChain<Expr>),
    Stochastic(StochasticChain<Expr>),
    /// `'e`: a size relative to the scope (or the area for splitArea).
    Relative(Box<Expr>),
    /// `~e`: a floating size.
    Floating(Box<Expr>),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnaryOp {
    Neg,
    Plus,
    Not,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BinaryOp {
    Add,
    Sub,
    Mul,
    Div,
    Rem,
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
    And,
    Or,
}
