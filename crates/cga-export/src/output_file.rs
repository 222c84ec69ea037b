//! Opening a model file where an older one may stand.
//!
//! Regenerating over the last output is the common case, and replacing a
//! large file in place is slow on the path of the model: truncating it
//! frees its cached pages before the first lot starts (20 Candler
//! buildings over their 112 MB GLB: the workers started 70 ms after the
//! process), and ext4 writes the new content out when the file is closed,
//! before `close` returns (it guards programs that truncate and rewrite
//! against losing both versions in a crash): the writing thread's last 80
//! ms, after the workers had finished.
//!
//! So an existing output that is a plain file of one name is moved aside
//! (renamed to a hidden name in its folder) and unlinked, a large one on a
//! thread of its own while the model is made, and a new file is created in
//! its place, with the old one's permissions and owner. A symbolic link, a
//! file with other hard links, or anything else (a device, a pipe) is
//! opened and truncated as before, so that writing through it still
//! reaches what it names.

use std::fs::{File, OpenOptions};
use std::io::{self, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::thread::JoinHandle;

/// Older files from this size on are unlinked on a thread of their own;
/// smaller ones (the tiles of a tileset written again) right away, which
/// costs less than a thread.
const UNLINK_APART_BYTES: u64 = 4 << 20;

/// An output file; dropping it closes the file and waits for the older
/// file it replaced to be unlinked (so that no hidden file is left behind
/// when the process ends right after).
pub(crate) struct OutputFile {
    file: File,
    unlinking: Option<JoinHandle<()>>,
    /// While its writes go around the page cache (see `around_cache`).
    direct: Option<crate::direct_write::Direct>,
}

/// Creates `path` for writing (and reading, with `read`), replacing what
/// stands there (see the module docs).
pub(crate) fn create(path: &Path, read: bool) -> io::Result<OutputFile> {
    let mut options = OpenOptions::new();
    options.read(read).write(true);
    let Some(old) = move_aside(path) else {
        return Ok(OutputFile {
            file: options.create(true).truncate(true).open(path)?,
            unlinking: None,
            direct: None,
        });
    };
    let file = match options.create_new(true).open(path) {
        Ok(file) => file,
        Err(e) => {
            // Put the old file back where it was.
            let _ = std::fs::rename(&old, path);
            return Err(e);
        }
    };
    let old_meta = std::fs::metadata(&old).ok();
    if let Some(meta) = &old_meta {
        keep_owner_and_permissions(&file, meta);
    }
    let large = old_meta.is_some_and(|m| m.len() >= UNLINK_APART_BYTES);
    let unlinking = large.then(|| unlink_apart(old.clone())).flatten();
    if unlinking.is_none() {
        let _ = std::fs::remove_file(&old);
    }
    Ok(OutputFile {
        file,
        unlinking,
        direct: None,
    })
}

impl OutputFile {
    /// From here on, the file's bytes past its first MiB are written
    /// around the page cache where the system allows (see
    /// `direct_write`): for a large model written from its start to its
    /// end, before any seek back. Nothing changes where it does not
    /// (another system, a pipe or a device, a file system without direct
    /// writes).
    pub(crate) fn around_cache(&mut self) {
        if self.direct.is_none() {
            self.direct = crate::direct_write::Direct::begin(&self.file);
        }
    }

    /// Writes what is staged and goes on with ordinary writes (kept for a
    /// retry if that fails).
    fn end_direct(&mut self) -> io::Result<()> {
        if let Some(d) = &mut self.direct {
            d.end(&self.file)?;
            self.direct = None;
        }
        Ok(())
    }
}

/// Unlinks `old` on a thread of its own (`None` if none could start).
fn unlink_apart(old: PathBuf) -> Option<JoinHandle<()>> {
    let unlink = move || {
        let _ = std::fs::remove_file(&old);
    };
    std::thread::Builder::new()
        .name("cga-unlink".into())
        .spawn(unlink)
        .ok()
}

/// Renames the older file at `path` to a hidden name beside it, when it is
/// a plain file of one name that can be moved: that name.
fn move_aside(path: &Path) -> Option<PathBuf> {
    let meta = std::fs::symlink_metadata(path).ok()?;
    if !meta.file_type().is_file() || !single_name(&meta) || meta.len() == 0 {
        return None;
    }
    // Unique within the process too: two writers may replace files of one
    // name in different folders, or one after the other.
    static NEXT: AtomicU64 = AtomicU64::new(0);
    let n = NEXT.fetch_add(1, Ordering::Relaxed);
    let name = path.file_name()?.to_string_lossy();
    let hidden = path.with_file_name(format!(".{name}.cga-old-{}-{n}", std::process::id()));
    std::fs::rename(path, &hidden).ok()?;
    Some(hidden)
}

/// Gives the new file the old one's permissions and, where the process
/// may (as root), its owner: as truncating the old file would have kept
/// them.
fn keep_owner_and_permissions(file: &File, old: &std::fs::Metadata) {
    let _ = file.set_permissions(old.permissions());
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if let Ok(new) = file.metadata() {
            if (new.uid(), new.gid()) != (old.uid(), old.gid()) {
                let _ = std::os::unix::fs::fchown(file, Some(old.uid()), Some(old.gid()));
            }
        }
    }
}

