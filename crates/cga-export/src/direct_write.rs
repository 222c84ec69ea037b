//! Writing a large model around the page cache.
//!
//! An ordinary write copies the bytes into the kernel's page cache, which
//! takes pages for them, accounts and dirties them and copies: on this
//! project's machine about half a millisecond of the writing thread's CPU
//! per megabyte (112 MB of GLB for 20 Candler buildings: the largest share
//! of the writing thread's samples), taken from the two cores the workers
//! derive on. A direct write (`O_DIRECT`) hands the bytes to the device
//! from our memory and costs a tenth of that. It asks for aligned memory,
//! offsets and lengths, so from the first chunk boundary on (the first
//! MiB is written the ordinary way) the bytes are staged in an aligned
//! buffer of one chunk and written a whole chunk at a time; what is left
//! when the writing ends (at most a chunk) is written the ordinary way, and
//! so is everything after it (the GLB's header, written last at the file's
//! start). A model smaller than a chunk never stages, and `O_DIRECT` is
//! set only when the first chunk goes out.
//!
//! Linux only; elsewhere, or where the file system refuses direct writes,
//! the bytes go out the ordinary way.

// Elsewhere nothing begins direct writing (only tests stage).
#![cfg_attr(not(target_os = "linux"), allow(dead_code))]

use std::fs::File;
use std::io::{self, IoSlice, Seek, Write};

/// Bytes written at once. A direct write returns when the device has the
/// bytes (about a millisecond a megabyte here), and the writing thread
/// waits for it, off the CPU.
const CHUNK: usize = 1 << 20;

/// Alignment of direct writes' memory (offsets and lengths are multiples
/// of `CHUNK`): the page size, a multiple of the block sizes file systems
/// ask for.
const ALIGN: usize = 4096;

/// A file's writes, staged for direct writing from a chunk boundary on.
pub(crate) struct Direct {
    /// `raw[start..]` is the staged part, `start` its aligned offset in
    /// the allocation. Empty until staging starts.
    raw: Vec<u8>,
    start: usize,
    /// File offset of the first staged byte (a multiple of `CHUNK`).
    base: u64,
    /// Whether the writing reached a chunk boundary and stages; before,
    /// writes and seeks go to the file as they come.
    staging: bool,
    /// `O_DIRECT` is set on the file.
    set: bool,
    /// A direct write was refused (or is not to be tried): chunks are
    /// written the ordinary way.
    refused: bool,
}

impl Direct {
    /// Direct writing of `file`, if it is a plain file (not a pipe or a
    /// device, which are written as they come) on Linux.
    #[cfg(target_os = "linux")]
    pub(crate) fn begin(file: &File) -> Option<Direct> {
        file.metadata()
            .ok()?
            .file_type()
            .is_file()
            .then(|| Direct::staged(true))
    }

    #[cfg(not(target_os = "linux"))]
    pub(crate) fn begin(_: &File) -> Option<Direct> {
        None
    }

    /// Staging as `begin` does; with `may_set` false, whole chunks are
    /// written the ordinary way (what a refusing file system gives).
    pub(crate) fn staged(may_set: bool) -> Direct {
        Direct {
            raw: Vec::new(),
            start: 0,
            base: 0,
            staging: false,
            set: false,
            refused: !may_set,
        }
    }

    /// Whether `O_DIRECT` is on.
    #[cfg(test)]
    pub(crate) fn is_set(&self) -> bool {
        self.set
    }

