//! A compact, unambiguous text form of the syntax tree (S-expressions), for
//! tests and for looking at what the parser made of a file. Spans are left out.
//!
//! ```text
//! Lot --> extrude(10) split(y) { ~2 : A | { 1 : B. }* }*   comp(f) { top = NIL }
//! ```
//! prints as
//! ```text
//! (rule Lot (extrude 10) (split y {(~ 2) : A | {1 : B.}*}*) (comp f {top = NIL}))
//! ```
//!
//! Expressions: names as written, numbers as `f64` display (`1`, `0.5`),
//! strings quoted, `(call f a b)`, `(+ a b)`, `(.+ a b)` (element-wise),
//! `(neg a)`, `(not a)`, `(' e)` relative, `(~ e)` floating,
//! `[a b; c d]` arrays, `(range a b)`, `(range a step b)`, `(index a i j)`,
//! `(case (c v) ... (else v))`, `(stoch (30 v) ... (else v))`,
//! `(compfn (args) {head : v | ...})`.
//! Statements: `(op args...)`, `Rule` (no parentheses), `(Rule)` (empty
//! parentheses), `Leaf.`, `NIL`, `[push body]`, blocks `{part | part}*`.

use std::fmt::Write;

use crate::ast::*;

/// The whole module, one item per line.
pub fn module(m: &Module) -> String {
    let mut out = String::new();
    for item in &m.items {
        out.push_str(&self::item(item));
        out.push('\n');
    }
    out
}

pub fn item(item: &Item) -> String {
    let mut out = String::new();
    match item {
        Item::Version { value, .. } => {
            let _ = write!(out, "(version {value:?})");
        }
        Item::Style { name, extends, .. } => {
            let _ = write!(out, "(style {}", name.name);
            if let Some(base) = extends {
                let _ = write!(out, " extends {}", base.name);
            }
            out.push(')');
        }
        Item::Import(import) => {
            out.push_str("(import");
            annotations(&mut out, &import.annotations);
            if let Some(alias) = &import.alias {
                let _ = write!(out, " {}", alias.name);
            }
            if let Some(styles) = &import.styles {
                let names: Vec<_> = styles.iter().map(|s| s.name.as_str()).collect();
                let _ = write!(out, " (styles {})", names.join(" "));
            }
            let _ = write!(out, " {:?}", import.path);
            if let Some(list) = &import.overrides {
                out.push(' ');
                overrides(&mut out, list);
            }
            out.push(')');
        }
        Item::Attr(attr) => {
            out.push_str("(attr");
            annotations(&mut out, &attr.annotations);
            let _ = write!(out, " {}", attr.name.name);
            locals(&mut out, &attr.locals);
            let _ = write!(out, " {})", expr(&attr.value));
        }
        Item::Function(f) => {
            out.push_str(if f.is_const { "(const" } else { "(fn" });
            annotations(&mut out, &f.annotations);
            let _ = write!(out, " {}", f.name.name);
            params(&mut out, &f.params);
            locals(&mut out, &f.locals);
            let _ = write!(out, " {})", expr(&f.value));
        }
        Item::Rule(rule) => {
            out.push_str(match rule.kind {
                RuleKind::Plain => "(rule",
                RuleKind::Start => "(start-rule",
                RuleKind::Extension => "(extension-rule",
            });
            annotations(&mut out, &rule.annotations);
            let _ = write!(out, " {}", rule.name.name);
            params(&mut out, &rule.params);
            locals(&mut out, &rule.locals);
            let b = body(&rule.body);
            if !b.is_empty() {
                out.push(' ');
                out.push_str(&b);
            }
            out.push(')');
        }
    }
    out
}

