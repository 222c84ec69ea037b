//! The files the engine reads, behind one trait.
//!
//! Rule files, imports, assets, textures, text tables and lot files are all
//! read through a [`World`]. Three implementations cover what hosts need:
//!
//! - [`DiskWorld`]: the file system as it is;
//! - [`MemoryWorld`]: files held in memory (an editor's unsaved buffers, a
//!   Python string, a test's rule file), over another world for everything
//!   else;
//! - [`ConfinedWorld`]: another world seen only inside given folders, for
//!   services that run rules they did not write (a rule may otherwise
//!   `readTextFile("/etc/passwd")`).
//!
//! Paths are plain [`Path`]s. A world answers for absolute paths; relative
//! ones are taken from the process's working folder, as the file system
//! takes them.

mod archive;
mod confined;
mod disk;
mod memory;
mod text;

use std::io;
use std::path::{Component, Path, PathBuf};
use std::time::SystemTime;

pub use archive::{archive_files, mount_archive};
pub use confined::ConfinedWorld;
pub use disk::DiskWorld;
pub use memory::MemoryWorld;
pub use text::decode_text;

/// What a world knows of a file or folder.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Metadata {
    pub is_dir: bool,
    /// Size in bytes (0 for folders).
    pub len: u64,
    /// When the file last changed, where the world knows it: caches compare
    /// it to tell an edited file from the one they hold.
    pub modified: Option<SystemTime>,
}

/// A source of files.
///
/// Implementations are shared between the threads that derive lots, so
/// they are `Send + Sync`; every method may be called from any thread.
pub trait World: Send + Sync {
    /// The bytes of the file at `path`.
    fn read(&self, path: &Path) -> io::Result<Vec<u8>>;

    /// What is at `path`; `None` when there is nothing, or nothing this
    /// world lets its user see.
    fn metadata(&self, path: &Path) -> Option<Metadata>;

    /// The entries of the folder at `path`, as full paths, in no particular
    /// order.
    fn read_dir(&self, path: &Path) -> io::Result<Vec<PathBuf>>;

    /// One name for a file however it is written (`a/../b.cga`, a symbolic
    /// link): the key of caches and of import-cycle detection. A file that
    /// does not exist gets its absolute, lexically normalised path.
    fn canonical(&self, path: &Path) -> PathBuf;

    /// The first `max` bytes of the file at `path` (all of it when shorter):
    /// image headers, without reading the image.
    fn read_prefix(&self, path: &Path, max: usize) -> io::Result<Vec<u8>> {
        let mut bytes = self.read(path)?;
        bytes.truncate(max);
        Ok(bytes)
    }

    /// Whether a file (not a folder) is at `path`.
    fn is_file(&self, path: &Path) -> bool {
        self.metadata(path).is_some_and(|m| !m.is_dir)
    }

    /// Whether a folder is at `path`.
    fn is_dir(&self, path: &Path) -> bool {
        self.metadata(path).is_some_and(|m| m.is_dir)
    }

    /// The text of the file at `path`, decoded as [`decode_text`] does.
    fn read_text(&self, path: &Path) -> io::Result<String> {
        self.read(path).map(|bytes| decode_text(&bytes))
    }

    /// A reader of the file at `path`, for files read as a stream (lot
    /// files of any size): the file itself on disk, else its bytes.
    fn open(&self, path: &Path) -> io::Result<Box<dyn io::Read + Send>> {
        Ok(Box::new(io::Cursor::new(self.read(path)?)))
    }

    /// Where the file at `path` is on disk, for readers that can only open
    /// a path (a GeoPackage's SQLite database); `None` when this world does
    /// not show it as a plain file on disk.
    fn disk_path(&self, path: &Path) -> Option<PathBuf> {
        let _ = path;
        None
    }
}

/// `path` made absolute (from the working folder) with `.` and `..`
/// removed by their meaning in the path's text, without asking the file
/// system (a `..` after a symbolic link is taken lexically).
pub fn normalize(path: &Path) -> PathBuf {
    let absolute;
    let path = if path.is_absolute() {
        path
    } else {
        absolute = std::env::current_dir()
            .map(|d| d.join(path))
            .unwrap_or_else(|_| path.to_path_buf());
        &absolute
    };
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                // `/..` is `/`.
                if out.parent().is_some() {
                    out.pop();
                }
            }
            other => out.push(other.as_os_str()),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalize_removes_dots_lexically() {
        let p = normalize(Path::new("/a/b/../c/./d.cga"));
        assert_eq!(p, PathBuf::from("/a/c/d.cga"));
        assert_eq!(normalize(Path::new("/../../x")), PathBuf::from("/x"));
        let rel = normalize(Path::new("x/../y.cga"));
        assert!(rel.is_absolute());
        assert!(rel.ends_with("y.cga"));
        assert!(!rel.to_string_lossy().contains(".."));
    }
}