    /// Writes or stages `bufs`; the bytes taken.
    pub(crate) fn write(&mut self, file: &File, bufs: &[IoSlice<'_>]) -> io::Result<usize> {
        let mut taken = 0;
        for buf in bufs {
            let mut rest: &[u8] = buf;
            while !rest.is_empty() {
                match self.write_some(file, rest) {
                    Ok(n) => {
                        rest = &rest[n..];
                        taken += n;
                    }
                    // What was taken is kept; the error comes again with
                    // the next write.
                    Err(_) if taken > 0 => return Ok(taken),
                    Err(e) => return Err(e),
                }
            }
        }
        Ok(taken)
    }

    /// Writes or stages a first part of `bytes` (not empty); its length.
    fn write_some(&mut self, mut file: &File, bytes: &[u8]) -> io::Result<usize> {
        if !self.staging {
            let at = file.stream_position()?;
            let boundary = at.next_multiple_of(CHUNK as u64).max(CHUNK as u64);
            if at < boundary {
                let n = bytes.len().min((boundary - at) as usize);
                return file.write(&bytes[..n]);
            }
            self.raw = Vec::with_capacity(CHUNK + ALIGN);
            self.start = self.raw.as_ptr().align_offset(ALIGN);
            self.raw.resize(self.start, 0);
            self.base = at;
            self.staging = true;
        }
        let full = self.start + CHUNK;
        if self.raw.len() == full {
            self.write_chunk(file)?;
        }
        let n = bytes.len().min(full - self.raw.len());
        self.raw.extend_from_slice(&bytes[..n]);
        Ok(n)
    }

    /// Where a seek to `pos` lands, when it keeps the writing as it is:
    /// before staging any seek (done on the file), while staging one that
    /// asks where the writing is or goes where it already is. `None`: the
    /// seek needs the staged bytes written first.
    pub(crate) fn seek_within(
        &self,
        mut file: &File,
        pos: io::SeekFrom,
    ) -> io::Result<Option<u64>> {
        if !self.staging {
            return file.seek(pos).map(Some);
        }
        let here = self.base + (self.raw.len() - self.start) as u64;
        Ok(match pos {
            io::SeekFrom::Current(0) => Some(here),
            io::SeekFrom::Start(p) if p == here => Some(here),
            _ => None,
        })
    }

    /// Writes what is staged the ordinary way, from where ordinary writing
    /// goes on. On an error nothing staged is lost: ending again retries.
    pub(crate) fn end(&mut self, mut file: &File) -> io::Result<()> {
        if self.set {
            ordinary(file)?;
            self.set = false;
            self.refused = true;
        }
        if self.staging {
            let staged = &self.raw[self.start..];
            write_all_at(file, staged, self.base)?;
            file.seek(io::SeekFrom::Start(self.base + staged.len() as u64))?;
            self.staging = false;
            self.raw = Vec::new();
        }
        Ok(())
    }

    /// Writes the full staging buffer at `base`.
    fn write_chunk(&mut self, file: &File) -> io::Result<()> {
        let chunk = &self.raw[self.start..];
        if !self.set && !self.refused {
            self.set = set_direct(file).is_ok();
            self.refused = !self.set;
        }
        if !self.refused {
            match write_all_at(file, chunk, self.base) {
                Ok(()) => {}
                // Alignment the file system wants beyond ours, a short
                // write that left an unaligned rest, or direct writes
                // refused only when writing: ordinary writes from here.
                Err(e)
                    if matches!(
                        e.kind(),
                        io::ErrorKind::InvalidInput | io::ErrorKind::Unsupported
                    ) =>
                {
                    ordinary(file)?;
                    self.set = false;
                    self.refused = true;
                }
                Err(e) => return Err(e),
            }
        }
        if self.refused {
            write_all_at(file, chunk, self.base)?;
        }
        self.base += CHUNK as u64;
        self.raw.truncate(self.start);
        Ok(())
    }
}

/// Turns direct writing of `file` on.
#[cfg(target_os = "linux")]
fn set_direct(file: &File) -> io::Result<()> {
    use rustix::fs::{fcntl_getfl, fcntl_setfl, OFlags};
    let flags = fcntl_getfl(file)?;
    Ok(fcntl_setfl(file, flags | OFlags::DIRECT)?)
}

#[cfg(not(target_os = "linux"))]
fn set_direct(_: &File) -> io::Result<()> {
    Err(io::ErrorKind::Unsupported.into())
}

/// Turns direct writing of `file` off.
#[cfg(target_os = "linux")]
fn ordinary(file: &File) -> io::Result<()> {
    use rustix::fs::{fcntl_getfl, fcntl_setfl, OFlags};
    let flags = fcntl_getfl(file)?;
    Ok(fcntl_setfl(file, flags - OFlags::DIRECT)?)
}

#[cfg(not(target_os = "linux"))]
fn ordinary(_: &File) -> io::Result<()> {
    Ok(())
}

#[cfg(unix)]
fn write_all_at(file: &File, buf: &[u8], offset: u64) -> io::Result<()> {
    std::os::unix::fs::FileExt::write_all_at(file, buf, offset)
}

#[cfg(not(unix))]
fn write_all_at(mut file: &File, buf: &[u8], offset: u64) -> io::Result<()> {
    file.seek(io::SeekFrom::Start(offset))?;
    file.write_all(buf)
}
