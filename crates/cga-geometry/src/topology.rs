//! Welding and edge topology: which faces share which edges.
//!
//! Meshes may repeat a position under several indices (assets, meshes
//! merged from several shapes), so topology is computed on *welded* vertex
//! ids: positions closer than a tolerance count as one vertex. Edges are
//! numbered in the order CGA's `comp(e)` uses: index 0 is the first edge of
//! the first face, then the second edge of the first face, and so on; an edge
//! shared with an earlier face is skipped on its second encounter.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

use glam::DVec3;

use crate::mesh::Mesh;

/// A fast non-cryptographic hasher (the multiply-rotate scheme of rustc's
/// `FxHasher`) for the integer keys of the geometry maps, which SipHash
/// would make several times slower. Keys are not attacker-controlled.
/// Also used by the interpreter's caches.
#[derive(Default, Clone, Copy)]
pub struct FxHasher(u64);

impl Hasher for FxHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut b = [0u8; 8];
            b[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(b));
        }
    }
    #[inline]
    fn write_u32(&mut self, i: u32) {
        self.write_u64(i as u64);
    }
    #[inline]
    fn write_u64(&mut self, i: u64) {
        self.0 = (self.0.rotate_left(5) ^ i).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
    #[inline]
    fn write_i64(&mut self, i: i64) {
        self.write_u64(i as u64);
    }
    #[inline]
    fn write_usize(&mut self, i: usize) {
        self.write_u64(i as u64);
    }
    #[inline]
    fn finish(&self) -> u64 {
        self.0
    }
}

/// A `HashMap` with [`FxHasher`].
pub type FxHashMap<K, V> = HashMap<K, V, BuildHasherDefault<FxHasher>>;

pub fn fx_map<K, V>(capacity: usize) -> FxHashMap<K, V> {
    FxHashMap::with_capacity_and_hasher(capacity, Default::default())
}

/// The tolerance used by this crate to decide that two points coincide or
/// that a point lies on a plane: 1e-9 relative to the magnitude of the
/// coordinates (at least 1e-9 absolute), far below any modelling scale and
/// far above the rounding of f64 arithmetic on such coordinates.
pub fn mesh_tolerance(mesh: &Mesh) -> f64 {
    let m = mesh
        .positions
        .iter()
        .fold(0.0f64, |m, p| m.max(p.abs().max_element()));
    1e-9 * m.max(1.0)
}

/// Welded vertex ids for a list of points.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Weld {
    /// For each input point, its vertex id in `0..count`. Ids are given in
    /// order of first appearance, so the first point of each cluster names it.
    pub id: Vec<u32>,
    /// Number of distinct vertices.
    pub count: usize,
    /// For each vertex id, the index of the input point that represents it.
    pub representative: Vec<u32>,
}

fn cell_key(p: DVec3, cell: f64) -> [i64; 3] {
    // `+ 0.0` turns -0.0 into 0.0 so that both land in the same cell.
    [p.x, p.y, p.z].map(|c| ((c + 0.0) / cell).floor() as i64)
}

/// Welds points closer than `tol` (per coordinate, a box test) to the first
/// of them. `tol <= 0` welds only bitwise-equal coordinates. Runs in linear
/// time with a hash grid of cell size `tol`. Clusters are formed greedily: a
/// point joins the first earlier representative within `tol`.
pub fn weld_points(points: &[DVec3], tol: f64) -> Weld {
    let mut id = Vec::with_capacity(points.len());
    let mut representative: Vec<u32> = Vec::new();
    weld_points_into(points, tol, &mut id, &mut representative);
    Weld {
        count: representative.len(),
        id,
        representative,
    }
}

/// Up to this many points, [`weld_points_into`] first tries a plain scan of
/// the representatives: cheaper than hashing for the boxes and quads most
/// shapes are.
const SMALL_WELD: usize = 40;

/// [`weld_points`] into reused buffers: `id` and `representative` are
/// cleared and filled as the fields of [`Weld`] are.
pub(crate) fn weld_points_into(
    points: &[DVec3],
    tol: f64,
    id: &mut Vec<u32>,
    representative: &mut Vec<u32>,
) {
    id.clear();
    representative.clear();
    if points.len() <= SMALL_WELD && weld_small(points, tol, id, representative) {
        return;
    }
    weld_grid(points, tol, id, representative);
}

