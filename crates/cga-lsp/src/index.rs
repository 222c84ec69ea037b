//! What one rule file defines and uses, with byte spans: the base of
//! navigation, hover, symbols and highlighting. Built from the engine's
//! error-tolerant syntax tree, so a file with errors is indexed as far as
//! it parses.

use std::ops::Range;

use cga::syntax::{ast, parse, FileId};

use crate::text::LineIndex;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DefKind {
    Rule,
    Attr,
    Function,
    Const,
    Import,
    Style,
    Param,
    Local,
}

impl DefKind {
    pub fn word(self) -> &'static str {
        match self {
            DefKind::Rule => "rule",
            DefKind::Attr => "attribute",
            DefKind::Function => "function",
            DefKind::Const => "const",
            DefKind::Import => "import",
            DefKind::Style => "style",
            DefKind::Param => "parameter",
            DefKind::Local => "local",
        }
    }
}

/// A name the file defines.
#[derive(Clone, Debug)]
pub struct Def {
    pub kind: DefKind,
    pub name: String,
    pub name_span: Range<usize>,
    /// The whole declaration, annotations included.
    pub span: Range<usize>,
    pub params: Vec<String>,
    /// `@Group("Name", ...)`'s name.
    pub group: Option<String>,
    /// The comment lines just above the declaration, without markers.
    pub doc: Option<String>,
    /// Parameters and locals: the declaration (index into `defs`) they
    /// belong to.
    pub owner: Option<usize>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RefKind {
    /// A name in operation position: a rule invocation or an operation.
    Stmt,
    /// A name read in an expression: attribute, const, parameter, ...
    Value,
    /// A function call in an expression.
    Call,
    /// `Name.`: a leaf shape's name.
    Leaf,
}

/// A name the file uses, as written (`imp.Facade` is one name).
#[derive(Clone, Debug)]
pub struct Ref {
    pub name: String,
    pub span: Range<usize>,
    pub kind: RefKind,
    /// The top-level declaration it stands in.
    pub owner: Option<usize>,
}

impl Ref {
    /// The span of the last part of the name (`Facade` of `imp.Facade`),
    /// the part a rename of the definition replaces.
    pub fn last_span(&self) -> Range<usize> {
        let last = self.name.rsplit('.').next().unwrap_or(&self.name);
        self.span
            .end
            .saturating_sub(last.len())
            .max(self.span.start)..self.span.end
    }

    /// `("imp", "Facade")` for `imp.Facade`.
    pub fn split_prefix(&self) -> Option<(&str, &str)> {
        self.name.split_once('.')
    }
}

#[derive(Clone, Debug)]
pub struct Import {
    pub alias: Option<String>,
    pub path: String,
    /// The path's string literal, quotes included.
    pub path_span: Range<usize>,
    /// Its definition in `defs`.
    pub def: usize,
}

/// Everything known of one file.
pub struct FileIndex {
    pub text: String,
    pub lines: LineIndex,
    pub defs: Vec<Def>,
    pub refs: Vec<Ref>,
    pub imports: Vec<Import>,
    /// Spans worth folding: declarations, blocks.
    pub folds: Vec<Range<usize>>,
    /// Top-level definitions by name (indices into `defs`), so that
    /// resolving every name of a large file stays linear.
    by_name: std::collections::HashMap<String, Vec<usize>>,
}

impl FileIndex {
    pub fn new(text: String) -> FileIndex {
        // The parser's errors are the engine's diagnostics' business.
        let (module, _errors) = parse(FileId(0), &text);
        let mut index = FileIndex {
            lines: LineIndex::new(&text),
            defs: Vec::new(),
            refs: Vec::new(),
            imports: Vec::new(),
            folds: Vec::new(),
            by_name: Default::default(),
            text,
        };
        for item in &module.items {
            index.item(item);
        }
        for (i, d) in index.defs.iter().enumerate() {
            if d.owner.is_none() {
                index.by_name.entry(d.name.clone()).or_default().push(i);
            }
        }
        index
    }

