//! The tree shape of CGA's tricky constructs, on small inline sources.

use cga_syntax::ast::*;
use cga_syntax::{parse, sexpr, FileId, Span};

/// Parses `src`, asserts there is no diagnostic, returns the items as S-expressions.
#[track_caller]
fn items(src: &str) -> Vec<String> {
    let (module, diagnostics) = parse(FileId(0), src);
    assert!(diagnostics.is_empty(), "{src:?}: {diagnostics:#?}");
    module.items.iter().map(sexpr::item).collect()
}

#[track_caller]
fn one(src: &str) -> String {
    let all = items(src);
    assert_eq!(all.len(), 1, "{all:?}");
    all.into_iter().next().unwrap()
}

fn module(src: &str) -> Module {
    let (module, diagnostics) = parse(FileId(0), src);
    assert!(diagnostics.is_empty(), "{src:?}: {diagnostics:#?}");
    module
}

fn span(start: u32, end: u32) -> Span {
    Span::new(FileId(0), start, end)
}

#[test]
fn leaves_versus_dotted_names() {
    assert_eq!(
        one("Lot --> X. imp.Lot material.color.r imp.Lot. set(scope.sx, 1) Y.//c\n"),
        "(rule Lot X. imp.Lot material.color.r imp.Lot. (set scope.sx 1) Y.)"
    );
    // A leaf right before `]`, `|`, `}` and at the end of the file.
    assert_eq!(
        one("Lot --> [ A.] split(x){ 1 : B.| 2 : C.}*D."),
        "(rule Lot [A.] (split x {1 : B. | 2 : C.}*) D.)"
    );
    // The leaf's name span leaves the dot out.
    let m = module("R --> Leaf.");
    let Item::Rule(r) = &m.items[0] else { panic!() };
    let Body::Ops(stmts) = &r.body else { panic!() };
    assert_eq!(
        stmts[0],
        Stmt::Leaf(Ident {
            name: "Leaf".into(),
            span: span(6, 10)
        })
    );
}

#[test]
fn size_prefixes_apply_to_the_whole_expression() {
    assert_eq!(
        one("R --> t('-0.2, 0, ~1) tileUV(0, '1.85*8, '(a)/100) s(' 1, '~x, 0)"),
        "(rule R (t (' (neg 0.2)) 0 (~ 1)) (tileUV 0 (' (* 1.85 8)) (' (/ a 100))) (s (' 1) (' (~ x)) 0))"
    );
    assert_eq!(
        one("R --> split(x) { ~scope.sx/n : A | 'nTiles : B | 3 : C }"),
        "(rule R (split x {(~ (/ scope.sx n)) : A | (' nTiles) : B | 3 : C}))"
    );
    let m = module("R --> t('1.5*2, 0, 0)");
    let Item::Rule(r) = &m.items[0] else { panic!() };
    let Body::Ops(stmts) = &r.body else { panic!() };
    let Stmt::Call(call) = &stmts[0] else {
        panic!()
    };
    let arg = &call.args.as_ref().unwrap()[0];
    assert!(
        matches!(&arg.kind, ExprKind::Relative(inner) if matches!(inner.kind, ExprKind::Binary { op: BinaryOp::Mul, .. }))
    );
    assert_eq!(arg.span, span(8, 14));
    assert_eq!(call.span, span(6, 21));
    assert_eq!(call.name.span, span(6, 7));
}

#[test]
fn stochastic_chains_and_remainder() {
    assert_eq!(
        one("R --> 12.5% : NIL 0.3% : A. else : B"),
        "(rule R (stoch (12.5 NIL) (0.3 A.) (else B)))"
    );
    // `%` followed by a value is the remainder operator.
    assert_eq!(one("f(x) = x%3 == 0"), "(fn f(x) (== (% x 3) 0))");
    assert_eq!(
        one("c = 50% : 1 + 2 % 3 else : 4"),
        "(fn c (stoch (50 (+ 1 (% 2 3))) (else 4)))"
    );
    // Stochastic chain nested in a case branch and in an argument.
    assert_eq!(
        one("R --> case a : 30% : X else : Y else : set(n, 20% : \"p\" else : \"q\") Z"),
        "(rule R (case (a (stoch (30 X) (else Y))) (else (set n (stoch (20 \"p\") (else \"q\"))) Z)))"
    );
}