#[cfg(unix)]
fn single_name(meta: &std::fs::Metadata) -> bool {
    use std::os::unix::fs::MetadataExt;
    meta.nlink() == 1
}

#[cfg(not(unix))]
fn single_name(_: &std::fs::Metadata) -> bool {
    false
}

impl Drop for OutputFile {
    fn drop(&mut self) {
        // Writers end with `flush` (which writes what is staged and can
        // report an error); this is for one that stopped part way.
        let _ = self.end_direct();
        if let Some(t) = self.unlinking.take() {
            let _ = t.join();
        }
    }
}

impl Read for OutputFile {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        self.end_direct()?;
        self.file.read(buf)
    }
}

impl Write for OutputFile {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        match &mut self.direct {
            Some(d) => d.write(&self.file, &[io::IoSlice::new(buf)]),
            None => self.file.write(buf),
        }
    }

    fn write_vectored(&mut self, bufs: &[io::IoSlice<'_>]) -> io::Result<usize> {
        match &mut self.direct {
            Some(d) => d.write(&self.file, bufs),
            None => self.file.write_vectored(bufs),
        }
    }

    /// Writes what is staged for a direct write too (and ends direct
    /// writing: writers flush when they are done).
    fn flush(&mut self) -> io::Result<()> {
        self.end_direct()?;
        self.file.flush()
    }
}

