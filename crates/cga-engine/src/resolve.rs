//! Loading and resolving rule files: parse the main file and its imports,
//! give every attribute, function and rule an index, and turn the syntax
//! trees into resolved bodies and expressions (`expr.rs`).
//!
//! Imports: each `import` statement instantiates the imported file as a rule
//! set of its own. An attribute of an imported file takes the value of the
//! importing file's attribute of the same name (propagation) unless it is
//! protected (`import x : "f.cga" (height)` or `( )`) or set explicitly
//! (`( height = 20 )`, evaluated in the importing file). Extension rules can
//! be redefined by the importer (`( Roof --> roofHip(30) )`).

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use cga_syntax::ast::{self, BlockPart, Body, Expr, ExprKind, Item, Stmt};
use cga_syntax::{Diagnostic, SourceMap, Span};
use cga_value::Value;
use cga_world::World;

use crate::expr::{OpCall, RBlock, RBody, RExpr, RExprKind, RPart, RStmt, RuleCall};
use crate::locate::Workspaces;
use crate::ops::{self, ArgMode, Op, SetTarget};
use crate::program::{
    AnnotationInfo, AttrDef, AttrId, FuncId, FunctionDef, Program, RuleDef, RuleId, RuleSet,
    RuleSetId,
};
use crate::shape_fns;
use crate::values;

/// The result of loading a rule file: the program and every diagnostic
/// found. A file with errors still gives a program of everything that
/// could be resolved (rules, attributes, functions with their spans; what
/// did not resolve is a placeholder), for tools that read it; only a
/// program without errors may be derived ([`Loaded::usable`]).
pub struct Loaded {
    pub program: Program,
    pub diagnostics: Vec<Diagnostic>,
}

impl Loaded {
    /// Whether a diagnostic is an error.
    pub fn has_errors(&self) -> bool {
        self.diagnostics.iter().any(Diagnostic::is_error)
    }

    /// The program, if it has no errors.
    pub fn usable(self) -> Option<Program> {
        (!self.has_errors()).then_some(self.program)
    }
}

/// How rule files are loaded besides the file itself.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct LoadOptions {
    /// Where workspace paths (`/Project/...`) are looked for after the
    /// rule file's own workspace.
    pub workspaces: Workspaces,
    /// The style of the main rule file to load (`style Modern`); `None` or
    /// `Default` loads the default style. A name the file does not define
    /// is an error naming the styles it does.
    pub style: Option<String>,
}

/// Loads `path` and everything it imports from `world` into `sources`,
/// parses and resolves.
pub fn load(world: &dyn World, path: &Path, sources: &mut SourceMap) -> Loaded {
    load_with(world, path, sources, &LoadOptions::default())
}

/// Like [`load`], with workspace roots for imports that name a project
/// (`/Project/...`, see `locate.rs`).
pub fn load_with(
    world: &dyn World,
    path: &Path,
    sources: &mut SourceMap,
    options: &LoadOptions,
) -> Loaded {
    match world.read_text(path) {
        Ok(text) => load_text_with(world, path, text, sources, options),
        Err(e) => Loaded {
            program: Program::default(),
            diagnostics: vec![plain_error(format!(
                "cannot read rule file {}: {e}",
                path.display()
            ))],
        },
    }
}

/// Like [`load`] for rule text already in memory; `path` names it in
/// diagnostics and is where its imports are searched from.
pub fn load_text(world: &dyn World, path: &Path, text: String, sources: &mut SourceMap) -> Loaded {
    load_text_with(world, path, text, sources, &LoadOptions::default())
}

/// [`load_text`] with workspace roots.
pub fn load_text_with(
    world: &dyn World,
    path: &Path,
    text: String,
    sources: &mut SourceMap,
    options: &LoadOptions,
) -> Loaded {
    let mut r = Resolver {
        world,
        sources,
        workspaces: options.workspaces.clone(),
        program: Program::default(),
        diags: Vec::new(),
        tables: Vec::new(),
        parsed: HashMap::new(),
        parsed_files: Vec::new(),
        stack: Vec::new(),
        pending: Vec::new(),
        symbols: HashMap::new(),
        type_checks: Vec::new(),
    };
    let main = r.parse_file(path, text);
    r.program.styles = module_styles(&r.parsed_files[main].module);
    let style = match options.style.as_deref() {
        Some(s) if !r.program.styles.iter().any(|d| d == s) => {
            r.diags.push(plain_error(format!(
                "unknown style `{s}`: {} defines the styles {}",
                path.display(),
                r.program.styles.join(", ")
            )));
            None
        }
        other => other,
    };
    r.instantiate(main, String::new(), None, style);
    r.resolve_pending();
    r.check_types();
    if let Some(t) = r.tables.first() {
        let mut attrs: Vec<_> = t.attrs.iter().map(|(n, &id)| (n.clone(), id)).collect();
        attrs.sort();
        r.program.main_attrs = attrs;
        let mut rules: Vec<_> = t
            .rules
            .iter()
            .flat_map(|(n, ids)| ids.iter().map(move |&id| (n.clone(), id)))
            .collect();
        rules.sort_by_key(|&(_, id)| id);
        r.program.main_rules = rules;
    }
    // Report in file order, whatever stage found them.
    r.diags
        .sort_by_key(|d| d.span.map(|s| (s.file.0, s.start)).unwrap_or((0, 0)));
    let mut program = r.program;
    program.symbols = {
        let mut v = vec![Arc::<str>::from(""); r.symbols.len()];
        for (name, id) in r.symbols {
            v[id as usize] = name;
        }
        v
    };
    Loaded {
        program,
        diagnostics: r.diags,
    }
}

fn plain_error(message: String) -> Diagnostic {
    Diagnostic {
        severity: cga_syntax::Severity::Error,
        message,
        span: None,
        label: None,
        notes: Vec::new(),
    }
}

struct ParsedFile {
    path: PathBuf,
    module: Arc<ast::Module>,
}

/// Names visible in one rule set.
#[derive(Default)]
struct Tables {
    attrs: HashMap<String, AttrId>,
    funcs: HashMap<String, Vec<FuncId>>,
    rules: HashMap<String, Vec<RuleId>>,
    imports: HashMap<String, RuleSetId>,
    start_rule: Option<RuleId>,
}

/// Work left for after every rule set is declared (bodies may reference
/// rules of any rule set).
enum Pending {
    Attr {
        id: AttrId,
        ruleset: RuleSetId,
        decl: ast::AttrDecl,
    },
    /// An attribute value set by an importer, resolved in the importer.
    AttrOverride {
        id: AttrId,
        importer: RuleSetId,
        expr: Expr,
    },
    Function {
        id: FuncId,
        ruleset: RuleSetId,
        decl: ast::FunctionDecl,
    },
    Rule {
        id: RuleId,
        ruleset: RuleSetId,
        params: Vec<ast::Param>,
        locals: Vec<ast::LocalVar>,
        body: Body,
    },
}

struct Resolver<'s> {
    world: &'s dyn World,
    sources: &'s mut SourceMap,
    workspaces: Workspaces,
    program: Program,
    diags: Vec<Diagnostic>,
    tables: Vec<Tables>,
    parsed: HashMap<PathBuf, usize>,
    parsed_files: Vec<ParsedFile>,
    /// Files being instantiated (import cycle detection).
    stack: Vec<PathBuf>,
    pending: Vec<Pending>,
    symbols: HashMap<Arc<str>, u32>,
    /// Binary operations whose operand types may be known before deriving
    /// (constants, attributes): checked once every attribute is resolved.
    type_checks: Vec<(ast::BinaryOp, RExpr, RExpr, Span)>,
}

/// The styles a module defines: `Default`, then each `style NAME` in order.
fn module_styles(module: &ast::Module) -> Vec<String> {
    std::iter::once("Default".to_string())
        .chain(module.items.iter().filter_map(|i| match i {
            Item::Style { name, .. } if name.name != "Default" => Some(name.name.clone()),
            _ => None,
        }))
        .collect()
}

