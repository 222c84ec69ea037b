//! The shape: geometry, scope, pivot, material and the attributes operations set.
//!
//! Frames are kept in object (lot) coordinates as an origin and a rotation
//! matrix, so that `t`, `r` and the scope queries never convert Euler angles.
//! The geometry is stored relative to the scope ("scope-local": a vertex `v`
//! is at `scope.origin + scope.axes * v`) behind a lazy affine map, so moving,
//! rotating and scaling a shape are O(1): vertices are only touched when an
//! operation needs them (a cut, a query, the output).

use std::cell::Cell;
use std::sync::Arc;

use cga_geometry::{DAffine3, DMat3, DVec3, Mesh};
use cga_value::Value;

use crate::material_attr::MaterialOverrides;
use crate::program::AttrId;

/// An orthonormal, right-handed frame in object coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    pub origin: DVec3,
    /// Columns are the x, y and z axes.
    pub axes: DMat3,
}

impl Frame {
    pub const IDENTITY: Frame = Frame {
        origin: DVec3::ZERO,
        axes: DMat3::IDENTITY,
    };

    /// Object coordinates of a point given in this frame.
    pub fn to_object(&self, p: DVec3) -> DVec3 {
        self.origin + self.axes * p
    }

    /// This frame's coordinates of a point given in object coordinates.
    pub fn to_local(&self, p: DVec3) -> DVec3 {
        self.axes.transpose() * (p - self.origin)
    }

    pub fn affine(&self) -> DAffine3 {
        DAffine3::from_mat3_translation(self.axes, self.origin)
    }
}

/// The scope: an oriented box from `frame.origin` along the frame's axes.
/// Sizes may be zero (flat shapes) or negative (mirrored by `s`).
///
/// `rot` holds the Euler angles relative to the pivot (`scope.r`) as CGA
/// keeps them: `r()` adds to these angles, which is not the same as
/// composing rotations, so they are stored rather than recomputed. Invariant:
/// `frame.axes == pivot.axes * euler_to_mat(rot)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scope {
    pub frame: Frame,
    pub size: DVec3,
    pub rot: DVec3,
}

impl Scope {
    /// Sets the scope axes (object coordinates) and the angles relative to `pivot_axes`.
    pub fn set_axes(&mut self, pivot_axes: &DMat3, axes: DMat3) {
        self.frame.axes = axes;
        self.rot = relative_euler(pivot_axes, &axes);
    }

    pub fn center(&self) -> DVec3 {
        self.frame.to_object(self.size * 0.5)
    }
}

/// A shape's geometry: a shared mesh and the map from its coordinates to
/// scope-local coordinates (`None` = identity).
#[derive(Clone, Debug)]
pub struct Geometry {
    mesh: Arc<Mesh>,
    to_scope: Option<DAffine3>,
}

impl Geometry {
    pub fn new(mesh: Arc<Mesh>) -> Geometry {
        Geometry {
            mesh,
            to_scope: None,
        }
    }

    /// No geometry (a shared empty mesh: no allocation).
    pub fn empty() -> Geometry {
        Geometry::new(empty_mesh())
    }

    /// A stand-in for geometry nothing will read but that is not empty (a
    /// part of a generation without a model whose rules read nothing of
    /// it: only whether it is empty shows, in the count of leaves): one
    /// shared triangle per thread.
    pub fn unread() -> Geometry {
        thread_local! {
            static TRIANGLE: Arc<Mesh> = Arc::new(Mesh::polygon(&[DVec3::ZERO, DVec3::X, DVec3::Y]));
        }
        Geometry::new(
            TRIANGLE
                .try_with(|m| m.clone())
                .unwrap_or_else(|_| Arc::new(Mesh::polygon(&[DVec3::ZERO, DVec3::X, DVec3::Y]))),
        )
    }

    /// Applies `m` (scope-local → scope-local) after the current map.
    pub fn transform(&mut self, m: DAffine3) {
        self.to_scope = Some(match self.to_scope {
            Some(t) => m * t,
            None => m,
        });
    }

