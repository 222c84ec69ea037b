//! Moving meshes between frames, reversing faces, and merging meshes.

use glam::{DAffine3, DMat3, DVec2, DVec3};

use crate::mesh::{Face, Mesh};

/// Applies `m` to every position, and its inverse transpose to the normals
/// (renormalised). Face winding is left alone: a mirroring transform
/// (negative determinant) turns outward normals inward, so a caller
/// mirroring a solid should follow with [`reverse_faces`].
pub fn transform(mesh: &mut Mesh, m: &DAffine3) {
    for p in &mut mesh.positions {
        *p = m.transform_point3(*p);
    }
    if let Some(normals) = &mut mesh.normals {
        let nm = normal_matrix(m);
        for n in normals {
            *n = (nm * *n).normalize_or_zero();
        }
    }
}

/// The matrix [`transform`] maps normals with (before renormalising): the
/// inverse transpose of `m`'s linear part, or that part itself if singular.
pub fn normal_matrix(m: &DAffine3) -> DMat3 {
    let lin = m.matrix3;
    if lin.determinant().abs() > 0.0 {
        lin.inverse().transpose()
    } else {
        lin
    }
}

/// Reverses the winding of every loop, keeping each loop's first corner
/// first (`c0 cn-1 .. c1`), with its per-corner attributes; per-corner
/// normals are negated.
pub fn reverse_faces(mesh: &mut Mesh) {
    for i in 0..mesh.loops.len() {
        let r = mesh.loop_corners(mesh.loops[i]);
        if r.len() < 3 {
            continue;
        }
        let tail = r.start + 1..r.end;
        mesh.corners[tail.clone()].reverse();
        for uv in mesh.uvs.iter_mut().flatten() {
            uv[tail.clone()].reverse();
        }
        if let Some(n) = &mut mesh.normals {
            n[tail.clone()].reverse();
        }
        crate::tags::reverse_loop_tags(mesh, r);
    }
    if let Some(n) = &mut mesh.normals {
        for v in n {
            *v = -*v;
        }
    }
}

