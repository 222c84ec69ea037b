//! The rule examples of the seed pages (split, subdivision split, splitArea,
//! comp) and of the CGA reference pages, as small complete files under
//! `tests/fixtures/`: `seed_*` (seed pages), `ref_*` (reference examples
//! gathered by topic, fragments wrapped into rules) and `ref_page_*` (every
//! complete example of one reference page, in page order; examples that the
//! page prints on one line are broken before each declaration). Each must
//! parse without a diagnostic, and the tricky ones must give exactly the
//! expected tree.

use std::path::{Path, PathBuf};

use cga_syntax::ast::*;
use cga_syntax::{parse, sexpr, FileId, SourceMap};

fn fixtures_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures")
}

fn fixture(name: &str) -> Module {
    let path = fixtures_dir().join(name);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let (module, diagnostics) = parse(FileId(0), &text);
    if !diagnostics.is_empty() {
        let mut sources = SourceMap::new();
        sources.add(&path, text);
        let rendered: String = diagnostics.iter().map(|d| d.render(&sources)).collect();
        panic!("{name} has diagnostics:\n{rendered}");
    }
    module
}

/// The S-expressions of all items of a fixture, one per line.
fn items(name: &str) -> Vec<String> {
    fixture(name).items.iter().map(sexpr::item).collect()
}

/// Asserts that the fixture has an item printing exactly as `expected`.
#[track_caller]
fn has(name: &str, expected: &str) {
    let all = items(name);
    assert!(
        all.iter().any(|s| s == expected),
        "{name}: no item\n  {expected}\namong\n  {}",
        all.join("\n  ")
    );
}

#[test]
fn every_fixture_parses_without_diagnostics() {
    let mut names: Vec<String> = std::fs::read_dir(fixtures_dir())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".cga"))
        .collect();
    names.sort();
    assert!(
        names.iter().filter(|n| n.starts_with("seed_")).count() >= 30,
        "{names:?}"
    );
    assert!(
        names.iter().filter(|n| n.starts_with("ref_")).count() >= 25,
        "{names:?}"
    );
    for name in &names {
        assert!(!fixture(name).items.is_empty(), "{name} is empty");
    }
}

#[test]
fn seed_split_examples() {
    has(
        "seed_split_relative.cga",
        "(rule A (split x {(' 0.5) : Z | (' 0.1) : (Y 2) | (' 0.2) : (X 1)}))",
    );
    has(
        "seed_split_mixed.cga",
        "(rule A (split x {3.3 : (Z 1) | (~ 3) : (Y 2) | 5 : (X 1)}))",
    );
    // `} *` with a space is still the repeat switch.
    has(
        "seed_split_repeat.cga",
        "(rule A (split x {2 : (X 2) | 1 : (Y 1)}*))",
    );
    has(
        "seed_split_nested_repeat.cga",
        "(rule A (split x {1 : (X 3) | {(~ 1) : (Y 2) | 0.2 : (Z 1) | (~ 1) : (Y 2)}* | 1 : (X 3)}))",
    );
    has(
        "seed_split_leading_repeat.cga",
        "(rule A (split x {{1 : (X 3) | (~ 3) : (Y 1)}* | 1 : (X 3)}))",
    );
    has(
        "seed_split_cylinder.cga",
        "(rule A (i \"cylinder.hor.obj\") (t 0 (' 0.5) 0) (split x {{(~ 0.75) : XX | (~ 1) : NIL}* | (~ 0.5) : XX}))",
    );
    has(
        "seed_split_rules.cga",
        "(rule X(h) (s (' 1) (' h) (' 1)) (color \"#0000ff\"))",
    );
    has(
        "seed_split_street.cga",
        "(rule Street (texture \"builtin:uvtest.png\") \
         (split u unitSpace 0 {(~ 10) : NIL | (~ 3) : (color \"#ff0000\") X | (~ 10) : NIL}*))",
    );
    has(
        "seed_subdivision_absolute.cga",
        "(rule Lot3 (split x {1.5 : (Green 1) | (neg 2) : (Yellow 1) | 1.5 : (Blue 0.5) | 1.5 : (Green 1) \
         | 0 : (Yellow 1) | 1.5 : (Green 1)}))",
    );
    has(
        "seed_subdivision_repeat.cga",
        "(rule R4 (split x {(~ 1) : (Blue 2) | {2 : (Green 1)}*}))",
    );
    has(
        "seed_subdivision_patterns.cga",
        "(rule P3 (split x {(~ 1) : (Green 1) | {(~ 1) : (Yellow 2)}* | (~ 1) : (Green 1) | {(~ 1) : (Blue 2)}* \
         | (~ 1) : (Green 1)}))",
    );
}

