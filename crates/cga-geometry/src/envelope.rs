//! Building envelopes (CGA's `envelope`): above every face, walls rising to
//! a base height per edge, then planes sloping inwards at an angle per
//! edge, the whole volume cut horizontally at a maximum height.
//!
//! The volume is the wavefront of a weighted straight skeleton
//! ([`crate::skeleton`]) run in height: time is height above the face, and
//! edge `i` stands still (a vertical wall) until its base height `b_i`, then
//! moves inwards at `1 / tan(angle_i)` (a plane at `angle_i` rising from the
//! top of the wall); an angle of 90 degrees keeps the wall vertical up to
//! the top. The wavefront stopped at the maximum height is the flat top.
//! Because the skeleton handles concave footprints and holes (notches close,
//! wings separate), so does the envelope.
//!
//! # Faces, in order
//!
//! Per input face: the base (the face reversed, starting at its second
//! corner, as `extrude` gives its bottom), then per footprint edge (outer
//! loop from its first edge, then each hole) its vertical part up to its
//! base height and its sloped part above, then the top faces. Parts
//! without area are left out.

use glam::{DVec2, DVec3};

use crate::measure::face_normal;
use crate::mesh::Mesh;
use crate::skeleton::{polygon_area, skeleton, SkeletonError, StopAt, WeightChange};
use crate::triangulate::plane_basis;

/// The role (component tag) of an envelope face.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EnvelopeRole {
    /// `envelope.bottom`: the original face.
    Bottom,
    /// `envelope.side.base`: a vertical wall of an outer edge.
    SideBase,
    /// `envelope.side.slope`: a sloped plane of an outer edge.
    SideSlope,
    /// `envelope.side.inner`: a wall or slope of a hole's edge.
    SideInner,
    /// `envelope.top`: the flat top at the maximum height.
    Top,
}

impl EnvelopeRole {
    pub fn tag(self) -> &'static str {
        match self {
            EnvelopeRole::Bottom => "envelope.bottom",
            EnvelopeRole::SideBase => "envelope.side.base",
            EnvelopeRole::SideSlope => "envelope.side.slope",
            EnvelopeRole::SideInner => "envelope.side.inner",
            EnvelopeRole::Top => "envelope.top",
        }
    }
}

/// The result of [`envelope`].
#[derive(Clone, Debug, Default)]
pub struct Envelope {
    pub mesh: Mesh,
    pub roles: Vec<EnvelopeRole>,
    /// Input faces whose envelope could not be built (missing from `mesh`).
    pub failed: Vec<(usize, SkeletonError)>,
}

/// Smallest slope angle in degrees: flatter planes would move infinitely
/// fast.
const MIN_ANGLE: f64 = 0.01;

/// Builds the envelope of every face of `mesh`. `direction`: the direction
/// the envelope rises in (`None`: each face's normal; `Some(up)`, a unit
/// vector: walls parallel to `up`, heights measured along it from the
/// face). `base[k]` and `angle[k]` (degrees) are given per face edge in
/// face-edge order (every edge of every loop of every face); missing
/// values are 0 and 90 (a vertical wall up to `max_height`).
pub fn envelope(
    mesh: &Mesh,
    direction: Option<DVec3>,
    max_height: f64,
    base: &[f64],
    angle: &[f64],
) -> Envelope {
    let mut out = Envelope {
        mesh: Mesh::new(),
        ..Default::default()
    };
    out.mesh.materials = mesh.materials.clone();
    out.mesh.tags = mesh.tags.clone();
    let mut k = 0usize;
    for f in 0..mesh.faces.len() {
        let first = out.mesh.faces.len();
        let count: usize = mesh.face_loops(f).iter().map(|l| l.len as usize).sum();
        let b = |i: usize| base.get(k + i).copied().unwrap_or(0.0);
        let a = |i: usize| angle.get(k + i).copied().unwrap_or(90.0);
        let bs: Vec<f64> = (0..count).map(b).collect();
        let as_: Vec<f64> = (0..count).map(a).collect();
        if let Err(e) = face_envelope(&mut out, mesh, f, direction, max_height, &bs, &as_) {
            out.failed.push((f, e));
        }
        // Faces built on a face keep its tags (the caller adds the
        // envelope's auto-tags).
        let tags = mesh.faces[f].tags;
        for face in &mut out.mesh.faces[first..] {
            face.tags = tags;
        }
        k += count;
    }
    out
}