/// Welding with a hash grid (or, for `tol <= 0`, a hash of the bits).
fn weld_grid(points: &[DVec3], tol: f64, id: &mut Vec<u32>, representative: &mut Vec<u32>) {
    id.clear();
    representative.clear();
    if tol <= 0.0 || !tol.is_finite() {
        let mut seen: FxHashMap<[u64; 3], u32> = fx_map(points.len());
        for (i, p) in points.iter().enumerate() {
            let key = [p.x + 0.0, p.y + 0.0, p.z + 0.0].map(f64::to_bits);
            let next = representative.len() as u32;
            let v = *seen.entry(key).or_insert(next);
            if v == next {
                representative.push(i as u32);
            }
            id.push(v);
        }
    } else {
        // Cells much larger than `tol`: a point within `tol` of another lies
        // in the same cell, or in a neighbour across a cell boundary closer
        // than `tol`, so most points need a single lookup. `head` holds the
        // first representative of each cell, `next` chains further ones.
        let cell = tol * 1024.0;
        let mut head: FxHashMap<[i64; 3], u32> = fx_map(points.len());
        let mut next: Vec<u32> = Vec::new();
        for (i, &p) in points.iter().enumerate() {
            let k = cell_key(p, cell);
            let mut range = [(0i64, 0i64); 3];
            for a in 0..3 {
                let lo = k[a] as f64 * cell;
                let c = p[a] + 0.0;
                range[a] = (
                    if c - lo <= tol { -1 } else { 0 },
                    if lo + cell - c <= tol { 1 } else { 0 },
                );
            }
            let mut found = None;
            'search: for dx in range[0].0..=range[0].1 {
                for dy in range[1].0..=range[1].1 {
                    for dz in range[2].0..=range[2].1 {
                        let kk = [k[0] + dx, k[1] + dy, k[2] + dz];
                        let mut r = head.get(&kk).copied().unwrap_or(u32::MAX);
                        while r != u32::MAX {
                            let q = points[representative[r as usize] as usize];
                            if (q - p).abs().max_element() <= tol {
                                found = Some(r);
                                break 'search;
                            }
                            r = next[r as usize];
                        }
                    }
                }
            }
            let v = match found {
                Some(v) => v,
                None => {
                    let v = representative.len() as u32;
                    representative.push(i as u32);
                    let h = head.entry(k).or_insert(u32::MAX);
                    next.push(*h);
                    *h = v;
                    v
                }
            };
            id.push(v);
        }
    }
}

/// Welding by scanning all representatives, for few points. It only
/// decides the plain case, where every point is either bitwise equal (up to
/// the sign of zero) to one representative and farther than `tol` from all
/// others, or farther than `tol` from all: there the hash grid finds the
/// same clusters. Anything closer (points within `tol` but not equal, or
/// near several representatives) returns false, leaving the grid to decide,
/// so the result never depends on the path taken.
fn weld_small(
    points: &[DVec3],
    tol: f64,
    id: &mut Vec<u32>,
    representative: &mut Vec<u32>,
) -> bool {
    let exact = tol <= 0.0 || !tol.is_finite();
    for (i, &p) in points.iter().enumerate() {
        let p = p + DVec3::ZERO;
        let mut found = u32::MAX;
        for (r, &ri) in representative.iter().enumerate() {
            let q = points[ri as usize] + DVec3::ZERO;
            let equal = q.x.to_bits() == p.x.to_bits()
                && q.y.to_bits() == p.y.to_bits()
                && q.z.to_bits() == p.z.to_bits();
            if equal {
                if found != u32::MAX {
                    return false;
                }
                found = r as u32;
            } else if !exact && (q - p).abs().max_element() <= tol {
                return false;
            }
        }
        if found == u32::MAX {
            found = representative.len() as u32;
            representative.push(i as u32);
        }
        id.push(found);
    }
    true
}

/// One use of an edge by a face: the corner the edge starts at (the edge runs
/// from `corner` to the next corner of its loop).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EdgeUse {
    pub face: u32,
    pub corner: u32,
    /// True if this use runs against the edge's direction (`Edge::v[1]` to `v[0]`).
    pub reversed: bool,
}

/// A unique undirected edge between two welded vertices.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Edge {
    /// Welded vertex ids, in the direction of the first face that uses it.
    pub v: [u32; 2],
    /// Position indices of the two ends (from the first use).
    pub p: [u32; 2],
}

/// Edge topology of a mesh on welded vertices.
#[derive(Clone, Debug, Default)]
pub struct Topology {
    /// Welded vertex id of every position of the mesh.
    pub weld: Weld,
    /// Unique edges, in `comp(e)` order.
    pub edges: Vec<Edge>,
    /// For each corner, the edge from it to the next corner of its loop;
    /// `u32::MAX` where that edge has zero length (both ends weld together).
    pub edge_of_corner: Vec<u32>,
    /// `uses[use_start[e]..use_start[e + 1]]` are the uses of edge `e`.
    pub use_start: Vec<u32>,
    pub uses: Vec<EdgeUse>,
}

