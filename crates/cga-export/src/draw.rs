//! Models as a viewer draws them: the faces of [`PlainMesh`](crate::PlainMesh)es
//! in compact arrays (positions and texture coordinates in `f32`,
//! normals in bytes, convex faces as their corner counts), about a third
//! of the bytes, written once and read once by whatever uploads them.
//!
//! The live preview collects these on the workers instead of plain
//! meshes: a street's plain meshes are 64 bytes a vertex of `f64` that
//! the preview's encoding only reads again to round them.

use cga_geometry::DVec2;

use crate::plain::{each_triangle, fan_corners, fit, MeshArrays, PlainModel};
use crate::FaceData;

/// A [`DrawMesh`] per material.
pub type DrawModel = PlainModel<DrawMesh>;

/// How a [`DrawMesh`]'s triangles are given.
#[derive(Clone, Debug, PartialEq)]
pub enum DrawFaces {
    /// The number of corners of each face, in order: the triangles of a
    /// face whose run of vertices starts at `b` are `(b, b + i, b + i +
    /// 1)`, and each face's run follows the one before. Every face
    /// triangulated as a fan from one of its corners (every convex face)
    /// is written so, from that corner on.
    Fans(Vec<u8>),
    /// Three vertex indices per triangle: some face is not a fan, or has
    /// more than 255 corners.
    Triangles(Vec<[u32; 3]>),
}

/// The triangles of one material, as a viewer draws them: the vertices and
/// triangles of the [`PlainMesh`](crate::PlainMesh) of the same leaves, in
/// smaller types.
#[derive(Clone, Debug, PartialEq)]
pub struct DrawMesh {
    /// Index into [`PlainModel::materials`].
    pub material: usize,
    /// Vertex positions as placed, rounded to `f32` (leaves are placed
    /// relative to an origin near them: `f32` keeps about 7 digits).
    pub positions: Vec<[f32; 3]>,
    /// Unit normal per vertex (the mesh's own, else its face's), each
    /// coordinate as `round(n * 127)`.
    pub normals: Vec<[i8; 3]>,
    /// Texture coordinates of UV set 0 per vertex; (0, 0) where the face
    /// has none.
    pub uvs: Vec<[f32; 2]>,
    pub faces: DrawFaces,
    /// Per triangle, the leaf it comes from.
    pub triangle_leaf: Vec<u32>,
}

/// A unit normal's coordinate as a byte: `round(n * 127)` (halves up),
/// clamped to ±127. Collectors meet only finite normals (faces with
/// others are left out); NaN gives -127.
pub fn normal_byte(n: f64) -> i8 {
    // The clamp keeps the sum in range; `as` takes NaN to 0.
    ((n.clamp(-1.0, 1.0) * 127.0 + 127.5) as i32 - 127) as i8
}

fn f32s<const N: usize>(v: [f64; N]) -> [f32; N] {
    v.map(|c| c as f32)
}

impl DrawMesh {
    /// Triangles held.
    pub fn triangles(&self) -> usize {
        self.triangle_leaf.len()
    }

    /// The triangles as indices, whichever way they are held.
    pub fn indices(&self) -> Vec<[u32; 3]> {
        match &self.faces {
            DrawFaces::Triangles(t) => t.clone(),
            DrawFaces::Fans(sizes) => fan_indices(sizes, self.triangles()),
        }
    }

    /// Holds the triangles as indices from now on.
    fn as_triangles(&mut self) -> &mut Vec<[u32; 3]> {
        if let DrawFaces::Fans(sizes) = &self.faces {
            self.faces = DrawFaces::Triangles(fan_indices(sizes, self.triangle_leaf.len()));
        }
        match &mut self.faces {
            DrawFaces::Triangles(t) => t,
            DrawFaces::Fans(_) => unreachable!("made indices above"),
        }
    }
}

/// The triangles of faces given as fans (see [`DrawFaces::Fans`]).
fn fan_indices(sizes: &[u8], triangles: usize) -> Vec<[u32; 3]> {
    let mut out = Vec::with_capacity(triangles);
    let mut base = 0u32;
    for &n in sizes {
        let n = n as u32;
        out.extend((1..n.saturating_sub(1)).map(|k| [base, base + k, base + k + 1]));
        base += n;
    }
    out
}

