//! Trim planes: made by a face component split (`comp(f) { sel : ... }`)
//! along the edges a new face shares with its neighbours, and applied when
//! geometry is inserted (`i`, the primitives) or by `trim()`.
//!
//! A trim plane contains the shared edge and bisects the angle between the
//! two faces, so that geometry inserted on two neighbouring faces (ledges,
//! cornices, a beam wider than its facade) is mitred where they meet instead
//! of intersecting. The part of the geometry on the face's side of the plane
//! is kept, and the cut is left open: no cap faces close a trimmed solid.
//! That is what CityEngine does: the Candler building's ledges and cornices
//! (closed assets, mitred at every corner) have CityEngine's areas only
//! without caps (see `tests/comp_candler.rs`).
//!
//! Planes are fixed in space: they are stored in object coordinates and do
//! not move with the scope, so a shape translated after the split is still
//! cut where the faces met. Each plane is classified by its edge when it is
//! applied: if the edge makes less than 40 degrees with the xz-plane of the
//! shape's pivot *at that moment*, the plane is *horizontal*, otherwise
//! *vertical* (attr_trim.md). Right after the split the pivot is the new
//! face's (its y-axis in the face, across the first edge), so a facade's
//! vertical edges and a roof face's hip edges are vertical; an operation
//! that turns the pivot before the insert (`alignScopeToAxes`, `setPivot`)
//! reclassifies them. CityEngine keeps a cube inserted beside a roof-top
//! face whole after `alignScopeToAxes(y)` (`s(4,0,2) center(xz) extrude(3)
//! comp(f){ top : T }`, `T --> extrude(1) alignScopeToAxes(y) t(4,0,0)
//! primitiveCube()`: area 28, measured with its runtime): the pivot is then
//! level and all four edges of the top face are horizontal. Classifying
//! against the pivot of the shape being split instead breaks the Candler
//! building's match (faces split again after a roof-top split), and
//! `extrude` keeps the planes (op_trim.md: "A roof face is extruded and
//! trimmed"). `trim.vertical` (default true) and `trim.horizontal` (default
//! false) switch the two classes when the planes are applied.

use std::sync::Arc;

use cga_geometry::topology::FxHashMap;
use cga_geometry::{DVec3, Mesh};

use crate::derive::{Interp, RtError, ShapeState};
use crate::expr::OpCall;
use crate::shape::{local_bounds, Geometry, Shape};

/// One trim plane, in object coordinates: the geometry with
/// `normal · (p - point) >= 0` is kept.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrimPlane {
    pub point: DVec3,
    /// Unit normal pointing towards the kept side (into the face).
    pub normal: DVec3,
    /// Unit direction of the generating edge: classifies the plane against
    /// the pivot in force when it is applied ([`TrimPlane::is_vertical`]).
    pub edge: DVec3,
}

impl TrimPlane {
    /// Whether the plane is vertical (switched by `trim.vertical`) for a
    /// shape whose pivot has the y-axis `pivot_y` (unit, same frame as the
    /// plane); else horizontal (`trim.horizontal`).
    pub fn is_vertical(&self, pivot_y: DVec3) -> bool {
        let angle = self
            .edge
            .dot(pivot_y)
            .abs()
            .clamp(0.0, 1.0)
            .asin()
            .to_degrees();
        angle >= HORIZONTAL_LIMIT_DEGREES
    }
}

/// The trim planes of a shape (shared between a shape and its successors).
pub type TrimPlanes = Arc<[TrimPlane]>;

/// How close the trims of a subtree being remembered came to the trim
/// planes of its root (`crate::subtree_memo`): per plane, how far it could
/// move towards the geometry before one of them would cut (+∞: none met
/// it; -∞: one was cut by it).
pub struct PlaneLog {
    planes: Option<TrimPlanes>,
    pub slack: Vec<f64>,
}

impl PlaneLog {
    pub fn new(planes: Option<TrimPlanes>) -> PlaneLog {
        let n = planes.as_ref().map_or(0, |p| p.len());
        PlaneLog {
            planes,
            slack: vec![f64::INFINITY; n],
        }
    }

    /// A trim met plane `i` of `planes` with `slack` to spare.
    pub fn met(&mut self, planes: &TrimPlanes, i: usize, slack: f64) {
        if self.planes.as_ref().is_some_and(|p| Arc::ptr_eq(p, planes)) {
            self.slack[i] = self.slack[i].min(slack);
        }
    }
}

/// Below this angle (degrees) between the generating edge and the pivot's
/// xz-plane a plane is horizontal.
pub const HORIZONTAL_LIMIT_DEGREES: f64 = 40.0;

