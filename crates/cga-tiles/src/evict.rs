//! Tiles written are dropped from the page cache once on disk.
//!
//! A tileset of a large city is many gigabytes written once and not read
//! back by the process that writes it. Left to the page cache, each tile
//! takes fresh pages of memory (and evicts what other programs keep
//! there); writing each finished tile out at once and dropping its pages
//! when it is on disk keeps the cache to a few tiles, whose pages the
//! next tiles reuse.

use std::collections::VecDeque;
use std::fs::File;
use std::path::Path;

/// Tiles whose pages are still in the cache, oldest first.
#[derive(Default)]
pub(crate) struct Evict {
    written: VecDeque<File>,
}

/// Tiles kept in the cache while they are written out.
const IN_FLIGHT: usize = 4;

impl Evict {
    /// Starts writing the finished file at `path` to disk; drops the pages
    /// of the file that was finished `IN_FLIGHT` files before.
    pub(crate) fn written(&mut self, path: &Path) {
        let Ok(file) = File::open(path) else {
            return;
        };
        start_writeback(&file);
        self.written.push_back(file);
        if self.written.len() > IN_FLIGHT {
            if let Some(old) = self.written.pop_front() {
                drop_pages(&old);
            }
        }
    }
}

impl Drop for Evict {
    fn drop(&mut self) {
        for f in self.written.drain(..) {
            drop_pages(&f);
        }
    }
}

#[cfg(target_os = "linux")]
fn start_writeback(file: &File) {
    use std::os::fd::AsRawFd;
    // SAFETY: a valid descriptor; the call only schedules writeback.
    unsafe {
        libc::sync_file_range(file.as_raw_fd(), 0, 0, libc::SYNC_FILE_RANGE_WRITE);
    }
}

#[cfg(target_os = "linux")]
fn drop_pages(file: &File) {
    use std::os::fd::AsRawFd;
    let fd = file.as_raw_fd();
    // SAFETY: a valid descriptor; waiting for writeback and advising the
    // kernel do not touch our memory.
    unsafe {
        libc::sync_file_range(
            fd,
            0,
            0,
            libc::SYNC_FILE_RANGE_WAIT_BEFORE
                | libc::SYNC_FILE_RANGE_WRITE
                | libc::SYNC_FILE_RANGE_WAIT_AFTER,
        );
        libc::posix_fadvise(fd, 0, 0, libc::POSIX_FADV_DONTNEED);
    }
}

#[cfg(not(target_os = "linux"))]
fn start_writeback(_: &File) {}

#[cfg(not(target_os = "linux"))]
fn drop_pages(_: &File) {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn evicted_files_read_back_whole() {
        let dir = std::env::temp_dir().join(format!("cga-evict-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let body =
            |k: usize| -> Vec<u8> { (0..100_000).map(|i| ((i * 7 + k) % 251) as u8).collect() };
        {
            let mut evict = Evict::default();
            for k in 0..IN_FLIGHT + 3 {
                let path = dir.join(format!("{k}.glb"));
                std::fs::write(&path, body(k)).unwrap();
                evict.written(&path);
            }
            assert_eq!(evict.written.len(), IN_FLIGHT);
            // A file that cannot be opened is left alone.
            evict.written(&dir.join("missing.glb"));
            assert_eq!(evict.written.len(), IN_FLIGHT);
        }
        for k in 0..IN_FLIGHT + 3 {
            assert_eq!(
                std::fs::read(dir.join(format!("{k}.glb"))).unwrap(),
                body(k)
            );
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
