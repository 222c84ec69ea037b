//! Shape recomposition (CGA's `inline(recompose)` and `modify`): merging
//! the pieces of a subdivided geometry back into one connected mesh.
//!
//! CityEngine tracks, through the derivation, which source vertex every
//! vertex of a piece came from, and reconnects pieces by those relations
//! whatever happened to their positions. Here every corner of a piece
//! carries its *rest position*: where the point was on the geometry when the
//! recomposition began (the engine stores it in texture coordinates, which
//! cuts interpolate along the edge a new vertex lies on, so a vertex made by
//! a split gets the rest position of the point of the source edge it was
//! made from). Pieces are then reconnected in rest space:
//!
//! - corners with the same rest position (within a tolerance) become one
//!   vertex;
//! - a vertex whose rest position lies inside an edge of another face gets
//!   inserted into that face's loop (the "vertices inserted on polygon
//!   boundaries" of cga_shapeRecomposition.md);
//! - each piece moves a vertex by its *offset*, its position minus the rest
//!   position; a merged vertex is placed at its rest position plus the sum of
//!   the offsets of all pieces that have it (a piece that has the point only
//!   inside one of its edges offsets it by the interpolation of that edge's
//!   end offsets). So a piece moved alone carries its shared vertices along,
//!   and four faces moved up by one each lift their common corner by four,
//!   as the reference describes ("Accumulating Offsets").
//!
//! Corners without a rest position (geometry inserted or rebuilt during the
//! derivation: assets, primitives, roofs) are appended unconnected, as
//! CityEngine does for the operations it cannot track.
//!
//! Known difference: CityEngine interpolates a vertex made on an edge along
//! that edge as *finally* placed; here it moves only by the offsets of the
//! pieces that hold it, so a split vertex on an edge whose end was moved by
//! another piece alone (recomp_vertex_move_split_2) stays where it was.

use glam::{DVec2, DVec3};

use crate::material::Material;
use crate::mesh::{Face, Loop, Mesh};
use crate::topology::{fx_map, weld_points, FxHashMap};

/// One piece to recompose.
pub struct Part<'a> {
    /// The piece's geometry (all pieces in one coordinate system).
    pub mesh: &'a Mesh,
    /// The rest position of each corner of `mesh` (`None`: not tracked).
    pub rest: &'a [Option<DVec3>],
    /// Whether the piece's faces belong to the result; a piece deleted
    /// during the derivation still moves the vertices it shares.
    pub keep_faces: bool,
    /// Whether faces of one or two corners (vertex and edge shapes) are
    /// kept; when the full geometry is restored around edited edges and
    /// vertices they only carry offsets.
    pub keep_points: bool,
}

/// The recomposed geometry.
#[derive(Debug)]
pub struct Recomposed {
    pub mesh: Mesh,
    /// Per position of `mesh`: the rest position it was merged at (`None`
    /// for untracked vertices).
    pub rest: Vec<Option<DVec3>>,
}

const NONE: u32 = u32::MAX;

/// The tolerance for "same rest position": relative to the magnitude of
/// the coordinates. Rest positions of split vertices are interpolated in
/// floating point along different pieces' edges, so they agree to about
/// 1e-12 relative, far inside this.
fn tolerance(points: impl Iterator<Item = DVec3>) -> f64 {
    let m = points.fold(0.0f64, |m, p| {
        if p.is_finite() {
            m.max(p.abs().max_element())
        } else {
            m
        }
    });
    1e-7 * m.max(1.0)
}

/// Points in a uniform hash grid, for "which points lie on this segment".
struct PointGrid {
    points: Vec<DVec3>,
    cell: f64,
    /// Point ids sorted by cell; `cells` maps a cell to its range here.
    order: Vec<u32>,
    cells: FxHashMap<[i64; 3], (u32, u32)>,
}

impl PointGrid {
    fn new(points: Vec<DVec3>, cell: f64) -> PointGrid {
        let key = |p: DVec3| [p.x, p.y, p.z].map(|c| ((c + 0.0) / cell).floor() as i64);
        let mut order: Vec<u32> = (0..points.len() as u32)
            .filter(|&i| points[i as usize].is_finite())
            .collect();
        order.sort_by_key(|&i| key(points[i as usize]));
        let mut cells = fx_map(order.len());
        let mut i = 0;
        while i < order.len() {
            let k = key(points[order[i] as usize]);
            let start = i;
            while i < order.len() && key(points[order[i] as usize]) == k {
                i += 1;
            }
            cells.insert(k, (start as u32, (i - start) as u32));
        }
        PointGrid {
            points,
            cell,
            order,
            cells,
        }
    }

    fn key(&self, p: DVec3) -> [i64; 3] {
        [p.x, p.y, p.z].map(|c| ((c + 0.0) / self.cell).floor() as i64)
    }

