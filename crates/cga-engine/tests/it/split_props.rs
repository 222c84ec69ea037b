//! Property tests of `split` through the engine: for random split patterns
//! on random boxes and prisms (concave lots extruded), the parts' volumes add
//! up to the whole's (exactly when a floating part fills the split) and every
//! part of a closed shape is closed.

use crate::ops_common::*;
use cga_geometry::DVec3;
use proptest::prelude::*;

/// A random split size: absolute, relative or floating.
fn size() -> impl Strategy<Value = String> {
    prop_oneof![
        (0.2f64..6.0).prop_map(|x| format!("{x:.3}")),
        (0.05f64..0.6).prop_map(|x| format!("'{x:.3}")),
        (0.2f64..4.0).prop_map(|x| format!("~{x:.3}")),
    ]
}

/// A random pattern: entries and nested repeat groups.
fn pattern() -> impl Strategy<Value = (String, bool)> {
    let entry = size().prop_map(|s| format!("{s} : P"));
    let group = prop::collection::vec(size(), 1..3).prop_map(|sizes| {
        let inner: Vec<String> = sizes.iter().map(|s| format!("{s} : P")).collect();
        format!("{{ {} }}*", inner.join(" | "))
    });
    (
        prop::collection::vec(prop_oneof![3 => entry, 1 => group], 1..5),
        any::<bool>(),
    )
        .prop_map(|(parts, repeat)| {
            let floats = parts.iter().any(|p| p.contains('~'));
            (
                format!(
                    "{{ {} }}{}",
                    parts.join(" | "),
                    if repeat { "*" } else { "" }
                ),
                floats,
            )
        })
}

/// A star-shaped (often concave) lot around the origin.
fn lot() -> impl Strategy<Value = Vec<DVec3>> {
    prop::collection::vec(4.0f64..15.0, 5..9).prop_map(|radii| {
        let n = radii.len();
        radii
            .iter()
            .enumerate()
            .map(|(i, r)| {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                DVec3::new(r * a.cos(), 0.0, -r * a.sin())
            })
            .collect()
    })
}

fn check(src: &str, opts: &Opts, fills: bool) -> Result<(), TestCaseError> {
    let g = gen_with(src, opts).ok();
    let prints = g.prints();
    let whole: f64 = prints[0].parse().unwrap();
    let mut sum = 0.0;
    for line in &prints[1..] {
        let (vol, closed) = line.split_once(' ').unwrap();
        prop_assert_eq!(closed, "true", "a part is not closed: {}", src);
        sum += vol.parse::<f64>().unwrap();
    }
    prop_assert!(
        sum <= whole * (1.0 + 1e-9) + 1e-9,
        "{} > {} for {}",
        sum,
        whole,
        src
    );
    if fills {
        prop_assert!(
            (sum - whole).abs() <= 1e-8 * whole,
            "{} != {} for {}",
            sum,
            whole,
            src
        );
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn parts_of_a_box_add_up((pat, fills) in pattern(), axis in 0usize..3, dims in (2.0f64..20.0, 2.0f64..20.0, 2.0f64..20.0)) {
        let axis = ["x", "y", "z"][axis];
        let src = format!(
            "Lot --> s({}, {}, {}) primitiveCube() print(geometry.volume) split({axis}) {pat}\n\
             P --> print(geometry.volume + \" \" + geometry.isClosedSurface)\n",
            dims.0, dims.1, dims.2
        );
        check(&src, &Opts::default(), fills)?;
    }

    #[test]
    fn parts_of_a_concave_prism_add_up((pat, fills) in pattern(), axis in 0usize..3, height in 2.0f64..12.0, points in lot()) {
        let axis = ["x", "y", "z"][axis];
        let src = format!(
            "Lot --> extrude({height}) print(geometry.volume) split({axis}) {pat}\n\
             P --> print(geometry.volume + \" \" + geometry.isClosedSurface)\n"
        );
        check(&src, &Opts::polygon(&points), fills)?;
    }
}
