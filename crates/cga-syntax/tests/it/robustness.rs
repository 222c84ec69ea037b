//! `parse` never panics, never loops, and keeps its recursion bounded,
//! whatever the input: random bytes, random token soup, truncated and
//! mutated rule files, and absurdly deep nesting. Every diagnostic it
//! returns points inside the text and renders.

use std::path::Path;
use std::time::{Duration, Instant};

use cga_syntax::{parse, FileId, SourceMap};

/// How many times more random inputs to try than by default: set
/// `CGA_FUZZ_SCALE=100` for a long run (in release mode).
fn scale() -> usize {
    std::env::var("CGA_FUZZ_SCALE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1)
}

/// A small deterministic generator (xorshift64*), so failures reproduce.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Parses `text` and checks the diagnostics' spans and rendering.
fn check(text: &str) -> usize {
    let (_module, diagnostics) = parse(FileId(0), text);
    let mut sources = SourceMap::new();
    sources.add("fuzz.cga", text.to_string());
    for d in &diagnostics {
        let span = d.span.expect("parser diagnostics have a span");
        let (start, end) = (span.start as usize, span.end as usize);
        assert!(
            start <= end && end <= text.len(),
            "span {start}..{end} outside {} bytes: {d:?}\n{text:?}",
            text.len()
        );
        assert!(
            text.is_char_boundary(start) && text.is_char_boundary(end),
            "{d:?}"
        );
        let rendered = d.render(&sources);
        assert!(rendered.starts_with("error: "), "{rendered}");
        assert!(rendered.contains("fuzz.cga:"), "{rendered}");
    }
    diagnostics.len()
}

fn fixture_texts() -> Vec<String> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures");
    let mut texts: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| std::fs::read_to_string(e.unwrap().path()).unwrap())
        .collect();
    texts.sort();
    texts
}

/// Pieces of CGA that make random input reach deep into the parser.
const VOCABULARY: &[&str] = &[
    "Lot",
    "X",
    "X.",
    "imp.Lot",
    "scope.sx",
    "split",
    "comp",
    "(",
    ")",
    "{",
    "}",
    "}*",
    "[",
    "]",
    "|",
    ":",
    "=",
    "=:",
    ":=",
    "-->",
    ",",
    ";",
    "case",
    "else",
    "with",
    "attr",
    "const",
    "import",
    "style",
    "extends",
    "version",
    "start",
    "extension",
    "NIL",
    "true",
    "false",
    "@Hidden",
    "@Range(min=1,",
    "30%",
    "%",
    "'",
    "~",
    "1",
    ".5",
    "1.",
    "2e3",
    "\"s\"",
    "\"open",
    "/*",
    "*/",
    "//",
    "#",
    "\n",
    " ",
    "\t",
    "+",
    "-",
    "*",
    "/",
    "!",
    "&&",
    "||",
    "==",
    "<",
    ">=",
    ".+",
    ".==",
    ".!",
    ".",
    "x",
    "f(",
    "imp(h = 1).Lot",
    "comp(f) {",
    "split(y) {",
    "é",
    "$",
];

fn soup(rng: &mut Rng, len: usize) -> String {
    let mut s = String::new();
    for _ in 0..len {
        s.push_str(VOCABULARY[rng.below(VOCABULARY.len())]);
        if rng.below(3) == 0 {
            s.push(' ');
        }
    }
    s
}

#[test]
fn random_bytes() {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    for _ in 0..3000 * scale() {
        let len = rng.below(120);
        let bytes: Vec<u8> = (0..len)
            .map(|_| {
                // Mostly ASCII punctuation and letters, some arbitrary bytes.
                if rng.below(8) == 0 {
                    rng.next() as u8
                } else {
                    const CHARS: &[u8] = b" \n\t(){}[]|:;,.'~%*+-/!<>=&@#\"aXz019_";
                    CHARS[rng.below(CHARS.len())]
                }
            })
            .collect();
        check(&String::from_utf8_lossy(&bytes));
    }
}

#[test]
fn random_token_soup() {
    let mut rng = Rng(42);
    let mut with_errors = 0;
    let rounds = 4000 * scale();
    for _ in 0..rounds {
        let len = 1 + rng.below(60);
        if check(&soup(&mut rng, len)) > 0 {
            with_errors += 1;
        }
    }
    // The soup is nearly always broken: the test did reach the error paths.
    assert!(with_errors > rounds * 3 / 4, "{with_errors}");
}

