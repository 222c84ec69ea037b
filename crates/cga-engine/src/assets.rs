//! Finding and caching assets (geometry files, textures).
//!
//! Search (as CGA specifies): relative to the rule file that invokes the
//! operation: its folder, then each ancestor's `assets/` folder and the
//! ancestor itself (the project root); absolute workspace paths (`/lib/x.obj`)
//! inside an ancestor or its `.ws` folder. Loaded meshes are shared between
//! all shapes and all lots.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use cga_geometry::topology::FxHashMap;
use cga_geometry::Mesh;
use cga_syntax::{FileId, SourceMap};

use crate::resolve::find_relative;

/// Default largest asset file read, in MiB (`--max-asset-mib`).
pub const DEFAULT_MAX_ASSET_MIB: u64 = 512;

pub struct Assets {
    /// The rule file of each source file id.
    files: Vec<PathBuf>,
    /// Larger asset files are not read: a warning, the model goes on.
    max_file_bytes: u64,
    meshes: Mutex<HashMap<PathBuf, Result<Arc<Mesh>, String>>>,
    texts: Mutex<HashMap<PathBuf, Option<Arc<str>>>>,
    /// Answers by request (rule file, path as written), shared by all lots:
    /// a search looks at the file system several times, and Candler alone
    /// inserts 1,600 assets and names 6,000 textures per building.
    found: Requests<Option<PathBuf>>,
    mesh_requests: Requests<Result<Arc<Mesh>, String>>,
    texture_files: Requests<Option<Arc<str>>>,
    /// Whether a texture file has an alpha channel, by file: reading the
    /// image's header once for all lots (a city reads it once, not per lot).
    alpha: Mutex<FxHashMap<Arc<str>, bool>>,
}

/// A cache by rule file and path as written.
type Requests<T> = Mutex<FxHashMap<u32, FxHashMap<Box<str>, T>>>;

fn cached<T: Clone>(cache: &Requests<T>, from: FileId, path: &str, make: impl FnOnce() -> T) -> T {
    fn lock<T>(
        c: &Requests<T>,
    ) -> std::sync::MutexGuard<'_, FxHashMap<u32, FxHashMap<Box<str>, T>>> {
        c.lock().unwrap_or_else(|e| e.into_inner())
    }
    if let Some(v) = lock(cache).get(&from.0).and_then(|m| m.get(path)) {
        return v.clone();
    }
    // Not under the lock: making it may take a while (loading a mesh).
    let v = make();
    lock(cache)
        .entry(from.0)
        .or_default()
        .insert(path.into(), v.clone());
    v
}

impl Assets {
    pub fn new(sources: &SourceMap) -> Assets {
        Assets {
            max_file_bytes: DEFAULT_MAX_ASSET_MIB << 20,
            // Absolute paths: searching the ancestors of `rules/a.cga` given
            // relative to the working directory must reach the project root.
            files: sources
                .files()
                .map(|(_, f)| {
                    f.path.canonicalize().unwrap_or_else(|_| {
                        std::env::current_dir()
                            .map(|d| d.join(&f.path))
                            .unwrap_or_else(|_| f.path.clone())
                    })
                })
                .collect(),
            meshes: Mutex::new(HashMap::new()),
            texts: Mutex::new(HashMap::new()),
            found: Default::default(),
            mesh_requests: Default::default(),
            texture_files: Default::default(),
            alpha: Default::default(),
        }
    }

    /// An asset set with no rule files (tests).
    pub fn empty() -> Assets {
        Assets {
            max_file_bytes: DEFAULT_MAX_ASSET_MIB << 20,
            files: Vec::new(),
            meshes: Mutex::new(HashMap::new()),
            texts: Mutex::new(HashMap::new()),
            found: Default::default(),
            mesh_requests: Default::default(),
            texture_files: Default::default(),
            alpha: Default::default(),
        }
    }

