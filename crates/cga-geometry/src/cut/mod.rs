//! Cutting meshes with planes: the geometry behind CGA's `split`, and trim
//! planes.
//!
//! Written by hand: no crate cuts indexed polygon meshes with holes and
//! per-corner attributes, and closes the cut with cap polygons.
//!
//! # How a cut works
//!
//! Positions are first welded (coincident within [`mesh_tolerance`]), so
//! that faces sharing an edge share its vertex ids even when the mesh repeats
//! positions. Every vertex gets a signed distance `s` to each plane and is
//! *on* the plane if `|s| <= tol`. A face with no vertex strictly below goes
//! above; with none strictly above, below; with all vertices on the plane, to
//! the side its normal points away from (a top face lying in the plane closes
//! the part below it). Only faces with vertices strictly on both sides are
//! split:
//!
//! - The plane is symbolically pushed up by an infinitesimal amount, so that
//!   on-plane vertices count as below and no edge crosses it at a vertex
//!   ("simulation of simplicity"). An edge from an on-plane vertex to a vertex
//!   above crosses at that vertex itself; an edge between strictly opposite
//!   vertices crosses at a new vertex, created once per welded edge so that
//!   both faces of the edge share it.
//! - The crossings of all loops (outer and holes) are sorted along the cut
//!   line; consecutive pairs bound the segments of the line inside the face
//!   (ties at a shared vertex are ordered by where the pushed plane would cut
//!   the two edges). Walking each loop on one side and jumping along the line
//!   from a crossing to its partner traces every piece's outer boundary.
//!   Holes not crossing the line go to the piece containing them.
//! - Pieces are cleaned: repeated vertices (crossings at on-plane vertices)
//!   are merged, and pieces without area (all vertices on the plane) dropped:
//!   no slivers.
//!
//! If the input is closed (every welded edge used as often in one direction
//! as in the other), each part is closed with caps: the directed edges of a
//! part that lie in a cut plane and are not matched by a reverse edge of the
//! same part are exactly the boundary of the cross-section. They are chained
//! into loops in the plane (at a vertex where several continue, the sharpest
//! turn keeps loops simple), counter-clockwise loops become cap faces and
//! clockwise ones their holes (a cut through a tube gives a ring). Caps take
//! the material and group of the face along their first edge, UVs (0, 0) and,
//! if the mesh has normals, the cap's outward normal. Both parts use the same
//! cap vertices, so volumes add up exactly.
//!
//! Per-corner attributes of new corners are interpolated along the original
//! edge they lie on: every corner of a piece is stored as an original edge
//! `(a, b)` and a parameter `t`, which stays exact through successive cuts of
//! [`split_along_axis`].
//!
//! # Speed
//!
//! Typical calls are small (a building mass into floors, a facade into
//! tiles) and frequent, so the cut allocates nothing but its output: all
//! working arrays live in a per-thread `Bufs` reused from call to call
//! (freed when a huge input made them grow past a bound), pieces are ranges
//! of flat arrays, pieces above a plane wait on an explicit stack instead of
//! a recursion, crossing vertices are found in an open-addressing table
//! cleared in constant time, and cap edges are matched by sorting instead of
//! hashing. The common split (a polygon without holes crossing the plane at
//! two edges, no vertex on it: every convex face) takes a direct path,
//! `Cutter::split_simple`, that gives exactly the general path's result;
//! the tests compare both. And a facade's tiles are the same small mesh
//! again and again but for their texture coordinates: a split of a mesh of
//! up to 32 corners is remembered per thread as its parts' geometry and
//! each corner's source, and replayed for the next mesh with the same
//! positions, faces and planes, carrying that mesh's attributes by the
//! same rule (`replay`; a test compares replayed and fresh cuts).
//! `benches/cut.rs` measures the typical calls.

use std::cell::RefCell;

use glam::DVec3;

use crate::measure::face_normal;
use crate::mesh::Mesh;
use crate::topology::{mesh_tolerance, weld_points_into};
use crate::triangulate::plane_basis;

// The cut in parts: working arrays (`bufs`), pieces being routed
// (`pieces`), crossings and the crossing table (`crossings`), routing faces
// through the planes (`cutter`), splitting one face (`split`), caps of
// closed meshes (`caps`), the output meshes (`build`), polygon helpers
// (`polygon`).
mod bufs;
mod build;
mod caps;
mod crossings;
mod cutter;
mod pieces;
mod polygon;
mod replay;
mod split;
#[cfg(test)]
pub(crate) mod tests;

use bufs::*;
use crossings::*;
use cutter::*;
use pieces::*;
use polygon::*;

/// Cuts `mesh` with the plane `normal · p = offset` into the part below
/// (`normal · p < offset`) and the part above. `normal` need not be of unit
/// length. Closed meshes give closed parts (see the module docs); a zero or
/// non-finite normal returns the whole mesh below.
pub fn cut_by_plane(mesh: &Mesh, normal: DVec3, offset: f64) -> (Mesh, Mesh) {
    let len = normal.length();
    if !(len > 0.0 && len.is_finite() && offset.is_finite()) {
        return (mesh.clone(), empty_like(mesh));
    }
    let mut parts = split_by_parallel_planes(mesh, normal / len, &[offset / len]);
    let above = parts.pop().unwrap_or_else(|| empty_like(mesh));
    let below = parts.pop().unwrap_or_else(|| empty_like(mesh));
    (below, above)
}