    /// A point within `tol` of `q` (per coordinate), if any (`tol` must be
    /// below the cell size).
    fn near(&self, q: DVec3, tol: f64) -> Option<u32> {
        if !q.is_finite() {
            return None;
        }
        let k = self.key(q);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(&(start, n)) = self.cells.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) {
                        for &i in &self.order[start as usize..(start + n) as usize] {
                            if (self.points[i as usize] - q).abs().max_element() <= tol {
                                return Some(i);
                            }
                        }
                    }
                }
            }
        }
        None
    }

    /// The points strictly inside the segment `a b` (closer than `tol` to
    /// it and farther than `tol` from both ends), as (parameter, id),
    /// sorted by parameter, into `out` (cleared first). `scratch` is a
    /// reused buffer.
    fn on_segment(
        &self,
        a: DVec3,
        b: DVec3,
        tol: f64,
        scratch: &mut Vec<u32>,
        out: &mut Vec<(f64, u32)>,
    ) {
        out.clear();
        scratch.clear();
        let d = b - a;
        let len2 = d.length_squared();
        if len2.partial_cmp(&(4.0 * tol * tol)) != Some(std::cmp::Ordering::Greater)
            || !len2.is_finite()
        {
            return;
        }
        // Samples a cell apart: a point within `tol` of the segment is
        // within half a cell (plus `tol`) of a sample, so in the sample's
        // cell or a neighbour.
        let steps = ((len2.sqrt() / self.cell).ceil() as usize).clamp(1, 1 << 20);
        let mut last = [i64::MIN; 3];
        for s in 0..=steps {
            let k = self.key(a + d * (s as f64 / steps as f64));
            if k == last {
                continue;
            }
            last = k;
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        if let Some(&(start, n)) =
                            self.cells.get(&[k[0] + dx, k[1] + dy, k[2] + dz])
                        {
                            scratch.extend_from_slice(
                                &self.order[start as usize..(start + n) as usize],
                            );
                        }
                    }
                }
            }
        }
        scratch.sort_unstable();
        scratch.dedup();
        for &i in scratch.iter() {
            let p = self.points[i as usize];
            let t = (p - a).dot(d) / len2;
            if t <= 0.0 || t >= 1.0 {
                continue;
            }
            if (a + d * t - p).length() <= tol && (p - a).length() > tol && (p - b).length() > tol {
                out.push((t, i));
            }
        }
        out.sort_by(|x, y| x.0.total_cmp(&y.0));
    }
}

/// Per part: the merged vertex (key) of each position, or `NONE`.
fn part_keys(parts: &[Part], tol: f64) -> (Vec<DVec3>, Vec<Vec<u32>>) {
    // Rest position of each position of each part, from its corners.
    let mut pts: Vec<DVec3> = Vec::new();
    let mut owner: Vec<(u32, u32)> = Vec::new();
    let mut pos_rest: Vec<Vec<Option<DVec3>>> = Vec::with_capacity(parts.len());
    for (pi, part) in parts.iter().enumerate() {
        let m = part.mesh;
        let mut rest = vec![None; m.positions.len()];
        for (c, &p) in m.corners.iter().enumerate() {
            if let (Some(Some(r)), Some(slot)) = (part.rest.get(c), rest.get_mut(p as usize)) {
                if slot.is_none() && r.is_finite() && m.positions[p as usize].is_finite() {
                    *slot = Some(*r);
                }
            }
        }
        for (i, r) in rest.iter().enumerate() {
            if let Some(r) = r {
                pts.push(*r);
                owner.push((pi as u32, i as u32));
            }
        }
        pos_rest.push(rest);
    }
    let weld = weld_points(&pts, tol);
    let key_rest: Vec<DVec3> = weld
        .representative
        .iter()
        .map(|&i| pts[i as usize])
        .collect();
    let mut keys: Vec<Vec<u32>> = parts
        .iter()
        .map(|p| vec![NONE; p.mesh.positions.len()])
        .collect();
    for (j, &(pi, pos)) in owner.iter().enumerate() {
        keys[pi as usize][pos as usize] = weld.id[j];
    }
    // Within one part a rest position should name one place. Operations
    // that copy texture coordinates to new vertices (the top of an
    // extrusion) break that: the position that moved least keeps the key
    // (the extrusion's base, still where the face was), the others are
    // not tracked.
    let mut winner: FxHashMap<u32, (u32, f64)> = fx_map(0);
    for (pi, part) in parts.iter().enumerate() {
        winner.clear();
        let pos = &part.mesh.positions;
        let ks = &mut keys[pi];
        for (i, &k) in ks.iter().enumerate() {
            if k == NONE {
                continue;
            }
            let disp = (pos[i] - key_rest[k as usize]).length();
            let e = winner.entry(k).or_insert((i as u32, disp));
            if disp < e.1 && (pos[i] - pos[e.0 as usize]).length() > tol {
                *e = (i as u32, disp);
            }
        }
        for i in 0..ks.len() {
            let k = ks[i];
            if k == NONE {
                continue;
            }
            let w = winner[&k].0 as usize;
            if (pos[i] - pos[w]).length() > tol {
                ks[i] = NONE;
            }
        }
    }
    (key_rest, keys)
}