fn face_envelope(
    out: &mut Envelope,
    mesh: &Mesh,
    f: usize,
    direction: Option<DVec3>,
    max_height: f64,
    base: &[f64],
    angle: &[f64],
) -> Result<(), SkeletonError> {
    let n = face_normal(mesh, f);
    if n == DVec3::ZERO || !max_height.is_finite() || max_height <= 0.0 {
        return Err(SkeletonError::Empty);
    }
    let up = match direction {
        Some(d) if d.length_squared() > 0.0 => d.normalize(),
        _ => n,
    };
    if up.dot(n).abs() < 1e-9 {
        // A face parallel to the direction has no footprint.
        return Err(SkeletonError::Empty);
    }
    let (u, v) = plane_basis(up);
    let loops_m = mesh.face_loops(f).to_vec();
    let o = mesh.positions[mesh.corners[loops_m[0].start as usize] as usize];
    // A face facing away from the direction is seen clockwise: its loops
    // are reversed for the skeleton (interior on the left), which reverses
    // the edge order within each loop.
    let flip = up.dot(n) < 0.0;
    let mut loops2: Vec<Vec<DVec2>> = Vec::with_capacity(loops_m.len());
    // Per skeleton edge: index into `base`/`angle` and whether it is a hole's.
    let mut edge_src: Vec<(usize, bool)> = Vec::new();
    let mut k = 0usize;
    for (li, &l) in loops_m.iter().enumerate() {
        let mut pts: Vec<DVec2> = mesh
            .loop_points(l)
            .map(|p| DVec2::new((p - o).dot(u), (p - o).dot(v)))
            .collect();
        let m = pts.len();
        if flip {
            pts.reverse();
            // Reversed point j -> j+1 is original edge m - 2 - j.
            for j in 0..m {
                edge_src.push((k + (2 * m - 2 - j) % m, li > 0));
            }
        } else {
            for j in 0..m {
                edge_src.push((k + j, li > 0));
            }
        }
        k += m;
        loops2.push(pts);
    }
    let mut weights: Vec<Vec<f64>> = Vec::with_capacity(loops2.len());
    let mut changes = Vec::new();
    let mut g = 0usize;
    let mut switch_at: Vec<f64> = Vec::with_capacity(edge_src.len());
    for pts in &loops2 {
        let mut wl = Vec::with_capacity(pts.len());
        for _ in 0..pts.len() {
            let (src, _) = edge_src[g];
            let b = base[src];
            let a = angle[src];
            let b = if b.is_finite() {
                b.clamp(0.0, max_height)
            } else {
                0.0
            };
            let a = if a.is_finite() { a } else { 90.0 };
            let w = if a >= 90.0 {
                0.0
            } else {
                1.0 / a.max(MIN_ANGLE).to_radians().tan()
            };
            if b > 0.0 && w > 0.0 {
                wl.push(0.0);
                changes.push(WeightChange {
                    edge: g,
                    time: b,
                    weight: w,
                });
                switch_at.push(b);
            } else {
                wl.push(w);
                switch_at.push(if w > 0.0 { 0.0 } else { max_height });
            }
            g += 1;
        }
        weights.push(wl);
    }
    let sk = skeleton(&loops2, &weights, StopAt::Time(max_height), &changes)?;
    // A skeleton node (2D point, height) lifted: the point of the face
    // above or below the 2D point, then up by the height.
    let dn = up.dot(n);
    let lift = |q: DVec2, t: f64| {
        let p = o + u * q.x + v * q.y;
        p - up * ((p - o).dot(n) / dn) + up * t
    };
    let material = mesh.faces[f].material;

    // The base.
    {
        let mut ids: Vec<Vec<u32>> = Vec::new();
        for &l in &loops_m {
            let pts: Vec<DVec3> = mesh.loop_points(l).collect();
            let m = pts.len() as u32;
            let s = out.mesh.positions.len() as u32;
            out.mesh.positions.extend_from_slice(&pts);
            ids.push((0..m).map(|i| s + (m + 1 - i) % m).collect());
        }
        let refs: Vec<&[u32]> = ids.iter().map(|x| x.as_slice()).collect();
        out.mesh.add_face(&refs, material);
        out.roles.push(EnvelopeRole::Bottom);
    }
    // Sides, in the footprint's edge order.
    let mut order: Vec<usize> = (0..edge_src.len()).collect();
    order.sort_by_key(|&g| edge_src[g].0);
    for g in order {
        let face = &sk.faces[g];
        if face.len() < 3 {
            continue;
        }
        let poly: Vec<(DVec2, f64)> = face
            .iter()
            .map(|&nd| (sk.nodes[nd as usize], sk.times[nd as usize]))
            .collect();
        let hole = edge_src[g].1;
        let cut = switch_at[g];
        let (below, above) = split_at_height(&poly, cut);
        for (part, role) in [
            (below, EnvelopeRole::SideBase),
            (above, EnvelopeRole::SideSlope),
        ] {
            if part.len() < 3 {
                continue;
            }
            let pts: Vec<DVec3> = part.iter().map(|&(q, t)| lift(q, t)).collect();
            if area3(&pts) <= 1e-12 * (1.0 + max_height * max_height) {
                continue;
            }
            let s = out.mesh.positions.len() as u32;
            out.mesh.positions.extend_from_slice(&pts);
            let ids: Vec<u32> = (s..s + pts.len() as u32).collect();
            out.mesh.add_face(&[&ids], material);
            out.roles
                .push(if hole { EnvelopeRole::SideInner } else { role });
        }
    }
    // The top: the wavefront where it stopped, outer loops with their holes.
    let tops: Vec<Vec<DVec2>> = sk
        .wavefront
        .iter()
        .map(|lp| lp.iter().map(|&(nd, _)| sk.nodes[nd as usize]).collect())
        .collect();
    let (outers, holes): (Vec<usize>, Vec<usize>) =
        (0..tops.len()).partition(|&i| polygon_area(&tops[i]) > 0.0);
    for &oi in &outers {
        let mut loops = vec![oi];
        for &h in &holes {
            if contains(&tops[oi], tops[h][0])
                && !outers.iter().any(|&o2| {
                    o2 != oi
                        && polygon_area(&tops[o2]) < polygon_area(&tops[oi])
                        && contains(&tops[o2], tops[h][0])
                })
            {
                loops.push(h);
            }
        }
        let mut ids: Vec<Vec<u32>> = Vec::new();
        for &l in &loops {
            let s = out.mesh.positions.len() as u32;
            out.mesh
                .positions
                .extend(tops[l].iter().map(|&q| lift(q, sk.stop_time)));
            ids.push((s..s + tops[l].len() as u32).collect());
        }
        let refs: Vec<&[u32]> = ids.iter().map(|x| x.as_slice()).collect();
        out.mesh.add_face(&refs, material);
        out.roles.push(EnvelopeRole::Top);
    }
    Ok(())
}

