//! Wavefront OBJ + MTL output.
//!
//! Everything is written as meshes come, so memory does not grow with the
//! model: vertices (`v`, `vt`, `vn`; a position used by several faces of a
//! mesh is one `v`; equal UVs and normals share one `vt` / `vn`, also
//! across meshes), then each face, after a `usemtl` line where its material
//! differs from the face before. The MTL file is written in `finish`.
//!
//! Faces are written as polygons; faces with holes are written as their
//! triangles, since OBJ has no holes. Numbers are written with at most six
//! decimals (micrometres for coordinates in metres), trailing zeros dropped.

use crate::output_file::OutputFile;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use cga_geometry::{Material, Mesh};

use crate::hash::FastMap;
use crate::materials::MaterialTable;
use crate::textures::Textures;
use crate::{ExportError, ExportStats, FaceData};

/// MTL statements for texture channels, with the channel index
/// (see `cga_geometry::TEXTURE_CHANNELS`).
const MAPS: [(&str, usize); 5] = [
    ("map_Kd", 0),   // colormap
    ("map_bump", 1), // bumpmap
    ("map_Ks", 3),   // specularmap
    ("map_d", 4),    // opacitymap
    ("norm", 5),     // normalmap
];

/// Entries above which the `vt` / `vn` lookup tables are emptied.
const SHARED_LOOKUP_LIMIT: usize = 1 << 16;

/// How the MTL names one texture channel's file.
enum MapRef {
    /// A texture file that was found.
    Found(u32),
    /// Not found: the path as the rule wrote it (the name still tells a
    /// reader, or a later copy of the textures, what was meant).
    Missing(Arc<str>),
}

pub(crate) struct ObjWriter {
    path: PathBuf,
    out: BufWriter<OutputFile>,
    mtl_name: String,
    line: Vec<u8>,
    v_count: u32,
    vt_count: u32,
    vn_count: u32,
    /// `v` index of each position of the mesh being added (0: not written).
    position_v: Vec<u32>,
    vt_ids: FastMap<[u64; 2], u32>,
    vn_ids: FastMap<[u64; 3], u32>,
    /// (v, vt, vn) of each corner of the face being added.
    corner_refs: Vec<[u32; 3]>,
    /// Per material: its MTL name and whether a face used it.
    names: Vec<String>,
    used: Vec<bool>,
    /// The material of the last `usemtl` line.
    current: Option<u32>,
    maps: Vec<[Option<MapRef>; MAPS.len()]>,
}

impl ObjWriter {
    pub(crate) fn create(path: &Path, header: Option<String>) -> Result<ObjWriter, ExportError> {
        let file = crate::output_file::create(path, false).map_err(|e| ExportError::io(path, e))?;
        let stem = path
            .file_stem()
            .map_or("model".into(), |s| s.to_string_lossy());
        let mtl_name = format!("{stem}.mtl");
        let mut out = BufWriter::with_capacity(1 << 16, file);
        // Material names are tokens (no spaces), the MTL file name may not be.
        writeln!(out, "# CGA engine model").map_err(|e| ExportError::io(path, e))?;
        if let Some(h) = header {
            writeln!(out, "{h}").map_err(|e| ExportError::io(path, e))?;
        }
        writeln!(out, "mtllib {mtl_name}").map_err(|e| ExportError::io(path, e))?;
        Ok(ObjWriter {
            path: path.to_path_buf(),
            out,
            mtl_name,
            line: Vec::with_capacity(256),
            v_count: 0,
            vt_count: 0,
            vn_count: 0,
            position_v: Vec::new(),
            vt_ids: FastMap::default(),
            vn_ids: FastMap::default(),
            corner_refs: Vec::new(),
            names: Vec::new(),
            used: Vec::new(),
            current: None,
            maps: Vec::new(),
        })
    }

