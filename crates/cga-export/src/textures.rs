//! Finding texture files and deciding how the output refers to them.
//!
//! A rule names textures as it wrote them (`"assets/brick.jpg"`,
//! `"/Project/assets/brick.jpg"`). Such a path is looked up as an existing
//! absolute path first, then relative to each texture root in order (a
//! leading `/`, CityEngine's workspace-absolute form, is dropped for that).
//! A texture that cannot be found is a warning, never an error: the model is
//! still worth having without it.
//!
//! `builtin:` names are CGA's built-in textures ([`crate::builtin`]): they
//! are generated in memory, embedded in GLB files and otherwise always
//! written next to the output (there is no file to refer to).

use std::collections::{HashMap, HashSet};
use std::io::{Read, Write};
use std::path::{Component, Path, PathBuf};
use std::sync::{Arc, Mutex};

use cga_world::World;

use crate::ExportError;

/// One texture file that the output uses.
pub(crate) struct Texture {
    /// Where the file is (canonical path).
    pub source: PathBuf,
    /// File size when it was found; embedding checks it did not change.
    pub len: u64,
    /// `image/png` or `image/jpeg`, from the file's first bytes; `None` for
    /// other formats (which glTF cannot use).
    pub mime: Option<&'static str>,
    /// File name next to the output when textures are copied there; unique
    /// among the textures and output files of the model.
    pub out_name: String,
    /// The image itself, for built-in textures (which are no files).
    pub data: Option<Arc<[u8]>>,
}

pub(crate) struct Textures {
    world: Arc<dyn World>,
    roots: Vec<PathBuf>,
    /// Copy textures next to the output (else refer to them where they are).
    copy: bool,
    out_dir: PathBuf,
    by_rule_path: HashMap<Arc<str>, Option<u32>>,
    by_source: HashMap<PathBuf, u32>,
    names: HashSet<String>,
    list: Vec<Texture>,
}

impl Textures {
    /// `reserved`: file names of the model's own output files, which a copied
    /// texture must not overwrite.
    pub(crate) fn new(
        world: Arc<dyn World>,
        roots: &[PathBuf],
        copy: bool,
        out_dir: &Path,
        reserved: &[&str],
    ) -> Self {
        Textures {
            world,
            roots: roots.to_vec(),
            copy,
            out_dir: out_dir.to_path_buf(),
            by_rule_path: HashMap::new(),
            by_source: HashMap::new(),
            names: reserved.iter().map(|s| s.to_string()).collect(),
            list: Vec::new(),
        }
    }

