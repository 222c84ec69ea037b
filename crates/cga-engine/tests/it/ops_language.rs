//! The examples of the reference pages of the language: `with`, `const`,
//! `attr`, `style` (only the Default style is generated), `import` (with
//! `start` and `extension`), and the arrays (array initialization, index
//! and colon operators, array type operators) through rules: what `print`
//! writes.
//!
//! The import examples are rule files under tests/rules/ops/import.

use crate::ops_common::*;

/// The text `print` writes for an array written as on the reference pages:
/// `[1,2;3,4]` (rows by `;`), `["a","b"]`, `[true;false]`.
fn show(page: &str) -> String {
    let inner = page
        .trim()
        .strip_prefix('[')
        .and_then(|s| s.strip_suffix(']'))
        .unwrap_or_else(|| panic!("not an array: {page}"));
    let rows: Vec<Vec<String>> = inner
        .split(';')
        .map(|r| {
            r.split(',')
                .map(|e| e.trim().trim_matches('"').to_string())
                .filter(|e| !e.is_empty())
                .collect()
        })
        .collect();
    if rows.len() == 1 {
        return format!("({})[{}]", rows[0].len(), rows[0].join(","));
    }
    let cols = rows[0].len();
    let mut widths = vec![0; cols];
    for r in &rows {
        for (c, e) in r.iter().enumerate() {
            widths[c] = widths[c].max(e.len());
        }
    }
    let mut out = format!("({}x{})", rows.len(), cols);
    for r in &rows {
        out.push('\n');
        for (c, e) in r.iter().enumerate() {
            out.push_str(&" ".repeat(widths[c] + 3 - e.len()));
            out.push_str(e);
        }
    }
    out
}

/// Prints each expression (after the definitions `defs`) and compares with
/// the expected texts: arrays in page notation (converted by [`show`]),
/// anything else literally.
#[track_caller]
fn check_prints(defs: &str, cases: &[(&str, &str)]) {
    let mut src = format!("{defs}\nLot -->\n");
    for (e, _) in cases {
        src.push_str(&format!("    print({e})\n"));
    }
    let g = gen(&src).ok();
    let p = g.prints();
    assert_eq!(p.len(), cases.len());
    for (got, (e, expected)) in p.iter().zip(cases) {
        let expected = if expected.starts_with('[') {
            show(expected)
        } else {
            expected.to_string()
        };
        assert_eq!(got, &expected, "print({e})");
    }
}

fn import_file(name: &str) -> std::path::PathBuf {
    rules_dir().join("import").join(name)
}

// ---------------------------------------------------------------------------
// with, const, attr
// ---------------------------------------------------------------------------

/// with.md, the four definitions: an attribute, a const function, a
/// function and a rule with local variables.
#[test]
fn with_definitions() {
    let src = "attr  a  with ( x := \"example\" )        = x\n\
               const b  with ( x := [0,1,2]  y := 0 )  = x[y]\n\
               f(a)     with ( x := a  y := x )        = y\n\
               Lot      with ( x := f(1) )             --> extrude(x) print(a) print(b) print(f(7)) print(scope.sy) X\n";
    let g = gen(src).ok();
    assert_eq!(g.prints(), ["example", "0", "7", "1"]);
    assert_near(g.volume(), 600.0, 1e-9);
}

/// with.md: dist2d(1,1,2,2) with locals d1, d2 is sqrt(2).
#[test]
fn with_distance_function() {
    let src = "dist2d(x1, y1, x2, y2) with ( d1 := x2-x1  \n                              d2 := y2-y1 )\n= sqrt(d1*d1 + d2*d2) \n\
               Lot --> print(\"distance: \" + dist2d(1,1,2,2)) // 1.414\n";
    let g = gen(src).ok();
    assert_eq!(g.prints(), ["distance: 1.4142135623731"]);
}