/// Recomposes `parts` into one mesh (see the module docs). Faces keep their
/// materials (slots merged by equality) and groups; texture coordinates and
/// normals follow their corners, interpolated for inserted corners.
pub fn recompose(parts: &[Part]) -> Recomposed {
    let tol = tolerance(
        parts
            .iter()
            .flat_map(|p| p.mesh.positions.iter().copied())
            .chain(parts.iter().flat_map(|p| p.rest.iter().flatten().copied())),
    );
    let (key_rest, keys) = part_keys(parts, tol);
    let nk = key_rest.len();

    // Grid cells about the mean tracked edge length.
    let (mut total, mut count) = (0.0, 0usize);
    for (pi, part) in parts.iter().enumerate() {
        let m = part.mesh;
        for l in &m.loops {
            let idx = m.loop_indices(*l);
            for (i, &a) in idx.iter().enumerate() {
                let b = idx[(i + 1) % idx.len()];
                let (ka, kb) = (keys[pi][a as usize], keys[pi][b as usize]);
                if ka != NONE && kb != NONE && ka != kb {
                    total += (key_rest[ka as usize] - key_rest[kb as usize]).length();
                    count += 1;
                }
            }
        }
    }
    let cell = if count > 0 && total.is_finite() {
        (total / count as f64).max(64.0 * tol)
    } else {
        64.0 * tol
    };
    let grid = PointGrid::new(key_rest, cell);
    let key_rest = &grid.points;
    let mut scratch = Vec::new();
    let mut hits = Vec::new();

    // Offsets: each part once per vertex, by its own vertex or by the edge
    // of its that the vertex lies in.
    let mut offset = vec![DVec3::ZERO; nk];
    let mut stamp = vec![NONE; nk];
    for (pi, part) in parts.iter().enumerate() {
        let m = part.mesh;
        let ks = &keys[pi];
        for (i, &k) in ks.iter().enumerate() {
            if k != NONE && stamp[k as usize] != pi as u32 {
                stamp[k as usize] = pi as u32;
                offset[k as usize] += m.positions[i] - key_rest[k as usize];
            }
        }
        for l in &m.loops {
            let idx = m.loop_indices(*l);
            let n = idx.len();
            let edges = match n {
                0 | 1 => 0,
                2 => 1,
                _ => n,
            };
            for i in 0..edges {
                let (a, b) = (idx[i] as usize, idx[(i + 1) % n] as usize);
                let (ka, kb) = (ks[a], ks[b]);
                if ka == NONE || kb == NONE || ka == kb {
                    continue;
                }
                let (ra, rb) = (key_rest[ka as usize], key_rest[kb as usize]);
                grid.on_segment(ra, rb, tol, &mut scratch, &mut hits);
                if hits.is_empty() {
                    continue;
                }
                let (oa, ob) = (m.positions[a] - ra, m.positions[b] - rb);
                for &(t, k) in &hits {
                    if stamp[k as usize] != pi as u32 {
                        stamp[k as usize] = pi as u32;
                        offset[k as usize] += oa.lerp(ob, t);
                    }
                }
            }
        }
    }

    // The result.
    let mut out = Mesh::new();
    out.materials = Vec::<Material>::new().into();
    out.groups = Vec::<String>::new().into();
    let uv_sets: Vec<bool> = (0..out.uvs.len())
        .map(|s| {
            parts
                .iter()
                .any(|p| p.keep_faces && p.mesh.uvs[s].is_some())
        })
        .collect();
    let with_normals = parts
        .iter()
        .any(|p| p.keep_faces && p.mesh.normals.is_some());
    let mut uvs: Vec<Vec<DVec2>> = vec![Vec::new(); out.uvs.len()];
    let mut normals: Vec<DVec3> = Vec::new();
    // Vertex of each key in the result (only keys some kept face uses).
    let mut key_vertex = vec![NONE; nk];
    let mut rest_out: Vec<Option<DVec3>> = Vec::new();
    let mut loop_buf: Vec<(u32, u32, u32, f64)> = Vec::new(); // (vertex, corner a, corner b, t)
    for (pi, part) in parts.iter().enumerate() {
        if !part.keep_faces {
            continue;
        }
        let m = part.mesh;
        let ks = &keys[pi];
        let mut own_vertex = vec![NONE; m.positions.len()];
        let mat_map = slot_map(&mut out.materials, &m.materials);
        let group_map = slot_map(&mut out.groups, &m.groups);
        // Face tags are kept; edge and vertex tags of the pieces are not
        // carried into the recomposed mesh.
        let tag_map = crate::tags::import_table(&mut out, m);
        for f in 0..m.faces.len() {
            let face = m.faces[f];
            let outer_len = m.outer_loop(f).len;
            if outer_len < 3 && !part.keep_points {
                continue;
            }
            let first_loop = out.loops.len() as u32;
            let mut nloops = 0u32;
            for (li, &l) in m.face_loops(f).iter().enumerate() {
                loop_buf.clear();
                let corners = m.loop_corners(l);
                let n = corners.len();
                for (i, c) in corners.clone().enumerate() {
                    let p = m.corners[c] as usize;
                    let k = ks[p];
                    let v = if k != NONE {
                        let slot = &mut key_vertex[k as usize];
                        if *slot == NONE {
                            *slot = out.positions.len() as u32;
                            out.positions
                                .push(key_rest[k as usize] + offset[k as usize]);
                            rest_out.push(Some(key_rest[k as usize]));
                        }
                        *slot
                    } else {
                        let slot = &mut own_vertex[p];
                        if *slot == NONE {
                            *slot = out.positions.len() as u32;
                            out.positions.push(m.positions[p]);
                            rest_out.push(None);
                        }
                        *slot
                    };
                    loop_buf.push((v, c as u32, c as u32, 0.0));
                    if n < 3 || k == NONE {
                        continue;
                    }
                    // Vertices of other pieces inside this edge.
                    let c2 = corners.start + (i + 1) % n;
                    let k2 = ks[m.corners[c2] as usize];
                    if k2 == NONE || k2 == k {
                        continue;
                    }
                    grid.on_segment(
                        key_rest[k as usize],
                        key_rest[k2 as usize],
                        tol,
                        &mut scratch,
                        &mut hits,
                    );
                    for &(t, kk) in &hits {
                        let slot = &mut key_vertex[kk as usize];
                        if *slot == NONE {
                            *slot = out.positions.len() as u32;
                            out.positions
                                .push(key_rest[kk as usize] + offset[kk as usize]);
                            rest_out.push(Some(key_rest[kk as usize]));
                        }
                        loop_buf.push((*slot, c as u32, c2 as u32, t));
                    }
                }
                // Corners merged into one vertex follow each other: keep one.
                if n >= 3 {
                    loop_buf.dedup_by(|b, a| a.0 == b.0);
                    while loop_buf.len() > 1 && loop_buf[0].0 == loop_buf[loop_buf.len() - 1].0 {
                        loop_buf.pop();
                    }
                    if loop_buf.len() < 3 {
                        if li == 0 {
                            break;
                        }
                        continue;
                    }
                }
                let start = out.corners.len() as u32;
                for &(v, ca, cb, t) in &loop_buf {
                    out.corners.push(v);
                    for (s, set) in uvs.iter_mut().enumerate() {
                        if !uv_sets[s] {
                            continue;
                        }
                        let uv = match &m.uvs[s] {
                            Some(src) => {
                                let a = src.get(ca as usize).copied().unwrap_or_default();
                                let b = src.get(cb as usize).copied().unwrap_or_default();
                                a.lerp(b, t)
                            }
                            None => DVec2::ZERO,
                        };
                        set.push(uv);
                    }
                    if with_normals {
                        let nrm = match &m.normals {
                            Some(src) => {
                                let a = src.get(ca as usize).copied().unwrap_or_default();
                                let b = src.get(cb as usize).copied().unwrap_or_default();
                                a.lerp(b, t).normalize_or(a)
                            }
                            None => DVec3::ZERO,
                        };
                        normals.push(nrm);
                    }
                }
                out.loops.push(Loop {
                    start,
                    len: loop_buf.len() as u32,
                });
                nloops += 1;
            }
            if nloops == 0 {
                continue;
            }
            out.faces.push(Face {
                first_loop,
                loop_count: nloops,
                material: mat_map.get(face.material as usize).copied().unwrap_or(0),
                group: group_map.get(face.group as usize).copied().unwrap_or(0),
                tags: tag_map.get(face.tags as usize).copied().unwrap_or(0),
            });
        }
    }
    for (s, set) in uvs.into_iter().enumerate() {
        if uv_sets[s] {
            out.uvs[s] = Some(set);
        }
    }
    if with_normals {
        out.normals = Some(normals);
    }
    if out.materials.is_empty() {
        out.materials = vec![Material::default()].into();
    }
    if out.groups.is_empty() {
        out.groups = vec![String::new()].into();
    }
    Recomposed {
        mesh: out,
        rest: rest_out,
    }
}

