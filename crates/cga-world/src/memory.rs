//! Files held in memory, over another world.

use std::collections::BTreeMap;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::{Arc, RwLock};
use std::time::SystemTime;

use crate::{normalize, Metadata, World};

/// Files held in memory (an editor's unsaved buffers, rule text given as a
/// string, a test's files), seen in front of a base world: a path held in
/// memory reads from memory, every other path from the base. Folders exist
/// where a held file's path goes through them, or in the base.
///
/// Files can be set and removed while the world is in use (an editor
/// changes a buffer); each setting counts as a new modification, so caches
/// keyed by [`Metadata::modified`] see the change.
pub struct MemoryWorld {
    files: RwLock<BTreeMap<PathBuf, Held>>,
    base: Option<Arc<dyn World>>,
}

#[derive(Clone)]
struct Held {
    bytes: Arc<[u8]>,
    modified: SystemTime,
}

impl MemoryWorld {
    /// Only the files set in memory: nothing else exists.
    pub fn new() -> MemoryWorld {
        MemoryWorld {
            files: RwLock::new(BTreeMap::new()),
            base: None,
        }
    }

    /// Files set in memory in front of `base`.
    pub fn over(base: Arc<dyn World>) -> MemoryWorld {
        MemoryWorld {
            files: RwLock::new(BTreeMap::new()),
            base: Some(base),
        }
    }

    /// Sets the file at `path` (relative paths are taken from the working
    /// folder) to `bytes`.
    pub fn set(&self, path: impl AsRef<Path>, bytes: impl Into<Vec<u8>>) {
        let held = Held {
            bytes: Arc::from(bytes.into()),
            modified: SystemTime::now(),
        };
        self.write().insert(normalize(path.as_ref()), held);
    }

    /// [`MemoryWorld::set`], returning the world: for building one in an
    /// expression.
    pub fn with(self, path: impl AsRef<Path>, bytes: impl Into<Vec<u8>>) -> MemoryWorld {
        self.set(path, bytes);
        self
    }

    /// Forgets the file held at `path`: the base's file (if any) shows again.
    pub fn remove(&self, path: impl AsRef<Path>) {
        self.write().remove(&normalize(path.as_ref()));
    }

    fn held(&self, path: &Path) -> Option<Held> {
        self.read_lock().get(&normalize(path)).cloned()
    }

    fn read_lock(&self) -> std::sync::RwLockReadGuard<'_, BTreeMap<PathBuf, Held>> {
        self.files.read().unwrap_or_else(|e| e.into_inner())
    }

    fn write(&self) -> std::sync::RwLockWriteGuard<'_, BTreeMap<PathBuf, Held>> {
        self.files.write().unwrap_or_else(|e| e.into_inner())
    }

    /// Whether a held file lies inside the folder `dir`.
    fn holds_folder(&self, dir: &Path) -> bool {
        let dir = normalize(dir);
        self.read_lock()
            .range(dir.clone()..)
            .next()
            .is_some_and(|(p, _)| p != &dir && p.starts_with(&dir))
    }
}

impl Default for MemoryWorld {
    fn default() -> Self {
        MemoryWorld::new()
    }
}

impl World for MemoryWorld {
    fn open(&self, path: &Path) -> io::Result<Box<dyn io::Read + Send>> {
        match (self.held(path), &self.base) {
            (Some(h), _) => Ok(Box::new(io::Cursor::new(h.bytes))),
            (None, Some(base)) => base.open(path),
            (None, None) => self
                .read(path)
                .map(|b| -> Box<dyn io::Read + Send> { Box::new(io::Cursor::new(b)) }),
        }
    }

    fn disk_path(&self, path: &Path) -> Option<PathBuf> {
        match self.held(path) {
            Some(_) => None,
            None => self.base.as_ref()?.disk_path(path),
        }
    }

    fn read(&self, path: &Path) -> io::Result<Vec<u8>> {
        if let Some(h) = self.held(path) {
            return Ok(h.bytes.to_vec());
        }
        match &self.base {
            Some(base) => base.read(path),
            None => Err(io::Error::new(
                io::ErrorKind::NotFound,
                format!("{} is not in memory", path.display()),
            )),
        }
    }

