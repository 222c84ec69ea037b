use super::*;

fn v(x: f64, y: f64) -> DVec2 {
    DVec2::new(x, y)
}

fn face_area(s: &Skeleton, f: &[u32]) -> f64 {
    let p: Vec<DVec2> = f.iter().map(|&i| s.nodes[i as usize]).collect();
    polygon_area(&p)
}

#[test]
fn rectangle_hip() {
    let r = vec![v(0.0, 0.0), v(10.0, 0.0), v(10.0, 4.0), v(0.0, 4.0)];
    let s = straight_skeleton(&[r]).unwrap();
    assert_eq!(s.faces.len(), 4);
    // Long sides: trapezoids of area (10 + 6) / 2 * 2 = 16; short: triangles 4 * 2 / 2 = 4.
    let areas: Vec<f64> = s.faces.iter().map(|f| face_area(&s, f)).collect();
    for (a, e) in areas.iter().zip([16.0, 4.0, 16.0, 4.0]) {
        assert!((a - e).abs() < 1e-9, "{areas:?}");
    }
    assert_eq!(s.faces[0].len(), 4);
    assert_eq!(s.faces[1].len(), 3);
    assert!((s.stop_time - 2.0).abs() < 1e-12);
}

use proptest::prelude::*;

/// Checks the invariants of a full skeleton: faces start with their edge,
/// lie in their edge's plane, and tile the polygon.
fn check(loops: &[Vec<DVec2>], weights: &[Vec<f64>], s: &Skeleton) -> Result<(), String> {
    let mut total = 0.0;
    let mut sum = 0.0;
    let mut base = 0;
    let size = loops
        .iter()
        .flatten()
        .fold(0.0f64, |m, p| m.max(p.abs().max_element()))
        .max(1.0);
    for (l, pts) in loops.iter().enumerate() {
        total += polygon_area(pts);
        let n = pts.len();
        for i in 0..n {
            let f = &s.faces[base + i];
            let a = pts[i];
            let b = pts[(i + 1) % n];
            if (b - a).length() < 1e-9 * size {
                continue;
            }
            if f.len() < 3 && weights[l][i] > 0.0 {
                return Err(format!("face {} has {} nodes", base + i, f.len()));
            }
            if f[0] as usize != base + i || f[1] as usize != base + (i + 1) % n {
                return Err(format!("face {} does not start with its edge", base + i));
            }
            let d = (b - a).normalize();
            let nn = d.perp();
            let w = weights[l][i];
            for &k in f {
                let p = s.nodes[k as usize];
                let t = s.times[k as usize];
                let off = nn.dot(p - a) - w * t;
                if off.abs() > 1e-7 * size {
                    return Err(format!("face {} not planar: {off}", base + i));
                }
            }
            sum += face_area(s, f);
        }
        base += n;
    }
    for f in &s.step_faces {
        sum += face_area(s, f);
    }
    if (sum - total).abs() > 1e-9 * total.abs().max(1.0) {
        return Err(format!("areas {sum} vs {total}"));
    }
    Ok(())
}

/// Largest angular gap of a set of angles (radians).
fn max_gap(angles: &[f64]) -> f64 {
    let mut a: Vec<f64> = angles.to_vec();
    a.sort_by(f64::total_cmp);
    let mut g = a[0] + std::f64::consts::TAU - a[a.len() - 1];
    for w in a.windows(2) {
        g = g.max(w[1] - w[0]);
    }
    g
}

/// A polygon through points at the given angles around `c`, simple when the
/// largest angular gap is below pi.
fn star(angles: &[f64], radii: &[f64], c: DVec2, scale: f64, ccw: bool) -> Vec<DVec2> {
    let mut a: Vec<f64> = angles.to_vec();
    a.sort_by(f64::total_cmp);
    a.dedup_by(|x, y| (*x - *y).abs() < 1e-3);
    let mut p: Vec<DVec2> = a
        .iter()
        .zip(radii)
        .map(|(t, r)| c + DVec2::new(t.cos(), t.sin()) * r * scale)
        .collect();
    if !ccw {
        p.reverse();
    }
    p
}