/// The items of a module as one style sees them: the items of the Default
/// style (before the first `style` statement, or after `style Default`),
/// with the attributes, functions and rules that `style` (and the styles it
/// extends) redefines replaced by its versions, and its new ones added.
fn style_items<'m>(module: &'m ast::Module, style: Option<&str>) -> Vec<&'m Item> {
    // Sections: (style name, extends, items).
    let mut sections: Vec<(&str, Option<&str>, Vec<&Item>)> = vec![("Default", None, Vec::new())];
    for item in &module.items {
        match item {
            Item::Style { name, extends, .. } => sections.push((
                name.name.as_str(),
                Some(extends.as_ref().map_or("Default", |e| e.name.as_str())),
                Vec::new(),
            )),
            Item::Import(_) | Item::Version { .. } => sections[0].2.push(item),
            _ => sections
                .last_mut()
                .expect("the Default section")
                .2
                .push(item),
        }
    }
    let mut items: Vec<&Item> = sections
        .iter()
        .filter(|s| s.0 == "Default")
        .flat_map(|s| s.2.iter().copied())
        .collect();
    // The chain of styles from the most basic to the chosen one.
    let mut chain = Vec::new();
    let mut current = style.filter(|s| *s != "Default");
    while let Some(name) = current {
        if chain.contains(&name) || chain.len() > 32 {
            break;
        }
        let Some(section) = sections.iter().find(|s| s.0 == name) else {
            break;
        };
        chain.push(name);
        current = section.1.filter(|s| *s != "Default");
    }
    for name in chain.into_iter().rev() {
        for section in sections.iter().filter(|s| s.0 == name) {
            for &item in &section.2 {
                match items.iter().position(|&i| same_definition(i, item)) {
                    Some(k) => items[k] = item,
                    None => items.push(item),
                }
            }
        }
    }
    items
}

/// The candidate closest to `name` by edit distance, if close enough to be a
/// likely typo (1 edit for short names, up to 3 for long ones).
fn closest<'a>(name: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<String> {
    let len = name.chars().count();
    let allowed = match len {
        0..=3 => 1,
        4..=6 => 2,
        _ => 3,
    };
    candidates
        .into_iter()
        // The edit distance is at least the difference in length: skip the
        // candidates that cannot be close before computing it.
        .filter(|c| c.chars().count().abs_diff(len) <= allowed)
        .map(|c| (strsim::damerau_levenshtein(name, c), c))
        .filter(|&(d, c)| d <= allowed && d < c.len())
        .min()
        .map(|(_, c)| c.to_string())
}

/// Whether the type of `e` may be known before deriving: a constant, an
/// attribute, or operators over them.
fn type_checkable(e: &RExpr) -> bool {
    match &e.kind {
        RExprKind::Const(_) | RExprKind::Attr(_) => true,
        RExprKind::Unary { operand, .. } => type_checkable(operand),
        RExprKind::Binary { lhs, rhs, .. } => type_checkable(lhs) && type_checkable(rhs),
        _ => false,
    }
}

/// A value of the scalar type `e` certainly has (`0`, `false` or `""`):
/// constants, attributes whose default has a known type (an attribute keeps
/// its type whatever it is set to), and operators over them. `None` when
/// the type is not known or is an array.
fn static_scalar(program: &Program, e: &RExpr, depth: usize) -> Option<Value> {
    if depth > 16 {
        return None;
    }
    let scalar = |v: &Value| match v {
        Value::Float(_) => Some(Value::Float(1.0)),
        Value::Bool(_) => Some(Value::Bool(false)),
        Value::Str(_) => Some(Value::Str(Arc::from(""))),
        _ => None,
    };
    match &e.kind {
        RExprKind::Const(v) => scalar(v),
        RExprKind::Attr(id) => {
            static_scalar(program, &program.attrs[*id as usize].default, depth + 1)
        }
        RExprKind::Unary {
            op,
            elementwise: false,
            operand,
        } => {
            let v = static_scalar(program, operand, depth + 1)?;
            values::unary(*op, false, &v).ok().as_ref().and_then(scalar)
        }
        RExprKind::Binary {
            op,
            elementwise: false,
            lhs,
            rhs,
        } => {
            let a = static_scalar(program, lhs, depth + 1)?;
            let b = static_scalar(program, rhs, depth + 1)?;
            values::binary(*op, false, &a, &b)
                .ok()
                .as_ref()
                .and_then(scalar)
        }
        _ => None,
    }
}

/// The CGA version a file is written for (`version "2014.1"`); without a
/// `version` statement, 2009.1 (version.md).
fn module_version(module: &ast::Module) -> (u32, u32) {
    module
        .items
        .iter()
        .find_map(|item| match item {
            Item::Version { value, .. } => {
                let mut parts = value.trim().split('.');
                let major = parts.next()?.trim().parse().ok()?;
                let minor = parts
                    .next()
                    .and_then(|m| m.trim().parse().ok())
                    .unwrap_or(0);
                Some((major, minor))
            }
            _ => None,
        })
        .unwrap_or((2009, 1))
}

/// Whether two items define the same attribute, function or rule (name and
/// number of parameters).
fn same_definition(a: &Item, b: &Item) -> bool {
    match (a, b) {
        (Item::Attr(x), Item::Attr(y)) => x.name.name == y.name.name,
        (Item::Function(x), Item::Function(y)) => {
            x.name.name == y.name.name && x.params.len() == y.params.len()
        }
        (Item::Rule(x), Item::Rule(y)) => {
            x.name.name == y.name.name && x.params.len() == y.params.len()
        }
        _ => false,
    }
}

/// Names in scope inside one definition: parameters, then `with` locals.
struct Cx {
    rs: RuleSetId,
    locals: Vec<String>,
}

impl Cx {
    fn local(&self, name: &str) -> Option<u16> {
        self.locals
            .iter()
            .rposition(|l| l == name)
            .map(|i| i as u16)
    }
}

fn placeholder(span: Span) -> RExpr {
    RExpr::constant(Value::Float(0.0), span)
}

