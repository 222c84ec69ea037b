//! A large GLB's JSON without holding it: the accessors and buffer views of
//! its lots' primitives (most of the JSON of a model with a node per lot:
//! four to six of each per primitive, 200,000 for 10,000 lots) are written
//! as compact JSON text to temporary files as they are laid out, instead of
//! being kept as structures until the whole document is serialised. The
//! document keeps one marker object in each array where the spooled items
//! belong (they come first), and the JSON chunk is written as the
//! document's text with each marker replaced by its file's contents: the
//! same bytes as serialising the whole document at once, since compact JSON
//! writes an array's items one after the other, separated by commas.

use std::fs::File;
use std::io::{self, BufWriter, Read, Seek, SeekFrom, Write};

use gltf_json as json;
use serde::Serialize;

/// A GLB with at least this many primitives spools their accessors and
/// views; smaller models (3D Tiles' tiles, single buildings) keep them in
/// the document and need no temporary file.
const SPOOL_FROM_PRIMITIVES: usize = 2048;

/// Whether a GLB of `primitives` primitives spools their JSON.
pub(crate) fn spools(primitives: usize) -> bool {
    #[cfg(test)]
    {
        let forced = tests::SPOOL_FROM.load(std::sync::atomic::Ordering::Relaxed);
        if forced > 0 {
            return primitives >= forced;
        }
    }
    primitives >= SPOOL_FROM_PRIMITIVES
}

/// The spooled items of one JSON array: compact objects separated by
/// commas, in a temporary file (removed when closed).
pub(crate) struct Part {
    file: BufWriter<File>,
    bytes: u64,
    count: usize,
    /// The first error writing the file: reported when the GLB is written
    /// (laying out goes on counting indices meanwhile).
    error: Option<io::Error>,
}

impl Part {
    fn new() -> io::Result<Part> {
        Ok(Part {
            file: BufWriter::with_capacity(1 << 16, tempfile::tempfile()?),
            bytes: 0,
            count: 0,
            error: None,
        })
    }

    /// How many items were spooled.
    pub(crate) fn count(&self) -> usize {
        self.count
    }

    /// Spools `item`; its index among the spooled items.
    pub(crate) fn push(&mut self, item: &impl Serialize) -> usize {
        if let Err(e) = self.write(item) {
            self.error.get_or_insert(e);
        }
        self.count += 1;
        self.count - 1
    }

    fn write(&mut self, item: &impl Serialize) -> io::Result<()> {
        if self.count > 0 {
            self.file.write_all(b",")?;
            self.bytes += 1;
        }
        let mut w = Counted {
            out: &mut self.file,
            len: 0,
        };
        serde_json::to_writer(&mut w, item)?;
        self.bytes += w.len;
        Ok(())
    }

    fn into_reader(self) -> io::Result<(File, u64)> {
        if let Some(e) = self.error {
            return Err(e);
        }
        let mut file = self.file.into_inner().map_err(|e| e.into_error())?;
        file.seek(SeekFrom::Start(0))?;
        Ok((file, self.bytes))
    }
}

/// The spooled accessors and buffer views of a GLB being laid out.
pub(crate) struct Spool {
    pub(crate) accessors: Part,
    pub(crate) views: Part,
}

impl Spool {
    /// A spool in two temporary files; `None` if they cannot be created
    /// (the document then holds everything, as for small models).
    pub(crate) fn create() -> Option<Spool> {
        #[cfg(test)]
        tests::CREATED.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        Some(Spool {
            accessors: Part::new().ok()?,
            views: Part::new().ok()?,
        })
    }
}

/// The object standing in the document's accessors for the spooled ones.
pub(crate) fn accessor_marker() -> json::Accessor {
    json::Accessor {
        buffer_view: None,
        byte_offset: None,
        count: json::validation::USize64(0),
        component_type: json::validation::Checked::Valid(json::accessor::GenericComponentType(
            json::accessor::ComponentType::U8,
        )),
        extensions: None,
        extras: Default::default(),
        type_: json::validation::Checked::Valid(json::accessor::Type::Scalar),
        min: None,
        max: None,
        name: Some(MARKER.into()),
        normalized: false,
        sparse: None,
    }
}

/// The object standing in the document's buffer views for the spooled
/// ones.
pub(crate) fn view_marker() -> json::buffer::View {
    json::buffer::View {
        buffer: json::Index::new(u32::MAX),
        byte_length: json::validation::USize64(0),
        byte_offset: None,
        byte_stride: None,
        name: Some(MARKER.into()),
        target: None,
        extensions: None,
        extras: Default::default(),
    }
}

/// The markers' name. A name in the model (a lot's, a material's) cannot
/// make a marker's text appear elsewhere in the document: inside a JSON
/// string its quotes would be escaped.
const MARKER: &str = "\u{0}spooled";

/// A GLB's JSON chunk: the document's compact text, and where the spooled
/// items replace a marker.
pub(crate) struct GlbJson {
    text: Vec<u8>,
    /// Sorted by position: (byte offset of a marker in `text`, its length,
    /// the items' file and length).
    splices: Vec<(usize, usize, File, u64)>,
}