    /// The texture a rule path names, found once per distinct path; a path
    /// that names no readable file adds one warning and gives `None`.
    pub(crate) fn resolve(
        &mut self,
        rule_path: &Arc<str>,
        warnings: &mut Vec<String>,
    ) -> Option<u32> {
        if rule_path.is_empty() {
            return None;
        }
        if let Some(&known) = self.by_rule_path.get(rule_path) {
            return known;
        }
        if rule_path.starts_with(crate::builtin::PREFIX) {
            let found = self.add_builtin(rule_path);
            if found.is_none() {
                warnings.push(format!(
                    "'{rule_path}' is not a built-in texture (builtin:default, builtin:uvtest.png); written without it"
                ));
            }
            self.by_rule_path.insert(rule_path.clone(), found);
            return found;
        }
        let found = locate(&*self.world, &self.roots, rule_path).and_then(|p| self.add(&p).ok());
        if found.is_none() {
            let searched = if self.roots.is_empty() {
                "the current directory".to_string()
            } else {
                self.roots
                    .iter()
                    .map(|r| format!("'{}'", r.display()))
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            warnings.push(format!(
                "texture '{rule_path}' not found (searched {searched}); written without it"
            ));
        }
        self.by_rule_path.insert(rule_path.clone(), found);
        found
    }

    fn add(&mut self, path: &Path) -> std::io::Result<u32> {
        let source = self.world.canonical(path);
        if let Some(&i) = self.by_source.get(&source) {
            return Ok(i);
        }
        let (len, mime) = file_kind(&*self.world, &source)?;
        let out_name = self.unique_name(&source);
        let i = self.list.len() as u32;
        self.list.push(Texture {
            source: source.clone(),
            len,
            mime,
            out_name,
            data: None,
        });
        self.by_source.insert(source, i);
        Ok(i)
    }

    fn add_builtin(&mut self, name: &str) -> Option<u32> {
        let t = crate::builtin::builtin_texture(name)?;
        let source = PathBuf::from(name);
        if let Some(&i) = self.by_source.get(&source) {
            return Some(i);
        }
        let out_name = self.unique_name(Path::new(t.file_name));
        let i = self.list.len() as u32;
        self.list.push(Texture {
            source: source.clone(),
            len: t.png.len() as u64,
            mime: Some("image/png"),
            out_name,
            data: Some(t.png),
        });
        self.by_source.insert(source, i);
        Some(i)
    }

    /// `wall.jpg`, or `wall_2.jpg` when another texture already took that
    /// name (two folders can both hold a `wall.jpg`). The extension is
    /// written in lower case (`1.PNG` becomes `1.png`), as CityEngine's
    /// exporters name copied textures.
    fn unique_name(&mut self, source: &Path) -> String {
        let stem = source
            .file_stem()
            .map_or("texture".into(), |s| s.to_string_lossy());
        let ext = source
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        let with = |suffix: &str| match &ext {
            Some(e) => format!("{stem}{suffix}.{e}"),
            None => format!("{stem}{suffix}"),
        };
        let mut name = with("");
        let mut n = 2;
        while self.names.contains(&name) {
            name = with(&format!("_{n}"));
            n += 1;
        }
        self.names.insert(name.clone());
        name
    }

    pub(crate) fn get(&self, i: u32) -> &Texture {
        &self.list[i as usize]
    }

    /// Writes the bytes of texture `i` to `w`: a built-in's image, or the
    /// file's, which must still have the size it had when it was found.
    /// A file is copied through a small buffer rather than read whole: a
    /// block of each texture's size, at the model's very end, took fresh
    /// memory for each (a large page zeroed per size; 20 Candler
    /// buildings' eight textures of 55-410 KB cost more there than the
    /// copying).
    pub(crate) fn write_to(&self, i: u32, w: &mut impl Write) -> Result<(), ExportError> {
        let t = self.get(i);
        if let Some(data) = &t.data {
            return w.write_all(data).map_err(|e| ExportError::io(&t.source, e));
        }
        let io = |e| ExportError::io(&t.source, e);
        let mut file = self.world.open(&t.source).map_err(io)?;
        let copied = std::io::copy(&mut (&mut file).take(t.len), w).map_err(io)?;
        let mut more = [0u8; 1];
        let grew = loop {
            match file.read(&mut more) {
                Ok(n) => break n > 0,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(io(e)),
            }
        };
        if copied != t.len || grew {
            let now = match grew {
                true => format!("more than {}", t.len),
                false => copied.to_string(),
            };
            let msg = format!(
                "texture changed while exporting ({} bytes, then {now})",
                t.len
            );
            return Err(ExportError::io(&t.source, std::io::Error::other(msg)));
        }
        Ok(())
    }

    /// How the output refers to texture `i`, as a `/`-separated path: its
    /// copied file name, or the path from the output's folder to the source.
    pub(crate) fn reference(&self, i: u32) -> String {
        let t = self.get(i);
        if self.copy || t.data.is_some() {
            return t.out_name.clone();
        }
        let out_dir = self
            .out_dir
            .canonicalize()
            .unwrap_or_else(|_| self.out_dir.clone());
        match relative_path(&out_dir, &t.source) {
            Some(rel) => rel,
            None => t.source.to_string_lossy().replace('\\', "/"),
        }
    }

    /// Copies the given textures next to the output, when copying, and
    /// writes the built-in ones there in any case.
    pub(crate) fn copy_all(&self, which: impl IntoIterator<Item = u32>) -> Result<(), ExportError> {
        for t in which.into_iter().map(|i| self.get(i)) {
            let dest = self.out_dir.join(&t.out_name);
            if let Some(data) = &t.data {
                std::fs::write(&dest, data).map_err(|e| ExportError::io(&dest, e))?;
                continue;
            }
            if !self.copy {
                continue;
            }
            let same = dest.canonicalize().is_ok_and(|d| d == t.source);
            if !same {
                let bytes = self
                    .world
                    .read(&t.source)
                    .map_err(|e| ExportError::io(&t.source, e))?;
                std::fs::write(&dest, bytes).map_err(|e| ExportError::io(&dest, e))?;
            }
        }
        Ok(())
    }
}

/// Where a rule path names a file: an existing absolute path, else the
/// first texture root holding it (a leading `/` dropped).
fn locate(world: &dyn World, roots: &[PathBuf], rule_path: &str) -> Option<PathBuf> {
    let path = Path::new(rule_path);
    if path.is_absolute() && world.is_file(path) {
        return Some(path.to_path_buf());
    }
    let relative = rule_path.trim_start_matches(['/', '\\']);
    if relative.is_empty() {
        return None;
    }
    if roots.is_empty() {
        let p = Path::new(relative);
        return world.is_file(p).then(|| p.to_path_buf());
    }
    roots
        .iter()
        .map(|root| root.join(relative))
        .find(|p| world.is_file(p))
}

/// A file's size and image format (`None`: neither PNG nor JPEG).
fn file_kind(world: &dyn World, path: &Path) -> std::io::Result<(u64, Option<&'static str>)> {
    let len = world
        .metadata(path)
        .ok_or_else(|| std::io::Error::new(std::io::ErrorKind::NotFound, "no such file"))?
        .len;
    let magic = world.read_prefix(path, 8)?;
    Ok((len, sniff_mime(&magic)))
}

/// Tells, from any thread, whether a texture path will be usable in glTF
/// (found, and PNG or JPEG), as [`Textures::resolve`] will find: encoders
/// need it to lay out vertices before the writer resolves the texture.
/// Each path is looked at once.
pub(crate) struct TextureProbe {
    world: Arc<dyn World>,
    roots: Vec<PathBuf>,
    known: Mutex<HashMap<Arc<str>, bool>>,
}

impl TextureProbe {
    pub(crate) fn new(world: Arc<dyn World>, roots: &[PathBuf]) -> TextureProbe {
        TextureProbe {
            world,
            roots: roots.to_vec(),
            known: Mutex::new(HashMap::new()),
        }
    }