/// Appends `src` to `dst`: positions, faces and per-corner attributes. Its
/// material slots are mapped onto equal slots of `dst` (added if missing),
/// its groups onto groups of the same name. A UV set or normals present on
/// only one side are filled with zeros on the other.
pub fn merge(dst: &mut Mesh, src: &Mesh) {
    if src.faces.is_empty() {
        return;
    }
    let dst_corners = dst.corners.len();
    let base_pos = dst.positions.len() as u32;
    let base_corner = dst.corners.len() as u32;
    let base_loop = dst.loops.len() as u32;
    let mat_map: Vec<u32> = src
        .materials
        .iter()
        .map(|m| match dst.materials.iter().position(|d| d == m) {
            Some(i) => i as u32,
            None => {
                dst.materials.push(m.clone());
                dst.materials.len() as u32 - 1
            }
        })
        .collect();
    let group_map: Vec<u32> = src
        .groups
        .iter()
        .map(|g| match dst.groups.iter().position(|d| d == g) {
            Some(i) => i as u32,
            None => {
                dst.groups.push(g.clone());
                dst.groups.len() as u32 - 1
            }
        })
        .collect();
    let tag_map = crate::tags::import_table(dst, src);
    let tag = |i: u32| tag_map.get(i as usize).copied().unwrap_or(0);
    dst.positions.extend_from_slice(&src.positions);
    dst.corners
        .extend(src.corners.iter().map(|&c| c + base_pos));
    dst.loops
        .extend(src.loops.iter().map(|l| crate::mesh::Loop {
            start: l.start + base_corner,
            len: l.len,
        }));
    dst.faces.extend(src.faces.iter().map(|f| Face {
        first_loop: f.first_loop + base_loop,
        loop_count: f.loop_count,
        material: mat_map.get(f.material as usize).copied().unwrap_or(0),
        group: group_map.get(f.group as usize).copied().unwrap_or(0),
        tags: tag(f.tags),
    }));
    let n = dst.corners.len();
    for (d, s) in dst.uvs.iter_mut().zip(&src.uvs) {
        match (d.as_mut(), s) {
            (Some(d), Some(s)) => {
                d.resize(dst_corners, DVec2::ZERO);
                d.extend_from_slice(s);
                d.resize(n, DVec2::ZERO);
            }
            (Some(d), None) => d.resize(n, DVec2::ZERO),
            (None, Some(s)) => {
                let mut v = vec![DVec2::ZERO; dst_corners];
                v.extend_from_slice(s);
                v.resize(n, DVec2::ZERO);
                *d = Some(v);
            }
            (None, None) => {}
        }
    }
    match (dst.normals.as_mut(), &src.normals) {
        (Some(d), Some(s)) => {
            d.resize(dst_corners, DVec3::ZERO);
            d.extend_from_slice(s);
            d.resize(n, DVec3::ZERO);
        }
        (Some(d), None) => d.resize(n, DVec3::ZERO),
        (None, Some(s)) => {
            let mut v = vec![DVec3::ZERO; dst_corners];
            v.extend_from_slice(s);
            v.resize(n, DVec3::ZERO);
            dst.normals = Some(v);
        }
        (None, None) => {}
    }
    // Edge and vertex tags: kept on both sides, untagged where absent.
    for which in 0..2 {
        let (d, s) = if which == 0 {
            (&mut dst.edge_tags, &src.edge_tags)
        } else {
            (&mut dst.vertex_tags, &src.vertex_tags)
        };
        match (d.as_mut(), s) {
            (Some(d), Some(s)) => {
                d.resize(dst_corners, 0);
                d.extend(s.iter().map(|&t| tag(t)));
                d.resize(n, 0);
            }
            (Some(d), None) => d.resize(n, 0),
            (None, Some(s)) => {
                let mut v = vec![0; dst_corners];
                v.extend(s.iter().map(|&t| tag(t)));
                v.resize(n, 0);
                *d = Some(v);
            }
            (None, None) => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::extrude::{extrude, Extrusion};
    use crate::material::Material;
    use crate::measure::{face_normal, mesh_area, volume};
    use glam::{DMat3, DQuat};
    use std::sync::Arc;

    fn v(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    fn box_mesh() -> Mesh {
        let lot = Mesh::polygon(&[v(0., 0., 0.), v(2., 0., 0.), v(2., 0., -3.), v(0., 0., -3.)]);
        extrude(&lot, Extrusion::FaceNormal, 4.0)
    }

    #[test]
    fn transform_moves_positions_and_normals() {
        let mut m = box_mesh();
        m.normals = Some(vec![DVec3::Y; m.corners.len()]);
        let a = DAffine3::from_scale_rotation_translation(
            v(2.0, 1.0, 1.0),
            DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2),
            v(10.0, 0.0, 0.0),
        );
        transform(&mut m, &a);
        assert!((volume(&m) - 48.0).abs() < 1e-9);
        // y maps to -x under the rotation.
        let n = m.normals.as_ref().unwrap()[0];
        assert!((n - v(-1.0, 0.0, 0.0)).length() < 1e-12);
        assert!((m.positions[1] - v(10.0, 4.0, 0.0)).length() < 1e-12);
    }

    #[test]
    fn mirroring_then_reversing_keeps_volume_positive() {
        let mut m = box_mesh();
        m.uvs[0] = Some(
            (0..m.corners.len())
                .map(|i| DVec2::new(i as f64, 0.0))
                .collect(),
        );
        transform(
            &mut m,
            &DAffine3::from_mat3(DMat3::from_diagonal(v(-1.0, 1.0, 1.0))),
        );
        assert!((volume(&m) + 24.0).abs() < 1e-9);
        reverse_faces(&mut m);
        assert!((volume(&m) - 24.0).abs() < 1e-9);
        // First corner kept, attributes follow their corners.
        assert_eq!(m.loop_indices(m.outer_loop(1)), &[4, 7, 6, 5]);
        assert_eq!(
            m.uvs[0].as_ref().unwrap()[4..8]
                .iter()
                .map(|u| u.x)
                .collect::<Vec<_>>(),
            vec![4.0, 7.0, 6.0, 5.0]
        );
    }

    #[test]
    fn merge_remaps_materials_groups_and_attributes() {
        let mut a = Mesh::polygon(&[v(0., 0., 0.), v(1., 0., 0.), v(1., 0., -1.)]);
        let mut b = box_mesh();
        let red = Material {
            name: Arc::from("red"),
            color: [1.0, 0.0, 0.0],
            ..Material::default()
        };
        b.materials = vec![Material::default(), red.clone()].into();
        b.faces[1].material = 1;
        b.groups = vec![String::new(), "roof".into()].into();
        b.faces[1].group = 1;
        b.uvs[2] = Some(vec![DVec2::ONE; b.corners.len()]);
        merge(&mut a, &b);
        assert_eq!(a.faces.len(), 7);
        assert_eq!(a.positions.len(), 3 + 8);
        assert_eq!(a.materials, vec![Material::default(), red]);
        assert_eq!(a.faces[2].material, 1);
        assert_eq!(a.groups, vec![String::new(), "roof".to_string()]);
        assert_eq!(a.faces[2].group, 1);
        let uv = a.uvs[2].as_ref().unwrap();
        assert_eq!(uv.len(), a.corners.len());
        assert_eq!(uv[0], DVec2::ZERO);
        assert_eq!(uv[3], DVec2::ONE);
        assert_eq!(mesh_area(&a), 0.5 + 2.0 * (6.0 + 8.0 + 12.0));
        assert_eq!(face_normal(&a, 1), -DVec3::Y);
        assert_eq!(a.loop_indices(a.outer_loop(1)), &[4, 3, 6, 5]);
    }
}
