//! The vertex data of one material as glTF stores it, and how it grows: an
//! [`Encoder`](crate::Encoder) fills buckets of its own off the writing
//! thread, and the writer holds them as chunks of the material's data
//! (`held`) until it writes them.

use cga_geometry::{DVec2, DVec3};

use crate::ExportError;

/// Vertex data of one material, kept as the `f32` and `u32` values the
/// binary buffer holds (written as their little-endian bytes: on
/// little-endian machines the arrays' own memory).
#[derive(Default)]
pub(crate) struct Bucket {
    /// x, y, z per vertex (their number is the bucket's vertex count).
    pub positions: Vec<[f32; 3]>,
    /// x, y, z per vertex.
    pub normals: Vec<[f32; 3]>,
    /// The UV sets written as `TEXCOORD` arrays, set 0 first when present,
    /// and their coordinates (`f32` u and flipped v per vertex). A set a mesh
    /// lacks reads set 0 instead, as CGA does for texture layers; vertices
    /// without either get (0, 0). Set 0 is added when the first mesh with
    /// UVs comes (earlier vertices get (0, 0)); a textured material has it
    /// from the start, with one more set per other texture layer it uses.
    pub sets: Vec<usize>,
    pub coords: Vec<Vec<[f32; 2]>>,
    /// `TANGENT` (x, y, z, w) per vertex, for normal-mapped materials.
    pub tangents: Option<Vec<[f32; 4]>>,
    /// Vertex indices per triangle.
    pub indices: Vec<[u32; 3]>,
    pub min: [f32; 3],
    pub max: [f32; 3],
}

pub(crate) fn too_many_vertices() -> ExportError {
    ExportError::TooLarge("more than 2^32 vertices with one material".into())
}

/// The tangent written for a vertex with normal `n` given the face's
/// tangent: perpendicular to the normal, as glTF requires.
#[inline]
pub(crate) fn vertex_tangent(n: DVec3, (t, w): (DVec3, f64)) -> [f32; 4] {
    let t = (t - n * n.dot(t))
        .try_normalize()
        .unwrap_or_else(|| n.any_orthonormal_vector());
    let t = t.as_vec3();
    [t.x, t.y, t.z, w as f32]
}

/// The written texture coordinates of `corner` from a UV source: v flipped
/// (glTF puts v = 0 at the top of the image, CGA at the bottom); (0, 0)
/// without a source.
#[inline(always)]
pub(crate) fn uv_at(src: Option<&[DVec2]>, corner: usize) -> [f32; 2] {
    match src.and_then(|u| u.get(corner)) {
        Some(t) => [t.x as f32, (1.0 - t.y) as f32],
        None => [0.0, 0.0],
    }
}

/// Widens the bounds `min..max` to take in `lo..hi`.
#[inline(always)]
pub(crate) fn widen(min: &mut [f32; 3], max: &mut [f32; 3], lo: [f32; 3], hi: [f32; 3]) {
    // Bounds start at +inf and -inf and are never NaN, so plain comparisons
    // keep what `f32::min` and `max` would (a NaN coordinate changes
    // nothing; of 0 and -0 the first stays) without their NaN handling.
    // Widening by another bucket's bounds gives what pushing its positions
    // one by one would.
    for (((a, b), x), y) in min.iter_mut().zip(max).zip(lo).zip(hi) {
        if x < *a {
            *a = x;
        }
        if y > *b {
            *b = y;
        }
    }
}

impl Bucket {
    pub fn new() -> Bucket {
        Bucket {
            min: [f32::INFINITY; 3],
            max: [f32::NEG_INFINITY; 3],
            ..Bucket::default()
        }
    }

    /// An empty bucket that writes the UV `sets` (set 0 first, if any) and,
    /// if `tangents`, tangents.
    pub fn with_layout(sets: Vec<usize>, tangents: bool) -> Bucket {
        Bucket {
            coords: vec![Vec::new(); sets.len()],
            sets,
            tangents: tangents.then(Vec::new),
            ..Bucket::new()
        }
    }

    /// Empties the bucket for a material that writes the UV `sets` and, if
    /// `tangents`, tangents, keeping the arrays' room.
    pub fn relayout(&mut self, sets: Vec<usize>, tangents: bool) {
        self.clear();
        self.coords.resize_with(sets.len(), Vec::new);
        self.sets = sets;
        self.tangents = match (tangents, self.tangents.take()) {
            (true, t) => Some(t.unwrap_or_default()),
            (false, _) => None,
        };
    }

    /// Bytes of vertex data held.
    pub fn bytes(&self) -> usize {
        self.positions.len() * 12
            + self.normals.len() * 12
            + self.coords.iter().map(|c| c.len() * 8).sum::<usize>()
            + self.tangents.as_ref().map_or(0, |t| t.len() * 16)
            + self.indices.len() * 12
    }

    /// Empties the arrays (keeping their room), as for a new primitive.
    pub fn clear(&mut self) {
        self.positions.clear();
        self.normals.clear();
        self.coords.iter_mut().for_each(Vec::clear);
        if let Some(t) = &mut self.tangents {
            t.clear();
        }
        self.indices.clear();
        self.min = [f32::INFINITY; 3];
        self.max = [f32::NEG_INFINITY; 3];
    }

