//! Extrusion of faces into prisms (CGA's `extrude`).
//!
//! Face order, as CityEngine produces it: for each input face in order, its
//! bottom (the original face), its top (the moved copy), then one side quad
//! per boundary edge, outer loop first, each loop from its first edge (the
//! first edge of a lot is its street front, so side 0 is the front facade).
//! With a positive distance along the face normal the bottom is the original
//! face reversed so that it faces out: its loop starts at the original second
//! corner (`p1 p0 pn-1 .. p2`), so its first edge is the front edge reversed.
//! A side quad on edge `a -> b` is `a b b' a'`. When the extrusion runs
//! against the face normal (negative distance), the bottom keeps the
//! original loop, and the top (`p1' p0' ..`) and the sides (`b a a' b'`) are
//! reversed, so normals always point out of the solid.
//!
//! Faces that share an edge and move it by the same vector (coplanar
//! neighbours along the normal, or any faces with `world.up`) share the top
//! vertices and get no side faces on that edge (no internal lamina faces);
//! faces with different normals are extruded individually (with internal
//! faces), all as CityEngine does.
//!
//! Vertices are shared: the original positions (welded), then the top
//! positions in order of first use. Texture coordinates are inherited: the
//! bottom and top copy the face's corners, a side quad takes the UVs of its
//! edge's two corners. Normals are not carried over (they no longer apply).

use glam::{DVec2, DVec3};

use crate::measure::face_normal;
use crate::mesh::{Face, Loop, Mesh};
use crate::remembered::{mesh_bits_len, push_mesh_bits, Key, Remembered};
use crate::topology::{mesh_tolerance, weld_points};

/// How faces are moved (CGA's `extrusionType`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Extrusion {
    /// `face.normal` (the default): each face along its own normal.
    FaceNormal,
    /// `world.up`: along a direction, given in the mesh's frame (the caller
    /// converts world up into it). Need not be of unit length.
    Direction(DVec3),
    /// `world.up.flatTop`: along a direction up to a common plane: the
    /// distance is measured from the lowest vertex (from the highest if
    /// negative), and is at least the extent of the geometry along the
    /// direction, so that the top is flat.
    DirectionFlatTop(DVec3),
    /// `vertex.normal`: every vertex along its normal (the average of the
    /// normals of the faces around it), keeping faces together.
    VertexNormal,
}

/// The component tag CGA gives a face created by `extrude`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExtrudeRole {
    /// `extrude.bottom`: the original face.
    Bottom,
    /// `extrude.top`: the moved face.
    Top,
    /// `extrude.side.outer`: a side from an edge of an outer loop.
    SideOuter,
    /// `extrude.side.inner`: a side from an edge of a hole.
    SideInner,
}

impl ExtrudeRole {
    pub fn tag(self) -> &'static str {
        match self {
            ExtrudeRole::Bottom => "extrude.bottom",
            ExtrudeRole::Top => "extrude.top",
            ExtrudeRole::SideOuter => "extrude.side.outer",
            ExtrudeRole::SideInner => "extrude.side.inner",
        }
    }
}

/// Extrudes every face of `mesh` by `distance` (see the module docs).
pub fn extrude(mesh: &Mesh, how: Extrusion, distance: f64) -> Mesh {
    extrude_with_roles(mesh, how, distance).0
}

/// [`extrude`], also returning the role of every face of the result.
///
/// A small mesh's extrusion is remembered per thread and replayed for the
/// next mesh with the same geometry, extrusion and distance (see
/// [`ExtrusionPlan`]): a facade's window frames and sills are extruded
/// alike, thousands of times (Candler: 16,400 extrusions of 241 kinds on
/// 20 buildings, 4,241 when their texture coordinates count).
pub fn extrude_with_roles(mesh: &Mesh, how: Extrusion, distance: f64) -> (Mesh, Vec<ExtrudeRole>) {
    let distance = if distance.is_finite() { distance } else { 0.0 };
    let key = replay_key(mesh, how, distance);
    if let Some(key) = &key {
        let replayed = EXTRUSIONS
            .try_with(|e| e.borrow().get(key).map(|plan| plan.replay(mesh)))
            .ok()
            .flatten();
        if let Some(done) = replayed {
            return done;
        }
    }
    let (out, roles, sources) = extrude_anew(mesh, how, distance);
    if let Some(key) = key {
        let plan = ExtrusionPlan {
            positions: out.positions.clone(),
            corners: out.corners.clone(),
            loops: out.loops.clone(),
            faces: out.faces.clone(),
            roles: roles.clone(),
            sources,
        };
        let bytes = plan.bytes();
        // Fails only while the thread shuts down: then nothing is kept.
        let _ = EXTRUSIONS.try_with(|e| e.borrow_mut().insert(key, plan, bytes));
    }
    (out, roles)
}

