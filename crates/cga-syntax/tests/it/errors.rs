//! Syntax errors: the exact text of the rendered diagnostics (message,
//! `path:line:col`, the source line, carets and label, notes), and recovery
//! that reports every error of a file once.

use cga_syntax::ast::Item;
use cga_syntax::{parse, sexpr, FileId, SourceMap};

/// Parses `src` as `broken.cga` and renders all its diagnostics.
fn rendered(src: &str) -> String {
    let mut sources = SourceMap::new();
    let file = sources.add("broken.cga", src.to_string());
    let (_, diagnostics) = parse(file, src);
    diagnostics.iter().map(|d| d.render(&sources)).collect()
}

#[test]
fn argument_list_and_missing_pipe() {
    let src = r#"version "2023.0"

attr height = 10

Lot -->
	extrude(height;) Mass

Mass --> comp(f) { top : Roof side = Facade }
"#;
    assert_eq!(
        rendered(src),
        r#"error: expected `)` to close the argument list, found `;`
 --> broken.cga:6:16
  |
6 | 	extrude(height;) Mass
  | 	              ^ expected `,` or `)`
error: expected `|` or `}` after the block entry, found identifier `side`
 --> broken.cga:8:31
  |
8 | Mass --> comp(f) { top : Roof side = Facade }
  |                               ^^^^ expected `|` or `}`
"#
    );
}

#[test]
fn missing_arrow_and_missing_colon_in_case() {
    let src = r#"attr h = 10
Lot extrude(h)
Facade -->
    case scope.sy > 3 Floor
    else : NIL
"#;
    assert_eq!(
        rendered(src),
        r#"error: expected `-->` (rule) or `=` (function) after `Lot`, found identifier `extrude`
 --> broken.cga:2:5
  |
2 | Lot extrude(h)
  |     ^^^^^^^ expected `-->` or `=`
error: expected `:` after the `case` condition, found identifier `Floor`
 --> broken.cga:4:23
  |
4 |     case scope.sy > 3 Floor
  |                       ^^^^^ expected `:`
"#
    );
}

