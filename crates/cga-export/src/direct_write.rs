//! Writing a large model around the page cache.
//!
//! An ordinary write copies the bytes into the kernel's page cache, which
//! takes pages for them, accounts and dirties them and copies: on this
//! project's machine about half a millisecond of the writing thread's CPU
//! per megabyte (112 MB of GLB for 20 Candler buildings: the largest share
//! of the writing thread's samples), taken from the two cores the workers
//! derive on. A direct write (`O_DIRECT`) hands the bytes to the device
//! from our memory and costs a tenth of that. It asks for aligned memory,
//! offsets and lengths, so the bytes are staged in an aligned buffer of
//! one chunk and written a whole chunk at a time; what is left when the
//! writing ends (less than a chunk) is written the ordinary way, and so is
//! everything after it (the GLB's header, written last at the file's
//! start). A model smaller than a chunk never writes directly.
//!
//! Linux only; elsewhere, or where the file system refuses direct writes,
//! nothing changes.

use std::fs::File;
use std::io::{self, IoSlice, Seek};

/// Bytes written at once. A direct write returns when the device has the
/// bytes (about a millisecond a megabyte here), and the writing thread
/// waits for it, off the CPU.
const CHUNK: usize = 1 << 20;

/// Alignment of direct writes' memory, offsets and lengths: the page size,
/// a multiple of the block sizes file systems ask for.
const ALIGN: usize = 4096;

/// A file's writes staged for direct writing.
pub(crate) struct Direct {
    /// `raw[start..]` is the staged part, `start` its aligned offset in
    /// the allocation. Empty until the first write.
    raw: Vec<u8>,
    start: usize,
    /// File offset of the first staged byte (a multiple of `ALIGN`).
    base: u64,
    /// Whether the first write came: before it, seeks go to the file.
    anchored: bool,
    /// A direct write was refused: chunks are written the ordinary way.
    refused: bool,
}

impl Direct {
    /// Direct writing of `file`, if it is new and empty and its file
    /// system takes direct writes.
    #[cfg(target_os = "linux")]
    pub(crate) fn begin(file: &File) -> Option<Direct> {
        use rustix::fs::{fcntl_getfl, fcntl_setfl, OFlags};
        if file.metadata().ok()?.len() != 0 {
            return None;
        }
        let flags = fcntl_getfl(file).ok()?;
        fcntl_setfl(file, flags | OFlags::DIRECT).ok()?;
        Some(Direct {
            raw: Vec::new(),
            start: 0,
            base: 0,
            anchored: false,
            refused: false,
        })
    }

    #[cfg(not(target_os = "linux"))]
    pub(crate) fn begin(_: &File) -> Option<Direct> {
        None
    }

    /// Stages `bufs` (writing every chunk that fills); the bytes taken.
    pub(crate) fn write(&mut self, file: &File, bufs: &[IoSlice<'_>]) -> io::Result<usize> {
        if !self.anchored {
            self.anchor(file)?;
        }
        let full = self.start + CHUNK;
        let mut taken = 0;
        for buf in bufs {
            let mut rest: &[u8] = buf;
            while !rest.is_empty() {
                if self.raw.len() == full {
                    if let Err(e) = self.write_chunk(file) {
                        return if taken > 0 { Ok(taken) } else { Err(e) };
                    }
                }
                let n = rest.len().min(full - self.raw.len());
                self.raw.extend_from_slice(&rest[..n]);
                rest = &rest[n..];
                taken += n;
            }
        }
        Ok(taken)
    }

    /// Where a seek to `pos` lands, when it keeps writing direct: before
    /// the first write any seek (done on the file), after it one that asks
    /// where the writing is or goes where it already is. `None`: the seek
    /// needs the staged bytes written first.
    pub(crate) fn seek_within(
        &self,
        file: &mut File,
        pos: io::SeekFrom,
    ) -> io::Result<Option<u64>> {
        if !self.anchored {
            return file.seek(pos).map(Some);
        }
        let here = self.base + (self.raw.len() - self.start) as u64;
        Ok(match pos {
            io::SeekFrom::Current(0) => Some(here),
            io::SeekFrom::Start(p) if p == here => Some(here),
            _ => None,
        })
    }

    /// Writes what is staged the ordinary way, and ordinary writing goes
    /// on from where it ends.
    pub(crate) fn end(self, file: &mut File) -> io::Result<()> {
        ordinary(file)?;
        if self.anchored {
            let staged = &self.raw[self.start..];
            write_all_at(file, staged, self.base)?;
            file.seek(io::SeekFrom::Start(self.base + staged.len() as u64))?;
        }
        Ok(())
    }

    /// At the first write: the staging buffer, starting at the aligned
    /// offset at or before the file's position. The bytes before the
    /// position are zeros, as the new file holds there.
    fn anchor(&mut self, file: &File) -> io::Result<()> {
        let at = (&*file).stream_position()?;
        self.base = at - at % ALIGN as u64;
        self.raw = Vec::with_capacity(CHUNK + ALIGN);
        self.start = self.raw.as_ptr().align_offset(ALIGN);
        self.raw.resize(self.start + (at - self.base) as usize, 0);
        self.anchored = true;
        Ok(())
    }

    /// Writes the full staging buffer at `base`.
    fn write_chunk(&mut self, file: &File) -> io::Result<()> {
        let chunk = &self.raw[self.start..];
        if !self.refused {
            match write_all_at(file, chunk, self.base) {
                Ok(()) => {}
                // Alignment the file system wants beyond ours (or a short
                // write that left an unaligned rest): ordinary writes.
                Err(e) if e.kind() == io::ErrorKind::InvalidInput => {
                    self.refused = true;
                    ordinary(file)?;
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

/// Turns direct writing of `file` off.
#[cfg(target_os = "linux")]
fn ordinary(file: &File) -> io::Result<()> {
    use rustix::fs::{fcntl_getfl, fcntl_setfl, OFlags};
    let flags = fcntl_getfl(file)?;
    if flags.contains(OFlags::DIRECT) {
        fcntl_setfl(file, flags - OFlags::DIRECT)?;
    }
    Ok(())
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
    use std::io::Write;
    file.seek(io::SeekFrom::Start(offset))?;
    file.write_all(buf)
}