/// Inputs up to this many corners are remembered for replay.
const REPLAY_MAX_CORNERS: usize = 64;

/// Extrusions remembered per thread at most, and the bytes they hold.
const REPLAY_ENTRIES: usize = 1024;
const REPLAY_BUDGET_BYTES: usize = 4 << 20;

thread_local! {
    static EXTRUSIONS: std::cell::RefCell<Remembered<ExtrusionPlan>> =
        std::cell::RefCell::new(Remembered::new(REPLAY_ENTRIES, REPLAY_BUDGET_BYTES));
}

/// What an extrusion made of a mesh's geometry: everything but the
/// texture coordinates, and the source corner of each corner, whose
/// coordinates it copies. The geometry, the face roles and the sources
/// depend only on the mesh's positions, corners, loops, faces, the kind
/// of extrusion and the distance (every bit of them), so a replay gives
/// what extruding anew gives. Meshes with normals (read for edge and
/// vertex shapes) or edge and vertex tags (carried by rules of their own)
/// are not remembered.
struct ExtrusionPlan {
    positions: Vec<DVec3>,
    corners: Vec<u32>,
    loops: Vec<Loop>,
    faces: Vec<Face>,
    roles: Vec<ExtrudeRole>,
    sources: Vec<u32>,
}

impl ExtrusionPlan {
    /// The extrusion of `mesh` (whose key is the plan's).
    fn replay(&self, mesh: &Mesh) -> (Mesh, Vec<ExtrudeRole>) {
        let mut out = Mesh::new();
        out.share_slots(mesh);
        out.positions = self.positions.clone();
        out.corners = self.corners.clone();
        out.loops = self.loops.clone();
        out.faces = self.faces.clone();
        for (set, uvs) in mesh.uvs.iter().enumerate() {
            if let Some(uvs) = uvs {
                out.uvs[set] = Some(
                    self.sources
                        .iter()
                        .map(|&c| uvs.get(c as usize).copied().unwrap_or(DVec2::ZERO))
                        .collect(),
                );
            }
        }
        #[cfg(test)]
        REPLAYED.with(|r| r.set(r.get() + 1));
        (out, self.roles.clone())
    }

    /// Bytes the plan holds (what the budget counts).
    fn bytes(&self) -> usize {
        use std::mem::size_of;
        self.positions.len() * size_of::<DVec3>()
            + (self.corners.len() + self.sources.len()) * size_of::<u32>()
            + self.loops.len() * size_of::<Loop>()
            + self.faces.len() * size_of::<Face>()
            + self.roles.len() * size_of::<ExtrudeRole>()
    }
}

#[cfg(test)]
thread_local! {
    /// Extrusions replayed on this thread, for tests.
    static REPLAYED: std::cell::Cell<usize> = const { std::cell::Cell::new(0) };
}

/// Forgets this thread's remembered extrusions (for tests that compare a
/// replay with extruding anew).
#[cfg(test)]
fn forget_extrusions() {
    EXTRUSIONS.with(|e| *e.borrow_mut() = Remembered::new(REPLAY_ENTRIES, REPLAY_BUDGET_BYTES));
}

/// The key of extruding `mesh` by `distance` as `how` says, if it is
/// remembered (see [`ExtrusionPlan`]).
fn replay_key(mesh: &Mesh, how: Extrusion, distance: f64) -> Option<Key> {
    if mesh.corners.len() > REPLAY_MAX_CORNERS
        || mesh.normals.is_some()
        || mesh.edge_tags.is_some()
        || mesh.vertex_tags.is_some()
    {
        return None;
    }
    let (kind, dir) = match how {
        Extrusion::FaceNormal => (0, DVec3::ZERO),
        Extrusion::Direction(d) => (1, d),
        Extrusion::DirectionFlatTop(d) => (2, d),
        Extrusion::VertexNormal => (3, DVec3::ZERO),
    };
    let mut data = Vec::with_capacity(5 + mesh_bits_len(mesh));
    data.push(kind);
    data.extend(dir.to_array().map(f64::to_bits));
    data.push(distance.to_bits());
    push_mesh_bits(&mut data, mesh);
    Some(Key::new(data))
}

