//! The CGA parser: tokens to [`ast::Module`], hand-written recursive descent.
//!
//! CGA has no statement terminators and newlines mean nothing, so where a
//! rule body ends is found by lookahead: a body stops where a new top-level
//! item starts (see [`Parser::is_item_start`]). To keep that lookahead O(1)
//! the partner of every bracket is computed once up front ([`Parser::partner`]).
//!
//! Error recovery, so that one run reports every error of a file:
//! - inside an argument list, array or index, a bad token makes the parser
//!   jump to the matching closing bracket;
//! - inside a block (`{ a : X | b : Y }`) it resumes at the next `|` or `}`;
//! - inside a push (`[ ... ]`) at the `]`;
//! - otherwise at the next top-level item.
//!
//! After the first error in a region, follow-up errors of the same region are
//! suppressed (they are nearly always consequences). Nesting deeper than
//! [`MAX_DEPTH`] is reported once and the rest of the item is skipped, so the
//! parser's recursion is bounded whatever the input.

mod body;
mod expr;

use crate::ast::*;
use crate::diagnostic::Diagnostic;
use crate::lexer::{self, Tok, Token};
use crate::span::{FileId, Span};

/// Deepest nesting of expressions, bodies and blocks the parser accepts,
/// counted in parser levels (a parenthesis costs two, as does a nested
/// block; every operator of a chain `a + b + ...` one, since it nests the
/// tree). Real rule files stay far below. The limit bounds the recursion:
/// parsing needs about 700 KiB of stack in a debug build and 200 KiB in a
/// release build, well inside a thread's default 2 MiB; and it bounds the
/// depth of the tree, which is dropped (and evaluated) recursively.
pub(crate) const MAX_DEPTH: u32 = 200;

const NO_PARTNER: u32 = u32::MAX;

pub(crate) struct Parser<'t> {
    file: FileId,
    text: &'t str,
    toks: Vec<Token>,
    /// For each bracket token, the index of its partner; `NO_PARTNER` otherwise.
    partner: Vec<u32>,
    pos: usize,
    diags: Vec<Diagnostic>,
    depth: u32,
    /// Set when nesting exceeded [`MAX_DEPTH`]: the parser then sees end of
    /// file (and reports nothing) until the top level skips to the next item.
    bail: bool,
    /// Start offsets of the lexer's errors, ascending. An unclosed bracket
    /// after an unterminated string is the string's fault and not reported.
    lex_errors: Vec<u32>,
}

pub(crate) fn parse(file: FileId, text: &str) -> (Module, Vec<Diagnostic>) {
    let lexed = lexer::lex(file, text);
    let mut parser = Parser::new(file, text, lexed.tokens);
    parser.lex_errors = lexed
        .diagnostics
        .iter()
        .filter_map(|d| d.span.map(|s| s.start))
        .collect();
    let module = parser.parse_module();
    let mut diags = lexed.diagnostics;
    diags.extend(parser.diags);
    // Lexer and parser errors interleaved in source order.
    diags.sort_by_key(|d| d.span.map(|s| s.start));
    (module, diags)
}

impl<'t> Parser<'t> {
    fn new(file: FileId, text: &'t str, toks: Vec<Token>) -> Parser<'t> {
        let partner = match_brackets(&toks);
        Parser {
            file,
            text,
            toks,
            partner,
            pos: 0,
            diags: Vec::new(),
            depth: 0,
            bail: false,
            lex_errors: Vec::new(),
        }
    }

    // ----- token access -------------------------------------------------

    /// Kind of the token `k` positions ahead (end of file past the end, and
    /// everywhere while bailing out).
    fn nth(&self, k: usize) -> Tok {
        if self.bail {
            return Tok::Eof;
        }
        self.kind_at(self.pos + k)
    }

    fn cur(&self) -> Tok {
        self.nth(0)
    }

    fn kind_at(&self, i: usize) -> Tok {
        self.toks.get(i).map_or(Tok::Eof, |t| t.kind)
    }

    fn tok_at(&self, i: usize) -> Token {
        *self
            .toks
            .get(i)
            .unwrap_or_else(|| self.toks.last().expect("token list ends with Eof"))
    }

    fn span_at(&self, i: usize) -> Span {
        let t = self.tok_at(i);
        Span::new(self.file, t.start, t.end)
    }

    fn cur_span(&self) -> Span {
        self.span_at(self.pos)
    }

    /// End of the last consumed token (start of the current one at the very beginning).
    fn prev_end(&self) -> u32 {
        if self.pos == 0 {
            self.tok_at(0).start
        } else {
            self.tok_at(self.pos - 1).end
        }
    }

    /// Span from `start` (a byte offset) to the end of the last consumed token.
    fn span_from(&self, start: u32) -> Span {
        Span::new(self.file, start, self.prev_end().max(start))
    }

    fn text_at(&self, i: usize) -> &'t str {
        let t = self.tok_at(i);
        &self.text[t.start as usize..t.end as usize]
    }

