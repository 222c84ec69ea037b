//! Lot validation and repair, in the local frame's metres.
//!
//! A lot is invalid when its rings cross themselves or each other, a hole
//! lies outside its shell, a ring has fewer than three distinct corners,
//! a ring mixes positions with and without elevation, or the polygon is a
//! sliver: thinner on average (area over half the perimeter) than
//! [`SLIVER_WIDTH`]. The rules are `geo`'s `Validation` (OGC simple
//! features) and the checks around it here; each problem is named with
//! the place where it is.
//!
//! Repair: rings cross or holes stray → the shell's area (even where it
//! crosses itself, each loop counts) minus the holes', by `i_overlay`
//! (through `cga_geometry::footprint`), which may give several polygons;
//! missing elevations → the mean of the polygon's given ones; a hole with
//! fewer than three corners → left out. Slivers and shells with fewer than
//! three corners cannot be repaired: they give no lot.

use cga_geometry::{DVec2, DVec3};
use geo::Validation;

use super::feature::Polygon;

/// Polygons thinner than this on average (2 · area / perimeter, metres)
/// are slivers: a millimetre, finer than any survey of a footprint.
pub const SLIVER_WIDTH: f64 = 1e-3;

/// What to do with invalid lots (`--invalid`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum InvalidPolicy {
    /// Repair them, with a warning (the default).
    #[default]
    Repair,
    /// Leave them out, with a warning.
    Skip,
    /// Stop with an error.
    Error,
}

impl std::str::FromStr for InvalidPolicy {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "repair" => Ok(InvalidPolicy::Repair),
            "skip" => Ok(InvalidPolicy::Skip),
            "error" => Ok(InvalidPolicy::Error),
            _ => Err(format!(
                "expected --invalid repair, skip or error, found `{s}`"
            )),
        }
    }
}

/// One problem of a lot, and where (frame metres: x east, y north).
#[derive(Clone, Debug, PartialEq)]
pub struct Problem {
    pub what: String,
    pub at: Option<DVec2>,
}

/// What checking a polygon found.
pub struct Checked {
    pub problems: Vec<Problem>,
    /// The polygons to use: the input if it is valid, else its repair
    /// (none when it cannot be repaired).
    pub repaired: Vec<Polygon>,
}

/// Checks a polygon (x east, y north in metres, z elevation or NaN) and
/// repairs it if it is invalid.
pub fn check(mut polygon: Polygon) -> Checked {
    let mut problems = Vec::new();
    fill_elevations(&mut polygon, &mut problems);
    // Rings of fewer than three distinct corners.
    for (r, ring) in polygon.iter_mut().enumerate() {
        dedup_ring(ring);
        if ring.len() < 3 {
            problems.push(Problem {
                what: format!("{} has fewer than three distinct corners", ring_name(r)),
                at: ring.first().map(|p| p.truncate()),
            });
        }
    }
    if polygon.first().is_none_or(|shell| shell.len() < 3) {
        return Checked {
            problems,
            repaired: Vec::new(),
        };
    }
    polygon.retain(|ring| ring.len() >= 3);
    let g = to_geo(&polygon);
    let topology = g.validation_errors();
    for e in &topology {
        problems.push(describe(e, &polygon));
    }
    let sliver = |at: Option<DVec2>, width: f64| {
        Problem {
        what: format!(
            "it is a sliver: {width:.2e} m wide on average (2 · area / perimeter), thinner than {SLIVER_WIDTH} m"
        ),
        at,
    }
    };
    let at = polygon[0].first().map(|p| p.truncate());
    if topology.is_empty() {
        let width = mean_width(&polygon);
        if width < SLIVER_WIDTH {
            problems.push(sliver(at, width));
            return Checked {
                problems,
                repaired: Vec::new(),
            };
        }
        return Checked {
            problems,
            repaired: vec![polygon],
        };
    }
    let repaired = repair(&polygon);
    if repaired.is_empty() {
        problems.push(sliver(at, 0.0));
    }
    Checked { problems, repaired }
}

/// 2 · area / perimeter: the width of a long thin polygon.
fn mean_width(polygon: &Polygon) -> f64 {
    let (area, perimeter) = measure(polygon);
    2.0 * area.abs() / perimeter.max(f64::MIN_POSITIVE)
}

fn ring_name(r: usize) -> String {
    if r == 0 {
        "the outer ring".into()
    } else {
        format!("hole {r}")
    }
}

