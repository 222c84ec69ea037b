//! Repeated assets as GPU instances (`EXT_mesh_gpu_instancing`).
//!
//! An asset inserted with `i()` and left unchanged is one mesh shared by
//! every shape that inserted it, placed by each shape's transform. Instead
//! of writing its triangles again for every insert, a glTF writer writes
//! the mesh once per distinct (mesh, materials) pair (a *group*) and, per
//! node, the translation, rotation and scale of each placement. Only
//! placements that are a rotation and a positive scale along the mesh's
//! axes can be instances (glTF's TRS); sheared or mirrored ones are written
//! as ordinary geometry.
//!
//! Groups are found by the mesh's address (the engine hands out one mesh
//! per asset, see `Leaf::asset`) and the materials' values, in the order
//! placements reach the writer, so the file is the same from run to run.

use std::collections::{BTreeMap, HashMap};
use std::sync::Arc;

use cga_geometry::mesh::SharedVec;
use cga_geometry::{DAffine3, DQuat, DVec3, Material, Mesh};

use crate::bucket::Bucket;

/// A placement as glTF's translation, rotation and scale.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Trs {
    pub translation: DVec3,
    pub rotation: DQuat,
    pub scale: DVec3,
}

/// `t` as translation, rotation and scale, when it is one: its axes at
/// right angles (to 1e-9 of their lengths), none of length zero, not
/// mirrored.
pub(crate) fn decompose(t: &DAffine3) -> Option<Trs> {
    let m = t.matrix3;
    let cols = [m.x_axis, m.y_axis, m.z_axis];
    let scale = DVec3::new(cols[0].length(), cols[1].length(), cols[2].length());
    if !scale.is_finite() || scale.min_element() <= 1e-12 || !t.translation.is_finite() {
        return None;
    }
    for (a, b) in [(0, 1), (0, 2), (1, 2)] {
        if cols[a].dot(cols[b]).abs() > 1e-9 * scale[a] * scale[b] {
            return None;
        }
    }
    let r = cga_geometry::DMat3::from_cols(cols[0] / scale.x, cols[1] / scale.y, cols[2] / scale.z);
    if r.determinant() <= 0.0 {
        return None;
    }
    Some(Trs {
        translation: t.translation,
        rotation: DQuat::from_mat3(&r).normalize(),
        scale,
    })
}

/// An asset placement an encoder took, on its way to the writer (which
/// finds its group: groups are the writer's, in the order it sees them).
pub(crate) struct Pending {
    pub mesh: Arc<Mesh>,
    pub materials: SharedVec<Material>,
    pub transform: DAffine3,
    pub trs: Trs,
}

/// A distinct (mesh, materials) pair: its geometry, encoded once in the
/// mesh's own coordinates, a bucket per material id.
pub(crate) struct Group {
    mesh: Arc<Mesh>,
    materials: SharedVec<Material>,
    pub buckets: Vec<(u32, Bucket)>,
    /// Faces and triangles of one placement.
    pub faces: u64,
    pub triangles: u64,
    /// The box of its vertices in its own coordinates.
    pub bounds: Option<[DVec3; 2]>,
}

/// One placement of a group (its node's): the lot it belongs to (its
/// position among the writer's lots) and its TRS as written (relative to
/// the origin).
pub(crate) struct Placement {
    pub lot: Option<u32>,
    pub translation: [f32; 3],
    pub rotation: [f32; 4],
    pub scale: [f32; 3],
}

/// An instance node: its lot (when per lot) and group.
pub(crate) type NodeKey = (Option<u32>, u32);

/// The groups and placements of one model.
#[derive(Default)]
pub(crate) struct Instances {
    pub groups: Vec<Group>,
    by_mesh: HashMap<usize, Vec<u32>>,
    /// The placements of each node, in order of node (lot, then group)
    /// and, within a node, in the order they came. Gathered as they come:
    /// one array of all placements, sorted into nodes at the end, grew in
    /// fresh memory on the writing thread and took two more arrays of its
    /// size at the model's last step (each new size of block a fresh page
    /// of the allocator, zeroed whole by a huge page).
    pub nodes: BTreeMap<NodeKey, Vec<Placement>>,
    pub with_features: bool,
}

impl Instances {
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The group of `mesh` with `materials`, if there is one.
    pub fn find(&self, mesh: &Arc<Mesh>, materials: &SharedVec<Material>) -> Option<u32> {
        let candidates = self.by_mesh.get(&(Arc::as_ptr(mesh) as usize))?;
        candidates.iter().copied().find(|&g| {
            let group = &self.groups[g as usize];
            Arc::ptr_eq(&group.mesh, mesh) && group.materials[..] == materials[..]
        })
    }

    /// Adds a group (its mesh kept alive, so that its address names it).
    pub fn add_group(
        &mut self,
        mesh: Arc<Mesh>,
        materials: SharedVec<Material>,
        buckets: Vec<(u32, Bucket)>,
        faces: u64,
        triangles: u64,
    ) -> u32 {
        let id = self.groups.len() as u32;
        let bounds = buckets
            .iter()
            .filter(|(_, b)| !b.positions.is_empty())
            .map(|(_, b)| {
                [
                    DVec3::from_array(b.min.map(f64::from)),
                    DVec3::from_array(b.max.map(f64::from)),
                ]
            })
            .reduce(|a, b| [a[0].min(b[0]), a[1].max(b[1])]);
        self.by_mesh
            .entry(Arc::as_ptr(&mesh) as usize)
            .or_default()
            .push(id);
        self.groups.push(Group {
            mesh,
            materials,
            buckets,
            faces,
            triangles,
            bounds,
        });
        id
    }

