//! Models as a viewer draws them: the faces of [`PlainMesh`](crate::PlainMesh)es
//! in compact arrays (positions and texture coordinates in `f32`,
//! normals in bytes, convex faces as their corner counts), about a third
//! of the bytes, written once and read once by whatever uploads them.
//!
//! The live preview collects these on the workers instead of plain
//! meshes: a street's plain meshes are 64 bytes a vertex of `f64` that
//! the preview's encoding only reads again to round them.

use cga_geometry::DVec2;

use crate::plain::{
    corner_position, corner_uv, each_triangle, fan_corners, fit, push_corners, CornerArrays,
    MeshArrays, PlainModel,
};
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

/// How a [`DrawMesh`]'s normals are given: bytes, each coordinate
/// `round(n * 127)` (see [`normal_byte`]).
#[derive(Clone, Debug, PartialEq)]
pub enum DrawNormals {
    /// One per face, in face order, for every corner of the face: while
    /// every face is flat (all its corners' normals the same bytes) and a
    /// fan
    /// ([`DrawFaces::Fans`], which gives each face's number of
    /// vertices). A quad's normal is then 3 bytes instead of 12.
    PerFace(Vec<[i8; 3]>),
    /// One per vertex.
    PerVertex(Vec<[i8; 3]>),
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
    /// Unit normals (the mesh's own, else the face's).
    pub normals: DrawNormals,
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

    /// The normal of each vertex, whichever way they are held.
    pub fn vertex_normals(&self) -> Vec<[i8; 3]> {
        match (&self.normals, &self.faces) {
            (DrawNormals::PerVertex(n), _) => n.clone(),
            (DrawNormals::PerFace(n), DrawFaces::Fans(sizes)) => {
                per_vertex(n, sizes, self.positions.len())
            }
            (DrawNormals::PerFace(_), DrawFaces::Triangles(_)) => {
                unreachable!("normals per face are held with fans only")
            }
        }
    }

    /// Holds the normals per vertex from now on.
    fn as_vertex_normals(&mut self) -> &mut Vec<[i8; 3]> {
        if let DrawNormals::PerFace(_) = &self.normals {
            self.normals = DrawNormals::PerVertex(self.vertex_normals());
        }
        match &mut self.normals {
            DrawNormals::PerVertex(n) => n,
            DrawNormals::PerFace(_) => unreachable!("made per vertex above"),
        }
    }

    /// Holds the normals per vertex from now on, while the last face
    /// counted in the fans has no normals yet (its own are added next).
    fn normals_without_last_face(&mut self) -> &mut Vec<[i8; 3]> {
        if let (DrawNormals::PerFace(n), DrawFaces::Fans(sizes)) = (&self.normals, &self.faces) {
            let before = &sizes[..sizes.len().saturating_sub(1)];
            self.normals = DrawNormals::PerVertex(per_vertex(n, before, self.positions.len()));
        }
        match &mut self.normals {
            DrawNormals::PerVertex(n) => n,
            DrawNormals::PerFace(_) => unreachable!("held with indices, made per vertex"),
        }
    }

    /// Holds the triangles as indices (and so the normals per vertex)
    /// from now on.
    fn as_triangles(&mut self) -> &mut Vec<[u32; 3]> {
        self.as_vertex_normals();
        if let DrawFaces::Fans(sizes) = &self.faces {
            self.faces = DrawFaces::Triangles(fan_indices(sizes, self.triangle_leaf.len()));
        }
        match &mut self.faces {
            DrawFaces::Triangles(t) => t,
            DrawFaces::Fans(_) => unreachable!("made indices above"),
        }
    }
}

/// Normals given per face as per vertex, each face's for its `sizes[f]`
/// vertices.
fn per_vertex(normals: &[[i8; 3]], sizes: &[u8], vertices: usize) -> Vec<[i8; 3]> {
    let mut out = Vec::with_capacity(vertices);
    for (n, &k) in normals.iter().zip(sizes) {
        out.extend(std::iter::repeat_n(*n, k as usize));
    }
    out
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
            // Most faces are quads: two triangles a face.
            normals: DrawNormals::PerFace(Vec::with_capacity(triangles / 2)),
            uvs: Vec::with_capacity(vertices),
            faces: DrawFaces::Fans(Vec::with_capacity(triangles / 2)),
            triangle_leaf: Vec::with_capacity(triangles),
        }
    }

    fn sizes(&self) -> (usize, usize) {
        (self.positions.len(), self.triangle_leaf.len())
    }

    fn push_face(
        &mut self,
        f: &FaceData,
        uvs: Option<&[DVec2]>,
        corner_vertex: &mut [u32],
        leaf: u32,
        _: u32,
    ) {
        push_corners(self, f, uvs, corner_vertex, leaf);
    }

    fn fit(&mut self) {
        fit(&mut self.positions);
        match &mut self.normals {
            DrawNormals::PerFace(v) | DrawNormals::PerVertex(v) => fit(v),
        }
        fit(&mut self.uvs);
        match &mut self.faces {
            DrawFaces::Fans(v) => fit(v),
            DrawFaces::Triangles(v) => fit(v),
        }
        fit(&mut self.triangle_leaf);
    }
}

