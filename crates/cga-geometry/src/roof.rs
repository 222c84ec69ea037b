//! Roofs on footprint faces: CGA's `roofHip`, `roofGable`, `roofPyramid`,
//! `roofShed` and `roofRidge`.
//!
//! Each face of the input is a footprint in its own plane; "up" is its
//! normal. The roof of a face is built in a 2D frame of that plane and
//! lifted back. Hip and gable roofs come from the weighted straight skeleton
//! ([`crate::skeleton`]): every footprint edge moves inwards with weight 1
//! (its roof plane rises at the roof angle) or 0 (a gable end: a vertical
//! pediment), and a node reached at time `t` gets the height `t · tan(angle)`
//! (or, `byHeight`, heights scaled so that the highest node is at the given
//! height).
//!
//! # Faces, in order
//!
//! For every input face, in order:
//!
//! | roof | faces |
//! | --- | --- |
//! | hip, gable, pyramid | the base, then one face per footprint edge (outer loop from its first edge, then each hole), then the vertical step faces the skeleton may add |
//! | shed, ridge | the base, the top face(s), then one vertical side face per footprint edge that has a height |
//!
//! The base is the original face reversed (its normal points down, out of
//! the roof solid) starting at its second corner, as `extrude` gives its
//! bottom. On a rectangle `roofGable` thus gives `0`: base, `1`, `3`: the
//! pediments of edges 0 and 2, `2`, `4`: the roof planes (when edge 0 is the
//! short side, the ridge runs along the long one). The face of a footprint
//! edge starts with that edge (`a b ...`, counter-clockwise seen from above),
//! so its first edge is the eave. Without overhang, base and roof faces are
//! closed together (watertight) and the roof faces project exactly onto the
//! footprint; with overhang the roof faces are extended outwards and down
//! along their planes (a negative overhang pulls them in and up, as
//! CityEngine does) and the base stays where it was (a lid above the base,
//! as CityEngine draws it). Edges of length zero get no face.
//!
//! Roof edges are classified for `comp(e)`'s `eave`, `hip`, `valley` and
//! `ridge` selectors in [`Roof::edge_kinds`], aligned with
//! [`Topology::new`]`(&roof.mesh).edges`.

use glam::{DVec2, DVec3};

use crate::measure::face_normal;
use crate::mesh::Mesh;
use crate::skeleton::{skeleton, Skeleton, SkeletonError, StopAt};
use crate::topology::{mesh_tolerance, Topology};
use crate::triangulate::plane_basis;

/// How steep the roof is (`byAngle` / `byHeight`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RoofSlope {
    /// Angle of the roof planes against the footprint, in degrees.
    Angle(f64),
    /// Height of the highest roof point above the footprint.
    Height(f64),
}

/// Which roof, with its options.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RoofKind {
    /// `roofHip(angle, overhang, even)`.
    Hip { overhang: f64, even: bool },
    /// `roofGable(angle, overhangX, overhangY, even, index)`: gable ends are
    /// chosen automatically (the edges whose hip roof face is a triangle,
    /// no two adjacent, first in edge order) unless `index` is given, in
    /// which case edges within 45 degrees of the direction of edge `index`
    /// (of the outer loop) are eaves and all others gable ends.
    Gable {
        overhang_x: f64,
        overhang_y: f64,
        even: bool,
        index: Option<usize>,
    },
    /// `roofPyramid`: the average of the outer loop's points raised, joined
    /// to every outer edge. `byAngle` measures the angle on the face of edge
    /// 0.
    Pyramid,
    /// `roofShed(angle, index)`: one plane rising from edge `index` of the
    /// outer loop (modulo its length).
    Shed { index: usize },
    /// `roofRidge`: two planes meeting in one ridge parallel to `ridge`
    /// (a direction in the mesh's frame, e.g. the scope's x axis; it is
    /// projected onto each face's plane), rising from the footprint's
    /// extreme lines on either side.
    Ridge { ridge: DVec3 },
}

