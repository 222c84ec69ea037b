//! The examples of the reference pages of `print` (operation and function),
//! `report`, push/pop, `NIL`, the `split` shape attribute, `seedian`,
//! `rand` and `p`, and the rule forms every page relies on: case chains and
//! stochastic rules (proportions over many lots and seeds, determinism for
//! one seed).

use crate::ops_common::*;
use cga_geometry::DVec3;
use cga_value::Value;

/// `n` lots `rect:10,10` (each has its own random stream).
fn many_lots(n: usize) -> Opts {
    Opts {
        lots: (0..n).map(|_| cga_engine::lot::rect(10.0, 10.0)).collect(),
        ..Opts::default()
    }
}

// ---------------------------------------------------------------------------
// print, report
// ---------------------------------------------------------------------------

/// op_print, "Printing some stuff", on `rect:20,30`: one line per 2 m slice
/// of the 16 m mass; each slice is turned about its centre by rand(90), so
/// its scope.tx is 10 + (-10 cos ry - 15 sin ry).
#[test]
fn print_operation_example() {
    let src = "Lot-->\n  extrude(16)\n  split(y) { 2 : r(scopeCenter, 0, rand(90), 0)\n                 print(\"idx: \" + split.index +\n                       \", tx = \" + scope.tx +\n                       \" ry = \" + scope.ry)\n                 X. }*\n";
    let g = gen(src).ok();
    let p = g.prints();
    assert_eq!(p.len(), 8);
    for (i, line) in p.iter().enumerate() {
        assert!(line.starts_with(&format!("idx: {i}, tx = ")), "{line}");
        assert!(line.contains(" ry = "), "{line}");
        let v = numbers(line);
        let (tx, ry) = (v[1], v[2]);
        assert!((0.0..=90.0).contains(&ry), "{line}");
        let (s, c) = ry.to_radians().sin_cos();
        assert_near(tx, 10.0 - 10.0 * c - 15.0 * s, 1e-9);
    }
    assert_eq!(g.meshes().len(), 8);
}

/// op_print and func_print: every printable type, one line each; the
/// function returns what it prints.
#[test]
fn print_values_and_function() {
    let src = "Lot --> print(1.5) print(true) print(\"text\") print([1,2,3]) print([true,false]) print([\"a\",\"b\"]) \
               print(print(3) + 1) print(print(\"x\") + \"y\") print(material.color.r)\n";
    let g = gen(src).ok();
    assert_eq!(
        g.prints(),
        [
            "1.5",
            "true",
            "text",
            "(3)[1,2,3]",
            "(2)[true,false]",
            "(2)[a,b]",
            "3",
            "4",
            "x",
            "xy",
            "1"
        ]
    );
}

/// op_report, "Reporting Window State", without the component split: the
/// page's Facade rule on the lot itself (20 x 30, floors along z). Each
/// window (2 m wide, a floor deep) reports its area and is open (deleted)
/// or closed (coloured).
#[test]
fn report_window_state() {
    let src = "Facade -->\n    report(\"facades\", 1)\n    split(z) { ~5 : Floor  | ~0.5 : Ledge }*\n\
               Floor -->\n    split(x) { ~1 : Tile | 2 : Window | ~1 : Tile}*\n\
               Window -->\n    40%:\n      report(\"windowarea\", geometry.area())\n      report(\"windows.open\", 1)\n      NIL\n\
               else:\n      report(\"windowarea\", geometry.area())\n      report(\"windows.closed\", 1)\n      color(\"#aaffaa\")\n\
               Tile --> NIL\nLedge --> NIL\n";
    let g = gen_with(src, &Opts::default().start("Facade")).ok();
    let r = &g.out().reports;
    let count = |k: &str| r.iter().filter(|(key, _)| key == k).count();
    assert_eq!(count("facades"), 1);
    let windows = count("windowarea");
    assert_eq!(count("windows.open") + count("windows.closed"), windows);
    assert!(windows >= 10, "{windows} windows");
    for (k, v) in r {
        if k == "windowarea" {
            let Value::Float(a) = v else { panic!("{v:?}") };
            // 2 m wide, one floor (about 5 m) deep
            assert!((*a / 2.0 - 5.0).abs() < 1.0, "{a}");
        } else {
            assert_eq!(v, &Value::Float(1.0));
        }
    }
    // closed windows are the only geometry, light green
    assert_eq!(g.meshes().len(), count("windows.closed"));
    for m in g.face_materials() {
        assert_eq!(rgb255(m), [0xaa, 0xff, 0xaa]);
    }
}

