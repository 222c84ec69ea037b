//! The CGA lexer: text to tokens.
//!
//! Hand-written rather than generated because three CGA rules depend on the
//! characters around a dot, which a table-driven lexer expresses poorly:
//!
//! - `scope.sx`, `imp.Lot`, `material.color.r` are ONE dotted identifier
//!   (a dot followed by an identifier character continues the name);
//! - `Window.` is the identifier `Window` followed by a [`Tok::Dot`], which the
//!   parser turns into a leaf because the two touch;
//! - `.+`, `.==`, `.!` ... are element-wise array operators, `.5` is a number,
//!   and `1.==1` is `1 .== 1` (the short float `1.` does not swallow the dot
//!   of a following element-wise operator, as CityEngine reads it).
//!
//! Whitespace and comments (`//`, `/* */`, `#`) are skipped; newlines carry no
//! meaning. Errors (stray characters, unterminated strings and comments) are
//! reported as diagnostics and lexing goes on, so the parser always gets a
//! well-formed token stream ending in [`Tok::Eof`].

use crate::diagnostic::Diagnostic;
use crate::span::{FileId, Span};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Tok {
    Ident,
    Number,
    Str,
    // Keywords. `start` is a keyword only in front of a rule head; elsewhere
    // (`start(20)`) the parser reads it as a name.
    Attr,
    Const,
    Import,
    Style,
    Extends,
    Version,
    Case,
    Else,
    With,
    Start,
    Extension,
    Nil,
    True,
    False,
    // Punctuation.
    LParen,
    RParen,
    LBracket,
    RBracket,
    LBrace,
    RBrace,
    Comma,
    Semi,
    Colon,
    /// `:=` (local variables in `with`)
    ColonEq,
    /// `=:` (comp operator: one shape per connected set)
    EqColon,
    Pipe,
    Star,
    Slash,
    Percent,
    Plus,
    Minus,
    Bang,
    Lt,
    Le,
    Gt,
    Ge,
    EqEq,
    Ne,
    AndAnd,
    OrOr,
    Eq,
    /// `-->`
    Arrow,
    /// `'` (relative size prefix)
    Quote,
    /// `~` (floating size prefix)
    Tilde,
    At,
    /// `^`: not an operator of CGA, but annotations use it
    /// (`@Handle(shape=Mass^1)`).
    Caret,
    /// A lone dot: the end of a leaf `Name.`, or `.Lot` of a dynamic import.
    Dot,
    // Element-wise array operators.
    DotPlus,
    DotMinus,
    DotStar,
    DotSlash,
    DotPercent,
    DotEqEq,
    DotNe,
    DotLt,
    DotLe,
    DotGt,
    DotGe,
    DotAndAnd,
    DotOrOr,
    DotBang,
    Eof,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Token {
    pub kind: Tok,
    pub start: u32,
    pub end: u32,
}

impl Tok {
    /// How the token is shown in a diagnostic when its text is not needed.
    pub(crate) fn describe(self) -> &'static str {
        match self {
            Tok::Ident => "identifier",
            Tok::Number => "number",
            Tok::Str => "string",
            Tok::Attr => "keyword `attr`",
            Tok::Const => "keyword `const`",
            Tok::Import => "keyword `import`",
            Tok::Style => "keyword `style`",
            Tok::Extends => "keyword `extends`",
            Tok::Version => "keyword `version`",
            Tok::Case => "keyword `case`",
            Tok::Else => "keyword `else`",
            Tok::With => "keyword `with`",
            Tok::Start => "keyword `start`",
            Tok::Extension => "keyword `extension`",
            Tok::Nil => "`NIL`",
            Tok::True => "`true`",
            Tok::False => "`false`",
            Tok::LParen => "`(`",
            Tok::RParen => "`)`",
            Tok::LBracket => "`[`",
            Tok::RBracket => "`]`",
            Tok::LBrace => "`{`",
            Tok::RBrace => "`}`",
            Tok::Comma => "`,`",
            Tok::Semi => "`;`",
            Tok::Colon => "`:`",
            Tok::ColonEq => "`:=`",
            Tok::EqColon => "`=:`",
            Tok::Pipe => "`|`",
            Tok::Star => "`*`",
            Tok::Slash => "`/`",
            Tok::Percent => "`%`",
            Tok::Plus => "`+`",
            Tok::Minus => "`-`",
            Tok::Bang => "`!`",
            Tok::Lt => "`<`",
            Tok::Le => "`<=`",
            Tok::Gt => "`>`",
            Tok::Ge => "`>=`",
            Tok::EqEq => "`==`",
            Tok::Ne => "`!=`",
            Tok::AndAnd => "`&&`",
            Tok::OrOr => "`||`",
            Tok::Eq => "`=`",
            Tok::Arrow => "`-->`",
            Tok::Quote => "`'`",
            Tok::Tilde => "`~`",
            Tok::At => "`@`",
            Tok::Caret => "`^`",
            Tok::Dot => "`.`",
            Tok::DotPlus => "`.+`",
            Tok::DotMinus => "`.-`",
            Tok::DotStar => "`.*`",
            Tok::DotSlash => "`./`",
            Tok::DotPercent => "`.%`",
            Tok::DotEqEq => "`.==`",
            Tok::DotNe => "`.!=`",
            Tok::DotLt => "`.<`",
            Tok::DotLe => "`.<=`",
            Tok::DotGt => "`.>`",
            Tok::DotGe => "`.>=`",
            Tok::DotAndAnd => "`.&&`",
            Tok::DotOrOr => "`.||`",
            Tok::DotBang => "`.!`",
            Tok::Eof => "end of file",
        }
    }
}