/// The trim plane through the edge `a -> b` shared by a face and its
/// neighbour. `m_face` and `m_other` are the unit directions in each face's
/// plane, perpendicular to the edge, pointing into that face. The plane
/// bisects the two half-planes: its normal is `m_face - m_other` (which is
/// perpendicular to both the edge and the bisector `m_face + m_other`), so
/// for coplanar faces it is the plane perpendicular to both through the
/// edge. All vectors in one frame; the result is in that frame.
pub fn bisecting_plane(a: DVec3, b: DVec3, m_face: DVec3, m_other: DVec3) -> Option<TrimPlane> {
    let d = (b - a).try_normalize()?;
    let normal = (m_face - m_other)
        .try_normalize()
        .or_else(|| m_face.try_normalize())?;
    Some(TrimPlane {
        point: a,
        normal,
        edge: d,
    })
}

/// `trim()`: applies the shape's active trim planes to its geometry.
pub fn exec(cx: &mut Interp, st: &mut ShapeState, call: &OpCall) -> Result<(), RtError> {
    let need = cx.trim_need(call);
    apply(&mut st.shape, None, need, &mut cx.plane_logs);
    Ok(())
}

/// What a trim has to give: the trimmed geometry, or only a geometry that
/// is empty when the trimmed one would be (a leaf of a generation without
/// a model whose geometry nothing reads: see `crate::geometry_use`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Need {
    Geometry,
    Emptiness,
}

/// Cuts the shape's geometry with its active trim planes, keeping the part
/// on the kept side of every plane. `bounds`: the geometry's bounding box in
/// scope-local coordinates if the caller knows it (inserts do), so that
/// planes that do not touch the geometry cost nothing and the geometry is
/// not even transformed.
///
/// With [`Need::Emptiness`], a geometry with a face that keeps some area
/// inside every cutting plane is left as it is (its trimmed part is not
/// empty).
///
/// `logs` of remembered subtrees (`crate::subtree_memo`) whose root has
/// these planes learn how far each plane tested could move towards the
/// geometry before it cut it.
pub fn apply(shape: &mut Shape, bounds: Option<(DVec3, DVec3)>, need: Need, logs: &mut [PlaneLog]) {
    let Some(planes) = shape.trim.planes.clone() else {
        return;
    };
    let (use_v, use_h) = (shape.trim.vertical, shape.trim.horizontal);
    if !use_v && !use_h {
        return;
    }
    let frame = shape.scope.frame;
    let to_local = frame.axes.transpose();
    let pivot_y = shape.pivot.axes.y_axis;
    let bounds = match bounds {
        Some(b) => Some(b),
        None => local_bounds(shape.geometry.local()),
    };
    let Some((lo, hi)) = bounds else {
        return;
    };
    let scale = (hi - lo)
        .abs()
        .max_element()
        .max(lo.abs().max_element())
        .max(1.0);
    let tol = 1e-9 * scale;
    // Planes in scope-local coordinates that actually cut the box.
    let mut cutting: Vec<(DVec3, f64)> = Vec::new();
    for (i, p) in planes.iter().enumerate() {
        if !(if p.is_vertical(pivot_y) { use_v } else { use_h }) {
            continue;
        }
        let n = to_local * p.normal;
        let offset = n.dot(to_local * (p.point - frame.origin));
        // Smallest and largest n · corner over the box.
        let (mut min, mut max) = (0.0, 0.0);
        for i in 0..3 {
            let (x, y) = (n[i] * lo[i], n[i] * hi[i]);
            min += x.min(y);
            max += x.max(y);
        }
        let kept = min >= offset - tol;
        for log in logs.iter_mut() {
            log.met(
                &planes,
                i,
                if kept {
                    min - offset + tol
                } else {
                    f64::NEG_INFINITY
                },
            );
        }
        if kept {
            continue;
        }
        if max <= offset + tol {
            // Entirely on the trimmed side: nothing is left.
            let mut empty = Mesh::new();
            let src = shape.geometry.local();
            empty.materials = src.materials.clone();
            empty.groups = src.groups.clone();
            shape.set_local_mesh(empty);
            return;
        }
        cutting.push((n, offset));
    }
    if cutting.is_empty() {
        return;
    }
    if need == Need::Emptiness && keeps_a_face(shape, &cutting, tol) {
        return;
    }
    let remembered = RememberedTrim::of(&shape.geometry, &cutting);
    if let Some(done) = remembered.as_ref().and_then(RememberedTrim::recall) {
        shape.geometry = Geometry::new(done);
        return;
    }
    // The first cut reads the shape's mesh, each later one the last cut's.
    let source = shape.geometry.local().clone();
    let mut cut: Option<Mesh> = None;
    for (n, offset) in cutting {
        let mesh = cut.as_ref().unwrap_or(&source);
        if mesh.faces.is_empty() {
            break;
        }
        // Faces of the mesh lying in the plane and facing out go too.
        cut = Some(without_faces_on_cut(
            cga_geometry::part_above_plane(mesh, n, offset),
            n,
            offset,
        ));
    }
    if let Some(mesh) = cut {
        let done = Arc::new(mesh);
        if let Some(r) = remembered {
            r.remember(done.clone());
        }
        shape.geometry = Geometry::new(done);
    }
}

