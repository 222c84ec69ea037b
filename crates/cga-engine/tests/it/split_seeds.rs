//! Every example of the split seed pages (split and subdivision split), run
//! through the engine on real geometry: which parts exist, where they start
//! and how long they are (printed `scope.tx` and `scope.sx`), and that the
//! cut geometry keeps its volume.

use crate::ops_common::*;

/// Part rules that print their name, position and size along x; `h` is
/// the page's height factor, unused here.
const PARTS: &str = r#"
X(h) --> print("X " + scope.tx + " " + scope.sx + " " + geometry.volume)
Y(h) --> print("Y " + scope.tx + " " + scope.sx + " " + geometry.volume)
Z(h) --> print("Z " + scope.tx + " " + scope.sx + " " + geometry.volume)
Z --> Z(1)
XX --> print("XX " + scope.tx + " " + scope.sx + " " + geometry.volume)
Blue(h) --> print("Blue " + scope.tx + " " + scope.sx + " " + geometry.volume)
Green(h) --> print("Green " + scope.tx + " " + scope.sx + " " + geometry.volume)
Yellow(h) --> print("Yellow " + scope.tx + " " + scope.sx + " " + geometry.volume)
"#;

/// Splits a `length` x 1 x 1 cube with `split` and returns the parts as
/// (name, start, size, volume).
fn parts(length: f64, split: &str) -> Vec<(String, f64, f64, f64)> {
    let src = format!("Lot --> s({length}, 1, 1) primitiveCube() {split}\n{PARTS}");
    let mut got: Vec<_> = gen(&src)
        .ok()
        .prints()
        .iter()
        .map(|l| {
            let mut it = l.split(' ');
            let name = it.next().unwrap().to_string();
            let n: Vec<f64> = it.map(|x| x.parse().unwrap()).collect();
            (name, n[0], n[1], n[2])
        })
        .collect();
    // Rules run generation by generation, so `Z --> Z(1)` prints a
    // generation later than its siblings: order the parts by position.
    got.sort_by(|a, b| a.1.total_cmp(&b.1));
    got
}

/// Asserts names and sizes; starts must follow each other from 0 (with the
/// given gaps implied by `starts`) and the volume of a unit cross-section
/// part equals its size.
fn expect(got: &[(String, f64, f64, f64)], expected: &[(&str, f64, f64)]) {
    assert_eq!(
        got.iter().map(|p| p.0.as_str()).collect::<Vec<_>>(),
        expected.iter().map(|p| p.0).collect::<Vec<_>>(),
        "{got:?}"
    );
    for (g, e) in got.iter().zip(expected) {
        assert!((g.1 - e.1).abs() < 1e-9, "start of {g:?}, expected {e:?}");
        assert!((g.2 - e.2).abs() < 1e-9, "size of {g:?}, expected {e:?}");
        assert!((g.3 - e.2).abs() < 1e-9, "volume of {g:?}, expected {e:?}");
    }
}