/// The faces where volumes touch removed: faces lying on each other with
/// opposite orientation (the same vertices, positions welded within the
/// tolerance) are both removed, and of faces lying on each other with the
/// same orientation one is kept. Returns the mesh and whether closed parts
/// of it still overlap (a bounding box test between its connected closed
/// pieces), which this engine cannot unite.
///
/// The result's coincident vertices (within the tolerance) are welded into
/// one, so pieces that touch share their vertices.
pub fn unify_touching(mesh: &Mesh) -> (Mesh, bool) {
    let tol = tolerance(mesh.positions.iter().copied());
    let weld = weld_points(&mesh.positions, tol);
    let mut welded = mesh.clone();
    welded.positions = weld
        .representative
        .iter()
        .map(|&i| mesh.positions[i as usize])
        .collect();
    for c in &mut welded.corners {
        *c = weld.id[*c as usize];
    }
    let mesh = &welded;
    let normals: Vec<DVec3> = (0..mesh.faces.len())
        .map(|f| crate::measure::face_normal(mesh, f))
        .collect();
    let mut by_key: FxHashMap<Vec<u32>, Vec<u32>> = fx_map(mesh.faces.len());
    for f in 0..mesh.faces.len() {
        let mut key: Vec<u32> = mesh
            .face_loops(f)
            .iter()
            .flat_map(|&l| mesh.loop_indices(l).iter().map(|&p| weld.id[p as usize]))
            .collect();
        key.sort_unstable();
        key.dedup();
        if key.len() < 3 {
            continue;
        }
        by_key.entry(key).or_default().push(f as u32);
    }
    let mut drop = vec![false; mesh.faces.len()];
    for faces in by_key.values() {
        if faces.len() < 2 {
            continue;
        }
        let mut alive: Vec<u32> = faces.clone();
        // Pair faces facing each other.
        let mut i = 0;
        while i < alive.len() {
            let a = alive[i] as usize;
            let partner =
                (i + 1..alive.len()).find(|&j| normals[a].dot(normals[alive[j] as usize]) < 0.0);
            match partner {
                Some(j) => {
                    drop[a] = true;
                    drop[alive[j] as usize] = true;
                    alive.remove(j);
                    alive.remove(i);
                }
                None => i += 1,
            }
        }
        // Duplicates facing the same way: keep the first.
        for &f in alive.iter().skip(1) {
            drop[f as usize] = true;
        }
    }
    let out = if drop.iter().any(|&d| d) {
        let mut m = mesh.clone();
        retain_faces(&mut m, &drop);
        m
    } else {
        mesh.clone()
    };
    let overlaps = closed_pieces_overlap(&out, tol);
    (out, overlaps)
}