    fn bump(&mut self) {
        if self.kind_at(self.pos) != Tok::Eof {
            self.pos += 1;
        }
    }

    fn eat(&mut self, kind: Tok) -> bool {
        if self.cur() == kind {
            self.bump();
            true
        } else {
            false
        }
    }

    /// Whether token `j` starts exactly where token `i` ends (no space or comment between).
    fn touches(&self, i: usize, j: usize) -> bool {
        self.tok_at(i).end == self.tok_at(j).start
    }

    fn partner_of(&self, i: usize) -> Option<usize> {
        match self.partner.get(i) {
            Some(&p) if p != NO_PARTNER => Some(p as usize),
            _ => None,
        }
    }

    /// Tokens that can serve as a name: identifiers and `start`, which is a
    /// keyword only in front of a rule head (`start(20)` calls the start rule).
    fn is_name(kind: Tok) -> bool {
        matches!(kind, Tok::Ident | Tok::Start)
    }

    fn ident_here(&self) -> Ident {
        Ident {
            name: self.text_at(self.pos).to_string(),
            span: self.cur_span(),
        }
    }

    // ----- diagnostics --------------------------------------------------

    /// How the current token is named in "found ..." messages.
    fn found(&self) -> String {
        self.describe(self.pos)
    }

    fn describe(&self, i: usize) -> String {
        let kind = if self.bail { Tok::Eof } else { self.kind_at(i) };
        match kind {
            Tok::Ident => format!("identifier `{}`", self.text_at(i)),
            Tok::Number => format!("number `{}`", self.text_at(i)),
            Tok::Str => {
                let text = self.text_at(i);
                if text.chars().count() > 24 {
                    format!("string {}...", text.chars().take(20).collect::<String>())
                } else {
                    format!("string {text}")
                }
            }
            other => other.describe().to_string(),
        }
    }

    fn error(&mut self, message: impl Into<String>, span: Span, label: impl Into<String>) {
        if self.bail {
            return;
        }
        self.diags
            .push(Diagnostic::error(message, span).with_label(label));
    }

    /// `expected {what}, found {current token}`, pointing at the current token.
    fn expected(&mut self, what: &str, label: &str) {
        let message = format!("expected {what}, found {}", self.found());
        let span = self.cur_span();
        self.error(message, span, label);
    }

    /// Whether the lexer reported an error between token `from` and the
    /// current token: errors about brackets in that stretch are then
    /// consequences (an unterminated string swallowed the closing bracket).
    fn lex_error_since(&self, from: usize) -> bool {
        let start = self.tok_at(from).start;
        let end = self.tok_at(self.pos).start;
        let i = self.lex_errors.partition_point(|&e| e < start);
        self.lex_errors.get(i).is_some_and(|&e| e <= end)
    }

    /// Appends a note to the last diagnostic.
    fn note(&mut self, note: String) {
        if let Some(d) = self.diags.last_mut() {
            d.notes.push(note);
        }
    }

    /// `line L, column C` of a byte offset, for notes about a second place.
    fn line_col(&self, offset: u32) -> (usize, usize) {
        let before = &self.text[..(offset as usize).min(self.text.len())];
        let line = before.bytes().filter(|&b| b == b'\n').count() + 1;
        let line_start = before.rfind('\n').map_or(0, |p| p + 1);
        (line, before[line_start..].chars().count() + 1)
    }

