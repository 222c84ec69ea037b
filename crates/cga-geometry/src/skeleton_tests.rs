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
        let s = skeleton(&loops, &w, StopAt::Collapse, &[]).map_err(|e| TestCaseError::fail(format!("{e:?} {loops:?} {w:?}")))?;
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
