//! A resolved rule program: every name of the rule files turned into an index,
//! so that derivation never looks anything up by string.
//!
//! One [`RuleSet`] exists per loaded rule file *instance*: the main file, and
//! each `import` of another file (importing one file twice, with different
//! attribute overrides, gives two rule sets). Attributes live in one global
//! table of slots so that attribute propagation across imports is just two
//! names mapping to the same slot.

use std::sync::Arc;

use cga_syntax::Span;
use cga_value::Value;

use crate::expr::{RBody, RExpr};

/// Index of an attribute slot in [`Program::attrs`].
pub type AttrId = u32;
/// Index of a function (or const) in [`Program::functions`].
pub type FuncId = u32;
/// Index of a rule in [`Program::rules`].
pub type RuleId = u32;
/// Index of a rule set in [`Program::rulesets`].
pub type RuleSetId = u32;

/// An annotation as written (`@Range(min=1, max=2)`), kept for tools and for
/// the start rule choice; it never changes what is generated.
#[derive(Clone, Debug)]
pub struct AnnotationInfo {
    pub name: String,
    /// Positional arguments (name `None`) and named ones, as constant values
    /// where they are constant.
    pub args: Vec<(Option<String>, Option<Value>)>,
}

#[derive(Debug)]
pub struct AttrDef {
    /// The name as declared in its rule file.
    pub name: String,
    /// The rule set whose declaration provides the default.
    pub ruleset: RuleSetId,
    /// Default value expression, evaluated once per initial shape.
    pub default: RExpr,
    /// Number of local variable slots the default expression needs (`with`).
    pub frame_size: usize,
    pub annotations: Vec<AnnotationInfo>,
    pub span: Span,
}

#[derive(Debug)]
pub struct FunctionDef {
    pub name: String,
    pub ruleset: RuleSetId,
    pub arity: usize,
    /// `const`: evaluated once per initial shape (only when `arity == 0`).
    pub is_const: bool,
    /// Parameters, then `with` locals.
    pub frame_size: usize,
    pub locals: Vec<RExpr>,
    pub body: RExpr,
    pub span: Span,
}

#[derive(Debug)]
pub struct RuleDef {
    pub name: String,
    pub ruleset: RuleSetId,
    pub arity: usize,
    /// Parameters, then `with` locals.
    pub frame_size: usize,
    pub locals: Vec<RExpr>,
    pub body: RBody,
    pub annotations: Vec<AnnotationInfo>,
    pub is_start: bool,
    /// The rule's name as a symbol (shapes carry the name of their rule).
    pub symbol: u32,
    pub span: Span,
}

/// One instance of a rule file.
#[derive(Debug, Default)]
pub struct RuleSet {
    /// The import alias path (`""` for the main file, `"imp"`, `"imp.sub"`).
    pub prefix: String,
    pub path: std::path::PathBuf,
}

#[derive(Debug, Default)]
pub struct Program {
    pub rulesets: Vec<RuleSet>,
    pub attrs: Vec<AttrDef>,
    pub functions: Vec<FunctionDef>,
    pub rules: Vec<RuleDef>,
    /// Attributes of the main rule file by name, for `--attr NAME=VALUE`.
    pub main_attrs: Vec<(String, AttrId)>,
    /// Rules of the main rule file by name (all overloads).
    pub main_rules: Vec<(String, RuleId)>,
    /// Leaf and rule names, interned: shapes carry a `u32` name.
    pub symbols: Vec<Arc<str>>,
    /// Whether a rule calls `getTreeKey`: only then are the shapes' tree
    /// keys kept during derivation.
    pub uses_tree_key: bool,
    /// The styles of the main rule file, `Default` first, in file order.
    pub styles: Vec<String>,
    /// Which rules the first pass of context queries applies (see
    /// `crate::context::FirstPass`), worked out on first use.
    pub(crate) first_pass: std::sync::OnceLock<crate::context::FirstPass>,
    /// Per rule, whether it can reach an operation that uses trim planes
    /// (see `ops::comp::uses_trim_planes`), worked out on first use.
    pub(crate) trim_rules: std::sync::OnceLock<Vec<bool>>,
    /// The texture coordinate sets the rules can read (see
    /// `crate::uv_use`), worked out on first use.
    pub(crate) uv_sets_read: std::sync::OnceLock<crate::uv_use::UvSets>,
    /// Which operations leave geometry nothing reads (see
    /// `crate::geometry_use`), worked out on first use.
    pub(crate) geometry_use: std::sync::OnceLock<crate::geometry_use::GeometryUse>,
    /// Which rules' subtrees may be derived once per key (see
    /// `crate::subtree_memo`), worked out on first use.
    pub(crate) subtree_memo: std::sync::OnceLock<crate::subtree_memo::SubtreeMemo>,
}

impl Program {
    /// The texture coordinate sets the rules can read (see `crate::uv_use`).
    pub fn uv_sets_read(&self) -> crate::uv_use::UvSets {
        *self
            .uv_sets_read
            .get_or_init(|| crate::uv_use::sets_read(self))
    }

    /// Where the rules can read a shape's geometry (see
    /// `crate::geometry_use`).
    pub fn geometry_use(&self) -> &crate::geometry_use::GeometryUse {
        self.geometry_use
            .get_or_init(|| crate::geometry_use::GeometryUse::of(self))
    }

    /// Which rules' subtrees may be derived once per key (see
    /// `crate::subtree_memo`).
    pub fn subtree_memo(&self) -> &crate::subtree_memo::SubtreeMemo {
        self.subtree_memo
            .get_or_init(|| crate::subtree_memo::SubtreeMemo::of(self))
    }

    /// The program of one rule file's text (tests of analyses).
    #[cfg(test)]
    pub(crate) fn from_text(src: &str) -> Program {
        let world = cga_world::MemoryWorld::new().with("/r/rules.cga", src);
        let mut sources = cga_syntax::SourceMap::new();
        let loaded = crate::load(&world, std::path::Path::new("/r/rules.cga"), &mut sources);
        assert!(!loaded.has_errors(), "{:?}", loaded.diagnostics);
        loaded.program
    }

    /// The attribute of the main file called `name`.
    pub fn main_attr(&self, name: &str) -> Option<AttrId> {
        self.main_attrs
            .iter()
            .find(|(n, _)| n == name)
            .map(|&(_, id)| id)
    }

    /// The start rule: `name` if given, else the main file's `@StartRule` (or
    /// `start` rule), else `Lot`. Only rules without parameters qualify.
    pub fn start_rule(&self, name: Option<&str>) -> Result<RuleId, String> {
        let zero_arity = |n: &str| {
            self.main_rules
                .iter()
                .find(|(rn, id)| rn == n && self.rules[*id as usize].arity == 0)
                .map(|&(_, id)| id)
        };
        if let Some(name) = name {
            return zero_arity(name)
                .ok_or_else(|| format!("start rule `{name}` is not defined in the rule file"));
        }
        let annotated = self.main_rules.iter().find(|(_, id)| {
            let r = &self.rules[*id as usize];
            r.arity == 0 && (r.is_start || r.annotations.iter().any(|a| a.name == "StartRule"))
        });
        if let Some(&(_, id)) = annotated {
            return Ok(id);
        }
        zero_arity("Lot").ok_or_else(|| {
            "no start rule: mark a rule with @StartRule, define `Lot`, or pass --start-rule"
                .to_string()
        })
    }

    pub fn rule_symbol(&self, rule: RuleId) -> u32 {
        self.rules[rule as usize].symbol
    }

    pub fn symbol(&self, id: u32) -> &str {
        &self.symbols[id as usize]
    }
}