#[test]
fn case_chains() {
    assert_eq!(
        one("const h = case a > 1 : 2 case(a < 0): -1 else : 3"),
        "(const h (case ((> a 1) 2) ((< a 0) (neg 1)) (else 3)))"
    );
    assert_eq!(
        one("R --> case a : case b : X else : Y else : Z"),
        "(rule R (case (a (case (b X) (else Y))) (else Z)))"
    );
    assert_eq!(
        one("R --> case a : X else : case b : Y else : Z W"),
        "(rule R (case (a X) (else (case (b Y) (else Z W)))))"
    );
    // A nested chain ends with its `else` branch: the next `case` belongs to
    // the outer chain (CityEngine's manual, "Conditional rule", example 2).
    assert_eq!(
        one("Footprint(type) -->\n\
             case type == \"residential\" || type == \"park\":\n\
             case geometry.area/2 < 200 && geometry.area > 10 : extrude(10)\n\
             else: extrude(15)\n\
             case type == \"industrial\" : extrude(100)\n\
             else : NIL"),
        "(rule Footprint(type) (case ((|| (== type \"residential\") (== type \"park\")) (case ((&& (< (/ geometry.area 2) 200) \
         (> geometry.area 10)) (extrude 10)) (else (extrude 15)))) ((== type \"industrial\") (extrude 100)) (else NIL)))"
    );
    // Conditions may use the full operator set; chains inside a block entry.
    assert_eq!(
        one("R --> comp(f) { top : case scope.sx > 3 && !x : A else : B | side : C }"),
        "(rule R (comp f {top : (case ((&& (> scope.sx 3) (not x)) A) (else B)) | side : C}))"
    );
}

#[test]
fn nested_groups_with_repeat() {
    assert_eq!(
        one("R --> split(x){ 1 : X | { ~1 : Y | 0.2 : Z }* | 1 : X }"),
        "(rule R (split x {1 : X | {(~ 1) : Y | 0.2 : Z}* | 1 : X}))"
    );
    assert_eq!(
        one("R --> split(x){ { { 1 : A }* | 2 : B } | 3 : C }*"),
        "(rule R (split x {{{1 : A}* | 2 : B} | 3 : C}*))"
    );
    let m = module("R --> split(x){ 1 : X | { ~1 : Y }* }");
    let Item::Rule(r) = &m.items[0] else { panic!() };
    let Body::Ops(stmts) = &r.body else { panic!() };
    let Stmt::Call(call) = &stmts[0] else {
        panic!()
    };
    let block = call.block.as_ref().unwrap();
    assert!(!block.repeat);
    let BlockPart::Group(group) = &block.parts[1] else {
        panic!()
    };
    assert!(group.repeat);
    assert_eq!(group.parts.len(), 1);
}

#[test]
fn dynamic_imports() {
    assert_eq!(
        one("R --> imp(height = 20, Roof --> roofHip(30), width).Lot(2) imp().Lot"),
        "(rule R (imp.Lot import(height = 20, Roof --> (roofHip 30), width) 2) (imp.Lot import()))"
    );
    let m = module("R --> imp( h = 2 ).Lot");
    let Item::Rule(r) = &m.items[0] else { panic!() };
    let Body::Ops(stmts) = &r.body else { panic!() };
    let Stmt::Call(call) = &stmts[0] else {
        panic!()
    };
    assert_eq!(
        call.name,
        Ident {
            name: "imp.Lot".into(),
            span: span(6, 22)
        }
    );
    assert!(call.args.is_none());
    assert!(
        matches!(&call.import_overrides.as_ref().unwrap()[0], ImportOverride::Attr(name, _) if name.name == "h")
    );
}