impl GlbJson {
    /// The JSON of `root`, with `spool`'s items (if any) in place of the
    /// markers `root` holds for them. `room`: the bytes the JSON is
    /// expected to take, kept from the start (growing the text from empty
    /// takes a fresh block at every doubling, at the model's last step);
    /// not with a spool, which holds most of it.
    pub(crate) fn new(root: &json::Root, spool: Option<Spool>, room: usize) -> io::Result<GlbJson> {
        let mut text = Vec::with_capacity(if spool.is_none() { room } else { 0 });
        serde_json::to_writer(&mut text, root)?;
        let mut splices = Vec::new();
        if let Some(spool) = spool {
            let parts = [
                (spool.accessors, serde_json::to_vec(&accessor_marker())?),
                (spool.views, serde_json::to_vec(&view_marker())?),
            ];
            for (part, marker) in parts {
                if part.count == 0 {
                    continue;
                }
                let at = memchr::memmem::find(&text, &marker).ok_or_else(|| {
                    io::Error::other("the model's JSON lost the place of its spooled accessors")
                })?;
                let (file, bytes) = part.into_reader()?;
                splices.push((at, marker.len(), file, bytes));
            }
            splices.sort_by_key(|s| s.0);
        }
        Ok(GlbJson { text, splices })
    }

    /// Its length in bytes.
    pub(crate) fn len(&self) -> u64 {
        self.splices
            .iter()
            .fold(self.text.len() as u64, |n, s| n - s.1 as u64 + s.3)
    }

    /// Writes it to `out` (once: the spooled items are read from their
    /// files).
    pub(crate) fn write_to(&mut self, out: &mut impl Write) -> io::Result<()> {
        let mut from = 0;
        for (at, marker, file, bytes) in &mut self.splices {
            out.write_all(&self.text[from..*at])?;
            let copied = io::copy(&mut file.take(*bytes), out)?;
            if copied != *bytes {
                return Err(io::Error::other(
                    "a spooled part of the model's JSON is short",
                ));
            }
            from = *at + *marker;
        }
        out.write_all(&self.text[from..])
    }
}

/// A writer that counts the bytes passed through it.
struct Counted<W> {
    out: W,
    len: u64,
}

impl<W: Write> Write for Counted<W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let n = self.out.write(buf)?;
        self.len += n as u64;
        Ok(n)
    }
    fn flush(&mut self) -> io::Result<()> {
        self.out.flush()
    }
}

#[cfg(test)]
mod tests {
    use std::sync::atomic::{AtomicUsize, Ordering};

    use cga_geometry::{DVec3, Material, Mesh};

    use crate::{ExportOptions, ModelWriter};

    /// Forces the spool on from this many primitives (0: the default).
    pub(super) static SPOOL_FROM: AtomicUsize = AtomicUsize::new(0);
    /// Spools created.
    pub(super) static CREATED: AtomicUsize = AtomicUsize::new(0);

    /// A GLB of `lots` lots, each a quad in one of three materials, named
    /// with quotes and the markers' name; data written early and the JSON's
    /// room for only one lot if `early`.
    fn city(lots: usize, early: bool) -> Vec<u8> {
        let options = ExportOptions {
            flush_mib: if early { 0 } else { 64 },
            ..ExportOptions::default()
        };
        let mut w = ModelWriter::glb_in_memory(options).unwrap();
        if early {
            w.expect_lots(1);
        }
        let materials: Vec<Material> = (0..3)
            .map(|k| Material {
                color: [0.2 * k as f64, 0.5, 0.7],
                ..Material::default()
            })
            .collect();
        for lot in 0..lots {
            let name = format!("lot \"{lot}\" \u{0}spooled");
            w.begin_lot(&name, Some(serde_json::json!({ "index": lot })))
                .unwrap();
            let mut m = Mesh::new();
            let x = lot as f64 * 3.0;
            m.positions.extend([
                DVec3::new(x, 0.0, 0.0),
                DVec3::new(x + 2.0, 0.0, 0.0),
                DVec3::new(x + 2.0, 0.0, 1.5 + lot as f64 * 0.01),
                DVec3::new(x, 0.0, 1.5),
            ]);
            m.add_face(&[&[0, 1, 2, 3]], 0);
            m.materials = vec![materials[lot % 3].clone()].into();
            w.add_mesh(&m).unwrap();
        }
        w.finish_bytes().unwrap().0
    }

    #[test]
    fn spooled_json_is_the_json_held() {
        for early in [false, true] {
            SPOOL_FROM.store(usize::MAX, Ordering::Relaxed);
            let held = city(300, early);
            SPOOL_FROM.store(1, Ordering::Relaxed);
            let before = CREATED.load(Ordering::Relaxed);
            let spooled = city(300, early);
            assert!(
                CREATED.load(Ordering::Relaxed) > before,
                "no spool was made"
            );
            SPOOL_FROM.store(0, Ordering::Relaxed);
            assert!(held == spooled, "early {early}: the GLBs differ");
            let g = gltf::Gltf::from_slice(&spooled).unwrap();
            assert_eq!(g.nodes().count(), 300);
            // Per lot: positions, normals and indices.
            assert_eq!(g.accessors().count(), 900);
            assert_eq!(g.views().count(), 900);
            let last = g.meshes().last().unwrap().primitives().next().unwrap();
            let pos = last.get(&gltf::Semantic::Positions).unwrap();
            assert_eq!(pos.index(), 897);
            let top = pos.max().unwrap()[2].as_f64().unwrap();
            assert!((top - 4.49).abs() < 1e-6, "{top}");
            assert_eq!(
                g.nodes().next().unwrap().name(),
                Some("lot \"0\" \u{0}spooled")
            );
        }
    }
}
