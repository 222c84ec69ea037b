//! Tests of the split layout: every worked example of CGA's `split` reference page, the
//! "subdivision split" manual page and the `splitArea` pages, the split patterns of the Candler
//! building rule, edge cases, and randomised property checks.

use cga_engine::split_layout::{
    layout, LayoutError, Placed, Size, SplitLayouter, SplitPattern, MAX_PARTS,
};

/// Parses the size part of a CGA split body, e.g. `{ 3.3 : Z | ~3 : Y | { '0.5 : X }* }*`.
/// Each entry is `size [: Label]` where size is `v`, `'v` or `~v`; returns the pattern and the
/// labels by part id (the part id itself when an entry has no label).
fn pattern(src: &str) -> (SplitPattern, Vec<String>) {
    let src = src.trim();
    assert!(src.starts_with('{'), "pattern must start with '{{': {src}");
    let (repeat, body) = if let Some(b) = src.strip_suffix("}*") {
        (true, &b[1..])
    } else {
        (false, &src[1..src.len() - 1])
    };
    let mut p = SplitPattern::new(repeat);
    let mut labels = Vec::new();
    let chars: Vec<char> = body.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if c.is_whitespace() || c == '|' {
            i += 1;
        } else if c == '{' {
            p.open();
            i += 1;
        } else if c == '}' {
            let star = chars.get(i + 1) == Some(&'*');
            p.close(star).unwrap();
            i += if star { 2 } else { 1 };
        } else {
            // size [: label]
            let start = i;
            while i < chars.len() && !matches!(chars[i], '|' | '{' | '}') {
                i += 1;
            }
            let entry: String = chars[start..i].iter().collect();
            let (size, label) = match entry.split_once(':') {
                Some((s, l)) => (s.trim().to_string(), Some(l.trim().to_string())),
                None => (entry.trim().to_string(), None),
            };
            let size = if let Some(v) = size.strip_prefix('\'') {
                Size::Relative(v.parse().unwrap())
            } else if let Some(v) = size.strip_prefix('~') {
                Size::Floating(v.parse().unwrap())
            } else {
                Size::Absolute(size.parse().unwrap())
            };
            let id = p.push(size);
            labels.push(label.unwrap_or_else(|| id.to_string()));
        }
    }
    (p, labels)
}

/// Lays out `src` on `length` and returns (label, start, size, end) of every part, checking that
/// `index` is the position and that the parts follow each other without gap or overlap.
fn run(src: &str, length: f64) -> Vec<(String, f64, f64, f64)> {
    let (p, labels) = pattern(src);
    let parts = layout(&p, length).unwrap();
    let mut end = 0.0;
    for (i, q) in parts.iter().enumerate() {
        assert_eq!(q.index, i, "split.index of part {i} in {src}");
        assert_eq!(
            q.start, end,
            "part {i} of {src} starts where the previous ends"
        );
        assert_eq!(q.size, q.end - q.start);
        end = q.end;
    }
    parts
        .iter()
        .map(|q| (labels[q.part].clone(), q.start, q.size, q.end))
        .collect()
}

/// Asserts the exact layout (positions to 1e-12 of the length).
#[track_caller]
fn check(src: &str, length: f64, expected: &[(&str, f64, f64)]) {
    let got = run(src, length);
    let eps = 1e-12 * length.max(1.0);
    let ok = got.len() == expected.len()
        && got
            .iter()
            .zip(expected)
            .all(|(g, e)| g.0 == e.0 && (g.1 - e.1).abs() <= eps && (g.2 - e.2).abs() <= eps);
    assert!(
        ok,
        "{src} on {length}\n  expected {expected:?}\n  got      {got:?}"
    );
}