/// op_report: the page's rule with comp(f).
#[test]
fn report_window_state_page_rule() {
    let src = "Lot -->\n    extrude(30)\n    comp(f) { side : Facade | top : Roof }\n\
               Facade -->\n    report(\"facades\", 1)\n    split(y) { ~5 : Floor  | ~0.5 : Ledge }*\n\
               Floor -->\n    split(x) { ~1 : Tile | 2 : Window | ~1 : Tile}*\n\
               Window -->\n    40%:\n      report(\"windowarea\", geometry.area())\n      report(\"windows.open\", 1)\n      NIL\n\
               else:\n      report(\"windowarea\", geometry.area())\n      report(\"windows.closed\", 1)\n      color(\"#aaffaa\")\n";
    let g = gen(src).ok();
    let facades = g
        .out()
        .reports
        .iter()
        .filter(|(k, _)| k == "facades")
        .count();
    assert_eq!(facades, 4);
}

/// op_report: value types float, bool and string; other types are errors.
#[test]
fn report_value_types() {
    let g =
        gen("Lot --> report(\"a.b\", 2.5) report(\"flag\", true) report(\"name\", \"x\") X\n").ok();
    assert_eq!(
        g.out().reports,
        [
            ("a.b".to_string(), Value::Float(2.5)),
            ("flag".to_string(), Value::Bool(true)),
            ("name".to_string(), Value::str("x")),
        ]
    );
    let g = gen("Lot --> report(\"arr\", [1,2]) X\n");
    assert_eq!(g.errors.len(), 1);
}

// ---------------------------------------------------------------------------
// push / pop, NIL
// ---------------------------------------------------------------------------

/// Width (x) and depth (z) of the bounding box of a 20 x 30 footprint
/// turned by `deg` about y.
fn turned_extent(deg: f64) -> (f64, f64) {
    let (s, c) = deg.to_radians().sin_cos();
    (20.0 * c + 30.0 * s, 20.0 * s + 30.0 * c)
}

/// op_pushpop, "Rotation Example": without push/pop the three rotations
/// build on each other (22.5, 45, 67.5 degrees); with push/pop each X is
/// turned by 22.5 degrees only. All turn about the centre (10, 7.5, -15).
#[test]
fn push_pop_rotation() {
    let chained = "Lot -->\n    extrude(15)\n    r(scopeCenter, 0, 22.5, 0) X.\n    r(scopeCenter, 0, 22.5, 0) X.\n    r(scopeCenter, 0, 22.5, 0) X.\n";
    let pushed = "Lot -->\n    extrude(15)\n    [ r(scopeCenter, 0, 22.5, 0) X. ]\n    [ r(scopeCenter, 0, 22.5, 0) X. ]\n    [ r(scopeCenter, 0, 22.5, 0) X. ]\n";
    for (src, angles) in [(chained, [22.5, 45.0, 67.5]), (pushed, [22.5; 3])] {
        let g = gen(src).ok();
        assert_eq!(g.meshes().len(), 3);
        for (m, a) in g.meshes().iter().zip(angles) {
            let (lo, hi) = mesh_bounds(m);
            let (w, d) = turned_extent(a);
            assert_near(hi.x - lo.x, w, 1e-9);
            assert_near(hi.z - lo.z, d, 1e-9);
            assert_vec_near(0.5 * (lo + hi), [10.0, 7.5, -15.0], 1e-9);
        }
    }
}