/// Positions without elevation in a polygon that has some get the mean of
/// the given ones; a polygon with none is at elevation 0.
fn fill_elevations(polygon: &mut Polygon, problems: &mut Vec<Problem>) {
    let (mut sum, mut given, mut missing) = (0.0, 0usize, 0usize);
    for p in polygon.iter().flatten() {
        if p.z.is_nan() {
            missing += 1;
        } else {
            sum += p.z;
            given += 1;
        }
    }
    let fill = if given > 0 { sum / given as f64 } else { 0.0 };
    if given > 0 && missing > 0 {
        let at = polygon
            .iter()
            .flatten()
            .find(|p| p.z.is_nan())
            .map(|p| p.truncate());
        problems.push(Problem {
            what: format!(
                "it mixes 2D and 3D positions ({missing} of {} have no elevation; given the mean elevation {fill})",
                given + missing
            ),
            at,
        });
    }
    for p in polygon.iter_mut().flatten() {
        if p.z.is_nan() {
            p.z = fill;
        }
    }
}

/// Drops corners that repeat the one before (GIS rings often do).
fn dedup_ring(ring: &mut Vec<DVec3>) {
    let scale = ring
        .iter()
        .fold(1.0f64, |m, p| m.max(p.x.abs()).max(p.y.abs()));
    let tol = 1e-12 * scale;
    ring.dedup_by(|b, a| a.truncate().distance(b.truncate()) <= tol);
    while ring.len() > 1 && ring[0].truncate().distance(ring[ring.len() - 1].truncate()) <= tol {
        ring.pop();
    }
}

fn to_geo(polygon: &Polygon) -> geo::Polygon<f64> {
    let ring = |r: &Vec<DVec3>| -> geo::LineString<f64> {
        r.iter().map(|p| geo::coord! { x: p.x, y: p.y }).collect()
    };
    geo::Polygon::new(ring(&polygon[0]), polygon[1..].iter().map(ring).collect())
}

/// A validation error with its place.
fn describe(e: &geo::algorithm::validation::InvalidPolygon, polygon: &Polygon) -> Problem {
    use geo::algorithm::validation::{InvalidPolygon as E, RingRole};
    let index = |role: &RingRole| match role {
        RingRole::Exterior => 0,
        RingRole::Interior(i) => i + 1,
    };
    let ring = |role: &RingRole| &polygon[index(role).min(polygon.len() - 1)];
    match e {
        E::SelfIntersection(role) => Problem {
            what: format!("{} crosses itself", ring_name(index(role))),
            at: first_crossing(ring(role), ring(role), true),
        },
        E::InteriorRingNotContainedInExteriorRing(role) => Problem {
            what: format!("{} lies outside the outer ring", ring_name(index(role))),
            at: ring(role).first().map(|p| p.truncate()),
        },
        E::IntersectingRingsOnALine(a, b) | E::IntersectingRingsOnAnArea(a, b) => Problem {
            what: format!(
                "{} and {} overlap",
                ring_name(index(a)),
                ring_name(index(b))
            ),
            at: first_crossing(ring(a), ring(b), false),
        },
        other => Problem {
            what: other.to_string(),
            at: None,
        },
    }
}

/// Where two rings' edges first meet (for one ring, edges that are not
/// neighbours). Quadratic, but only for rings already known to be invalid.
fn first_crossing(a: &[DVec3], b: &[DVec3], same: bool) -> Option<DVec2> {
    use geo::line_intersection::{line_intersection, LineIntersection};
    let edge = |r: &[DVec3], i: usize| {
        let p = r[i];
        let q = r[(i + 1) % r.len()];
        geo::Line::new(
            geo::coord! { x: p.x, y: p.y },
            geo::coord! { x: q.x, y: q.y },
        )
    };
    for i in 0..a.len() {
        let start = if same { i + 2 } else { 0 };
        for j in start..b.len() {
            if same && (j + 1) % b.len() == i {
                continue;
            }
            match line_intersection(edge(a, i), edge(b, j)) {
                Some(LineIntersection::SinglePoint { intersection, .. }) => {
                    return Some(DVec2::new(intersection.x, intersection.y))
                }
                Some(LineIntersection::Collinear { intersection }) => {
                    return Some(DVec2::new(intersection.start.x, intersection.start.y))
                }
                None => {}
            }
        }
    }
    None
}