impl Resolver<'_> {
    fn error(&mut self, message: impl Into<String>, span: Span) {
        self.diags.push(Diagnostic::error(message, span));
    }

    fn symbol(&mut self, name: &str) -> u32 {
        if let Some(&id) = self.symbols.get(name) {
            return id;
        }
        let id = self.symbols.len() as u32;
        self.symbols.insert(Arc::from(name), id);
        id
    }

    fn parse_file(&mut self, path: &Path, text: String) -> usize {
        let key = self.world.canonical(path);
        if let Some(&idx) = self.parsed.get(&key) {
            return idx;
        }
        let file = self.sources.add(path, text);
        let (module, diags) = cga_syntax::parse(file, &self.sources.get(file).text);
        self.diags.extend(diags);
        let idx = self.parsed_files.len();
        self.parsed_files.push(ParsedFile {
            path: key.clone(),
            module: Arc::new(module),
        });
        self.parsed.insert(key, idx);
        idx
    }

    /// Creates the rule set for one instance of a parsed file and declares
    /// its names; bodies are resolved later (`resolve_pending`).
    fn instantiate(
        &mut self,
        file_idx: usize,
        prefix: String,
        importer: Option<(RuleSetId, ast::ImportDecl)>,
        main_style: Option<&str>,
    ) -> RuleSetId {
        let module = self.parsed_files[file_idx].module.clone();
        let path = self.parsed_files[file_idx].path.clone();
        let rs = self.program.rulesets.len() as RuleSetId;
        self.program.rulesets.push(RuleSet {
            prefix: prefix.clone(),
            path: path.clone(),
        });
        self.tables.push(Tables::default());
        let overrides: Option<Vec<ast::ImportOverride>> =
            importer.as_ref().and_then(|(_, d)| d.overrides.clone());

        // An import that lists styles (`import imp (mystyle) : "f.cga"`)
        // generates with the first of them; the main file with the style
        // asked for; everything else with Default.
        let style: Option<String> = match &importer {
            Some((_, d)) => d
                .styles
                .as_ref()
                .and_then(|list| list.first())
                .and_then(|s| {
                    let defined = module_styles(&module);
                    if defined.contains(&s.name) {
                        return Some(s.name.clone());
                    }
                    self.diags.push(
                        Diagnostic::error(format!("unknown style `{}`", s.name), s.span)
                            .with_label(format!(
                                "{} defines the styles {}",
                                path.display(),
                                defined.join(", ")
                            )),
                    );
                    None
                }),
            None => main_style.map(str::to_string),
        };
        let version = module_version(&module);
        for item in style_items(&module, style.as_deref()) {
            match item {
                Item::Attr(decl) if !decl.params.is_empty() => {
                    self.declare_attr_with_params(rs, decl, version)
                }
                Item::Attr(decl) => {
                    self.declare_attr(rs, decl, importer.as_ref().map(|i| i.0), &overrides)
                }
                Item::Function(decl) => self.declare_function(rs, decl),
                Item::Rule(decl) => {
                    self.declare_rule(rs, decl, importer.as_ref().map(|i| i.0), &overrides)
                }
                _ => {}
            }
        }

        for item in &module.items {
            let Item::Import(decl) = item else { continue };
            // An import without a path was a syntax error, reported already.
            if decl.path.is_empty() && decl.path_span.start == decl.path_span.end {
                continue;
            }
            let target = match self.find_import(&path, &decl.path) {
                Ok(t) => t,
                Err(searched) => {
                    let mut d = Diagnostic::error(
                        format!("cannot find the imported rule file \"{}\"", decl.path),
                        decl.path_span,
                    )
                    .with_label(if decl.path.starts_with('/') {
                        "not found in the rule file's workspace or the --workspace folders"
                    } else {
                        "not found relative to this rule file or its project"
                    });
                    if !searched.is_empty() {
                        d = d.with_note(crate::locate::searched_note(&searched));
                    }
                    self.diags.push(d);
                    continue;
                }
            };
            if self.stack.contains(&target) || target == path {
                let name = |p: &Path| {
                    p.file_name()
                        .map(|n| n.to_string_lossy().into_owned())
                        .unwrap_or_default()
                };
                let start = self.stack.iter().position(|p| *p == target);
                let mut chain: Vec<String> = start
                    .map(|i| self.stack[i..].iter().map(|p| name(p)).collect())
                    .unwrap_or_default();
                chain.push(name(&path));
                chain.push(name(&target));
                self.diags.push(
                    Diagnostic::error(
                        format!("import cycle: {}", chain.join(" imports ")),
                        decl.path_span,
                    )
                    .with_label("this import closes the cycle"),
                );
                continue;
            }
            let text = match self.world.read_text(&target) {
                Ok(t) => t,
                Err(e) => {
                    self.error(
                        format!("cannot read imported rule file {}: {e}", target.display()),
                        decl.path_span,
                    );
                    continue;
                }
            };
            let child_file = self.parse_file(&target, text);
            let alias = decl.alias.as_ref().map(|a| a.name.clone());
            let child_prefix = match (&alias, prefix.is_empty()) {
                (Some(a), true) => a.clone(),
                (Some(a), false) => format!("{prefix}.{a}"),
                (None, _) => prefix.clone(),
            };
            self.stack.push(path.clone());
            let child = self.instantiate(child_file, child_prefix, Some((rs, decl.clone())), None);
            self.stack.pop();
            if let Some(a) = alias {
                self.tables[rs as usize].imports.insert(a, child);
            }
        }
        self.attach_foreign_rules(rs);
        rs
    }

    /// Rules a file defines for a rule set it imports (`imp.Glazing(d) --> ...`)
    /// become rules of that rule set, replacing its own of the same arity;
    /// their bodies are resolved in the defining file.
    fn attach_foreign_rules(&mut self, rs: RuleSetId) {
        let foreign: Vec<(String, RuleId)> = self.tables[rs as usize]
            .rules
            .iter()
            .filter(|(name, _)| name.contains('.'))
            .flat_map(|(name, ids)| ids.iter().map(move |&id| (name.clone(), id)))
            .collect();
        for (name, id) in foreign {
            let mut target = rs;
            let mut rest = name.as_str();
            while let Some((alias, tail)) = rest.split_once('.') {
                match self.tables[target as usize].imports.get(alias) {
                    Some(&child) => {
                        target = child;
                        rest = tail;
                    }
                    None => break,
                }
            }
            if target == rs {
                // No import of that name: a rule whose name has a dot.
                continue;
            }
            let arity = self.program.rules[id as usize].arity;
            let list = self.tables[target as usize]
                .rules
                .entry(rest.to_string())
                .or_default();
            let rules = &self.program.rules;
            list.retain(|&r| rules[r as usize].arity != arity);
            list.push(id);
        }
    }

    fn declare_function(&mut self, rs: RuleSetId, decl: &ast::FunctionDecl) {
        let id = self.program.functions.len() as FuncId;
        self.program.functions.push(FunctionDef {
            name: decl.name.name.clone(),
            ruleset: rs,
            arity: decl.params.len(),
            is_const: decl.is_const,
            frame_size: decl.params.len() + decl.locals.len(),
            locals: Vec::new(),
            body: placeholder(decl.span),
            span: decl.name.span,
        });
        let same = self.tables[rs as usize]
            .funcs
            .entry(decl.name.name.clone())
            .or_default();
        let dup = same
            .iter()
            .any(|&f| self.program.functions[f as usize].arity == decl.params.len());
        same.push(id);
        if dup {
            self.error(
                format!(
                    "function `{}` with {} parameters is defined twice",
                    decl.name.name,
                    decl.params.len()
                ),
                decl.name.span,
            );
        }
        self.pending.push(Pending::Function {
            id,
            ruleset: rs,
            decl: decl.clone(),
        });
    }

    /// `attr P(idx) = e`: CGA allowed attributes with parameters before
    /// 2019.1 (indexed object attributes; `streetWidth(i)` still is one).
    /// Lots carry no such arrays here, so it is a function of its
    /// parameters with the default as its body. In files of 2019.1 or later
    /// it is an error, as in CityEngine.
    fn declare_attr_with_params(
        &mut self,
        rs: RuleSetId,
        decl: &ast::AttrDecl,
        version: (u32, u32),
    ) {
        if version >= (2019, 1) && decl.name.name != "streetWidth" {
            self.diags.push(
                Diagnostic::error(
                    format!(
                        "attribute `{}` has parameters, which CGA allows only before version 2019.1 (this file is version {}.{})",
                        decl.name.name, version.0, version.1
                    ),
                    decl.name.span,
                )
                .with_label("use a function `name(params) = ...` instead"),
            );
            return;
        }
        self.declare_function(
            rs,
            &ast::FunctionDecl {
                annotations: decl.annotations.clone(),
                is_const: false,
                name: decl.name.clone(),
                params: decl.params.clone(),
                locals: decl.locals.clone(),
                value: decl.value.clone(),
                span: decl.span,
            },
        );
    }

    fn declare_attr(
        &mut self,
        rs: RuleSetId,
        decl: &ast::AttrDecl,
        importer: Option<RuleSetId>,
        overrides: &Option<Vec<ast::ImportOverride>>,
    ) {
        let name = &decl.name.name;
        if self.tables[rs as usize].attrs.contains_key(name) {
            self.error(
                format!("attribute `{name}` is defined twice"),
                decl.name.span,
            );
            return;
        }
        let explicit = overrides.as_ref().and_then(|list| {
            list.iter().find_map(|o| match o {
                ast::ImportOverride::Attr(n, e) if &n.name == name => Some(e.clone()),
                _ => None,
            })
        });
        let protected = overrides.as_ref().is_some_and(|list| {
            list.is_empty()
                || list
                    .iter()
                    .any(|o| matches!(o, ast::ImportOverride::Protect(n) if &n.name == name))
        });
        if let (Some(imp), None, false) = (importer, &explicit, protected) {
            if let Some(&slot) = self.tables[imp as usize].attrs.get(name) {
                // Propagation: the importer's attribute of the same name.
                self.tables[rs as usize].attrs.insert(name.clone(), slot);
                return;
            }
        }
        let id = self.program.attrs.len() as AttrId;
        self.program.attrs.push(AttrDef {
            name: name.clone(),
            ruleset: rs,
            default: placeholder(decl.span),
            frame_size: decl.locals.len(),
            annotations: annotations(&decl.annotations),
            span: decl.name.span,
        });
        self.tables[rs as usize].attrs.insert(name.clone(), id);
        match (explicit, importer) {
            (Some(expr), Some(imp)) => self.pending.push(Pending::AttrOverride {
                id,
                importer: imp,
                expr,
            }),
            _ => self.pending.push(Pending::Attr {
                id,
                ruleset: rs,
                decl: decl.clone(),
            }),
        }
    }

    fn declare_rule(
        &mut self,
        rs: RuleSetId,
        decl: &ast::RuleDecl,
        importer: Option<RuleSetId>,
        overrides: &Option<Vec<ast::ImportOverride>>,
    ) {
        let name = &decl.name.name;
        let id = self.program.rules.len() as RuleId;
        let symbol = self.symbol(name);
        self.program.rules.push(RuleDef {
            name: name.clone(),
            ruleset: rs,
            arity: decl.params.len(),
            frame_size: decl.params.len() + decl.locals.len(),
            locals: Vec::new(),
            body: RBody::Ops(Vec::new()),
            annotations: annotations(&decl.annotations),
            is_start: decl.kind == ast::RuleKind::Start,
            symbol,
            span: decl.name.span,
        });
        let same = self.tables[rs as usize]
            .rules
            .entry(name.clone())
            .or_default();
        let dup = same
            .iter()
            .any(|&r| self.program.rules[r as usize].arity == decl.params.len());
        same.push(id);
        if dup {
            self.error(
                format!(
                    "rule `{name}` with {} parameters is defined twice",
                    decl.params.len()
                ),
                decl.name.span,
            );
        }
        if decl.kind == ast::RuleKind::Start {
            self.tables[rs as usize].start_rule = Some(id);
        }
        // An importer may redefine an extension rule; its body is then
        // resolved in the importer's rule set.
        let redefined = (decl.kind == ast::RuleKind::Extension)
            .then(|| {
                overrides.as_ref().and_then(|list| {
                    list.iter().find_map(|o| match o {
                        ast::ImportOverride::Rule {
                            name: n,
                            params,
                            body,
                        } if &n.name == name => Some((params.clone(), body.clone())),
                        _ => None,
                    })
                })
            })
            .flatten();
        match (redefined, importer) {
            (Some((params, body)), Some(imp)) => self.pending.push(Pending::Rule {
                id,
                ruleset: imp,
                params,
                locals: Vec::new(),
                body,
            }),
            _ => self.pending.push(Pending::Rule {
                id,
                ruleset: rs,
                params: decl.params.clone(),
                locals: decl.locals.clone(),
                body: decl.body.clone(),
            }),
        }
    }

    /// Finds an imported file (`locate.rs`), or every place searched.
    fn find_import(&self, importer: &Path, target: &str) -> Result<PathBuf, Vec<PathBuf>> {
        crate::locate::locate(self.world, importer, target, &self.workspaces)
    }

    fn resolve_pending(&mut self) {
        let pending = std::mem::take(&mut self.pending);
        for p in pending {
            match p {
                Pending::Attr { id, ruleset, decl } => {
                    let mut cx = Cx {
                        rs: ruleset,
                        locals: Vec::new(),
                    };
                    let locals = self.resolve_locals(&mut cx, &decl.locals);
                    let value = self.expr(&cx, &decl.value);
                    let default = if locals.is_empty() {
                        value
                    } else {
                        wrap_locals(locals, value)
                    };
                    self.program.attrs[id as usize].default = default;
                }
                Pending::AttrOverride { id, importer, expr } => {
                    let cx = Cx {
                        rs: importer,
                        locals: Vec::new(),
                    };
                    self.program.attrs[id as usize].default = self.expr(&cx, &expr);
                }
                Pending::Function { id, ruleset, decl } => {
                    let mut cx = Cx {
                        rs: ruleset,
                        locals: decl.params.iter().map(|p| p.name.name.clone()).collect(),
                    };
                    let locals = self.resolve_locals(&mut cx, &decl.locals);
                    let body = self.expr(&cx, &decl.value);
                    let f = &mut self.program.functions[id as usize];
                    f.locals = locals;
                    f.body = body;
                }
                Pending::Rule {
                    id,
                    ruleset,
                    params,
                    locals,
                    body,
                } => {
                    let mut cx = Cx {
                        rs: ruleset,
                        locals: params.iter().map(|p| p.name.name.clone()).collect(),
                    };
                    let locals = self.resolve_locals(&mut cx, &locals);
                    let body = self.body(&cx, &body);
                    let r = &mut self.program.rules[id as usize];
                    r.locals = locals;
                    r.frame_size = params.len() + r.locals.len();
                    r.body = body;
                }
            }
        }
    }

    /// Reports the binary operations that fail whatever the values, because
    /// their operand types are known and the operator does not apply to
    /// them (`floors == "six"` for a float attribute): `cga check` finds
    /// what deriving would stop on.
    fn check_types(&mut self) {
        for (op, lhs, rhs, span) in std::mem::take(&mut self.type_checks) {
            let (Some(a), Some(b)) = (
                static_scalar(&self.program, &lhs, 0),
                static_scalar(&self.program, &rhs, 0),
            ) else {
                continue;
            };
            if let Err(message) = values::binary(op, false, &a, &b) {
                self.diags.push(
                    Diagnostic::error(format!("type mismatch: {message}"), span).with_label(
                        format!(
                            "{} and {} do not combine with this operator",
                            a.type_name(),
                            b.type_name()
                        ),
                    ),
                );
            }
        }
    }

    fn resolve_locals(&mut self, cx: &mut Cx, locals: &[ast::LocalVar]) -> Vec<RExpr> {
        let mut out = Vec::with_capacity(locals.len());
        for l in locals {
            out.push(self.expr(cx, &l.value));
            cx.locals.push(l.name.name.clone());
        }
        out
    }

    // ----- names -----

    /// Follows `alias.rest` through imports: the rule set and the rest of the name.
    fn through_alias<'n>(&self, rs: RuleSetId, name: &'n str) -> Option<(RuleSetId, &'n str)> {
        let (alias, rest) = name.split_once('.')?;
        let child = *self.tables[rs as usize].imports.get(alias)?;
        Some((child, rest))
    }

    fn find_attr(&self, rs: RuleSetId, name: &str) -> Option<AttrId> {
        if let Some(&id) = self.tables[rs as usize].attrs.get(name) {
            return Some(id);
        }
        let (child, rest) = self.through_alias(rs, name)?;
        self.find_attr(child, rest)
    }

    fn find_func(&self, rs: RuleSetId, name: &str, arity: usize) -> Option<FuncId> {
        if let Some(ids) = self.tables[rs as usize].funcs.get(name) {
            if let Some(&id) = ids
                .iter()
                .find(|&&f| self.program.functions[f as usize].arity == arity)
            {
                return Some(id);
            }
        }
        let (child, rest) = self.through_alias(rs, name)?;
        self.find_func(child, rest, arity)
    }

    fn find_rule(&self, rs: RuleSetId, name: &str, arity: usize) -> Option<RuleId> {
        let t = &self.tables[rs as usize];
        if name == "start" {
            if let Some(id) = t.start_rule {
                if self.program.rules[id as usize].arity == arity {
                    return Some(id);
                }
            }
        }
        if let Some(ids) = t.rules.get(name) {
            if let Some(&id) = ids
                .iter()
                .find(|&&r| self.program.rules[r as usize].arity == arity)
            {
                return Some(id);
            }
        }
        let (child, rest) = self.through_alias(rs, name)?;
        self.find_rule(child, rest, arity)
    }

    /// Arities of the rules called `name` (for an arity mismatch message).
    fn rule_arities(&self, rs: RuleSetId, name: &str) -> Vec<usize> {
        if let Some(ids) = self.tables[rs as usize].rules.get(name) {
            return ids
                .iter()
                .map(|&r| self.program.rules[r as usize].arity)
                .collect();
        }
        match self.through_alias(rs, name) {
            Some((child, rest)) => self.rule_arities(child, rest),
            None => Vec::new(),
        }
    }

    /// The closest known name to `name`, for "did you mean" hints.
    fn suggest(&self, rs: RuleSetId, name: &str, kind: NameKind) -> Option<String> {
        let t = &self.tables[rs as usize];
        let mut candidates: Vec<&str> = Vec::new();
        match kind {
            NameKind::Value => {
                candidates.extend(t.attrs.keys().map(|s| s.as_str()));
                candidates.extend(t.funcs.keys().map(|s| s.as_str()));
                candidates.extend(KNOWN_FUNCTIONS);
            }
            NameKind::Statement => {
                candidates.extend(t.rules.keys().map(|s| s.as_str()));
                for op in ops::table::names() {
                    candidates.push(op);
                }
            }
        }
        closest(name, candidates)
    }

    /// The rule whose name is closest to `name` (a likely typo), if any.
    fn suggest_rule(&self, rs: RuleSetId, name: &str) -> Option<String> {
        let rules: Vec<&str> = self.tables[rs as usize]
            .rules
            .keys()
            .map(|s| s.as_str())
            .filter(|r| *r != name)
            .collect();
        closest(name, rules)
    }

    fn unknown(&mut self, what: &str, ident: &ast::Ident, rs: RuleSetId, kind: NameKind) {
        if ident.name.is_empty() {
            // The parser's stand-in for a missing expression: already reported.
            return;
        }
        let mut d = Diagnostic::error(format!("unknown {what} `{}`", ident.name), ident.span)
            .with_label(format!("not a known {what}"));
        if let Some(s) = self.suggest(rs, &ident.name, kind) {
            d = d.with_note(format!("help: did you mean `{s}`?"));
        }
        self.diags.push(d);
    }

    // ----- expressions -----

    fn expr(&mut self, cx: &Cx, e: &Expr) -> RExpr {
        let span = e.span;
        let kind = match &e.kind {
            ExprKind::Float(x) => RExprKind::Const(Value::Float(*x)),
            ExprKind::Bool(b) => RExprKind::Const(Value::Bool(*b)),
            ExprKind::Str(s) => RExprKind::Const(Value::Str(Arc::from(s.as_str()))),
            ExprKind::Name(ident) => return self.name(cx, ident, false),
            ExprKind::Call { name, args } => {
                let args: Vec<RExpr> = args
                    .iter()
                    .enumerate()
                    .map(|(i, a)| {
                        if shape_fns::arg_is_selector(&name.name, i) {
                            self.selector_arg(cx, a)
                        } else {
                            self.expr(cx, a)
                        }
                    })
                    .collect();
                return self.call(cx, name, args, span);
            }
            ExprKind::Unary {
                op,
                elementwise,
                operand,
            } => RExprKind::Unary {
                op: *op,
                elementwise: *elementwise,
                operand: Box::new(self.expr(cx, operand)),
            },
            ExprKind::Binary {
                op,
                elementwise,
                lhs,
                rhs,
            } => {
                let lhs = self.expr(cx, lhs);
                let rhs = self.expr(cx, rhs);
                if !*elementwise && type_checkable(&lhs) && type_checkable(&rhs) {
                    self.type_checks.push((*op, lhs.clone(), rhs.clone(), span));
                }
                RExprKind::Binary {
                    op: *op,
                    elementwise: *elementwise,
                    lhs: Box::new(lhs),
                    rhs: Box::new(rhs),
                }
            }
            ExprKind::Array(rows) => RExprKind::Array(
                rows.iter()
                    .map(|r| r.iter().map(|x| self.expr(cx, x)).collect())
                    .collect(),
            ),
            ExprKind::Range { base, step, limit } => RExprKind::Range {
                base: Box::new(self.expr(cx, base)),
                step: step.as_ref().map(|s| Box::new(self.expr(cx, s))),
                limit: Box::new(self.expr(cx, limit)),
            },
            ExprKind::Index { base, indices } => RExprKind::Index {
                base: Box::new(self.expr(cx, base)),
                indices: indices.iter().map(|i| self.expr(cx, i)).collect(),
            },
            ExprKind::Case(chain) => RExprKind::Case {
                branches: chain
                    .branches
                    .iter()
                    .map(|(c, v)| (self.expr(cx, c), self.expr(cx, v)))
                    .collect(),
                otherwise: chain.otherwise.as_ref().map(|v| Box::new(self.expr(cx, v))),
            },
            ExprKind::Stochastic(chain) => RExprKind::Stochastic {
                branches: chain
                    .branches
                    .iter()
                    .map(|(c, v)| (self.expr(cx, c), self.expr(cx, v)))
                    .collect(),
                otherwise: chain.otherwise.as_ref().map(|v| Box::new(self.expr(cx, v))),
            },
            ExprKind::Relative(inner) => RExprKind::Relative(Box::new(self.expr(cx, inner))),
            ExprKind::Floating(inner) => RExprKind::Floating(Box::new(self.expr(cx, inner))),
            ExprKind::CompFn { args, block } => RExprKind::CompFn {
                args: args.iter().map(|a| self.selector_arg(cx, a)).collect(),
                block: self.expr_block(cx, block),
            },
        };
        RExpr { kind, span }
    }

    /// The block of the comp function (the only expression with a block).
    fn expr_block(&mut self, cx: &Cx, b: &ast::Block<Expr>) -> RBlock<RExpr> {
        RBlock {
            parts: b
                .parts
                .iter()
                .map(|p| match p {
                    BlockPart::Entry(e) => RPart::Entry {
                        head: self.comp_head(cx, &e.head),
                        depth: e.depth.as_ref().map(|d| self.expr(cx, d)),
                        op: e.op,
                        body: self.expr(cx, &e.body),
                        span: e.span,
                    },
                    BlockPart::Group(g) => RPart::Group(self.expr_block(cx, g)),
                    BlockPart::Unlabeled { body, span } => RPart::Unlabeled {
                        body: self.expr(cx, body),
                        span: *span,
                    },
                })
                .collect(),
            repeat: b.repeat,
            span: b.span,
        }
    }

    /// A name in value position. `selector_ok`: an unknown name is taken as
    /// a selector keyword (a string constant) instead of an error.
    fn name(&mut self, cx: &Cx, ident: &ast::Ident, selector_ok: bool) -> RExpr {
        let span = ident.span;
        let name = ident.name.as_str();
        let kind = if let Some(i) = cx.local(name) {
            RExprKind::Local(i)
        } else if let Some(id) = self.find_attr(cx.rs, name) {
            RExprKind::Attr(id)
        } else if let Some(f) = self.find_func(cx.rs, name, 0) {
            RExprKind::Func(f, Vec::new())
        } else if let Some(f) = shape_fns::lookup(name, 0) {
            self.note_shape_fn(f);
            RExprKind::Shape(f, Vec::new())
        } else if let Some(b) = values::lookup(name, 0) {
            RExprKind::Pure(b, Vec::new())
        } else if selector_ok {
            RExprKind::Const(Value::Str(Arc::from(name)))
        } else {
            self.unknown("name", ident, cx.rs, NameKind::Value);
            return placeholder(span);
        };
        RExpr { kind, span }
    }

    /// Records what the derivation must keep for a shape function.
    fn note_shape_fn(&mut self, f: shape_fns::ShapeFn) {
        if f == shape_fns::ShapeFn::File(crate::file_fns::FileFn::TreeKey) {
            self.program.uses_tree_key = true;
        }
    }

    fn call(&mut self, cx: &Cx, name: &ast::Ident, args: Vec<RExpr>, span: Span) -> RExpr {
        let n = args.len();
        let kind = if let Some(f) = self.find_func(cx.rs, &name.name, n) {
            RExprKind::Func(f, args)
        } else if let Some(f) = shape_fns::lookup(&name.name, n) {
            self.note_shape_fn(f);
            RExprKind::Shape(f, args)
        } else if let Some(b) = values::lookup(&name.name, n) {
            RExprKind::Pure(b, args)
        } else if let Some(b) = values::lookup_name(&name.name) {
            self.error(
                format!(
                    "`{}` takes {} arguments, found {n}",
                    name.name,
                    arity_text(b.min_args, b.max_args)
                ),
                span,
            );
            return placeholder(span);
        } else if let Some(arities) = self.known_arities(cx.rs, &name.name) {
            // A known function called with the wrong number of arguments.
            self.error(
                format!("`{}` takes {arities} arguments, found {n}", name.name),
                span,
            );
            return placeholder(span);
        } else {
            self.unknown("function", name, cx.rs, NameKind::Value);
            return placeholder(span);
        };
        RExpr { kind, span }
    }

    /// The argument counts a user function or shape function called `name`
    /// takes (`1 or 3`), if there is one.
    fn known_arities(&self, rs: RuleSetId, name: &str) -> Option<String> {
        let mut counts: Vec<usize> = match self.tables[rs as usize].funcs.get(name) {
            Some(ids) => ids
                .iter()
                .map(|&f| self.program.functions[f as usize].arity)
                .collect(),
            None => (0..=10)
                .filter(|&k| shape_fns::lookup(name, k).is_some())
                .collect(),
        };
        counts.sort_unstable();
        counts.dedup();
        match counts.as_slice() {
            [] => None,
            [one] => Some(one.to_string()),
            [first, .., last] if counts.windows(2).all(|w| w[1] == w[0] + 1) => {
                Some(format!("{first} to {last}"))
            }
            _ => Some(
                counts
                    .iter()
                    .map(|c| c.to_string())
                    .collect::<Vec<_>>()
                    .join(" or "),
            ),
        }
    }

    /// A block head (split size or comp selector): names that are not values
    /// are selector keywords.
    fn head(&mut self, cx: &Cx, e: &Expr) -> RExpr {
        match &e.kind {
            ExprKind::Name(ident) => self.name(cx, ident, true),
            ExprKind::Relative(inner) => RExpr {
                kind: RExprKind::Relative(Box::new(self.head(cx, inner))),
                span: e.span,
            },
            ExprKind::Floating(inner) => RExpr {
                kind: RExprKind::Floating(Box::new(self.head(cx, inner))),
                span: e.span,
            },
            _ => self.expr(cx, e),
        }
    }

    /// A comp head: the selection expression with the selector text as
    /// written (`comp.sel`).
    fn comp_head(&mut self, cx: &Cx, e: &Expr) -> RExpr {
        let text = self
            .sources
            .get(e.span.file)
            .text
            .get(e.span.range())
            .unwrap_or("")
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" ");
        RExpr {
            kind: RExprKind::CompHead {
                text: Arc::from(text.as_str()),
                expr: Box::new(self.comp_selection(cx, e)),
            },
            span: e.span,
        }
    }

    /// A comp selection expression: selector keywords (and `isTagged(...)`)
    /// are selectors, alone or under `!`, `&&`, `||` and comparisons; in
    /// a comp head a keyword wins over an attribute or function of the same
    /// name (`inside` is the selector there, not the occlusion query).
    /// Anything else is an ordinary expression (an index, a condition on
    /// the component shape such as `geometry.area() > 1`).
    fn comp_selection(&mut self, cx: &Cx, e: &Expr) -> RExpr {
        let span = e.span;
        let kind = match &e.kind {
            ExprKind::Name(ident) => match crate::selectors::Selector::parse(&ident.name) {
                Some(sel) => RExprKind::CompSelector(sel, Vec::new()),
                None => return self.name(cx, ident, false),
            },
            ExprKind::Call { name, args } if name.name == "isTagged" => {
                if args.is_empty() || args.len() > 2 {
                    self.error(
                        format!(
                            "`isTagged` takes 1 or 2 arguments (tag query, e|v), found {}",
                            args.len()
                        ),
                        span,
                    );
                    return placeholder(span);
                }
                let mut list = vec![self.expr(cx, &args[0])];
                if let Some(sub) = args.get(1) {
                    list.push(self.selector_arg(cx, sub));
                }
                RExprKind::CompSelector(crate::selectors::Selector::IsTagged, list)
            }
            ExprKind::Unary {
                op,
                elementwise,
                operand,
            } => RExprKind::Unary {
                op: *op,
                elementwise: *elementwise,
                operand: Box::new(self.comp_selection(cx, operand)),
            },
            ExprKind::Binary {
                op,
                elementwise,
                lhs,
                rhs,
            } => RExprKind::Binary {
                op: *op,
                elementwise: *elementwise,
                lhs: Box::new(self.comp_selection(cx, lhs)),
                rhs: Box::new(self.comp_selection(cx, rhs)),
            },
            _ => return self.expr(cx, e),
        };
        RExpr { kind, span }
    }

    fn selector_arg(&mut self, _cx: &Cx, e: &Expr) -> RExpr {
        match &e.kind {
            ExprKind::Name(ident) => {
                RExpr::constant(Value::Str(Arc::from(ident.name.as_str())), e.span)
            }
            _ => self.expr(_cx, e),
        }
    }

    // ----- bodies -----

    fn body(&mut self, cx: &Cx, b: &Body) -> RBody {
        match b {
            Body::Ops(stmts) => RBody::Ops(self.stmts(cx, stmts)),
            Body::Case(chain) => RBody::Case {
                branches: chain
                    .branches
                    .iter()
                    .map(|(c, b)| (self.expr(cx, c), self.body(cx, b)))
                    .collect(),
                otherwise: chain.otherwise.as_ref().map(|b| Box::new(self.body(cx, b))),
            },
            Body::Stochastic(chain) => RBody::Stochastic {
                branches: chain
                    .branches
                    .iter()
                    .map(|(c, b)| (self.expr(cx, c), self.body(cx, b)))
                    .collect(),
                otherwise: chain.otherwise.as_ref().map(|b| Box::new(self.body(cx, b))),
            },
        }
    }

    /// The block of an operation, its heads resolved as `heads` says.
    fn op_block(&mut self, cx: &Cx, b: &ast::Block<Body>, heads: Heads) -> RBlock<RBody> {
        RBlock {
            parts: b
                .parts
                .iter()
                .map(|p| match p {
                    BlockPart::Entry(e) => RPart::Entry {
                        head: match (heads, &e.head.kind) {
                            // The setback selector `remainder` is not an
                            // edge selector: a plain keyword.
                            (Heads::Setback, ExprKind::Name(n)) if n.name == "remainder" => {
                                self.head(cx, &e.head)
                            }
                            (Heads::Comp | Heads::Setback, _) => self.comp_head(cx, &e.head),
                            (Heads::Plain, _) => self.head(cx, &e.head),
                        },
                        depth: e.depth.as_ref().map(|d| self.expr(cx, d)),
                        op: e.op,
                        body: self.body(cx, &e.body),
                        span: e.span,
                    },
                    BlockPart::Group(g) => RPart::Group(self.op_block(cx, g, heads)),
                    BlockPart::Unlabeled { body, span } => RPart::Unlabeled {
                        body: self.body(cx, body),
                        span: *span,
                    },
                })
                .collect(),
            repeat: b.repeat,
            span: b.span,
        }
    }

    /// An operation sequence. `inline` takes the statement after it (a rule
    /// call or a subdivision), unless it has a `{ operations }` block.
    fn stmts(&mut self, cx: &Cx, stmts: &[Stmt]) -> Vec<RStmt> {
        let mut out = Vec::with_capacity(stmts.len());
        let mut i = 0;
        while i < stmts.len() {
            match &stmts[i] {
                Stmt::Call(call) if self.is_inline(cx, call) => {
                    let (stmt, used) = self.inline_stmt(cx, &stmts[i..]);
                    out.push(stmt);
                    i += used;
                }
                Stmt::Call(call) if i + 1 < stmts.len() && self.is_old_boolean(cx, call) => {
                    out.push(self.old_boolean(cx, call, &stmts[i + 1]));
                    i += 2;
                }
                s => {
                    out.push(self.stmt(cx, s));
                    i += 1;
                }
            }
        }
        out
    }

    /// `subtract Rule`, `subtract(swap) Rule` (and `union`, `intersect`):
    /// the Boolean operations' syntax before 2025.0, the current shape and
    /// the next statement's shape as operands.
    fn is_old_boolean(&self, cx: &Cx, call: &ast::Call) -> bool {
        matches!(call.name.name.as_str(), "union" | "subtract" | "intersect")
            && call.block.is_none()
            && call.import_overrides.is_none()
            && call.args.as_ref().is_none_or(|a| a.len() <= 1)
            && self
                .find_rule(
                    cx.rs,
                    &call.name.name,
                    call.args.as_ref().map_or(0, |a| a.len()),
                )
                .is_none()
    }

    /// The old Boolean syntax as the new one (cga_changelog.md, 2025.0):
    /// `subtract Rule` is `subtract { OperandA. | Rule }`, `subtract(swap)
    /// Rule` is `subtract { Rule | OperandB. }`.
    fn old_boolean(&mut self, cx: &Cx, call: &ast::Call, next: &Stmt) -> RStmt {
        let swap = match call.args.as_deref() {
            Some([arg]) => match &arg.kind {
                ExprKind::Name(n) if n.name == "swap" => true,
                _ => {
                    self.error(
                        format!("`{}` takes `swap` or no argument here", call.name.name),
                        arg.span,
                    );
                    false
                }
            },
            _ => false,
        };
        let span = call.span;
        let current = |r: &mut Self, name: &str| RPart::Unlabeled {
            body: RBody::Ops(vec![RStmt::Leaf(r.symbol(name))]),
            span,
        };
        let other = RPart::Unlabeled {
            body: RBody::Ops(vec![self.stmt(cx, next)]),
            span,
        };
        let parts = if swap {
            vec![other, current(self, "OperandB")]
        } else {
            vec![current(self, "OperandA"), other]
        };
        use cga_geometry::boolean::BoolOp;
        let op = Op::Boolean(match call.name.name.as_str() {
            "union" => BoolOp::Union,
            "subtract" => BoolOp::Subtract,
            _ => BoolOp::Intersect,
        });
        RStmt::Op(OpCall {
            op,
            args: Vec::new(),
            block: Some(RBlock {
                parts,
                repeat: false,
                span,
            }),
            remainder_block: None,
            span,
        })
    }

    /// `inline` is a keyword unless a rule of that name exists.
    fn is_inline(&self, cx: &Cx, call: &ast::Call) -> bool {
        call.name.name == "inline"
            && call.import_overrides.is_none()
            && self
                .find_rule(cx.rs, "inline", call.args.as_ref().map_or(0, |a| a.len()))
                .is_none()
    }

    /// `inline Rule`, `inline subdivision`, `inline { operations }`, each
    /// with an optional `(strategy)`: an `Op::Inline` call whose block has
    /// one unlabeled part, the operations to derive (`stmts[0]` is the
    /// `inline` call). Returns the statement and how many statements it took.
    fn inline_stmt(&mut self, cx: &Cx, stmts: &[Stmt]) -> (RStmt, usize) {
        let Stmt::Call(call) = &stmts[0] else {
            return (RStmt::Nil, 1);
        };
        let span = call.span;
        let args_in = call.args.as_deref().unwrap_or(&[]);
        if args_in.len() > 1 {
            self.error(
                format!(
                    "`inline` takes at most 1 argument (append, unify or recompose), found {}",
                    args_in.len()
                ),
                span,
            );
        }
        let args: Vec<RExpr> = args_in
            .iter()
            .take(1)
            .map(|a| self.selector_arg(cx, a))
            .collect();
        if call.remainder_block.is_some() {
            self.error("`inline` takes one `{ ... }` block", span);
        }
        let (body, body_span, used) = match &call.block {
            Some(b) => {
                let mut parts = Vec::new();
                for p in &b.parts {
                    match p {
                        BlockPart::Unlabeled { body, .. } => parts.push(self.body(cx, body)),
                        BlockPart::Entry(e) => self.error(
                            "`inline { ... }` takes operations, not `head : ...` entries",
                            e.span,
                        ),
                        BlockPart::Group(g) => {
                            self.error("`inline { ... }` takes operations, not a pattern", g.span)
                        }
                    }
                }
                if b.repeat {
                    self.error("`inline { ... }` cannot repeat (`*`)", b.span);
                }
                let body = match parts.len() {
                    1 => parts.pop().unwrap_or(RBody::Ops(Vec::new())),
                    // `{ A | B }`: each alternative in sequence.
                    _ => RBody::Ops(parts.into_iter().map(RStmt::Push).collect()),
                };
                (body, b.span, 1)
            }
            None => match stmts.get(1) {
                Some(Stmt::Call(next)) if self.is_inline(cx, next) => {
                    let (s, used) = self.inline_stmt(cx, &stmts[1..]);
                    (RBody::Ops(vec![s]), next.span, 1 + used)
                }
                Some(next) => {
                    let next_span = match next {
                        Stmt::Call(c) => c.span,
                        Stmt::Leaf(i) => i.span,
                        Stmt::Nil(s) | Stmt::Push(_, s) => *s,
                    };
                    (RBody::Ops(vec![self.stmt(cx, next)]), next_span, 2)
                }
                None => {
                    self.error(
                        "`inline` needs a rule, a subdivision or `{ operations }` after it",
                        span,
                    );
                    (RBody::Ops(Vec::new()), span, 1)
                }
            },
        };
        let block = RBlock {
            parts: vec![RPart::Unlabeled {
                body,
                span: body_span,
            }],
            repeat: false,
            span: body_span,
        };
        let stmt = RStmt::Op(OpCall {
            op: ops::Op::Inline,
            args,
            block: Some(block),
            remainder_block: None,
            span,
        });
        (stmt, used)
    }

    fn stmt(&mut self, cx: &Cx, s: &Stmt) -> RStmt {
        match s {
            Stmt::Call(call) => self.call_stmt(cx, call),
            Stmt::Leaf(ident) => RStmt::Leaf(self.symbol(&ident.name)),
            Stmt::Nil(_) => RStmt::Nil,
            Stmt::Push(body, _) => RStmt::Push(self.body(cx, body)),
        }
    }

    fn call_stmt(&mut self, cx: &Cx, call: &ast::Call) -> RStmt {
        let name = call.name.name.as_str();
        let arity = call.args.as_ref().map_or(0, |a| a.len());
        let span = call.span;

        if name == "set" && call.block.is_none() {
            return self.set_stmt(cx, call);
        }
        if let Some(rule) = self.find_rule(cx.rs, name, arity) {
            let args = call
                .args
                .iter()
                .flatten()
                .map(|a| self.expr(cx, a))
                .collect();
            let attr_overrides = match &call.import_overrides {
                Some(list) => self.dynamic_overrides(cx, name, list),
                None => Vec::new(),
            };
            if let Some(b) = &call.block {
                self.error("a rule call takes no `{ ... }` block", b.span);
            }
            return RStmt::Rule(RuleCall {
                rule,
                args,
                dynamic: call.import_overrides.is_some(),
                attr_overrides,
                span,
            });
        }
        let def = ops::table::find(name);
        if let Some((def, op)) = def.and_then(|d| match d.run {
            ops::table::Run::Op(op) => Some((d, op)),
            _ => None,
        }) {
            if !def.accepts(arity) {
                let mut d = Diagnostic::error(
                    format!(
                        "`{name}` takes {} arguments, found {arity}",
                        def.arity_text()
                    ),
                    span,
                );
                for form in def.signatures() {
                    d = d.with_note(format!("form: {form}"));
                }
                self.diags.push(d);
                return RStmt::Nil;
            }
            let mut args = self.op_args(cx, def, call.args.as_deref().unwrap_or(&[]));
            if name == "setbackPerEdge" {
                // A shortcut for `setback(comp(fe) { all : distance })`
                // (op_setbackPerEdge.md): the distance is evaluated on
                // every face edge component, not on the current shape.
                let d = args.remove(0);
                args.insert(0, per_face_edge(d));
            }
            let heads = match name {
                "comp" | "modify" => Heads::Comp,
                "setback" | "setbackPerEdge" | "setbackToArea" => Heads::Setback,
                _ => Heads::Plain,
            };
            let block = call.block.as_ref().map(|b| self.op_block(cx, b, heads));
            if block.is_some() && def.block == ops::table::Block::None {
                self.error(format!("`{name}` takes no `{{ ... }}` block"), span);
            }
            let remainder_block = call
                .remainder_block
                .as_ref()
                .map(|b| self.op_block(cx, b, Heads::Plain));
            if remainder_block.is_some()
                && op != Op::Footprint(ops::FootprintOp::SplitAndSetbackPerimeter)
            {
                self.error(format!("`{name}` takes one `{{ ... }}` block"), span);
            }
            return RStmt::Op(OpCall {
                op,
                args,
                block,
                remainder_block,
                span,
            });
        }
        if let Some(def) = def {
            // An operation that is not run: resolve what is inside anyway,
            // so that its errors are reported.
            let _ = self.op_args(cx, def, call.args.as_deref().unwrap_or(&[]));
            if let Some(b) = &call.block {
                let _ = self.op_block(cx, b, Heads::Plain);
            }
            return RStmt::Unsupported {
                name: name.to_string(),
                span: call.name.span,
            };
        }
        if call.args.is_none() && call.import_overrides.is_none() {
            // A rule name without a rule: a leaf shape of that name, as in
            // CityEngine. A name close to a rule's is most likely a typo:
            // say so (`Facde` for `Facade`).
            if let Some(close) = self.suggest_rule(cx.rs, name) {
                self.diags.push(
                    Diagnostic::warning(
                        format!("rule `{name}` is not defined; the shape becomes a leaf"),
                        call.name.span,
                    )
                    .with_label("no rule of this name")
                    .with_note(format!("help: did you mean `{close}`?")),
                );
            }
            return RStmt::Leaf(self.symbol(name));
        }
        let arities = self.rule_arities(cx.rs, name);
        let looks_like_rule = name
            .rsplit('.')
            .next()
            .and_then(|n| n.chars().next())
            .is_some_and(|c| c.is_uppercase());
        if !arities.is_empty() {
            // `Rule(x)` where only `Rule` (or `Rule(a, b)`) exists: no rule
            // has this signature, so, as for an undefined rule, the shape
            // becomes a leaf (CityEngine warns "undefined rule").
            let _ = call.args.iter().flatten().map(|a| self.expr(cx, a)).count();
            self.diags.push(
                Diagnostic::warning(
                    format!(
                        "rule `{name}` takes {} parameter(s), called with {arity}: no such rule, the shape becomes a leaf",
                        arities
                            .iter()
                            .map(|a| a.to_string())
                            .collect::<Vec<_>>()
                            .join(" or ")
                    ),
                    call.name.span,
                )
                .with_label("no rule with this number of parameters"),
            );
            return RStmt::Leaf(self.symbol(name));
        }
        if looks_like_rule {
            // A rule that is not defined here (an importing file may define
            // it, `imp.Rule(x) --> ...`): a leaf shape, as in CityEngine.
            let mut d = Diagnostic::warning(
                format!("rule `{name}` is not defined; the shape becomes a leaf"),
                call.name.span,
            )
            .with_label("no rule of this name");
            if let Some(close) = self.suggest_rule(cx.rs, name) {
                d = d.with_note(format!("help: did you mean `{close}`?"));
            }
            self.diags.push(d);
            return RStmt::Leaf(self.symbol(name));
        }
        self.unknown("operation or rule", &call.name, cx.rs, NameKind::Statement);
        RStmt::Nil
    }

    fn op_args(&mut self, cx: &Cx, def: &ops::table::OpDef, args: &[Expr]) -> Vec<RExpr> {
        let n = args.len();
        // Operations not run read names as selector words where they are.
        let runs = matches!(def.run, ops::table::Run::Op(_));
        args.iter()
            .enumerate()
            .map(
                |(i, a)| match (if runs { def.mode(n, i) } else { ArgMode::Maybe }, &a.kind) {
                    (ArgMode::Selector, _) => self.selector_arg(cx, a),
                    (ArgMode::Maybe, _) => self.head(cx, a),
                    (ArgMode::Expr, _) => self.expr(cx, a),
                },
            )
            .collect()
    }

    fn set_stmt(&mut self, cx: &Cx, call: &ast::Call) -> RStmt {
        let span = call.span;
        let args = call.args.as_deref().unwrap_or(&[]);
        if args.len() != 2 {
            self.error(
                format!(
                    "`set` takes 2 arguments (attribute, value), found {}",
                    args.len()
                ),
                span,
            );
            return RStmt::Nil;
        }
        let ExprKind::Name(target) = &args[0].kind else {
            self.diags.push(
                Diagnostic::error(
                    "the first argument of `set` must be an attribute name",
                    args[0].span,
                )
                .with_label("expected an attribute name"),
            );
            return RStmt::Nil;
        };
        let t = if let Some(id) = self.find_attr(cx.rs, &target.name) {
            SetTarget::Attr(id)
        } else if let Some(f) =
            shape_fns::lookup(&target.name, 0).filter(|&f| shape_fns::is_settable(f))
        {
            SetTarget::Shape(f)
        } else {
            let d = Diagnostic::error(
                format!("`{}` is not an attribute that `set` can write", target.name),
                target.span,
            )
            .with_label("expected an `attr` of the rule file or a writable shape attribute");
            self.diags.push(d);
            return RStmt::Nil;
        };
        let value = self.expr(cx, &args[1]);
        RStmt::Op(OpCall {
            op: ops::table::set_op(t),
            args: vec![value],
            block: None,
            remainder_block: None,
            span,
        })
    }

    /// `imp(height = 20).Lot`: attribute values for this call only.
    fn dynamic_overrides(
        &mut self,
        cx: &Cx,
        rule_name: &str,
        list: &[ast::ImportOverride],
    ) -> Vec<(AttrId, RExpr)> {
        let Some((alias, _)) = rule_name.rsplit_once('.') else {
            return Vec::new();
        };
        let Some(&child) = self.tables[cx.rs as usize].imports.get(alias) else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for o in list {
            match o {
                ast::ImportOverride::Attr(n, e) => match self.find_attr(child, &n.name) {
                    Some(id) => {
                        let v = self.expr(cx, e);
                        out.push((id, v));
                    }
                    None => self.error(
                        format!("`{}` is not an attribute of `{alias}`", n.name),
                        n.span,
                    ),
                },
                ast::ImportOverride::Protect(n) | ast::ImportOverride::Rule { name: n, .. } => self
                    .error(
                        "only attribute values (`name = value`) can be set in a rule call",
                        n.span,
                    ),
            }
        }
        out
    }
}