    fn note_opened_at(&mut self, what: &str, open: usize) {
        // `what` names the bracket, e.g. "`(`".
        let (line, col) = self.line_col(self.tok_at(open).start);
        self.note(format!(
            "the {what} was opened at line {line}, column {col}"
        ));
    }

    /// Enters one nesting level; `false` (after reporting once) when too deep.
    fn enter(&mut self) -> bool {
        if self.bail {
            return false;
        }
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            let span = self.cur_span();
            self.error(
                "expressions or blocks are nested too deeply",
                span,
                "too deeply nested",
            );
            self.note(
                "the parser accepts about 100 levels of parentheses or nested blocks; \
                 the rest of this declaration is skipped"
                    .to_string(),
            );
            self.bail = true;
            self.depth -= 1;
            return false;
        }
        true
    }

    fn leave(&mut self) {
        self.depth = self.depth.saturating_sub(1);
    }

    // ----- lookahead ----------------------------------------------------

    /// Whether token `i` starts a top-level item: `@`, `attr`, `const`,
    /// `import`, `style`, `version`, `extension`, `start Name -->`,
    /// `Name -->`, `Name(...) -->`, `Name with (...)`, `Name =`, `Name(...) =`.
    ///
    /// With `soft == false` the last two (function definitions) are not
    /// counted: inside brackets `side = X` is a comp entry, not a function.
    fn is_item_start_at(&self, i: usize, soft: bool) -> bool {
        match self.kind_at(i) {
            Tok::At
            | Tok::Attr
            | Tok::Const
            | Tok::Import
            | Tok::Style
            | Tok::Version
            | Tok::Extension => true,
            // `start Name -->`, or a rule or function named `start`.
            Tok::Start => {
                (Self::is_name(self.kind_at(i + 1)) && self.is_head_tail(i + 2, false))
                    || self.is_head_tail(i + 1, soft)
            }
            Tok::Ident => self.is_head_tail(i + 1, soft),
            _ => false,
        }
    }

    fn is_item_start(&self, soft: bool) -> bool {
        !self.bail && self.is_item_start_at(self.pos, soft)
    }

    /// Whether what follows a name at `i` makes it a rule or function head.
    fn is_head_tail(&self, i: usize, soft: bool) -> bool {
        let tail = |k: Tok| matches!(k, Tok::Arrow | Tok::With) || (soft && k == Tok::Eq);
        match self.kind_at(i) {
            Tok::LParen => self
                .partner_of(i)
                .is_some_and(|j| tail(self.kind_at(j + 1))),
            k => tail(k),
        }
    }

    /// `30% :`, the start of a stochastic branch.
    fn is_percent_at(&self, i: usize) -> bool {
        !self.bail
            && self.kind_at(i) == Tok::Number
            && self.kind_at(i + 1) == Tok::Percent
            && self.kind_at(i + 2) == Tok::Colon
    }

    /// Skips to the next top-level item (or end of file).
    fn skip_to_item_start(&mut self) {
        while self.cur() != Tok::Eof && !self.is_item_start(true) {
            self.bump();
        }
    }

    // ----- items --------------------------------------------------------

    fn parse_module(&mut self) -> Module {
        let mut items = Vec::new();
        loop {
            self.bail = false;
            self.depth = 0;
            if self.cur() == Tok::Eof {
                break;
            }
            let start = self.pos;
            let errors = self.diags.len();
            if let Some(item) = self.parse_item() {
                items.push(item);
            }
            self.bail = false;
            if self.diags.len() == errors && Self::is_name(self.cur()) && self.pos != start {
                // `attr h = 10  Lot extrude(10)`: let the next round read
                // `Lot` as a definition and report its missing `-->`.
                continue;
            }
            if self.cur() != Tok::Eof && !self.is_item_start(true) {
                if self.diags.len() == errors {
                    self.expected("an operator or the next declaration", "unexpected here");
                }
                self.skip_to_item_start();
            }
            if self.pos == start {
                // Nothing could be made of this token: never loop on it.
                self.bump();
            }
        }
        Module { items }
    }

    fn parse_item(&mut self) -> Option<Item> {
        let annotations = self.parse_annotations();
        let first_annotation = annotations.first().map(|a| a.span);
        match self.cur() {
            Tok::Import => Some(Item::Import(self.parse_import(annotations))),
            Tok::Attr => self.parse_attr(annotations).map(Item::Attr),
            Tok::Const => self.parse_definition(annotations),
            Tok::Start | Tok::Extension | Tok::Ident => self.parse_definition(annotations),
            Tok::Version => {
                let start = self.tok_at(self.pos).start;
                self.bump();
                if self.cur() == Tok::Str {
                    let value = lexer::string_value(self.text_at(self.pos));
                    self.bump();
                    Some(Item::Version {
                        value,
                        span: self.span_from(start),
                        annotations,
                    })
                } else {
                    self.expected(
                        "a version string such as \"2023.0\" after `version`",
                        "expected a string",
                    );
                    None
                }
            }
            Tok::Style => {
                let start = self.tok_at(self.pos).start;
                self.bump();
                let name = self.expect_name("a style name after `style`")?;
                let extends = if self.eat(Tok::Extends) {
                    Some(self.expect_name("the base style name after `extends`")?)
                } else {
                    None
                };
                Some(Item::Style {
                    name,
                    extends,
                    span: self.span_from(start),
                    annotations,
                })
            }
            Tok::Eof if first_annotation.is_some() => {
                self.error(
                    "annotation is not followed by a declaration",
                    first_annotation.unwrap_or_default(),
                    "nothing to annotate",
                );
                None
            }
            _ => {
                self.expected(
                    "a declaration (`attr`, `const`, `import`, a rule `Name --> ...` or a function `name = ...`)",
                    "expected a declaration",
                );
                None
            }
        }
    }

    fn expect_name(&mut self, what: &str) -> Option<Ident> {
        if Self::is_name(self.cur()) {
            let ident = self.ident_here();
            self.bump();
            Some(ident)
        } else {
            self.expected(what, "expected a name");
            None
        }
    }

    /// Consumes `kind` or reports `expected {what}` (without consuming).
    fn expect(&mut self, kind: Tok, what: &str, label: &str) -> bool {
        if self.eat(kind) {
            true
        } else {
            self.expected(what, label);
            false
        }
    }

    fn parse_annotations(&mut self) -> Vec<Annotation> {
        let mut annotations = Vec::new();
        while self.cur() == Tok::At {
            let start = self.tok_at(self.pos).start;
            self.bump();
            let Some(name) = self.expect_name("an annotation name after `@`") else {
                continue;
            };
            let mut args = Vec::new();
            if self.cur() == Tok::LParen {
                let open = self.pos;
                self.bump();
                if !self.eat(Tok::RParen) {
                    loop {
                        let mark = self.diags.len();
                        args.push(self.parse_annotation_arg(open));
                        if self.eat(Tok::Comma) {
                            continue;
                        }
                        if self.eat(Tok::RParen) {
                            break;
                        }
                        self.close_list_after_error(
                            open,
                            mark,
                            "`)` to close the annotation arguments",
                            "`,` or `)`",
                        );
                        break;
                    }
                }
            }
            annotations.push(Annotation {
                name,
                args,
                span: self.span_from(start),
            });
        }
        annotations
    }

    /// One argument of an annotation: `value` or `key=value`. A value that
    /// is not a CGA expression up to the next `,` or `)` is kept as written
    /// ([`AnnotationArg::Verbatim`]), without an error.
    fn parse_annotation_arg(&mut self, open: usize) -> AnnotationArg {
        let key = if Self::is_name(self.cur()) && self.nth(1) == Tok::Eq {
            let key = self.ident_here();
            self.bump();
            self.bump();
            Some(key)
        } else {
            None
        };
        let (mark, at, bail) = (self.diags.len(), self.pos, self.bail);
        let value = self.parse_expr();
        if self.diags.len() == mark && matches!(self.cur(), Tok::Comma | Tok::RParen) {
            return match key {
                Some(k) => AnnotationArg::Named(k, value),
                None => AnnotationArg::Positional(value),
            };
        }
        // Not an expression: back to its start, then over balanced
        // brackets to the `,` or `)` that ends it (never past the
        // annotation's own closing parenthesis).
        self.diags.truncate(mark);
        self.pos = at;
        self.bail = bail;
        let end = self.partner_of(open).unwrap_or(usize::MAX);
        while self.pos < end && !matches!(self.cur(), Tok::Comma | Tok::RParen | Tok::Eof) {
            match self.partner_of(self.pos) {
                Some(close) if close > self.pos && close < end => self.pos = close + 1,
                _ => self.bump(),
            }
        }
        let start = self.tok_at(at).start;
        let stop = if self.pos > at {
            self.tok_at(self.pos - 1).end
        } else {
            start
        };
        AnnotationArg::Verbatim {
            key,
            text: self.text[start as usize..stop as usize].to_string(),
            span: Span::new(self.file, start, stop),
        }
    }

    /// After a list element that is not followed by a separator or the
    /// closing bracket: report (unless the element already did) and continue
    /// after the matching closing bracket if there is one.
    fn close_list_after_error(&mut self, open: usize, mark: usize, what: &str, label: &str) {
        if self.diags.len() == mark && !self.lex_error_since(open) {
            self.expected(what, &format!("expected {label}"));
            if self.partner_of(open).is_none() {
                let kind = self.kind_at(open).describe();
                self.note_opened_at(kind, open);
            }
        }
        self.skip_past_partner(open);
    }

    /// Moves past the bracket matching the one at `open`, if it lies ahead.
    fn skip_past_partner(&mut self, open: usize) {
        if let Some(close) = self.partner_of(open) {
            if close >= self.pos && !self.bail {
                self.pos = close + 1;
            }
        }
    }

    fn parse_import(&mut self, annotations: Vec<Annotation>) -> ImportDecl {
        let start = self.tok_at(self.pos).start;
        self.bump();
        let mark = self.diags.len();
        let mut alias = None;
        let mut styles = None;
        if Self::is_name(self.cur()) {
            alias = Some(self.ident_here());
            self.bump();
            if self.cur() == Tok::LParen {
                styles = Some(self.parse_name_list("a style name"));
            }
            self.expect(
                Tok::Colon,
                "`:` between the import name and the file path",
                "expected `:`",
            );
        }
        let (path, path_span) = if self.cur() == Tok::Str {
            let value = lexer::string_value(self.text_at(self.pos));
            let span = self.cur_span();
            self.bump();
            (value, span)
        } else {
            if self.diags.len() == mark {
                self.expected(
                    "the path of the imported rule file as a string",
                    "expected a string",
                );
            }
            (
                String::new(),
                Span::new(self.file, self.prev_end(), self.prev_end()),
            )
        };
        let overrides = if self.cur() == Tok::LParen {
            Some(self.parse_import_overrides())
        } else {
            None
        };
        ImportDecl {
            annotations,
            alias,
            styles,
            path,
            path_span,
            overrides,
            span: self.span_from(start),
        }
    }

    /// `( a, b, c )`: names only (import styles).
    fn parse_name_list(&mut self, what: &str) -> Vec<Ident> {
        let open = self.pos;
        self.bump();
        let mut names = Vec::new();
        if self.eat(Tok::RParen) {
            return names;
        }
        loop {
            let mark = self.diags.len();
            if let Some(name) = self.expect_name(what) {
                names.push(name);
            }
            if self.eat(Tok::Comma) {
                continue;
            }
            if self.eat(Tok::RParen) {
                break;
            }
            self.close_list_after_error(open, mark, "`)` to close the list", "`,` or `)`");
            break;
        }
        names
    }

    /// `( height, width = 20, Roof --> roofHip(30), Col(h) --> X )` after an
    /// import path or in a dynamic import `imp( ... ).Lot`. Empty `( )` is
    /// an empty list.
    fn parse_import_overrides(&mut self) -> Vec<ImportOverride> {
        let open = self.pos;
        self.bump();
        let mut list = Vec::new();
        if self.eat(Tok::RParen) {
            return list;
        }
        loop {
            let mark = self.diags.len();
            if let Some(name) = self.expect_name("an attribute or rule name") {
                match self.cur() {
                    Tok::Eq => {
                        self.bump();
                        list.push(ImportOverride::Attr(name, self.parse_expr()));
                    }
                    Tok::Arrow | Tok::LParen => {
                        let params = if self.cur() == Tok::LParen {
                            self.parse_params()
                        } else {
                            Vec::new()
                        };
                        if self.expect(
                            Tok::Arrow,
                            "`-->` after the redefined rule's name",
                            "expected `-->`",
                        ) {
                            let term = body::Term::IMPORT.inside(self, open);
                            let body = self.parse_body(term, "`-->`");
                            list.push(ImportOverride::Rule { name, params, body });
                        }
                    }
                    _ => list.push(ImportOverride::Protect(name)),
                }
            }
            if self.eat(Tok::Comma) {
                continue;
            }
            if self.eat(Tok::RParen) {
                break;
            }
            self.close_list_after_error(open, mark, "`)` to close the import list", "`,` or `)`");
            break;
        }
        list
    }

    /// `(a, float b, string[] c)`
    fn parse_params(&mut self) -> Vec<Param> {
        let open = self.pos;
        self.bump();
        let mut params = Vec::new();
        if self.eat(Tok::RParen) {
            return params;
        }
        loop {
            let mark = self.diags.len();
            if let Some(param) = self.parse_param() {
                params.push(param);
            }
            if self.eat(Tok::Comma) {
                continue;
            }
            if self.eat(Tok::RParen) {
                break;
            }
            self.close_list_after_error(
                open,
                mark,
                "`)` to close the parameter list",
                "`,` or `)`",
            );
            break;
        }
        params
    }

    fn parse_param(&mut self) -> Option<Param> {
        let first = self.expect_name("a parameter name")?;
        let is_array = self.cur() == Tok::LBracket && self.nth(1) == Tok::RBracket;
        if !is_array && !Self::is_name(self.cur()) {
            return Some(Param {
                ty: None,
                name: first,
            });
        }
        // A type comes first: `float x`, `string[] names`.
        if is_array {
            self.bump();
            self.bump();
        }
        let ty = match (first.name.as_str(), is_array) {
            ("float", false) => Some(TypeName::Float),
            ("bool", false) => Some(TypeName::Bool),
            ("string", false) => Some(TypeName::String),
            ("float", true) => Some(TypeName::FloatArray),
            ("bool", true) => Some(TypeName::BoolArray),
            ("string", true) => Some(TypeName::StringArray),
            _ => {
                self.error(
                    format!("unknown parameter type `{}`", first.name),
                    first.span,
                    "expected `float`, `bool` or `string`, optionally followed by `[]`",
                );
                None
            }
        };
        let name = self.expect_name("a parameter name after the type")?;
        Some(Param { ty, name })
    }

    /// `with ( x := e  y := e )`; `None` when there is no `with`.
    fn parse_with(&mut self) -> Vec<LocalVar> {
        let mut locals = Vec::new();
        if !self.eat(Tok::With) {
            return locals;
        }
        if self.cur() != Tok::LParen {
            self.expected("`(` after `with`", "expected `(`");
            return locals;
        }
        let open = self.pos;
        self.bump();
        loop {
            if self.eat(Tok::RParen) {
                break;
            }
            let mark = self.diags.len();
            if Self::is_name(self.cur()) {
                let name = self.ident_here();
                self.bump();
                if self.expect(
                    Tok::ColonEq,
                    "`:=` after the local variable name",
                    "expected `:=`",
                ) {
                    let value = self.parse_expr();
                    locals.push(LocalVar { name, value });
                    // Locals are separated by whitespace only.
                    if Self::is_name(self.cur()) || self.cur() == Tok::RParen {
                        continue;
                    }
                }
            }
            if self.diags.len() == mark {
                self.expected(
                    "a local variable `name := value` or `)`",
                    "expected `name :=` or `)`",
                );
                if self.cur() == Tok::Comma {
                    self.note(
                        "local variables in `with ( ... )` are separated by whitespace, not commas"
                            .to_string(),
                    );
                }
            }
            self.skip_past_partner(open);
            break;
        }
        locals
    }

    fn parse_attr(&mut self, annotations: Vec<Annotation>) -> Option<AttrDecl> {
        let start = self.tok_at(self.pos).start;
        self.bump();
        let name = self.expect_name("the attribute name after `attr`")?;
        let params = if self.cur() == Tok::LParen {
            self.parse_params()
        } else {
            Vec::new()
        };
        let mark = self.diags.len();
        let locals = self.parse_with();
        if !self.eat(Tok::Eq) {
            if self.diags.len() == mark {
                self.expected(&format!("`=` after `attr {}`", name.name), "expected `=`");
            }
            return None;
        }
        let value = self.parse_expr();
        Some(AttrDecl {
            annotations,
            name,
            params,
            locals,
            value,
            span: self.span_from(start),
        })
    }

    /// `const`, functions and rules: `const c(p) with (...) = e`,
    /// `f(p) = e`, `[start|extension] R(p) with (...) --> body`.
    fn parse_definition(&mut self, annotations: Vec<Annotation>) -> Option<Item> {
        let start = self.tok_at(self.pos).start;
        let is_const = self.eat(Tok::Const);
        let kind = if is_const {
            RuleKind::Plain
        } else if self.cur() == Tok::Start && Self::is_name(self.nth(1)) {
            self.bump();
            RuleKind::Start
        } else if self.eat(Tok::Extension) {
            RuleKind::Extension
        } else {
            RuleKind::Plain
        };
        let name = self.expect_name(if is_const {
            "the constant name after `const`"
        } else {
            "a rule or function name"
        })?;
        let params = if self.cur() == Tok::LParen {
            self.parse_params()
        } else {
            Vec::new()
        };
        let mark = self.diags.len();
        let locals = self.parse_with();
        match self.cur() {
            Tok::Arrow if !is_const => {
                self.bump();
                let body = self.parse_body(body::Term::NONE, "`-->`");
                Some(Item::Rule(RuleDecl {
                    annotations,
                    kind,
                    name,
                    params,
                    locals,
                    body,
                    span: self.span_from(start),
                }))
            }
            Tok::Eq if kind == RuleKind::Plain => {
                self.bump();
                let value = self.parse_expr();
                Some(Item::Function(FunctionDecl {
                    annotations,
                    is_const,
                    name,
                    params,
                    locals,
                    value,
                    span: self.span_from(start),
                }))
            }
            _ if self.diags.len() > mark => None,
            _ => {
                let (what, label) = if is_const {
                    (format!("`=` after `const {}`", name.name), "expected `=`")
                } else if kind != RuleKind::Plain {
                    (
                        format!("`-->` after the rule name `{}`", name.name),
                        "expected `-->`",
                    )
                } else {
                    (
                        format!("`-->` (rule) or `=` (function) after `{}`", name.name),
                        "expected `-->` or `=`",
                    )
                };
                self.expected(&what, label);
                None
            }
        }
    }
}