    /// The file `path` names, searched from the rule file `from` (once per
    /// rule file and path).
    pub fn resolve(&self, from: FileId, path: &str) -> Option<PathBuf> {
        cached(&self.found, from, path, || {
            let p = std::path::Path::new(path);
            if p.is_absolute() && p.is_file() {
                return Some(p.to_path_buf());
            }
            let rule_file = self.files.get(from.0 as usize)?;
            find_relative(rule_file, path)
        })
    }

    /// The texture file `path` names, searched from the rule file `from`
    /// like an asset or else as a path from the working folder, as an
    /// absolute path (once per rule file and path).
    pub fn texture_file(&self, from: FileId, path: &str) -> Option<Arc<str>> {
        cached(&self.texture_files, from, path, || {
            // Textures of inserted assets come as paths next to the asset
            // file, which may be relative to the working folder.
            let file = self.resolve(from, path).or_else(|| {
                let p = std::path::Path::new(path);
                p.is_file().then(|| p.to_path_buf())
            });
            file.map(|f| {
                let f = f.canonicalize().unwrap_or(f);
                Arc::from(f.to_string_lossy().as_ref())
            })
        })
    }

    /// The geometry of the asset `path`: a built-in (`builtin:cube`, ...)
    /// or an OBJ, COLLADA or glTF file, loaded once.
    pub fn mesh(&self, from: FileId, path: &str) -> Result<Arc<Mesh>, String> {
        if let Some(name) = path.strip_prefix("builtin:") {
            return builtin_geometry(name)
                .ok_or_else(|| format!("there is no built-in asset \"{path}\""));
        }
        cached(&self.mesh_requests, from, path, || {
            self.load_mesh(from, path)
        })
    }

    /// Sets the largest asset file that is read, in MiB.
    pub fn with_max_file_mib(mut self, mib: u64) -> Assets {
        self.max_file_bytes = mib.saturating_mul(1 << 20);
        self
    }

    /// Refuses files larger than the limit, before reading them.
    fn check_size(&self, file: &std::path::Path) -> Result<(), String> {
        let len = std::fs::metadata(file).map(|m| m.len()).unwrap_or(0);
        if len > self.max_file_bytes {
            return Err(format!(
                "{} is {} MiB, larger than the asset size limit ({} MiB; raise it with --max-asset-mib)",
                file.display(),
                len >> 20,
                self.max_file_bytes >> 20
            ));
        }
        Ok(())
    }

    fn load_mesh(&self, from: FileId, path: &str) -> Result<Arc<Mesh>, String> {
        let file = self
            .resolve(from, path)
            .ok_or_else(|| format!("asset \"{path}\" not found"))?;
        self.check_size(&file)?;
        let mut cache = self.meshes.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(r) = cache.get(&file) {
            return r.clone();
        }
        let r = load_any(&file).map(Arc::new);
        cache.insert(file, r.clone());
        r
    }
}

/// The built-in geometry assets as unit shapes, made once.
fn builtin_geometry(name: &str) -> Option<Arc<Mesh>> {
    use cga_geometry::primitive as p;
    use cga_geometry::DVec3;
    static BUILTINS: std::sync::LazyLock<Vec<(&str, Arc<Mesh>)>> = std::sync::LazyLock::new(|| {
        vec![
            ("cube", Arc::new(p::builtin_cube())),
            ("quad", Arc::new(p::quad(1.0, 1.0))),
            ("disk", Arc::new(p::disk(16, 1.0, 1.0))),
            ("sphere", Arc::new(p::sphere(16, 16, DVec3::ONE))),
            ("cylinder", Arc::new(p::cylinder(16, DVec3::ONE))),
            ("cone", Arc::new(p::cone(16, DVec3::ONE))),
        ]
    });
    let name = name.strip_suffix(".obj").unwrap_or(name);
    BUILTINS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, m)| m.clone())
}