    /// The mesh in scope-local coordinates, transforming it if needed (once:
    /// the result replaces the stored mesh). A mesh no other shape shares is
    /// transformed where it is, without a copy.
    pub fn local(&mut self) -> &Arc<Mesh> {
        self.bake();
        &self.mesh
    }

    /// The mesh in scope-local coordinates for editing: copied first only if
    /// another shape shares it (an operation that changes UVs or winding of
    /// a freshly cut piece edits it in place).
    pub fn local_mut(&mut self) -> &mut Mesh {
        self.bake();
        Arc::make_mut(&mut self.mesh)
    }

    /// Applies the pending map to the vertices.
    fn bake(&mut self) {
        if let Some(t) = self.to_scope.take() {
            if t != DAffine3::IDENTITY {
                match Arc::get_mut(&mut self.mesh) {
                    Some(m) => transform_in_place(m, &t),
                    None => self.mesh = transformed_shared(&self.mesh, &t),
                }
            }
        }
    }

    /// The stored mesh and its map, without transforming anything.
    pub fn raw(&self) -> (&Arc<Mesh>, Option<&DAffine3>) {
        (&self.mesh, self.to_scope.as_ref())
    }

    pub fn is_empty(&self) -> bool {
        self.mesh.faces.is_empty()
    }
}

/// A copy of `mesh` with positions (and normals) mapped by `t`. A map that
/// mirrors (negative determinant) also reverses the faces so that they keep
/// facing outwards.
pub fn transformed(mesh: &Mesh, t: &DAffine3) -> Mesh {
    let mut m = mesh.clone();
    transform_in_place(&mut m, t);
    m
}

/// [`transformed`] for a mesh other shapes share (an inserted asset),
/// remembered for the last few meshes and maps: the windows of a facade
/// are one asset placed by one map, and the result is the same mesh each
/// time. The entries hold both meshes, so an address names one mesh.
fn transformed_shared(mesh: &Arc<Mesh>, t: &DAffine3) -> Arc<Mesh> {
    type Entry = (Arc<Mesh>, [u64; 12], Arc<Mesh>);
    thread_local! {
        static BAKED: std::cell::RefCell<(Vec<Entry>, usize)> = const {
            std::cell::RefCell::new((Vec::new(), 0))
        };
    }
    const ENTRIES: usize = 8;
    let key = t.to_cols_array().map(f64::to_bits);
    BAKED.with(|b| {
        let (entries, next) = &mut *b.borrow_mut();
        if let Some((_, _, done)) = entries
            .iter()
            .find(|(m, k, _)| Arc::ptr_eq(m, mesh) && *k == key)
        {
            return done.clone();
        }
        let done = Arc::new(transformed(mesh, t));
        let entry = (mesh.clone(), key, done.clone());
        if entries.len() < ENTRIES {
            entries.push(entry);
        } else {
            entries[*next] = entry;
            *next = (*next + 1) % ENTRIES;
        }
        done
    })
}

/// [`transformed`] without the copy.
pub fn transform_in_place(mesh: &mut Mesh, t: &DAffine3) {
    cga_geometry::transform::transform(mesh, t);
    if t.matrix3.determinant() < 0.0 {
        cga_geometry::transform::reverse_faces(mesh);
    }
}

/// Trim state of a shape: the switches `trim.horizontal` and
/// `trim.vertical`, and the trim planes the last face component split gave
/// the shape or an ancestor (see `crate::trim`; shared, so copies are cheap).
#[derive(Clone, Debug, PartialEq)]
pub struct TrimFlags {
    pub horizontal: bool,
    pub vertical: bool,
    pub planes: Option<crate::trim::TrimPlanes>,
}

impl Default for TrimFlags {
    fn default() -> Self {
        TrimFlags {
            horizontal: false,
            vertical: true,
            planes: None,
        }
    }
}

/// What the last component split recorded (`comp.sel`, `comp.index`, `comp.total`).
#[derive(Clone, Debug, PartialEq)]
pub struct CompInfo {
    pub sel: Arc<str>,
    pub index: f64,
    pub total: f64,
}