/// [`extrude_with_roles`] worked out, also giving the source corner of
/// every corner of the result.
fn extrude_anew(mesh: &Mesh, how: Extrusion, distance: f64) -> (Mesh, Vec<ExtrudeRole>, Vec<u32>) {
    let tol = mesh_tolerance(mesh);
    let weld = weld_points(&mesh.positions, tol);
    let vid = |corner: usize| weld.id[mesh.corners[corner] as usize];
    let normals: Vec<DVec3> = (0..mesh.faces.len())
        .map(|f| face_normal(mesh, f))
        .collect();
    // The direction a face moves along with `face.normal`: its normal, or
    // for edge and vertex shapes the normal stored on their corners.
    let face_dir = |f: usize| {
        if normals[f] != DVec3::ZERO {
            normals[f]
        } else {
            stored_normal(mesh, f)
        }
    };

    // The extrusion vector of every corner.
    let mut vec_of_corner = vec![DVec3::ZERO; mesh.corners.len()];
    match how {
        Extrusion::FaceNormal => {
            for f in 0..mesh.faces.len() {
                let n = face_dir(f);
                for &l in mesh.face_loops(f) {
                    for c in mesh.loop_corners(l) {
                        vec_of_corner[c] = n * distance;
                    }
                }
            }
        }
        Extrusion::Direction(d) => {
            let d = d.normalize_or(DVec3::Y);
            vec_of_corner.fill(d * distance);
        }
        Extrusion::DirectionFlatTop(d) => {
            let d = d.normalize_or(DVec3::Y);
            let mut lo = f64::INFINITY;
            let mut hi = f64::NEG_INFINITY;
            for &p in &mesh.corners {
                let h = mesh.positions[p as usize].dot(d);
                lo = lo.min(h);
                hi = hi.max(h);
            }
            let level = if distance >= 0.0 {
                lo + distance.max(hi - lo)
            } else {
                hi - (-distance).max(hi - lo)
            };
            for (c, v) in vec_of_corner.iter_mut().enumerate() {
                let h = mesh.positions[mesh.corners[c] as usize].dot(d);
                *v = d * (level - h);
            }
        }
        Extrusion::VertexNormal => {
            // Average of the normals of the distinct faces around each
            // welded vertex.
            let mut acc = vec![DVec3::ZERO; weld.count];
            let mut last_face = vec![u32::MAX; weld.count];
            for f in 0..mesh.faces.len() {
                let n = face_dir(f);
                for &l in mesh.face_loops(f) {
                    for c in mesh.loop_corners(l) {
                        let v = vid(c) as usize;
                        if last_face[v] != f as u32 {
                            last_face[v] = f as u32;
                            acc[v] += n;
                        }
                    }
                }
            }
            for (c, v) in vec_of_corner.iter_mut().enumerate() {
                *v = acc[vid(c) as usize].normalize_or_zero() * distance;
            }
        }
    }

    let mut out = Mesh::new();
    out.share_slots(mesh);
    out.positions = weld
        .representative
        .iter()
        .map(|&i| mesh.positions[i as usize])
        .collect();
    // Room for a top per base vertex, the usual case.
    out.positions.reserve(weld.count);
    // Top vertex of every corner: shared between corners of the same base
    // vertex moved by the same vector. The tops made for a base vertex are
    // a chain in `tops` (vector, top vertex, next entry), searched in the
    // order they were made; most vertices have one, so a flat array
    // replaces a list per vertex.
    const END: u32 = u32::MAX;
    let mut first_top = vec![END; weld.count];
    let mut tops: Vec<(DVec3, u32, u32)> = Vec::with_capacity(weld.count);
    let mut top_of_corner = vec![0u32; mesh.corners.len()];
    let vtol = tol.max(1e-9 * distance.abs());
    for f in 0..mesh.faces.len() {
        for &l in mesh.face_loops(f) {
            for c in mesh.loop_corners(l) {
                let v = vid(c);
                let w = vec_of_corner[c];
                let (mut e, mut last) = (first_top[v as usize], END);
                let found = loop {
                    let Some(&(x, t, next)) = tops.get(e as usize) else {
                        break None;
                    };
                    if (x - w).abs().max_element() <= vtol {
                        break Some(t);
                    }
                    (last, e) = (e, next);
                };
                let t = match found {
                    Some(t) => t,
                    None => {
                        let t = out.positions.len() as u32;
                        out.positions.push(out.positions[v as usize] + w);
                        let entry = tops.len() as u32;
                        tops.push((w, t, END));
                        match last {
                            END => first_top[v as usize] = entry,
                            _ => tops[last as usize].2 = entry,
                        }
                        t
                    }
                };
                top_of_corner[c] = t;
            }
        }
    }
    // Directed side edges (base a, base b, top a, top b), to detect the
    // internal ones (the same edge moved identically by a neighbour).
    let mut sides: crate::topology::FxHashMap<(u32, u32, u32, u32), ()> =
        crate::topology::fx_map(mesh.corners.len());
    for f in 0..mesh.faces.len() {
        if mesh.outer_loop(f).len < 3 {
            continue;
        }
        for &l in mesh.face_loops(f) {
            let r = mesh.loop_corners(l);
            for c in r.clone() {
                let n = if c + 1 == r.end { r.start } else { c + 1 };
                sides.insert((vid(c), vid(n), top_of_corner[c], top_of_corner[n]), ());
            }
        }
    }

    let has_uv: Vec<usize> = (0..mesh.uvs.len())
        .filter(|&k| mesh.uvs[k].is_some())
        .collect();
    let mut uv_out: Vec<Vec<DVec2>> = vec![Vec::new(); mesh.uvs.len()];
    // Edge and vertex tags (tag propagation of cga_componentTags.md): an
    // output edge between the corners of one source edge keeps its tags;
    // an edge between two copies of one source corner (a side's vertical
    // edge) "emanates" from that vertex and inherits the vertex's tags;
    // corners keep their source corner's vertex tags; a side face inherits
    // the tags of the edge it emanates from.
    let corner_tags = mesh.edge_tags.is_some() || mesh.vertex_tags.is_some();
    let mut next_src = vec![0u32; if corner_tags { mesh.corners.len() } else { 0 }];
    if corner_tags {
        for l in &mesh.loops {
            let r = mesh.loop_corners(*l);
            for c in r.clone() {
                next_src[c] = if c + 1 == r.end { r.start } else { c + 1 } as u32;
            }
        }
    }
    let mut edge_out: Vec<u32> = Vec::new();
    let mut vertex_out: Vec<u32> = Vec::new();
    // Every corner gives at most a bottom, a top and the four corners of
    // a side (an edge shape's quad too): room for all of it at once, not
    // by doubling.
    let corners = mesh.corners.len();
    out.corners.reserve(6 * corners);
    out.loops.reserve(2 * mesh.loops.len() + corners);
    out.faces.reserve(2 * mesh.faces.len() + corners);
    for &k in &has_uv {
        uv_out[k].reserve(6 * corners);
    }
    let mut roles = Vec::with_capacity(2 * mesh.faces.len() + corners);
    let mut sources: Vec<u32> = Vec::with_capacity(6 * corners);
    // One side's loop of (position, source corner), refilled per side.
    let mut side: [Vec<(u32, u32)>; 1] = [Vec::with_capacity(4)];
    let mut emit =
        |out: &mut Mesh, uv_out: &mut Vec<Vec<DVec2>>, loops: &[Vec<(u32, u32)>], f: usize| {
            let first_loop = out.loops.len() as u32;
            for l in loops {
                let start = out.corners.len() as u32;
                if corner_tags {
                    for (k, &(_, s)) in l.iter().enumerate() {
                        let t = l[(k + 1) % l.len()].1;
                        let e = if next_src.get(s as usize) == Some(&t) {
                            mesh.edge_tag_index(s as usize)
                        } else if next_src.get(t as usize) == Some(&s) {
                            mesh.edge_tag_index(t as usize)
                        } else if s == t {
                            mesh.vertex_tag_index(s as usize)
                        } else {
                            0
                        };
                        edge_out.push(e);
                        vertex_out.push(mesh.vertex_tag_index(s as usize));
                    }
                }
                for &(p, src) in l {
                    out.corners.push(p);
                    sources.push(src);
                    for &k in &has_uv {
                        let uv = mesh.uvs[k].as_ref().and_then(|u| u.get(src as usize));
                        uv_out[k].push(uv.copied().unwrap_or(DVec2::ZERO));
                    }
                }
                out.loops.push(Loop {
                    start,
                    len: l.len() as u32,
                });
            }
            let src = mesh.faces[f];
            out.faces.push(Face {
                first_loop,
                loop_count: loops.len() as u32,
                material: src.material,
                group: src.group,
                tags: src.tags,
            });
        };

    for f in 0..mesh.faces.len() {
        let outer = mesh.outer_loop(f);
        if outer.len < 3 {
            // Edge shape: a quad; vertex shape: an edge.
            let r = mesh.loop_corners(outer);
            let c: Vec<usize> = r.collect();
            let loops = match c.len() {
                2 => vec![vec![
                    (vid(c[0]), c[0] as u32),
                    (vid(c[1]), c[1] as u32),
                    (top_of_corner[c[1]], c[1] as u32),
                    (top_of_corner[c[0]], c[0] as u32),
                ]],
                1 => vec![vec![
                    (vid(c[0]), c[0] as u32),
                    (top_of_corner[c[0]], c[0] as u32),
                ]],
                _ => continue,
            };
            emit(&mut out, &mut uv_out, &loops, f);
            roles.push(ExtrudeRole::SideOuter);
            continue;
        }
        // Does the extrusion run against the face normal?
        let mean: DVec3 = mesh
            .loop_corners(outer)
            .map(|c| vec_of_corner[c])
            .sum::<DVec3>();
        let flip = mean.dot(face_dir(f)) < 0.0;
        let base: Vec<Vec<(u32, u32)>> = mesh
            .face_loops(f)
            .iter()
            .map(|&l| mesh.loop_corners(l).map(|c| (vid(c), c as u32)).collect())
            .collect();
        let top: Vec<Vec<(u32, u32)>> = mesh
            .face_loops(f)
            .iter()
            .map(|&l| {
                mesh.loop_corners(l)
                    .map(|c| (top_of_corner[c], c as u32))
                    .collect()
            })
            .collect();
        let reversed = |ls: &[Vec<(u32, u32)>]| -> Vec<Vec<(u32, u32)>> {
            ls.iter()
                .map(|l| {
                    // p1 p0 pn-1 .. p2: the first edge reversed comes first.
                    let n = l.len();
                    (0..n).map(|k| l[(n + 1 - k) % n]).collect()
                })
                .collect()
        };
        if flip {
            emit(&mut out, &mut uv_out, &base, f);
            emit(&mut out, &mut uv_out, &reversed(&top), f);
        } else {
            emit(&mut out, &mut uv_out, &reversed(&base), f);
            emit(&mut out, &mut uv_out, &top, f);
        }
        roles.push(ExtrudeRole::Bottom);
        roles.push(ExtrudeRole::Top);
        for (li, &l) in mesh.face_loops(f).iter().enumerate() {
            let r = mesh.loop_corners(l);
            for c in r.clone() {
                let n = if c + 1 == r.end { r.start } else { c + 1 };
                let (a, b, ta, tb) = (vid(c), vid(n), top_of_corner[c], top_of_corner[n]);
                if a == b || sides.contains_key(&(b, a, tb, ta)) {
                    continue; // zero-length or internal edge
                }
                let quad = &mut side[0];
                quad.clear();
                if flip {
                    quad.extend([(b, n as u32), (a, c as u32), (ta, c as u32), (tb, n as u32)]);
                } else {
                    quad.extend([(a, c as u32), (b, n as u32), (tb, n as u32), (ta, c as u32)]);
                }
                emit(&mut out, &mut uv_out, &side, f);
                let et = mesh.edge_tag_index(c);
                if et != 0 {
                    // The side emanates from a tagged edge.
                    let nf = out.faces.len() - 1;
                    let set = out.tag_set(out.faces[nf].tags).union(mesh.tag_set(et));
                    out.faces[nf].tags = out.intern_tags(set);
                }
                roles.push(if li == 0 {
                    ExtrudeRole::SideOuter
                } else {
                    ExtrudeRole::SideInner
                });
            }
        }
    }
    for k in has_uv {
        out.uvs[k] = Some(std::mem::take(&mut uv_out[k]));
    }
    if edge_out.iter().any(|&t| t != 0) {
        out.edge_tags = Some(edge_out);
    }
    if mesh.vertex_tags.is_some() {
        out.vertex_tags = Some(vertex_out);
    }
    // Drop welded positions no face uses (duplicates folded by welding).
    compact_positions(&mut out);
    (out, roles, sources)
}