/// The component tag of a roof face (`roof.bottom`, `roof.top`, ...).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RoofFaceRole {
    /// `roof.bottom`: the original face.
    Bottom,
    /// `roof.top`: a sloped roof face.
    Top,
    /// `roof.side`: a gable pediment.
    Side,
    /// `roof.side.outer`: a side wall of a shed or ridge roof on an outer edge.
    SideOuter,
    /// `roof.side.inner`: a side wall on an edge of a hole.
    SideInner,
}

impl RoofFaceRole {
    pub fn tag(self) -> &'static str {
        match self {
            RoofFaceRole::Bottom => "roof.bottom",
            RoofFaceRole::Top => "roof.top",
            RoofFaceRole::Side => "roof.side",
            RoofFaceRole::SideOuter => "roof.side.outer",
            RoofFaceRole::SideInner => "roof.side.inner",
        }
    }
}

/// The class of a roof edge for `comp(e)`'s roof selectors.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RoofEdgeKind {
    /// Lowest horizontal border of the roof faces (`eave`).
    Eave,
    /// Between two roof faces, touching an eave, convex (`hip`).
    Hip,
    /// Between two roof faces forming a concavity (`valley`).
    Valley,
    /// Between two roof faces, neither hip nor valley (`ridge`).
    Ridge,
    /// Any other edge: the base's, walls', rakes along pediments.
    Other,
}

/// A footprint edge: input face, loop of that face (0 = outer), edge in the loop.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SourceEdge {
    pub face: u32,
    pub loop_index: u32,
    pub edge: u32,
}

/// The result of [`roof`].
#[derive(Clone, Debug)]
pub struct Roof {
    pub mesh: Mesh,
    /// Role (component tag) of every face.
    pub roles: Vec<RoofFaceRole>,
    /// The footprint edge each face was built on (`None` for bases, tops of
    /// shed and ridge roofs, and skeleton step faces).
    pub source_edge: Vec<Option<SourceEdge>>,
    /// Class of every edge of `Topology::new(&mesh)`, in its order.
    pub edge_kinds: Vec<RoofEdgeKind>,
    /// Position indices of every edge in the direction CGA gives the edge
    /// component: eaves counter-clockwise around the footprint, hips,
    /// valleys and ridges upwards, other edges as the topology has them.
    pub edge_ends: Vec<[u32; 2]>,
    /// Input faces whose roof could not be built (they keep only their base).
    pub failed: Vec<(usize, SkeletonError)>,
}

/// Builds the roof of every face of `mesh` (see the module docs).
pub fn roof(mesh: &Mesh, slope: RoofSlope, kind: RoofKind) -> Roof {
    let mut b = Builder {
        out: Mesh::new(),
        roles: Vec::new(),
        source: Vec::new(),
        up: Vec::new(),
        failed: Vec::new(),
    };
    b.out.materials = mesh.materials.clone();
    b.out.tags = mesh.tags.clone();
    for f in 0..mesh.faces.len() {
        let first = b.out.faces.len();
        if let Err(e) = b.face(mesh, f, slope, kind) {
            b.failed.push((f, e));
        }
        // Faces built on a face keep its tags (the caller adds the roof's
        // auto-tags); edge and vertex tags are not carried into roofs.
        let tags = mesh.faces[f].tags;
        for face in &mut b.out.faces[first..] {
            face.tags = tags;
        }
    }
    let (edge_kinds, edge_ends) = classify_edges(&b.out, &b.roles, &b.up);
    Roof {
        mesh: b.out,
        roles: b.roles,
        source_edge: b.source,
        edge_kinds,
        edge_ends,
        failed: b.failed,
    }
}

struct Builder {
    out: Mesh,
    roles: Vec<RoofFaceRole>,
    source: Vec<Option<SourceEdge>>,
    /// Up direction and base plane offset of each output face's footprint.
    up: Vec<(DVec3, f64)>,
    failed: Vec<(usize, SkeletonError)>,
}

fn tan_of(angle_deg: f64) -> f64 {
    let a = angle_deg.clamp(0.0, 89.9);
    a.to_radians().tan()
}

/// Per-edge outward offset of closed loops (mitred): edge `i` of loop `l`
/// moves out by `d[l][i]`.
/// Twice the signed area of a loop (positive counter-clockwise).
fn loop_area(pts: &[DVec2]) -> f64 {
    let n = pts.len();
    (0..n).map(|i| pts[i].perp_dot(pts[(i + 1) % n])).sum()
}