fn match_brackets(toks: &[Token]) -> Vec<u32> {
    let mut partner = vec![NO_PARTNER; toks.len()];
    let mut stack: Vec<usize> = Vec::new();
    for (i, t) in toks.iter().enumerate() {
        let opener = match t.kind {
            Tok::LParen | Tok::LBracket | Tok::LBrace => {
                stack.push(i);
                continue;
            }
            Tok::RParen => Tok::LParen,
            Tok::RBracket => Tok::LBracket,
            Tok::RBrace => Tok::LBrace,
            // These never stand inside brackets: whatever is still open
            // before them is unclosed. Nor does a rule head `Name -->`,
            // unless it redefines a rule in an import list `( ..., R --> X )`.
            Tok::At
            | Tok::Attr
            | Tok::Const
            | Tok::Import
            | Tok::Style
            | Tok::Version
            | Tok::Extension => {
                stack.clear();
                continue;
            }
            Tok::Ident | Tok::Start
                if toks.get(i + 1).is_some_and(|n| n.kind == Tok::Arrow)
                    && !(i > 0 && matches!(toks[i - 1].kind, Tok::Comma | Tok::LParen)) =>
            {
                stack.clear();
                continue;
            }
            _ => continue,
        };
        // Only the innermost open bracket can be closed; a closer of
        // another kind is stray and closes nothing (so that `{ 1 : A ) }`
        // keeps its braces paired).
        if stack.last().is_some_and(|&open| toks[open].kind == opener) {
            let open = stack.pop().unwrap_or_default();
            partner[open] = i as u32;
            partner[i] = open as u32;
        }
    }
    partner
}
