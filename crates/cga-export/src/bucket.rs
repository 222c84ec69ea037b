//! The vertex data of one material as glTF stores it, and how it grows: an
//! [`Encoder`](crate::Encoder) fills buckets of its own off the writing
//! thread, and the writer appends them to the model's buckets
//! ([`Bucket::append`]). How the data is laid out in the file is
//! `gltf`'s part.

use cga_geometry::{DVec2, DVec3};

use crate::array_pool::ArrayPool;
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
    /// After `merge_equal_coords`: the `TEXCOORD` index of each set (sets
    /// with equal coordinates share one array).
    pub tex_coords: Vec<u32>,
    /// `TANGENT` (x, y, z, w) per vertex, for normal-mapped materials.
    pub tangents: Option<Vec<[f32; 4]>>,
    /// Vertex indices per triangle.
    pub indices: Vec<[u32; 3]>,
    /// With per-lot features: the feature id of each vertex so far (filled
    /// up to the vertex count when the lot changes or data is written).
    pub features: Vec<f32>,
    pub min: [f32; 3],
    pub max: [f32; 3],
    /// Data appended whole, before the arrays above (see
    /// [`Bucket::append`]): each segment laid out as this bucket, its
    /// indices numbering the vertices of the whole bucket. The arrays
    /// above take pushes only while there are none
    /// ([`Bucket::consolidate`]).
    pub sealed: Vec<Bucket>,
    /// The capacity of the shortest vertex array when
    /// [`Bucket::room_from`] last looked (0: not since arrays were
    /// replaced): while the vertices stay within it, a face needs one
    /// comparison, not one per array. Arrays only grow between looks, so
    /// it never overstates their room; an array replaced without resetting
    /// it would only grow as any `Vec` does.
    vertex_room: usize,
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
        self.tex_coords.clear();
        self.tangents = match (tangents, self.tangents.take()) {
            (true, t) => Some(t.unwrap_or_default()),
            (false, _) => None,
        };
        self.vertex_room = 0;
    }

    /// Bytes of vertex data held.
    pub fn bytes(&self) -> usize {
        self.sealed.iter().map(Bucket::own_bytes).sum::<usize>() + self.own_bytes()
    }

    /// Bytes of vertex data in this segment's own arrays.
    pub fn own_bytes(&self) -> usize {
        self.positions.len() * 12
            + self.normals.len() * 12
            + self.coords.iter().map(|c| c.len() * 8).sum::<usize>()
            + self.tangents.as_ref().map_or(0, |t| t.len() * 16)
            + self.indices.len() * 12
    }

    /// The segments of the data in order: those appended whole, then the
    /// bucket's own arrays.
    pub fn segments(&self) -> impl Iterator<Item = &Bucket> {
        self.sealed.iter().chain(std::iter::once(self))
    }

    /// Calls `f` on each segment in order (see [`Bucket::segments`]).
    pub fn each_segment_mut(&mut self, mut f: impl FnMut(&mut Bucket)) {
        self.sealed.iter_mut().for_each(&mut f);
        f(self);
    }

    /// Vertices held.
    pub fn vertex_count(&self) -> usize {
        self.segments().map(|s| s.positions.len()).sum()
    }

    /// Whether any triangle is held.
    pub fn has_triangles(&self) -> bool {
        self.segments().any(|s| !s.indices.is_empty())
    }

    /// Empties the arrays (keeping their room), as for a new primitive.
    pub fn clear(&mut self) {
        self.sealed.clear();
        self.positions.clear();
        self.normals.clear();
        self.coords.iter_mut().for_each(Vec::clear);
        if let Some(t) = &mut self.tangents {
            t.clear();
        }
        self.indices.clear();
        self.features.clear();
        self.min = [f32::INFINITY; 3];
        self.max = [f32::NEG_INFINITY; 3];
    }

    /// The data in its arrays (of a bucket filled by pushes alone),
    /// leaving fresh arrays with room for as much and a quarter more.
    /// The new arrays come from `pool` (arrays written out before).
    pub fn take_leaving_room(&mut self, pool: &ArrayPool) -> Bucket {
        debug_assert!(self.sealed.is_empty());
        // The next batch of a material is about as large, often a little
        // larger: without the slack its arrays grew (a copy of each) in a
        // batch of every few (20 Candler buildings: 17 M instructions).
        // Room never written is not memory the process touches.
        let slack = |n: usize| n + n / 4;
        let (vertices, triangles) = (slack(self.positions.len()), slack(self.indices.len()));
        let out = self.take_arrays();
        self.positions = pool.vectors.take(vertices);
        self.normals = pool.vectors.take(vertices);
        for c in &mut self.coords {
            *c = pool.coords.take(vertices);
        }
        if let Some(t) = &mut self.tangents {
            *t = pool.tangents.take(vertices);
        }
        self.indices = pool.indices.take(triangles);
        out
    }

    /// Room for `vertices` more vertices and `triangles` more triangles,
    /// where an array is short taken from `pool` (arrays written out, see
    /// [`ArrayPool`]): its data copied over and the short array given back.
    /// A batch's array that outgrew its room was reallocated by the
    /// allocator into fresh memory, pages the kernel zeroes, while the pool
    /// held arrays of that size already touched (20 Candler buildings into
    /// a GLB: a third of a run's page faults).
    #[inline]
    pub fn room_from(&mut self, pool: &ArrayPool, vertices: usize, triangles: usize) {
        if self.positions.len() + vertices > self.vertex_room
            || self.indices.capacity() - self.indices.len() < triangles
        {
            self.regrow_from(pool, vertices, triangles);
        }
    }

    /// [`Bucket::room_from`] for a bucket with a short array.
    #[cold]
    fn regrow_from(&mut self, pool: &ArrayPool, vertices: usize, triangles: usize) {
        pool.vectors.grow(&mut self.positions, vertices);
        pool.vectors.grow(&mut self.normals, vertices);
        for c in &mut self.coords {
            pool.coords.grow(c, vertices);
        }
        if let Some(t) = &mut self.tangents {
            pool.tangents.grow(t, vertices);
        }
        pool.indices.grow(&mut self.indices, triangles);
        let rooms = [&self.positions, &self.normals]
            .into_iter()
            .map(Vec::capacity)
            .chain(self.coords.iter().map(Vec::capacity))
            .chain(self.tangents.iter().map(Vec::capacity));
        self.vertex_room = rooms.min().unwrap_or(0);
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
        for s in &mut self.sealed {
            s.start_coords();
        }
        self.sets.push(0);
        self.coords.push(vec![[0.0; 2]; self.positions.len()]);
        self.vertex_room = 0;
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
        // Pushed vertices are numbered by the bucket's own arrays.
        debug_assert!(self.sealed.is_empty(), "consolidate before pushing");
        let p = p.as_vec3().to_array();
        self.widen(p, p);
        self.positions.push(p);
    }

    /// Widens the bounds to take in `lo..hi`.
    #[inline(always)]
    fn widen(&mut self, lo: [f32; 3], hi: [f32; 3]) {
        // `min` and `max` start at +inf and -inf (see `Bucket::new`) and are
        // never NaN, so plain comparisons keep what `f32::min` and `max`
        // would (a NaN coordinate changes nothing; of 0 and -0 the first
        // stays) without their NaN handling. Widening by another bucket's
        // bounds gives what pushing its positions one by one would.
        for (((a, b), x), y) in self.min.iter_mut().zip(&mut self.max).zip(lo).zip(hi) {
            if x < *a {
                *a = x;
            }
            if y > *b {
                *b = y;
            }
        }
    }

    /// Moves the data of `other` (filled for the same material, by pushes
    /// alone) to the end of this bucket, leaving `other` empty: the result
    /// is what pushing `other`'s vertices here would have given. Where the
    /// two write different UV sets or tangents (a texture file that changed
    /// between the encoder's look and the writer's), missing arrays are
    /// filled with (0, 0) and default tangents and extra ones are dropped.
    ///
    /// The arrays are kept as they are, as a segment of their own (see
    /// [`Bucket::sealed`]), their indices renumbered in place: a batch's
    /// data is not copied again on its way to the file.
    pub fn append(&mut self, other: &mut Bucket) -> Result<(), ExportError> {
        let base = self.vertex_count();
        let added = other.positions.len();
        if base + added > u32::MAX as usize + 1 {
            return Err(too_many_vertices());
        }
        if self.sets.is_empty() && other.sets == [0] {
            self.start_coords();
        }
        if added == 0 {
            other.clear();
            return Ok(());
        }
        let mut part = std::mem::replace(other, Bucket::new());
        part.conform(&self.sets, self.tangents.is_some());
        if base > 0 {
            let base = base as u32;
            for t in &mut part.indices {
                *t = t.map(|v| v + base);
            }
        }
        self.widen(part.min, part.max);
        if !self.positions.is_empty() || !self.indices.is_empty() {
            let own = self.take_arrays();
            self.sealed.push(own);
        }
        self.sealed.push(part);
        Ok(())
    }

    /// Lays out a segment's data as a bucket writing the UV `sets` (and
    /// tangents if `tangents`) holds it.
    fn conform(&mut self, sets: &[usize], tangents: bool) {
        self.vertex_room = 0;
        let n = self.positions.len();
        if self.sets != sets {
            let mut coords = std::mem::take(&mut self.coords);
            self.coords = sets
                .iter()
                .map(|set| match self.sets.iter().position(|s| s == set) {
                    Some(k) => std::mem::take(&mut coords[k]),
                    None => vec![[0.0; 2]; n],
                })
                .collect();
            self.sets = sets.to_vec();
        }
        match (tangents, &self.tangents) {
            (true, None) => {
                self.tangents = Some(
                    self.normals
                        .iter()
                        .map(|n| {
                            let n = DVec3::from(n.map(f64::from));
                            vertex_tangent(n, (n.any_orthonormal_vector(), 1.0))
                        })
                        .collect(),
                )
            }
            (false, Some(_)) => self.tangents = None,
            _ => {}
        }
    }

    /// This bucket's own arrays as a segment, leaving them empty.
    fn take_arrays(&mut self) -> Bucket {
        Bucket {
            positions: std::mem::take(&mut self.positions),
            normals: std::mem::take(&mut self.normals),
            sets: self.sets.clone(),
            coords: self.coords.iter_mut().map(std::mem::take).collect(),
            tex_coords: self.tex_coords.clone(),
            tangents: self.tangents.as_mut().map(std::mem::take),
            indices: std::mem::take(&mut self.indices),
            features: std::mem::take(&mut self.features),
            min: self.min,
            max: self.max,
            sealed: Vec::new(),
            vertex_room: std::mem::take(&mut self.vertex_room),
        }
    }

    /// Copies the segments appended whole into this bucket's own arrays,
    /// so that vertices can be pushed again (their numbers follow the
    /// bucket's own positions). Feature ids are copied as they are: the
    /// vertices without theirs yet (`GltfWriter::sync_features` gives them)
    /// are always the last ones, since data only ever comes at the end, so
    /// the ids copied stay those of the first vertices.
    pub fn consolidate(&mut self) {
        if self.sealed.is_empty() {
            return;
        }
        let own = self.take_arrays();
        let sealed = std::mem::take(&mut self.sealed);
        let total: usize =
            sealed.iter().map(|s| s.positions.len()).sum::<usize>() + own.positions.len();
        self.positions.reserve_exact(total);
        self.normals.reserve_exact(total);
        for s in sealed.iter().chain(std::iter::once(&own)) {
            self.positions.extend_from_slice(&s.positions);
            self.normals.extend_from_slice(&s.normals);
            for (c, from) in self.coords.iter_mut().zip(&s.coords) {
                c.extend_from_slice(from);
            }
            if let (Some(t), Some(from)) = (&mut self.tangents, &s.tangents) {
                t.extend_from_slice(from);
            }
            self.indices.extend_from_slice(&s.indices);
            self.features.extend_from_slice(&s.features);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(uvs: bool) -> Bucket {
        let mut b = Bucket::new();
        let src = [DVec2::new(0.25, 0.75), DVec2::new(1.0, 0.0)];
        let sources = [uvs.then_some(&src[..])];
        let sets = if uvs {
            b.start_coords();
            &sources[..]
        } else {
            &sources[..0]
        };
        for (i, x) in [-1.5, 2.0].into_iter().enumerate() {
            b.push_vertex(DVec3::new(x, 0.5, -x), DVec3::Y, sets, i, (DVec3::X, 1.0))
                .unwrap();
        }
        b.indices.push([0, 1, 0]);
        b
    }

    #[test]
    fn appending_gives_what_pushing_gives() {
        let mut whole = Bucket::new();
        let mut parts = Bucket::new();
        for uvs in [false, true, false] {
            let mut part = sample(uvs);
            // Pushed into `whole` directly, as one writer would.
            if uvs && whole.sets.is_empty() {
                whole.start_coords();
            }
            let base = whole.positions.len() as u32;
            let src = [DVec2::new(0.25, 0.75), DVec2::new(1.0, 0.0)];
            let sources = [uvs.then_some(&src[..])];
            let n = whole.sets.len();
            for (i, x) in [-1.5, 2.0].into_iter().enumerate() {
                whole
                    .push_vertex(
                        DVec3::new(x, 0.5, -x),
                        DVec3::Y,
                        &sources[..n],
                        i,
                        (DVec3::X, 1.0),
                    )
                    .unwrap();
            }
            whole.indices.push([base, base + 1, base]);
            let data = part.positions.as_ptr();
            parts.append(&mut part).unwrap();
            assert!(part.positions.is_empty() && part.indices.is_empty());
            // Kept as it was, not copied.
            assert_eq!(parts.sealed.last().unwrap().positions.as_ptr(), data);
        }
        assert_eq!(parts.sealed.len(), 3);
        assert_eq!(parts.vertex_count(), 6);
        assert!(parts.positions.is_empty());
        let sealed_indices: Vec<[u32; 3]> =
            parts.segments().flat_map(|s| s.indices.clone()).collect();
        assert_eq!(sealed_indices, [[0, 1, 0], [2, 3, 2], [4, 5, 4]]);
        parts.consolidate();
        assert!(parts.sealed.is_empty());
        assert_eq!(parts.positions, whole.positions);
        assert_eq!(parts.normals, whole.normals);
        assert_eq!(parts.sets, [0]);
        assert_eq!(parts.coords, whole.coords);
        assert_eq!(parts.coords[0].len(), 6);
        assert_eq!(parts.coords[0][0], [0.0, 0.0]);
        assert_eq!(parts.coords[0][2], [0.25, 0.25]);
        assert_eq!(parts.indices, [[0, 1, 0], [2, 3, 2], [4, 5, 4]]);
        assert_eq!((parts.min, parts.max), (whole.min, whole.max));
        assert_eq!(parts.min, [-1.5, 0.5, -2.0]);
        assert_eq!(parts.max, [2.0, 0.5, 1.5]);
    }

    #[test]
    fn differing_layouts_are_filled_not_lost() {
        let mut target = Bucket::with_layout(vec![0, 5], true);
        let mut part = sample(false);
        target.append(&mut part).unwrap();
        target.consolidate();
        assert_eq!(target.positions.len(), 2);
        assert_eq!(target.coords, [vec![[0.0; 2]; 2], vec![[0.0; 2]; 2]]);
        let t = target.tangents.as_ref().unwrap();
        assert_eq!(t.len(), 2);
        // Perpendicular to the normal (y), as glTF requires.
        assert!(t.iter().all(|t| t[1].abs() < 1e-6 && t[3] == 1.0));
    }

    /// Vertices pushed before and after appended segments keep the order
    /// and numbering of pushing everything.
    #[test]
    fn pushes_and_appends_interleave() {
        let mut b = sample(true);
        b.append(&mut sample(true)).unwrap();
        // The pushed vertices became a segment of their own, before the
        // appended one.
        assert_eq!(b.sealed.len(), 2);
        assert!(b.positions.is_empty());
        b.consolidate();
        let src = [DVec2::new(0.25, 0.75), DVec2::new(1.0, 0.0)];
        let v = b
            .push_vertex(
                DVec3::new(9.0, 0.0, 0.0),
                DVec3::X,
                &[Some(&src[..])],
                1,
                (DVec3::Y, 1.0),
            )
            .unwrap();
        assert_eq!(v, 4);
        b.indices.push([4, 0, 2]);
        b.append(&mut sample(true)).unwrap();
        b.consolidate();
        assert_eq!(b.positions.len(), 7);
        assert_eq!(b.positions[4], [9.0, 0.0, 0.0]);
        assert_eq!(b.positions[5], [-1.5, 0.5, 1.5]);
        assert_eq!(b.indices, [[0, 1, 0], [2, 3, 2], [4, 0, 2], [5, 6, 5]]);
        assert_eq!(b.coords[0].len(), 7);
        assert_eq!(b.coords[0][4], [1.0, 1.0]);
        assert_eq!(b.max[0], 9.0);
    }

    /// Feature ids given so far belong to the first vertices, and stay
    /// theirs when the segments are copied together.
    #[test]
    fn consolidating_keeps_feature_ids_with_their_vertices() {
        let mut b = sample(false);
        b.features = vec![0.0; 2];
        b.append(&mut sample(false)).unwrap();
        b.sealed[1].features = vec![1.0; 2];
        b.append(&mut sample(false)).unwrap();
        assert_eq!(b.sealed.len(), 3);
        b.consolidate();
        assert_eq!(b.positions.len(), 6);
        // The last two vertices have no id yet; the others keep theirs.
        assert_eq!(b.features, [0.0, 0.0, 1.0, 1.0]);
    }

    /// An empty batch with texture coordinates still starts the model's
    /// UV set 0, as appending its vertices one by one would.
    #[test]
    fn an_empty_batch_with_coordinates_starts_set_0() {
        let mut b = sample(false);
        let mut empty = Bucket::new();
        empty.start_coords();
        b.append(&mut empty).unwrap();
        assert_eq!(b.sets, [0]);
        assert_eq!(b.coords, [vec![[0.0; 2]; 2]]);
        assert!(b.sealed.is_empty());
    }

    #[test]
    fn empty_buckets_leave_the_bounds_alone() {
        let mut target = sample(false);
        let (min, max) = (target.min, target.max);
        target.append(&mut Bucket::new()).unwrap();
        assert_eq!((target.min, target.max), (min, max));
        assert_eq!(target.positions.len(), 2);
    }
}