/// Expected layout of `count` repetitions of `unit` (label, size) starting at `start`.
fn repeated(
    start: f64,
    count: usize,
    unit: &[(&'static str, f64)],
) -> Vec<(&'static str, f64, f64)> {
    let mut out = Vec::new();
    let mut x = start;
    for _ in 0..count {
        for &(l, s) in unit {
            out.push((l, x, s));
            x += s;
        }
    }
    out
}

fn concat(parts: &[&[(&'static str, f64, f64)]]) -> Vec<(&'static str, f64, f64)> {
    parts.iter().flat_map(|p| p.iter().copied()).collect()
}

// ---------------------------------------------------------------------------------------------
// CGA reference, split operation (scope.sx = 10)
// ---------------------------------------------------------------------------------------------

#[test]
fn reference_relative_sizes_leave_a_gap() {
    check(
        "{ '0.5 : Z | '0.1 : Y | '0.2 : X }",
        10.0,
        &[("Z", 0.0, 5.0), ("Y", 5.0, 1.0), ("X", 6.0, 2.0)],
    );
}

#[test]
fn reference_floating_sizes_only_keep_ratios() {
    check(
        "{ ~0.5 : Z | ~0.1 : Y | ~0.2 : X }",
        10.0,
        &[("Z", 0.0, 6.25), ("Y", 6.25, 1.25), ("X", 7.5, 2.5)],
    );
}

#[test]
fn reference_absolute_and_floating() {
    check(
        "{ 3.3 : Z | ~3 : Y | 5 : X }",
        10.0,
        &[("Z", 0.0, 3.3), ("Y", 3.3, 1.7), ("X", 5.0, 5.0)],
    );
}

#[test]
fn reference_oversized_is_cut_and_dropped() {
    check(
        "{ '0.5 : Z | '0.6 : Y | 3 : X }",
        10.0,
        &[("Z", 0.0, 5.0), ("Y", 5.0, 5.0)],
    );
}

#[test]
fn reference_repeat_with_absolute_sizes_cuts_the_last_x() {
    check(
        "{ 2 : X | 1 : Y }*",
        10.0,
        &[
            ("X", 0.0, 2.0),
            ("Y", 2.0, 1.0),
            ("X", 3.0, 2.0),
            ("Y", 5.0, 1.0),
            ("X", 6.0, 2.0),
            ("Y", 8.0, 1.0),
            ("X", 9.0, 1.0),
        ],
    );
}

#[test]
fn reference_repeat_with_floating_sizes_keeps_ratio_and_fills() {
    // Period 3 on 10: three repetitions (stretch 10/9) beat four (10/12), as the figure shows.
    let x = 20.0 / 9.0;
    let y = 10.0 / 9.0;
    check(
        "{ ~2 : X | ~1 : Y }*",
        10.0,
        &repeated(0.0, 3, &[("X", x), ("Y", y)]),
    );
}

#[test]
fn reference_interleaved_repeat_floating_parts_are_0_9() {
    let expected = concat(&[
        &[("X", 0.0, 1.0)],
        &repeated(1.0, 4, &[("Y", 0.9), ("Z", 0.2), ("Y", 0.9)]),
        &[("X", 9.0, 1.0)],
    ]);
    check(
        "{ 1 : X | { ~1 : Y | 0.2 : Z | ~1 : Y }* | 1 : X }",
        10.0,
        &expected,
    );
}

#[test]
fn reference_rhythm_gives_xyxyxyx() {
    // Current page: ~2.7, drawn as X Y X Y X Y X with Y = 2.
    let expected = concat(&[
        &repeated(0.0, 3, &[("X", 1.0), ("Y", 2.0)]),
        &[("X", 9.0, 1.0)],
    ]);
    check("{ { 1 : X | ~2.7 : Y }* | 1 : X }", 10.0, &expected);
}

#[test]
fn reference_rhythm_older_page_with_3() {
    // The older page writes ~3: two repetitions (Y = 3.5, stretch 1.17) beat three (Y = 2, 0.67).
    let expected = concat(&[
        &repeated(0.0, 2, &[("X", 1.0), ("Y", 3.5)]),
        &[("X", 9.0, 1.0)],
    ]);
    check("{ { 1 : X | ~3 : Y }* | 1 : X }", 10.0, &expected);
}

#[test]
fn reference_cutting_geometry_cylinder() {
    // Six XX pieces, as in the figure: 5 x (0.75 + 1) + 0.5 = 9.25 fits exactly.
    let expected = concat(&[
        &repeated(0.0, 5, &[("XX", 0.75), ("NIL", 1.0)]),
        &[("XX", 8.75, 0.5)],
    ]);
    check(
        "{ { ~0.75 : XX | ~1 : NIL }* | ~0.5 : XX }",
        9.25,
        &expected,
    );
    // On 10: still five repetitions (stretch 10/9.25 = 1.08 against 10/11 = 0.91).
    let s = 10.0 / 9.25;
    let expected = concat(&[
        &repeated(0.0, 5, &[("XX", 0.75 * s), ("NIL", s)]),
        &[("XX", 8.75 * s, 0.5 * s)],
    ]);
    check(
        "{ { ~0.75 : XX | ~1 : NIL }* | ~0.5 : XX }",
        10.0,
        &expected,
    );
}

#[test]
fn reference_uv_split_in_uv_space_and_unit_space() {
    // uvSpace: u in [0, 1], split at 0.5.
    check("{ 0.5 : X }*", 1.0, &[("X", 0.0, 0.5), ("X", 0.5, 0.5)]);
    // unitSpace: a facade 10 wide (extrude(scope.sx * 0.5) of a 10 lot ... any width): splits at 5.
    check("{ 5 : X }*", 10.0, &[("X", 0.0, 5.0), ("X", 5.0, 5.0)]);
    check(
        "{ 5 : X }*",
        12.0,
        &[("X", 0.0, 5.0), ("X", 5.0, 5.0), ("X", 10.0, 2.0)],
    );
}

#[test]
fn reference_uv_split_on_streets() {
    // A 92 m street: four bands of 3 m, each between two 10 m gaps.
    let unit = [("NIL", 10.0), ("X", 3.0), ("NIL", 10.0)];
    check(
        "{ ~10 : NIL | ~3 : X | ~10 : NIL }*",
        92.0,
        &repeated(0.0, 4, &unit),
    );
    // 100 m: four repetitions stretched by 100/92 (five would shrink by 100/115).
    let s = 100.0 / 92.0;
    let unit = [("NIL", 10.0 * s), ("X", 3.0 * s), ("NIL", 10.0 * s)];
    check(
        "{ ~10 : NIL | ~3 : X | ~10 : NIL }*",
        100.0,
        &repeated(0.0, 4, &unit),
    );
}

#[test]
fn reference_split_index_is_global() {
    // "split(x) { '0.1 : A | '0.1 : B }* will create 5 shapes with rule A interleaved with 5
    // shapes with rule B where split.index goes from 0 to 9 ... split.total will be 10."
    for length in [1.0, 3.7, 10.0, 123.456] {
        let (p, labels) = pattern("{ '0.1 : A | '0.1 : B }*");
        let parts = layout(&p, length).unwrap();
        assert_eq!(parts.len(), 10, "split.total on {length}");
        for (i, q) in parts.iter().enumerate() {
            assert_eq!(q.index, i);
            assert_eq!(labels[q.part], if i % 2 == 0 { "A" } else { "B" });
            assert!((q.start - i as f64 * 0.1 * length).abs() < 1e-12 * length);
            assert!((q.size - 0.1 * length).abs() < 1e-12 * length);
        }
        assert_eq!(parts[9].start + parts[9].size, length);
    }
}

#[test]
fn reference_split_attribute_example() {
    // Lot --> extrude(20) A;  A --> split(y){ 2 : B }*: ten B, index 0 red ... index 9 blue.
    let parts = run("{ 2 : B }*", 20.0);
    assert_eq!(parts.len(), 10);
    assert_eq!(parts.last().unwrap().1, 18.0);
    assert_eq!(parts.last().unwrap().3, 20.0);
}

// ---------------------------------------------------------------------------------------------
// Manual, subdivision split (cube of length 5, then 10 for the repeat splits)
// ---------------------------------------------------------------------------------------------

#[test]
fn manual_absolute_split() {
    check("{ 3 : Blue }", 5.0, &[("Blue", 0.0, 3.0)]);
}

#[test]
fn manual_two_absolute_splits() {
    check(
        "{ 3 : Green | 1 : Blue }",
        5.0,
        &[("Green", 0.0, 3.0), ("Blue", 3.0, 1.0)],
    );
}

#[test]
fn manual_absolute_values_within_a_limited_scope() {
    check(
        "{ 2 : Green | 1 : Green | 1 : Blue | 2 : Yellow | 1 : Blue }",
        5.0,
        &[
            ("Green", 0.0, 2.0),
            ("Green", 2.0, 1.0),
            ("Blue", 3.0, 1.0),
            ("Yellow", 4.0, 1.0),
        ],
    );
}

#[test]
fn manual_no_splits_with_negative_or_zero_sizes() {
    check(
        "{ 1.5 : Green | -2 : Yellow | 1.5 : Blue | 1.5 : Green | 0 : Yellow | 1.5 : Green }",
        5.0,
        &[
            ("Green", 0.0, 1.5),
            ("Blue", 1.5, 1.5),
            ("Green", 3.0, 1.5),
            ("Green", 4.5, 0.5),
        ],
    );
}

#[test]
fn manual_golden_ratio() {
    check(
        "{ '0.382 : A | '0.618 : B }",
        5.0,
        &[("A", 0.0, 1.91), ("B", 1.91, 3.09)],
    );
    // A --> split(x){ '0.382 : Green | '0.618 : Yellow } on A's 1.91, B's likewise on 3.09.
    check(
        "{ '0.382 : Green | '0.618 : Yellow }",
        1.91,
        &[("Green", 0.0, 0.72962), ("Yellow", 0.72962, 1.18038)],
    );
    check(
        "{ '0.382 : Green | '0.618 : Yellow }",
        3.09,
        &[("Green", 0.0, 1.18038), ("Yellow", 1.18038, 1.90962)],
    );
}

#[test]
fn manual_golden_ratio_recursion() {
    // A --> split(x){ '0.382 : A | '0.618 : C }: each level keeps the golden ratio, and the
    // pieces of every level tile the parent exactly.
    let (p, _) = pattern("{ '0.382 : A | '0.618 : C }");
    let mut layouter = SplitLayouter::new();
    let mut out = Vec::new();
    let mut length = 5.0;
    let mut depth = 0;
    while length > 0.01 {
        layouter.layout(&p, length, &mut out).unwrap();
        assert_eq!(out.len(), 2);
        assert!((out[0].size - 0.382 * length).abs() < 1e-12);
        assert!((out[1].start - 0.382 * length).abs() < 1e-12);
        assert_eq!(out[1].start + out[1].size, length);
        length = out[0].size;
        depth += 1;
    }
    // 5 * 0.382^n < 0.01 first for n = 7.
    assert_eq!(depth, 7);
}

#[test]
fn manual_floating_split_fills_the_rest() {
    check(
        "{ 3 : Green | ~1 : Blue }",
        5.0,
        &[("Green", 0.0, 3.0), ("Blue", 3.0, 2.0)],
    );
}

#[test]
fn manual_floating_value_fills_the_space_between_absolutes() {
    check(
        "{ 1 : Blue | ~2 : Yellow | 1 : Blue }",
        5.0,
        &[("Blue", 0.0, 1.0), ("Yellow", 1.0, 3.0), ("Blue", 4.0, 1.0)],
    );
}

#[test]
fn manual_multiple_floating_splits_distributed_evenly() {
    check(
        "{ 3 : Green | ~1.5 : Blue | ~1.5 : Blue2 }",
        5.0,
        &[("Green", 0.0, 3.0), ("Blue", 3.0, 1.0), ("Blue2", 4.0, 1.0)],
    );
}

#[test]
fn manual_three_floating_splits() {
    let t = 2.0 / 3.0;
    check(
        "{ 3 : Green | ~2 : Blue | ~2 : Blue | ~2 : Blue }",
        5.0,
        &[
            ("Green", 0.0, 3.0),
            ("Blue", 3.0, t),
            ("Blue", 3.0 + t, t),
            ("Blue", 3.0 + 2.0 * t, t),
        ],
    );
}

#[test]
fn manual_floating_split_without_space_is_not_generated() {
    check("{ 5 : Green | ~1 : Blue }", 5.0, &[("Green", 0.0, 5.0)]);
}

#[test]
fn manual_repeat_split_five_cubes() {
    check("{ 2 : Green }*", 10.0, &repeated(0.0, 5, &[("Green", 2.0)]));
}

#[test]
fn manual_floating_repeat_2_1_gives_five_of_2() {
    check(
        "{ ~2.1 : Green }*",
        10.0,
        &repeated(0.0, 5, &[("Green", 2.0)]),
    );
}

#[test]
fn manual_floating_repeat_bordered_by_absolutes() {
    // (10 - 2) / 3 = 2.66..., "the best approximation for the target value 2.5".
    let g = 8.0 / 3.0;
    let expected = concat(&[
        &[("Blue", 0.0, 1.0)],
        &repeated(1.0, 3, &[("Green", g)]),
        &[("Blue", 9.0, 1.0)],
    ]);
    check(
        "{ 1 : Blue | { ~2.5 : Green }* | 1 : Blue }",
        10.0,
        &expected,
    );
}

#[test]
fn manual_absolute_repeat_is_evaluated_first_on_either_side() {
    let greens = repeated(0.0, 5, &[("Green", 2.0)]);
    check("{ { 2 : Green }* | ~1 : Blue }", 10.0, &greens);
    check("{ ~1 : Blue | { 2 : Green }* }", 10.0, &greens);
}

#[test]
fn manual_absolute_repeat_bordered_by_floating_splits() {
    // "A repeat split with absolute values can be bordered by two
    // neighboring floating splits": the repetition count is the one that
    // stretches the floating borders least (CityEngine: the Candler pipe
    // holders, see candler_pipe_holders_are_centred). On 10, four Blues and
    // Greens of exactly 1 ...
    let expected = concat(&[
        &[("Green", 0.0, 1.0)],
        &repeated(1.0, 4, &[("Blue", 2.0)]),
        &[("Green", 9.0, 1.0)],
    ]);
    check(
        "{ ~1 : Green | { 2 : Blue }* | ~1 : Green }",
        10.0,
        &expected,
    );
    // ... and on 10.6 still four, with Greens of 1.3 (five would leave 0.3).
    let expected = concat(&[
        &[("Green", 0.0, 1.3)],
        &repeated(1.3, 4, &[("Blue", 2.0)]),
        &[("Green", 9.3, 1.3)],
    ]);
    check(
        "{ ~1 : Green | { 2 : Blue }* | ~1 : Green }",
        10.6,
        &expected,
    );
}

#[test]
fn manual_floating_and_repeat_floating_same_size() {
    // (10 - 3) / 4 = 1.75 for all four Blues.
    let expected = concat(&[
        &[("Blue", 0.0, 1.75)],
        &repeated(1.75, 3, &[("Green", 1.0), ("Blue", 1.75)]),
    ]);
    check(
        "{ ~2 : Blue | { 1 : Green | ~2 : Blue }* }",
        10.0,
        &expected,
    );
}

#[test]
fn manual_repeating_pattern() {
    // Four repetitions stretch by 9/8, five shrink by 8.75/10: an exact tie, which keeps fewer.
    check(
        "{ ~1 : Yellow | 0.25 : Green | ~1 : Yellow }*",
        10.0,
        &repeated(
            0.0,
            4,
            &[("Yellow", 1.125), ("Green", 0.25), ("Yellow", 1.125)],
        ),
    );
    // Without the tie (10.5): five repetitions, 9.25 / 10.
    check(
        "{ ~1 : Yellow | 0.25 : Green | ~1 : Yellow }*",
        10.5,
        &repeated(
            0.0,
            5,
            &[("Yellow", 0.925), ("Green", 0.25), ("Yellow", 0.925)],
        ),
    );
}

#[test]
fn manual_repeating_pattern_inside_other_geometries() {
    let expected = concat(&[
        &[("Blue", 0.0, 1.0)],
        &repeated(1.0, 4, &[("Yellow", 0.9), ("Green", 0.2), ("Yellow", 0.9)]),
        &[("Blue", 9.0, 1.0)],
    ]);
    check(
        "{ 1 : Blue | { ~1 : Yellow | 0.2 : Green | ~1 : Yellow }* | 1 : Blue }",
        10.0,
        &expected,
    );
}

#[test]
fn manual_parallel_floating_repeats_bordered_by_floating_splits() {
    // Seven floating parts of weight 1 fit 10 - 3 exactly: 4 Yellow, 3 Blue, all of size 1.
    let expected = concat(&[
        &[("Green", 0.0, 1.0)],
        &repeated(1.0, 4, &[("Yellow", 1.0)]),
        &[("Green", 5.0, 1.0)],
        &repeated(6.0, 3, &[("Blue", 1.0)]),
        &[("Green", 9.0, 1.0)],
    ]);
    check(
        "{ ~1 : Green | { ~1 : Yellow }* | ~1 : Green | { ~1 : Blue }* | ~1 : Green }",
        10.0,
        &expected,
    );
}

#[test]
fn manual_two_successive_absolute_repeats_bordered_by_absolutes() {
    // The two repeats take turns: G Y G Y G fills the 8 between the borders.
    check(
        "{ 1 : Blue | { 2 : Green }* | { 1 : Yellow }* | 1 : Blue }",
        10.0,
        &[
            ("Blue", 0.0, 1.0),
            ("Green", 1.0, 2.0),
            ("Green", 3.0, 2.0),
            ("Green", 5.0, 2.0),
            ("Yellow", 7.0, 1.0),
            ("Yellow", 8.0, 1.0),
            ("Blue", 9.0, 1.0),
        ],
    );
}

// ---------------------------------------------------------------------------------------------
// splitArea: the same sizes with areas (L = the shape's area)
// ---------------------------------------------------------------------------------------------

#[test]
fn split_area_relative_sums_below_and_above_the_whole() {
    check(
        "{ '0.7 : Green | '0.3 : Yellow }",
        1234.5,
        &[("Green", 0.0, 864.15), ("Yellow", 864.15, 370.35)],
    );
    // "For sums less than 1, the rest of the shape is discarded" ...
    check(
        "{ '0.4 : Green | '0.3 : Yellow }",
        1000.0,
        &[("Green", 0.0, 400.0), ("Yellow", 400.0, 300.0)],
    );
    // ... "and split sections greater than 1 are ignored".
    check(
        "{ '0.7 : Green | '0.5 : Yellow | '0.1 : Blue }",
        1000.0,
        &[("Green", 0.0, 700.0), ("Yellow", 700.0, 300.0)],
    );
}

#[test]
fn split_area_repeating_split() {
    for area in [1.0, 850.0, 1234.5] {
        let got = run("{ '0.2 : ColorMe }*", area);
        assert_eq!(got.len(), 5, "five equal parts on {area}");
        for (i, g) in got.iter().enumerate() {
            assert!((g.1 - 0.2 * area * i as f64).abs() < 1e-12 * area);
            assert!((g.2 - 0.2 * area).abs() < 1e-12 * area);
        }
        // '0.3 gives 30, 30, 30 and 10 %.
        let got = run("{ '0.3 : ColorMe }*", area);
        let sizes: Vec<f64> = got.iter().map(|g| g.2 / area).collect();
        assert_eq!(sizes.len(), 4, "{sizes:?}");
        for (s, e) in sizes.iter().zip([0.3, 0.3, 0.3, 0.1]) {
            assert!((s - e).abs() < 1e-12, "{sizes:?}");
        }
        assert_eq!(got[3].3, area);
    }
}

#[test]
fn split_area_floating_and_absolute() {
    check(
        "{ ~1 : Green | 600 : Yellow | ~1 : Blue }",
        1000.0,
        &[
            ("Green", 0.0, 200.0),
            ("Yellow", 200.0, 600.0),
            ("Blue", 800.0, 200.0),
        ],
    );
}

#[test]
fn split_area_nested() {
    check(
        "{ ~1 : A | ~1 : B | ~1 : C }",
        900.0,
        &[("A", 0.0, 300.0), ("B", 300.0, 300.0), ("C", 600.0, 300.0)],
    );
    check(
        "{ '0.5 : Red | '0.5 : Yellow }",
        300.0,
        &[("Red", 0.0, 150.0), ("Yellow", 150.0, 150.0)],
    );
}

// ---------------------------------------------------------------------------------------------
// The Candler building rule
// ---------------------------------------------------------------------------------------------

const CORNER: f64 = 1.0; // CornerWallWidth
const TILE: f64 = 3.55; // TileWidth
const FLOOR: f64 = 3.5; // FloorHeight

fn candler_floor() -> String {
    format!(
        "{{ {CORNER} : Wall | {TILE} : TileA | {{ ~{TILE} : TileB }}* | {TILE} : TileC \
         | {{ ~{TILE} : TileB }}* | {TILE} : TileA | {CORNER} : Wall }}"
    )
}

#[track_caller]
fn assert_symmetric(parts: &[(String, f64, f64, f64)], length: f64) {
    let n = parts.len();
    for i in 0..n {
        let (a, b) = (&parts[i], &parts[n - 1 - i]);
        assert_eq!(a.0, b.0, "mirror labels {i}");
        assert!((a.2 - b.2).abs() < 1e-12, "mirror sizes {i}: {parts:?}");
        assert!(
            (a.1 - (length - b.1 - b.2)).abs() < 1e-12,
            "mirror position {i}"
        );
    }
}

#[test]
fn candler_floor_20_wide_is_symmetric() {
    // 20 - 2 - 3 * 3.55 = 7.35 for the two floating repeats: one tile each, 3.675 wide.
    let parts = run(&candler_floor(), 20.0);
    let b = 7.35 / 2.0;
    let expected = [
        ("Wall", 0.0, 1.0),
        ("TileA", 1.0, TILE),
        ("TileB", 4.55, b),
        ("TileC", 4.55 + b, TILE),
        ("TileB", 8.1 + b, b),
        ("TileA", 8.1 + 2.0 * b, TILE),
        ("Wall", 19.0, 1.0),
    ];
    check(&candler_floor(), 20.0, &expected);
    assert_symmetric(&parts, 20.0);
}

#[test]
fn candler_floor_wider_facades() {
    for (width, total_b) in [(30.0, 5), (27.4, 4), (41.0, 8), (60.0, 13)] {
        let parts = run(&candler_floor(), width);
        let b: Vec<&(String, f64, f64, f64)> = parts.iter().filter(|p| p.0 == "TileB").collect();
        assert_eq!(b.len(), total_b, "Tile(b) count on {width}");
        // Both repeats share the floating space: one common tile size, the least stretched.
        let size = (width - 2.0 * CORNER - 3.0 * TILE) / total_b as f64;
        for t in &b {
            assert!((t.2 - size).abs() < 1e-12, "{width}: {parts:?}");
        }
        let stretch = (size / TILE - 1.0).abs();
        for other in [total_b - 1, total_b + 1] {
            let s = (width - 2.0 * CORNER - 3.0 * TILE) / other as f64;
            assert!(stretch <= (s / TILE - 1.0).abs());
        }
        // The centre tile splits the floating tiles evenly, the first repeat taking an odd one.
        let c = parts.iter().position(|p| p.0 == "TileC").unwrap();
        let before = parts[..c].iter().filter(|p| p.0 == "TileB").count();
        assert_eq!(before, total_b.div_ceil(2), "{width}");
        if total_b % 2 == 0 {
            assert_symmetric(&parts, width);
        }
        let last = parts.last().unwrap();
        assert_eq!((last.0.as_str(), last.3), ("Wall", width));
    }
}

#[test]
fn candler_narrow_floor() {
    let src = format!("{{ {CORNER} : Wall | {{ ~{TILE} : TileA }}* | {CORNER} : Wall }}");
    let expected = concat(&[
        &[("Wall", 0.0, 1.0)],
        &repeated(1.0, 3, &[("TileA", 3.5)]),
        &[("Wall", 11.5, 1.0)],
    ]);
    check(&src, 12.5, &expected);
}

#[test]
fn candler_facade_floors() {
    // Facade --> split(y){ ~2.3: Base | ~12 : Mid | ~3 : Upper | 2.5 : Top } on a 62 high facade.
    let parts = run("{ ~2.3 : Base | ~12 : Mid | ~3 : Upper | 2.5 : Top }", 62.0);
    let s = 59.5 / 17.3;
    let expected = [
        ("Base", 0.0, 2.3 * s),
        ("Mid", 2.3 * s, 12.0 * s),
        ("Upper", 14.3 * s, 3.0 * s),
        ("Top", 59.5, 2.5),
    ];
    check(
        "{ ~2.3 : Base | ~12 : Mid | ~3 : Upper | 2.5 : Top }",
        62.0,
        &expected,
    );

    // Mid --> split(y){ ~FloorHeight : Floor }*: 41.27 / 3.5 = 11.8 gives 12 floors.
    let mid = parts[1].2;
    let floors = run(&format!("{{ ~{FLOOR} : Floor }}*"), mid);
    assert_eq!(floors.len(), 12);
    assert_eq!(floors[11].3, mid);
    // Upper: 10.32 / 3.5 = 2.95 gives 3 floors.
    let upper = parts[2].2;
    assert_eq!(run(&format!("{{ ~{FLOOR} : Floor }}*"), upper).len(), 3);
    // Base on the street: 4.3 ground floor and the rest, 3.61, as one upper base floor.
    let base = parts[0].2;
    let got = run(
        &format!("{{ 4.3 : Ground | {{ ~{FLOOR} : Floor }}* }}"),
        base,
    );
    assert_eq!(got.len(), 2);
    assert_eq!(got[1].0, "Floor");
    assert!((got[1].2 - (base - 4.3)).abs() < 1e-12);
    assert_eq!(got[1].3, base);
}

#[test]
fn candler_windows_give_n_windows_and_n_minus_1_dividers() {
    // Windows(n) --> split(x){ { ~scope.sx/n: Window | dividerW: Wall }* | ~scope.sx/n: Window }
    let width = 2.15; // FrontWindowWidth
    for n in 1..=3usize {
        let w = width / n as f64;
        let src = format!("{{ {{ ~{w} : Window | 0.25 : Wall }}* | ~{w} : Window }}");
        let parts = run(&src, width);
        let windows: Vec<_> = parts.iter().filter(|p| p.0 == "Window").collect();
        let walls: Vec<_> = parts.iter().filter(|p| p.0 == "Wall").collect();
        assert_eq!(windows.len(), n, "windows for n = {n}: {parts:?}");
        assert_eq!(walls.len(), n - 1);
        let size = (width - 0.25 * (n - 1) as f64) / n as f64;
        for p in &windows {
            assert!((p.2 - size).abs() < 1e-12);
        }
        assert_symmetric(&parts, width);
    }
}

#[test]
fn candler_tile() {
    // Tile --> split(x){ winSideW: Wall | ~1: SubTile | winSideW: Wall } with winSideW = 0.7.
    check(
        "{ 0.7 : Wall | ~1 : SubTile | 0.7 : Wall }",
        3.55,
        &[
            ("Wall", 0.0, 0.7),
            ("SubTile", 0.7, 2.15),
            ("Wall", 2.85, 0.7),
        ],
    );
    // SubTile --> split(y){ sillH: Wall | WindowHeight: Windows | ~1: Wall } (3.5 high floor).
    let sill = (3.5 - 2.05) * 0.66;
    check(
        &format!("{{ {sill} : Wall | 2.05 : Windows | ~1 : Wall2 }}"),
        3.5,
        &[
            ("Wall", 0.0, sill),
            ("Windows", sill, 2.05),
            ("Wall2", sill + 2.05, 3.5 - sill - 2.05),
        ],
    );
}

#[test]
fn candler_pipe_holders_are_centred() {
    // PipeHolders --> split(x){ ~3: NIL | { 0.3: PipeHolder | 4: NIL }* | 0.3: PipeHolder | ~3: NIL }
    // The count keeps the margins nearest their target 3: on 20, three
    // repetitions (margins 3.4) rather than the four that would fit
    // (margins 1.25). This is what CityEngine generates: with it the
    // Candler pipe areas match its output on both reference lots.
    let parts = run(
        "{ ~3 : NIL | { 0.3 : Holder | 4 : Gap }* | 0.3 : Holder | ~3 : NIL }",
        20.0,
    );
    let expected = concat(&[
        &[("NIL", 0.0, 3.4)],
        &repeated(3.4, 3, &[("Holder", 0.3), ("Gap", 4.0)]),
        &[("Holder", 16.3, 0.3), ("NIL", 16.6, 3.4)],
    ]);
    check(
        "{ ~3 : NIL | { 0.3 : Holder | 4 : Gap }* | 0.3 : Holder | ~3 : NIL }",
        20.0,
        &expected,
    );
    assert_eq!(parts.len(), 9);
}

#[test]
fn candler_ventilation_pipes() {
    // split(x){ ~scope.sy/2: VerticalPipes | { ~scope.sy: VerticalPipes }* | ~scope.sy/2: NIL }
    // with scope.sx = 8.2, scope.sy = 2.5: the two halves and n whole ones weigh (n + 1) * 2.5;
    // n = 2 stretches by 8.2 / 7.5 = 1.09, n = 3 shrinks by 8.2 / 10 = 0.82: two in the repeat.
    let parts = run("{ ~1.25 : Pipes | { ~2.5 : Pipes }* | ~1.25 : NIL }", 8.2);
    let s = 8.2 / 7.5;
    let expected = concat(&[
        &[("Pipes", 0.0, 1.25 * s)],
        &repeated(1.25 * s, 2, &[("Pipes", 2.5 * s)]),
        &[("NIL", 6.25 * s, 1.25 * s)],
    ]);
    check(
        "{ ~1.25 : Pipes | { ~2.5 : Pipes }* | ~1.25 : NIL }",
        8.2,
        &expected,
    );
    assert_eq!(parts.len(), 4);
    // Ventilator --> split(x){ ~scope.sy: Ventilator }* with sx = 8.2, sy = 2.5: three of 2.73.
    check("{ ~2.5 : V }*", 8.2, &repeated(0.0, 3, &[("V", 8.2 / 3.0)]));
}

// ---------------------------------------------------------------------------------------------
// Edge cases
// ---------------------------------------------------------------------------------------------

#[test]
fn nested_groups_are_inlined_and_relative_sizes_use_the_whole_length() {
    check(
        "{ 1 : A | { '0.5 : B | ~1 : C } | { ~1 : D } }",
        10.0,
        &[
            ("A", 0.0, 1.0),
            ("B", 1.0, 5.0),
            ("C", 6.0, 2.0),
            ("D", 8.0, 2.0),
        ],
    );
    // Deeply nested relative size: still a fraction of the whole split.
    check(
        "{ { { '0.25 : A } } | '0.25 : B }",
        8.0,
        &[("A", 0.0, 2.0), ("B", 2.0, 2.0)],
    );
    // {{ P }*} is the same as { P }*.
    assert_eq!(
        run("{ { 2 : X | 1 : Y }* }", 10.0),
        run("{ 2 : X | 1 : Y }*", 10.0)
    );
    assert_eq!(
        run("{ { ~2 : X | ~1 : Y }* }", 10.0),
        run("{ ~2 : X | ~1 : Y }*", 10.0)
    );
}

#[test]
fn repeat_nested_in_a_repeat_is_laid_out_once_per_repetition() {
    check(
        "{ 1 : A | { 2 : B }* }*",
        7.0,
        &[
            ("A", 0.0, 1.0),
            ("B", 1.0, 2.0),
            ("A", 3.0, 1.0),
            ("B", 4.0, 2.0),
            ("A", 6.0, 1.0),
        ],
    );
}

#[test]
fn relative_repeat_inside_a_split() {
    // { 1 : A | { '0.2 : B }* | 1 : A } on 10: 8 left, four B of 2.
    let expected = concat(&[
        &[("A", 0.0, 1.0)],
        &repeated(1.0, 4, &[("B", 2.0)]),
        &[("A", 9.0, 1.0)],
    ]);
    check("{ 1 : A | { '0.2 : B }* | 1 : A }", 10.0, &expected);
}

#[test]
fn absolute_repeat_between_absolutes_cuts_its_last_repetition() {
    // Nothing floats: the repeat fills its space with a cut repetition, the border stays whole.
    check(
        "{ 1 : A | { 2 : B }* | 1 : A }",
        10.5,
        &[
            ("A", 0.0, 1.0),
            ("B", 1.0, 2.0),
            ("B", 3.0, 2.0),
            ("B", 5.0, 2.0),
            ("B", 7.0, 2.0),
            ("B", 9.0, 0.5),
            ("A", 9.5, 1.0),
        ],
    );
}

#[test]
fn floating_repeat_too_small_for_its_fixed_parts() {
    // { 1 : X | ~2.7 : Y }* | 1 : X on 1.5: no whole repetition fits in the 0.5 left by the last
    // X; a cut one covers it.
    check(
        "{ { 1 : X | ~2.7 : Y }* | 1 : X }",
        1.5,
        &[("X", 0.0, 0.5), ("X", 0.5, 1.0)],
    );
    // A floating repeat alone on a short length: one stretched (shrunk) part.
    check("{ ~2.1 : G }*", 0.5, &[("G", 0.0, 0.5)]);
    // Not even the fixed part of one repetition fits: a cut repetition, as without the `*`.
    check("{ 1 : A | ~1 : B }*", 0.5, &[("A", 0.0, 0.5)]);
    check(
        "{ ~1 : Window | 0.5 : Pillar }*",
        0.4,
        &[("Pillar", 0.0, 0.4)],
    );
    check(
        "{ 1 : A | { 1 : B | ~1 : C }* | 1 : A }",
        2.5,
        &[("A", 0.0, 1.0), ("B", 1.0, 0.5), ("A", 1.5, 1.0)],
    );
}

#[test]
fn floating_repeat_with_no_room_creates_nothing() {
    check(
        "{ 1 : A | { ~1 : B }* | 1 : A }",
        2.0,
        &[("A", 0.0, 1.0), ("A", 1.0, 1.0)],
    );
}

#[test]
fn degenerate_inputs() {
    assert!(run("{ 1 : A }", 0.0).is_empty());
    assert!(run("{ 1 : A }", -3.0).is_empty());
    assert!(run("{ ~1 : A }*", 0.0).is_empty());
    assert!(run("{ 0 : A | -1 : B | ~0 : C | ~-2 : D | '0 : E }", 10.0).is_empty());
    assert!(run("{ 0 : A | ~0 : B }*", 10.0).is_empty());
    assert!(run("{ }*", 10.0).is_empty());
    assert!(run("{ }", 10.0).is_empty());
    assert!(run("{ { } { }* }", 10.0).is_empty());
}

#[test]
fn errors_are_reported() {
    let mut p = SplitPattern::new(false);
    p.push(Size::Absolute(1.0));
    assert_eq!(p.close(false), Err(LayoutError::UnbalancedGroups));
    assert_eq!(layout(&p, 10.0), Err(LayoutError::UnbalancedGroups));

    let mut p = SplitPattern::new(false);
    p.open();
    p.push(Size::Absolute(1.0));
    assert_eq!(layout(&p, 10.0), Err(LayoutError::UnbalancedGroups));

    let mut p = SplitPattern::new(false);
    p.push(Size::Absolute(1.0));
    p.push(Size::Floating(f64::NAN));
    assert!(matches!(
        layout(&p, 10.0),
        Err(LayoutError::NonFiniteSize { part: 1, .. })
    ));
    let mut p = SplitPattern::new(false);
    p.push(Size::Relative(f64::INFINITY));
    assert!(matches!(
        layout(&p, 10.0),
        Err(LayoutError::NonFiniteSize { part: 0, .. })
    ));

    let (p, _) = pattern("{ 1 : A }");
    assert!(matches!(
        layout(&p, f64::NAN),
        Err(LayoutError::NonFiniteLength(_))
    ));
    assert!(matches!(
        layout(&p, f64::INFINITY),
        Err(LayoutError::NonFiniteLength(_))
    ));

    // Runaway repeats are refused instead of allocating without bound.
    for src in [
        "{ 0.000001 : A }*",
        "{ ~0.000001 : A }*",
        "{ 1 : A | { 0.0000001 : B | 0.0000001 : C }* }",
    ] {
        let (p, _) = pattern(src);
        match layout(&p, 1000.0) {
            Err(LayoutError::TooManyParts { parts }) => assert!(parts > MAX_PARTS as f64),
            other => panic!("{src}: {other:?}"),
        }
    }
    // ... but large honest splits work.
    let (p, _) = pattern("{ 0.001 : A }*");
    assert_eq!(layout(&p, 1000.0).unwrap().len(), 1_000_000);
}

#[test]
fn no_slivers_from_rounding() {
    // 0.1 is not exact in binary: ten of them must still be ten parts ending at 1, not eleven.
    let got = run("{ 0.1 : A }*", 1.0);
    assert_eq!(got.len(), 10);
    assert_eq!(got[9].3, 1.0);
    let got = run("{ 0.1 : A | 0.2 : B }*", 0.9);
    assert_eq!(got.len(), 6);
    assert_eq!(got[5].3, 0.9);
    // Floating parts whose sizes do not add up to L bit for bit still end exactly at L.
    for length in [1.0, 0.3, 7.1, 10.0, 1e-3, 12345.6789] {
        for src in [
            "{ ~1 : A | ~1 : B | ~1 : C }",
            "{ ~0.1 : A }*",
            "{ '0.1 : A | ~0.7 : B }*",
        ] {
            let got = run(src, length);
            let last = got.last().unwrap();
            assert_eq!(last.3, length, "{src} on {length}");
        }
    }
    // Three repetitions of 3.3 leave 0.1 for one more, cut, repetition (not a sliver).
    let got = run("{ 3.3 : A }*", 10.0);
    assert_eq!(got.len(), 4);
    assert!((got[3].2 - 0.1).abs() < 1e-12);
}

#[test]
fn layouter_and_pattern_reuse() {
    let mut layouter = SplitLayouter::new();
    let mut p = SplitPattern::new(true);
    let mut out = vec![];
    p.push(Size::Absolute(2.0));
    layouter.layout(&p, 10.0, &mut out).unwrap();
    assert_eq!(out.len(), 5);
    p.reset(false);
    assert!(!p.is_repeat());
    assert_eq!(p.part_count(), 0);
    p.push(Size::Absolute(3.0));
    p.push(Size::Floating(1.0));
    layouter.layout(&p, 5.0, &mut out).unwrap();
    assert_eq!(
        out,
        vec![
            Placed {
                part: 0,
                start: 0.0,
                size: 3.0,
                end: 3.0,
                index: 0
            },
            Placed {
                part: 1,
                start: 3.0,
                size: 2.0,
                end: 5.0,
                index: 1
            },
        ]
    );
}

// ---------------------------------------------------------------------------------------------
// Randomised properties
// ---------------------------------------------------------------------------------------------

/// A small deterministic generator (xorshift64*), so that failures reproduce.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn random_size(rng: &mut Rng) -> Size {
    let v = match rng.below(10) {
        0 => 0.0,
        1 => -rng.unit() * 3.0,
        2 => (rng.below(8) as f64) * 0.25, // "nice" values that make exact fits and ties
        _ => rng.unit() * 4.0,
    };
    match rng.below(3) {
        0 => Size::Absolute(v),
        1 => Size::Relative(v / 8.0),
        _ => Size::Floating(v),
    }
}

/// Appends a random group body; returns whether it contains a repeat.
fn random_group(rng: &mut Rng, p: &mut SplitPattern, sizes: &mut Vec<Size>, depth: u32) -> bool {
    let mut has_repeat = false;
    for _ in 0..1 + rng.below(4) {
        if depth < 2 && rng.below(4) == 0 {
            p.open();
            has_repeat |= random_group(rng, p, sizes, depth + 1);
            let repeat = rng.below(2) == 0;
            has_repeat |= repeat;
            p.close(repeat).unwrap();
        } else {
            let s = random_size(rng);
            sizes.push(s);
            p.push(s);
        }
    }
    has_repeat
}

#[test]
fn random_layouts_tile_the_split() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let mut layouter = SplitLayouter::new();
    let mut out = Vec::new();
    let mut p = SplitPattern::new(false);
    let mut sizes = Vec::new();
    let (mut filled, mut repeated_cases, mut cut) = (0, 0, 0);
    for case in 0..20_000 {
        p.reset(rng.below(3) == 0);
        sizes.clear();
        let has_repeat = random_group(&mut rng, &mut p, &mut sizes, 0) || p.is_repeat();
        let length = match rng.below(4) {
            0 => rng.below(20) as f64 * 0.5,
            _ => rng.unit() * 30.0,
        };
        layouter.layout(&p, length, &mut out).unwrap();
        let ctx = || format!("case {case}: {sizes:?} on {length}: {out:?}");

        let mut end = 0.0;
        let mut scale = None;
        let mut any_floating = false;
        for (i, q) in out.iter().enumerate() {
            assert_eq!(q.index, i, "{}", ctx());
            // In order, without overlap or inner gap, inside [0, L], never empty.
            assert_eq!(q.start, end, "{}", ctx());
            assert!(q.size > 0.0 && q.end > q.start, "{}", ctx());
            assert_eq!(q.size, q.end - q.start, "{}", ctx());
            end = q.end;
            assert!(end <= length, "{}", ctx());
            match sizes[q.part] {
                // Fixed parts are never longer than asked (shorter only when cut).
                // (A part ending within the fit tolerance of the end is snapped to it.)
                Size::Absolute(z) => assert!(q.size <= z + 1e-9 * length, "{}", ctx()),
                Size::Relative(r) => assert!(q.size <= r * length * (1.0 + 1e-9), "{}", ctx()),
                // All floating parts share one scale.
                Size::Floating(w) => {
                    any_floating = true;
                    let s = q.size / w;
                    let s0 = *scale.get_or_insert(s);
                    assert!((s - s0).abs() <= 1e-9 * s0.max(1.0), "{}", ctx());
                }
            }
        }
        // Floating parts that got room fill the split exactly.
        if any_floating {
            assert_eq!(end, length, "{}", ctx());
            filled += 1;
        }
        if has_repeat && out.len() > sizes.len() {
            repeated_cases += 1;
        }
        if out.iter().any(|q| match sizes[q.part] {
            Size::Absolute(z) => q.size < z * (1.0 - 1e-9),
            _ => false,
        }) {
            cut += 1;
        }
        // Without repeats, a floating part of positive weight with room left covers [0, L].
        let fixed_total: f64 = sizes
            .iter()
            .map(|s| match *s {
                Size::Absolute(z) if z > 0.0 => z,
                Size::Relative(r) if r > 0.0 => r * length,
                _ => 0.0,
            })
            .sum();
        let has_float = sizes
            .iter()
            .any(|s| matches!(*s, Size::Floating(w) if w > 0.0));
        if !has_repeat && has_float && fixed_total < length * 0.999 {
            assert_eq!(end, length, "{}", ctx());
        }
    }
    // The generator exercises every case, not only trivial ones.
    assert!(
        filled > 5_000 && repeated_cases > 2_000 && cut > 2_000,
        "{filled} {repeated_cases} {cut}"
    );
}

/// The least stretched count of one floating repeat between random borders, by brute force.
#[test]
fn random_floating_repeat_counts_are_least_stretched() {
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    let mut checked = 0;
    for case in 0..5_000 {
        // fixed and floating borders, and a repeat of fixed `a` and floating weight `f`
        let border_fixed = (rng.below(3) as f64) * rng.unit() * 3.0;
        let border_float = if rng.below(2) == 0 {
            0.0
        } else {
            rng.unit() * 3.0
        };
        let a = if rng.below(3) == 0 {
            0.0
        } else {
            rng.unit() * 2.0
        };
        let f = 0.05 + rng.unit() * 3.0;
        let length = rng.unit() * 40.0;
        let mut p = SplitPattern::new(false);
        p.push(Size::Absolute(border_fixed));
        p.open();
        if a > 0.0 {
            p.push(Size::Absolute(a));
        }
        let rep = p.push(Size::Floating(f));
        p.close(true).unwrap();
        p.push(Size::Floating(border_float));
        let parts = layout(&p, length).unwrap();
        let n = parts.iter().filter(|q| q.part == rep).count();

        let rest0 = length - border_fixed;
        let stretch = |n: usize| {
            let rest = rest0 - n as f64 * a;
            let weight = border_float + n as f64 * f;
            if weight > 0.0 {
                (rest.max(0.0) / weight - 1.0).abs()
            } else if rest <= 1e-9 * length {
                0.0
            } else {
                f64::INFINITY
            }
        };
        if rest0 <= 1e-9 * length {
            continue;
        }
        let mut best = 0;
        let mut k = 1;
        while rest0 - k as f64 * a >= -1e-9 * length && k < 10_000 {
            if stretch(k) < stretch(best) - 1e-12 {
                best = k;
            }
            k += 1;
        }
        assert_eq!(
            n, best,
            "case {case}: {border_fixed} | {{ {a} | ~{f} }}* | ~{border_float} on {length}: {parts:?}"
        );
        checked += 1;
    }
    assert!(checked > 4_000);
}

#[test]
fn positions_stay_exact_over_many_repetitions() {
    // Every position is within a few ulps of the exact value, not n * ulp after n parts.
    let got = run("{ 0.1 : A }*", 1000.0);
    assert_eq!(got.len(), 10_000);
    for (k, g) in got.iter().enumerate() {
        assert!((g.1 - k as f64 * 0.1).abs() < 1e-12, "part {k}: {g:?}");
        assert!((g.2 - 0.1).abs() < 1e-12, "part {k}: {g:?}");
    }
    assert_eq!(got.last().unwrap().3, 1000.0);
    // Floating: 0.1 + 0.3 stretched to fill 999.9 with 2500 repetitions (s = 0.9999).
    let got = run("{ 0.1 : A | ~0.3 : B }*", 999.9);
    assert_eq!(got.len(), 5000);
    let b = (999.9 - 250.0) / 2500.0;
    for (k, g) in got.iter().enumerate() {
        let expected = (k / 2) as f64 * (0.1 + b) + if k % 2 == 1 { 0.1 } else { 0.0 };
        assert!(
            (g.1 - expected).abs() < 1e-12,
            "part {k}: {g:?} vs {expected}"
        );
    }
    assert_eq!(got.last().unwrap().3, 999.9);
}