/// How the heads of an operation's block are resolved: comp selectors
/// (`comp`), comp selectors and the keyword `remainder` (the setback
/// operations), or split sizes and plain keywords (everything else).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Heads {
    Comp,
    Setback,
    Plain,
}

/// `comp(fe) { all : e }`: the value of `e` on every face edge.
fn per_face_edge(e: RExpr) -> RExpr {
    let span = e.span;
    let head = RExpr {
        kind: RExprKind::CompHead {
            text: Arc::from("all"),
            expr: Box::new(RExpr {
                kind: RExprKind::CompSelector(crate::selectors::Selector::All, Vec::new()),
                span,
            }),
        },
        span,
    };
    RExpr {
        kind: RExprKind::CompFn {
            args: vec![RExpr::constant(Value::Str(Arc::from("fe")), span)],
            block: RBlock {
                parts: vec![RPart::Entry {
                    head,
                    depth: None,
                    op: cga_syntax::ast::BlockOp::Colon,
                    body: e,
                    span,
                }],
                repeat: false,
                span,
            },
        },
        span,
    }
}

#[derive(Clone, Copy)]
enum NameKind {
    Value,
    Statement,
}

fn arity_text(min: usize, max: usize) -> String {
    if min == max {
        min.to_string()
    } else {
        format!("{min} to {max}")
    }
}