    /// Places `group` by `trs` (relative to the origin) in `lot`, in the
    /// node of `lot` and `group` (`per_lot`) or of `group`; returns the box
    /// of the placed geometry (relative to the origin).
    pub fn place(
        &mut self,
        group: u32,
        lot: Option<u32>,
        per_lot: bool,
        trs: &Trs,
        transform: &DAffine3,
    ) -> Option<[[f64; 3]; 2]> {
        let node = (if per_lot { lot } else { None }, group);
        self.nodes.entry(node).or_default().push(Placement {
            lot,
            translation: trs.translation.as_vec3().to_array(),
            rotation: trs.rotation.as_quat().to_array(),
            scale: trs.scale.as_vec3().to_array(),
        });
        let [lo, hi] = self.groups[group as usize].bounds?;
        let corners = (0..8).map(|k| {
            let pick = |bit: usize, a: f64, b: f64| if k & bit == 0 { a } else { b };
            transform.transform_point3(DVec3::new(
                pick(1, lo.x, hi.x),
                pick(2, lo.y, hi.y),
                pick(4, lo.z, hi.z),
            ))
        });
        let (lo, hi) = corners.fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
            (lo.min(p), hi.max(p))
        });
        Some([lo.to_array(), hi.to_array()])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use cga_geometry::DMat3;

    /// Nodes come in order of lot and group, each with its placements in
    /// the order they were placed; without nodes per lot, one per group.
    #[test]
    fn placements_are_gathered_by_node_in_order() {
        let mut instances = Instances::default();
        let trs = Trs {
            translation: DVec3::ZERO,
            rotation: DQuat::IDENTITY,
            scale: DVec3::ONE,
        };
        for _ in 0..2 {
            let mesh = Arc::new(cga_geometry::primitive::cube(DVec3::ONE));
            instances.add_group(mesh, SharedVec::default(), Vec::new(), 0, 0);
        }
        // (lot, group) of each placement, in the order placed; a
        // placement's lot is its x, its order its y.
        let placed = [(0, 1), (0, 0), (0, 1), (1, 0), (1, 1), (1, 0), (2, 1)];
        let mut whole = instances_like(&instances);
        for (k, (lot, group)) in placed.into_iter().enumerate() {
            let trs = Trs {
                translation: DVec3::new(lot as f64, k as f64, 0.0),
                ..trs
            };
            instances.place(group, Some(lot), true, &trs, &DAffine3::IDENTITY);
            whole.place(group, Some(lot), false, &trs, &DAffine3::IDENTITY);
        }
        type Lots = Vec<(Option<u32>, f32)>;
        let nodes = |i: &Instances| -> Vec<(NodeKey, Lots)> {
            i.nodes
                .iter()
                .map(|(key, ps)| (*key, ps.iter().map(|p| (p.lot, p.translation[1])).collect()))
                .collect()
        };
        let per_lot = vec![
            ((Some(0), 0), vec![(Some(0), 1.0)]),
            ((Some(0), 1), vec![(Some(0), 0.0), (Some(0), 2.0)]),
            ((Some(1), 0), vec![(Some(1), 3.0), (Some(1), 5.0)]),
            ((Some(1), 1), vec![(Some(1), 4.0)]),
            ((Some(2), 1), vec![(Some(2), 6.0)]),
        ];
        assert_eq!(nodes(&instances), per_lot);
        // Without nodes per lot the placements keep their lots (feature
        // ids) in nodes by group.
        let by_group = vec![
            (
                (None, 0),
                vec![(Some(0), 1.0), (Some(1), 3.0), (Some(1), 5.0)],
            ),
            (
                (None, 1),
                vec![
                    (Some(0), 0.0),
                    (Some(0), 2.0),
                    (Some(1), 4.0),
                    (Some(2), 6.0),
                ],
            ),
        ];
        assert_eq!(nodes(&whole), by_group);
    }

    /// Instances with the groups of `i` and no placements.
    fn instances_like(i: &Instances) -> Instances {
        let mut out = Instances::default();
        for g in &i.groups {
            out.add_group(g.mesh.clone(), g.materials.clone(), Vec::new(), 0, 0);
        }
        out
    }

    #[test]
    fn rotations_and_scales_decompose() {
        let t = DAffine3::from_scale_rotation_translation(
            DVec3::new(2.0, 0.5, 3.0),
            DQuat::from_rotation_y(0.7) * DQuat::from_rotation_x(-0.2),
            DVec3::new(10.0, 1.0, -4.0),
        );
        let trs = decompose(&t).unwrap();
        assert!((trs.scale - DVec3::new(2.0, 0.5, 3.0)).length() < 1e-12);
        let back =
            DAffine3::from_scale_rotation_translation(trs.scale, trs.rotation, trs.translation);
        assert!(back.abs_diff_eq(t, 1e-12));
    }

    #[test]
    fn shear_mirror_and_flat_placements_do_not() {
        let shear = DAffine3::from_mat3(DMat3::from_cols(
            DVec3::X,
            DVec3::new(0.5, 1.0, 0.0),
            DVec3::Z,
        ));
        assert_eq!(decompose(&shear), None);
        let mirror = DAffine3::from_scale(DVec3::new(-1.0, 1.0, 1.0));
        assert_eq!(decompose(&mirror), None);
        let flat = DAffine3::from_scale(DVec3::new(1.0, 0.0, 1.0));
        assert_eq!(decompose(&flat), None);
    }
}