impl CornerArrays for DrawMesh {
    fn push_fan(&mut self, f: &FaceData, uvs: Option<&[DVec2]>, first: u32, leaf: u32) {
        let corners = fan_corners(f, first);
        let n = f.loops[0].len as usize;
        let base = self.positions.len() as u32;
        self.positions
            .extend(corners.clone().map(|c| f32s(corner_position(f, c))));
        self.uvs
            .extend(corners.clone().map(|c| f32s(corner_uv(uvs, c))));
        // Corner counts before normals: a face that cannot be a fan
        // makes the normals per vertex.
        match &mut self.faces {
            DrawFaces::Fans(sizes) if n <= u8::MAX as usize => sizes.push(n as u8),
            _ => {
                let n = n as u32;
                self.as_triangles()
                    .extend((1..n - 1).map(|k| [base, base + k, base + k + 1]));
            }
        }
        let byte = |n: cga_geometry::DVec3| n.to_array().map(normal_byte);
        // A face is flat where its corners' normals are one byte triple:
        // every face without normals of its own, and most that have them
        // (an inserted box's).
        let flat = match f.normals {
            None => Some(byte(f.normal())),
            Some(own) => {
                let mut bytes = corners.clone().map(|c| byte(own[c]));
                let first = bytes.next();
                first.filter(|b| bytes.all(|o| o == *b))
            }
        };
        match (flat, &mut self.normals) {
            (Some(b), DrawNormals::PerFace(normals)) => normals.push(b),
            (Some(b), DrawNormals::PerVertex(normals)) => normals.extend(std::iter::repeat_n(b, n)),
            (None, _) => {
                // The face's count is in the fans already: the normals
                // before it are made per vertex without it.
                let own = f.normals.expect("only faces with normals are not flat");
                let mine = self.normals_without_last_face();
                mine.extend(corners.map(|c| byte(own[c])));
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
            normals: DrawNormals::PerVertex(normals),
            uvs: out_uvs,
            faces: DrawFaces::Triangles(indices),
            triangle_leaf,
            ..
        } = self
        else {
            unreachable!("made indices and normals per vertex above")
        };
        each_triangle(
            f,
            corner_vertex,
            next,
            |c| {
                let n = f.normals.map_or_else(|| f.normal(), |n| n[c]);
                positions.push(f32s(corner_position(f, c)));
                normals.push(n.to_array().map(normal_byte));
                out_uvs.push(f32s(corner_uv(uvs, c)));
            },
            |ids| {
                indices.push(ids);
                triangle_leaf.push(leaf);
            },
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plain::tests::sample_faces;
    use crate::{DrawCollector, PlainCollector};
    use cga_geometry::{DAffine3, DVec3, Mesh};

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
            assert_eq!(bytes, d.vertex_normals());
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
        // Flat faces: a normal per face.
        let DrawNormals::PerFace(n) = &draw.meshes[0].normals else {
            panic!("{:?}", draw.meshes[0].normals)
        };
        assert_eq!(n.len(), 12);
        // A face that is no fan: every triangle as indices from then on,
        // those of the fans before it too.
        let draw = assert_rounded_plain(&[
            (cube.clone(), shift),
            (sample_faces(), turned),
            (cube, shift),
        ]);
        let DrawFaces::Triangles(t) = &draw.meshes[0].faces else {
            panic!("{:?}", draw.meshes[0].faces)
        };
        assert_eq!(t.len(), 12 + 3 + 2 + 6 + 8 + 1 + 12);
        assert_eq!(
            draw.meshes[0].normals,
            DrawNormals::PerVertex(draw.meshes[0].vertex_normals())
        );
        // The mesh's own normals, per corner.
        let mut sphere = cga_geometry::primitive::sphere(8, 6, DVec3::splat(3.0));
        assert!(sphere.normals.is_some());
        sphere.uvs[0] = None;
        assert_rounded_plain(&[(sphere.clone(), turned)]);
        // Flat faces, then a face with normals of its own (the normals
        // before it given to their vertices), then flat ones again.
        let cube = cga_geometry::primitive::cube(DVec3::ONE);
        let draw = assert_rounded_plain(&[(cube.clone(), shift), (sphere, shift), (cube, turned)]);
        let DrawNormals::PerVertex(n) = &draw.meshes[0].normals else {
            panic!("{:?}", draw.meshes[0].normals)
        };
        assert_eq!(n.len(), draw.meshes[0].positions.len());
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