    /// File names this writer creates next to the output.
    pub(crate) fn file_names(&self) -> Vec<String> {
        let own = self
            .path
            .file_name()
            .map(|n| n.to_string_lossy().into_owned());
        own.into_iter().chain([self.mtl_name.clone()]).collect()
    }

    pub(crate) fn new_material(
        &mut self,
        name: &str,
        material: &Material,
        textures: &mut Textures,
        warnings: &mut Vec<String>,
    ) {
        let maps = MAPS.map(|(_, channel)| {
            let path = &material.maps[channel].path;
            if path.is_empty() {
                return None;
            }
            Some(match textures.resolve(path, warnings) {
                Some(t) => MapRef::Found(t),
                None => MapRef::Missing(path.clone()),
            })
        });
        self.maps.push(maps);
        self.names.push(name.to_string());
        self.used.push(false);
    }

    pub(crate) fn begin_mesh(&mut self, mesh: &Mesh) {
        self.position_v.clear();
        self.position_v.resize(mesh.positions.len(), 0);
        // UVs and normals repeat across shapes (every wall facing south has
        // the same normal), so they are shared across meshes; the tables are
        // emptied now and then so memory stays bounded.
        if self.vt_ids.len() > SHARED_LOOKUP_LIMIT {
            self.vt_ids.clear();
        }
        if self.vn_ids.len() > SHARED_LOOKUP_LIMIT {
            self.vn_ids.clear();
        }
        self.corner_refs.clear();
        self.corner_refs.resize(mesh.corners.len(), [0; 3]);
    }

    /// Starts the group of a lot: `g NAME` (whitespace in the name made
    /// `_`), so that a modelling program can pick one building out of a
    /// city. Each group names its material again.
    pub(crate) fn begin_group(&mut self, name: &str) -> Result<(), ExportError> {
        let name: String = name
            .trim()
            .chars()
            .map(|c| {
                if c.is_whitespace() || c.is_control() {
                    '_'
                } else {
                    c
                }
            })
            .collect();
        let name = if name.is_empty() { "lot".into() } else { name };
        self.current = None;
        writeln!(self.out, "g {name}").map_err(|e| ExportError::io(&self.path, e))
    }

    pub(crate) fn add_face(&mut self, f: &FaceData) -> Result<(), ExportError> {
        let mesh = f.mesh;
        let uvs = mesh.uvs[0].as_deref();
        let loops = f.loops;
        for &l in loops {
            for c in mesh.loop_corners(l) {
                let position = mesh.corners[c] as usize;
                let mut v = self.position_v[position];
                if v == 0 {
                    let p = f.positions[position];
                    v = next(&mut self.v_count)?;
                    self.position_v[position] = v;
                    write_line(&mut self.out, &mut self.line, "v", &[p.x, p.y, p.z])
                        .map_err(|e| ExportError::io(&self.path, e))?;
                }
                let vt = match uvs {
                    None => 0,
                    Some(uvs) => {
                        let t = uvs[c];
                        let key = [t.x, t.y].map(f64::to_bits);
                        match self.vt_ids.get(&key) {
                            Some(&vt) => vt,
                            None => {
                                let vt = next(&mut self.vt_count)?;
                                self.vt_ids.insert(key, vt);
                                write_line(&mut self.out, &mut self.line, "vt", &[t.x, t.y])
                                    .map_err(|e| ExportError::io(&self.path, e))?;
                                vt
                            }
                        }
                    }
                };
                let n = match f.normals {
                    Some(normals) => normals[c].try_normalize().unwrap_or_else(|| f.normal()),
                    None => f.normal(),
                };
                let key = [n.x, n.y, n.z].map(f64::to_bits);
                let vn = match self.vn_ids.get(&key) {
                    Some(&vn) => vn,
                    None => {
                        let vn = next(&mut self.vn_count)?;
                        self.vn_ids.insert(key, vn);
                        write_line(&mut self.out, &mut self.line, "vn", &[n.x, n.y, n.z])
                            .map_err(|e| ExportError::io(&self.path, e))?;
                        vn
                    }
                };
                self.corner_refs[c] = [v, vt, vn];
            }
        }
        let io = |e| ExportError::io(&self.path, e);
        if self.current != Some(f.material) {
            self.current = Some(f.material);
            self.used[f.material as usize] = true;
            writeln!(self.out, "usemtl {}", self.names[f.material as usize]).map_err(io)?;
        }
        let (line, refs) = (&mut self.line, &self.corner_refs);
        if loops.len() == 1 {
            write_face(
                &mut self.out,
                line,
                mesh.loop_corners(loops[0]).map(|c| refs[c]),
            )
            .map_err(io)?;
        } else {
            for t in f.triangles {
                write_face(&mut self.out, line, t.iter().map(|&c| refs[c as usize])).map_err(io)?;
            }
        }
        Ok(())
    }