#[test]
fn comp_function() {
    assert_eq!(
        one("const a = comp(fe) { front : comp.sel + comp.index | back = str(comp.index) }"),
        "(const a (compfn (fe) {front : (+ comp.sel comp.index) | back = (call str comp.index)}))"
    );
    // Multiplying a comp function's result: the `*` is not a repeat switch.
    assert_eq!(
        one("f = comp(e) { all : scope.sx } * 2"),
        "(fn f (* (compfn (e) {all : scope.sx}) 2))"
    );
}

#[test]
fn element_wise_operators_and_numbers() {
    assert_eq!(
        one("f = .-a .+ b .* c ./ d .% e .== f .!= g .< h .<= i .> j .>= k .&& .!l .|| m"),
        "(fn f (.|| (.&& (.!= (.== (.+ (.neg a) (.% (./ (.* b c) d) e)) f) (.>= (.> (.<= (.< g h) i) j) k)) (.not l)) m))"
    );
    assert_eq!(
        one("f = [.5, 1., 1.5e2, 2E-1, 1.==1, 3.-1]"),
        "(fn f [0.5 1 150 0.2 (.== 1 1) (.- 3 1)])"
    );
}

#[test]
fn operator_precedence() {
    assert_eq!(
        one("f = a || b && c == d < e + f * -g"),
        "(fn f (|| a (&& b (== c (< d (+ e (* f (neg g))))))))"
    );
    assert_eq!(
        one("f = a - b - c / d / e"),
        "(fn f (- (- a b) (/ (/ c d) e)))"
    );
    assert_eq!(
        one("f = !(a != b) + +1"),
        "(fn f (+ (not (!= a b)) (plus 1)))"
    );
}

#[test]
fn arrays_ranges_and_indexing() {
    assert_eq!(one("a = [1, 2; 3, 4]"), "(fn a [1 2; 3 4])");
    assert_eq!(
        one("a = [0:2 ; 3:-1:1, x]"),
        "(fn a [(range 0 2); (range 3 (neg 1) 1) x])"
    );
    assert_eq!(
        one("a = b[0:2, [0,2]][1] + f(x)[0] + [1,2][1]"),
        "(fn a (+ (+ (index (index b (range 0 2) [0 2]) 1) (index (call f x) 0)) (index [1 2] 1)))"
    );
    assert_eq!(
        one("a = floatArray[1:3]"),
        "(fn a (index floatArray (range 1 3)))"
    );
    assert_eq!(
        one("a = [case x : 1 else : 2, 30% : 3 else : 4]"),
        "(fn a [(case (x 1) (else 2)) (stoch (30 3) (else 4))])"
    );
}

#[test]
fn with_locals_and_typed_params() {
    assert_eq!(
        one("f(float a, string[] b, bool c, bool[] d, float[] e, string s, u) with ( x := a  y := x*2 ) = y"),
        "(fn f(float a, string[] b, bool c, bool[] d, float[] e, string s, u) (with x := a, y := (* x 2)) y)"
    );
    assert_eq!(
        items("attr a with(x := 1) = x\nR(n) with (k := n) --> X.\nconst c(p) = p"),
        [
            "(attr a (with x := 1) x)",
            "(rule R(n) (with k := n) X.)",
            "(const c(p) p)"
        ]
    );
}

#[test]
fn annotations_with_named_arguments() {
    assert_eq!(
        one("@Range(min=1, max=10, stepsize=0, restricted=true) @Enum(\"a\",\"b\") @Unknown(x) attr h = 3"),
        "(attr @Range(min=1 max=10 stepsize=0 restricted=true) @Enum(\"a\" \"b\") @Unknown(x) h 3)"
    );
    assert_eq!(
        one("@Hidden\nimport x : \"x.cga\""),
        "(import @Hidden x \"x.cga\")"
    );
    assert_eq!(
        one("@StartRule\nstart Lot --> X."),
        "(start-rule @StartRule Lot X.)"
    );
}