/// Loads an asset in any format the engine reads (OBJ, COLLADA, glTF; see
/// `cga_geometry::load_asset`); its warnings (missing MTL, unknown
/// materials, skipped polygons) are dropped here: the asset still loads.
/// A file that cannot be read, in a format that is not read, or without
/// polygons is an error message: the caller warns, naming it.
fn load_any(path: &std::path::Path) -> Result<Mesh, String> {
    cga_geometry::load_asset(path).map(|asset| asset.mesh)
}

impl Assets {
    /// Whether the texture `file` (as [`Assets::texture_file`] found it) has
    /// an alpha channel, asking `read` the first time for each file.
    pub fn texture_alpha(&self, file: &Arc<str>, read: impl FnOnce(&str) -> bool) -> bool {
        let lock = || self.alpha.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(&a) = lock().get(file) {
            return a;
        }
        // Not under the lock: reading may take a while.
        let a = read(file);
        lock().insert(file.clone(), a);
        a
    }

    /// The text of a file found like an asset (`readTextFile`, tables),
    /// with line endings normalised; cached.
    pub fn text(&self, from: FileId, path: &str) -> Option<Arc<str>> {
        let file = self.resolve(from, path)?;
        self.check_size(&file).ok()?;
        let mut cache = self.texts.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(t) = cache.get(&file) {
            return t.clone();
        }
        let t = std::fs::read(&file).ok().map(|bytes| {
            let s = String::from_utf8_lossy(&bytes).replace("\r\n", "\n");
            Arc::from(s.as_str())
        });
        cache.insert(file, t.clone());
        t
    }

    /// Files of the rule file's project matching a search query (`*` and `?`
    /// wildcards, `$regex`, whitespace = and), as paths relative to the
    /// project's `assets/` folder (or to the project folder), sorted.
    pub fn search(&self, from: FileId, query: &str) -> Vec<String> {
        let Some(rule_file) = self.files.get(from.0 as usize) else {
            return Vec::new();
        };
        let root = project_root(rule_file);
        let mut files = Vec::new();
        list_files(&root, &mut files, 0);
        let terms: Vec<fancy_regex::Regex> = query
            .split_whitespace()
            .filter_map(|t| {
                let pattern = match t.strip_prefix('$') {
                    Some(re) => re.to_string(),
                    None => wildcard_regex(t.trim_matches('\'')),
                };
                fancy_regex::Regex::new(&format!("^(?:.*/)?{pattern}$")).ok()
            })
            .collect();
        let assets = root.join("assets");
        let mut found: Vec<String> = files
            .into_iter()
            .filter_map(|f| {
                let rel = f
                    .strip_prefix(&assets)
                    .or_else(|_| f.strip_prefix(&root))
                    .ok()?
                    .to_string_lossy()
                    .replace('\\', "/");
                terms
                    .iter()
                    .all(|re| re.is_match(&rel).unwrap_or(false))
                    .then_some(rel)
            })
            .collect();
        found.sort();
        found
    }
}

/// The project folder of a rule file: the nearest ancestor holding an
/// `assets/` or `rules/` folder, else the rule file's folder.
fn project_root(rule_file: &std::path::Path) -> PathBuf {
    let dir = rule_file.parent().unwrap_or(std::path::Path::new("."));
    dir.ancestors()
        .find(|d| d.join("assets").is_dir() || d.join("rules").is_dir())
        .unwrap_or(dir)
        .to_path_buf()
}

fn list_files(dir: &std::path::Path, out: &mut Vec<PathBuf>, depth: usize) {
    if depth > 16 {
        return;
    }
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            list_files(&p, out, depth + 1);
        } else {
            out.push(p);
        }
    }
}

fn wildcard_regex(glob: &str) -> String {
    let mut re = String::new();
    for c in glob.chars() {
        match c {
            '*' => re.push_str("[^/]*"),
            '?' => re.push_str("[^/]"),
            c => re.push_str(&fancy_regex::escape(&c.to_string())),
        }
    }
    re
}