/// A texture projection set up by `setupProjection` (for `projectUV`), kept
/// in object coordinates so that the shapes derived from the one that set it
/// up (the tiles of a facade) get continuous texture coordinates.
///
/// A point `p` with coordinates `(a, b, c)` along the frame's u, v and w
/// axes gets `u = (a - offset.x - uw * c) / size.x` and
/// `v = (b - offset.y) / size.y` (see `ops::texturing`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projection {
    /// Origin and axes (columns u, v, w = u × v) of the uvw system.
    pub frame: Frame,
    /// Texture tile width and height in scene units (negative: mirrored).
    pub size: cga_geometry::DVec2,
    /// Offsets along u and v in scene units.
    pub offset: cga_geometry::DVec2,
    /// How much the w coordinate adds to u (`uwFactor`).
    pub uw: f64,
}

impl Projection {
    /// The texture coordinates of a point given in object coordinates.
    pub fn uv(&self, p: DVec3) -> cga_geometry::DVec2 {
        let l = self.frame.to_local(p);
        cga_geometry::DVec2::new(
            (l.x - self.offset.x - self.uw * l.z) / self.size.x,
            (l.y - self.offset.y) / self.size.y,
        )
    }
}

#[derive(Clone, Debug)]
pub struct Shape {
    pub scope: Scope,
    pub pivot: Frame,
    pub geometry: Geometry,
    /// The centre of the scope of the shape this one was derived from, in
    /// object coordinates (all `center` needs of it: a whole scope here
    /// made every shape 120 bytes larger, and shapes are moved often).
    pub parent_center: DVec3,
    pub material: Arc<MaterialOverrides>,
    /// Attribute values set on this shape (or an ancestor) with `set`.
    pub attrs: Option<Arc<Vec<(AttrId, Value)>>>,
    pub split_index: f64,
    pub split_total: f64,
    pub comp: Option<Arc<CompInfo>>,
    pub trim: TrimFlags,
    pub projections: Option<Arc<[Option<Projection>; 10]>>,
    /// Random stream state (`rand`, `p`, stochastic rules).
    pub rng: Cell<u64>,
    /// The `seedian` attribute: the initial shape's seed, inherited; setting
    /// it restarts the random stream.
    pub seedian: f64,
    /// The shape's symbol (rule or leaf name), an index into `Program::symbols`.
    pub name: u32,
    /// The shape's node in the shape tree kept for context queries
    /// (`crate::context`): its address tells ancestors and descendants
    /// apart across the two derivation passes. 0 (the root) in programs
    /// without context queries.
    pub ctx: u32,
}

impl Shape {
    /// A copy of the shape with `geometry` in place of its own: what
    /// `clone` and then setting the geometry give, without taking and
    /// handing back a reference to the geometry replaced (two atomic
    /// operations for every split part).
    pub fn clone_with_geometry(&self, geometry: Geometry) -> Shape {
        Shape {
            scope: self.scope,
            pivot: self.pivot,
            geometry,
            parent_center: self.parent_center,
            material: self.material.clone(),
            attrs: self.attrs.clone(),
            split_index: self.split_index,
            split_total: self.split_total,
            comp: self.comp.clone(),
            trim: self.trim.clone(),
            projections: self.projections.clone(),
            rng: self.rng.clone(),
            seedian: self.seedian,
            name: self.name,
            ctx: self.ctx,
        }
    }

    /// A shape with nothing set: no geometry, the identity frame for scope
    /// and pivot, its own default material, no attributes, component or
    /// projection info. The initial shape starts from it, and it is the
    /// husk a shape's state keeps once the shape went on as its own
    /// successor (`Interp::last_child`), sharing nothing other shapes change.
    pub(crate) fn blank() -> Shape {
        let frame = Frame {
            origin: DVec3::ZERO,
            axes: DMat3::IDENTITY,
        };
        Shape {
            scope: Scope {
                frame,
                size: DVec3::ZERO,
                rot: DVec3::ZERO,
            },
            pivot: frame,
            geometry: Geometry::empty(),
            parent_center: DVec3::ZERO,
            material: Arc::new(MaterialOverrides::default()),
            attrs: None,
            split_index: 0.0,
            split_total: 0.0,
            comp: None,
            trim: TrimFlags::default(),
            projections: None,
            rng: Cell::new(0),
            seedian: 0.0,
            name: 0,
            ctx: 0,
        }
    }