/// A rectilinear "histogram" polygon on the integer grid: many collinear
/// edges and simultaneous events.
fn histogram(h: &[u8]) -> Vec<DVec2> {
    let k = h.len();
    let mut p = vec![v(0.0, 0.0), v(k as f64, 0.0)];
    for i in (0..k).rev() {
        let y = h[i] as f64;
        p.push(v((i + 1) as f64, y));
        p.push(v(i as f64, y));
    }
    // Drop repeated points between bars of equal height (keeps collinear ones).
    p.dedup_by(|a, b| a.distance(*b) < 1e-12);
    p
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn star_polygons(angles in prop::collection::vec(0.0..std::f64::consts::TAU, 3..40),
                     radii in prop::collection::vec(0.3f64..1.0, 40)) {
        prop_assume!(max_gap(&angles) < 3.0);
        let p = star(&angles, &radii, DVec2::ZERO, 10.0, true);
        prop_assume!(p.len() >= 3 && polygon_area(&p) > 1e-3);
        let w = vec![vec![1.0; p.len()]];
        let loops = vec![p];
        let s = skeleton(&loops, &w, StopAt::Collapse, &[]).map_err(|e| TestCaseError::fail(format!("{e:?} {loops:?}")))?;
        check(&loops, &w, &s).map_err(|e| TestCaseError::fail(format!("{e} {loops:?}")))?;
    }

    #[test]
    fn star_polygons_weighted(angles in prop::collection::vec(0.0..std::f64::consts::TAU, 3..30),
                     radii in prop::collection::vec(0.3f64..1.0, 30),
                     ws in prop::collection::vec(prop::sample::select(vec![0.0, 0.5, 1.0, 1.0, 2.0]), 30)) {
        prop_assume!(max_gap(&angles) < 3.0);
        let p = star(&angles, &radii, DVec2::ZERO, 10.0, true);
        prop_assume!(p.len() >= 3 && polygon_area(&p) > 1e-3);
        let mut w: Vec<f64> = ws[..p.len()].to_vec();
        if w.iter().all(|&x| x == 0.0) { w[0] = 1.0; }
        let w = vec![w];
        let loops = vec![p];
        let s = skeleton(&loops, &w, StopAt::Collapse, &[]);
        // With zero weights the moving edges may all vanish, leaving a static rest.
        if s == Err(SkeletonError::NoCollapse) && w[0].contains(&0.0) {
            return Ok(());
        }
        let s = s.map_err(|e| TestCaseError::fail(format!("{e:?} {loops:?} {w:?}")))?;
        check(&loops, &w, &s).map_err(|e| TestCaseError::fail(format!("{e} {loops:?} {w:?}")))?;
    }

    #[test]
    fn star_with_hole(n in 7usize..25, jit in prop::collection::vec(0.0f64..0.8, 25),
                      radii in prop::collection::vec(0.6f64..1.0, 25),
                      hangles in prop::collection::vec(0.0..std::f64::consts::TAU, 3..10),
                      hradii in prop::collection::vec(0.1f64..0.35, 10),
                      hx in -0.1f64..0.1, hy in -0.1f64..0.1) {
        let angles: Vec<f64> = (0..n).map(|i| (i as f64 + jit[i]) * std::f64::consts::TAU / n as f64).collect();
        prop_assume!(max_gap(&angles) < std::f64::consts::FRAC_PI_3 && max_gap(&hangles) < 3.0);
        let p = star(&angles, &radii, DVec2::ZERO, 10.0, true);
        let h = star(&hangles, &hradii, v(hx, hy) * 10.0, 10.0, false);
        prop_assume!(p.len() >= 3 && h.len() >= 3 && polygon_area(&p) > 1.0);
        // Keep the hole inside: all hole points closer than every outer point's radius bound.
        let loops = vec![p, h];
        let w: Vec<Vec<f64>> = loops.iter().map(|l| vec![1.0; l.len()]).collect();
        let s = skeleton(&loops, &w, StopAt::Collapse, &[]).map_err(|e| TestCaseError::fail(format!("{e:?} {loops:?}")))?;
        check(&loops, &w, &s).map_err(|e| TestCaseError::fail(format!("{e} {loops:?}")))?;
    }

    #[test]
    fn rectilinear(h in prop::collection::vec(1u8..6, 1..12)) {
        let p = histogram(&h);
        let loops = vec![p];
        let w: Vec<Vec<f64>> = loops.iter().map(|l| vec![1.0; l.len()]).collect();
        let s = skeleton(&loops, &w, StopAt::Collapse, &[]).map_err(|e| TestCaseError::fail(format!("{e:?} {loops:?}")))?;
        check(&loops, &w, &s).map_err(|e| TestCaseError::fail(format!("{e} {loops:?}")))?;
    }
}

#[test]
fn random_polygons_succeed_on_first_attempt() {
    use proptest::strategy::ValueTree;
    use proptest::test_runner::TestRunner;
    let mut runner = TestRunner::deterministic();
    let strat = (
        prop::collection::vec(0.0..std::f64::consts::TAU, 3..60),
        prop::collection::vec(0.3f64..1.0, 60),
        prop::collection::vec(1u8..6, 1..30),
    );
    let (mut fails, mut total, mut hfails) = (0, 0, 0);
    for _ in 0..2000 {
        let (angles, radii, h) = strat.new_tree(&mut runner).unwrap().current();
        if max_gap(&angles) < 3.0 {
            let p = star(&angles, &radii, DVec2::ZERO, 10.0, true);
            if p.len() >= 3 {
                let w = vec![vec![1.0; p.len()]];
                total += 1;
                if run(&[p], &w, StopAt::Collapse, &[], 0.0).is_err() {
                    fails += 1;
                }
            }
        }
        let p = histogram(&h);
        let w = vec![vec![1.0; p.len()]];
        if run(std::slice::from_ref(&p), &w, StopAt::Collapse, &[], 0.0).is_err() {
            hfails += 1;
        }
    }
    // The perturbed retry is a safety net, not the rule.
    assert!(total > 1000);
    assert_eq!((fails, hfails), (0, 0));
}