/// The part of `mesh` above the plane `normal · p = offset`, as
/// [`cut_by_plane`] gives it but never closed with a cap: for callers that
/// would take the cap off again (a trim plane keeps the cut open), the
/// caps' tracing and triangulating of the cut outline is saved. A zero or
/// non-finite normal gives an empty mesh.
pub fn part_above_plane(mesh: &Mesh, normal: DVec3, offset: f64) -> Mesh {
    let len = normal.length();
    if !(len > 0.0 && len.is_finite() && offset.is_finite()) {
        return empty_like(mesh);
    }
    let mut parts = cut_with(mesh, normal / len, &[offset / len], Some(1));
    parts.pop().unwrap_or_else(|| empty_like(mesh))
}

/// Cuts `mesh` at the planes `p[axis] = cuts[i]` into `cuts.len() + 1`
/// slabs: slab `i` lies between `cuts[i - 1]` and `cuts[i]` (slab 0 below
/// the first cut, the last above the last cut). Empty slabs are empty
/// meshes. `cuts` should be ascending; a smaller value than its predecessor
/// is raised to it. Faces lying inside one slab are copied once, so the work
/// is about linear in faces plus pieces. An `axis` beyond 2 returns the whole
/// mesh as the first slab.
pub fn split_along_axis(mesh: &Mesh, axis: usize, cuts: &[f64]) -> Vec<Mesh> {
    let normal = match axis {
        0 => DVec3::X,
        1 => DVec3::Y,
        2 => DVec3::Z,
        _ => {
            let mut out = vec![mesh.clone()];
            out.extend((0..cuts.len()).map(|_| empty_like(mesh)));
            return out;
        }
    };
    split_by_parallel_planes(mesh, normal, cuts)
}

/// Cuts `mesh` at the parallel planes `normal · p = offsets[i]` (`normal` of
/// unit length, `offsets` ascending) into `offsets.len() + 1` parts, as
/// [`split_along_axis`] does for a general direction.
pub fn split_by_parallel_planes(mesh: &Mesh, normal: DVec3, offsets: &[f64]) -> Vec<Mesh> {
    cut_with(mesh, normal, offsets, None)
}

/// [`split_by_parallel_planes`]: all parts, closed with caps where the mesh
/// is closed (`only_part` None), or the one part asked for, without caps.
fn cut_with(mesh: &Mesh, normal: DVec3, offsets: &[f64], only_part: Option<usize>) -> Vec<Mesh> {
    // The working buffers of the cut are kept per thread and reused: a
    // split of a box into floors is a few microseconds of arithmetic, and
    // allocating its dozens of small buffers anew each time cost several
    // times that. `try_with` fails only while the thread shuts down, and
    // `try_borrow_mut` never fails (nothing here calls back into a cut);
    // both fall back to fresh buffers rather than panic.
    let run = |bufs: &mut Bufs| {
        // All parts of a small mesh: replayed if cut before (see `replay`).
        let key = match only_part {
            None => replay::key_of(mesh, normal, offsets),
            Some(_) => None,
        };
        if let Some(out) = key.as_ref().and_then(|k| bufs.replays.replay(k, mesh)) {
            return out;
        }
        let mut plans = Vec::new();
        let mut cutter = Cutter::new(mesh, normal, offsets, bufs);
        cutter.only_part = only_part;
        cutter.run();
        let out = cutter.build(key.is_some().then_some(&mut plans));
        if let Some(key) = key {
            bufs.replays.remember(key, plans);
        }
        bufs.trim();
        out
    };
    SCRATCH
        .try_with(|cell| match cell.try_borrow_mut() {
            Ok(mut bufs) => run(&mut bufs),
            Err(_) => run(&mut Bufs::default()),
        })
        .unwrap_or_else(|_| run(&mut Bufs::default()))
}

thread_local! {
    static SCRATCH: RefCell<Bufs> = RefCell::new(Bufs::default());
}

/// Forgets this thread's remembered cuts, so that the next cut runs the
/// cutter (tests comparing its paths).
#[cfg(test)]
pub(crate) fn forget_replays() {
    SCRATCH.with(|c| c.borrow_mut().replays = Default::default());
}

/// An empty mesh with the same material slots and groups as `mesh`.
fn empty_like(mesh: &Mesh) -> Mesh {
    // Not `Mesh::new()`: its default material would be built only to be
    // replaced.
    Mesh {
        positions: Vec::new(),
        corners: Vec::new(),
        loops: Vec::new(),
        faces: Vec::new(),
        uvs: Default::default(),
        normals: None,
        materials: mesh.materials.clone(),
        groups: mesh.groups.clone(),
        tags: mesh.tags.clone(),
        edge_tags: None,
        vertex_tags: None,
    }
}

/// A corner of a piece: a vertex (welded id, or a new crossing vertex) and
/// where its attributes come from: the point at parameter `t` of the original
/// edge from corner `a` to corner `b` (`t = 0`: corner `a` itself). `a ==
/// CAP` marks a cap corner.
#[derive(Clone, Copy, Debug, PartialEq)]
struct WCorner {
    v: u32,
    a: u32,
    b: u32,
    t: f64,
}

const CAP: u32 = u32::MAX;
const NONE: u32 = u32::MAX;

/// Faces routed to a part: either a whole original face, or a piece stored in
/// the cutter's piece store.
#[derive(Clone, Copy, Debug)]
enum Item {
    Whole(u32),
    Piece(u32),
}

/// A piece of a face: loops `loops[first..first + count]` of the piece store.
#[derive(Clone, Copy, Debug)]
struct PieceRec {
    face: u32,
    first: u32,
    count: u32,
}