/// op_pushpop, "House Example": both rules give the same model.
#[test]
fn push_pop_house() {
    let house = Opts::default().start("House");
    let a = gen_with(
        "House -->\n    extrude(10)\n    comp(f) { top : roofHip(45) Roof. | all = House.}\n",
        &house,
    )
    .ok();
    let b = gen_with("House -->\n    [ t(0,10,0) roofHip(45) Roof. ]\n    extrude(10)\n    comp(f) { top : NIL | all = House. }\n", &house).ok();
    assert_near(a.area(), b.area(), 1e-9);
    let (lo, hi) = a.bounds();
    let (lo2, hi2) = b.bounds();
    assert_vec_near(lo, lo2.to_array(), 1e-9);
    assert_vec_near(hi, hi2.to_array(), 1e-9);
    // On 20 x 30 the hip roof at 45 degrees rises by half the width.
    assert_near(hi.y, 20.0, 1e-9);
    // Walls, floor (the roof's base is not shown: the roof and the house
    // are separate leaves) and the four roof planes.
    let roof = 2.0f64.sqrt() * 20.0 * 30.0;
    assert_near(
        a.area(),
        2.0 * (20.0 + 30.0) * 10.0 + 600.0 + 600.0 + roof,
        1e-9,
    );
}

/// op_pushpop, "Translation Example", on `rect:20,30`: five cylinders of
/// radius 1 and height 2, each centred in its scope: the lot's, and the
/// lot's moved by one scope size along +-z and +-x.
#[test]
fn push_pop_translation() {
    let src = "House-->\n    Cylinder\n    [ t(  0, 0, ' 1) Cylinder ]\n    [ t(  0, 0, '-1) Cylinder ]\n    [ t(' 1, 0,   0) Cylinder ]\n    [ t('-1, 0,   0) Cylinder ]\n\
               Cylinder -->\n    primitiveCylinder(16, 1, 2)\n";
    let g = gen_with(src, &Opts::default().start("House")).ok();
    let centers: Vec<DVec3> = g
        .meshes()
        .iter()
        .map(|m| {
            let (lo, hi) = mesh_bounds(m);
            assert_vec_near(hi - lo, [2.0, 2.0, 2.0], 1e-9);
            0.5 * (lo + hi)
        })
        .collect();
    let expected = [
        [10.0, 1.0, -15.0],
        [10.0, 1.0, 15.0],
        [10.0, 1.0, -45.0],
        [30.0, 1.0, -15.0],
        [-10.0, 1.0, -15.0],
    ];
    assert_eq!(centers.len(), 5);
    for (c, e) in centers.iter().zip(expected) {
        assert_vec_near(*c, e, 1e-9);
    }
}

/// op_pushpop, "Condition Example": a case switch inside push/pop after an
/// operation; scope.sx is 1, so a 1 x 1 x 1 cube.
#[test]
fn push_pop_condition() {
    let src = "Lot -->\n    s(1,1,1)\n    [ case scope.sx == 1 : primitiveCube() Cube.\n      else : primitiveCylinder() Cylinder. ]\n";
    let g = gen(src).ok();
    assert_eq!(g.meshes().len(), 1);
    assert_eq!(g.meshes()[0].faces.len(), 6);
    assert_near(g.volume(), 1.0, 1e-12);
}

/// op_nil, "Using NIL to create Holes", on `rect:20,30` (the page has a
/// stray closing brace): the pattern {~1 X | ~1 NIL}* | ~1 X over 20 m
/// repeats 10 times (21 parts of 20/21 m, the repetition count whose
/// stretch is closest to 1, as the split page prescribes); the X parts keep
/// 11 of them, the NIL parts leave gaps.
#[test]
fn nil_creates_holes() {
    let src = "Lot-->\n   extrude(10)\n   split(x){ { ~1 : X | ~1 : NIL }* | ~1 : X }\n";
    let g = gen(src).ok();
    let w = 20.0 / 21.0;
    assert_eq!(g.meshes().len(), 11);
    for (i, m) in g.meshes().iter().enumerate() {
        let (lo, hi) = mesh_bounds(m);
        assert_near(lo.x, 2.0 * w * i as f64, 1e-9);
        assert_near(hi.x - lo.x, w, 1e-9);
    }
    assert_near(g.volume(), 11.0 * w * 10.0 * 30.0, 1e-6);
}

