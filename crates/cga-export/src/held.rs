//! A material's vertex data held until it is written as one primitive.
//!
//! The data is kept in the chunks it came in: an encoded batch's bucket is
//! moved here, not copied, so a model's geometry is in memory once, and a
//! chunk's room goes back to the encoders when it has been written. Each
//! chunk numbers its vertices from 0; the writer adds the vertices of the
//! chunks before it when it writes the indices. Meshes encoded on the
//! writing thread go into an open chunk after the others.

use std::io::Write;

use crate::bucket::{too_many_vertices, widen, Bucket};
use crate::ExportError;

#[derive(Default)]
pub(crate) struct Held {
    /// The UV sets every chunk carries, set 0 first (see `Bucket::sets`),
    /// and whether chunks carry tangents.
    pub sets: Vec<usize>,
    pub tangents: bool,
    /// Where meshes encoded on the writing thread go (after `chunks`).
    pub open: Bucket,
    chunks: Vec<Bucket>,
    vertices: usize,
    triangles: usize,
    min: [f32; 3],
    max: [f32; 3],
    /// The `TEXCOORD` arrays written, as positions in `sets` (sets with
    /// equal coordinates share one array), and the `TEXCOORD` index of
    /// each set.
    pub written_sets: Vec<usize>,
    pub tex_coords: Vec<u32>,
}

/// Vertex indices converted at a time when written (a chunk's indices plus
/// the vertices before it).
const INDEX_BLOCK: usize = 1 << 12;

impl Held {
    pub fn new(sets: Vec<usize>, tangents: bool) -> Held {
        Held {
            open: Bucket::with_layout(sets.clone(), tangents),
            sets,
            tangents,
            min: [f32::INFINITY; 3],
            max: [f32::NEG_INFINITY; 3],
            ..Held::default()
        }
    }

    /// Vertices held (the open chunk's once sealed).
    pub fn vertices(&self) -> usize {
        self.vertices
    }

    pub fn triangles(&self) -> usize {
        self.triangles
    }

    pub fn bounds(&self) -> ([f32; 3], [f32; 3]) {
        (self.min, self.max)
    }

    pub fn is_empty(&self) -> bool {
        self.triangles == 0 && self.open.indices.is_empty()
    }

    /// Adds a chunk after the data held (after the open chunk's, which is
    /// sealed first).
    pub fn push(&mut self, chunk: Bucket) -> Result<(), ExportError> {
        self.seal()?;
        self.add_chunk(chunk)
    }

    /// Makes the open chunk's data a chunk like the others.
    pub fn seal(&mut self) -> Result<(), ExportError> {
        if self.open.positions.is_empty() && self.open.indices.is_empty() {
            return Ok(());
        }
        let empty = Bucket::with_layout(self.sets.clone(), self.tangents);
        let open = std::mem::replace(&mut self.open, empty);
        self.add_chunk(open)
    }

    fn add_chunk(&mut self, mut chunk: Bucket) -> Result<(), ExportError> {
        let added = chunk.positions.len();
        if self.vertices + added > u32::MAX as usize + 1 {
            return Err(too_many_vertices());
        }
        if self.sets.is_empty() && chunk.sets == [0] {
            // The first mesh with UVs of an untextured material: the
            // vertices before it read (0, 0).
            self.sets.push(0);
            for c in &mut self.chunks {
                c.start_coords();
            }
            self.open.start_coords();
        }
        if chunk.sets != self.sets || chunk.tangents.is_some() != self.tangents {
            chunk.conform(&self.sets, self.tangents);
        }
        if added > 0 {
            widen(&mut self.min, &mut self.max, chunk.min, chunk.max);
        }
        self.vertices += added;
        self.triangles += chunk.indices.len();
        self.chunks.push(chunk);
        Ok(())
    }

    /// Bytes of vertex data held in chunks.
    pub fn bytes(&self) -> usize {
        self.vertices * (24 + 8 * self.sets.len() + if self.tangents { 16 } else { 0 })
            + self.triangles * 12
    }