/// Area (counter-clockwise positive, holes subtracted by their
/// orientation-free size) and perimeter of a polygon.
fn measure(polygon: &Polygon) -> (f64, f64) {
    let mut area = 0.0;
    let mut perimeter = 0.0;
    for (r, ring) in polygon.iter().enumerate() {
        let mut a = 0.0;
        for i in 0..ring.len() {
            let p = ring[i];
            let q = ring[(i + 1) % ring.len()];
            a += p.x * q.y - q.x * p.y;
            perimeter += p.truncate().distance(q.truncate());
        }
        let a = (a / 2.0).abs();
        area += if r == 0 { a } else { -a };
    }
    (area, perimeter)
}

/// The shell's area minus the holes', as valid polygons, each corner's
/// elevation that of the nearest input corner.
fn repair(polygon: &Polygon) -> Vec<Polygon> {
    let to2 = |r: &Vec<DVec3>| r.iter().map(|p| p.truncate()).collect::<Vec<DVec2>>();
    let shell = [to2(&polygon[0])];
    let holes: Vec<Vec<DVec2>> = polygon[1..].iter().map(to2).collect();
    let shapes = if holes.is_empty() {
        cga_geometry::footprint::union(&shell)
    } else {
        cga_geometry::footprint::difference(&shell, &holes)
    };
    let corners: Vec<DVec3> = polygon.iter().flatten().copied().collect();
    let z_at = |p: DVec2| {
        corners
            .iter()
            .min_by(|a, b| {
                a.truncate()
                    .distance_squared(p)
                    .total_cmp(&b.truncate().distance_squared(p))
            })
            .map_or(0.0, |c| c.z)
    };
    shapes
        .into_iter()
        .map(|shape| {
            shape
                .into_iter()
                .map(|ring| ring.into_iter().map(|p| p.extend(z_at(p))).collect())
                .collect::<Polygon>()
        })
        .filter(|p: &Polygon| mean_width(p) >= SLIVER_WIDTH)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ring(points: &[(f64, f64)]) -> Vec<DVec3> {
        points
            .iter()
            .map(|&(x, y)| DVec3::new(x, y, f64::NAN))
            .collect()
    }

    #[test]
    fn a_figure_eight_becomes_two_triangles() {
        // 10 x 10 drawn as a bow tie: (0,0) (10,10) (10,0) (0,10).
        let c = check(vec![ring(&[
            (0.0, 0.0),
            (10.0, 10.0),
            (10.0, 0.0),
            (0.0, 10.0),
        ])]);
        assert_eq!(c.problems.len(), 1, "{:?}", c.problems);
        assert!(c.problems[0].what.contains("crosses itself"));
        assert_eq!(c.problems[0].at, Some(DVec2::new(5.0, 5.0)));
        assert_eq!(c.repaired.len(), 2);
        for p in &c.repaired {
            assert!((measure(p).0 - 25.0).abs() < 1e-9);
        }
    }

    #[test]
    fn a_hole_outside_its_shell_is_left_out() {
        let c = check(vec![
            ring(&[(0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (0.0, 10.0)]),
            ring(&[(20.0, 0.0), (22.0, 0.0), (22.0, 2.0), (20.0, 2.0)]),
        ]);
        assert!(
            c.problems[0].what.contains("hole 1 lies outside"),
            "{:?}",
            c.problems
        );
        assert_eq!(c.problems[0].at, Some(DVec2::new(20.0, 0.0)));
        assert_eq!(c.repaired.len(), 1);
        assert_eq!(c.repaired[0].len(), 1);
        assert!((measure(&c.repaired[0]).0 - 100.0).abs() < 1e-9);
    }

    #[test]
    fn slivers_and_mixed_elevations() {
        let c = check(vec![ring(&[
            (0.0, 0.0),
            (10.0, 0.0),
            (10.0, 0.0001),
            (0.0, 0.0001),
        ])]);
        assert!(c.problems[0].what.contains("sliver"));
        assert!(c.repaired.is_empty());
        let mut r = ring(&[(0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (0.0, 10.0)]);
        r[0].z = 4.0;
        r[1].z = 6.0;
        let c = check(vec![r]);
        assert!(
            c.problems[0].what.contains("mixes 2D and 3D"),
            "{:?}",
            c.problems
        );
        assert_eq!(c.repaired[0][0][2].z, 5.0);
        // Valid lots pass unchanged.
        let c = check(vec![ring(&[(0.0, 0.0), (10.0, 0.0), (10.0, 10.0)])]);
        assert!(c.problems.is_empty());
        assert_eq!(c.repaired[0][0].len(), 3);
    }
}