fn offset_out(loops: &[Vec<DVec2>], d: &[Vec<f64>]) -> Vec<Vec<DVec2>> {
    loops
        .iter()
        .zip(d)
        .map(|(pts, dl)| {
            let n = pts.len();
            (0..n)
                .map(|i| {
                    let ip = (i + n - 1) % n;
                    let (a0, a1) = (pts[ip], pts[i]);
                    let (b0, b1) = (pts[i], pts[(i + 1) % n]);
                    let da = (a1 - a0).normalize_or_zero();
                    let db = (b1 - b0).normalize_or_zero();
                    // Outward normals (right of the direction).
                    let na = -da.perp();
                    let nb = -db.perp();
                    let (oa, ob) = (dl[ip], dl[i]);
                    let cr = da.perp_dot(db);
                    if cr.abs() < 1e-9 || da == DVec2::ZERO || db == DVec2::ZERO {
                        return pts[i]
                            + (na * oa + nb * ob) * 0.5
                            + if da == DVec2::ZERO {
                                nb * ob * 0.5
                            } else {
                                DVec2::ZERO
                            }
                            + if db == DVec2::ZERO {
                                na * oa * 0.5
                            } else {
                                DVec2::ZERO
                            };
                    }
                    // Intersection of the two offset lines.
                    let pa = a1 + na * oa;
                    let pb = b0 + nb * ob;
                    let s = (pb - pa).perp_dot(db) / cr;
                    pa + da * s
                })
                .collect()
        })
        .collect()
}