#[test]
fn seed_split_area_and_comp_examples() {
    has(
        "seed_splitarea_nested.cga",
        "(rule Lot (print (+ \"total area = \" geometry.area)) (splitArea x {(~ 1) : (splitArea z {(' 0.5) : Red \
         | (' 0.5) : Yellow}) | (~ 1) : (splitArea z {(' 0.5) : Green | (' 0.5) : Cyan}) | (~ 1) : (splitArea z \
         {(' 0.5) : Blue | (' 0.5) : Magenta})}))",
    );
    has(
        "seed_splitarea_adjust.cga",
        "(rule SplitNoAdjust (splitArea x noAdjust {(' 0.2) : (splitArea z noAdjust {(' 0.2) : SplitLeaf}*)}*))",
    );
    has(
        "seed_splitarea_adjust.cga",
        "(rule SplitLeaf (color 0.5 0.5 0.5) Geometry. (primitiveQuad) (t 0 0.02 0) Pink (comp e {all : (color 0 0 0) Edge.}))",
    );
    has(
        "seed_splitarea_repeat.cga",
        "(rule ColorMe (case ((== split.index 0) Red) ((== split.index 1) Yellow) ((== split.index 2) Green) \
         ((== split.index 3) Cyan) (else Blue)))",
    );
    has(
        "seed_splitarea_block.cga",
        "(fn alpha (/ (- geometry.area minArea) (- maxArea minArea)))",
    );
    // A comment between `-->` and the body.
    has(
        "seed_splitarea_colors.cga",
        "(rule Pink (color 1 0.5 0.5 0.3))",
    );
    has(
        "seed_comp_operators.cga",
        "(rule Sides2 (comp f {side = Sides}))",
    );
    has(
        "seed_comp_components.cga",
        "(rule Groups (comp g {2 : Trunk. | all = (set material.opacity 0.2) Foilage.}))",
    );
    has(
        "seed_comp_index_trim.cga",
        "(rule Tube (comp f {0 : X | 2 : X | 4 : X}))",
    );
}

#[test]
fn comp_selectors_and_operators() {
    has(
        "ref_comp.cga",
        "(rule Sphere2 (comp f {(|| top front) = X.}))",
    );
    has(
        "ref_comp.cga",
        "(rule Triangle (comp f {(&& (> (call geometry.area) 1) (not inside)) : X.}))",
    );
    has(
        "ref_comp.cga",
        "(rule Lot4 (extrude 10) (comp f {front =: (color rand rand rand) Front. | all = Mass.}))",
    );
    has(
        "ref_comp.cga",
        "(rule Init2 (envelope normal 4 0 45 3 45 2.5 50 2 50) (comp f {(&& (call isTagged \"envelope.bottom\" e) \
         (call isTagged \"envelope.side.slope\")) : ShowEnvelopeAutoTags}))",
    );
    has(
        "ref_comp.cga",
        "(rule Lot7 (setback 10 {street.front : (color 0 1 0) FrontYard | remainder : Building}))",
    );
    has(
        "ref_comp.cga",
        "(fn mySelectorFunc (|| (call geometry.isOriented top) (== geometry.nVertices 3)))",
    );
}

#[test]
fn comp_function_examples() {
    has(
        "ref_comp_function.cga",
        "(const array (compfn (v) {all : comp.index}))",
    );
    has(
        "ref_comp_function.cga",
        "(const array3 (compfn (fe) {front : (+ comp.sel comp.index) | back = (call str comp.index)}))",
    );
    has(
        "ref_comp_function.cga",
        "(const array4 (compfn (f) {side = touches}))",
    );
    has(
        "ref_setback.cga",
        "(const dists2 (compfn (fe) {inside = 0 | front : (case ((== comp.index 0) 4) (else 5)) | back = 2 | side = 0.5}))",
    );
    has(
        "ref_setback.cga",
        "(const dists (compfn (fe) {all : (case ((== (% comp.index 2) 0) 1) (else 6))}))",
    );
    has(
        "ref_bool_inline.cga",
        "(fn taggedArea(name) (call sum (compfn (f) {(call isTagged name) : geometry.area})))",
    );
}