fn keyword(word: &[u8]) -> Option<Tok> {
    Some(match word {
        b"attr" => Tok::Attr,
        b"const" => Tok::Const,
        b"import" => Tok::Import,
        b"style" => Tok::Style,
        b"extends" => Tok::Extends,
        b"version" => Tok::Version,
        b"case" => Tok::Case,
        b"else" => Tok::Else,
        b"with" => Tok::With,
        b"start" => Tok::Start,
        b"extension" => Tok::Extension,
        b"NIL" => Tok::Nil,
        b"true" => Tok::True,
        b"false" => Tok::False,
        _ => return None,
    })
}

fn is_ident_start(b: u8) -> bool {
    b.is_ascii_alphabetic() || b == b'_'
}

fn is_ident_char(b: u8) -> bool {
    b.is_ascii_alphanumeric() || b == b'_'
}

/// The element-wise operator starting at `text[i]` (which is a `.`), if any,
/// with its length in bytes.
fn elementwise_op(text: &[u8], i: usize) -> Option<(Tok, usize)> {
    let at = |k: usize| text.get(i + k).copied().unwrap_or(0);
    let op = match (at(1), at(2)) {
        (b'=', b'=') => (Tok::DotEqEq, 3),
        (b'!', b'=') => (Tok::DotNe, 3),
        (b'<', b'=') => (Tok::DotLe, 3),
        (b'>', b'=') => (Tok::DotGe, 3),
        (b'&', b'&') => (Tok::DotAndAnd, 3),
        (b'|', b'|') => (Tok::DotOrOr, 3),
        (b'<', _) => (Tok::DotLt, 2),
        (b'>', _) => (Tok::DotGt, 2),
        (b'+', _) => (Tok::DotPlus, 2),
        // `X.-->` is a leaf followed by an arrow (not valid, but not `.-` either).
        (b'-', b'-') if text.get(i + 3) == Some(&b'>') => return None,
        (b'-', _) => (Tok::DotMinus, 2),
        (b'*', _) => (Tok::DotStar, 2),
        // `Leaf.// comment` and `Leaf./* comment */` end a leaf, they do not divide.
        (b'/', b'/') | (b'/', b'*') => return None,
        (b'/', _) => (Tok::DotSlash, 2),
        (b'%', _) => (Tok::DotPercent, 2),
        (b'!', _) => (Tok::DotBang, 2),
        _ => return None,
    };
    Some(op)
}