    /// The top-level definitions called `name` (parameters and locals
    /// excluded).
    pub fn top_level<'a>(&'a self, name: &'a str) -> impl Iterator<Item = (usize, &'a Def)> + 'a {
        self.by_name
            .get(name)
            .into_iter()
            .flatten()
            .map(|&i| (i, &self.defs[i]))
    }

    /// The definition a reference made in this file names, if it is in
    /// this file: a parameter or local of the declaration it stands in,
    /// else a top-level definition of a kind that fits its position.
    pub fn resolve_local(&self, r: &Ref) -> Option<usize> {
        if r.kind == RefKind::Leaf {
            return None;
        }
        if let Some(owner) = r.owner {
            // A declaration's parameters and locals follow it in `defs`.
            let found = self.defs[owner + 1..]
                .iter()
                .take_while(|d| d.owner == Some(owner))
                .position(|d| d.name == r.name);
            if let Some(i) = found {
                return Some(owner + 1 + i);
            }
        }
        let fits = |d: &Def| match r.kind {
            RefKind::Stmt => d.kind == DefKind::Rule,
            RefKind::Call => matches!(d.kind, DefKind::Function | DefKind::Const | DefKind::Attr),
            RefKind::Value => matches!(d.kind, DefKind::Attr | DefKind::Const | DefKind::Function),
            RefKind::Leaf => false,
        };
        let found = self.top_level(&r.name).find(|(_, d)| fits(d));
        found.map(|(i, _)| i)
    }

    /// The import whose alias is `alias`.
    pub fn import_named(&self, alias: &str) -> Option<&Import> {
        self.imports
            .iter()
            .find(|i| i.alias.as_deref() == Some(alias))
    }

    /// The innermost reference or definition name at byte `offset`
    /// (touching its end counts, for a cursor just after a name).
    pub fn at(&self, offset: usize) -> Option<Hit> {
        let inside = |s: &Range<usize>| s.start <= offset && offset <= s.end && s.start < s.end;
        if let Some(i) = self.defs.iter().position(|d| inside(&d.name_span)) {
            return Some(Hit::Def(i));
        }
        self.refs
            .iter()
            .enumerate()
            .filter(|(_, r)| inside(&r.span))
            .min_by_key(|(_, r)| r.span.len())
            .map(|(i, _)| Hit::Ref(i))
    }

    fn item(&mut self, item: &ast::Item) {
        match item {
            ast::Item::Version { .. } => {}
            ast::Item::Import(import) => {
                let name = import
                    .alias
                    .as_ref()
                    .map(|a| (a.name.clone(), a.span.range()));
                let stem = std::path::Path::new(&import.path)
                    .file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default();
                let (name, name_span) = name.unwrap_or((stem, import.path_span.range()));
                let def = self.def(
                    DefKind::Import,
                    name,
                    name_span,
                    import.span,
                    &import.annotations,
                    &[],
                );
                self.imports.push(Import {
                    alias: import.alias.as_ref().map(|a| a.name.clone()),
                    path: import.path.clone(),
                    path_span: import.path_span.range(),
                    def,
                });
                for o in import.overrides.iter().flatten() {
                    self.import_override(o, import.alias.as_ref().map(|a| a.name.as_str()), def);
                }
            }
            ast::Item::Attr(a) => {
                let def = self.def(
                    DefKind::Attr,
                    a.name.name.clone(),
                    a.name.span.range(),
                    a.span,
                    &a.annotations,
                    &a.params,
                );
                self.locals(def, &a.params, &a.locals);
                self.expr(&a.value, Some(def));
            }
            ast::Item::Function(f) => {
                let kind = if f.is_const {
                    DefKind::Const
                } else {
                    DefKind::Function
                };
                let def = self.def(
                    kind,
                    f.name.name.clone(),
                    f.name.span.range(),
                    f.span,
                    &f.annotations,
                    &f.params,
                );
                self.locals(def, &f.params, &f.locals);
                self.expr(&f.value, Some(def));
            }
            ast::Item::Rule(r) => {
                let def = self.def(
                    DefKind::Rule,
                    r.name.name.clone(),
                    r.name.span.range(),
                    r.span,
                    &r.annotations,
                    &r.params,
                );
                self.locals(def, &r.params, &r.locals);
                self.body(&r.body, Some(def));
            }
            ast::Item::Style {
                name,
                span,
                annotations,
                ..
            } => {
                self.def(
                    DefKind::Style,
                    name.name.clone(),
                    name.span.range(),
                    *span,
                    annotations,
                    &[],
                );
            }
        }
    }

    fn def(
        &mut self,
        kind: DefKind,
        name: String,
        name_span: Range<usize>,
        span: cga::syntax::Span,
        annotations: &[ast::Annotation],
        params: &[ast::Param],
    ) -> usize {
        let start = annotations
            .iter()
            .map(|a| a.span.start as usize)
            .min()
            .unwrap_or(span.start as usize)
            .min(span.start as usize);
        let span = self.clamp(start..(span.end as usize).max(start));
        let name_span = self.clamp(name_span);
        if self.lines.position(&self.text, span.start).line
            != self.lines.position(&self.text, span.end).line
        {
            self.folds.push(span.clone());
        }
        let group = annotations
            .iter()
            .find(|a| a.name.name == "Group")
            .and_then(|a| a.args.first())
            .and_then(|arg| match arg {
                ast::AnnotationArg::Positional(e) | ast::AnnotationArg::Named(_, e) => {
                    match &e.kind {
                        ast::ExprKind::Str(s) => Some(s.clone()),
                        _ => None,
                    }
                }
                ast::AnnotationArg::Verbatim { .. } => None,
            });
        self.defs.push(Def {
            kind,
            name,
            name_span,
            doc: cga::syntax::doc_comment(&self.text, span.start),
            span,
            params: params.iter().map(|p| p.name.name.clone()).collect(),
            group,
            owner: None,
        });
        self.defs.len() - 1
    }

    fn locals(&mut self, owner: usize, params: &[ast::Param], locals: &[ast::LocalVar]) {
        for p in params {
            self.defs.push(Def {
                kind: DefKind::Param,
                name: p.name.name.clone(),
                name_span: self.clamp(p.name.span.range()),
                span: self.clamp(p.name.span.range()),
                params: Vec::new(),
                group: None,
                doc: None,
                owner: Some(owner),
            });
        }
        for l in locals {
            self.defs.push(Def {
                kind: DefKind::Local,
                name: l.name.name.clone(),
                name_span: self.clamp(l.name.span.range()),
                span: self.clamp(l.name.span.to(l.value.span).range()),
                params: Vec::new(),
                group: None,
                doc: None,
                owner: Some(owner),
            });
            self.expr(&l.value, Some(owner));
        }
    }

    fn import_override(&mut self, o: &ast::ImportOverride, alias: Option<&str>, owner: usize) {
        let qualified = |name: &str| match alias {
            Some(a) => format!("{a}.{name}"),
            None => name.to_string(),
        };
        match o {
            ast::ImportOverride::Protect(id) => self.reference(
                qualified(&id.name),
                id.span.range(),
                RefKind::Value,
                Some(owner),
            ),
            ast::ImportOverride::Attr(id, e) => {
                self.reference(
                    qualified(&id.name),
                    id.span.range(),
                    RefKind::Value,
                    Some(owner),
                );
                self.expr(e, Some(owner));
            }
            ast::ImportOverride::Rule { name, body, .. } => {
                self.reference(
                    qualified(&name.name),
                    name.span.range(),
                    RefKind::Stmt,
                    Some(owner),
                );
                self.body(body, Some(owner));
            }
        }
    }

    /// `span` within the text: a placeholder the parser made at the end of
    /// a cut text may reach past it.
    fn clamp(&self, span: Range<usize>) -> Range<usize> {
        let end = span.end.min(self.text.len());
        span.start.min(end)..end
    }

    fn reference(&mut self, name: String, span: Range<usize>, kind: RefKind, owner: Option<usize>) {
        let span = self.clamp(span);
        if name.is_empty() || span.is_empty() {
            return;
        }
        self.refs.push(Ref {
            name,
            span,
            kind,
            owner,
        });
    }

    fn body(&mut self, body: &ast::Body, owner: Option<usize>) {
        match body {
            ast::Body::Ops(stmts) => {
                for s in stmts {
                    self.stmt(s, owner);
                }
            }
            ast::Body::Case(chain) => {
                for (cond, b) in &chain.branches {
                    self.expr(cond, owner);
                    self.body(b, owner);
                }
                if let Some(b) = &chain.otherwise {
                    self.body(b, owner);
                }
            }
            ast::Body::Stochastic(chain) => {
                for (p, b) in &chain.branches {
                    self.expr(p, owner);
                    self.body(b, owner);
                }
                if let Some(b) = &chain.otherwise {
                    self.body(b, owner);
                }
            }
        }
    }

    fn stmt(&mut self, stmt: &ast::Stmt, owner: Option<usize>) {
        match stmt {
            ast::Stmt::Call(call) => {
                // `imp(h = 1).Lot`: the name's span covers the overrides;
                // keep the name as written without them.
                self.reference(
                    call.name.name.clone(),
                    call.name.span.range(),
                    RefKind::Stmt,
                    owner,
                );
                let alias = call.name.name.split_once('.').map(|(a, _)| a.to_string());
                for o in call.import_overrides.iter().flatten() {
                    if let Some(import) = owner {
                        self.import_override(o, alias.as_deref(), import);
                    }
                }
                for a in call.args.iter().flatten() {
                    self.expr(a, owner);
                }
                for block in [&call.block, &call.remainder_block].into_iter().flatten() {
                    self.block(block, owner);
                }
            }
            ast::Stmt::Leaf(id) => {
                self.reference(id.name.clone(), id.span.range(), RefKind::Leaf, owner)
            }
            ast::Stmt::Nil(_) => {}
            ast::Stmt::Push(body, _) => self.body(body, owner),
        }
    }

    fn block(&mut self, block: &ast::Block<ast::Body>, owner: Option<usize>) {
        self.fold(block.span.range());
        for part in &block.parts {
            match part {
                ast::BlockPart::Entry(e) => {
                    self.expr(&e.head, owner);
                    if let Some(d) = &e.depth {
                        self.expr(d, owner);
                    }
                    self.body(&e.body, owner);
                }
                ast::BlockPart::Group(b) => self.block(b, owner),
                ast::BlockPart::Unlabeled { body, .. } => self.body(body, owner),
            }
        }
    }

    fn fold(&mut self, span: Range<usize>) {
        if self.lines.position(&self.text, span.start).line
            != self.lines.position(&self.text, span.end).line
        {
            self.folds.push(span);
        }
    }

    fn expr(&mut self, e: &ast::Expr, owner: Option<usize>) {
        use ast::ExprKind as K;
        match &e.kind {
            K::Float(_) | K::Bool(_) | K::Str(_) => {}
            K::Name(id) => self.reference(id.name.clone(), id.span.range(), RefKind::Value, owner),
            K::Call { name, args } => {
                self.reference(name.name.clone(), name.span.range(), RefKind::Call, owner);
                for a in args {
                    self.expr(a, owner);
                }
            }
            K::CompFn { args, block } => {
                for a in args {
                    self.expr(a, owner);
                }
                self.expr_block(block, owner);
            }
            K::Unary { operand, .. } => self.expr(operand, owner),
            K::Binary { lhs, rhs, .. } => {
                self.expr(lhs, owner);
                self.expr(rhs, owner);
            }
            K::Array(rows) => {
                for e in rows.iter().flatten() {
                    self.expr(e, owner);
                }
            }
            K::Range { base, step, limit } => {
                self.expr(base, owner);
                if let Some(s) = step {
                    self.expr(s, owner);
                }
                self.expr(limit, owner);
            }
            K::Index { base, indices } => {
                self.expr(base, owner);
                for i in indices {
                    self.expr(i, owner);
                }
            }
            K::Case(chain) => {
                for (c, v) in &chain.branches {
                    self.expr(c, owner);
                    self.expr(v, owner);
                }
                if let Some(v) = &chain.otherwise {
                    self.expr(v, owner);
                }
            }
            K::Stochastic(chain) => {
                for (c, v) in &chain.branches {
                    self.expr(c, owner);
                    self.expr(v, owner);
                }
                if let Some(v) = &chain.otherwise {
                    self.expr(v, owner);
                }
            }
            K::Relative(inner) | K::Floating(inner) => self.expr(inner, owner),
        }
    }

    fn expr_block(&mut self, block: &ast::Block<ast::Expr>, owner: Option<usize>) {
        for part in &block.parts {
            match part {
                ast::BlockPart::Entry(e) => {
                    self.expr(&e.head, owner);
                    self.expr(&e.body, owner);
                }
                ast::BlockPart::Group(b) => self.expr_block(b, owner),
                ast::BlockPart::Unlabeled { body, .. } => self.expr(body, owner),
            }
        }
    }
}