/// Consecutive parts from 0.
fn run_of(parts: &[(&'static str, f64)]) -> Vec<(&'static str, f64, f64)> {
    let mut at = 0.0;
    parts
        .iter()
        .map(|&(n, s)| {
            let p = (n, at, s);
            at += s;
            p
        })
        .collect()
}

// ----- split page (scope.sx = 10) -----

#[test]
fn relative_sizes() {
    let got = parts(10.0, "split(x){ '0.5 : Z | '0.1 : Y(2) | '0.2 : X(1) }");
    expect(&got, &run_of(&[("Z", 5.0), ("Y", 1.0), ("X", 2.0)]));
}

#[test]
fn floating_sizes_only_keep_ratios() {
    let got = parts(10.0, "split(x) { ~0.5 : Z | ~0.1 : Y(2) | ~0.2 : X(1) }");
    expect(&got, &run_of(&[("Z", 6.25), ("Y", 1.25), ("X", 2.5)]));
}

#[test]
fn absolute_and_floating_sizes() {
    // "Its size is adjusted from 3 to 1.7".
    let got = parts(10.0, "split(x) { 3.3 : Z(1) | ~3 : Y(2) | 5 : X(1) }");
    expect(&got, &run_of(&[("Z", 3.3), ("Y", 1.7), ("X", 5.0)]));
}

#[test]
fn oversized_parts_are_cut_and_later_ones_not_created() {
    let got = parts(10.0, "split(x) { '0.5 : Z(1) | '0.6 : Y(2) | 3 : X(1) }");
    expect(&got, &run_of(&[("Z", 5.0), ("Y", 5.0)]));
}

#[test]
fn repeat_with_absolute_sizes_cuts_the_last() {
    let got = parts(10.0, "split(x) { 2 : X(2) | 1 : Y(1) } *");
    expect(
        &got,
        &run_of(&[
            ("X", 2.0),
            ("Y", 1.0),
            ("X", 2.0),
            ("Y", 1.0),
            ("X", 2.0),
            ("Y", 1.0),
            ("X", 1.0),
        ]),
    );
}

#[test]
fn repeat_with_floating_sizes_fills_without_cutting() {
    let got = parts(10.0, "split(x){ ~2 : X(2) | ~1 : Y(1) }*");
    let (x, y) = (20.0 / 9.0, 10.0 / 9.0);
    expect(
        &got,
        &run_of(&[("X", x), ("Y", y), ("X", x), ("Y", y), ("X", x), ("Y", y)]),
    );
}

#[test]
fn interleaved_repeat_gives_yellow_parts_of_0_9() {
    let got = parts(
        10.0,
        "split(x){ 1 : X(3) | { ~1 : Y(2) | 0.2 : Z(1) | ~1 : Y(2) }* | 1 : X(3) }",
    );
    let mut e = vec![("X", 1.0)];
    for _ in 0..4 {
        e.extend([("Y", 0.9), ("Z", 0.2), ("Y", 0.9)]);
    }
    e.push(("X", 1.0));
    expect(&got, &run_of(&e));
}

#[test]
fn rhythm_abababa() {
    let got = parts(10.0, "split(x){ { 1 : X(3) | ~3 : Y(1) }* | 1 : X(3) }");
    expect(
        &got,
        &run_of(&[("X", 1.0), ("Y", 3.5), ("X", 1.0), ("Y", 3.5), ("X", 1.0)]),
    );
}

#[test]
fn cutting_a_horizontal_cylinder_keeps_closed_pieces() {
    // The seed's "Cutting Geometry": the inserted cylinder is cut into
    // pieces with NIL holes; the cut surfaces are closed.
    let g = gen_file(&rules_dir().join("split/cylinder.cga"), &Opts::default()).ok();
    let prints = g.prints();
    let whole: f64 = prints[0].split(' ').nth(1).unwrap().parse().unwrap();
    let pieces: Vec<Vec<String>> = prints[1..]
        .iter()
        .map(|l| l.split(' ').map(String::from).collect())
        .collect();
    // {~0.75 | ~1}* then ~0.5 on 10: n repetitions of 1.75 plus 0.5 with one
    // common stretch; n = 5 gives 9.25 -> s = 10/9.25, the least stretched.
    let s = 10.0 / 9.25;
    assert_eq!(pieces.len(), 6, "{prints:?}");
    let mut kept = 0.0;
    for (i, p) in pieces.iter().enumerate() {
        let (start, size, vol): (f64, f64, f64) = (
            p[1].parse().unwrap(),
            p[2].parse().unwrap(),
            p[3].parse().unwrap(),
        );
        let expected = if i < 5 { 0.75 * s } else { 0.5 * s };
        assert!((size - expected).abs() < 1e-6, "{p:?}");
        assert!((start - i as f64 * 1.75 * s).abs() < 1e-6, "{p:?}");
        assert_eq!(p[4], "true", "piece {i} is closed");
        // A cylinder along x: every slab's volume is proportional to its length.
        assert!((vol - whole * size / 10.0).abs() < 1e-6 * whole, "{p:?}");
        kept += vol;
    }
    assert!((kept - whole * (5.0 * 0.75 + 0.5) * s / 10.0).abs() < 1e-6 * whole);
}

// ----- subdivision split page (cube of length 5, then 10) -----

#[test]
fn absolute_split() {
    expect(
        &parts(5.0, "split(x) { 3 : Blue(1) }"),
        &run_of(&[("Blue", 3.0)]),
    );
    expect(
        &parts(5.0, "split(x) { 3 : Green(1) | 1 : Blue(0.5) }"),
        &run_of(&[("Green", 3.0), ("Blue", 1.0)]),
    );
}

#[test]
fn absolute_values_within_a_limited_scope() {
    let got = parts(
        5.0,
        "split(x) { 2 : Green(1) | 1 : Green(1) | 1 : Blue(0.5) | 2 : Yellow(2) | 1 : Blue(1) }",
    );
    expect(
        &got,
        &run_of(&[
            ("Green", 2.0),
            ("Green", 1.0),
            ("Blue", 1.0),
            ("Yellow", 1.0),
        ]),
    );
}

#[test]
fn negative_and_zero_sizes_create_nothing() {
    let got = parts(
        5.0,
        "split(x) { 1.5 : Green(1) | -2 : Yellow(1) | 1.5 : Blue(0.5) | 1.5 : Green(1) | 0 : Yellow(1) | 1.5 : Green(1) }",
    );
    expect(
        &got,
        &run_of(&[
            ("Green", 1.5),
            ("Blue", 1.5),
            ("Green", 1.5),
            ("Green", 0.5),
        ]),
    );
}

#[test]
fn golden_ratio_split() {
    let src = "Lot --> s(5, 1, 1) primitiveCube() split(x) { '0.382 : A | '0.618 : B }\n\
               A --> split(x) { '0.382 : Green(1) | '0.618 : Yellow(2) }\n\
               B --> split(x) { '0.382 : Green(1) | '0.618 : Yellow(2) }\n";
    let g = gen(&format!("{src}{PARTS}")).ok();
    let sizes: Vec<f64> = g.prints().iter().map(|l| numbers(l)[1]).collect();
    let (a, b) = (0.382 * 5.0, 0.618 * 5.0);
    assert_all_near(&sizes, &[0.382 * a, 0.618 * a, 0.382 * b, 0.618 * b], 1e-9);
}

#[test]
fn recursive_golden_ratio_stops_when_parts_get_too_small() {
    let src = "Lot --> s(5, 1, 1) primitiveCube() split(x) { '0.382 : A | '0.618 : B }\n\
               A --> split(x) { '0.382 : A | '0.618 : C }\n\
               B --> split(x) { '0.382 : B | '0.618 : D }\n\
               C --> split(x) { '0.382 : Green(1) | '0.618 : Yellow(2) }\n\
               D --> split(x) { '0.382 : Green(1) | '0.618 : Yellow(2) }\n";
    let g = gen(&format!("{src}{PARTS}")).ok();
    let parts: Vec<Vec<f64>> = g.prints().iter().map(|l| numbers(l)).collect();
    // The recursion ends; the parts tile the cube without gaps or overlaps.
    assert!(parts.len() > 20 && parts.len() < 200, "{}", parts.len());
    let volume: f64 = parts.iter().map(|p| p[2]).sum();
    assert!(volume <= 5.0 + 1e-9 && volume > 5.0 - 1e-3, "{volume}");
}

#[test]
fn floating_splits() {
    expect(
        &parts(5.0, "split(x) { 3 : Green(1) | ~1 : Blue(2) }"),
        &run_of(&[("Green", 3.0), ("Blue", 2.0)]),
    );
    expect(
        &parts(
            5.0,
            "split(x) { 1 : Blue(1.5) | ~2 : Yellow(1) | 1 : Blue(0.5) }",
        ),
        &run_of(&[("Blue", 1.0), ("Yellow", 3.0), ("Blue", 1.0)]),
    );
    expect(
        &parts(
            5.0,
            "split(x) { 3 : Green(1) | ~1.5 : Blue(0.5) | ~1.5 : Blue(2) }",
        ),
        &run_of(&[("Green", 3.0), ("Blue", 1.0), ("Blue", 1.0)]),
    );
    let t = 2.0 / 3.0;
    expect(
        &parts(
            5.0,
            "split(x) { 3 : Green(1) | ~2 : Blue(0.5) | ~2 : Blue(2) | ~2 : Blue(1) }",
        ),
        &run_of(&[("Green", 3.0), ("Blue", t), ("Blue", t), ("Blue", t)]),
    );
    expect(
        &parts(5.0, "split(x) { 5 : Green(1) | ~1 : Blue(1) }"),
        &run_of(&[("Green", 5.0)]),
    );
}

#[test]
fn repeat_splits() {
    let five_greens = run_of(&[("Green", 2.0); 5]);
    expect(&parts(10.0, "split(x) { 2 : Green(1) }*"), &five_greens);
    expect(&parts(10.0, "split(x) { ~2.1 : Green(1) }*"), &five_greens);
    let g = 8.0 / 3.0;
    expect(
        &parts(
            10.0,
            "split(x) { 1 : Blue(2) | { ~2.5 : Green(1) }* | 1 : Blue(3) }",
        ),
        &run_of(&[
            ("Blue", 1.0),
            ("Green", g),
            ("Green", g),
            ("Green", g),
            ("Blue", 1.0),
        ]),
    );
    // "The floating splits do not get any space to be generated."
    expect(
        &parts(10.0, "split(x) { { 2 : Green(1) }* | ~1 : Blue(2) }"),
        &five_greens,
    );
    expect(
        &parts(10.0, "split(x) { ~1 : Blue(2) | { 2 : Green(1) }* }"),
        &five_greens,
    );
    // "(10-3)/4 = 1.75".
    expect(
        &parts(
            10.0,
            "split(x) { ~2 : Blue(1) | { 1 : Green(2) | ~2 : Blue(1) }* }",
        ),
        &run_of(&[
            ("Blue", 1.75),
            ("Green", 1.0),
            ("Blue", 1.75),
            ("Green", 1.0),
            ("Blue", 1.75),
            ("Green", 1.0),
            ("Blue", 1.75),
        ]),
    );
}

#[test]
fn repeat_patterns_and_parallel_repeats() {
    let got = parts(10.0, "split(x) { 1 : Blue(3) | { ~1 : Yellow(2) | 0.2 : Green(1) | ~1 : Yellow(2) }* | 1 : Blue(3) }");
    assert_eq!(got.iter().filter(|p| p.0 == "Green").count(), 4);
    assert!(got
        .iter()
        .filter(|p| p.0 == "Yellow")
        .all(|p| (p.2 - 0.9).abs() < 1e-9));
    // Two repeats bordered by absolute parts: G G G Y Y between the borders.
    let got = parts(
        10.0,
        "split(x) { 1 : Blue(2) | { 2 : Green(1) }* | { 1 : Yellow(1) }* | 1 : Blue(3) }",
    );
    assert_eq!(
        got.iter().map(|p| p.0.as_str()).collect::<Vec<_>>(),
        ["Blue", "Green", "Green", "Green", "Yellow", "Yellow", "Blue"]
    );
    // Two floating repeats bordered by floating parts: all parts equal.
    let got = parts(10.0, "split(x) { ~1 : Green(1) | { ~1 : Yellow(2) }* | ~1 : Green(1) | { ~1 : Blue(2) }* | ~1 : Green(1) }");
    let size = got[0].2;
    assert!(got.iter().all(|p| (p.2 - size).abs() < 1e-9), "{got:?}");
    assert!((got.iter().map(|p| p.2).sum::<f64>() - 10.0).abs() < 1e-9);
}

#[test]
fn split_index_and_total_drive_rules() {
    // attr_split.md: the first floor red, the last blue.
    let g = gen("Lot --> extrude(20) A\nA --> split(y){ 2 : B }*\nB --> case split.index == 0 : print(\"first \" + split.total) case split.index == split.total - 1 : print(\"last \" + split.index) else : X.\n").ok();
    assert_eq!(g.prints(), ["first 10", "last 9"]);
}

#[test]
fn no_adjust_scopes_tile_the_parent_scope() {
    // Parts of the cylinder with noAdjust keep the slab as scope even where
    // the geometry is narrower.
    let src = "Lot --> s(10, 4, 4) primitiveSphere() split(x, noAdjust) { ~1 : P }*\n\
               P --> print(scope.sx + \" \" + scope.sy + \" \" + scope.sz)\n";
    for line in gen(src).ok().prints() {
        assert_all_near(&numbers(&line), &[1.0, 4.0, 4.0], 1e-9);
    }
    let src = "Lot --> s(10, 4, 4) primitiveSphere() split(x) { ~1 : P }*\n\
               P --> print(scope.sx + \" \" + scope.sy + \" \" + scope.sz)\n";
    let first = numbers(&gen(src).ok().prints()[0]);
    assert!(
        (first[0] - 1.0).abs() < 1e-9 && first[1] < 4.0 - 1e-3,
        "{first:?}"
    );
}