pub(crate) struct Lexed {
    pub tokens: Vec<Token>,
    pub diagnostics: Vec<Diagnostic>,
}

/// Splits `text` into tokens. The last token is always [`Tok::Eof`].
pub(crate) fn lex(file: FileId, text: &str) -> Lexed {
    let bytes = text.as_bytes();
    let mut tokens = Vec::with_capacity(text.len() / 4 + 1);
    let mut diagnostics = Vec::new();
    let span = |s: usize, e: usize| Span::new(file, s as u32, e as u32);
    let mut i = 0;
    // A UTF-8 byte order mark is not part of the code.
    if bytes.starts_with(b"\xEF\xBB\xBF") {
        i = 3;
    }
    // Start of a run of stray characters, reported as one diagnostic.
    let mut stray: Option<usize> = None;
    let flush_stray = |stray: &mut Option<usize>, end: usize, diagnostics: &mut Vec<Diagnostic>| {
        if let Some(s) = stray.take() {
            let chars = &text[s..end];
            let (what, shown) = if chars.chars().count() == 1 {
                ("character", chars.to_string())
            } else {
                ("characters", chars.chars().take(20).collect::<String>())
            };
            diagnostics.push(
                Diagnostic::error(format!("unexpected {what} `{shown}`"), span(s, end))
                    .with_label("not valid in CGA code outside strings and comments"),
            );
        }
    };

    while i < bytes.len() {
        let b = bytes[i];
        let start = i;
        let kind = match b {
            b' ' | b'\t' | b'\n' | b'\r' | 0x0b | 0x0c => {
                if stray.is_some() {
                    flush_stray(&mut stray, i, &mut diagnostics);
                }
                i += 1;
                continue;
            }
            b'#' => {
                if stray.is_some() {
                    flush_stray(&mut stray, i, &mut diagnostics);
                }
                i = skip_line(bytes, i);
                continue;
            }
            b'/' if bytes.get(i + 1) == Some(&b'/') => {
                if stray.is_some() {
                    flush_stray(&mut stray, i, &mut diagnostics);
                }
                i = skip_line(bytes, i);
                continue;
            }
            b'/' if bytes.get(i + 1) == Some(&b'*') => {
                if stray.is_some() {
                    flush_stray(&mut stray, i, &mut diagnostics);
                }
                match find(bytes, i + 2, b"*/") {
                    Some(end) => i = end + 2,
                    None => {
                        diagnostics.push(
                            Diagnostic::error("unterminated block comment", span(i, i + 2))
                                .with_label("this comment is never closed with `*/`"),
                        );
                        i = bytes.len();
                    }
                }
                continue;
            }
            b'"' => {
                if stray.is_some() {
                    flush_stray(&mut stray, i, &mut diagnostics);
                }
                match string_end(bytes, i) {
                    Ok(end) => i = end,
                    Err(line_end) => {
                        diagnostics.push(
                            Diagnostic::error("unterminated string", span(start, start + 1))
                                .with_label("this string is not closed before the end of the line"),
                        );
                        i = line_end;
                    }
                }
                // `i` may stop inside a multi-byte character only at a
                // backslash escape of one; move to the next boundary.
                while !text.is_char_boundary(i) {
                    i += 1;
                }
                Tok::Str
            }
            b'0'..=b'9' => {
                if stray.is_some() {
                    flush_stray(&mut stray, i, &mut diagnostics);
                }
                i = lex_number(bytes, i);
                Tok::Number
            }
            b'.' if bytes.get(i + 1).is_some_and(u8::is_ascii_digit) => {
                if stray.is_some() {
                    flush_stray(&mut stray, i, &mut diagnostics);
                }
                i = lex_number(bytes, i);
                Tok::Number
            }
            b'.' => {
                if stray.is_some() {
                    flush_stray(&mut stray, i, &mut diagnostics);
                }
                match elementwise_op(bytes, i) {
                    Some((tok, len)) => {
                        i += len;
                        tok
                    }
                    None => {
                        i += 1;
                        Tok::Dot
                    }
                }
            }
            b if is_ident_start(b) || (b >= 0x80 && char_at(text, i).is_alphabetic()) => {
                if stray.is_some() {
                    flush_stray(&mut stray, i, &mut diagnostics);
                }
                // Letters outside ASCII are not allowed in names, but a word
                // such as `höhe` is still lexed as one identifier so that it
                // gets one diagnostic and the parser goes on undisturbed.
                let mut non_ascii = false;
                // Letters outside ASCII (rare) take the slow path.
                let other_letter = |i: usize| -> usize {
                    match bytes.get(i) {
                        Some(&c) if c >= 0x80 => {
                            let c = char_at(text, i);
                            if c.is_alphanumeric() {
                                c.len_utf8()
                            } else {
                                0
                            }
                        }
                        _ => 0,
                    }
                };
                loop {
                    while i < bytes.len() && is_ident_char(bytes[i]) {
                        i += 1;
                    }
                    let len = other_letter(i);
                    if len > 0 {
                        non_ascii = true;
                        i += len;
                        continue;
                    }
                    // A dot followed by an identifier start continues the name.
                    let after_dot = bytes.get(i + 1).copied().unwrap_or(0);
                    if bytes.get(i) == Some(&b'.')
                        && (is_ident_start(after_dot) || other_letter(i + 1) > 0)
                    {
                        i += 1;
                    } else {
                        break;
                    }
                }
                if non_ascii {
                    diagnostics.push(
                        Diagnostic::error(
                            format!("identifier `{}` contains characters other than ASCII letters, digits and `_`", &text[start..i]),
                            span(start, i),
                        )
                        .with_label("not a valid name"),
                    );
                }
                keyword(&bytes[start..i]).unwrap_or(Tok::Ident)
            }
            _ => {
                let (tok, len) = match (b, bytes.get(i + 1).copied().unwrap_or(0)) {
                    (b'-', b'-') if bytes.get(i + 2) == Some(&b'>') => (Tok::Arrow, 3),
                    (b':', b'=') => (Tok::ColonEq, 2),
                    (b'=', b':') => (Tok::EqColon, 2),
                    (b'=', b'=') => (Tok::EqEq, 2),
                    (b'!', b'=') => (Tok::Ne, 2),
                    (b'<', b'=') => (Tok::Le, 2),
                    (b'>', b'=') => (Tok::Ge, 2),
                    (b'&', b'&') => (Tok::AndAnd, 2),
                    (b'|', b'|') => (Tok::OrOr, 2),
                    (b'(', _) => (Tok::LParen, 1),
                    (b')', _) => (Tok::RParen, 1),
                    (b'[', _) => (Tok::LBracket, 1),
                    (b']', _) => (Tok::RBracket, 1),
                    (b'{', _) => (Tok::LBrace, 1),
                    (b'}', _) => (Tok::RBrace, 1),
                    (b',', _) => (Tok::Comma, 1),
                    (b';', _) => (Tok::Semi, 1),
                    (b':', _) => (Tok::Colon, 1),
                    (b'|', _) => (Tok::Pipe, 1),
                    (b'*', _) => (Tok::Star, 1),
                    (b'/', _) => (Tok::Slash, 1),
                    (b'%', _) => (Tok::Percent, 1),
                    (b'+', _) => (Tok::Plus, 1),
                    (b'-', _) => (Tok::Minus, 1),
                    (b'!', _) => (Tok::Bang, 1),
                    (b'<', _) => (Tok::Lt, 1),
                    (b'>', _) => (Tok::Gt, 1),
                    (b'=', _) => (Tok::Eq, 1),
                    (b'\'', _) => (Tok::Quote, 1),
                    (b'~', _) => (Tok::Tilde, 1),
                    (b'@', _) => (Tok::At, 1),
                    (b'^', _) => (Tok::Caret, 1),
                    _ => {
                        // Not ASCII punctuation: Unicode whitespace (a
                        // non-breaking space pasted from a web page) is
                        // whitespace, anything else is a stray character.
                        let c = char_at(text, i);
                        if c.is_whitespace() || c == '\u{feff}' {
                            if stray.is_some() {
                                flush_stray(&mut stray, i, &mut diagnostics);
                            }
                        } else if stray.is_none() {
                            stray = Some(i);
                        }
                        i += c.len_utf8().max(1);
                        continue;
                    }
                };
                if stray.is_some() {
                    flush_stray(&mut stray, i, &mut diagnostics);
                }
                i += len;
                tok
            }
        };
        tokens.push(Token {
            kind,
            start: start as u32,
            end: i as u32,
        });
    }
    flush_stray(&mut stray, bytes.len(), &mut diagnostics);
    tokens.push(Token {
        kind: Tok::Eof,
        start: bytes.len() as u32,
        end: bytes.len() as u32,
    });
    Lexed {
        tokens,
        diagnostics,
    }
}