    /// Room for `n` more vertices.
    pub fn reserve(&mut self, n: usize) {
        self.positions.reserve(n);
        self.normals.reserve(n);
        for c in &mut self.coords {
            c.reserve(n);
        }
        if let Some(t) = &mut self.tangents {
            t.reserve(n);
        }
    }

    /// Starts writing UV set 0, with (0, 0) for the vertices so far: the
    /// first mesh with UVs of an untextured material.
    pub fn start_coords(&mut self) {
        self.sets.push(0);
        self.coords.push(vec![[0.0; 2]; self.positions.len()]);
    }

    /// Appends a vertex at `p` with normal `n`; `sources[k]` is where the
    /// `k`-th written UV set reads (see [`Bucket::sets`]), at `corner`.
    #[inline(always)]
    pub fn push_vertex(
        &mut self,
        p: DVec3,
        n: DVec3,
        sources: &[Option<&[DVec2]>],
        corner: usize,
        tangent: (DVec3, f64),
    ) -> Result<u32, ExportError> {
        let index = u32::try_from(self.positions.len()).map_err(|_| too_many_vertices())?;
        self.push_position(p);
        self.normals.push(n.as_vec3().to_array());
        for (src, coords) in sources.iter().zip(&mut self.coords) {
            coords.push(uv_at(*src, corner));
        }
        if let Some(tangents) = &mut self.tangents {
            tangents.push(vertex_tangent(n, tangent));
        }
        Ok(index)
    }

    /// Appends a position and widens the bounds.
    #[inline(always)]
    pub fn push_position(&mut self, p: DVec3) {
        let p = p.as_vec3().to_array();
        widen(&mut self.min, &mut self.max, p, p);
        self.positions.push(p);
    }

    /// Makes the bucket carry the UV `sets` and, if `tangents`, tangents,
    /// as the material's other chunks do (a texture file that changed
    /// between an encoder's look and the writer's, or UVs that came late):
    /// missing coordinates are (0, 0), missing tangents perpendicular to
    /// the normals, extra arrays are dropped.
    pub fn conform(&mut self, sets: &[usize], tangents: bool) {
        let n = self.positions.len();
        let mut coords: Vec<Vec<[f32; 2]>> = sets
            .iter()
            .map(|set| match self.sets.iter().position(|s| s == set) {
                Some(k) => std::mem::take(&mut self.coords[k]),
                None => vec![[0.0; 2]; n],
            })
            .collect();
        std::mem::swap(&mut self.coords, &mut coords);
        self.sets = sets.to_vec();
        self.tangents = match (tangents, self.tangents.take()) {
            (false, _) => None,
            (true, Some(t)) => Some(t),
            (true, None) => Some(
                self.normals
                    .iter()
                    .map(|n| {
                        let n = DVec3::from(n.map(f64::from));
                        vertex_tangent(n, (n.any_orthonormal_vector(), 1.0))
                    })
                    .collect(),
            ),
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(uvs: bool) -> Bucket {
        let mut b = Bucket::new();
        let src = [DVec2::new(0.25, 0.75), DVec2::new(1.0, 0.0)];
        let sources = [uvs.then_some(&src[..])];
        if uvs {
            b.start_coords();
        }
        for (i, x) in [-1.5, 2.0].into_iter().enumerate() {
            b.push_vertex(
                DVec3::new(x, 0.5, -x),
                DVec3::Y,
                &sources[..b.sets.len()],
                i,
                (DVec3::X, 1.0),
            )
            .unwrap();
        }
        b.indices.push([0, 1, 0]);
        b
    }

    #[test]
    fn pushing_widens_the_bounds_and_flips_v() {
        let b = sample(true);
        assert_eq!(b.min, [-1.5, 0.5, -2.0]);
        assert_eq!(b.max, [2.0, 0.5, 1.5]);
        assert_eq!(b.coords, [vec![[0.25, 0.25], [1.0, 1.0]]]);
        assert_eq!(b.bytes(), 2 * (12 + 12 + 8) + 12);
    }

    #[test]
    fn conforming_fills_what_is_missing_and_drops_the_rest() {
        let mut b = sample(true);
        b.conform(&[0, 5], true);
        assert_eq!(b.sets, [0, 5]);
        assert_eq!(b.coords[0], [[0.25, 0.25], [1.0, 1.0]]);
        assert_eq!(b.coords[1], [[0.0; 2]; 2]);
        let t = b.tangents.as_ref().unwrap();
        assert_eq!(t.len(), 2);
        // Perpendicular to the normal (y), as glTF requires.
        assert!(t.iter().all(|t| t[1].abs() < 1e-6 && t[3] == 1.0));
        b.conform(&[], false);
        assert!(b.sets.is_empty() && b.coords.is_empty() && b.tangents.is_none());
        assert_eq!(b.positions.len(), 2);
    }

    #[test]
    fn a_relaid_bucket_keeps_its_room() {
        let mut b = sample(true);
        let room = b.positions.capacity();
        b.relayout(vec![0, 7], false);
        assert!(b.positions.is_empty() && b.positions.capacity() == room);
        assert_eq!(b.sets, [0, 7]);
        assert_eq!(b.coords.len(), 2);
        assert_eq!((b.min, b.max), ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]));
    }
}