/// A name under the cursor.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Hit {
    Def(usize),
    Ref(usize),
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "import f : \"facade.cga\" (height = 3)

// The building's height.
@Range(min=3, max=60) @Group(\"Massing\")
attr height = 10
const k = 2
twice(x) = x * k

@StartRule
Lot(h) --> extrude(h) comp(f) { side : f.Facade | top : Roof. }
";

    #[test]
    fn definitions_references_and_comments() {
        let index = FileIndex::new(TEXT.to_string());
        let names: Vec<(DefKind, &str)> = index
            .defs
            .iter()
            .map(|d| (d.kind, d.name.as_str()))
            .collect();
        assert_eq!(
            names,
            [
                (DefKind::Import, "f"),
                (DefKind::Attr, "height"),
                (DefKind::Const, "k"),
                (DefKind::Function, "twice"),
                (DefKind::Param, "x"),
                (DefKind::Rule, "Lot"),
                (DefKind::Param, "h"),
            ]
        );
        let height = &index.defs[1];
        assert_eq!(height.doc.as_deref(), Some("The building's height."));
        assert_eq!(height.group.as_deref(), Some("Massing"));
        assert_eq!(
            &TEXT[height.span.clone()].lines().next(),
            &Some("@Range(min=3, max=60) @Group(\"Massing\")")
        );

        // `x` in `twice` is its parameter; `k` the const.
        let x = index.refs.iter().find(|r| r.name == "x").unwrap();
        assert_eq!(index.resolve_local(x), Some(4));
        let k = index.refs.iter().find(|r| r.name == "k").unwrap();
        assert_eq!(index.resolve_local(k), Some(2));
        // The import override names the imported file's attribute.
        let over = index.refs.iter().find(|r| r.name == "f.height").unwrap();
        assert_eq!(&TEXT[over.span.clone()], "height");
        let facade = index.refs.iter().find(|r| r.name == "f.Facade").unwrap();
        assert_eq!(&TEXT[facade.last_span()], "Facade");
        assert_eq!(index.import_named("f").unwrap().path, "facade.cga");
        let at = TEXT.find("Facade").unwrap() + 2;
        assert!(matches!(index.at(at), Some(Hit::Ref(i)) if index.refs[i].name == "f.Facade"));
    }

    #[test]
    fn a_broken_file_still_has_its_definitions() {
        let index = FileIndex::new("attr a = 1\nLot --> extrude(a\nB --> X.\n".to_string());
        assert!(!parse(FileId(0), &index.text).1.is_empty());
        assert!(index.top_level("a").next().is_some());
        assert!(index.top_level("Lot").next().is_some());
    }
}