/// Removes the faces marked in `drop` (positions kept).
fn retain_faces(m: &mut Mesh, drop: &[bool]) {
    let src = m.clone();
    m.corners.clear();
    m.loops.clear();
    m.faces.clear();
    for set in m.uvs.iter_mut().flatten() {
        set.clear();
    }
    if let Some(n) = &mut m.normals {
        n.clear();
    }
    for (f, &dropped) in drop.iter().enumerate().take(src.faces.len()) {
        if dropped {
            continue;
        }
        let first_loop = m.loops.len() as u32;
        for &l in src.face_loops(f) {
            let start = m.corners.len() as u32;
            for c in src.loop_corners(l) {
                m.corners.push(src.corners[c]);
                for (s, set) in m.uvs.iter_mut().enumerate() {
                    if let (Some(set), Some(from)) = (set.as_mut(), &src.uvs[s]) {
                        set.push(from.get(c).copied().unwrap_or_default());
                    }
                }
                if let (Some(n), Some(from)) = (m.normals.as_mut(), &src.normals) {
                    n.push(from.get(c).copied().unwrap_or_default());
                }
            }
            m.loops.push(Loop { start, len: l.len });
        }
        let mut face = src.faces[f];
        face.first_loop = first_loop;
        m.faces.push(face);
    }
}