    pub(crate) fn finish(
        mut self,
        table: &MaterialTable,
        textures: &Textures,
        stats: &mut ExportStats,
    ) -> Result<(), ExportError> {
        let path = self.path.clone();
        self.out.flush().map_err(|e| ExportError::io(&path, e))?;
        let used: Vec<u32> = (0..self.used.len() as u32)
            .filter(|&id| self.used[id as usize])
            .collect();

        let mtl_path = self.path.with_file_name(&self.mtl_name);
        let file = crate::output_file::create(&mtl_path, false)
            .map_err(|e| ExportError::io(&mtl_path, e))?;
        let mut mtl = BufWriter::new(file);
        let mut copied = Vec::new();
        for &id in &used {
            write_material(
                &mut mtl,
                table.name(id),
                table.get(id),
                &self.maps[id as usize],
                textures,
                &mut copied,
            )
            .map_err(|e| ExportError::io(&mtl_path, e))?;
        }
        mtl.flush().map_err(|e| ExportError::io(&mtl_path, e))?;
        copied.sort_unstable();
        copied.dedup();
        textures.copy_all(copied.iter().copied())?;

        stats.vertices += self.v_count as u64;
        stats.materials += used.len() as u64;
        stats.textures += copied.len() as u64;
        Ok(())
    }
}

fn write_material(
    w: &mut impl Write,
    name: &str,
    m: &Material,
    maps: &[Option<MapRef>],
    textures: &Textures,
    used_textures: &mut Vec<u32>,
) -> std::io::Result<()> {
    let mut line = Vec::new();
    writeln!(w, "newmtl {name}\nillum 2")?;
    write_line(w, &mut line, "Kd", &m.color)?;
    write_line(w, &mut line, "Ka", &m.ambient)?;
    write_line(w, &mut line, "Ks", &m.specular)?;
    if m.emissive != [0.0; 3] {
        write_line(w, &mut line, "Ke", &m.emissive)?;
    }
    write_line(w, &mut line, "Ns", &[m.shininess])?;
    write_line(w, &mut line, "d", &[m.opacity])?;
    for ((keyword, _), map) in MAPS.iter().zip(maps) {
        match map {
            None => {}
            Some(MapRef::Found(t)) => {
                used_textures.push(*t);
                writeln!(w, "{keyword} {}", textures.reference(*t))?;
            }
            Some(MapRef::Missing(path)) => writeln!(w, "{keyword} {path}")?,
        }
    }
    writeln!(w)
}

/// Writes `f v/vt/vn ...` and a newline.
fn write_face(
    w: &mut impl Write,
    line: &mut Vec<u8>,
    corners: impl Iterator<Item = [u32; 3]>,
) -> std::io::Result<()> {
    line.clear();
    line.push(b'f');
    for [v, vt, vn] in corners {
        line.push(b' ');
        push_u32(line, v);
        line.push(b'/');
        if vt != 0 {
            push_u32(line, vt);
        }
        line.push(b'/');
        push_u32(line, vn);
    }
    line.push(b'\n');
    w.write_all(line)
}