impl Seek for OutputFile {
    fn seek(&mut self, pos: SeekFrom) -> io::Result<u64> {
        if let Some(d) = &self.direct {
            // Asking where the writing is, or seeking where it already is
            // (before staging: anywhere), keeps the staging.
            if let Some(at) = d.seek_within(&self.file, pos)? {
                return Ok(at);
            }
            self.end_direct()?;
        }
        self.file.seek(pos)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("cga-output-file-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    fn names(d: &Path) -> Vec<String> {
        let mut n: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        n.sort();
        n
    }

    /// An older file is replaced by a new one of the same permissions, and
    /// nothing else is left in the folder once the output is closed.
    #[test]
    fn an_older_file_is_replaced_and_nothing_is_left_beside_it() {
        let d = dir("replace");
        let path = d.join("model.glb");
        // Large enough to be unlinked on a thread of its own.
        std::fs::write(&path, vec![7u8; UNLINK_APART_BYTES as usize]).unwrap();
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o600)).unwrap();
        }
        #[cfg(unix)]
        let inode = || {
            use std::os::unix::fs::MetadataExt;
            std::fs::metadata(&path).unwrap().ino()
        };
        #[cfg(unix)]
        let old_inode = inode();
        let mut out = create(&path, true).unwrap();
        out.write_all(b"new").unwrap();
        drop(out);
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        // A new file, not the old one truncated (the old one may still
        // be open elsewhere, and is unlinked).
        #[cfg(unix)]
        assert_ne!(inode(), old_inode);
        assert_eq!(names(&d), ["model.glb"]);
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let mode = std::fs::metadata(&path).unwrap().permissions().mode();
            assert_eq!(mode & 0o777, 0o600);
        }
        // A small file, unlinked right away.
        #[cfg(unix)]
        let small_inode = inode();
        create(&path, false).unwrap().write_all(b"newer").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"newer");
        #[cfg(unix)]
        assert_ne!(inode(), small_inode);
        assert_eq!(names(&d), ["model.glb"]);
        // A new file, and one where none stood.
        let fresh = d.join("other.glb");
        create(&fresh, false).unwrap().write_all(b"x").unwrap();
        assert_eq!(std::fs::read(&fresh).unwrap(), b"x");
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// Bytes of a test pattern, different at every offset of a chunk.
    fn pattern(n: usize, seed: u32) -> Vec<u8> {
        (0..n as u32)
            .map(|i| (i.wrapping_mul(2_654_435_761).wrapping_add(seed) >> 13) as u8)
            .collect()
    }

    /// A model written around the page cache holds what ordinary writes
    /// would: written from an unaligned offset (before the first chunk
    /// boundary, and past it) in pieces of every size (vectored too), with
    /// a position asked for on the way, read back, then its head written
    /// at the start; with direct writes, and with chunks written the
    /// ordinary way (a file system that refuses them).
    #[test]
    fn writes_around_the_cache_give_the_bytes_written() {
        let d = dir("direct");
        let cases = [(1_000u64, true), ((1 << 20) + 1_000, true), (70_000, false)];
        for (case, (start, may_set)) in cases.into_iter().enumerate() {
            let path = d.join(format!("model-{case}.glb"));
            let mut out = create(&path, true).unwrap();
            if may_set {
                out.around_cache();
            } else {
                out.direct = Some(crate::direct_write::Direct::staged(false));
            }
            let linux = cfg!(target_os = "linux");
            assert_eq!(out.direct.is_some(), linux || !may_set);
            out.seek(SeekFrom::Start(start)).unwrap();
            let body = pattern(3 * (1 << 20) + 12_345, case as u32);
            let mut at = 0;
            let sizes = [1usize, 7, 4096, 65_536, 1 << 20, 3, 333_333];
            for (i, size) in sizes.iter().cycle().enumerate() {
                if at == body.len() {
                    break;
                }
                let n = (*size).min(body.len() - at);
                if i % 3 == 2 && n > 1 {
                    let half = n / 2;
                    let bufs = [
                        io::IoSlice::new(&body[at..at + half]),
                        io::IoSlice::new(&body[at + half..at + n]),
                    ];
                    let mut written = out.write_vectored(&bufs).unwrap();
                    // The rest, should a write take less.
                    while written < n {
                        written += out.write(&body[at + written..at + n]).unwrap();
                    }
                } else {
                    out.write_all(&body[at..at + n]).unwrap();
                }
                at += n;
                assert_eq!(out.stream_position().unwrap(), start + at as u64);
            }
            if let Some(direct) = &out.direct {
                // Whole chunks went to the file already, past the first
                // MiB; the position asked for kept the staging.
                assert!(out.file.metadata().unwrap().len() >= 3 << 20);
                assert_eq!(direct.is_set(), may_set, "case {case}");
            }
            // Reading back (as moving a GLB's data up does) sees every byte.
            out.seek(SeekFrom::Start(start + 10)).unwrap();
            assert!(out.direct.is_none());
            let mut back = vec![0u8; 100];
            out.read_exact(&mut back).unwrap();
            assert_eq!(back, body[10..110]);
            out.seek(SeekFrom::Start(0)).unwrap();
            out.write_all(b"head").unwrap();
            out.flush().unwrap();
            drop(out);
            let file = std::fs::read(&path).unwrap();
            assert_eq!(file.len() as u64, start + body.len() as u64, "case {case}");
            assert_eq!(&file[..4], b"head");
            assert!(file[4..start as usize].iter().all(|&b| b == 0));
            assert!(file[start as usize..] == body[..], "case {case}");
        }
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// A model smaller than a chunk, written and flushed, is whole; so is
    /// one whose writer stops without flushing (its file is closed). A
    /// pipe is written as it comes.
    #[test]
    fn small_or_abandoned_writes_around_the_cache_are_whole() {
        let d = dir("direct-small");
        let small = pattern(5_000, 2);
        let large = pattern(3 * (1 << 20) + 77, 3);
        for (name, bytes, flush) in [("a.glb", &small, true), ("b.glb", &large, false)] {
            let path = d.join(name);
            let mut out = create(&path, true).unwrap();
            out.around_cache();
            out.write_all(bytes).unwrap();
            if flush {
                out.flush().unwrap();
                assert!(out.direct.is_none());
            }
            drop(out);
            assert!(&std::fs::read(&path).unwrap() == bytes, "{name}");
        }
        #[cfg(target_os = "linux")]
        {
            let (_reader, writer) = io::pipe().unwrap();
            let pipe = File::from(std::os::fd::OwnedFd::from(writer));
            assert!(crate::direct_write::Direct::begin(&pipe).is_none());
        }
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// Through a symbolic link or a second hard link the file named is
    /// written, as opening it would.
    #[cfg(unix)]
    #[test]
    fn links_are_written_through() {
        let d = dir("links");
        let target = d.join("target.glb");
        std::fs::write(&target, b"old content").unwrap();
        let link = d.join("link.glb");
        std::os::unix::fs::symlink(&target, &link).unwrap();
        create(&link, false)
            .unwrap()
            .write_all(b"via link")
            .unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"via link");
        assert!(std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());

        let hard = d.join("hard.glb");
        std::fs::hard_link(&target, &hard).unwrap();
        create(&hard, false).unwrap().write_all(b"both").unwrap();
        assert_eq!(std::fs::read(&target).unwrap(), b"both");
        assert_eq!(names(&d), ["hard.glb", "link.glb", "target.glb"]);
        std::fs::remove_dir_all(&d).unwrap();
    }
}