/// Where the string opened by the quote at `open` ends (after its closing
/// quote), or, for an unterminated string, where its line ends.
///
/// A string may run over line breaks (real rule files have `@Enum(..., "
/// Highlight", ...)`, a line broken inside a string, which CityEngine's
/// compiler accepts): the string is taken to go on to the next line when it
/// closes there and its closing quote is followed by what can follow a
/// string (an operator, `,`, `)`, `]`, `}`, `:`, `|`, a line end) rather
/// than by a name or another quote. An unclosed string on one line
/// followed by more code therefore still ends at its line, with an error,
/// instead of swallowing the code up to the next quote.
pub fn string_end(bytes: &[u8], open: usize) -> Result<usize, usize> {
    let mut i = open + 1;
    let mut line_end = None;
    loop {
        match bytes.get(i) {
            None => return Err(line_end.unwrap_or(i)),
            Some(b'\n') | Some(b'\r') => {
                line_end.get_or_insert(i);
                i += 1;
            }
            Some(b'"') => {
                i += 1;
                let Some(first_break) = line_end else {
                    return Ok(i);
                };
                let mut j = i;
                while matches!(bytes.get(j), Some(b' ' | b'\t')) {
                    j += 1;
                }
                let follows_well = match bytes.get(j) {
                    None | Some(b'\n' | b'\r') => true,
                    Some(&c) => !(is_ident_char(c) || c == b'"' || c == b'.' || c >= 0x80),
                };
                return if follows_well {
                    Ok(i)
                } else {
                    Err(first_break)
                };
            }
            Some(b'\\') if matches!(bytes.get(i + 1), Some(b) if *b != b'\n' && *b != b'\r') => {
                i += 2
            }
            Some(_) => i += 1,
        }
    }
}