    /// Keeps one coordinate array per distinct content: a layer whose UV
    /// set no mesh had reads set 0's array.
    pub fn merge_equal_coords(&mut self) {
        self.written_sets.clear();
        self.tex_coords.clear();
        for k in 0..self.sets.len() {
            // Compared as numbers: 0 equals -0, NaN equals nothing.
            let same = |d: usize| self.chunks.iter().all(|c| c.coords[d] == c.coords[k]);
            match self.written_sets.iter().position(|&d| same(d)) {
                Some(i) => self.tex_coords.push(i as u32),
                None => {
                    self.tex_coords.push(self.written_sets.len() as u32);
                    self.written_sets.push(k);
                }
            }
        }
    }

    /// Each UV set in an array of its own (no merging), as once anything
    /// was written early.
    pub fn unmerged_coords(&mut self) {
        self.written_sets = (0..self.sets.len()).collect();
        self.tex_coords = (0..self.sets.len() as u32).collect();
    }

    /// Writes the arrays in the order of the binary layout: positions,
    /// normals, the written UV sets, tangents, indices; `scratch` holds
    /// converted indices.
    pub fn write_arrays(
        &self,
        w: &mut impl Write,
        scratch: &mut Vec<[u32; 3]>,
    ) -> std::io::Result<()> {
        for c in &self.chunks {
            write_le(w, &c.positions)?;
        }
        for c in &self.chunks {
            write_le(w, &c.normals)?;
        }
        for &k in &self.written_sets {
            for c in &self.chunks {
                write_le(w, &c.coords[k])?;
            }
        }
        if self.tangents {
            for c in &self.chunks {
                write_le(w, c.tangents.as_deref().unwrap_or_default())?;
            }
        }
        let mut base = 0u32;
        for c in &self.chunks {
            if base == 0 {
                write_le(w, &c.indices)?;
            } else {
                for block in c.indices.chunks(INDEX_BLOCK) {
                    scratch.clear();
                    scratch.extend(block.iter().map(|t| t.map(|v| v + base)));
                    write_le(w, scratch)?;
                }
            }
            // At most 2^32 vertices (checked when added): the last chunk's
            // end may be 2^32, which is never a base.
            base = base.wrapping_add(c.positions.len() as u32);
        }
        Ok(())
    }

    /// Empties the held data (after it was written), handing the chunks'
    /// room to `spare`.
    pub fn clear(&mut self, spare: &mut Vec<Bucket>) {
        for mut c in self.chunks.drain(..) {
            c.clear();
            spare.push(c);
        }
        self.vertices = 0;
        self.triangles = 0;
        self.min = [f32::INFINITY; 3];
        self.max = [f32::NEG_INFINITY; 3];
    }
}