impl Builder {
    fn face(
        &mut self,
        mesh: &Mesh,
        f: usize,
        slope: RoofSlope,
        kind: RoofKind,
    ) -> Result<(), SkeletonError> {
        let n = face_normal(mesh, f);
        if n == DVec3::ZERO {
            return Err(SkeletonError::Empty);
        }
        let (u, v) = plane_basis(n);
        let loops_m = mesh.face_loops(f).to_vec();
        let o = mesh.positions[mesh.corners[loops_m[0].start as usize] as usize];
        let to2 = |p: DVec3| DVec2::new((p - o).dot(u), (p - o).dot(v));
        let loops3: Vec<Vec<DVec3>> = loops_m
            .iter()
            .map(|&l| mesh.loop_points(l).collect())
            .collect();
        let loops2: Vec<Vec<DVec2>> = loops3
            .iter()
            .map(|l| l.iter().map(|&p| to2(p)).collect())
            .collect();
        let lift = |p: DVec2, h: f64| o + u * p.x + v * p.y + n * h;
        let plane = n.dot(o);

        // The base: every loop reversed, starting at its second corner.
        let base0 = self.out.positions.len() as u32;
        for l in &loops3 {
            self.out.positions.extend_from_slice(l);
        }
        let mut loop_base = Vec::with_capacity(loops3.len());
        let mut acc = base0;
        for l in &loops3 {
            loop_base.push(acc);
            acc += l.len() as u32;
        }
        {
            let rev: Vec<Vec<u32>> = loops3
                .iter()
                .zip(&loop_base)
                .map(|(l, &b)| {
                    let k = l.len() as u32;
                    (0..k).map(|i| b + (k + 1 - i) % k).collect()
                })
                .collect();
            let refs: Vec<&[u32]> = rev.iter().map(|x| x.as_slice()).collect();
            self.push_face(
                &refs,
                mesh.faces[f].material,
                RoofFaceRole::Bottom,
                None,
                (n, plane),
            );
        }
        let material = mesh.faces[f].material;
        let src = |l: usize, i: usize| {
            Some(SourceEdge {
                face: f as u32,
                loop_index: l as u32,
                edge: i as u32,
            })
        };

        match kind {
            RoofKind::Hip { overhang, even } => {
                let w: Vec<Vec<f64>> = loops2.iter().map(|l| vec![1.0; l.len()]).collect();
                self.skeleton_roof(
                    &loops2,
                    &w,
                    slope,
                    overhang,
                    overhang,
                    even,
                    &loop_base,
                    material,
                    f,
                    &lift,
                    (n, plane),
                )
            }
            RoofKind::Gable {
                overhang_x,
                overhang_y,
                even,
                index,
            } => {
                let w = gable_weights(&loops2, index)?;
                let even = even && index.is_none();
                self.skeleton_roof(
                    &loops2,
                    &w,
                    slope,
                    overhang_x,
                    overhang_y,
                    even,
                    &loop_base,
                    material,
                    f,
                    &lift,
                    (n, plane),
                )
            }
            RoofKind::Pyramid => {
                let outer = &loops2[0];
                let c = outer.iter().copied().sum::<DVec2>() / outer.len() as f64;
                let h = match slope {
                    RoofSlope::Angle(a) => {
                        let (p0, p1) = (outer[0], outer[1 % outer.len()]);
                        let d = (p1 - p0).normalize_or_zero();
                        d.perp().dot(c - p0).abs() * tan_of(a)
                    }
                    RoofSlope::Height(h) => h,
                };
                let apex = self.out.positions.len() as u32;
                self.out.positions.push(lift(c, h));
                let k = outer.len() as u32;
                for i in 0..k {
                    let (a, b) = (loop_base[0] + i, loop_base[0] + (i + 1) % k);
                    if outer[i as usize].distance(outer[((i + 1) % k) as usize]) <= 0.0 {
                        continue;
                    }
                    self.push_face(
                        &[&[a, b, apex]],
                        material,
                        RoofFaceRole::Top,
                        src(0, i as usize),
                        (n, plane),
                    );
                }
                Ok(())
            }
            RoofKind::Shed { index } => {
                let outer = &loops2[0];
                let i = index % outer.len();
                let (p0, p1) = (outer[i], outer[(i + 1) % outer.len()]);
                let d = (p1 - p0).normalize_or_zero();
                if d == DVec2::ZERO {
                    return Err(SkeletonError::Empty);
                }
                let dist = |p: DVec2| d.perp().dot(p - p0);
                let k = match slope {
                    RoofSlope::Angle(a) => tan_of(a),
                    RoofSlope::Height(h) => {
                        let m = loops2
                            .iter()
                            .flatten()
                            .map(|&p| dist(p))
                            .fold(0.0, f64::max);
                        if m > 0.0 {
                            h / m
                        } else {
                            0.0
                        }
                    }
                };
                let heights: Vec<Vec<f64>> = loops2
                    .iter()
                    .map(|l| l.iter().map(|&p| dist(p) * k).collect())
                    .collect();
                self.walled_roof(
                    &loops2,
                    &heights,
                    None,
                    &loop_base,
                    material,
                    f,
                    &lift,
                    (n, plane),
                );
                Ok(())
            }
            RoofKind::Ridge { ridge } => {
                let r2 = DVec2::new(ridge.dot(u), ridge.dot(v)).normalize_or(DVec2::X);
                let m = r2.perp();
                let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
                for p in loops2.iter().flatten() {
                    lo = lo.min(m.dot(*p));
                    hi = hi.max(m.dot(*p));
                }
                let mid = 0.5 * (lo + hi);
                let k = match slope {
                    RoofSlope::Angle(a) => tan_of(a),
                    RoofSlope::Height(h) => {
                        if hi > lo {
                            h / (0.5 * (hi - lo))
                        } else {
                            0.0
                        }
                    }
                };
                let hf = |p: DVec2| (m.dot(p) - lo).min(hi - m.dot(p)).max(0.0) * k;
                let heights: Vec<Vec<f64>> = loops2
                    .iter()
                    .map(|l| l.iter().map(|&p| hf(p)).collect())
                    .collect();
                self.walled_roof(
                    &loops2,
                    &heights,
                    Some((m, mid, hf(m * mid))),
                    &loop_base,
                    material,
                    f,
                    &lift,
                    (n, plane),
                );
                Ok(())
            }
        }
    }

    fn push_face(
        &mut self,
        loops: &[&[u32]],
        material: u32,
        role: RoofFaceRole,
        src: Option<SourceEdge>,
        up: (DVec3, f64),
    ) {
        self.out.add_face(loops, material);
        self.roles.push(role);
        self.source.push(src);
        self.up.push(up);
    }