/// Timing of a 200-vertex concave footprint: run with
/// `cargo test --release -p cga-geometry skeleton_timing -- --ignored --nocapture`.
#[test]
#[ignore]
fn skeleton_timing() {
    let n = 200;
    let p: Vec<DVec2> = (0..n)
        .map(|i| {
            let a = i as f64 * std::f64::consts::TAU / n as f64;
            let r = if i % 2 == 0 {
                10.0
            } else {
                7.0 + (i % 7) as f64 * 0.3
            };
            DVec2::new(a.cos(), a.sin()) * r
        })
        .collect();
    let w = vec![vec![1.0; n]];
    let loops = vec![p];
    let iters = 200;
    let t0 = std::time::Instant::now();
    for _ in 0..iters {
        let s = skeleton(&loops, &w, StopAt::Collapse, &[]).unwrap();
        assert_eq!(s.faces.len(), n);
    }
    let dt = t0.elapsed().as_secs_f64() / iters as f64;
    eprintln!("200-vertex skeleton: {:.1} us", dt * 1e6);
    let h = histogram(&[
        3, 1, 4, 1, 5, 2, 6, 2, 5, 3, 5, 1, 4, 2, 3, 1, 4, 1, 5, 2, 6, 2, 5, 3, 5, 1, 4, 2, 3, 1,
        4, 1, 5, 2, 6, 2, 5, 3, 5, 1, 4, 2, 3, 1, 4, 1, 5, 2, 6, 2,
    ]);
    let w = vec![vec![1.0; h.len()]];
    let m = h.len();
    let loops = vec![h];
    let t0 = std::time::Instant::now();
    for _ in 0..iters {
        skeleton(&loops, &w, StopAt::Collapse, &[]).unwrap();
    }
    let dt = t0.elapsed().as_secs_f64() / iters as f64;
    eprintln!("{m}-vertex rectilinear skeleton: {:.1} us", dt * 1e6);
}

/// Symmetric stars: several reflex vertices meet at the centre at once
/// (vertex events), on the first attempt, without the perturbed retry.
#[test]
fn symmetric_stars_vertex_events() {
    for n in (8usize..90).step_by(2) {
        let p: Vec<DVec2> = (0..n)
            .map(|i| {
                let a = i as f64 * std::f64::consts::TAU / n as f64;
                let r = if i % 2 == 0 {
                    10.0
                } else {
                    7.0 + (i % 7) as f64 * 0.3
                };
                DVec2::new(a.cos(), a.sin()) * r
            })
            .collect();
        let w = vec![vec![1.0; n]];
        let loops = vec![p];
        let s =
            run(&loops, &w, StopAt::Collapse, &[], 0.0).unwrap_or_else(|e| panic!("n={n}: {e:?}"));
        check(&loops, &w, &s).unwrap_or_else(|e| panic!("n={n}: {e}"));
    }
    // A regular star: all reflex vertices meet at the centre together.
    for n in [3usize, 4, 5, 8] {
        let p: Vec<DVec2> = (0..2 * n)
            .map(|i| {
                let a = i as f64 * std::f64::consts::PI / n as f64;
                DVec2::new(a.cos(), a.sin()) * if i % 2 == 0 { 10.0 } else { 4.0 }
            })
            .collect();
        let w = vec![vec![1.0; 2 * n]];
        let loops = vec![p];
        let s = skeleton(&loops, &w, StopAt::Collapse, &[]).unwrap();
        check(&loops, &w, &s).unwrap();
    }
}

#[test]
fn one_moving_edge_sweeps_the_square() {
    let sq = vec![v(0.0, 0.0), v(4.0, 0.0), v(4.0, 4.0), v(0.0, 4.0)];
    let w = vec![vec![2.0, 0.0, 0.0, 0.0]];
    let loops = vec![sq];
    let s = skeleton(&loops, &w, StopAt::Collapse, &[]).unwrap();
    check(&loops, &w, &s).unwrap();
    assert!((face_area(&s, &s.faces[0]) - 16.0).abs() < 1e-9);
    assert!((s.stop_time - 2.0).abs() < 1e-12);
    // Stopped half way it is a setback of depth 2 along the front.
    let s = skeleton(&loops, &w, StopAt::Time(0.5), &[]).unwrap();
    assert!((face_area(&s, &s.faces[0]) - 4.0).abs() < 1e-9);
    assert_eq!(s.wavefront.len(), 1);
    assert_eq!(s.wavefront[0].len(), 4);
}

#[test]
fn static_remainder_does_not_collapse() {
    // A spike that is the only moving part vanishes; the rest never moves.
    let p = vec![
        v(0.0, 0.0),
        v(4.0, 0.0),
        v(4.0, 4.0),
        v(2.0, 4.0),
        v(2.0, 8.0),
        v(1.0, 8.0),
        v(1.0, 4.0),
        v(0.0, 4.0),
    ];
    let w = vec![vec![0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0]];
    assert_eq!(
        skeleton(&[p], &w, StopAt::Collapse, &[]),
        Err(SkeletonError::NoCollapse)
    );
}