/// Whether two edge-connected pieces of `mesh` that are closed have
/// overlapping bounding boxes (more than touching).
fn closed_pieces_overlap(mesh: &Mesh, tol: f64) -> bool {
    let topo = crate::topology::Topology::with_tolerance(mesh, tol);
    let nf = mesh.faces.len();
    // Union-find of faces over shared edges.
    let mut parent: Vec<u32> = (0..nf as u32).collect();
    fn find(p: &mut [u32], mut x: u32) -> u32 {
        while p[x as usize] != x {
            p[x as usize] = p[p[x as usize] as usize];
            x = p[x as usize];
        }
        x
    }
    for e in 0..topo.edges.len() {
        let uses = topo.edge_uses(e);
        for u in uses.iter().skip(1) {
            let (a, b) = (find(&mut parent, uses[0].face), find(&mut parent, u.face));
            if a != b {
                parent[a as usize] = b;
            }
        }
    }
    // Per piece: bounds, and whether every edge of it is used twice.
    let mut pieces: FxHashMap<u32, (DVec3, DVec3, bool)> = fx_map(0);
    for f in 0..nf {
        let r = find(&mut parent, f as u32);
        let e = pieces.entry(r).or_insert((
            DVec3::splat(f64::INFINITY),
            DVec3::splat(f64::NEG_INFINITY),
            true,
        ));
        for p in mesh.loop_points(mesh.outer_loop(f)) {
            e.0 = e.0.min(p);
            e.1 = e.1.max(p);
        }
    }
    for e in 0..topo.edges.len() {
        let uses = topo.edge_uses(e);
        if uses.len() != 2 {
            let r = find(&mut parent, uses[0].face);
            if let Some(p) = pieces.get_mut(&r) {
                p.2 = false;
            }
        }
    }
    let closed: Vec<(DVec3, DVec3)> = pieces
        .values()
        .filter(|p| p.2)
        .map(|p| (p.0, p.1))
        .collect();
    for i in 0..closed.len() {
        for j in i + 1..closed.len() {
            let (a, b) = (closed[i], closed[j]);
            let lo = a.0.max(b.0);
            let hi = a.1.min(b.1);
            if (hi - lo).cmpgt(DVec3::splat(tol)).all() {
                return true;
            }
        }
    }
    false
}

/// Maps the slots `src` onto equal slots of `dst`, adding missing ones.
fn slot_map<T: Clone + PartialEq>(dst: &mut crate::mesh::SharedVec<T>, src: &[T]) -> Vec<u32> {
    src.iter()
        .map(|m| match dst.iter().position(|d| d == m) {
            Some(i) => i as u32,
            None => {
                dst.push(m.clone());
                dst.len() as u32 - 1
            }
        })
        .collect()
}

/// A value given at the vertices of a mesh, read anywhere on its surface by
/// linear interpolation: at a vertex, along an edge, or inside a face
/// (through the face's triangles). A recomposition nested in another uses
/// it to carry the outer rest positions to the vertices it made.
pub struct SurfaceMap<'a> {
    mesh: &'a Mesh,
    values: &'a [Option<DVec3>],
    tol: f64,
    weld: crate::topology::Weld,
    /// Welded vertex → first position with a value.
    valued: Vec<u32>,
    /// The welded vertices.
    grid: PointGrid,
    face_bounds: Vec<(DVec3, DVec3)>,
}

impl<'a> SurfaceMap<'a> {
    /// `values[i]` is the value at `mesh.positions[i]` (`None`: unknown).
    pub fn new(mesh: &'a Mesh, values: &'a [Option<DVec3>]) -> SurfaceMap<'a> {
        let tol = tolerance(mesh.positions.iter().copied());
        let weld = weld_points(&mesh.positions, tol);
        let mut valued = vec![NONE; weld.count];
        for (i, &v) in weld.id.iter().enumerate() {
            if valued[v as usize] == NONE && values.get(i).is_some_and(|x| x.is_some()) {
                valued[v as usize] = i as u32;
            }
        }
        let grid_points: Vec<DVec3> = weld
            .representative
            .iter()
            .map(|&i| mesh.positions[i as usize])
            .collect();
        let grid = PointGrid::new(grid_points, 1024.0 * tol);
        let face_bounds = (0..mesh.faces.len())
            .map(|f| {
                let mut lo = DVec3::splat(f64::INFINITY);
                let mut hi = DVec3::splat(f64::NEG_INFINITY);
                for p in mesh.loop_points(mesh.outer_loop(f)) {
                    lo = lo.min(p);
                    hi = hi.max(p);
                }
                (lo - DVec3::splat(tol), hi + DVec3::splat(tol))
            })
            .collect();
        SurfaceMap {
            mesh,
            values,
            tol,
            weld,
            valued,
            grid,
            face_bounds,
        }
    }

    fn value(&self, pos: u32) -> Option<DVec3> {
        self.values
            .get(pos as usize)
            .copied()
            .flatten()
            .or_else(|| {
                let v = self.weld.id.get(pos as usize)?;
                let p = self.valued[*v as usize];
                (p != NONE).then(|| self.values[p as usize]).flatten()
            })
    }

    /// The value at point `q` of the surface, or `None` if `q` is not on it
    /// (or the vertices around it have no value).
    pub fn value_at(&self, q: DVec3) -> Option<DVec3> {
        let tol = self.tol;
        // A vertex.
        if let Some(v) = self.grid.near(q, tol) {
            let p = self.valued[v as usize];
            return (p != NONE).then(|| self.values[p as usize]).flatten();
        }
        let m = self.mesh;
        for f in 0..m.faces.len() {
            let (lo, hi) = self.face_bounds[f];
            if q.cmplt(lo).any() || q.cmpgt(hi).any() {
                continue;
            }
            // An edge of the face.
            for &l in m.face_loops(f) {
                let idx = m.loop_indices(l);
                for (i, &a) in idx.iter().enumerate() {
                    let b = idx[(i + 1) % idx.len()];
                    let (pa, pb) = (m.positions[a as usize], m.positions[b as usize]);
                    let d = pb - pa;
                    let len2 = d.length_squared();
                    if len2.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
                        continue;
                    }
                    let t = (q - pa).dot(d) / len2;
                    if (0.0..=1.0).contains(&t) && (pa + d * t - q).length() <= tol {
                        return Some(self.value(a)?.lerp(self.value(b)?, t));
                    }
                }
            }
            // Inside the face: the triangle holding it.
            let mut tris = Vec::new();
            crate::triangulate::triangulate_face(m, f, &mut tris);
            for t in tris {
                let c = t.map(|c| m.corners[c as usize]);
                let [a, b, cc] = c.map(|p| m.positions[p as usize]);
                if let Some(w) = barycentric(a, b, cc, q, tol) {
                    let va = self.value(c[0])?;
                    let vb = self.value(c[1])?;
                    let vc = self.value(c[2])?;
                    return Some(va * w.x + vb * w.y + vc * w.z);
                }
            }
        }
        None
    }
}