impl Topology {
    /// Computes the topology with the default tolerance ([`mesh_tolerance`]).
    pub fn new(mesh: &Mesh) -> Topology {
        Topology::with_tolerance(mesh, mesh_tolerance(mesh))
    }

    pub fn with_tolerance(mesh: &Mesh, tol: f64) -> Topology {
        let weld = weld_points(&mesh.positions, tol);
        let mut index: FxHashMap<(u32, u32), u32> = fx_map(mesh.corners.len());
        let mut edges = Vec::new();
        let mut edge_of_corner = vec![u32::MAX; mesh.corners.len()];
        let mut counts: Vec<u32> = Vec::new();
        for face in 0..mesh.faces.len() {
            for &l in mesh.face_loops(face) {
                let r = mesh.loop_corners(l);
                for c in r.clone() {
                    let n = if c + 1 == r.end { r.start } else { c + 1 };
                    let (pa, pb) = (mesh.corners[c], mesh.corners[n]);
                    let (a, b) = (weld.id[pa as usize], weld.id[pb as usize]);
                    if a == b {
                        continue;
                    }
                    let key = (a.min(b), a.max(b));
                    let e = *index.entry(key).or_insert_with(|| {
                        edges.push(Edge {
                            v: [a, b],
                            p: [pa, pb],
                        });
                        counts.push(0);
                        (edges.len() - 1) as u32
                    });
                    counts[e as usize] += 1;
                    edge_of_corner[c] = e;
                }
            }
        }
        // Counting sort of the uses by edge (keeps face/corner order per edge).
        let mut use_start = Vec::with_capacity(edges.len() + 1);
        let mut acc = 0u32;
        for &c in &counts {
            use_start.push(acc);
            acc += c;
        }
        use_start.push(acc);
        let mut fill = use_start.clone();
        let mut uses = vec![
            EdgeUse {
                face: 0,
                corner: 0,
                reversed: false
            };
            acc as usize
        ];
        for face in 0..mesh.faces.len() {
            for &l in mesh.face_loops(face) {
                for c in mesh.loop_corners(l) {
                    let e = edge_of_corner[c];
                    if e == u32::MAX {
                        continue;
                    }
                    let a = weld.id[mesh.corners[c] as usize];
                    let slot = &mut fill[e as usize];
                    uses[*slot as usize] = EdgeUse {
                        face: face as u32,
                        corner: c as u32,
                        reversed: a != edges[e as usize].v[0],
                    };
                    *slot += 1;
                }
            }
        }
        Topology {
            weld,
            edges,
            edge_of_corner,
            use_start,
            uses,
        }
    }

    /// The uses of edge `e` by faces, in face order.
    pub fn edge_uses(&self, e: usize) -> &[EdgeUse] {
        &self.uses[self.use_start[e] as usize..self.use_start[e + 1] as usize]
    }

    /// True if the edge is used by at most one face corner (a border edge in
    /// CGA's sense: "connected to only one face").
    pub fn is_border(&self, e: usize) -> bool {
        self.use_start[e + 1] - self.use_start[e] <= 1
    }

    /// Number of distinct welded vertices referenced by the mesh's corners.
    pub fn referenced_vertex_count(&self, mesh: &Mesh) -> usize {
        let mut seen = vec![false; self.weld.count];
        let mut n = 0;
        for &p in &mesh.corners {
            let v = self.weld.id[p as usize] as usize;
            if !seen[v] {
                seen[v] = true;
                n += 1;
            }
        }
        n
    }