#[test]
fn import_examples() {
    let main = items("ref_import_main.cga");
    assert_eq!(
        &main[..10],
        [
            "(import imp \"imp.cga\")",
            "(import impStyles (styles mystyle other) \"imp.cga\")",
            "(import protected \"imp.cga\" (height))",
            "(import protectedAll \"imp.cga\" ())",
            "(import redefined \"imp.cga\" (height = 20))",
            "(import roof \"imp.cga\" (Roof --> (roofHip 30)))",
            "(import both \"imp.cga\" (height = 20, Roof --> (roofHip 30)))",
            "(import @Hidden hide_me \"rule.cga\")",
            "(import @Hidden(attribute_1 attribute_2) rule \"rule.cga\")",
            "(import \"unaliased.cga\")",
        ]
    );
    has(
        "ref_import_main.cga",
        "(rule Lot2 (imp.Lot import(height = 20)))",
    );
    has(
        "ref_import_main.cga",
        "(rule Building(h) (imp.Lot import(height = (+ h (call rand 10)))))",
    );
    has(
        "ref_import_main.cga",
        "(rule Lot4 (set imp.height 20) (imp.Lot import()))",
    );
    has(
        "ref_import_mytemple.cga",
        "(import CorinthianTemple \"temple.cga\" (columnHeight = 8, Column --> CorinthianColumn.start, \
         Roof --> (color 1 0.5 0.5) MyRoof))",
    );
    has(
        "ref_import_plants.cga",
        "(rule Plant2 (plant.Generate import(Name = getName)))",
    );
    has(
        "ref_extension.cga",
        "(import rule \"rule.cga\" (Roof(angle) --> (roofGable angle)))",
    );
    has(
        "ref_extension.cga",
        "(extension-rule Roof(angle) (roofHip angle))",
    );
    has(
        "ref_import_temple.cga",
        "(rule CreateColumns (offset (neg columnWidth) border) (comp f {all : (extrude columnHeight) \
         (split x {{(~ columnWidth) : Column | (~ (* 2 columnWidth)) : NIL}* | (~ columnWidth) : NIL})}))",
    );
    has(
        "ref_import_temple.cga",
        "(start-rule Temple CreateColumns CreateRoof)",
    );
    has(
        "ref_import_imp.cga",
        "(attr angle (case ((> height 10) 0) (else 30)))",
    );
}

#[test]
fn start_style_version_examples() {
    assert_eq!(
        items("ref_start.cga"),
        [
            "(start-rule Init (start 20))",
            "(start-rule Init(height) (extrude height))",
            "(import rule \"rule.cga\")",
            "(rule Lot (rule.start 10))",
        ]
    );
    let style = items("ref_style.cga");
    assert_eq!(style[2], "(style Blue_Bunny)");
    assert_eq!(style[5], "(style Red_Bull extends Blue_Bunny)");
    assert_eq!(style.len(), 8);
    assert_eq!(
        items("ref_version.cga"),
        ["(version \"2023.0\")", "(rule Lot X.)"]
    );
}

#[test]
fn with_locals() {
    assert_eq!(
        items("ref_with.cga"),
        [
            "(attr a (with x := \"example\") x)",
            "(const b (with x := [0 1 2], y := 0) (index x y))",
            "(fn f(a) (with x := a, y := x) y)",
            "(rule Lot (with x := (call f 1)) (extrude x))",
            "(fn dist2d(x1, y1, x2, y2) (with d1 := (- x2 x1), d2 := (- y2 y1)) (call sqrt (+ (* d1 d1) (* d2 d2))))",
            "(rule Lot2 (print (+ \"distance: \" (call dist2d 1 1 2 2))))",
            "(rule Lot3 (with area := (call geometry.area)) (s (' 2) 0 (' 2)) (print (+ \"initial area: \" area)) \
             (print (+ \"altered area: \" (call geometry.area))))",
        ]
    );
    has(
        "ref_modify.cga",
        "(rule Move(centerX, centerZ, a, b) (with x := (- scope.tx centerX), z := (- scope.tz centerZ)) \
         (t 0 (call hyperbolic x z a b) 0))",
    );
}