impl MeshArrays for DrawMesh {
    fn with_capacity(material: usize, vertices: usize, triangles: usize) -> DrawMesh {
        DrawMesh {
            material,
            positions: Vec::with_capacity(vertices),
            normals: Vec::with_capacity(vertices),
            uvs: Vec::with_capacity(vertices),
            // Most faces are quads: two triangles a face.
            faces: DrawFaces::Fans(Vec::with_capacity(triangles / 2)),
            triangle_leaf: Vec::with_capacity(triangles),
        }
    }

    fn sizes(&self) -> (usize, usize) {
        (self.positions.len(), self.triangle_leaf.len())
    }

    fn push_fan(&mut self, f: &FaceData, uvs: Option<&[DVec2]>, first: u32, leaf: u32) {
        let corners = fan_corners(f, first);
        let n = f.mesh.face_loops(f.face)[0].len as usize;
        let base = self.positions.len() as u32;
        self.positions.extend(
            corners
                .clone()
                .map(|c| f32s(f.positions[f.mesh.corners[c] as usize].to_array())),
        );
        let byte = |n: cga_geometry::DVec3| n.to_array().map(normal_byte);
        match f.normals {
            Some(normals) => self
                .normals
                .extend(corners.clone().map(|c| byte(normals[c]))),
            None => self.normals.extend(std::iter::repeat_n(byte(f.normal), n)),
        }
        self.uvs.extend(corners.map(|c| {
            uvs.and_then(|u| u.get(c))
                .map_or([0.0; 2], |t| f32s(t.to_array()))
        }));
        match &mut self.faces {
            DrawFaces::Fans(sizes) if n <= u8::MAX as usize => sizes.push(n as u8),
            _ => {
                let n = n as u32;
                self.as_triangles()
                    .extend((1..n - 1).map(|k| [base, base + k, base + k + 1]));
            }
        }
        self.triangle_leaf.extend(std::iter::repeat_n(leaf, n - 2));
    }

    fn push_triangles(
        &mut self,
        f: &FaceData,
        uvs: Option<&[DVec2]>,
        corner_vertex: &mut [u32],
        leaf: u32,
    ) {
        let next = self.positions.len() as u32;
        self.as_triangles();
        let DrawMesh {
            positions,
            normals,
            uvs: out_uvs,
            faces: DrawFaces::Triangles(indices),
            triangle_leaf,
            ..
        } = self
        else {
            unreachable!("made indices above")
        };
        each_triangle(
            f,
            corner_vertex,
            next,
            |c| {
                let p = f.positions[f.mesh.corners[c] as usize];
                let n = f.normals.map_or(f.normal, |n| n[c]);
                let uv = uvs.and_then(|u| u.get(c)).copied();
                positions.push(f32s(p.to_array()));
                normals.push(n.to_array().map(normal_byte));
                out_uvs.push(uv.map_or([0.0; 2], |t| f32s(t.to_array())));
            },
            |ids| {
                indices.push(ids);
                triangle_leaf.push(leaf);
            },
        );
    }