#[test]
fn where_rule_bodies_end() {
    // A function definition, a start rule, a rule with locals and a rule
    // with parameters all end the body before them.
    assert_eq!(
        items(
            "A --> X Y(1)\nsize = rand(1,3)\nB --> start(20)\nstart C --> D\nE with (k := 1) --> F\n\
             G(a, b) --> H\nI(a) = a\nextension J --> K\n@Hidden\nL --> M style S\nN --> O"
        ),
        [
            "(rule A X (Y 1))",
            "(fn size (call rand 1 3))",
            "(rule B (start 20))",
            "(start-rule C D)",
            "(rule E (with k := 1) F)",
            "(rule G(a, b) H)",
            "(fn I(a) a)",
            "(extension-rule J K)",
            "(rule @Hidden L M)",
            "(style S)",
            "(rule N O)",
        ]
    );
    // `start` as a rule name and as a call.
    assert_eq!(
        items("A --> X\nstart --> B\nstart(x) = x\nC --> start(1) start"),
        [
            "(rule A X)",
            "(rule start B)",
            "(fn start(x) x)",
            "(rule C (start 1) start)"
        ]
    );
    // Inside braces `side = X` is a comp entry, not a function.
    assert_eq!(
        one("R --> comp(f) { top : A |\n side = B }"),
        "(rule R (comp f {top : A | side = B}))"
    );
    // A block on the line after its operation.
    assert_eq!(
        one("R --> shapeL(4, 4)\n    { shape : A | remainder : B }"),
        "(rule R (shapeL 4 4 {shape : A | remainder : B}))"
    );
    // Calls written with a space before the parenthesis.
    assert_eq!(
        one("R --> color (1, 0, 0) report (\"a\", touches (all, \"b\"))"),
        "(rule R (color 1 0 0) (report \"a\" (call touches all \"b\")))"
    );
}

#[test]
fn selector_keywords_are_names() {
    assert_eq!(
        one("R --> alignScopeToGeometry(yUp, 0, longest) offset(-1, inside) extrude(world.up, 10) center(xyz) r(scopeCenter, 0, 45, 0) comp(f) { street.front : A | isTagged(\"win\") : B | 0 : C }"),
        "(rule R (alignScopeToGeometry yUp 0 longest) (offset (neg 1) inside) (extrude world.up 10) (center xyz) \
         (r scopeCenter 0 45 0) (comp f {street.front : A | (call isTagged \"win\") : B | 0 : C}))"
    );
}

#[test]
fn strings_comments_line_endings_and_unicode() {
    let src = "\u{feff}version \"2023.0\"\r\n# comment\r\n/* multi\r\n line */ attr s = \"über \\\"quoted\\\"\\n\\t\\\\ end\" // ünïcødé\r\nLot --> print(s) # tail\r\n";
    assert_eq!(
        items(src),
        [
            "(version \"2023.0\")",
            "(attr s \"über \\\"quoted\\\"\\n\\t\\\\ end\")",
            "(rule Lot (print s))"
        ]
    );
    let m = module(src);
    let Item::Attr(attr) = &m.items[1] else {
        panic!()
    };
    assert_eq!(
        attr.value.kind,
        ExprKind::Str("über \"quoted\"\n\t\\ end".into())
    );
}

#[test]
fn spans_of_declarations() {
    let src = "@Hidden\nattr h = 1 + 2\nLot --> X.";
    let m = module(src);
    let Item::Attr(attr) = &m.items[0] else {
        panic!()
    };
    assert_eq!(attr.annotations[0].span, span(0, 7));
    assert_eq!(attr.span, span(8, 22));
    assert_eq!(&src[attr.value.span.range()], "1 + 2");
    let Item::Rule(rule) = &m.items[1] else {
        panic!()
    };
    assert_eq!(&src[rule.span.range()], "Lot --> X.");
    assert_eq!(&src[rule.name.span.range()], "Lot");
}