/// Area of a planar 3D polygon.
fn area3(p: &[DVec3]) -> f64 {
    let mut n = DVec3::ZERO;
    for i in 0..p.len() {
        n += p[i].cross(p[(i + 1) % p.len()]);
    }
    0.5 * n.length()
}

/// Splits a polygon of (point, height) corners at height `h` into the part
/// below and the part above (Sutherland-Hodgman against each half-space;
/// the side faces of an envelope are monotone in height, so each part is
/// one polygon).
#[allow(clippy::type_complexity)]
fn split_at_height(poly: &[(DVec2, f64)], h: f64) -> (Vec<(DVec2, f64)>, Vec<(DVec2, f64)>) {
    let eps = 1e-12 * (1.0 + h.abs());
    let clip = |keep_below: bool| -> Vec<(DVec2, f64)> {
        let inside = |t: f64| {
            if keep_below {
                t <= h + eps
            } else {
                t >= h - eps
            }
        };
        let mut out: Vec<(DVec2, f64)> = Vec::with_capacity(poly.len() + 2);
        for i in 0..poly.len() {
            let (p, tp) = poly[i];
            let (q, tq) = poly[(i + 1) % poly.len()];
            let (ip, iq) = (inside(tp), inside(tq));
            if ip {
                out.push((p, tp));
            }
            if ip != iq && (tq - tp).abs() > 0.0 {
                let s = (h - tp) / (tq - tp);
                if s > 0.0 && s < 1.0 {
                    out.push((p + (q - p) * s, h));
                }
            }
        }
        // Drop repeated corners.
        out.dedup_by(|a, b| (a.0 - b.0).length() <= eps && (a.1 - b.1).abs() <= eps);
        while out.len() > 1 {
            let (a, b) = (out[0], out[out.len() - 1]);
            if (a.0 - b.0).length() <= eps && (a.1 - b.1).abs() <= eps {
                out.pop();
            } else {
                break;
            }
        }
        out
    };
    (clip(true), clip(false))
}