    fn fit(&mut self) {
        fit(&mut self.positions);
        fit(&mut self.normals);
        fit(&mut self.uvs);
        match &mut self.faces {
            DrawFaces::Fans(v) => fit(v),
            DrawFaces::Triangles(v) => fit(v),
        }
        fit(&mut self.triangle_leaf);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{DrawCollector, PlainCollector};
    use cga_geometry::{DAffine3, DVec3, Mesh};

    /// A convex pentagon, a quad, a U-shaped octagon (not a fan), a
    /// square with a hole and a triangle, with texture coordinates.
    fn faces() -> Mesh {
        let mut m = Mesh::new();
        let p = |x: f64, z: f64| DVec3::new(x, 0.0, z);
        m.positions.extend(
            [
                (0.0, 0.0),
                (2.0, 0.0),
                (3.0, -1.0),
                (1.0, -2.0),
                (-1.0, -1.0),
                (10.0, 0.0),
                (12.0, 0.0),
                (12.0, -2.0),
                (10.0, -2.0),
                (20.0, 0.0),
                (26.0, 0.0),
                (26.0, -4.0),
                (24.0, -4.0),
                (24.0, -1.0),
                (22.0, -1.0),
                (22.0, -4.0),
                (20.0, -4.0),
                (30.0, 0.0),
                (34.0, 0.0),
                (34.0, -4.0),
                (30.0, -4.0),
                (31.0, -1.0),
                (31.0, -3.0),
                (33.0, -3.0),
                (33.0, -1.0),
            ]
            .map(|(x, z)| p(x, z)),
        );
        m.add_face(&[&[0, 1, 2, 3, 4]], 0);
        m.add_face(&[&[5, 6, 7, 8]], 0);
        m.add_face(&[&[9, 10, 11, 12, 13, 14, 15, 16]], 0);
        m.add_face(&[&[17, 18, 19, 20], &[21, 22, 23, 24]], 0);
        m.add_face(&[&[0, 1, 3]], 0);
        m.uvs[0] = Some(
            (0..m.corners.len())
                .map(|c| DVec2::new(c as f64 * 0.25, 0.5))
                .collect(),
        );
        m
    }

    /// What a draw collector holds is what a plain collector holds of the
    /// same leaves, rounded: vertex for vertex, triangle for triangle.
    fn assert_rounded_plain(leaves: &[(Mesh, DAffine3)]) -> DrawModel {
        let mut plain = PlainCollector::new();
        let mut draw = DrawCollector::new();
        for (leaf, (mesh, t)) in leaves.iter().enumerate() {
            plain
                .add_placed(mesh, Some(t), &mesh.materials, leaf as u32)
                .unwrap();
            draw.add_placed(mesh, Some(t), &mesh.materials, leaf as u32)
                .unwrap();
        }
        let (plain, draw) = (plain.take(), draw.take());
        assert_eq!(plain.materials, draw.materials);
        assert_eq!((plain.faces, draw.faces), (plain.faces, plain.faces));
        assert_eq!(plain.triangles(), draw.triangles());
        for (p, d) in plain.meshes.iter().zip(&draw.meshes) {
            assert_eq!(p.material, d.material);
            let f32s = |v: &[[f64; 3]]| v.iter().map(|p| p.map(|c| c as f32)).collect::<Vec<_>>();
            assert_eq!(f32s(&p.positions), d.positions);
            let bytes: Vec<[i8; 3]> = p.normals.iter().map(|n| n.map(normal_byte)).collect();
            assert_eq!(bytes, d.normals);
            let uvs: Vec<[f32; 2]> = p.uvs.iter().map(|t| t.map(|c| c as f32)).collect();
            assert_eq!(uvs, d.uvs);
            assert_eq!(p.indices, d.indices());
            assert_eq!(p.triangle_leaf, d.triangle_leaf);
        }
        draw
    }

    #[test]
    fn drawn_meshes_hold_the_plain_meshes_rounded() {
        let shift = DAffine3::from_translation(DVec3::new(5.0, 1.0, 2.0));
        let turned = DAffine3::from_rotation_y(0.3) * shift;
        let cube = cga_geometry::primitive::cube(DVec3::new(2.0, 3.0, 4.0));
        // Only fans: faces as corner counts.
        let draw = assert_rounded_plain(&[(cube.clone(), shift), (cube.clone(), turned)]);
        assert_eq!(draw.meshes[0].faces, DrawFaces::Fans(vec![4; 12]));
        // A face that is no fan: every triangle as indices from then on,
        // those of the fans before it too.
        let draw = assert_rounded_plain(&[(cube.clone(), shift), (faces(), turned), (cube, shift)]);
        let DrawFaces::Triangles(t) = &draw.meshes[0].faces else {
            panic!("{:?}", draw.meshes[0].faces)
        };
        assert_eq!(t.len(), 12 + 3 + 2 + 6 + 8 + 1 + 12);
        // The mesh's own normals, per corner.
        let mut sphere = cga_geometry::primitive::sphere(8, 6, DVec3::splat(3.0));
        assert!(sphere.normals.is_some());
        sphere.uvs[0] = None;
        assert_rounded_plain(&[(sphere, turned)]);
    }

    #[test]
    fn normal_bytes_round_halves_up_and_clamp() {
        assert_eq!(normal_byte(1.0), 127);
        assert_eq!(normal_byte(-1.0), -127);
        assert_eq!(normal_byte(2.5), 127);
        assert_eq!(normal_byte(-7.0), -127);
        assert_eq!(normal_byte(f64::NAN), -127);
        assert_eq!(normal_byte(0.5 / 127.0), 1);
        assert_eq!(normal_byte(-0.5 / 127.0), 0);
        assert_eq!(normal_byte(std::f64::consts::FRAC_1_SQRT_2), 90);
    }
}