/// op_nil, "Using NIL to stop a Recursion" (the Erker rule).
#[test]
fn nil_stops_a_recursion() {
    let src = "attr ErkerFact = 0.8\nattr ErkerDepth = 0.8\nattr ErkerStop = 2\n\
               Lot-->\n   extrude(10)\n   X\n   comp(f) { all : Erker }\n\
               Erker-->\n   case(scope.sx > ErkerStop) :\n      s('ErkerFact, 'ErkerFact, 0)\n      center(xy)\n      alignScopeToGeometry(yUp, 0)\n      extrude(ErkerDepth)\n      X\n      comp(f){top : Erker}\n   else:\n      NIL\n";
    let g = gen(src).ok();
    assert!(g.meshes().len() > 6);
}

/// NIL deletes the shape even after operations; a rule that ends without
/// successors and without NIL is a leaf.
#[test]
fn nil_deletes_and_leaves_emit() {
    let g = gen("Lot --> extrude(10) NIL\n").ok();
    assert!(g.meshes().is_empty());
    let g = gen("Lot --> extrude(10) A\nA --> s('0.5,'1,'1)\n").ok();
    assert_eq!(g.meshes().len(), 1);
    assert_near(g.volume(), 3000.0, 1e-9);
}

// ---------------------------------------------------------------------------
// split attribute
// ---------------------------------------------------------------------------

/// attr_split, example on `rect:20,30`: ten 2 m floors of a 20 m mass; the
/// first is red, the last blue, the others keep the default white.
#[test]
fn split_index_and_total() {
    let src = "Lot -->\textrude(20) A\nA --> \n\tsplit(y){2 : B}*\n\
               B --> \n    case split.index == 0: \n        color(\"#ff0000\") X\n    case split.index == split.total-1: \n        color(\"#0000ff\") X\n    else: \n        X.\n";
    let g = gen(src).ok();
    assert_eq!(g.meshes().len(), 10);
    for (i, m) in g.meshes().iter().enumerate() {
        let c = rgb255(&m.materials[0]);
        let expected = match i {
            0 => [255, 0, 0],
            9 => [0, 0, 255],
            _ => [255, 255, 255],
        };
        assert_eq!(c, expected, "floor {i}");
        assert_near(mesh_bounds(m).0.y, 2.0 * i as f64, 1e-9);
    }
    let g = gen("Lot --> print([split.index, split.total]) extrude(9) split(y) { 3 : print([split.index, split.total]) X }*\n").ok();
    assert_eq!(g.prints(), ["(2)[0,0]", "(2)[0,3]", "(2)[1,3]", "(2)[2,3]"]);
}

/// Splits within the parts of a split, each level with a pattern of its
/// own (a repeat inside fixed parts, floating parts inside a repeat), and a
/// split after them on the same level: every part keeps its own index,
/// total and size, as the levels' patterns and layouts are in use at once.
#[test]
fn nested_and_sibling_splits_keep_their_own_parts() {
    let src = "Lot --> extrude(6) split(y) { 2 : A | ~1 : B | 1 : C }\n\
               A --> split(x) { 4 : print(\"a \" + split.index + \"/\" + split.total + \" \" + scope.sx) X. }*\n\
               B --> split(x) { { ~1 : Q | 2 : R }* | 1 : S }\n\
               Q --> split(z) { '0.5 : print(\"q \" + split.index + \"/\" + split.total + \" \" + scope.sz) X. }*\n\
               R --> print(\"r \" + split.index + \"/\" + split.total + \" \" + scope.sx) X.\n\
               S --> print(\"s \" + split.index + \"/\" + split.total + \" \" + scope.sx) X.\n\
               C --> split(x) { ~1 : print(\"c \" + split.index + \"/\" + split.total + \" \" + scope.sx) X. | 3 : X. }\n";
    let g = gen_with(src, &Opts::rect(20.0, 10.0)).ok();
    // A: five 4 m parts of 20 m. B: 19 m of repeats of (floating, 2 m),
    // then 1 m: six repeats, each Q split in two halves of the lot's 10 m
    // depth. C: 17 m floating, then 3 m.
    // In derivation order: C's rule runs before those of B's parts.
    let mut expected: Vec<String> = (0..5).map(|i| format!("a {i}/5 4")).collect();
    expected.push("c 0/2 17".to_string());
    for k in 0..6 {
        expected.push("q 0/2 5".to_string());
        expected.push("q 1/2 5".to_string());
        expected.push(format!("r {}/13 2", 2 * k + 1));
    }
    expected.push("s 12/13 1".to_string());
    assert_eq!(g.prints(), expected);
}