    #[allow(clippy::too_many_arguments)]
    fn skeleton_roof(
        &mut self,
        loops2: &[Vec<DVec2>],
        w: &[Vec<f64>],
        slope: RoofSlope,
        over_x: f64,
        over_y: f64,
        even: bool,
        loop_base: &[u32],
        material: u32,
        f: usize,
        lift: &dyn Fn(DVec2, f64) -> DVec3,
        up: (DVec3, f64),
    ) -> Result<(), SkeletonError> {
        // Overhangs are not clamped at zero: CityEngine pulls the eaves or
        // the gable ends in by a negative overhang (measured with its
        // runtime: `roofGable(30, 0, -2)` on a 20 x 30 lot has roof planes
        // from z = -28 to -2).
        let finite = |o: f64| if o.is_finite() { o } else { 0.0 };
        let (over_x, over_y) = (finite(over_x), finite(over_y));
        let base_sk = skeleton(loops2, w, StopAt::Collapse, &[])?;
        let k = match slope {
            RoofSlope::Angle(a) => tan_of(a),
            RoofSlope::Height(h) => {
                if base_sk.stop_time > 0.0 {
                    h / base_sk.stop_time
                } else {
                    0.0
                }
            }
        };
        let angle = k.atan();
        let overhang = over_x != 0.0 || over_y != 0.0;
        let (sk, drop, shared) = if overhang {
            let d: Vec<Vec<f64>> = w
                .iter()
                .map(|wl| {
                    wl.iter()
                        .map(|&x| {
                            if x > 0.0 {
                                over_x * angle.cos()
                            } else {
                                over_y
                            }
                        })
                        .collect()
                })
                .collect();
            let ext = offset_out(loops2, &d);
            // An overhang pulling the outline in past itself leaves no roof.
            if ext
                .iter()
                .zip(loops2)
                .any(|(e, l)| loop_area(e) * loop_area(l) <= 0.0)
            {
                return Err(SkeletonError::Empty);
            }
            (
                skeleton(&ext, w, StopAt::Collapse, &[])?,
                over_x * angle.sin(),
                false,
            )
        } else {
            (base_sk, 0.0, true)
        };
        let heights = node_heights(&sk, k, even);
        let mut pos_of = vec![u32::MAX; sk.nodes.len()];
        if shared {
            let mut g = 0;
            for (l, pts) in loops2.iter().enumerate() {
                for i in 0..pts.len() {
                    pos_of[g] = loop_base[l] + i as u32;
                    g += 1;
                }
            }
        }
        let mut idx = |node: u32, out: &mut Mesh| -> u32 {
            let i = node as usize;
            if pos_of[i] == u32::MAX {
                pos_of[i] = out.positions.len() as u32;
                out.positions.push(lift(sk.nodes[i], heights[i] - drop));
            }
            pos_of[i]
        };
        let mut g = 0;
        for (l, wl) in w.iter().enumerate() {
            for (i, &wi) in wl.iter().enumerate() {
                let face = &sk.faces[g];
                g += 1;
                if face.len() < 3 {
                    continue;
                }
                let ids: Vec<u32> = face.iter().map(|&nd| idx(nd, &mut self.out)).collect();
                let role = if wi > 0.0 {
                    RoofFaceRole::Top
                } else {
                    RoofFaceRole::Side
                };
                let src = Some(SourceEdge {
                    face: f as u32,
                    loop_index: l as u32,
                    edge: i as u32,
                });
                self.push_face(&[&ids], material, role, src, up);
            }
        }
        for face in &sk.step_faces {
            let ids: Vec<u32> = face.iter().map(|&nd| idx(nd, &mut self.out)).collect();
            self.push_face(&[&ids], material, RoofFaceRole::Top, None, up);
        }
        Ok(())
    }