/// A trim of shared geometry (an inserted asset, placed by a map not yet
/// applied) by given planes, remembered per thread with its result: the
/// same asset is trimmed by the same scope-local planes again and again
/// (a ledge at every floor's corner of every building; Candler: 1,380
/// trims of 529 kinds on 20 buildings, each a cut of some 84,000
/// instructions). The result is a function of the mesh's contents, the map
/// and the planes, so a trim recalled is the trim made, bit for bit. The
/// mesh is named by its address and held by the entry, so that the address
/// names no other mesh while the entry lives; meshes of one shape alone
/// (held once) are not remembered, since nothing else can ask for them.
struct RememberedTrim {
    source: Arc<Mesh>,
    key: TrimKey,
}

#[derive(PartialEq, Eq, Hash)]
struct TrimKey {
    mesh: usize,
    to_scope: Option<[u64; 12]>,
    planes: Box<[[u64; 4]]>,
}

/// Trims a thread remembers at most: the table is emptied when full, so
/// memory stays bounded on cities of many assets.
const TRIMS_REMEMBERED: usize = 1 << 10;

/// Per trim: the mesh trimmed (held so that its address stays its own)
/// and the result.
type Trims = FxHashMap<TrimKey, (Arc<Mesh>, Arc<Mesh>)>;

thread_local! {
    static TRIMS: std::cell::RefCell<Trims> = std::cell::RefCell::new(Trims::default());
}

impl RememberedTrim {
    /// The trim of `geometry` by `cutting` (scope-local planes), if its
    /// mesh is shared.
    fn of(geometry: &Geometry, cutting: &[(DVec3, f64)]) -> Option<RememberedTrim> {
        let (mesh, to_scope) = geometry.raw();
        if Arc::strong_count(mesh) < 2 {
            return None;
        }
        let planes = cutting
            .iter()
            .map(|(n, offset)| [n.x, n.y, n.z, *offset].map(f64::to_bits))
            .collect();
        Some(RememberedTrim {
            source: mesh.clone(),
            key: TrimKey {
                mesh: Arc::as_ptr(mesh) as usize,
                to_scope: to_scope.map(|t| t.to_cols_array().map(f64::to_bits)),
                planes,
            },
        })
    }

    /// The result of the same trim made before on this thread.
    fn recall(&self) -> Option<Arc<Mesh>> {
        TRIMS
            .try_with(|t| t.borrow().get(&self.key).map(|(_, done)| done.clone()))
            .ok()
            .flatten()
    }

    /// Remembers `done` as the result of this trim.
    fn remember(self, done: Arc<Mesh>) {
        // Fails only while the thread shuts down: then nothing is kept.
        let _ = TRIMS.try_with(|t| {
            let mut t = t.borrow_mut();
            if t.len() >= TRIMS_REMEMBERED {
                t.clear();
            }
            t.insert(self.key, (self.source, done));
        });
    }
}

/// Whether the part of the shape's geometry (scope-local, read through its
/// pending map without baking it) more than `tol` inside every plane of
/// `cutting` has area: a face without holes clipped by the planes keeps a
/// polygon. Then the trimmed geometry is not empty.
fn keeps_a_face(shape: &Shape, cutting: &[(DVec3, f64)], tol: f64) -> bool {
    let (mesh, to_scope) = shape.geometry.raw();
    let at = |c: u32| {
        let p = mesh.positions[mesh.corners[c as usize] as usize];
        to_scope.map_or(p, |t| t.transform_point3(p))
    };
    let (mut poly, mut next) = (Vec::new(), Vec::new());
    (0..mesh.faces.len()).any(|f| {
        let [outer] = mesh.face_loops(f) else {
            return false;
        };
        poly.clear();
        poly.extend((outer.start..outer.start + outer.len).map(at));
        for &(n, offset) in cutting {
            clip(&poly, n, offset + tol, &mut next);
            std::mem::swap(&mut poly, &mut next);
            if poly.len() < 3 {
                return false;
            }
        }
        // Twice the polygon's area (fan from its first point).
        let o = poly[0];
        let twice = poly
            .windows(2)
            .fold(DVec3::ZERO, |acc, w| acc + (w[0] - o).cross(w[1] - o));
        twice.length() > 2.0 * tol * tol
    })
}