    pub(crate) fn usable(&self, rule_path: &Arc<str>) -> bool {
        if rule_path.is_empty() {
            return false;
        }
        let lock = || self.known.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(&known) = lock().get(rule_path) {
            return known;
        }
        let usable = if rule_path.starts_with(crate::builtin::PREFIX) {
            crate::builtin::builtin_texture(rule_path).is_some()
        } else {
            locate(&*self.world, &self.roots, rule_path)
                .and_then(|p| file_kind(&*self.world, &p).ok())
                .is_some_and(|(_, mime)| mime.is_some())
        };
        lock().insert(rule_path.clone(), usable);
        usable
    }
}

/// The image formats glTF 2.0 core allows, recognised by their signatures.
fn sniff_mime(head: &[u8]) -> Option<&'static str> {
    if head.starts_with(&[0x89, b'P', b'N', b'G', b'\r', b'\n', 0x1a, b'\n']) {
        Some("image/png")
    } else if head.starts_with(&[0xff, 0xd8, 0xff]) {
        Some("image/jpeg")
    } else {
        None
    }
}

/// `to` relative to the folder `from` (both absolute), `/`-separated, or
/// `None` when they share no root (other drive).
fn relative_path(from: &Path, to: &Path) -> Option<String> {
    let a: Vec<Component> = from.components().collect();
    let b: Vec<Component> = to.components().collect();
    let common = a.iter().zip(&b).take_while(|(x, y)| x == y).count();
    if common == 0 {
        return None;
    }
    let mut parts: Vec<String> = vec!["..".to_string(); a.len() - common];
    parts.extend(
        b[common..]
            .iter()
            .map(|c| c.as_os_str().to_string_lossy().into_owned()),
    );
    Some(parts.join("/"))
}

/// Percent-encodes a `/`-separated relative path for a glTF `uri`: every byte
/// but RFC 3986's unreserved characters and `/` is escaped, so spaces and
/// non-ASCII names survive.
pub(crate) fn uri_encode(path: &str) -> String {
    let mut out = String::with_capacity(path.len());
    for b in path.bytes() {
        if b.is_ascii_alphanumeric() || matches!(b, b'-' | b'.' | b'_' | b'~' | b'/') {
            out.push(b as char);
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_paths() {
        assert_eq!(
            relative_path(Path::new("/a/b/out"), Path::new("/a/b/tex/w.png")).as_deref(),
            Some("../tex/w.png")
        );
        assert_eq!(
            relative_path(Path::new("/a/out"), Path::new("/a/out/w.png")).as_deref(),
            Some("w.png")
        );
    }

    #[test]
    fn uri_encoding_escapes_spaces_and_utf8() {
        assert_eq!(uri_encode("../my tex/é.png"), "../my%20tex/%C3%A9.png");
    }

    /// A texture file is written as it was found; one whose size changed
    /// since (larger or smaller) is an error, not a GLB whose images lie.
    #[test]
    fn a_texture_is_written_as_found_and_a_changed_one_is_refused() {
        let dir = std::env::temp_dir().join(format!("cga-textures-write-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("wall.png");
        // Larger than the copying buffers, so that it takes several reads.
        let mut image = b"\x89PNG\r\n\x1a\n".to_vec();
        image.extend((0..200_000u32).map(|i| (i * 7 % 251) as u8));
        std::fs::write(&path, &image).unwrap();
        let mut textures = Textures::new(
            Arc::new(cga_world::DiskWorld),
            std::slice::from_ref(&dir),
            false,
            &dir,
            &[],
        );
        let mut warnings = Vec::new();
        let i = textures
            .resolve(&Arc::from("wall.png"), &mut warnings)
            .unwrap();
        assert!(warnings.is_empty(), "{warnings:?}");
        assert_eq!(textures.get(i).mime, Some("image/png"));
        let mut out = Vec::new();
        textures.write_to(i, &mut out).unwrap();
        assert_eq!(out, image);

        let shorter = &image[..image.len() - 1];
        let longer = [image.as_slice(), b"+"].concat();
        for (changed, now) in [(shorter, "200007"), (&longer[..], "more than 200008")] {
            std::fs::write(&path, changed).unwrap();
            let err = textures
                .write_to(i, &mut Vec::new())
                .unwrap_err()
                .to_string();
            let said = format!("texture changed while exporting (200008 bytes, then {now})");
            assert!(err.contains(&said), "{err}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn mime_from_signature() {
        assert_eq!(sniff_mime(b"\x89PNG\r\n\x1a\n"), Some("image/png"));
        assert_eq!(sniff_mime(&[0xff, 0xd8, 0xff, 0xe0]), Some("image/jpeg"));
        assert_eq!(sniff_mime(b"II*\0"), None);
        assert_eq!(sniff_mime(b""), None);
    }
}
