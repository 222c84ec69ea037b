//! The indexed polygon mesh every shape's geometry is made of.
//!
//! Layout (flat arrays, no per-face allocation):
//! - `positions`: the vertices;
//! - `corners`: one entry per face corner, an index into `positions`;
//! - `loops`: ranges of `corners`; a face's first loop is its outer boundary
//!   (counter-clockwise seen from the side its normal points to), the others
//!   are holes (clockwise);
//! - `faces`: ranges of `loops`, each with a material slot and a group;
//! - `uvs[k]`, `normals`: per-corner attributes aligned with `corners`.

use glam::{DVec2, DVec3};

use crate::material::Material;

/// Number of texture coordinate sets a mesh can carry (CGA's UV sets 0..9).
pub const UV_SETS: usize = 10;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Loop {
    /// First corner (index into `Mesh::corners`).
    pub start: u32,
    pub len: u32,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Face {
    /// First loop (index into `Mesh::loops`): the outer boundary.
    pub first_loop: u32,
    /// 1 + number of holes.
    pub loop_count: u32,
    /// Index into `Mesh::materials`.
    pub material: u32,
    /// Index into `Mesh::groups`.
    pub group: u32,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    pub positions: Vec<DVec3>,
    pub corners: Vec<u32>,
    pub loops: Vec<Loop>,
    pub faces: Vec<Face>,
    /// Per-corner texture coordinates for each UV set; `None` if the set is absent.
    pub uvs: [Option<Vec<DVec2>>; UV_SETS],
    /// Per-corner normals, if the geometry carries its own (assets, `setNormals`).
    pub normals: Option<Vec<DVec3>>,
    /// Material slots referenced by `Face::material`; never empty.
    pub materials: Vec<Material>,
    /// Group names referenced by `Face::group` (OBJ `g`); never empty.
    pub groups: Vec<String>,
}

impl Default for Mesh {
    fn default() -> Self {
        Mesh::new()
    }
}

impl Mesh {
    /// An empty mesh with one default material slot and one unnamed group.
    pub fn new() -> Mesh {
        Mesh {
            positions: Vec::new(),
            corners: Vec::new(),
            loops: Vec::new(),
            faces: Vec::new(),
            uvs: Default::default(),
            normals: None,
            materials: vec![Material::default()],
            groups: vec![String::new()],
        }
    }

    /// A mesh of one polygon face (no holes) through `points` in order.
    pub fn polygon(points: &[DVec3]) -> Mesh {
        let mut m = Mesh::new();
        m.positions.extend_from_slice(points);
        let idx: Vec<u32> = (0..points.len() as u32).collect();
        m.add_face(&[&idx], 0);
        m
    }

    pub fn is_empty(&self) -> bool {
        self.faces.is_empty()
    }

    /// Adds a face from its loops (outer first, then holes) of position indices.
    /// Per-corner attributes present on the mesh get zero entries; fill them
    /// afterwards if needed. Returns the face index.
    pub fn add_face(&mut self, loops: &[&[u32]], material: u32) -> usize {
        let first_loop = self.loops.len() as u32;
        for l in loops {
            let start = self.corners.len() as u32;
            self.corners.extend_from_slice(l);
            self.loops.push(Loop {
                start,
                len: l.len() as u32,
            });
        }
        let n = self.corners.len();
        for set in self.uvs.iter_mut().flatten() {
            set.resize(n, DVec2::ZERO);
        }
        if let Some(normals) = &mut self.normals {
            normals.resize(n, DVec3::ZERO);
        }
        self.faces.push(Face {
            first_loop,
            loop_count: loops.len() as u32,
            material,
            group: 0,
        });
        self.faces.len() - 1
    }

    /// The loops of a face: outer boundary first, then holes.
    pub fn face_loops(&self, face: usize) -> &[Loop] {
        let f = &self.faces[face];
        &self.loops[f.first_loop as usize..(f.first_loop + f.loop_count) as usize]
    }

    /// The corner index range of a loop.
    pub fn loop_corners(&self, l: Loop) -> std::ops::Range<usize> {
        l.start as usize..(l.start + l.len) as usize
    }

    /// Position indices of a loop.
    pub fn loop_indices(&self, l: Loop) -> &[u32] {
        &self.corners[self.loop_corners(l)]
    }

    /// Positions of a loop, in order.
    pub fn loop_points(&self, l: Loop) -> impl Iterator<Item = DVec3> + '_ {
        self.loop_indices(l)
            .iter()
            .map(move |&i| self.positions[i as usize])
    }

    /// The outer boundary loop of a face.
    pub fn outer_loop(&self, face: usize) -> Loop {
        self.loops[self.faces[face].first_loop as usize]
    }

    /// Applies `f` to every position (normals are not touched).
    pub fn map_positions(&mut self, f: impl Fn(DVec3) -> DVec3) {
        for p in &mut self.positions {
            *p = f(*p);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polygon_has_one_face_one_loop() {
        let m = Mesh::polygon(&[DVec3::ZERO, DVec3::X, DVec3::new(1.0, 0.0, -1.0)]);
        assert_eq!(m.faces.len(), 1);
        assert_eq!(m.face_loops(0).len(), 1);
        assert_eq!(m.loop_indices(m.outer_loop(0)), &[0, 1, 2]);
    }
}