/// Point in polygon (even-odd), for assigning top holes to their outer loop.
fn contains(poly: &[DVec2], p: DVec2) -> bool {
    let mut inside = false;
    let n = poly.len();
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x);
            if p.x < x {
                inside = !inside;
            }
        }
    }
    inside
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::{face_area, volume};
    use crate::topology::Topology;

    fn rect(w: f64, d: f64) -> Mesh {
        Mesh::polygon(&[
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(w, 0.0, 0.0),
            DVec3::new(w, 0.0, -d),
            DVec3::new(0.0, 0.0, -d),
        ])
    }

    fn area_of(e: &Envelope, role: EnvelopeRole) -> f64 {
        (0..e.mesh.faces.len())
            .filter(|&f| e.roles[f] == role)
            .map(|f| face_area(&e.mesh, f))
            .sum()
    }

    #[test]
    fn walls_then_slopes_then_a_flat_top() {
        // 8 x 4, walls 0.45 high, 45 degrees, cut at 0.6: the top is inset
        // by 0.15 on every side.
        let m = rect(8.0, 4.0);
        let e = envelope(&m, Some(DVec3::Y), 0.6, &[0.45; 4], &[45.0; 4]);
        assert!(e.failed.is_empty());
        use EnvelopeRole::*;
        assert_eq!(
            e.roles,
            vec![
                Bottom, SideBase, SideSlope, SideBase, SideSlope, SideBase, SideSlope, SideBase,
                SideSlope, Top
            ]
        );
        assert!((area_of(&e, Top) - 7.7 * 3.7).abs() < 1e-9);
        assert!((area_of(&e, SideBase) - 0.45 * 24.0).abs() < 1e-9);
        let s = 0.15 * 2f64.sqrt();
        let slope = s * ((8.0 + 7.7) + (4.0 + 3.7));
        assert!((area_of(&e, SideSlope) - slope).abs() < 1e-9);
        assert!(Topology::new(&e.mesh).is_closed(&e.mesh));
        // The sloped part is a prismatoid: h/6 (bottom + top + 4 middle).
        let v = 32.0 * 0.45 + 0.15 / 6.0 * (32.0 + 7.7 * 3.7 + 4.0 * 7.85 * 3.85);
        assert!((volume(&e.mesh) - v).abs() < 1e-6, "{}", volume(&e.mesh));
    }

    #[test]
    fn vertical_sides_and_collapse_below_the_top() {
        // Front slopes at 45 from 2 m, the others are vertical walls up to
        // 10 m; the front plane meets the back wall at 2 + 4 = 6 m < 10 m.
        let m = rect(10.0, 4.0);
        let e = envelope(&m, None, 10.0, &[2.0], &[45.0]);
        assert!(e.failed.is_empty());
        let top = e.mesh.positions.iter().map(|p| p.y).fold(0.0, f64::max);
        assert!((top - 6.0).abs() < 1e-9);
        assert_eq!(area_of(&e, EnvelopeRole::Top), 0.0);
        assert!((area_of(&e, EnvelopeRole::SideSlope) - 10.0 * 4.0 * 2f64.sqrt()).abs() < 1e-9);
        // A vertical wall with angle 90 has no slope part.
        let vol = 40.0 * 2.0 + 10.0 * 4.0 * 4.0 / 2.0;
        assert!((volume(&e.mesh) - vol).abs() < 1e-6);
        assert!(Topology::new(&e.mesh).is_closed(&e.mesh));
    }

    #[test]
    fn concave_footprints_and_degenerate_input() {
        let l = Mesh::polygon(&[
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(12.0, 0.0, 0.0),
            DVec3::new(12.0, 0.0, -5.0),
            DVec3::new(5.0, 0.0, -5.0),
            DVec3::new(5.0, 0.0, -12.0),
            DVec3::new(0.0, 0.0, -12.0),
        ]);
        let e = envelope(&l, None, 3.0, &[1.0; 6], &[60.0; 6]);
        assert!(e.failed.is_empty());
        assert!(Topology::new(&e.mesh).is_closed(&e.mesh));
        let top = e.mesh.positions.iter().map(|p| p.y).fold(0.0, f64::max);
        assert!((top - 3.0).abs() < 1e-9);
        // Collinear points: a result or a failure, never a panic.
        let line = Mesh::polygon(&[DVec3::ZERO, DVec3::X, DVec3::new(2.0, 0.0, 0.0)]);
        let e = envelope(&line, None, 3.0, &[], &[]);
        assert_eq!(e.failed.len(), 1);
    }
}