/// The character starting at byte `i` (which must be a character boundary).
fn char_at(text: &str, i: usize) -> char {
    text.get(i..)
        .and_then(|t| t.chars().next())
        .unwrap_or('\u{fffd}')
}

/// To the end of the line: `\n`, `\r\n` or a lone `\r` (old Mac files).
fn skip_line(bytes: &[u8], mut i: usize) -> usize {
    while i < bytes.len() && bytes[i] != b'\n' && bytes[i] != b'\r' {
        i += 1;
    }
    i
}

fn find(bytes: &[u8], from: usize, needle: &[u8]) -> Option<usize> {
    bytes
        .get(from..)?
        .windows(needle.len())
        .position(|w| w == needle)
        .map(|p| p + from)
}

/// `12`, `1.5`, `.5`, `1.`, `1e-3`, `2.5E+2`. The short form `1.` keeps its
/// dot only when no identifier or element-wise operator follows it, so that
/// `1.==1` is `1 .== 1` and `3.x` is not silently a number.
fn lex_number(bytes: &[u8], mut i: usize) -> usize {
    let digits = |i: &mut usize| {
        while *i < bytes.len() && bytes[*i].is_ascii_digit() {
            *i += 1;
        }
    };
    digits(&mut i);
    if bytes.get(i) == Some(&b'.') {
        let next = bytes.get(i + 1).copied().unwrap_or(0);
        if next.is_ascii_digit() {
            i += 1;
            digits(&mut i);
        } else if !is_ident_start(next) && next != b'.' && elementwise_op(bytes, i).is_none() {
            i += 1;
        }
    }
    if matches!(bytes.get(i), Some(b'e' | b'E')) {
        let mut j = i + 1;
        if matches!(bytes.get(j), Some(b'+' | b'-')) {
            j += 1;
        }
        if bytes.get(j).is_some_and(u8::is_ascii_digit) {
            i = j;
            digits(&mut i);
        }
    }
    i
}

