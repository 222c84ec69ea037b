//! Another world, seen only inside given folders.

use std::io;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::{Metadata, World};

/// A world that shows only what lies inside its roots: every path is first
/// made canonical by the base world (`..` removed, symbolic links followed),
/// and a path whose canonical form is outside every root does not exist for
/// its user (reading it is refused with [`io::ErrorKind::PermissionDenied`]).
/// So neither an absolute path, nor `../..`, nor a link that points out of
/// a root reaches a file elsewhere.
pub struct ConfinedWorld {
    base: Arc<dyn World>,
    roots: Vec<PathBuf>,
}

impl ConfinedWorld {
    /// `base` seen inside `roots` (folders; made canonical here).
    pub fn new(base: Arc<dyn World>, roots: impl IntoIterator<Item = PathBuf>) -> ConfinedWorld {
        let roots = roots.into_iter().map(|r| base.canonical(&r)).collect();
        ConfinedWorld { base, roots }
    }

    /// The folders this world shows.
    pub fn roots(&self) -> &[PathBuf] {
        &self.roots
    }

    /// The canonical form of `path` when it is inside a root.
    fn allowed(&self, path: &Path) -> Option<PathBuf> {
        let c = self.base.canonical(path);
        self.roots.iter().any(|r| c.starts_with(r)).then_some(c)
    }

    fn refused(path: &Path) -> io::Error {
        io::Error::new(
            io::ErrorKind::PermissionDenied,
            format!(
                "{} is outside the folders this engine may read",
                path.display()
            ),
        )
    }
}

impl World for ConfinedWorld {
    fn read(&self, path: &Path) -> io::Result<Vec<u8>> {
        let c = self.allowed(path).ok_or_else(|| Self::refused(path))?;
        self.base.read(&c)
    }

    fn open(&self, path: &Path) -> io::Result<Box<dyn io::Read + Send>> {
        let c = self.allowed(path).ok_or_else(|| Self::refused(path))?;
        self.base.open(&c)
    }

    fn disk_path(&self, path: &Path) -> Option<PathBuf> {
        self.base.disk_path(&self.allowed(path)?)
    }

    fn read_prefix(&self, path: &Path, max: usize) -> io::Result<Vec<u8>> {
        let c = self.allowed(path).ok_or_else(|| Self::refused(path))?;
        self.base.read_prefix(&c, max)
    }

    fn metadata(&self, path: &Path) -> Option<Metadata> {
        self.base.metadata(&self.allowed(path)?)
    }

    fn read_dir(&self, path: &Path) -> io::Result<Vec<PathBuf>> {
        let c = self.allowed(path).ok_or_else(|| Self::refused(path))?;
        // Entries that are links out of the roots are not shown.
        Ok(self
            .base
            .read_dir(&c)?
            .into_iter()
            .filter(|e| self.allowed(e).is_some())
            .collect())
    }

    fn canonical(&self, path: &Path) -> PathBuf {
        self.base.canonical(path)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{DiskWorld, MemoryWorld};

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("cga-world-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("project/rules")).unwrap();
        std::fs::create_dir_all(dir.join("outside")).unwrap();
        std::fs::write(dir.join("project/rules/a.cga"), "Lot --> X.").unwrap();
        std::fs::write(dir.join("outside/secret.txt"), "secret").unwrap();
        dir
    }

    #[test]
    fn only_paths_inside_the_roots_are_read() {
        let dir = scratch("confined");
        let w = ConfinedWorld::new(Arc::new(DiskWorld), [dir.join("project")]);
        let inside = dir.join("project/rules/a.cga");
        assert_eq!(w.read(&inside).unwrap(), b"Lot --> X.");
        assert!(w.is_file(&inside) && w.is_dir(&dir.join("project/rules")));
        for outside in [
            dir.join("outside/secret.txt"),
            dir.join("project/rules/../../outside/secret.txt"),
            dir.join("project/../outside/secret.txt"),
            PathBuf::from("/etc/passwd"),
            PathBuf::from("/"),
        ] {
            let e = w.read(&outside).unwrap_err();
            assert_eq!(
                e.kind(),
                io::ErrorKind::PermissionDenied,
                "{}",
                outside.display()
            );
            assert!(w.metadata(&outside).is_none(), "{}", outside.display());
        }
        assert!(w.read_dir(&dir).is_err());
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[cfg(unix)]
    #[test]
    fn links_out_of_a_root_are_refused() {
        let dir = scratch("links");
        let link_file = dir.join("project/rules/passwd.txt");
        let link_dir = dir.join("project/out");
        std::os::unix::fs::symlink(dir.join("outside/secret.txt"), &link_file).unwrap();
        std::os::unix::fs::symlink(dir.join("outside"), &link_dir).unwrap();
        let w = ConfinedWorld::new(Arc::new(DiskWorld), [dir.join("project")]);
        assert_eq!(
            w.read(&link_file).unwrap_err().kind(),
            io::ErrorKind::PermissionDenied
        );
        assert!(w.read(&link_dir.join("secret.txt")).is_err());
        // A link inside the project to a file inside it is fine.
        let inner = dir.join("project/inner.cga");
        std::os::unix::fs::symlink(dir.join("project/rules/a.cga"), &inner).unwrap();
        assert_eq!(w.read(&inner).unwrap(), b"Lot --> X.");
        let listed = w.read_dir(&dir.join("project")).unwrap();
        assert!(listed.contains(&inner));
        assert!(!listed.contains(&link_dir));
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_memory_world_can_be_confined() {
        let base = Arc::new(
            MemoryWorld::new()
                .with("/p/rules/a.cga", "Lot --> X.")
                .with("/q/b.cga", "x"),
        );
        let w = ConfinedWorld::new(base, [PathBuf::from("/p")]);
        assert!(w.read(Path::new("/p/rules/a.cga")).is_ok());
        assert!(w.read(Path::new("/p/../q/b.cga")).is_err());
    }
}