    /// The value of attribute `id` set on this shape, if any.
    pub fn attr_override(&self, id: AttrId) -> Option<&Value> {
        self.attrs
            .as_ref()
            .and_then(|a| a.iter().rev().find(|(k, _)| *k == id).map(|(_, v)| v))
    }

    pub fn set_attr(&mut self, id: AttrId, value: Value) {
        let list = Arc::make_mut(self.attrs.get_or_insert_with(Default::default));
        if let Some(slot) = list.iter_mut().find(|(k, _)| *k == id) {
            slot.1 = value;
        } else {
            list.push((id, value));
        }
    }

    /// Replaces the geometry by `mesh` given in scope-local coordinates.
    pub fn set_local_mesh(&mut self, mesh: Mesh) {
        self.geometry = Geometry::new(Arc::new(mesh));
    }

    /// Next value in [0, 1) of the shape's random stream.
    pub fn next_random(&self) -> f64 {
        let mut x = self.rng.get();
        let r = splitmix64(&mut x);
        self.rng.set(x);
        (r >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }

    /// A child's random state: derived from the parent's state and the
    /// child's ordinal, so siblings differ and the result does not depend on
    /// evaluation order elsewhere.
    pub fn child_rng(&self, ordinal: u64) -> u64 {
        let mut x = self.rng.get() ^ ordinal.wrapping_mul(0x9E37_79B9_7F4A_7C15);
        splitmix64(&mut x)
    }

    /// Moves the scope to `scope` while the geometry stays where it is in
    /// object coordinates.
    pub fn reframe_scope(&mut self, scope: Scope) {
        let old = self.scope.frame.affine();
        let new_inv = scope.frame.affine().inverse();
        self.geometry.transform(new_inv * old);
        self.scope = scope;
    }

    /// Sets the scope size, scaling the geometry along the scope axes (an
    /// axis with zero size cannot be scaled and keeps its geometry).
    pub fn resize(&mut self, size: DVec3) {
        let old = self.scope.size;
        let factor = |n: f64, o: f64| if o.abs() > 1e-12 { n / o } else { 1.0 };
        let f = DVec3::new(
            factor(size.x, old.x),
            factor(size.y, old.y),
            factor(size.z, old.z),
        );
        if f != DVec3::ONE {
            self.geometry.transform(DAffine3::from_scale(f));
        }
        self.scope.size = size;
    }

    /// Sets the scope to the bounding box of the geometry in the frame with
    /// the given axes (object coordinates); the geometry stays in place.
    pub fn fit_scope(&mut self, axes: DMat3) {
        let origin = self.scope.frame.origin;
        let mut target = self.scope;
        target.frame = Frame { origin, axes };
        self.reframe_scope(target);
        let bounds = local_bounds(self.geometry.local());
        let (lo, hi) = bounds.unwrap_or((DVec3::ZERO, DVec3::ZERO));
        if lo != DVec3::ZERO {
            self.geometry.transform(DAffine3::from_translation(-lo));
        }
        self.scope.frame.origin = origin + axes * lo;
        self.scope.size = hi - lo;
        let pivot_axes = self.pivot.axes;
        self.scope.set_axes(&pivot_axes, axes);
    }

    /// The geometry in object coordinates (for output and world queries).
    pub fn object_mesh(&self) -> Mesh {
        transformed(self.geometry.raw().0, &self.object_transform())
    }

    /// The map from the stored mesh's coordinates to object coordinates
    /// (what [`object_mesh`](Shape::object_mesh) applies).
    pub fn object_transform(&self) -> DAffine3 {
        self.after_pending(self.scope.frame.affine())
    }

    /// The map from the stored mesh's coordinates to object coordinates
    /// without the scope's translation: the geometry turned as it stands
    /// in object space, but around the scope's origin. Measures and
    /// extrusions (which do not depend on where a shape stands) are taken
    /// there, so that shapes alike but for their place give the same
    /// results to the last bit (and coordinates far from the origin lose
    /// no precision on the way).
    pub fn oriented_transform(&self) -> DAffine3 {
        self.after_pending(DAffine3::from_mat3(self.scope.frame.axes))
    }

    /// `map` applied after the geometry's pending map, if any.
    fn after_pending(&self, map: DAffine3) -> DAffine3 {
        match self.geometry.raw().1 {
            Some(m) => map * *m,
            None => map,
        }
    }

    /// The geometry in [`oriented_transform`](Shape::oriented_transform)'s
    /// coordinates.
    pub fn oriented_mesh(&self) -> Mesh {
        transformed(self.geometry.raw().0, &self.oriented_transform())
    }

    /// [`oriented_mesh`](Shape::oriented_mesh), taking the mesh out of the
    /// shape (see [`take_object_mesh`](Shape::take_object_mesh)).
    pub fn take_oriented_mesh(&mut self) -> Mesh {
        let t = self.oriented_transform();
        self.take_mesh_mapped(&t)
    }

    /// [`object_mesh`](Shape::object_mesh), taking the mesh out of the shape
    /// (no copy when no other shape shares it); the shape is left without
    /// geometry, for an operation that replaces it.
    pub fn take_object_mesh(&mut self) -> Mesh {
        let t = self.object_transform();
        self.take_mesh_mapped(&t)
    }

    /// The stored mesh taken out of the shape and mapped by `t`.
    fn take_mesh_mapped(&mut self, t: &DAffine3) -> Mesh {
        let g = std::mem::replace(&mut self.geometry, Geometry::empty());
        let mut m = Arc::try_unwrap(g.mesh).unwrap_or_else(|shared| (*shared).clone());
        transform_in_place(&mut m, t);
        m
    }
}

/// A shared empty mesh (a placeholder that costs no allocation), one per
/// thread: a reference count shared by all threads would bounce between
/// the cores (see `cga_geometry::mesh::no_tags`).
fn empty_mesh() -> Arc<Mesh> {
    thread_local! {
        static EMPTY: Arc<Mesh> = Arc::new(Mesh::new());
    }
    EMPTY
        .try_with(|m| m.clone())
        .unwrap_or_else(|_| Arc::new(Mesh::new()))
}

/// Bounding box of the positions a mesh's faces use.
pub fn local_bounds(mesh: &Mesh) -> Option<(DVec3, DVec3)> {
    let mut it = mesh.corners.iter().map(|&c| mesh.positions[c as usize]);
    let first = it.next()?;
    Some(it.fold((first, first), |(lo, hi), p| (lo.min(p), hi.max(p))))
}

pub(crate) fn splitmix64(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Rotation matrix of CGA Euler angles in degrees: x first, then y, then z
/// (`R = Rz * Ry * Rx` applied to column vectors).
pub fn euler_to_mat(angles: DVec3) -> DMat3 {
    let (sx, cx) = sin_cos_degrees(angles.x);
    let (sy, cy) = sin_cos_degrees(angles.y);
    let (sz, cz) = sin_cos_degrees(angles.z);
    let rx = DMat3::from_cols(DVec3::X, DVec3::new(0.0, cx, sx), DVec3::new(0.0, -sx, cx));
    let ry = DMat3::from_cols(DVec3::new(cy, 0.0, -sy), DVec3::Y, DVec3::new(sy, 0.0, cy));
    let rz = DMat3::from_cols(DVec3::new(cz, sz, 0.0), DVec3::new(-sz, cz, 0.0), DVec3::Z);
    rz * ry * rx
}

/// Sine and cosine of an angle in degrees, exact for multiples of 90°: a
/// quarter turn (`r(0, 90, 0)`, a side face's scope) must not leave
/// `cos(pi/2) = 6e-17` in the axes, which shows as noise such as
/// `1.2e-15` in printed coordinates.
fn sin_cos_degrees(deg: f64) -> (f64, f64) {
    if deg.is_finite() && deg % 90.0 == 0.0 {
        match (deg / 90.0).rem_euclid(4.0) as u8 {
            0 => (0.0, 1.0),
            1 => (1.0, 0.0),
            2 => (0.0, -1.0),
            _ => (-1.0, 0.0),
        }
    } else {
        deg.to_radians().sin_cos()
    }
}

/// `mat_to_euler(pivot_axes^T * axes)`, remembered for the last inputs:
/// the parts of a split and the faces of a component split mostly keep
/// their parent's axes and pivot, and the angles take trigonometry.
fn relative_euler(pivot_axes: &DMat3, axes: &DMat3) -> DVec3 {
    /// The inputs (bits of both matrices) and the angles.
    struct Last {
        valid: bool,
        key: [u64; 18],
        rot: DVec3,
    }
    thread_local! {
        static LAST: std::cell::RefCell<Last> = const {
            std::cell::RefCell::new(Last { valid: false, key: [0; 18], rot: DVec3::ZERO })
        };
    }
    let mut key = [0u64; 18];
    for (k, x) in key.iter_mut().zip(
        pivot_axes
            .to_cols_array()
            .iter()
            .chain(&axes.to_cols_array()),
    ) {
        *k = x.to_bits();
    }
    LAST.with(|last| {
        let mut last = last.borrow_mut();
        if !(last.valid && last.key == key) {
            last.rot = mat_to_euler(&(pivot_axes.transpose() * *axes));
            last.key = key;
            last.valid = true;
        }
        last.rot
    })
}

/// CGA Euler angles in degrees of a rotation matrix (inverse of [`euler_to_mat`]).
pub fn mat_to_euler(m: &DMat3) -> DVec3 {
    // m = Rz*Ry*Rx: m[0][2] (col 0, row 2) = -sin(b).
    let sb = -m.x_axis.z;
    let (mut a, mut b, mut g);
    if sb.abs() < 1.0 - 1e-12 {
        b = sb.asin();
        a = m.y_axis.z.atan2(m.z_axis.z);
        g = m.x_axis.y.atan2(m.x_axis.x);
        // The same rotation has a second set of angles (b' = 180° - b);
        // prefer the smaller turn, so a back face is (0, 180, 0) rather
        // than (180, 0, 180).
        let b2 = if b >= 0.0 {
            std::f64::consts::PI - b
        } else {
            -std::f64::consts::PI - b
        };
        let a2 = (-m.y_axis.z).atan2(-m.z_axis.z);
        let g2 = (-m.x_axis.y).atan2(-m.x_axis.x);
        if a2.abs() + b2.abs() + g2.abs() < a.abs() + b.abs() + g.abs() - 1e-9 {
            (a, b, g) = (a2, b2, g2);
        }
    } else {
        // Gimbal lock: put everything into x.
        b = if sb > 0.0 {
            std::f64::consts::FRAC_PI_2
        } else {
            -std::f64::consts::FRAC_PI_2
        };
        g = 0.0;
        a = (-m.z_axis.y).atan2(m.y_axis.y);
    }
    let deg = |x: f64| {
        let d = x.to_degrees();
        if d.abs() < 1e-9 {
            0.0
        } else {
            d
        }
    };
    DVec3::new(deg(a), deg(b), deg(g))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn euler_prefers_the_smaller_turn() {
        let back = euler_to_mat(DVec3::new(180.0, 0.0, 180.0));
        assert!((mat_to_euler(&back) - DVec3::new(0.0, 180.0, 0.0)).length() < 1e-9);
    }

    #[test]
    fn euler_round_trip() {
        for angles in [
            DVec3::new(10.0, 20.0, 30.0),
            DVec3::new(0.0, 90.0 - 1e-3, 0.0),
            DVec3::new(-45.0, 0.0, 170.0),
        ] {
            let back = mat_to_euler(&euler_to_mat(angles));
            assert!((back - angles).abs().max_element() < 1e-9, "{back:?}");
        }
    }

    #[test]
    fn euler_matches_reference_matrix() {
        // cga_eulerAngles.md: R[0][1] = sa*sb*cg - ca*sg (row 0, column 1).
        let (a, b, g) = (0.3f64, -0.7f64, 1.1f64);
        let m = euler_to_mat(DVec3::new(a, b, g) * (180.0 / std::f64::consts::PI));
        let expect = a.sin() * b.sin() * g.cos() - a.cos() * g.sin();
        assert!((m.y_axis.x - expect).abs() < 1e-12);
        assert!((m.x_axis.z + b.sin()).abs() < 1e-12);
    }
}