#[test]
fn unterminated_string_and_comment() {
    let src = r##"Door --> color("#fff) NIL
Wall --> texture("a.jpg") /* todo
Roof --> X.
"##;
    assert_eq!(
        rendered(src),
        r##"error: unterminated string
 --> broken.cga:1:16
  |
1 | Door --> color("#fff) NIL
  |                ^ this string is not closed before the end of the line
error: unterminated block comment
 --> broken.cga:2:27
  |
2 | Wall --> texture("a.jpg") /* todo
  |                           ^^ this comment is never closed with `*/`
"##
    );
}

#[test]
fn stray_character_and_unbalanced_brackets() {
    let src = r#"Lot --> extrude(10) § split(y) { 1 : A | 2 : B
B --> [ t(0, 1, 0) X.
C --> X ]
"#;
    assert_eq!(
        rendered(src),
        r#"error: unexpected character `§`
 --> broken.cga:1:21
  |
1 | Lot --> extrude(10) § split(y) { 1 : A | 2 : B
  |                     ^ not valid in CGA code outside strings and comments
error: expected `}` to close the block, found identifier `B`
 --> broken.cga:2:1
  |
2 | B --> [ t(0, 1, 0) X.
  | ^ expected `}`
  = the `{` was opened at line 1, column 32
error: expected `]` to close the push, found identifier `C`
 --> broken.cga:3:1
  |
3 | C --> X ]
  | ^ expected `]`
  = the `[` was opened at line 2, column 7
error: expected an operation, a rule, `NIL`, a leaf `Name.` or `[`, found `]`
 --> broken.cga:3:9
  |
3 | C --> X ]
  |         ^ expected an operation
"#
    );
}

#[test]
fn chains_empty_bodies_and_dangling_annotation() {
    let src = r#"const h = case a > 1 : 2
Lot --> extrude(1) case h > 1 : A else : B
R -->
S --> comp(f) { }
@Hidden
"#;
    assert_eq!(
        rendered(src),
        r#"error: expected `case` or `else` to continue the chain, found identifier `Lot`
 --> broken.cga:2:1
  |
2 | Lot --> extrude(1) case h > 1 : A else : B
  | ^^^ a `case` chain must end with an `else` branch
error: a `case` chain must stand at the start of a body
 --> broken.cga:2:20
  |
2 | Lot --> extrude(1) case h > 1 : A else : B
  |                    ^^^^ conditions cannot follow operations
  = put the conditional in a push `[ case ... ]` to run it after operations
error: expected operations after `-->`, found the next declaration
 --> broken.cga:3:3
  |
3 | R -->
  |   ^^^ empty body
  = write `NIL` to delete the shape or `Name.` to keep it as a leaf
error: empty block
 --> broken.cga:4:15
  |
4 | S --> comp(f) { }
  |               ^^^ expected at least one entry such as `1 : X`
error: annotation is not followed by a declaration
 --> broken.cga:5:1
  |
5 | @Hidden
  | ^^^^^^^ nothing to annotate
"#
    );
}

#[test]
fn broken_expressions() {
    let src = r#"f = [1, 2; ]
g = a[ ]
k = (1 + ) * 2
t = f(')
"#;
    assert_eq!(
        rendered(src),
        r#"error: expected an expression, found `]`
 --> broken.cga:1:12
  |
1 | f = [1, 2; ]
  |            ^ expected an expression
error: expected an index inside `[ ]`
 --> broken.cga:2:8
  |
2 | g = a[ ]
  |        ^ empty index
error: expected an expression, found `)`
 --> broken.cga:3:10
  |
3 | k = (1 + ) * 2
  |          ^ expected an expression
error: expected an expression, found `)`
 --> broken.cga:4:8
  |
4 | t = f(')
  |        ^ expected an expression
"#
    );
}

#[test]
fn imports_locals_and_dynamic_import() {
    let src = r#"import imp "imp.cga"
import i2 : "x.cga" (h = , Roof --> )
Lot with (a := 1, b := 2) --> imp(h = 2 .Lot
"#;
    assert_eq!(
        rendered(src),
        r#"error: expected `:` between the import name and the file path, found string "imp.cga"
 --> broken.cga:1:12
  |
1 | import imp "imp.cga"
  |            ^^^^^^^^^ expected `:`
error: expected an expression, found `,`
 --> broken.cga:2:26
  |
2 | import i2 : "x.cga" (h = , Roof --> )
  |                          ^ expected an expression
error: expected operations after `-->`, found `)`
 --> broken.cga:2:37
  |
2 | import i2 : "x.cga" (h = , Roof --> )
  |                                     ^ expected operations
  = write `NIL` to delete the shape or `Name.` to keep it as a leaf
error: expected a local variable `name := value` or `)`, found `,`
 --> broken.cga:3:17
  |
3 | Lot with (a := 1, b := 2) --> imp(h = 2 .Lot
  |                 ^ expected `name :=` or `)`
  = local variables in `with ( ... )` are separated by whitespace, not commas
error: expected `)` to close the argument list, found `=`
 --> broken.cga:3:37
  |
3 | Lot with (a := 1, b := 2) --> imp(h = 2 .Lot
  |                                     ^ expected `,` or `)`
  = the `(` was opened at line 3, column 34
"#
    );
}

#[test]
fn tabs_in_the_source_line() {
    let src = r#"Lot --> s(1,1,1)
		t(0, 0, -) X.
"#;
    assert_eq!(
        rendered(src),
        r#"error: expected an expression, found `)`
 --> broken.cga:2:12
  |
2 | 		t(0, 0, -) X.
  | 		         ^ expected an expression
"#
    );
}

#[test]
fn crlf_line_endings_give_the_right_line_and_column() {
    let src = "Lot -->\r\n  extrude(10)\r\n  split(y) { 1 : A | 2 B }\r\n";
    assert_eq!(
        rendered(src),
        "error: expected `:`, `=` or `=:` after the block entry's head, found identifier `B`\n \
         --> broken.cga:3:24\n  |\n3 |   split(y) { 1 : A | 2 B }\n  |                        ^ expected `:`\n"
    );
}

#[test]
fn columns_count_characters_not_bytes() {
    let src = "attr name = \"Größe\" + )\n";
    assert_eq!(
        rendered(src),
        "error: expected an expression, found `)`\n --> broken.cga:1:23\n  |\n1 | attr name = \"Größe\" + )\n  |                       ^ expected an expression\n"
    );
}

#[test]
fn diagnostics_name_the_right_file() {
    let mut sources = SourceMap::new();
    sources.add("main.cga", "Lot --> X.".to_string());
    let text = "attr a = 1\nattr b = ]\n";
    let file = sources.add("rules/imported.cga", text.to_string());
    let (_, diagnostics) = parse(file, text);
    assert_eq!(diagnostics.len(), 1);
    assert_eq!(diagnostics[0].span.unwrap().file, file);
    assert!(diagnostics[0]
        .render(&sources)
        .contains(" --> rules/imported.cga:2:10\n"));
}

#[test]
fn every_error_is_reported_once_and_the_rest_still_parses() {
    let src = "\
attr a = (1 + 2
Good1 --> X.
Bad1 --> extrude(1; 2) Y
Good2 --> split(x) { 1 : A | 2 : B }
Bad2 --> comp(f) { top : | side : C }
Bad3 --> split(x) { 1 : A ) | 2 : B }
Good3 --> [ t(0,1,0) Z. ]
Bad4 --> t(0, 0, 0 W.
Good4 --> NIL
";
    let (module, diagnostics) = parse(FileId(0), src);
    let lines: Vec<usize> = diagnostics
        .iter()
        .map(|d| src[..d.span.unwrap().start as usize].matches('\n').count() + 1)
        .collect();
    // One diagnostic for each broken declaration (the unclosed parenthesis
    // of `attr a` is found where the next declaration starts).
    assert_eq!(diagnostics.len(), 5, "{diagnostics:#?}");
    assert_eq!(lines, [2, 3, 5, 6, 8]);
    let names: Vec<String> = module
        .items
        .iter()
        .filter_map(|i| match i {
            Item::Rule(r) => Some(r.name.name.clone()),
            _ => None,
        })
        .collect();
    assert_eq!(
        names,
        ["Good1", "Bad1", "Good2", "Bad2", "Bad3", "Good3", "Bad4", "Good4"]
    );
    // Recovery inside a block keeps the entries after the bad one.
    let bad3 = module
        .items
        .iter()
        .map(sexpr::item)
        .find(|s| s.contains("Bad3"))
        .unwrap();
    assert_eq!(bad3, "(rule Bad3 (split x {1 : A | 2 : B}))");
    let good2 = module
        .items
        .iter()
        .map(sexpr::item)
        .find(|s| s.contains("Good2"))
        .unwrap();
    assert_eq!(good2, "(rule Good2 (split x {1 : A | 2 : B}))");
}

#[test]
fn too_deep_nesting() {
    let src = format!(
        "attr a = {}1{}\nLot --> X.\n",
        "(".repeat(300),
        ")".repeat(300)
    );
    let out = rendered(&src);
    assert!(
        out.starts_with(
            "error: expressions or blocks are nested too deeply\n --> broken.cga:1:110\n"
        ),
        "{out}"
    );
    assert!(out.ends_with(
        "  = the parser accepts about 100 levels of parentheses or nested blocks; the rest of this declaration is skipped\n"
    ));
    assert_eq!(out.matches("error:").count(), 1);
}

#[test]
fn unclosed_brackets_before_a_function_definition() {
    let src = "Lot --> [ A\nf = 3\nB --> split(x) { 1 : A\ng = 2\n";
    assert_eq!(
        rendered(src),
        r#"error: expected `]` to close the push, found identifier `f`
 --> broken.cga:2:1
  |
2 | f = 3
  | ^ expected `]`
  = the `[` was opened at line 1, column 9
error: expected `}` to close the block, found identifier `g`
 --> broken.cga:4:1
  |
4 | g = 2
  | ^ expected `}`
  = the `{` was opened at line 3, column 16
"#
    );
    let (module, _) = parse(FileId(0), src);
    let items: Vec<String> = module.items.iter().map(sexpr::item).collect();
    assert_eq!(
        items,
        [
            "(rule Lot [A])",
            "(fn f 3)",
            "(rule B (split x {1 : A}))",
            "(fn g 2)"
        ]
    );
}