/// The value of a string token (quotes removed, escapes resolved). Unknown
/// escapes are kept as written (`"\d"` stays two characters), as file
/// patterns and regular expressions in string arguments rely on that.
pub(crate) fn string_value(raw: &str) -> String {
    let inner = raw.strip_prefix('"').unwrap_or(raw);
    let inner = inner
        .strip_suffix('"')
        .filter(|_| raw.len() >= 2)
        .unwrap_or(inner);
    if !inner.contains('\\') {
        return inner.to_string();
    }
    let mut out = String::with_capacity(inner.len());
    let mut chars = inner.chars();
    while let Some(c) = chars.next() {
        if c != '\\' {
            out.push(c);
            continue;
        }
        match chars.next() {
            Some('n') => out.push('\n'),
            Some('t') => out.push('\t'),
            Some('r') => out.push('\r'),
            Some('"') => out.push('"'),
            Some('\\') => out.push('\\'),
            Some('\'') => out.push('\''),
            // `\ue000` (the page of `isNull`): a character by its code.
            Some('u') => {
                let hex: String = chars.clone().take(4).collect();
                match u32::from_str_radix(&hex, 16).ok().and_then(char::from_u32) {
                    Some(c) if hex.len() == 4 && hex.bytes().all(|b| b.is_ascii_hexdigit()) => {
                        out.push(c);
                        for _ in 0..4 {
                            chars.next();
                        }
                    }
                    _ => out.push_str("\\u"),
                }
            }
            Some(other) => {
                out.push('\\');
                out.push(other);
            }
            None => out.push('\\'),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kinds(text: &str) -> Vec<(Tok, &str)> {
        let lexed = lex(FileId(0), text);
        assert!(lexed.diagnostics.is_empty(), "{:?}", lexed.diagnostics);
        lexed
            .tokens
            .iter()
            .filter(|t| t.kind != Tok::Eof)
            .map(|t| (t.kind, &text[t.start as usize..t.end as usize]))
            .collect()
    }

    #[test]
    fn dotted_names_leaves_and_elementwise_operators() {
        assert_eq!(
            kinds("scope.sx X. imp.Lot. a.+b .5 1.==1 x./y 1. Y.// c"),
            vec![
                (Tok::Ident, "scope.sx"),
                (Tok::Ident, "X"),
                (Tok::Dot, "."),
                (Tok::Ident, "imp.Lot"),
                (Tok::Dot, "."),
                (Tok::Ident, "a"),
                (Tok::DotPlus, ".+"),
                (Tok::Ident, "b"),
                (Tok::Number, ".5"),
                (Tok::Number, "1"),
                (Tok::DotEqEq, ".=="),
                (Tok::Number, "1"),
                (Tok::Ident, "x"),
                (Tok::DotSlash, "./"),
                (Tok::Ident, "y"),
                (Tok::Number, "1."),
                (Tok::Ident, "Y"),
                (Tok::Dot, "."),
            ]
        );
    }

    #[test]
    fn operators_and_numbers() {
        assert_eq!(
            kinds("--> =: := == != <= >= && || .|| .! 1e-3 2.5E+2 -"),
            vec![
                (Tok::Arrow, "-->"),
                (Tok::EqColon, "=:"),
                (Tok::ColonEq, ":="),
                (Tok::EqEq, "=="),
                (Tok::Ne, "!="),
                (Tok::Le, "<="),
                (Tok::Ge, ">="),
                (Tok::AndAnd, "&&"),
                (Tok::OrOr, "||"),
                (Tok::DotOrOr, ".||"),
                (Tok::DotBang, ".!"),
                (Tok::Number, "1e-3"),
                (Tok::Number, "2.5E+2"),
                (Tok::Minus, "-"),
            ]
        );
    }

    #[test]
    fn comments_and_keywords() {
        assert_eq!(
            kinds("# a\r\n// b\n/* c\n d */ start rule.start case NIL\u{a0}x"),
            vec![
                (Tok::Start, "start"),
                (Tok::Ident, "rule.start"),
                (Tok::Case, "case"),
                (Tok::Nil, "NIL"),
                (Tok::Ident, "x"),
            ]
        );
    }

    #[test]
    fn string_escapes() {
        assert_eq!(string_value(r#""a\nb\t\"c\"\\ \d""#), "a\nb\t\"c\"\\ \\d");
        assert_eq!(string_value("\"überbau\""), "überbau");
        assert_eq!(string_value("\"open"), "open");
        assert_eq!(string_value(r#""\ue000x\u00e4\uZZ""#), "\u{e000}xä\\uZZ");
    }

    #[test]
    fn comments_end_at_a_lone_carriage_return() {
        // Old Mac files end lines with CR alone.
        assert_eq!(
            kinds("# comment\rLot --> X.\r"),
            vec![
                (Tok::Ident, "Lot"),
                (Tok::Arrow, "-->"),
                (Tok::Ident, "X"),
                (Tok::Dot, "."),
            ]
        );
    }

    #[test]
    fn strings_over_line_breaks() {
        // Closed on the next line and followed by `,`: one string.
        let text = "@Enum(\"a\",\"\n b\",\"c\") attr x = 1";
        let lexed = lex(FileId(0), text);
        assert!(lexed.diagnostics.is_empty(), "{:?}", lexed.diagnostics);
        let strs: Vec<&str> = lexed
            .tokens
            .iter()
            .filter(|t| t.kind == Tok::Str)
            .map(|t| &text[t.start as usize..t.end as usize])
            .collect();
        assert_eq!(strs, ["\"a\"", "\"\n b\"", "\"c\""]);
        // An unclosed string followed by code: the error is on its line.
        let lexed = lex(FileId(0), "print(\"abc)\nLot --> print(\"x\")");
        assert_eq!(lexed.diagnostics.len(), 1);
        assert_eq!(lexed.diagnostics[0].span.unwrap().range(), 6..7);
    }

    #[test]
    fn lexer_errors() {
        let lexed = lex(FileId(0), "a $$ b \"open\n/* never");
        let messages: Vec<_> = lexed
            .diagnostics
            .iter()
            .map(|d| d.message.as_str())
            .collect();
        assert_eq!(
            messages,
            vec![
                "unexpected characters `$$`",
                "unterminated string",
                "unterminated block comment"
            ]
        );
        assert_eq!(lexed.diagnostics[0].span.unwrap().range(), 2..4);
    }

    #[test]
    fn non_ascii_names_are_one_token_with_one_error() {
        let lexed = lex(FileId(0), "höhe.wert + x");
        let kinds: Vec<Tok> = lexed.tokens.iter().map(|t| t.kind).collect();
        assert_eq!(kinds, [Tok::Ident, Tok::Plus, Tok::Ident, Tok::Eof]);
        assert_eq!(lexed.tokens[0].end, 10);
        assert_eq!(lexed.diagnostics.len(), 1);
        assert_eq!(
            lexed.diagnostics[0].message,
            "identifier `höhe.wert` contains characters other than ASCII letters, digits and `_`"
        );
    }
}