#[test]
fn annotations() {
    has(
        "ref_annotations.cga",
        "(attr @Range(min=0 max=45 stepsize=15 restricted=false) angle2 30)",
    );
    has(
        "ref_annotations.cga",
        "(attr @Enum(10 20 30 restricted=false) height2 20)",
    );
    has(
        "ref_annotations.cga",
        "(attr @Handle(shape=Solid align=right) dimension 40)",
    );
    has(
        "ref_annotations.cga",
        "(attr @Group(\"First\" \"Second\" \"Third\" 1) grouped2 0)",
    );
    has("ref_annotations.cga", "(attr @Order(1) @Hidden packed 1)");
    has(
        "ref_annotations.cga",
        "(rule @StartRule @InPolygon @Out(granularity=separatedShapes) Start NIL)",
    );
    has("ref_annotations.cga", "(fn @Hidden helper(x) (* x 2))");
    has("ref_annotations.cga", "(const @Hidden limit 3)");
    // A file-level annotation attaches to the declaration that follows it.
    has(
        "ref_annotations.cga",
        "(attr @RuleFileDescription(\"Creates a building mass from a lot.\") @Angle angle 180)",
    );
    let module = fixture("ref_annotations.cga");
    let Item::Attr(attr) = &module.items[24] else {
        panic!()
    };
    assert_eq!(attr.name.name, "height4");
    let AnnotationArg::Named(key, value) = &attr.annotations[0].args[1] else {
        panic!()
    };
    assert_eq!(key.name, "max");
    assert_eq!(value.kind, ExprKind::Float(50.0));
}

#[test]
fn arrays_ranges_and_element_wise_operators() {
    has("ref_arrays.cga", "(const m2 [(range 0 2); 3 3 3])");
    has("ref_arrays.cga", "(const s2 [(range 4 (neg 1) 2)])");
    has("ref_arrays.cga", "(const w1 (.not [true false]))");
    has("ref_arrays.cga", "(const w5 (.neg [1; 2]))");
    has(
        "ref_arrays.cga",
        "(const w6 (.* (neg 4) [0.25; (neg 0.75); (neg 1)]))",
    );
    has("ref_arrays.cga", "(const w7 (./ 12 [2 3 4]))");
    has(
        "ref_arrays.cga",
        "(const w12 (.<= [\"a\"; \"b\"; \"c\"] \"b\"))",
    );
    // `1.==1` is `1 .== 1`, as CityEngine reads it.
    has("ref_arrays.cga", "(const w16 (.== 1 1))");
    has(
        "ref_arrays.cga",
        "(fn fibonacci(a, n) (case ((== (call size a) n) a) (else (call fibonacci [a (+ (index a (- (call size a) 2)) \
         (index a (- (call size a) 1)))] n))))",
    );
    has(
        "ref_index.cga",
        "(const i5 (index array2d (range 0 2) [0 2]))",
    );
    has(
        "ref_index.cga",
        "(const i2 (index array (range 3 (neg 1) 1)))",
    );
    has(
        "ref_index.cga",
        "(const i6 (index array (.&& (.> array 1) (.<= array 3))))",
    );
    has(
        "ref_index.cga",
        "(fn ones(rows, cols) (.+ (index floatArray (range 1 rows) (range 1 cols)) 1))",
    );
    has(
        "ref_index.cga",
        "(const b [1 0 0 0; 0 2 0 0; 0 0 3 0; 0 0 0 4])",
    );
    has(
        "ref_index.cga",
        "(fn findPrimes(limit, a, primes) (case ((<= (index a 0) limit) (call findPrimes limit (index a \
         (.!= (.% a (index a 0)) 0)) [primes (index a 0)])) (else [primes a])))",
    );
    has(
        "ref_index.cga",
        "(const cells (call splitString file \"$;|\\n\"))",
    );
}

