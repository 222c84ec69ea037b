//! A lexical pass over the text for highlighting and folding: comments,
//! strings, numbers, words (dotted names) and annotations, with byte
//! spans. It follows the engine's lexer on what starts a comment (`//`,
//! `#`, `/* */`) and a name (ASCII letters, digits, `_`, dots between).

use std::ops::Range;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TokKind {
    Comment,
    Str,
    Number,
    Word,
    Annotation,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Tok {
    pub kind: TokKind,
    pub span: Range<usize>,
}

pub fn scan(text: &str) -> Vec<Tok> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    let word_end = |mut j: usize| {
        loop {
            while j < b.len() && (b[j].is_ascii_alphanumeric() || b[j] == b'_') {
                j += 1;
            }
            // `scope.sx`: a dot followed by a letter continues the name;
            // `Leaf.` ends it.
            if j + 1 < b.len()
                && b[j] == b'.'
                && (b[j + 1].is_ascii_alphabetic() || b[j + 1] == b'_')
            {
                j += 1;
                continue;
            }
            return j;
        }
    };
    while i < b.len() {
        let c = b[i];
        let start = i;
        let kind = match c {
            b'#' => {
                i = line_end(b, i);
                TokKind::Comment
            }
            b'/' if b.get(i + 1) == Some(&b'/') => {
                i = line_end(b, i);
                TokKind::Comment
            }
            b'/' if b.get(i + 1) == Some(&b'*') => {
                i = text[i + 2..].find("*/").map_or(b.len(), |e| i + 2 + e + 2);
                TokKind::Comment
            }
            b'"' => {
                i = cga::syntax::string_end(b, i).unwrap_or_else(|end| end);
                TokKind::Str
            }
            b'@' => {
                i = word_end(i + 1);
                TokKind::Annotation
            }
            b'0'..=b'9' => {
                while i < b.len() && (b[i].is_ascii_digit() || b[i] == b'.') {
                    i += 1;
                }
                if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
                    i += 1;
                    if i < b.len() && (b[i] == b'-' || b[i] == b'+') {
                        i += 1;
                    }
                    while i < b.len() && b[i].is_ascii_digit() {
                        i += 1;
                    }
                }
                TokKind::Number
            }
            c if c.is_ascii_alphabetic() || c == b'_' => {
                i = word_end(i);
                TokKind::Word
            }
            _ => {
                // One character (all of a UTF-8 sequence).
                i += text[i..].chars().next().map_or(1, char::len_utf8);
                continue;
            }
        };
        out.push(Tok {
            kind,
            span: start..i.max(start + 1).min(b.len()),
        });
    }
    out
}

fn line_end(b: &[u8], i: usize) -> usize {
    b[i..]
        .iter()
        .position(|&c| c == b'\n')
        .map_or(b.len(), |e| i + e)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn comments_strings_numbers_words() {
        let text =
            "@Range(0, 1.5e2) attr a = \"x // y\" # c\nLot --> s('0.5) /* m\nn */ scope.sx Leaf.";
        let text2 = "@Enum(\"a\",\"\n b\",\"c\") print(\"abc)\nLot";
        let strs: Vec<&str> = scan(text2)
            .iter()
            .filter(|t| t.kind == TokKind::Str)
            .map(|t| &text2[t.span.clone()])
            .collect();
        assert_eq!(strs, ["\"a\"", "\"\n b\"", "\"c\"", "\"abc)"]);
        let toks: Vec<(TokKind, &str)> = scan(text)
            .iter()
            .map(|t| (t.kind, &text[t.span.clone()]))
            .collect();
        use TokKind::*;
        assert_eq!(
            toks,
            [
                (Annotation, "@Range"),
                (Number, "0"),
                (Number, "1.5e2"),
                (Word, "attr"),
                (Word, "a"),
                (Str, "\"x // y\""),
                (Comment, "# c"),
                (Word, "Lot"),
                (Word, "s"),
                (Number, "0.5"),
                (Comment, "/* m\nn */"),
                (Word, "scope.sx"),
                (Word, "Leaf"),
            ]
        );
    }
}