/// with.md: the local is evaluated when the rule is invoked; the area of
/// the lot (600) is kept after s('2,0,'2) made it 2400.
#[test]
fn with_is_evaluated_once() {
    let src = "Lot with ( area := geometry.area() ) --> s('2,0,'2)\n                                         print(\"initial area: \" + area)\n                                         print(\"altered area: \" + geometry.area())\n";
    let g = gen(src).ok();
    assert_eq!(g.prints(), ["initial area: 600", "altered area: 2400"]);
    let g = gen("Lot with ( r := rand ) --> print(r) print(r) print(r == rand)\n").ok();
    let p = g.prints();
    assert_eq!(p[0], p[1]);
    assert_eq!(p[2], "false");
}

/// const.md: `const height = 250; Lot --> extrude(height)`. Constants are
/// evaluated once and are not attributes (they cannot be set from outside).
#[test]
fn const_example() {
    let src = "const height = 250\n\nLot --> extrude(height) print(scope.sy) X. A A\nconst r = rand\nA --> print(r) NIL\n";
    let g = gen(src).ok();
    let p = g.prints();
    assert_eq!(p[0], "250");
    assert_eq!(p[1], p[2], "one value for the whole generation");
    let (lo, hi) = g.bounds();
    assert_near(hi.y - lo.y, 250.0, 1e-9);
    let dir = std::env::temp_dir().join(format!("cga-ops-const-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("c.cga");
    std::fs::write(&path, src).unwrap();
    let mut sources = cga_syntax::SourceMap::new();
    let program = cga_engine::load(&cga_world::DiskWorld, &path, &mut sources)
        .usable()
        .unwrap();
    assert!(program.main_attr("height").is_none());
}

/// attr.md: `attr height = 250; Lot --> extrude(height)`; an attribute's
/// value can be set from outside (the command line's --attr).
#[test]
fn attr_example() {
    let src = "attr height = 250\n\nLot --> extrude(height) print(height)\n";
    let g = gen(src).ok();
    assert_eq!(g.prints(), ["250"]);
    assert_near(g.bounds().1.y, 250.0, 1e-9);
    let g = gen_with(src, &Opts::default().attr("height", "30")).ok();
    assert_eq!(g.prints(), ["30"]);
    assert_near(g.bounds().1.y, 30.0, 1e-9);
}

/// Attributes are evaluated once, on the initial shape, before any rule.
#[test]
fn attr_is_evaluated_on_the_initial_shape() {
    let src = "attr area = geometry.area\nattr r = rand\nLot --> extrude(10) print(area) print(r) A\nA --> print(r)\n";
    let g = gen(src).ok();
    let p = g.prints();
    assert_eq!(p[0], "600");
    assert_eq!(p[1], p[2]);
}

// ---------------------------------------------------------------------------
// style
// ---------------------------------------------------------------------------

/// style.md, "Defining Styles": only the Default style is generated: a
/// green cube (the other styles would insert a bunny and a bull).
#[test]
fn style_default_only() {
    let src = "attr color = \"#00ff00\" // define \"color\" attribute (green)\n\
               Shape --> color(color) primitiveCube() // create a green cube\n\n\
               // define a new style \"Blue_Bunny\"\nstyle Blue_Bunny\n\
               attr color = \"#0000ff\" // re-define \"color\" attribute (blue)\n\
               Shape --> color(color) i(\"bunny.obj\") // creates a blue bunny\n\n\
               // define a new style \"Red_Bull\"\nstyle Red_Bull\n\
               attr color = \"#ff0000\" // re-define \"color\" attribute (red)\n\
               Shape --> color(color) i(\"bull.obj\") // creates a red bull\n";
    let g = gen_with(src, &Opts::default().start("Shape")).ok();
    assert_eq!(g.meshes().len(), 1);
    assert_eq!(g.meshes()[0].faces.len(), 6);
    for m in g.face_materials() {
        assert_eq!(rgb255(m), [0, 255, 0]);
    }
    assert_near(g.volume(), 20.0 * 25.0 * 30.0, 1e-6);
    assert!(g.warnings().is_empty(), "{:?}", g.warnings());
}

// ---------------------------------------------------------------------------
// import, start, extension
// ---------------------------------------------------------------------------

/// Runs an import example and returns (prints, height of the model).
fn run_import(name: &str) -> (Vec<String>, f64) {
    let g = gen_file(&import_file(name), &Opts::default()).ok();
    let (lo, hi) = g.bounds();
    let h = if g.meshes().is_empty() {
        0.0
    } else {
        hi.y - lo.y
    };
    (g.prints(), h)
}

/// import.md, syntax 1: `imp.Lot` runs the imported rule (extrude(10)).
#[test]
fn import_reference() {
    let (_, h) = run_import("main_plain.cga");
    assert_near(h, 10.0, 1e-9);
}

/// import.md, syntax 2: importing only the style `mystyle` of the
/// imported file gives its rules: the extrusion is 20 high.
#[test]
fn import_selected_style() {
    let (_, h) = run_import("main_style.cga");
    assert_near(h, 20.0, 1e-9);
}

/// import.md, "Attribute redefinition by propagation", "Attribute
/// protection" (both forms) and "Explicit attribute ... override".
#[test]
fn import_attribute_propagation_protection_override() {
    for (file, height) in [
        ("main_propagate.cga", 20.0),
        ("main_protect.cga", 10.0),
        ("main_protect_all.cga", 10.0),
        ("main_explicit.cga", 20.0),
    ] {
        let (p, h) = run_import(file);
        assert_eq!(p, [height.to_string()], "{file}");
        assert_near(h, height, 1e-9);
    }
}

/// import.md, "Dynamic attribute and rule override": the redefinition only
/// holds for the call `imp( height = 20 ).Lot`.
#[test]
fn import_dynamic_override() {
    let (p, _) = run_import("main_dynamic.cga");
    assert_eq!(p, ["20", "10"]);
}

/// import.md, syntax 6: the importer redefines the extension rule Roof;
/// with a dynamic import after a static one, the dynamic height (30) and
/// the static Roof override both hold.
#[test]
fn import_extension_rule_override() {
    let (p, h) = run_import("main_rule_override.cga");
    assert_eq!(p, ["height 10", "hip 30"]);
    assert_near(h, 10.0, 1e-9);
    let (p, h) = run_import("main_dynamic_keeps_override.cga");
    assert_eq!(p, ["height 30", "hip 30"]);
    assert_near(h, 30.0, 1e-9);
}

/// import.md, "Re-initialization of attributes": each dynamic call
/// re-evaluates `angle` with its own height (5 + rand(10)): 0 above 10 m,
/// 30 otherwise. The 20 m lot is split into two buildings.
#[test]
fn import_dynamic_reinitializes_attributes() {
    let mut seen = [false; 2];
    for seed in 0..20 {
        let g = gen_file(
            &import_file("main_random_dynamic.cga"),
            &Opts::default().seed(seed),
        )
        .ok();
        let p = g.prints();
        assert_eq!(p.len(), 2);
        for line in &p {
            let v = numbers(line);
            let (height, angle) = (v[0], v[1]);
            assert!((5.0..=15.0).contains(&height), "{line}");
            assert_eq!(angle, if height > 10.0 { 0.0 } else { 30.0 }, "{line}");
            seen[(height > 10.0) as usize] = true;
        }
        for (m, line) in g.meshes().iter().zip(&p) {
            let (lo, hi) = mesh_bounds(m);
            assert_near(hi.y - lo.y, numbers(line)[0], 1e-9);
        }
    }
    assert_eq!(seen, [true, true], "both kinds of height occur");
}

/// import.md: "Any preceeding change to imported attributes will not be
/// effective for the dynamic import because all attributes are
/// re-initialized from the static import": `set(imp.height, 20) imp( ).Lot`
/// extrudes 10.
#[test]
fn import_empty_dynamic_reinitializes() {
    let (p, h) = run_import("main_dynamic_empty.cga");
    assert_eq!(p, ["10"]);
    assert_near(h, 10.0, 1e-9);
}

/// A value set on the shape reaches a plain call of an imported rule.
#[test]
fn import_set_reaches_plain_call() {
    let (p, _) = run_import("main_set_imported.cga");
    assert_eq!(p, ["20"]);
}

/// A dynamic import drops values set on the shape before for the other
/// attributes of the imported rule set too.
#[test]
fn import_dynamic_drops_earlier_sets() {
    let dir = rules_dir().join("import");
    let src = format!(
        "import imp : \"{}\"\nLot --> set(imp.angle, 99) imp( height = 12 ).Lot\n",
        dir.join("reinit.cga").display()
    );
    let g = gen(&src).ok();
    assert_eq!(g.prints(), ["12 0"]);
}

/// start.md: `rule.start(10)` is `rule.Init(10)`; the file alone starts
/// with `start(20)`.
#[test]
fn start_rules() {
    let (p, _) = run_import("main_start.cga");
    assert_eq!(p, ["10", "12"]);
    let g = gen_file(&import_file("start_rule.cga"), &Opts::default()).ok();
    assert_eq!(g.prints(), ["20"]);
    assert_near(g.bounds().1.y, 20.0, 1e-9);
}

/// extension.md: an extension rule with a parameter, redefined by the
/// importer with the same parameter.
#[test]
fn extension_rule_with_parameter() {
    let (p, _) = run_import("main_ext_param.cga");
    assert_eq!(p, ["gable 22"]);
    let g = gen_file(
        &import_file("ext_param.cga"),
        &Opts::default().start("Init"),
    )
    .ok();
    assert_eq!(g.prints(), ["hip 22"]);
}

/// import.md, "Customized temple model" (columns and roof only): the
/// Column override calls the start rule of another imported file, the Roof
/// override sets a colour and calls a rule of the importer; the plain
/// import keeps the defaults. Column height 16 (override) against 12.
#[test]
fn import_temple_overrides() {
    let file = import_file("my_temple.cga");
    let g = gen_file(&file, &Opts::default().start("Init")).ok();
    assert_eq!(g.prints(), ["my roof #ff8000"]);
    // an ionic column: base, shaft (16-sided cylinder, 18 faces), base
    assert_eq!(g.meshes().len(), 3);
    assert_eq!(g.meshes()[1].faces.len(), 18);
    assert_near(g.bounds().1.y - g.bounds().0.y, 16.0, 1e-9);
    let g = gen_file(&file, &Opts::default().start("Init").attr("type", "Plain")).ok();
    assert_eq!(g.prints(), ["default roof"]);
    assert_eq!(g.meshes().len(), 1);
    assert_near(g.bounds().1.y - g.bounds().0.y, 12.0, 1e-9);
}

// ---------------------------------------------------------------------------
// arrays
// ---------------------------------------------------------------------------

/// func_array: 1D and 2D initialization, with the printed forms of the page.
#[test]
fn array_initialization() {
    let defs = "const a = [\"B\", \"C\", \"D\"]\nconst b = [\"A\", a, \"E\"]\n\
                const a2 = [-1 ; -2]\nconst b2 = [0:2 ; 3, 3, 3]\nconst c2 = [a2, b2 ; b2, a2]";
    check_prints(
        defs,
        &[
            ("a", "(3)[B,C,D]"),
            ("b", "(5)[A,B,C,D,E]"),
            ("a2", "(2x1)\n   -1\n   -2"),
            ("b2", "(2x3)\n   0   1   2\n   3   3   3"),
            (
                "c2",
                "(4x4)\n   -1   0   1    2\n   -2   3   3    3\n    0   1   2   -1\n    3   3   3   -2",
            ),
        ],
    );
}

/// func_array, "Fibonacci numbers".
#[test]
fn array_fibonacci() {
    let src = "fibonacci(n) = case n <= 2 : [0:n-1] \n               else        : fibonacci([0,1], n)\n \n\
               fibonacci(a, n) = case size(a) == n : a\n                  else              : fibonacci([a, a[size(a)-2] + a[size(a)-1]], n)\n\n\
               Lot --> print(fibonacci(10))  // (10)[0,1,1,2,3,5,8,13,21,34]\n";
    let g = gen(src).ok();
    assert_eq!(g.prints(), ["(10)[0,1,1,2,3,5,8,13,21,34]"]);
}

/// func_index: indexing with values, index arrays, logical indexing,
/// invalid and linear indexing; every example of the page's tables.
#[test]
fn index_operator_examples() {
    let defs = "const array = [1,2,3,4]\nconst array2d = [1,2,3;  4,5,6;  7,8,9]";
    check_prints(
        defs,
        &[
            ("array[ 0 ]", "1"),
            ("array[ 3 ]", "4"),
            ("array2d[ 1 , 1 ]", "5"),
            ("array[ [0,2] ]", "[1,3]"),
            ("array[ [1,1] ]", "[2,2]"),
            ("array[ 3:-1:1 ]", "[4,3,2]"),
            ("array[ [0,1; 2,3] ]", "[1,2;  3,4]"),
            ("array2d[ 1 , [0,2] ]", "[4,6]"),
            ("array2d[ [0,0,1] , 2 ]", "[3;  3;  6]"),
            ("array2d[ 0:2 , [0,2] ]", "[1,3;  4,6;  7,9]"),
            ("array[ [true,false,true] ]", "[1,3]"),
            ("array[ array .> 2 ]", "[3,4]"),
            ("array[ array .> 1 .&& array .<= 3 ]", "[2,3]"),
            ("array2d[ [false,true,true], 0 ]", "[4;  7]"),
            ("array[ -1 ]", "0"),
            ("array[ [false,false,true,true,true] ]", "[3,4,0]"),
            ("array2d[ [2,3], -1:1 ]", "[0,7,8;  0,0,0]"),
            ("array2d[ 3 ]", "4"),
            // The page prints [0,1,...,9] here, which is not this array2d;
            // linear indexing of all elements gives them row by row.
            ("array2d[ 0 : size(array2d)-1 ]", "[1,2,3,4,5,6,7,8,9]"),
            ("array2d[ [0; 3; 6] ]", "[1;  4;  7]"),
            ("array2d[ 0 , [0,1; 2,3] ]", "[1,2,3,0]"),
            ("array[ [true,false; true,false] ]", "[1,3]"),
        ],
    );
}

/// func_index, the examples: 2D index arrays, out-of-bounds defaults,
/// prime numbers, a parsed text table and a CSV table.
#[test]
fn index_operator_page_examples() {
    let defs = "const a = [\"_\", \"d\", \"i\", \"a\", \"g\"]\n\
                const b = [1,0,0,0;\n           0,2,0,0;\n           0,0,3,0;\n           0,0,0,4]\nconst c = a[b]\n\
                zeros(elems)    = floatArray[1:elems]\nones(rows,cols) = floatArray[1:rows,1:cols] .+ 1\n\
                findPrimes(max) =\n   case max <= 1 : floatArray\n   else          : findPrimes(sqrt(max), [2 : max], floatArray)\n\
                findPrimes(limit, a, primes) =\n   case a[0] <= limit : findPrimes(limit, a[a .% a[0] .!= 0], [primes, a[0]])\n   else               : [primes, a]\n\
                const file     = readTextFile(\"table.txt\")\nconst cells    = splitString(file, \"$;|\\n\")\n\
                const columns  = 3\nconst indexes  = [0 : columns : size(cells)-1]\nconst firstCol = cells[indexes]\n\
                const table    = readStringTable(\"table.csv\")\nconst firstCol2 = table[0 : nRows(table)-1, 0]";
    check_prints(
        defs,
        &[
            ("c", "[d,_,_,_;_,i,_,_;_,_,a,_;_,_,_,g]"),
            ("zeros(4)", "[0,0,0,0]"),
            ("ones(2,3)", "[1,1,1 ; 1,1,1]"),
            ("findPrimes(20)", "(8)[2,3,5,7,11,13,17,19]"),
            ("cells", "[a,b,c,d,e,f,g,h,i]"),
            ("indexes", "[0,3,6]"),
            ("firstCol", "[a,d,g]"),
            // a row index array and one column: a column of the table
            ("firstCol2", "[a;d;g]"),
        ],
    );
}

/// func_index, "Recursive element selection" (needs the comp function).
#[test]
fn index_longest_edge() {
    let src = "indexOfLargest(array) = indexOfLargest(array, 0, 0)\n\
               indexOfLargest(array, i, iLargest) =\n    case i == size(array) : iLargest\n    else :\n        case array[i] > array[iLargest] : indexOfLargest(array, i+1, i)\n        else                            : indexOfLargest(array, i+1, iLargest)\n\
               const edgeLengths = comp(e) { all : scope.sx }\nindexOfLongestEdge = indexOfLargest(edgeLengths)\n\
               Lot --> print(edgeLengths) print(indexOfLongestEdge)\n";
    let g = gen(src).ok();
    assert_eq!(g.prints(), ["(4)[20,30,20,30]", "1"]);
}

/// func_colon: the binary and ternary examples and the floating point
/// imprecision example.
#[test]
fn colon_operator_examples() {
    check_prints(
        "",
        &[
            ("[2   : 4]", "(3)[2,3,4]"),
            ("[0.5 : 3]", "(3)[0.5,1.5,2.5]"),
            ("[4   : 2]", "(0)[]"),
            ("[1 :  0.5 : 3]", "(5)[1,1.5,2,2.5,3]"),
            ("[4 :   -1 : 2]", "(3)[4,3,2]"),
            ("[1 : -0.5 : 2]", "(0)[]"),
            ("[1 : -0.5 : 1]", "(1)[1]"),
            ("[1 :    0 : 1]", "(0)[]"),
        ],
    );
    let src = "const a = [0 : 0.15 : 0.5]\n\nInit --> print(a)                        // (4)[0,0.15,0.3,0.45]\n         print(a[3] == 0.45)             // false\n         print(abs(a[3] - 0.45) < 1e-10) // true\n";
    let g = gen_with(src, &Opts::default().start("Init")).ok();
    assert_eq!(g.prints(), ["(4)[0,0.15,0.3,0.45]", "false", "true"]);
}

/// arrayTypes: the operator tables (index, colon, equality, relational,
/// element-wise logical, arithmetic, equality, relational and string
/// concatenation), each result as the page gives it.
#[test]
fn array_type_operators() {
    check_prints(
        "const array1d = [1,2,3]\nconst array2d = [1,2;3,4]",
        &[
            ("array1d[1]", "2"),
            ("array2d[1,0]", "3"),
            ("[1:5]", "[1,2,3,4,5]"),
            ("[1:2:5]", "[1,3,5]"),
            ("[1,2]        == [1,2]", "true"),
            ("[\"a\",\"b\"]    == [\"a\";\"b\"]", "false"),
            ("[true,false] == [true,true]", "false"),
            ("[1,2]        != [1;2]", "true"),
            ("[\"a\",\"b\"]    != [\"a\";\"b\"]", "true"),
            ("[true,true]  != [true,true]", "false"),
            ("[1,2]        <  [1,3]", "true"),
            ("[\"a\",\"b\"]    <  [\"a\";\"b\"]", "false"),
            ("[1,2]        <= [1,2]", "true"),
            ("[\"a\";\"b\"]    <= [\"a\"]", "false"),
            ("[1,3]        >  [1,2]", "true"),
            ("[\"a\";\"b\"]    >  [\"a\"]", "true"),
            ("[1,2,3]      >= [1,2]", "true"),
            ("[\"a\";\"b\"]    >= [\"a\";\"b\"]", "true"),
            (".![true,false]", "[false,true]"),
            ("[true,false]  .|| true", "[true,true]"),
            ("false         .|| [false;true]", "[false;true]"),
            ("[false,true]  .|| [false,false]", "[false,true]"),
            ("[false;true]  .&& true", "[false;true]"),
            ("false         .&& [true;true;true]", "[false;false;false]"),
            ("[true,false]  .&& [false,true]", "[false,false]"),
            ("[1,2]         .+  1", "[2,3]"),
            ("1             .+  [1;2]", "[2;3]"),
            ("[1,2]         .+  [2,1]", "[3,3]"),
            (".+[1,2]", "[1,2]"),
            ("[1,2;3,4]     .-  1", "[0,1;2,3]"),
            ("3             .-  [1,2]", "[2,1]"),
            ("[3;2]         .-  [2;1]", "[1;1]"),
            (".-[1;2]", "[-1;-2]"),
            ("[4,2]         .*  2.5", "[10,5]"),
            ("-4            .*  [0.25;-0.75;-1]", "[-1;3;4]"),
            ("[1,2;3,4]     .*  [4,3;2,1]", "[4,6;6,4]"),
            ("[4;3]         ./  2", "[2;1.5]"),
            ("12            ./  [2,3,4]", "[6,4,3]"),
            ("[1.6,3.8]     ./  [0.8,1.9]", "[2,2]"),
            ("[8;-5;0]      .%  3", "[2;-2;0]"),
            ("7             .%  [2.7,-3]", "[1.6,1]"),
            ("[-5,3.8]      .%  [-3,0.7]", "[-2,0.3]"),
            ("1             .== [1,2]", "[true,false]"),
            ("[\"a\",\"b\"]     .== \"b\"", "[false,true]"),
            ("[true;false]  .== [true;false]", "[true;true]"),
            ("[1,1;2,2]     .!= [1,2;1,2]", "[false,true;true,false]"),
            ("[\"a\"]         .!= \"a\"", "[false]"),
            ("false         .!= [true]", "[true]"),
            ("1             .<  [1,2]", "[false,true]"),
            ("[\"a\",\"b\"]     .<  \"b\"", "[true,false]"),
            ("[1,2;2,1]     .<  [2,1;1,2]", "[true,false;false,true]"),
            ("1             .<= [1,2]", "[true,true]"),
            ("[\"a\";\"b\";\"c\"] .<= \"b\"", "[true;true;false]"),
            ("[\"a\",\"b\"]     .<= [\"b\",\"a\"]", "[true,false]"),
            ("[1,2;3,4]     .>  [1,1;3,3]", "[false,true;false,true]"),
            ("\"a\"           .>  [\"a\";\"a\"]", "[false;false]"),
            ("[\"a\";\"b\"]     .>  \"a\"", "[false;true]"),
            ("[1;2;3]       .>= [2;2;2]", "[false;true;true]"),
            ("2             .>= [1,2,3]", "[true,true,false]"),
            ("[\"a\"]         .>= \"a\"", "[true]"),
            ("[\"a\",\"b\"]     .+  \"c\"", "[ac,bc]"),
            ("\"a\"           .+  [\"b\";\"c\"]", "[ab;ac]"),
            ("[\"a\",\"b\"]     .+  [\"c\",\"d\"]", "[ac,bd]"),
            ("[\"a\",\"b\"]     .+  1", "[a1,b1]"),
            ("\"a\"           .+  [1,2;3,4]", "[a1,a2;a3,a4]"),
            ("[1;2]         .+  [\"a\";\"b\"]", "[1a;2b]"),
            ("[true;false]  .+  \"a\"", "[truea;falsea]"),
            ("\"a\"           .+  [true]", "[atrue]"),
            ("[\"a\";\"b\"]     .+  [false;true]", "[afalse;btrue]"),
            // string concatenation with arrays: the array's text
            ("\"array: \" + [\"element\"]", "array: (1)[element]"),
            (
                "[\"element\"] + \" is an array\"",
                "(1)[element] is an array",
            ),
            (
                "\"array:\\n\" + [1,2;3,4]",
                "array:\n(2x2)\n   1   2\n   3   4",
            ),
            ("\"array: \" + [true,true]", "array: (2)[true,true]"),
        ],
    );
}