#[test]
fn push_pop_nil_and_leaves() {
    has(
        "ref_pushpop.cga",
        "(rule House2 Cylinder [(t 0 0 (' 1)) Cylinder] [(t 0 0 (' (neg 1))) Cylinder] [(t (' 1) 0 0) Cylinder] \
         [(t (' (neg 1)) 0 0) Cylinder])",
    );
    has(
        "ref_pushpop.cga",
        "(rule Lot2 (s 1 1 1) [(case ((== scope.sx 1) (primitiveCube) Cube.) (else (primitiveCylinder) Cylinder.))])",
    );
    has(
        "ref_nil.cga",
        "(rule Erker (case ((> scope.sx ErkerStop) (s (' ErkerFact) (' ErkerFact) 0) (center xy) \
         (alignScopeToGeometry yUp 0) (extrude ErkerDepth) X (comp f {top : Erker})) (else NIL)))",
    );
}

#[test]
fn blocks_without_heads_and_two_head_entries() {
    has(
        "ref_bool_inline.cga",
        "(rule Middle (subtract {Cube | Sphere}))",
    );
    has(
        "ref_bool_inline.cga",
        "(rule Init (extrude 40) (subtract {Mass. | (t 20 (neg 15) (neg 15)) (rotate rel scope 15 12 25)}) SurfaceSplitter)",
    );
    has(
        "ref_bool_inline.cga",
        "(rule Init4 (inline {LayoutA LayoutB}) ChooseLayout)",
    );
    has(
        "ref_bool_inline.cga",
        "(rule Init3 inline Volumes Colorize)",
    );
    has(
        "ref_scatter.cga",
        "(rule Init (scatter surface 100 gaussian left (' 0.1) {Leaf}))",
    );
    has(
        "ref_split_and_setback_perimeter.cga",
        "(rule Lot (splitAndSetbackPerimeter 6 {40 : 5 : Yellow | 20 : 10 : Blue} {remainder : Grey}))",
    );
    has(
        "ref_split_and_setback_perimeter.cga",
        "(rule Lot3 (splitAndSetbackPerimeter 0 {(~ 30) : (call rand 3 15) : (extrude (call rand 2 10)) Yellow}* \
         {remainder : Grey}))",
    );
    let module = fixture("ref_bool_inline.cga");
    let Item::Rule(middle) = &module.items[3] else {
        panic!()
    };
    let Body::Ops(stmts) = &middle.body else {
        panic!()
    };
    let Stmt::Call(call) = &stmts[0] else {
        panic!()
    };
    assert!(call.args.is_none());
    let parts = &call.block.as_ref().unwrap().parts;
    assert!(
        matches!(&parts[0], BlockPart::Unlabeled { body: Body::Ops(ops), .. } if ops.len() == 1)
    );
}

#[test]
fn stochastic_and_case_chains() {
    has(
        "ref_report_stochastic.cga",
        "(rule Window (stoch (40 (report \"windowarea\" (call geometry.area)) (report \"windows.open\" 1) NIL) \
         (else (report \"windowarea\" (call geometry.area)) (report \"windows.closed\" 1) (color \"#aaffaa\"))))",
    );
    has(
        "ref_import_plants.cga",
        "(fn getName (stoch (33 \"California Bay\") (33 \"California Incense Cedar\") (else \"California Walnut\")))",
    );
    has(
        "ref_import_plants.cga",
        "(rule Plant (stoch (33 bay.Generate) (33 cedar.Generate) (else walnut.Generate)))",
    );
    has(
        "ref_operators.cga",
        "(fn f(a, b, c, x) (case ((not a) 1) ((|| (|| a b) (call f x)) 2) ((&& a (call f x)) 3) ((== a b) 4) \
         ((!= a b) 5) ((< a b) 6) ((<= a b) 7) ((> a b) 8) ((>= a b) 9) (else (- (+ c b) (% (/ (* (plus b) (neg b)) 4) 10)))))",
    );
    has(
        "ref_bool_inline.cga",
        "(rule ChooseLayout (case ((> (call taggedArea \"LayoutA\") (call taggedArea \"LayoutB\")) inline \
         (Extract \"LayoutA\") Mass) (else inline (Extract \"LayoutB\") Mass)))",
    );
}