/// The part of the polygon `poly` with `n · p >= offset` (Sutherland and
/// Hodgman), into `out`.
fn clip(poly: &[DVec3], n: DVec3, offset: f64, out: &mut Vec<DVec3>) {
    out.clear();
    let Some(&last) = poly.last() else {
        return;
    };
    let (mut a, mut da) = (last, n.dot(last) - offset);
    for &b in poly {
        let db = n.dot(b) - offset;
        if (da >= 0.0) != (db >= 0.0) {
            out.push(a + (b - a) * (da / (da - db)));
        }
        if db >= 0.0 {
            out.push(b);
        }
        (a, da) = (b, db);
    }
}

/// `mesh` without the faces lying in the plane `n · p = offset` and facing
/// away from `n`: faces of the input lying exactly in the plane and facing
/// out of the kept part, which would lie on the cut (a trimmed shape is
/// open there: the cut is taken without caps).
fn without_faces_on_cut(mut mesh: Mesh, n: DVec3, offset: f64) -> Mesh {
    let scale = mesh
        .positions
        .iter()
        .fold(offset.abs(), |m, p| m.max(p.abs().max_element()))
        .max(1.0);
    let tol = 1e-9 * scale * n.length().max(1.0);
    let on_plane = |p: DVec3| (n.dot(p) - offset).abs() <= tol;
    let keep: Vec<bool> = (0..mesh.faces.len())
        .map(|f| {
            let flat = mesh
                .face_loops(f)
                .iter()
                .all(|&l| mesh.loop_points(l).all(on_plane));
            !(flat && cga_geometry::measure::face_normal(&mesh, f).dot(n) < 0.0)
        })
        .collect();
    if keep.iter().all(|&k| k) {
        return mesh;
    }
    let mut out = Mesh::new();
    out.materials = std::mem::take(&mut mesh.materials);
    out.groups = std::mem::take(&mut mesh.groups);
    out.tags = mesh.tags.clone();
    let mut src = mesh;
    src.materials = out.materials.clone();
    src.groups = out.groups.clone();
    let mut faces = Vec::new();
    for (f, k) in keep.iter().enumerate() {
        if *k {
            faces.push(f);
        }
    }
    copy_faces(&src, &faces, &mut out);
    out
}