    /// Shed and ridge roofs: the footprint lifted to per-point heights (a
    /// ridge line `(m, mid, height)` splits it in two planes), then walls.
    #[allow(clippy::too_many_arguments)]
    fn walled_roof(
        &mut self,
        loops2: &[Vec<DVec2>],
        heights: &[Vec<f64>],
        ridge: Option<(DVec2, f64, f64)>,
        loop_base: &[u32],
        material: u32,
        f: usize,
        lift: &dyn Fn(DVec2, f64) -> DVec3,
        up: (DVec3, f64),
    ) {
        let tol = 1e-9
            * loops2
                .iter()
                .flatten()
                .fold(1.0f64, |m, p| m.max(p.abs().max_element()));
        // Top positions of the loop points, with the ridge crossings of each
        // edge inserted.
        let mut top_loops: Vec<Vec<u32>> = Vec::new();
        let mut crossing: Vec<Vec<Option<u32>>> = Vec::new();
        let mut top_of: Vec<Vec<u32>> = Vec::new();
        for (l, pts) in loops2.iter().enumerate() {
            let mut tl = Vec::new();
            let mut cr = Vec::new();
            let mut to = Vec::new();
            let k = pts.len();
            for i in 0..k {
                let id = self.out.positions.len() as u32;
                self.out.positions.push(lift(pts[i], heights[l][i]));
                to.push(id);
            }
            for i in 0..k {
                tl.push(to[i]);
                let (a, b) = (pts[i], pts[(i + 1) % k]);
                let mut c = None;
                if let Some((m, mid, h)) = ridge {
                    let (sa, sb) = (m.dot(a) - mid, m.dot(b) - mid);
                    if (sa < -tol && sb > tol) || (sa > tol && sb < -tol) {
                        let t = sa / (sa - sb);
                        let id = self.out.positions.len() as u32;
                        self.out.positions.push(lift(a + (b - a) * t, h));
                        tl.push(id);
                        c = Some(id);
                    }
                }
                cr.push(c);
            }
            top_loops.push(tl);
            crossing.push(cr);
            top_of.push(to);
        }
        // Top faces: one for a shed; for a ridge roof the two sides of the
        // ridge line, each a polygon with holes cut from the lifted loops.
        let mut top = Mesh::new();
        top.positions = self.out.positions.clone();
        let refs: Vec<&[u32]> = top_loops.iter().map(|x| x.as_slice()).collect();
        top.add_face(&refs, material);
        let pieces: Vec<Mesh> = match ridge {
            None => vec![top],
            Some((m, mid, h)) => {
                // Cut the lifted top along the vertical plane through the
                // ridge line; both parts share the crossing points.
                let p0 = lift(m * mid, h);
                let nrm3 = lift(m, 0.0) - lift(DVec2::ZERO, 0.0);
                let (a, b) = crate::cut::cut_by_plane(&top, nrm3, nrm3.dot(p0));
                vec![a, b]
            }
        };
        for piece in pieces {
            // Re-index the piece's positions into the output (cut pieces
            // have their own position lists).
            let tolw = mesh_tolerance(&piece);
            for pf in 0..piece.faces.len() {
                let mut loops: Vec<Vec<u32>> = Vec::new();
                for &l in piece.face_loops(pf) {
                    let ids: Vec<u32> = piece
                        .loop_points(l)
                        .map(|p| find_or_add(&mut self.out.positions, p, tolw))
                        .collect();
                    loops.push(ids);
                }
                let refs: Vec<&[u32]> = loops.iter().map(|x| x.as_slice()).collect();
                self.push_face(&refs, material, RoofFaceRole::Top, None, up);
            }
        }
        // Walls.
        for (l, pts) in loops2.iter().enumerate() {
            let k = pts.len();
            let role = if l == 0 {
                RoofFaceRole::SideOuter
            } else {
                RoofFaceRole::SideInner
            };
            for i in 0..k {
                let j = (i + 1) % k;
                let (ha, hb) = (heights[l][i], heights[l][j]);
                let hc = crossing[l][i]
                    .map(|_| ridge.map_or(0.0, |r| r.2))
                    .unwrap_or(0.0);
                if ha.abs() <= tol && hb.abs() <= tol && hc <= tol {
                    continue;
                }
                if pts[i].distance(pts[j]) <= tol {
                    continue;
                }
                let (a, b) = (loop_base[l] + i as u32, loop_base[l] + j as u32);
                let mut ids = vec![a, b];
                if hb.abs() > tol {
                    ids.push(top_of[l][j]);
                }
                if let Some(c) = crossing[l][i] {
                    ids.push(c);
                }
                if ha.abs() > tol {
                    ids.push(top_of[l][i]);
                }
                let src = Some(SourceEdge {
                    face: f as u32,
                    loop_index: l as u32,
                    edge: i as u32,
                });
                self.push_face(&[&ids], material, role, src, up);
            }
        }
    }
}