/// Names of built-in functions, for "did you mean" hints.
const KNOWN_FUNCTIONS: &[&str] = &[
    "rand", "p", "print", "str", "float", "bool", "abs", "floor", "ceil", "sqrt", "sin", "cos",
    "tan", "min", "max", "clamp", "len", "size",
];

/// An attribute default with `with` locals: the locals are evaluated in
/// order into the frame, then the value.
fn wrap_locals(locals: Vec<RExpr>, value: RExpr) -> RExpr {
    RExpr {
        span: value.span,
        kind: RExprKind::WithLocals {
            locals,
            body: Box::new(value),
        },
    }
}

fn annotations(list: &[ast::Annotation]) -> Vec<AnnotationInfo> {
    list.iter()
        .map(|a| AnnotationInfo {
            name: a.name.name.clone(),
            args: a
                .args
                .iter()
                .map(|arg| match arg {
                    ast::AnnotationArg::Positional(e) => (None, literal(e)),
                    ast::AnnotationArg::Named(n, e) => (Some(n.name.clone()), literal(e)),
                    ast::AnnotationArg::Verbatim { key, text, .. } => (
                        key.as_ref().map(|k| k.name.clone()),
                        Some(Value::Str(Arc::from(text.as_str()))),
                    ),
                })
                .collect(),
        })
        .collect()
}

fn literal(e: &Expr) -> Option<Value> {
    match &e.kind {
        ExprKind::Float(x) => Some(Value::Float(*x)),
        ExprKind::Bool(b) => Some(Value::Bool(*b)),
        ExprKind::Str(s) => Some(Value::Str(Arc::from(s.as_str()))),
        ExprKind::Unary {
            op: ast::UnaryOp::Neg,
            operand,
            ..
        } => match literal(operand) {
            Some(Value::Float(x)) => Some(Value::Float(-x)),
            _ => None,
        },
        _ => None,
    }
}