/// The next 1-based index of a counter.
fn next(count: &mut u32) -> Result<u32, ExportError> {
    *count = count
        .checked_add(1)
        .ok_or_else(|| ExportError::TooLarge("more than 2^32 OBJ vertices".into()))?;
    Ok(*count)
}

/// Writes `keyword x y ...` and a newline.
fn write_line(
    w: &mut impl Write,
    line: &mut Vec<u8>,
    keyword: &str,
    values: &[f64],
) -> std::io::Result<()> {
    line.clear();
    line.extend_from_slice(keyword.as_bytes());
    for &x in values {
        line.push(b' ');
        push_f64(line, x);
    }
    line.push(b'\n');
    w.write_all(line)
}

/// Appends `x` with at most six decimals, without trailing zeros (`2.5`,
/// `-0.333333`, `10`). Much faster than `format!` and gives compact files;
/// values too large for that (|x| >= 9e9) use Rust's shortest form.
fn push_f64(out: &mut Vec<u8>, x: f64) {
    const SCALE: f64 = 1e6;
    let scaled = (x * SCALE).round();
    if scaled.is_nan() || scaled.abs() >= 9e15 {
        if x.is_finite() {
            out.extend_from_slice(format!("{x}").as_bytes());
        } else {
            out.push(b'0');
        }
        return;
    }
    let mut n = scaled as i64;
    if n == 0 {
        // Also for -0.0 and tiny negatives: `-0` would be odd.
        out.push(b'0');
        return;
    }
    if n < 0 {
        out.push(b'-');
        n = -n;
    }
    push_u64(out, (n / 1_000_000) as u64);
    let mut frac = n % 1_000_000;
    if frac != 0 {
        let mut digits = 6;
        while frac % 10 == 0 {
            frac /= 10;
            digits -= 1;
        }
        out.push(b'.');
        let mut buf = [b'0'; 6];
        for d in buf[..digits].iter_mut().rev() {
            *d = b'0' + (frac % 10) as u8;
            frac /= 10;
        }
        out.extend_from_slice(&buf[..digits]);
    }
}

fn push_u32(out: &mut Vec<u8>, n: u32) {
    push_u64(out, n as u64);
}

fn push_u64(out: &mut Vec<u8>, mut n: u64) {
    let mut buf = [0u8; 20];
    let mut i = buf.len();
    loop {
        i -= 1;
        buf[i] = b'0' + (n % 10) as u8;
        n /= 10;
        if n == 0 {
            break;
        }
    }
    out.extend_from_slice(&buf[i..]);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fmt(x: f64) -> String {
        let mut v = Vec::new();
        push_f64(&mut v, x);
        String::from_utf8(v).unwrap()
    }

    #[test]
    fn numbers_are_compact_and_rounded() {
        assert_eq!(fmt(0.0), "0");
        assert_eq!(fmt(-0.0), "0");
        assert_eq!(fmt(-1e-9), "0");
        assert_eq!(fmt(2.5), "2.5");
        assert_eq!(fmt(-2.5), "-2.5");
        assert_eq!(fmt(10.0), "10");
        assert_eq!(fmt(0.1 + 0.2), "0.3");
        assert_eq!(fmt(1.0 / 3.0), "0.333333");
        assert_eq!(fmt(-0.000_001), "-0.000001");
        assert_eq!(fmt(0.05), "0.05");
        assert_eq!(fmt(123_456.789_012_3), "123456.789012");
        assert_eq!(fmt(1e12), "1000000000000");
        assert_eq!(fmt(f64::NAN), "0");
    }

    #[test]
    fn integers() {
        let mut v = Vec::new();
        push_u32(&mut v, 0);
        v.push(b' ');
        push_u32(&mut v, 4_294_967_295);
        assert_eq!(v, b"0 4294967295");
    }
}