#[test]
fn truncated_and_mutated_rule_files() {
    let texts = fixture_texts();
    let mut rng = Rng(7);
    for text in &texts {
        // Truncations at ~25 places, on character boundaries.
        let step = (text.len() / 25).max(1);
        for cut in (0..text.len()).step_by(step) {
            if text.is_char_boundary(cut) {
                check(&text[..cut]);
            }
        }
        // Mutations: delete, duplicate or replace a stretch, insert soup.
        for _ in 0..30 * scale() {
            let mut t = text.clone();
            let a = rng.below(t.len());
            let b = (a + rng.below(40)).min(t.len());
            if !t.is_char_boundary(a) || !t.is_char_boundary(b) {
                continue;
            }
            match rng.below(4) {
                0 => t.replace_range(a..b, ""),
                1 => {
                    let piece = t[a..b].to_string();
                    t.insert_str(b, &piece);
                }
                2 => {
                    let piece = soup(&mut rng, 3);
                    t.replace_range(a..b, &piece);
                }
                _ => {
                    let piece = soup(&mut rng, 1);
                    t.insert_str(a, &piece);
                }
            }
            check(&t);
        }
    }
}

#[test]
fn deep_nesting_is_an_error_not_a_crash() {
    let n = 50_000;
    let cases = [
        format!("f = {}1{}", "(".repeat(n), ")".repeat(n)),
        format!("f = {}1{}", "[".repeat(n), "]".repeat(n)),
        format!("f = {}1", "-".repeat(n)),
        format!("f = {}1", "!".repeat(n)),
        format!("R --> t({}1)", "'".repeat(n)),
        format!("R --> {}X{}", "[".repeat(n), "]".repeat(n)),
        format!("R --> {}X", "case a : ".repeat(n)),
        format!("R --> {}X", "30% : ".repeat(n)),
        format!("f = {}1", "case a : ".repeat(n)),
        format!("R --> split(x) {}1 : X{}", "{".repeat(n), "}".repeat(n)),
        format!("R --> {}X{}", "split(x) { 1 : ".repeat(n), " }".repeat(n)),
        format!("R --> {}", "f(".repeat(n)),
        format!("f = {}", "a[".repeat(n)),
        "{".repeat(n),
        "(".repeat(n) + &"]".repeat(n),
        format!("f = 1{}", "+1".repeat(n)),
        format!("f = a{}", "[1]".repeat(n)),
        format!("f = a{}", "+1*2".repeat(n)),
    ];
    for text in &cases {
        let (_, diagnostics) = parse(FileId(0), text);
        assert!(!diagnostics.is_empty(), "{}", &text[..40]);
        check(text);
    }
    let (_, diagnostics) = parse(FileId(0), &cases[0]);
    assert_eq!(diagnostics.len(), 1);
    assert_eq!(
        diagnostics[0].message,
        "expressions or blocks are nested too deeply"
    );
    // After the error the next declarations are parsed again.
    let text = format!(
        "f = {}1{}\ng = (1\nLot --> X.",
        "(".repeat(n),
        ")".repeat(n)
    );
    let (module, diagnostics) = parse(FileId(0), &text);
    assert_eq!(diagnostics.len(), 2, "{diagnostics:#?}");
    assert_eq!(module.items.len(), 3);
}

#[test]
fn realistic_nesting_is_fine() {
    // Well below the limit: no diagnostic, on a test thread's stack.
    let text = format!("f = {}1{}", "(".repeat(80), ")".repeat(80));
    assert_eq!(check(&text), 0);
    let text = format!("R --> {}X{}", "split(x) { 1 : ".repeat(60), " }".repeat(60));
    assert_eq!(check(&text), 0);
    let text = format!(
        "R --> {}X {}",
        "case a : ".repeat(60),
        "else : Y ".repeat(60)
    );
    assert_eq!(check(&text), 0);
    // Long operator chains are flat enough too.
    let text = format!("f = \"a\"{}", " + b".repeat(150));
    assert_eq!(check(&text), 0);
}

#[test]
fn parsing_is_fast_and_linear() {
    let candler = fixture_texts().concat();
    let small = candler.repeat(2);
    let large = candler.repeat(16);
    let time = |text: &str| {
        let start = Instant::now();
        let (module, diagnostics) = parse(FileId(0), text);
        assert!(diagnostics.is_empty());
        assert!(!module.items.is_empty());
        start.elapsed()
    };
    // Warm up, then compare: eight times the text must not take much more
    // than eight times as long (quadratic behaviour would take 64 times).
    time(&small);
    let t_small = (0..3).map(|_| time(&small)).min().unwrap();
    let t_large = (0..3).map(|_| time(&large)).min().unwrap();
    assert!(
        t_large < t_small * 24 + Duration::from_millis(5),
        "2 copies: {t_small:?}, 16 copies: {t_large:?}"
    );
}