/// Index of a position equal (within `tol`) to `p` among the last positions
/// added, or a new one. Linear in the search window, used for the few cut
/// pieces of a ridge roof.
fn find_or_add(positions: &mut Vec<DVec3>, p: DVec3, tol: f64) -> u32 {
    if let Some(i) = positions
        .iter()
        .rposition(|q| (*q - p).abs().max_element() <= tol)
    {
        return i as u32;
    }
    positions.push(p);
    (positions.len() - 1) as u32
}

/// Node heights `t · k`; with `even`, every group of interior nodes joined
/// by interior skeleton edges (a ridge network) is set to its mean height.
fn node_heights(sk: &Skeleton, k: f64, even: bool) -> Vec<f64> {
    let mut h: Vec<f64> = sk.times.iter().map(|t| t * k).collect();
    if !even {
        return h;
    }
    let n = h.len();
    let mut parent: Vec<u32> = (0..n as u32).collect();
    fn find(p: &mut [u32], mut x: u32) -> u32 {
        while p[x as usize] != x {
            p[x as usize] = p[p[x as usize] as usize];
            x = p[x as usize];
        }
        x
    }
    let interior = |i: u32| sk.times[i as usize] > 0.0;
    for face in &sk.faces {
        for j in 0..face.len() {
            let (a, b) = (face[j], face[(j + 1) % face.len()]);
            if interior(a) && interior(b) {
                let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
                parent[ra as usize] = rb;
            }
        }
    }
    let mut sum = vec![0.0; n];
    let mut cnt = vec![0u32; n];
    let mut used = vec![false; n];
    for face in &sk.faces {
        for &a in face {
            used[a as usize] = true;
        }
    }
    for i in 0..n as u32 {
        if used[i as usize] && interior(i) {
            let r = find(&mut parent, i) as usize;
            sum[r] += h[i as usize];
            cnt[r] += 1;
        }
    }
    for i in 0..n as u32 {
        if used[i as usize] && interior(i) {
            let r = find(&mut parent, i) as usize;
            h[i as usize] = sum[r] / cnt[r] as f64;
        }
    }
    h
}

/// Weights of a gable roof: 0 for gable ends, 1 for eaves.
fn gable_weights(
    loops: &[Vec<DVec2>],
    index: Option<usize>,
) -> Result<Vec<Vec<f64>>, SkeletonError> {
    let mut w: Vec<Vec<f64>> = loops.iter().map(|l| vec![1.0; l.len()]).collect();
    if let Some(ix) = index {
        let outer = &loops[0];
        let i = ix % outer.len();
        let d = (outer[(i + 1) % outer.len()] - outer[i]).normalize_or_zero();
        for (l, pts) in loops.iter().enumerate() {
            for j in 0..pts.len() {
                let e = (pts[(j + 1) % pts.len()] - pts[j]).normalize_or_zero();
                if e.dot(d).abs() < std::f64::consts::FRAC_1_SQRT_2 - 1e-12 {
                    w[l][j] = 0.0;
                }
            }
        }
        return Ok(w);
    }
    let hip = skeleton(loops, &w, StopAt::Collapse, &[])?;
    let mut g = 0;
    for (l, pts) in loops.iter().enumerate() {
        let n = pts.len();
        let base = g;
        for j in 0..n {
            let tri = hip.faces[base + j].len() == 3;
            let prev_gable = w[l][(j + n - 1) % n] == 0.0;
            let next_gable = j + 1 == n && w[l][0] == 0.0;
            if tri && !prev_gable && !next_gable {
                w[l][j] = 0.0;
            }
        }
        g += n;
    }
    Ok(w)
}