fn annotations(out: &mut String, list: &[Annotation]) {
    for a in list {
        let _ = write!(out, " @{}", a.name.name);
        if !a.args.is_empty() {
            let args: Vec<String> = a
                .args
                .iter()
                .map(|arg| match arg {
                    AnnotationArg::Positional(e) => expr(e),
                    AnnotationArg::Named(name, e) => format!("{}={}", name.name, expr(e)),
                    AnnotationArg::Verbatim { key, text, .. } => match key {
                        Some(k) => format!("{}={text:?}", k.name),
                        None => format!("{text:?}"),
                    },
                })
                .collect();
            let _ = write!(out, "({})", args.join(" "));
        }
    }
}

fn params(out: &mut String, list: &[Param]) {
    if list.is_empty() {
        return;
    }
    let ps: Vec<String> = list
        .iter()
        .map(|p| match p.ty {
            None => p.name.name.clone(),
            Some(ty) => {
                let ty = match ty {
                    TypeName::Float => "float",
                    TypeName::Bool => "bool",
                    TypeName::String => "string",
                    TypeName::FloatArray => "float[]",
                    TypeName::BoolArray => "bool[]",
                    TypeName::StringArray => "string[]",
                };
                format!("{ty} {}", p.name.name)
            }
        })
        .collect();
    let _ = write!(out, "({})", ps.join(", "));
}

fn locals(out: &mut String, list: &[LocalVar]) {
    if list.is_empty() {
        return;
    }
    let ls: Vec<String> = list
        .iter()
        .map(|l| format!("{} := {}", l.name.name, expr(&l.value)))
        .collect();
    let _ = write!(out, " (with {})", ls.join(", "));
}

fn overrides(out: &mut String, list: &[ImportOverride]) {
    let parts: Vec<String> = list
        .iter()
        .map(|o| match o {
            ImportOverride::Protect(name) => name.name.clone(),
            ImportOverride::Attr(name, e) => format!("{} = {}", name.name, expr(e)),
            ImportOverride::Rule {
                name,
                params: ps,
                body: b,
            } => {
                let mut s = name.name.clone();
                params(&mut s, ps);
                let _ = write!(s, " --> {}", body(b));
                s
            }
        })
        .collect();
    let _ = write!(out, "({})", parts.join(", "));
}

/// A body: statements separated by spaces, or a chain.
pub fn body(b: &Body) -> String {
    match b {
        Body::Ops(stmts) => stmts.iter().map(stmt).collect::<Vec<_>>().join(" "),
        Body::Case(chain) => chain_text("case", &chain.branches, chain.otherwise.as_deref(), body),
        Body::Stochastic(chain) => {
            chain_text("stoch", &chain.branches, chain.otherwise.as_deref(), body)
        }
    }
}

fn chain_text<T>(
    kind: &str,
    branches: &[(Expr, T)],
    otherwise: Option<&T>,
    value: fn(&T) -> String,
) -> String {
    let mut out = format!("({kind}");
    for (cond, v) in branches {
        let _ = write!(out, " ({} {})", expr(cond), value(v));
    }
    if let Some(v) = otherwise {
        let _ = write!(out, " (else {})", value(v));
    }
    out.push(')');
    out
}

pub fn stmt(s: &Stmt) -> String {
    match s {
        Stmt::Call(call) => {
            let mut out = String::new();
            let bare =
                call.args.is_none() && call.block.is_none() && call.import_overrides.is_none();
            if bare {
                return call.name.name.clone();
            }
            let _ = write!(out, "({}", call.name.name);
            if let Some(list) = &call.import_overrides {
                out.push_str(" import");
                overrides(&mut out, list);
            }
            for a in call.args.iter().flatten() {
                let _ = write!(out, " {}", expr(a));
            }
            for b in call.block.iter().chain(&call.remainder_block) {
                let _ = write!(out, " {}", block(b, body));
            }
            out.push(')');
            out
        }
        Stmt::Leaf(name) => format!("{}.", name.name),
        Stmt::Nil(_) => "NIL".to_string(),
        Stmt::Push(b, _) => format!("[{}]", body(b)),
    }
}