/// The normal stored on an edge or vertex shape's corners (their average),
/// or world up if it has none.
fn stored_normal(mesh: &Mesh, face: usize) -> DVec3 {
    let Some(normals) = &mesh.normals else {
        return DVec3::Y;
    };
    let s: DVec3 = mesh
        .loop_corners(mesh.outer_loop(face))
        .filter_map(|c| normals.get(c).copied())
        .sum();
    s.try_normalize().unwrap_or(DVec3::Y)
}

/// Removes positions no corner uses, keeping the order of the others.
pub(crate) fn compact_positions(m: &mut Mesh) {
    let mut used = vec![u32::MAX; m.positions.len()];
    for &c in &m.corners {
        used[c as usize] = 0;
    }
    if used.iter().all(|&u| u == 0) {
        return;
    }
    let mut next = 0u32;
    let mut kept = Vec::with_capacity(m.positions.len());
    for (i, u) in used.iter_mut().enumerate() {
        if *u == 0 {
            *u = next;
            next += 1;
            kept.push(m.positions[i]);
        }
    }
    m.positions = kept;
    for c in &mut m.corners {
        *c = used[*c as usize];
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::{counts, face_area, mesh_area, volume};
    use crate::topology::Topology;

    fn v(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    fn rect(w: f64, d: f64) -> Mesh {
        Mesh::polygon(&[v(0., 0., 0.), v(w, 0., 0.), v(w, 0., -d), v(0., 0., -d)])
    }

    fn loops(m: &Mesh) -> Vec<Vec<u32>> {
        (0..m.faces.len())
            .map(|f| m.loop_indices(m.outer_loop(f)).to_vec())
            .collect()
    }

    #[test]
    fn faces_holes_vertices_of_an_extruded_rectangle() {
        // The FacesHolesVertices rule of CityEngine's tests prints 8, 6, 0.
        let (m, roles) = extrude_with_roles(&rect(20.0, 30.0), Extrusion::FaceNormal, 10.0);
        let topo = Topology::new(&m);
        let c = counts(&m, &topo);
        assert_eq!((c.vertices, c.faces, c.holes, c.edges), (8, 6, 0, 12));
        assert_eq!(mesh_area(&m), 2200.0);
        assert!((volume(&m) - 6000.0).abs() < 1e-9);
        assert!(topo.is_closed(&m));
        // Exactly CityEngine's output (OBJ indices minus one).
        assert_eq!(
            loops(&m),
            vec![
                vec![1, 0, 3, 2],
                vec![4, 5, 6, 7],
                vec![0, 1, 5, 4],
                vec![1, 2, 6, 5],
                vec![2, 3, 7, 6],
                vec![3, 0, 4, 7],
            ]
        );
        assert_eq!(m.positions[4], v(0., 10., 0.));
        use ExtrudeRole::*;
        assert_eq!(
            roles,
            vec![Bottom, Top, SideOuter, SideOuter, SideOuter, SideOuter]
        );
        assert_eq!(face_normal(&m, 0), -DVec3::Y);
        assert_eq!(face_normal(&m, 2), DVec3::Z); // the front
    }

    #[test]
    fn negative_distance_keeps_normals_outward() {
        let m = extrude(&rect(20.0, 30.0), Extrusion::FaceNormal, -10.0);
        assert_eq!(
            loops(&m),
            vec![
                vec![0, 1, 2, 3],
                vec![5, 4, 7, 6],
                vec![1, 0, 4, 5],
                vec![2, 1, 5, 6],
                vec![3, 2, 6, 7],
                vec![0, 3, 7, 4],
            ]
        );
        assert!((volume(&m) - 6000.0).abs() < 1e-9);
        assert_eq!(m.positions[4], v(0., -10., 0.));
    }

    #[test]
    fn coplanar_faces_are_extruded_together() {
        // Two adjacent quads: CityEngine gives 12 vertices and 10 faces.
        let mut lot = Mesh::new();
        lot.positions.extend([
            v(0., 0., 0.),
            v(10., 0., 0.),
            v(10., 0., -10.),
            v(0., 0., -10.),
            v(20., 0., 0.),
            v(20., 0., -10.),
        ]);
        lot.add_face(&[&[0, 1, 2, 3]], 0);
        lot.add_face(&[&[1, 4, 5, 2]], 0);
        let m = extrude(&lot, Extrusion::FaceNormal, 10.0);
        assert_eq!(
            loops(&m),
            vec![
                vec![1, 0, 3, 2],
                vec![6, 7, 8, 9],
                vec![0, 1, 7, 6],
                vec![2, 3, 9, 8],
                vec![3, 0, 6, 9],
                vec![4, 1, 2, 5],
                vec![7, 10, 11, 8],
                vec![1, 4, 10, 7],
                vec![4, 5, 11, 10],
                vec![5, 2, 8, 11],
            ]
        );
        assert!(Topology::new(&m).is_closed(&m));
        assert!((volume(&m) - 2000.0).abs() < 1e-9);
    }

    #[test]
    fn uneven_faces_get_internal_sides() {
        // The second face tilted: extruded on its own, 14 vertices and 12
        // faces as in CityEngine.
        let mut lot = Mesh::new();
        lot.positions.extend([
            v(0., 0., 0.),
            v(10., 0., 0.),
            v(10., 0., -10.),
            v(0., 0., -10.),
            v(20., 5., 0.),
            v(20., 5., -10.),
        ]);
        lot.add_face(&[&[0, 1, 2, 3]], 0);
        lot.add_face(&[&[1, 4, 5, 2]], 0);
        let m = extrude(&lot, Extrusion::FaceNormal, 10.0);
        let c = counts(&m, &Topology::new(&m));
        assert_eq!((c.vertices, c.faces), (14, 12));
        assert!((m.positions[10] - v(5.528, 8.944, 0.)).length() < 1e-3);
        // With world.up the two faces share their top edge again.
        let m = extrude(&lot, Extrusion::Direction(DVec3::Y), 10.0);
        let c = counts(&m, &Topology::new(&m));
        assert_eq!((c.vertices, c.faces), (12, 10));
        assert!(Topology::new(&m).is_closed(&m));
        assert!((volume(&m) - 2000.0).abs() < 1e-9);
    }

    /// A 4 m square face with a 2 m square hole in its middle, on the
    /// ground.
    fn square_with_hole() -> Mesh {
        let mut m = Mesh::new();
        m.positions.extend([
            v(0., 0., 0.),
            v(4., 0., 0.),
            v(4., 0., -4.),
            v(0., 0., -4.),
            v(1., 0., -1.),
            v(1., 0., -3.),
            v(3., 0., -3.),
            v(3., 0., -1.),
        ]);
        m.add_face(&[&[0, 1, 2, 3], &[4, 5, 6, 7]], 0);
        m
    }

    #[test]
    fn holes_give_inner_sides() {
        let lot = square_with_hole();
        let (m, roles) = extrude_with_roles(&lot, Extrusion::FaceNormal, 2.0);
        let c = counts(&m, &Topology::new(&m));
        assert_eq!((c.vertices, c.faces, c.holes), (16, 10, 2));
        assert!(Topology::new(&m).is_closed(&m));
        assert!((volume(&m) - 24.0).abs() < 1e-12);
        assert_eq!(face_area(&m, 0), 12.0);
        assert_eq!(
            roles
                .iter()
                .filter(|r| **r == ExtrudeRole::SideInner)
                .count(),
            4
        );
        // A hole side faces into the hole: the side on hole edge
        // (1,-1) -> (1,-3) faces +x.
        let f = roles
            .iter()
            .position(|r| *r == ExtrudeRole::SideInner)
            .unwrap();
        assert_eq!(face_normal(&m, f), DVec3::X);
    }

    #[test]
    fn flat_top_over_a_sloped_face() {
        // A quad rising from y = 0 to y = 2 along -z.
        let lot = Mesh::polygon(&[v(0., 0., 0.), v(4., 0., 0.), v(4., 2., -4.), v(0., 2., -4.)]);
        let m = extrude(&lot, Extrusion::DirectionFlatTop(DVec3::Y), 5.0);
        // Top at y = 0 + 5.
        assert!(m.positions.iter().filter(|p| p.y == 5.0).count() == 4);
        assert!((volume(&m) - (5.0 * 16.0 - 0.5 * 2.0 * 4.0 * 4.0)).abs() < 1e-9);
        // A distance smaller than the extent is raised to it.
        let m = extrude(&lot, Extrusion::DirectionFlatTop(DVec3::Y), 1.0);
        // (the two high corners of the original face are at y = 2 too)
        assert_eq!(m.positions.iter().filter(|p| p.y == 2.0).count(), 6);
        // Negative: measured down from the highest vertex.
        let m = extrude(&lot, Extrusion::DirectionFlatTop(DVec3::Y), -3.0);
        assert_eq!(m.positions.iter().filter(|p| p.y == -1.0).count(), 4);
        assert!(volume(&m) > 0.0);
    }

    #[test]
    fn vertex_normals_keep_faces_together() {
        let mut lot = Mesh::new();
        lot.positions.extend([
            v(0., 0., 0.),
            v(10., 0., 0.),
            v(10., 0., -10.),
            v(0., 0., -10.),
            v(20., 5., 0.),
            v(20., 5., -10.),
        ]);
        lot.add_face(&[&[0, 1, 2, 3]], 0);
        lot.add_face(&[&[1, 4, 5, 2]], 0);
        let m = extrude(&lot, Extrusion::VertexNormal, 1.0);
        let c = counts(&m, &Topology::new(&m));
        assert_eq!((c.vertices, c.faces), (12, 10));
        assert!(Topology::new(&m).is_closed(&m));
    }

    #[test]
    fn uvs_are_inherited_and_edges_extrude_to_quads() {
        let mut lot = rect(2.0, 1.0);
        lot.uvs[0] = Some(vec![
            DVec2::new(0., 0.),
            DVec2::new(1., 0.),
            DVec2::new(1., 1.),
            DVec2::new(0., 1.),
        ]);
        let m = extrude(&lot, Extrusion::FaceNormal, 1.0);
        let uv = m.uvs[0].as_ref().unwrap();
        assert_eq!(uv.len(), m.corners.len());
        // Bottom p1 p0 p3 p2, top p0..p3, front side p0 p1 p1' p0'.
        assert_eq!(
            &uv[0..4],
            &[
                DVec2::new(1., 0.),
                DVec2::ZERO,
                DVec2::new(0., 1.),
                DVec2::ONE
            ]
        );
        assert_eq!(uv[4], DVec2::ZERO);
        assert_eq!(
            &uv[8..12],
            &[
                DVec2::ZERO,
                DVec2::new(1., 0.),
                DVec2::new(1., 0.),
                DVec2::ZERO
            ]
        );

        let mut e = Mesh::new();
        e.positions.extend([v(0., 0., 0.), v(3., 0., 0.)]);
        e.add_face(&[&[0, 1]], 0);
        e.normals = Some(vec![DVec3::Z, DVec3::Z]);
        let q = extrude(&e, Extrusion::FaceNormal, 2.0);
        assert_eq!(q.faces.len(), 1);
        assert_eq!(face_area(&q, 0), 6.0);
        assert_eq!(q.positions[3], v(3., 0., 2.));
        assert_eq!(q.loop_indices(q.outer_loop(0)), &[0, 1, 3, 2]);
    }

    /// A replayed extrusion is the extrusion made anew, with the new
    /// mesh's texture coordinates: for every kind of extrusion, a quad and
    /// a face with a hole, up and down; meshes with edge tags are not
    /// remembered.
    #[test]
    fn replayed_extrusions_equal_extruding_anew() {
        let replays = || REPLAYED.with(|r| r.get());
        let holed = square_with_hole();
        let textured = |m: &Mesh, k: f64| {
            let mut m = m.clone();
            let n = m.corners.len();
            m.uvs[0] = Some((0..n).map(|i| DVec2::new(k + i as f64, 0.5 * k)).collect());
            m.uvs[3] = Some((0..n).map(|i| DVec2::new(-k, i as f64 * k)).collect());
            m
        };
        let hows = [
            Extrusion::FaceNormal,
            Extrusion::Direction(DVec3::new(0.0, 1.0, 0.25)),
            Extrusion::DirectionFlatTop(DVec3::Y),
            Extrusion::VertexNormal,
        ];
        for base in [rect(3.0, 2.0), holed] {
            for how in hows {
                for d in [2.5, -1.25] {
                    forget_extrusions();
                    let first = extrude_with_roles(&textured(&base, 0.25), how, d);
                    let before = replays();
                    let replayed = extrude_with_roles(&textured(&base, 0.75), how, d);
                    assert_eq!(replays(), before + 1, "{how:?} {d}");
                    forget_extrusions();
                    let anew = extrude_with_roles(&textured(&base, 0.75), how, d);
                    assert_eq!(replayed, anew, "{how:?} {d}");
                    assert_ne!(first.0.uvs[0], replayed.0.uvs[0]);
                    assert_eq!(first.0.positions, replayed.0.positions);
                    assert!(replayed.0.uvs[3].is_some() && replayed.0.uvs[1].is_none());
                }
            }
        }
        // Another distance is another extrusion.
        forget_extrusions();
        let a = extrude(&rect(3.0, 2.0), Extrusion::FaceNormal, 2.0);
        let before = replays();
        let b = extrude(&rect(3.0, 2.0), Extrusion::FaceNormal, 2.5);
        assert_eq!(replays(), before);
        assert_ne!(a.positions, b.positions);
        // Edge tags are carried by rules of their own: not remembered.
        let mut tagged = rect(3.0, 2.0);
        let t = tagged.intern_tags(crate::tags::TagSet::from_names(["edge.a"]));
        tagged.edge_tags = Some(vec![t, 0, 0, 0]);
        let before = replays();
        let x = extrude(&tagged, Extrusion::FaceNormal, 2.0);
        let y = extrude(&tagged, Extrusion::FaceNormal, 2.0);
        assert_eq!(replays(), before);
        assert_eq!(x, y);
    }
}