    /// True if the mesh has at least one face of three or more corners and
    /// every edge is used exactly twice, once in each direction, by such
    /// faces (a watertight, consistently oriented surface). Faces of one or
    /// two corners (edge and vertex shapes) make a mesh not closed.
    pub fn is_closed(&self, mesh: &Mesh) -> bool {
        if mesh.faces.is_empty() {
            return false;
        }
        if (0..mesh.faces.len()).any(|f| mesh.outer_loop(f).len < 3) {
            return false;
        }
        (0..self.edges.len()).all(|e| {
            let u = self.edge_uses(e);
            u.len() == 2 && u[0].reversed != u[1].reversed
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        /// The scan for few points agrees with the grid whenever it
        /// decides: points on a coarse lattice (so many coincide, up to
        /// the sign of zero), some moved by less than the tolerance.
        #[test]
        fn small_welding_agrees_with_the_grid(
            pts in prop::collection::vec((prop::array::uniform3(-2i32..3), 0u8..4), 1..40),
            tol in prop::sample::select(vec![0.0, 1e-9, 1e-3]),
        ) {
            let points: Vec<DVec3> = pts
                .iter()
                .map(|(c, jitter)| {
                    let p = DVec3::new(c[0] as f64, c[1] as f64, c[2] as f64) * 0.5;
                    match jitter {
                        0 => p + DVec3::X * 0.3 * tol,
                        1 => -p,
                        _ => p,
                    }
                })
                .collect();
            let (mut id, mut rep) = (Vec::new(), Vec::new());
            let decided = weld_small(&points, tol, &mut id, &mut rep);
            let (mut gid, mut grep) = (Vec::new(), Vec::new());
            weld_grid(&points, tol, &mut gid, &mut grep);
            if decided {
                prop_assert_eq!(&id, &gid);
                prop_assert_eq!(&rep, &grep);
            }
            // Whichever path it takes, `weld_points` gives the grid's result.
            let w = weld_points(&points, tol);
            prop_assert_eq!(w.id, gid);
            prop_assert_eq!(w.representative, grep);
        }
    }

    #[test]
    fn welding_exact_and_with_tolerance() {
        let p = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(-0.0, 0.0, 0.0),
            DVec3::new(1.0, 2.0, 3.0),
            DVec3::new(1.0 + 1e-12, 2.0, 3.0),
            DVec3::new(0.0, 0.0, 0.0),
        ];
        let exact = weld_points(&p, 0.0);
        assert_eq!(exact.id, vec![0, 0, 1, 2, 0]);
        assert_eq!(exact.count, 3);
        let tol = weld_points(&p, 1e-9);
        assert_eq!(tol.id, vec![0, 0, 1, 1, 0]);
        assert_eq!(tol.representative, vec![0, 2]);
        // Points straddling a hash cell boundary still weld.
        let t = 1e-3;
        let cell = t * 1024.0;
        let a = DVec3::splat(3.0 * cell - 0.25 * t);
        let b = a + DVec3::splat(0.5 * t);
        let c = a + DVec3::new(2.0 * t, 0.0, 0.0);
        assert_eq!(weld_points(&[a, b, c], t).id, vec![0, 0, 1]);
    }

    #[test]
    fn few_points_are_welded_by_the_scan() {
        // The 24 corners of a cube (each position repeated per face, one
        // with a negative zero) weld to 8 without the grid.
        let cube = crate::primitive::cube(DVec3::new(1.0, 2.0, 3.0));
        let mut points: Vec<DVec3> = cube
            .corners
            .iter()
            .map(|&c| cube.positions[c as usize])
            .collect();
        assert_eq!(points.len(), 24);
        let zero_x = points.iter().position(|p| p.x == 0.0).unwrap();
        points[zero_x].x = -0.0;
        let (mut id, mut rep) = (Vec::new(), Vec::new());
        assert!(weld_small(&points, 1e-9, &mut id, &mut rep));
        assert_eq!(rep.len(), 8);
        assert_eq!(weld_points(&points, 1e-9).id, id);
        // A point within the tolerance but not equal is left to the grid.
        points.push(points[3] + DVec3::X * 1e-12);
        assert!(!weld_small(&points, 1e-9, &mut id, &mut rep));
        assert_eq!(weld_points(&points, 1e-9).count, 8);
    }

    #[test]
    fn edges_in_comp_e_order_with_uses() {
        // Two triangles sharing the edge 1-2.
        let mut m = Mesh::new();
        m.positions.extend([
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(0.0, 0.0, -1.0),
            DVec3::new(1.0, 0.0, -1.0),
        ]);
        m.add_face(&[&[0, 1, 2]], 0);
        m.add_face(&[&[1, 3, 2]], 0);
        let t = Topology::new(&m);
        let ends: Vec<[u32; 2]> = t.edges.iter().map(|e| e.v).collect();
        assert_eq!(ends, vec![[0, 1], [1, 2], [2, 0], [1, 3], [3, 2]]);
        assert_eq!(t.edge_uses(1).len(), 2);
        assert_eq!(
            t.edge_uses(1)[1],
            EdgeUse {
                face: 1,
                corner: 5,
                reversed: true
            }
        );
        assert!(t.is_border(0) && !t.is_border(1));
        assert_eq!(t.edge_of_corner, vec![0, 1, 2, 3, 4, 1]);
    }
}