pub fn block<T>(b: &Block<T>, value: fn(&T) -> String) -> String {
    let parts: Vec<String> = b
        .parts
        .iter()
        .map(|part| match part {
            BlockPart::Entry(e) => {
                let op = match e.op {
                    BlockOp::Colon => ":",
                    BlockOp::Equals => "=",
                    BlockOp::EqualsColon => "=:",
                };
                match &e.depth {
                    Some(depth) => format!(
                        "{} {op} {} : {}",
                        expr(&e.head),
                        expr(depth),
                        value(&e.body)
                    ),
                    None => format!("{} {op} {}", expr(&e.head), value(&e.body)),
                }
            }
            BlockPart::Group(g) => block(g, value),
            BlockPart::Unlabeled { body, .. } => value(body),
        })
        .collect();
    format!(
        "{{{}}}{}",
        parts.join(" | "),
        if b.repeat { "*" } else { "" }
    )
}

pub fn expr(e: &Expr) -> String {
    match &e.kind {
        ExprKind::Float(v) => format!("{v}"),
        ExprKind::Bool(v) => format!("{v}"),
        ExprKind::Str(s) => format!("{s:?}"),
        ExprKind::Name(name) => name.name.clone(),
        ExprKind::Call { name, args } => {
            let mut out = format!("(call {}", name.name);
            for a in args {
                let _ = write!(out, " {}", expr(a));
            }
            out.push(')');
            out
        }
        ExprKind::CompFn { args, block: b } => {
            let args: Vec<String> = args.iter().map(expr).collect();
            format!("(compfn ({}) {})", args.join(" "), block(b, expr))
        }
        ExprKind::Unary {
            op,
            elementwise,
            operand,
        } => {
            let op = match op {
                UnaryOp::Neg => "neg",
                UnaryOp::Plus => "plus",
                UnaryOp::Not => "not",
            };
            format!(
                "({}{op} {})",
                if *elementwise { "." } else { "" },
                expr(operand)
            )
        }
        ExprKind::Binary {
            op,
            elementwise,
            lhs,
            rhs,
        } => {
            let op = match op {
                BinaryOp::Add => "+",
                BinaryOp::Sub => "-",
                BinaryOp::Mul => "*",
                BinaryOp::Div => "/",
                BinaryOp::Rem => "%",
                BinaryOp::Eq => "==",
                BinaryOp::Ne => "!=",
                BinaryOp::Lt => "<",
                BinaryOp::Le => "<=",
                BinaryOp::Gt => ">",
                BinaryOp::Ge => ">=",
                BinaryOp::And => "&&",
                BinaryOp::Or => "||",
            };
            format!(
                "({}{op} {} {})",
                if *elementwise { "." } else { "" },
                expr(lhs),
                expr(rhs)
            )
        }
        ExprKind::Array(rows) => {
            let rows: Vec<String> = rows
                .iter()
                .map(|row| row.iter().map(expr).collect::<Vec<_>>().join(" "))
                .collect();
            format!("[{}]", rows.join("; "))
        }
        ExprKind::Range { base, step, limit } => match step {
            Some(step) => format!("(range {} {} {})", expr(base), expr(step), expr(limit)),
            None => format!("(range {} {})", expr(base), expr(limit)),
        },
        ExprKind::Index { base, indices } => {
            let mut out = format!("(index {}", expr(base));
            for i in indices {
                let _ = write!(out, " {}", expr(i));
            }
            out.push(')');
            out
        }
        ExprKind::Case(chain) => {
            chain_text("case", &chain.branches, chain.otherwise.as_deref(), expr)
        }
        ExprKind::Stochastic(chain) => {
            chain_text("stoch", &chain.branches, chain.otherwise.as_deref(), expr)
        }
        ExprKind::Relative(inner) => format!("(' {})", expr(inner)),
        ExprKind::Floating(inner) => format!("(~ {})", expr(inner)),
    }
}