/// Writes values as the little-endian bytes glTF's binary buffer holds.
pub(crate) fn write_le<T: bytemuck::Pod>(w: &mut impl Write, values: &[T]) -> std::io::Result<()> {
    if cfg!(target_endian = "little") {
        return w.write_all(bytemuck::cast_slice(values));
    }
    // Every component is 4 bytes: swap each.
    let mut buf = Vec::with_capacity(1 << 16);
    for chunk in bytemuck::cast_slice::<T, [u8; 4]>(values).chunks(1 << 14) {
        buf.clear();
        buf.extend(
            chunk
                .iter()
                .flat_map(|b| u32::from_ne_bytes(*b).to_le_bytes()),
        );
        w.write_all(&buf)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use cga_geometry::{DVec2, DVec3};

    /// A chunk of `n` vertices along x from `x0` (UV set 0 if `uvs`) and
    /// one triangle per vertex after the first two.
    fn chunk(x0: f32, n: usize, uvs: bool) -> Bucket {
        let mut b = Bucket::new();
        if uvs {
            b.start_coords();
        }
        let src: Vec<DVec2> = (0..n).map(|i| DVec2::new(i as f64, 0.5)).collect();
        let sources = [uvs.then_some(&src[..])];
        for i in 0..n {
            let p = DVec3::new(x0 as f64 + i as f64, 1.0, 0.0);
            b.push_vertex(p, DVec3::Y, &sources[..b.sets.len()], i, (DVec3::X, 1.0))
                .unwrap();
        }
        for i in 2..n as u32 {
            b.indices.push([i - 2, i - 1, i]);
        }
        b
    }

    fn written(h: &Held) -> Vec<u8> {
        let mut out = Vec::new();
        h.write_arrays(&mut out, &mut Vec::new()).unwrap();
        out
    }

    #[test]
    fn chunks_write_as_one_array_with_indices_numbered_on() {
        let mut h = Held::new(Vec::new(), false);
        h.push(chunk(0.0, 3, false)).unwrap();
        h.push(chunk(10.0, 4, false)).unwrap();
        assert_eq!((h.vertices(), h.triangles()), (7, 3));
        assert_eq!(h.bounds(), ([0.0, 1.0, 0.0], [13.0, 1.0, 0.0]));
        h.unmerged_coords();
        let bytes = written(&h);
        assert_eq!(bytes.len(), h.bytes());
        let words: Vec<u32> = bytes
            .chunks(4)
            .map(|b| u32::from_le_bytes(b.try_into().unwrap()))
            .collect();
        // 7 positions, 7 normals, then the indices: the second chunk's
        // start at vertex 3.
        assert_eq!(&words[42..], [0, 1, 2, 3, 4, 5, 4, 5, 6]);
        assert_eq!(f32::from_bits(words[9]), 10.0);
        let mut spare = Vec::new();
        h.clear(&mut spare);
        assert_eq!(spare.len(), 2);
        assert!(spare
            .iter()
            .all(|b| b.positions.is_empty() && b.positions.capacity() >= 3));
        assert!(h.is_empty() && h.bytes() == 0);
    }

    #[test]
    fn uvs_that_come_late_give_earlier_vertices_zero_coordinates() {
        let mut h = Held::new(Vec::new(), false);
        h.push(chunk(0.0, 3, false)).unwrap();
        h.push(chunk(5.0, 3, true)).unwrap();
        // Encoded on the writing thread, without UVs.
        let open = chunk(9.0, 3, false);
        h.open = open;
        h.seal().unwrap();
        assert_eq!(h.sets, [0]);
        h.merge_equal_coords();
        assert_eq!(
            (h.written_sets.clone(), h.tex_coords.clone()),
            (vec![0], vec![0])
        );
        let coords: Vec<[f32; 2]> = h.chunks.iter().flat_map(|c| c.coords[0].clone()).collect();
        assert_eq!(coords.len(), 9);
        assert_eq!(coords[..3], [[0.0, 0.0]; 3]);
        assert_eq!(coords[3..6], [[0.0, 0.5], [1.0, 0.5], [2.0, 0.5]]);
        assert_eq!(coords[6..], [[0.0, 0.0]; 3]);
    }

    #[test]
    fn values_are_written_little_endian() {
        let mut out = Vec::new();
        write_le(&mut out, &[[1.5f32, -2.0]]).unwrap();
        write_le(&mut out, &[[7u32, 1, 256]]).unwrap();
        assert_eq!(
            out,
            [0, 0, 192, 63, 0, 0, 0, 192, 7, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0]
        );
    }

    #[test]
    fn coordinate_arrays_compare_as_numbers() {
        // Sets with equal numbers share one array (0 equals -0); NaN equals
        // nothing.
        let sets = vec![0, 1, 2, 3, 4];
        let mut h = Held::new(sets.clone(), false);
        let mut c = Bucket::with_layout(sets, false);
        c.push_position(DVec3::ZERO);
        c.normals.push([0.0, 1.0, 0.0]);
        c.coords = vec![
            vec![[0.0, 0.5]],
            vec![[-0.0, 0.5]],
            vec![[1.0, 0.5]],
            vec![[f32::NAN, 0.5]],
            vec![[f32::NAN, 0.5]],
        ];
        h.push(c).unwrap();
        h.merge_equal_coords();
        assert_eq!(h.tex_coords, [0, 0, 1, 2, 3]);
        assert_eq!(h.written_sets, [0, 2, 3, 4]);
    }

    #[test]
    fn equal_sets_share_one_array() {
        let mut h = Held::new(vec![0, 7], false);
        for x in [0.0, 4.0] {
            let mut c = chunk(x, 3, true);
            c.sets = vec![0, 7];
            let copy = c.coords[0].clone();
            c.coords.push(copy);
            h.push(c).unwrap();
        }
        h.merge_equal_coords();
        assert_eq!(h.written_sets, [0]);
        assert_eq!(h.tex_coords, [0, 0]);
        // A differing second set in one chunk is an array of its own.
        h.chunks[1].coords[1][0] = [9.0, 9.0];
        h.merge_equal_coords();
        assert_eq!(h.written_sets, [0, 1]);
        assert_eq!(h.tex_coords, [0, 1]);
    }
}