/// A shape's last statement hands the shape itself on as its successor
/// (its box, its random stream, its material and geometry), and a split
/// or component split that is the last statement hands it on to its last
/// part or component; any other statement hands on a copy. Both successors are the same: with `NIL`
/// after each successor (the shape then ends deleted, which leaves no leaf
/// of its own) the prints, the random numbers, `center`'s reference to the
/// parent's scope and every leaf's geometry and material are those of the
/// rules without it. Split parts and component shapes, whose states end
/// with a rule too, take their turn in between.
#[test]
fn a_last_statement_hands_on_the_same_successor_as_any_other() {
    let rules = |end: &str| {
        format!(
            "Lot --> extrude(4) A{end}\n\
             A --> t(1,0,0) set(material.color.r, 0.5) B{end}\n\
             B --> print(rand()) s('0.5,'1,'1) center(x) print(scope.tx) split(x) {{ 1 : P{end} | ~1 : Q{end} }}*{end}\n\
             P --> print(\"p \" + split.index + \" \" + rand()) comp(f) {{ top : T{end} | side : S. }}{end}\n\
             Q --> print(\"q \" + rand()) color(\"#336699\") X.{end}\n\
             T --> print(\"t \" + rand() + \" \" + scope.sx) Y.{end}\n"
        )
    };
    let last = gen_with(&rules(""), &Opts::rect(10.0, 6.0)).ok();
    let copied = gen_with(&rules(" NIL"), &Opts::rect(10.0, 6.0)).ok();
    assert_eq!(last.prints(), copied.prints());
    // B is 5 m wide after `s('0.5,...)`, centred in A's 10 m: x from 3.5
    // (A was moved by 1 m); three repeats of a 1 m part P and a floating
    // part Q of 2/3 m.
    let prints = last.prints();
    assert_eq!(prints[1], "3.5");
    assert_eq!(prints.iter().filter(|p| p.starts_with("p ")).count(), 3);
    assert_eq!(prints.iter().filter(|p| p.starts_with("q ")).count(), 3);
    assert_eq!(
        prints[2..5],
        [
            "p 0 0.10567514085496",
            "q 0.683141746106393",
            "p 2 0.970772588856274"
        ]
    );
    assert_eq!(prints.iter().filter(|p| p.starts_with("t ")).count(), 3);
    let (a, b) = (last.meshes(), copied.meshes());
    assert_eq!(a.len(), b.len());
    // Q's three boxes, and per P its four sides and its top.
    assert_eq!(a.len(), 3 + 3 * 5);
    for (m, n) in a.iter().zip(b) {
        assert_eq!(m.positions, n.positions);
        assert_eq!(m.materials[0].color, n.materials[0].color);
    }
    assert!(a
        .iter()
        .all(|m| m.materials[0].color[0] == 0.5 || m.materials[0].color == [0.2, 0.4, 0.6]));
}

// ---------------------------------------------------------------------------
// case chains
// ---------------------------------------------------------------------------

/// Case chains: the first true condition wins, in order; `else` when none
/// holds; conditions may read attributes, parameters and shape attributes;
/// cases nest, and work in functions.
#[test]
fn case_chains() {
    let src = "attr mode = 2\n\
               Lot --> C(0) C(5) C(12) C(20) N(1) N(-1) print(f(3)) print(f(-3)) print(f(0)) D\n\
               C(x) --> case x > 10 && x < 15 : print(\"a\" + x)\n        case x > 10 : print(\"b\" + x)\n        case x == 5 || mode == 3 : print(\"c\" + x)\n        else : print(\"d\" + x)\n\
               N(x) --> case x > 0 : case mode == 2 : print(\"pos2\") else : print(\"pos\")\n        else : print(\"neg\")\n\
               f(x) = case x > 0 : \"plus\" case x < 0 : \"minus\" else : \"zero\"\n\
               D --> case scope.sx > 100 : print(\"wide\")\n      else : print(\"narrow\")\n";
    let g = gen(src).ok();
    // Lot's own prints come first: the rules it calls run a generation later.
    assert_eq!(
        g.prints(),
        ["plus", "minus", "zero", "d0", "c5", "a12", "b20", "pos2", "neg", "narrow"]
    );
    let g = gen_with(src, &Opts::default().attr("mode", "3")).ok();
    assert_eq!(g.prints()[3..5], ["c0", "c5"]);
    assert_eq!(g.prints()[7], "pos");
}