/// Classifies the edges of a roof mesh (see [`RoofEdgeKind`]).
fn classify_edges(
    mesh: &Mesh,
    roles: &[RoofFaceRole],
    up: &[(DVec3, f64)],
) -> (Vec<RoofEdgeKind>, Vec<[u32; 2]>) {
    let topo = Topology::new(mesh);
    let tol = mesh_tolerance(mesh) * 100.0;
    let height = |f: usize, p: u32| up[f].0.dot(mesh.positions[p as usize]) - up[f].1;
    // Lowest height of the roof faces of each footprint (by up vector).
    let mut low = vec![f64::INFINITY; mesh.faces.len()];
    for f in 0..mesh.faces.len() {
        if roles[f] != RoofFaceRole::Top {
            continue;
        }
        for &l in mesh.face_loops(f) {
            for &p in mesh.loop_indices(l) {
                low[f] = low[f].min(height(f, p));
            }
        }
    }
    let ne = topo.edges.len();
    let mut kinds = vec![RoofEdgeKind::Other; ne];
    let mut ends: Vec<[u32; 2]> = topo.edges.iter().map(|e| e.p).collect();
    let mut eave_vertex = vec![false; topo.weld.count];
    for e in 0..ne {
        let uses = topo.edge_uses(e);
        let tops: Vec<_> = uses
            .iter()
            .filter(|u| roles[u.face as usize] == RoofFaceRole::Top)
            .collect();
        if tops.len() == 1 {
            let u = tops[0];
            let f = u.face as usize;
            let others_ok = uses
                .iter()
                .all(|x| x.face == u.face || roles[x.face as usize] == RoofFaceRole::Bottom);
            let [a, b] = topo.edges[e].p;
            let (ha, hb) = (height(f, a), height(f, b));
            if others_ok && (ha - low[f]).abs() <= tol && (hb - low[f]).abs() <= tol {
                kinds[e] = RoofEdgeKind::Eave;
                // Counter-clockwise around the footprint: as the roof face runs.
                let c = u.corner as usize;
                let l = mesh
                    .face_loops(f)
                    .iter()
                    .find(|l| (l.start as usize..(l.start + l.len) as usize).contains(&c))
                    .copied()
                    .unwrap_or(mesh.outer_loop(f));
                let r = mesh.loop_corners(l);
                let nx = if c + 1 == r.end { r.start } else { c + 1 };
                ends[e] = [mesh.corners[c], mesh.corners[nx]];
                eave_vertex[topo.weld.id[a as usize] as usize] = true;
                eave_vertex[topo.weld.id[b as usize] as usize] = true;
            }
        }
    }
    for e in 0..ne {
        let uses = topo.edge_uses(e);
        if uses.len() != 2
            || roles[uses[0].face as usize] != RoofFaceRole::Top
            || roles[uses[1].face as usize] != RoofFaceRole::Top
        {
            continue;
        }
        let (f1, f2) = (uses[0].face as usize, uses[1].face as usize);
        let [a, b] = topo.edges[e].p;
        let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
        let n1 = face_normal(mesh, f1);
        // The point of f2 farthest from the edge tells the dihedral's sense.
        let dir = (pb - pa).normalize_or_zero();
        let mut best = (0.0, 0.0);
        for &l in mesh.face_loops(f2) {
            for q in mesh.loop_points(l) {
                let r = q - pa;
                let off = (r - dir * r.dot(dir)).length();
                if off > best.0 {
                    best = (off, r.dot(n1));
                }
            }
        }
        let kind = if best.1 > tol {
            RoofEdgeKind::Valley
        } else if eave_vertex[topo.weld.id[a as usize] as usize]
            || eave_vertex[topo.weld.id[b as usize] as usize]
        {
            RoofEdgeKind::Hip
        } else {
            RoofEdgeKind::Ridge
        };
        kinds[e] = kind;
        let f = f1;
        if height(f, a) > height(f, b) {
            ends[e] = [b, a];
        } else {
            ends[e] = [a, b];
        }
    }
    (kinds, ends)
}

#[cfg(test)]
#[path = "roof_tests.rs"]
mod tests;