/// The barycentric coordinates of `q` in triangle `a b c` if `q` lies on
/// it (within `tol` of its plane, inside up to rounding).
fn barycentric(a: DVec3, b: DVec3, c: DVec3, q: DVec3, tol: f64) -> Option<DVec3> {
    let n = (b - a).cross(c - a);
    let n2 = n.length_squared();
    if n2.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    if ((q - a).dot(n)).abs() / n2.sqrt() > tol {
        return None;
    }
    let wa = (c - b).cross(q - b).dot(n) / n2;
    let wb = (a - c).cross(q - c).dot(n) / n2;
    let wc = 1.0 - wa - wb;
    let eps = -1e-9;
    (wa >= eps && wb >= eps && wc >= eps).then_some(DVec3::new(wa, wb, wc))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cut::split_along_axis;
    use crate::measure::mesh_area;

    /// Rest position of every corner: where it is now.
    fn rest_here(m: &Mesh) -> Vec<Option<DVec3>> {
        m.corners
            .iter()
            .map(|&p| Some(m.positions[p as usize]))
            .collect()
    }

    fn square(w: f64) -> Mesh {
        Mesh::polygon(&[
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(w, 0.0, 0.0),
            DVec3::new(w, 0.0, -w),
            DVec3::new(0.0, 0.0, -w),
        ])
    }

    fn part<'a>(m: &'a Mesh, rest: &'a [Option<DVec3>]) -> Part<'a> {
        Part {
            mesh: m,
            rest,
            keep_faces: true,
            keep_points: true,
        }
    }

    #[test]
    fn split_pieces_weld_and_get_t_junctions() {
        // A square split in x in two, the right half in z in two: the
        // left half gets the right halves' middle vertex on its edge.
        let sq = square(2.0);
        let halves = split_along_axis(&sq, 0, &[1.0]);
        let quarters = split_along_axis(&halves[1], 2, &[-1.0]);
        let pieces = [&halves[0], &quarters[0], &quarters[1]];
        let rests: Vec<_> = pieces.iter().map(|m| rest_here(m)).collect();
        let parts: Vec<Part> = pieces.iter().zip(&rests).map(|(m, r)| part(m, r)).collect();
        let r = recompose(&parts);
        assert_eq!(r.mesh.faces.len(), 3);
        // 4 corners, 3 split points on the square's edges, the middle
        // point of the square: 8 vertices.
        assert_eq!(r.mesh.positions.len(), 8);
        // The left half now has 5 corners (the T-junction inserted).
        assert_eq!(r.mesh.outer_loop(0).len, 5);
        assert!((mesh_area(&r.mesh) - 4.0).abs() < 1e-12);
        assert!(r.rest.iter().all(|x| x.is_some()));
    }

    #[test]
    fn offsets_add_up_at_shared_vertices() {
        // Two unit squares side by side, the right one lifted by 2: the
        // shared edge goes up by 2, the left square's far edge stays.
        let sq = square(2.0);
        let halves = split_along_axis(&sq, 0, &[1.0]);
        let left = halves[0].clone();
        let mut right = halves[1].clone();
        let rest_l = rest_here(&left);
        let rest_r = rest_here(&right);
        right.map_positions(|p| p + DVec3::Y * 2.0);
        let r = recompose(&[part(&left, &rest_l), part(&right, &rest_r)]);
        assert_eq!(r.mesh.positions.len(), 6);
        let ys: Vec<(f64, f64)> = r.mesh.positions.iter().map(|p| (p.x, p.y)).collect();
        for (x, y) in ys {
            let want = if x < 0.5 { 0.0 } else { 2.0 };
            assert!((y - want).abs() < 1e-12, "x {x} y {y}");
        }
    }

    #[test]
    fn a_deleted_piece_still_moves_its_vertices() {
        let sq = square(2.0);
        let halves = split_along_axis(&sq, 0, &[1.0]);
        let left = halves[0].clone();
        let mut right = halves[1].clone();
        let rest_l = rest_here(&left);
        let rest_r = rest_here(&right);
        right.map_positions(|p| p + DVec3::Y);
        let mut pr = part(&right, &rest_r);
        pr.keep_faces = false;
        let r = recompose(&[part(&left, &rest_l), pr]);
        assert_eq!(r.mesh.faces.len(), 1);
        let max_y = r.mesh.positions.iter().map(|p| p.y).fold(0.0, f64::max);
        assert!((max_y - 1.0).abs() < 1e-12);
    }

    #[test]
    fn untracked_pieces_are_appended() {
        let a = square(1.0);
        let b = square(1.0);
        let rest_a = rest_here(&a);
        let none = vec![None; b.corners.len()];
        let r = recompose(&[part(&a, &rest_a), part(&b, &none)]);
        assert_eq!(r.mesh.positions.len(), 8);
        assert_eq!(r.rest.iter().filter(|x| x.is_none()).count(), 4);
    }

    #[test]
    fn an_edge_piece_offsets_its_part_of_a_face() {
        // The face is kept whole; a piece of its first edge, moved by -1
        // in z, pulls the points it holds inward (an inset).
        let face = square(4.0);
        let rest_f = rest_here(&face);
        let mut edge = Mesh::new();
        edge.positions = vec![DVec3::new(1.0, 0.0, 0.0), DVec3::new(3.0, 0.0, 0.0)];
        edge.add_face(&[&[0, 1]], 0);
        let rest_e = rest_here(&edge);
        edge.map_positions(|p| p - DVec3::Z);
        let mut pe = part(&edge, &rest_e);
        pe.keep_points = false;
        let r = recompose(&[part(&face, &rest_f), pe]);
        assert_eq!(r.mesh.faces.len(), 1);
        assert_eq!(r.mesh.outer_loop(0).len, 6);
        // The edge (0..4) now runs 0 -> 1,-1 -> 3,-1 -> 4: a trapezoid of
        // area (4 + 2) / 2 cut away.
        assert!((mesh_area(&r.mesh) - 13.0).abs() < 1e-9);
    }

    #[test]
    fn degenerate_input_does_not_panic() {
        let empty = Mesh::new();
        let r = recompose(&[part(&empty, &[])]);
        assert!(r.mesh.faces.is_empty());
        let mut bad = square(1.0);
        bad.positions[0] = DVec3::NAN;
        let rest = rest_here(&bad);
        let r = recompose(&[part(&bad, &rest), part(&bad, &rest)]);
        assert_eq!(r.mesh.faces.len(), 2);
        // Rest positions shorter than the corners.
        let sq = square(1.0);
        let r = recompose(&[part(&sq, &[Some(DVec3::ZERO)])]);
        assert_eq!(r.mesh.faces.len(), 1);
        let r = recompose(&[]);
        assert!(r.mesh.is_empty());
    }

    #[test]
    fn surface_map_interpolates() {
        let sq = square(2.0);
        let values: Vec<Option<DVec3>> = sq.positions.iter().map(|p| Some(*p * 10.0)).collect();
        let map = SurfaceMap::new(&sq, &values);
        let at = |q: DVec3| map.value_at(q).unwrap();
        assert!((at(DVec3::new(2.0, 0.0, 0.0)) - DVec3::new(20.0, 0.0, 0.0)).length() < 1e-9);
        assert!((at(DVec3::new(1.0, 0.0, 0.0)) - DVec3::new(10.0, 0.0, 0.0)).length() < 1e-9);
        assert!((at(DVec3::new(0.5, 0.0, -1.5)) - DVec3::new(5.0, 0.0, -15.0)).length() < 1e-9);
        assert!(map.value_at(DVec3::new(0.5, 1.0, -1.5)).is_none());
        assert!(map.value_at(DVec3::new(5.0, 0.0, 0.0)).is_none());
    }
}