/// A case chain needs its `else` (CGA rejects the rule file without one).
#[test]
fn case_chain_needs_else() {
    for src in [
        "f(x) = case x > 0 : 1\nLot --> print(f(-1))\n",
        "Lot --> case scope.sx > 1 : X\n",
        "Lot --> 30% : X\n",
    ] {
        let dir = std::env::temp_dir().join(format!("cga-ops-else-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("r.cga");
        std::fs::write(&path, src).unwrap();
        let mut sources = cga_syntax::SourceMap::new();
        let loaded = cga_engine::load(&cga_world::DiskWorld, &path, &mut sources);
        assert!(loaded.has_errors(), "{src}");
    }
}

// ---------------------------------------------------------------------------
// stochastic rules
// ---------------------------------------------------------------------------

/// Stochastic rules: `30% : A 20% : B else : C` picks A, B and C in those
/// proportions over many lots (each lot has its own random stream), and
/// over many seeds for one lot. 2000 draws: 4 standard deviations of a
/// proportion are at most 0.045.
#[test]
fn stochastic_rule_proportions() {
    let src =
        "Lot --> 30% : print(\"A\")\n        20% : print(\"B\")\n        else : print(\"C\")\n";
    let check = |prints: Vec<String>| {
        let n = prints.len() as f64;
        assert_eq!(n, 2000.0);
        let share = |s: &str| prints.iter().filter(|p| *p == s).count() as f64 / n;
        assert_near(share("A"), 0.3, 0.045);
        assert_near(share("B"), 0.2, 0.045);
        assert_near(share("C"), 0.5, 0.045);
    };
    check(gen_with(src, &many_lots(2000)).ok().prints());
    let seeds: Vec<u64> = (0..2000).collect();
    let by_seed: Vec<String> = gen_seeds(src, &Opts::rect(10.0, 10.0), &seeds)
        .into_iter()
        .flat_map(|g| g.ok().prints())
        .collect();
    check(by_seed);
}

/// Stochastic rules are deterministic: the same seed gives the same
/// choices, lot by lot, whatever other lots are derived; another seed
/// gives other choices.
#[test]
fn stochastic_rule_determinism() {
    let src = "Lot --> 30% : print(\"A\" + rand)\n        20% : print(\"B\" + rand)\n        else : print(\"C\" + rand)\n";
    let a = gen_with(src, &many_lots(50).seed(7)).ok().prints();
    let b = gen_with(src, &many_lots(50).seed(7)).ok().prints();
    assert_eq!(a, b);
    let c = gen_with(src, &many_lots(50).seed(8)).ok().prints();
    assert_ne!(a, c);
    let first = gen_with(src, &many_lots(1).seed(7)).ok().prints();
    assert_eq!(first[0], a[0]);
}

/// Stochastic forms: 0% never and 100% always; several branches up to
/// 100% leave else unused; in functions; a shape's successors draw
/// different numbers.
#[test]
fn stochastic_forms() {
    let src = "Lot --> S T U print(f) print(g) A A\n\
               S --> 0% : print(\"never\")\n      else : print(\"else\")\n\
               T --> 100% : print(\"always\")\n      else : print(\"else\")\n\
               U --> 50% : print(\"u1\") 50% : print(\"u2\")\n      else : print(\"else\")\n\
               f = 50% : 1 else : 2\n\
               g = 150% : \"first\" else : \"second\"\n\
               A --> print(rand)\n";
    for seed in 0..20 {
        let g = gen_with(src, &Opts::default().seed(seed)).ok();
        let p = g.prints();
        // Lot prints f and g before S, T and U run (generation order).
        assert!(p[0] == "1" || p[0] == "2");
        assert_eq!(p[1], "first");
        assert_eq!(p[2..4], ["else", "always"]);
        assert!(p[4] == "u1" || p[4] == "u2");
        assert_ne!(p[5], p[6], "siblings draw different numbers");
        assert_eq!(p.len(), 7);
    }
}

// ---------------------------------------------------------------------------
// rand, p, seedian
// ---------------------------------------------------------------------------

/// func_rand: values in [0,1], [0,max], [min,max]; uniform (means within 4
/// standard deviations over 2000 draws).
#[test]
fn rand_ranges() {
    let src = "Lot --> print([rand, rand(10), rand(-5, 5), rand(3, 3)])\n";
    let g = gen_with(src, &many_lots(2000)).ok();
    let rows: Vec<Vec<f64>> = g.prints().iter().map(|l| array(l)).collect();
    let mean = |k: usize| rows.iter().map(|r| r[k]).sum::<f64>() / rows.len() as f64;
    for r in &rows {
        assert!((0.0..=1.0).contains(&r[0]));
        assert!((0.0..=10.0).contains(&r[1]));
        assert!((-5.0..=5.0).contains(&r[2]));
        assert_eq!(r[3], 3.0);
    }
    // sd of a mean of 2000 uniforms on [0,1]: 0.2887 / sqrt(2000) = 0.0065
    assert_near(mean(0), 0.5, 0.026);
    assert_near(mean(1), 5.0, 0.26);
    assert_near(mean(2), 0.0, 0.26);
}

/// func_p, the page's examples: p(1), p(2) are true; p(0), p(-1) false;
/// p(0.5) and p(0.3) are true with those probabilities.
#[test]
fn p_examples() {
    let g = gen("Lot --> print(p(1)) print(p(0)) print(p(2)) print(p(-1))\n").ok();
    assert_eq!(g.prints(), ["true", "false", "true", "false"]);
    let g = gen_with("Lot --> print([p(0.5), p(0.3)])\n", &many_lots(2000)).ok();
    let rows: Vec<String> = g.prints();
    let share = |k: usize| {
        rows.iter()
            .filter(|r| {
                r.trim_start_matches("(2)[")
                    .split(',')
                    .nth(k)
                    .unwrap()
                    .starts_with("true")
            })
            .count() as f64
            / rows.len() as f64
    };
    assert_near(share(0), 0.5, 0.045);
    assert_near(share(1), 0.3, 0.045);
}

/// attr_seedian: the seed of the random numbers can be read and set;
/// shapes with the same seedian draw the same numbers, another seedian
/// other numbers.
#[test]
fn seedian_controls_rand() {
    let src = "Lot --> [ set(seedian, 42) print(rand) print(rand) ] [ set(seedian, 42) print(rand) print(rand) ] \
               [ set(seedian, 43) print(rand) ] print(seedian)\n";
    let g = gen(src).ok();
    let p = g.prints();
    assert_eq!(p[0..2], p[2..4]);
    assert_ne!(p[0], p[1]);
    assert_ne!(p[0], p[4]);
    assert!(numbers(&p[5]).len() == 1, "seedian is a float: {}", p[5]);
    // the same seedian gives the same numbers on any lot and with any seed
    let other = gen_with(src, &Opts::rect(3.0, 4.0).seed(99)).ok();
    assert_eq!(other.prints()[0..4], p[0..4]);
}

/// `NIL` in the middle of an operation sequence does not end it: the
/// operations after it still run (CityEngine's envelope2002 package reports
/// `report(..) NIL report(..) NIL` twice), and the shape is not part of the
/// model.
#[test]
fn operations_after_nil_still_run() {
    let g = gen("Lot --> extrude(3) comp(f) { top : print(\"a\" + geometry.area) NIL print(\"b\" + geometry.area) NIL | side : X. }\n").ok();
    assert_eq!(g.prints(), ["a600", "b600"]);
    // Only the four sides are in the model.
    assert_eq!(g.meshes().len(), 4);
}