    fn read_prefix(&self, path: &Path, max: usize) -> io::Result<Vec<u8>> {
        match (self.held(path), &self.base) {
            (Some(h), _) => Ok(h.bytes[..max.min(h.bytes.len())].to_vec()),
            (None, Some(base)) => base.read_prefix(path, max),
            (None, None) => self.read(path),
        }
    }

    fn metadata(&self, path: &Path) -> Option<Metadata> {
        if let Some(h) = self.held(path) {
            return Some(Metadata {
                is_dir: false,
                len: h.bytes.len() as u64,
                modified: Some(h.modified),
            });
        }
        if self.holds_folder(path) {
            return Some(Metadata {
                is_dir: true,
                len: 0,
                modified: None,
            });
        }
        self.base.as_ref()?.metadata(path)
    }

    fn read_dir(&self, path: &Path) -> io::Result<Vec<PathBuf>> {
        let dir = normalize(path);
        let mut entries: Vec<PathBuf> = match &self.base {
            Some(base) if base.is_dir(path) => base.read_dir(path)?,
            _ if self.holds_folder(&dir) => Vec::new(),
            _ => {
                return Err(io::Error::new(
                    io::ErrorKind::NotFound,
                    format!("no folder {}", path.display()),
                ))
            }
        };
        for held in self.read_lock().keys() {
            let Ok(rest) = held.strip_prefix(&dir) else {
                continue;
            };
            if let Some(first) = rest.components().next() {
                let entry = dir.join(first.as_os_str());
                if !entries.contains(&entry) {
                    entries.push(entry);
                }
            }
        }
        Ok(entries)
    }

    fn canonical(&self, path: &Path) -> PathBuf {
        match &self.base {
            Some(base) if self.held(path).is_none() => base.canonical(path),
            _ => normalize(path),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn held_files_read_and_make_folders() {
        let w = MemoryWorld::new()
            .with("/p/rules/a.cga", "Lot --> X.")
            .with("/p/assets/t.txt", vec![1u8, 2]);
        assert_eq!(w.read(Path::new("/p/rules/a.cga")).unwrap(), b"Lot --> X.");
        assert_eq!(
            w.read_text(Path::new("/p/rules/../rules/a.cga")).unwrap(),
            "Lot --> X."
        );
        assert!(w.is_file(Path::new("/p/assets/t.txt")));
        assert!(w.is_dir(Path::new("/p")) && w.is_dir(Path::new("/p/rules")));
        assert!(!w.is_dir(Path::new("/p/rules/a.cga")));
        assert!(w.metadata(Path::new("/q")).is_none());
        let mut listed = w.read_dir(Path::new("/p")).unwrap();
        listed.sort();
        assert_eq!(
            listed,
            vec![PathBuf::from("/p/assets"), PathBuf::from("/p/rules")]
        );
        assert_eq!(
            w.read(Path::new("/nothing")).unwrap_err().kind(),
            io::ErrorKind::NotFound
        );
    }

    #[test]
    fn held_files_hide_the_base_until_removed() {
        let base = Arc::new(MemoryWorld::new().with("/p/a.cga", "base"));
        let w = MemoryWorld::over(base);
        assert_eq!(w.read(Path::new("/p/a.cga")).unwrap(), b"base");
        let before = w.metadata(Path::new("/p/a.cga")).unwrap().modified;
        w.set("/p/a.cga", "edited");
        assert_eq!(w.read(Path::new("/p/a.cga")).unwrap(), b"edited");
        assert_ne!(w.metadata(Path::new("/p/a.cga")).unwrap().modified, before);
        w.set("/p/b.cga", "new");
        let mut listed = w.read_dir(Path::new("/p")).unwrap();
        listed.sort();
        assert_eq!(
            listed,
            vec![PathBuf::from("/p/a.cga"), PathBuf::from("/p/b.cga")]
        );
        w.remove("/p/a.cga");
        assert_eq!(w.read(Path::new("/p/a.cga")).unwrap(), b"base");
    }
}