/// Copies the faces `faces` of `src` (with their corner attributes) into
/// `out`, which has `src`'s materials and groups; positions are shared as is.
fn copy_faces(src: &Mesh, faces: &[usize], out: &mut Mesh) {
    out.positions = src.positions.clone();
    for (d, s) in out.uvs.iter_mut().zip(&src.uvs) {
        if s.is_some() {
            *d = Some(Vec::new());
        }
    }
    if src.normals.is_some() {
        out.normals = Some(Vec::new());
    }
    // Edge and vertex tags along (the table is `src`'s, shared by the caller).
    if src.edge_tags.is_some() {
        out.edge_tags = Some(Vec::new());
    }
    if src.vertex_tags.is_some() {
        out.vertex_tags = Some(Vec::new());
    }
    for &f in faces {
        let face = src.faces[f];
        let first_loop = out.loops.len() as u32;
        for &l in src.face_loops(f) {
            let start = out.corners.len() as u32;
            for c in src.loop_corners(l) {
                out.corners.push(src.corners[c]);
                for (d, s) in out.uvs.iter_mut().zip(&src.uvs) {
                    if let (Some(d), Some(s)) = (d.as_mut(), s.as_ref()) {
                        d.push(s[c]);
                    }
                }
                if let (Some(d), Some(s)) = (out.normals.as_mut(), src.normals.as_ref()) {
                    d.push(s[c]);
                }
                if let Some(d) = out.edge_tags.as_mut() {
                    d.push(src.edge_tag_index(c));
                }
                if let Some(d) = out.vertex_tags.as_mut() {
                    d.push(src.vertex_tag_index(c));
                }
            }
            out.loops.push(cga_geometry::Loop { start, len: l.len });
        }
        out.faces.push(cga_geometry::Face { first_loop, ..face });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_corner_plane_is_the_diagonal() {
        // Front face (normal +z) and right face (normal +x) of a box meet at
        // the vertical edge x = 1, z = 0. Into the front face from the edge
        // is -x, into the right face is -z.
        let p = bisecting_plane(
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            -DVec3::X,
            -DVec3::Z,
        )
        .unwrap();
        let s = std::f64::consts::FRAC_1_SQRT_2;
        assert!((p.normal - DVec3::new(-s, 0.0, s)).length() < 1e-12);
        assert!(p.is_vertical(DVec3::Y));
        // A horizontal edge of the same face is horizontal.
        let h = bisecting_plane(DVec3::ZERO, DVec3::X, DVec3::Y, -DVec3::Z).unwrap();
        assert!(!h.is_vertical(DVec3::Y));
        // With a pivot whose y-axis is horizontal (the pivot of a top face),
        // the same edges swap classes.
        assert!(!p.is_vertical(DVec3::Z));
        assert!(h.is_vertical(DVec3::X));
    }

    #[test]
    fn coplanar_neighbours_give_the_perpendicular_plane() {
        let p = bisecting_plane(DVec3::ZERO, DVec3::Y, -DVec3::X, DVec3::X).unwrap();
        assert!((p.normal + DVec3::X).length() < 1e-12);
    }

    /// A shape holding `mesh` (a unit cube) scaled by `scale`, in a scope
    /// of size 2 at the origin, with one vertical trim plane through
    /// (1, 0, 0) that cuts it diagonally.
    fn trimmed_shape(mesh: Arc<Mesh>, scale: f64) -> Shape {
        let mut s = crate::lot::initial_shape(&crate::lot::rect(4.0, 3.0), 0, 0);
        s.scope.frame = crate::shape::Frame {
            origin: DVec3::ZERO,
            axes: cga_geometry::DMat3::IDENTITY,
        };
        s.scope.size = DVec3::splat(2.0);
        let mut g = Geometry::new(mesh);
        g.transform(cga_geometry::DAffine3::from_scale(DVec3::splat(scale)));
        s.geometry = g;
        let plane = bisecting_plane(DVec3::X, DVec3::new(1.0, 1.0, 0.0), -DVec3::X, -DVec3::Z);
        s.trim.planes = Some(Arc::from([plane.unwrap()]));
        s
    }

    #[test]
    fn a_trim_of_shared_geometry_is_recalled_as_made() {
        let asset = Arc::new(cga_geometry::primitive::cube(DVec3::ONE));
        // Trimmed as an insert trims: the map not yet applied, the box known.
        let trimmed = |mesh: &Arc<Mesh>, scale: f64| {
            let mut s = trimmed_shape(mesh.clone(), scale);
            let bounds = Some((DVec3::ZERO, DVec3::splat(scale)));
            apply(&mut s, bounds, Need::Geometry, &mut []);
            s.geometry.raw().0.clone()
        };
        let first = trimmed(&asset, 2.0);
        // The plane keeps z >= x - 1: the prism over the triangle (1, 0),
        // (2, 0), (2, 1) of the xz-plane goes, and the cut stays open. Left:
        // 3.5 m² of the bottom and of the top, half of the faces x = 2 and
        // z = 0, the faces x = 0 and z = 2 whole.
        let area = cga_geometry::measure::mesh_area(&first);
        assert!((area - 19.0).abs() < 1e-9, "{area}");
        // The same asset, map and planes again: the trim made, not a new cut.
        let second = trimmed(&asset, 2.0);
        assert!(Arc::ptr_eq(&first, &second));
        // What a cut of a mesh of its own (never remembered) gives, bit for
        // bit.
        let own = trimmed(&Arc::new((*asset).clone()), 2.0);
        assert!(!Arc::ptr_eq(&own, &first));
        let bits = |m: &Mesh| -> Vec<u64> {
            m.positions
                .iter()
                .flat_map(|p| p.to_array().map(f64::to_bits))
                .collect()
        };
        assert_eq!(bits(&own), bits(&first));
        assert_eq!(*own, *first);
        // Another map is another trim.
        let other = trimmed(&asset, 1.5);
        assert!(!Arc::ptr_eq(&other, &first));
        assert_ne!(bits(&other), bits(&first));
    }

    #[test]
    fn degenerate_edge_gives_no_plane() {
        assert!(bisecting_plane(DVec3::ONE, DVec3::ONE, DVec3::X, DVec3::Z).is_none());
    }
}
