//! The file system as it is.

use std::io;
use std::path::{Path, PathBuf};

use crate::{normalize, Metadata, World};

/// Files on disk, read with `std::fs`.
#[derive(Clone, Copy, Debug, Default)]
pub struct DiskWorld;

impl World for DiskWorld {
    fn read(&self, path: &Path) -> io::Result<Vec<u8>> {
        std::fs::read(path)
    }

    fn open(&self, path: &Path) -> io::Result<Box<dyn io::Read + Send>> {
        Ok(Box::new(io::BufReader::with_capacity(
            1 << 16,
            std::fs::File::open(path)?,
        )))
    }

    fn disk_path(&self, path: &Path) -> Option<PathBuf> {
        path.is_file().then(|| path.to_path_buf())
    }

    fn read_prefix(&self, path: &Path, max: usize) -> io::Result<Vec<u8>> {
        use std::io::Read;
        let mut head = Vec::new();
        std::fs::File::open(path)?
            .take(max as u64)
            .read_to_end(&mut head)?;
        Ok(head)
    }

    fn metadata(&self, path: &Path) -> Option<Metadata> {
        let m = std::fs::metadata(path).ok()?;
        Some(Metadata {
            is_dir: m.is_dir(),
            len: if m.is_dir() { 0 } else { m.len() },
            modified: m.modified().ok(),
        })
    }

    fn read_dir(&self, path: &Path) -> io::Result<Vec<PathBuf>> {
        std::fs::read_dir(path)?
            .map(|e| e.map(|e| e.path()))
            .collect()
    }

    fn canonical(&self, path: &Path) -> PathBuf {
        canonical_on_disk(path)
    }
}

/// `path` with symbolic links resolved; for a path that does not exist,
/// its nearest existing ancestor's canonical path joined with the rest
/// (lexically normalised), so that a missing file inside a linked folder
/// still names where it would be.
pub(crate) fn canonical_on_disk(path: &Path) -> PathBuf {
    if let Ok(c) = std::fs::canonicalize(path) {
        return c;
    }
    let normal = normalize(path);
    let mut rest = Vec::new();
    let mut dir = normal.as_path();
    while let Some(parent) = dir.parent() {
        if let Some(name) = dir.file_name() {
            rest.push(name.to_os_string());
        }
        if let Ok(mut c) = std::fs::canonicalize(parent) {
            for name in rest.iter().rev() {
                c.push(name);
            }
            return c;
        }
        dir = parent;
    }
    normal
}
