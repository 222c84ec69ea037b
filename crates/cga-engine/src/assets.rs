//! Finding and caching assets (geometry files, textures).
//!
//! Search (as CGA specifies; `locate.rs` holds it): relative to the rule
//! file that invokes the operation: its folder, then each ancestor's
//! `assets/` folder and the ancestor itself (the project root); workspace
//! paths (`/Project/x.obj`) in the rule file's workspace, then in the
//! workspace roots. Loaded meshes are shared between all shapes and all lots.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use cga_geometry::topology::FxHashMap;
use cga_geometry::Mesh;
use cga_syntax::{FileId, SourceMap};

use crate::locate::{self, Workspaces};

/// Default largest asset file read, in MiB (`--max-asset-mib`).
pub const DEFAULT_MAX_ASSET_MIB: u64 = 512;

pub struct Assets {
    /// The rule file of each source file id.
    files: Vec<PathBuf>,
    /// More places for workspace paths (`/Project/...`).
    workspaces: Workspaces,
    /// Larger asset files are not read: a warning, the model goes on.
    max_file_bytes: u64,
    meshes: Mutex<HashMap<PathBuf, Result<Arc<Mesh>, String>>>,
    texts: Mutex<HashMap<PathBuf, Option<Arc<str>>>>,
    /// Answers by request (rule file, path as written), shared by all lots:
    /// a search looks at the file system several times, and Candler alone
    /// inserts 1,600 assets and names 6,000 textures per building.
    found: Requests<Result<PathBuf, Arc<[PathBuf]>>>,
    mesh_requests: Requests<Result<Arc<Mesh>, String>>,
    texture_files: Requests<Option<Arc<str>>>,
    /// `fileSearch` answers by rule file and query: a search lists folders.
    searches: Requests<Vec<String>>,
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
            workspaces: Workspaces::default(),
            meshes: Mutex::new(HashMap::new()),
            texts: Mutex::new(HashMap::new()),
            found: Default::default(),
            mesh_requests: Default::default(),
            texture_files: Default::default(),
            searches: Default::default(),
            alpha: Default::default(),
        }
    }

    /// An asset set with no rule files (tests).
    pub fn empty() -> Assets {
        Assets {
            max_file_bytes: DEFAULT_MAX_ASSET_MIB << 20,
            files: Vec::new(),
            workspaces: Workspaces::default(),
            meshes: Mutex::new(HashMap::new()),
            texts: Mutex::new(HashMap::new()),
            found: Default::default(),
            mesh_requests: Default::default(),
            texture_files: Default::default(),
            searches: Default::default(),
            alpha: Default::default(),
        }
    }

    /// Sets the workspace roots searched for workspace paths (`/Project/...`).
    pub fn with_workspaces(mut self, workspaces: Workspaces) -> Assets {
        self.workspaces = workspaces;
        self
    }

    /// The file `path` names, searched from the rule file `from` (once per
    /// rule file and path).
    pub fn resolve(&self, from: FileId, path: &str) -> Option<PathBuf> {
        self.search_for(from, path).ok()
    }

    /// The file `path` names from the rule file `from`, or the places
    /// searched (for a message).
    pub fn search_for(&self, from: FileId, path: &str) -> Result<PathBuf, Arc<[PathBuf]>> {
        cached(&self.found, from, path, || {
            let Some(rule_file) = self.files.get(from.0 as usize) else {
                let p = std::path::Path::new(path);
                return if p.is_absolute() && p.is_file() {
                    Ok(p.to_path_buf())
                } else {
                    Err(Arc::from(Vec::new()))
                };
            };
            locate::locate(rule_file, path, &self.workspaces).map_err(Arc::from)
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
    /// or an OBJ file, loaded once.
    pub fn mesh(&self, from: FileId, path: &str) -> Result<Arc<Mesh>, String> {
        if let Some(name) = path.strip_prefix("builtin:") {
            return builtin_geometry(name)
                .ok_or_else(|| format!("there is no built-in asset \"{path}\""));
        }
        cached(&self.mesh_requests, from, path, || {
            self.load_mesh(from, path)
        })
    }

    /// Whether `mesh` is an asset's own geometry as loaded (a built-in or a
    /// file), which `geometry.isInstanced` asks.
    pub fn is_asset_mesh(&self, mesh: &Arc<Mesh>) -> bool {
        let loaded = self.meshes.lock().unwrap_or_else(|e| e.into_inner());
        loaded
            .values()
            .any(|m| m.as_ref().is_ok_and(|m| Arc::ptr_eq(m, mesh)))
            || ["cube", "quad", "disk", "sphere", "cylinder", "cone"]
                .iter()
                .filter_map(|n| builtin_geometry(n))
                .any(|m| Arc::ptr_eq(&m, mesh))
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
        let file = self.search_for(from, path).map_err(|searched| {
            let mut m = format!("asset \"{path}\" not found");
            if path.starts_with('/') && !searched.is_empty() {
                // Workspace paths: say where the project was looked for.
                m.push_str(" (");
                m.push_str(&locate::searched_note(&searched).replace("\n  ", " "));
                m.push(')');
            }
            m
        })?;
        self.check_size(&file)?;
        let mut cache = self.meshes.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(r) = cache.get(&file) {
            return r.clone();
        }
        let r = load_obj(&file).map(Arc::new);
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

/// Loads an OBJ asset; its warnings (missing MTL, unknown materials) are
/// dropped here: the asset still loads with default materials.
fn load_obj(path: &std::path::Path) -> Result<Mesh, String> {
    cga_geometry::load_obj(path)
        .map(|asset| asset.mesh)
        .map_err(|e| format!("cannot load asset {}: {e}", path.display()))
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
            let s = crate::text_encoding::decode(&bytes).0.replace("\r\n", "\n");
            Arc::from(s.as_str())
        });
        cache.insert(file, t.clone());
        t
    }

    /// Files of the rule file's project matching a search query (`*` and `?`
    /// wildcards, `$regex`, whitespace = and), as paths relative to the
    /// project's `assets/` folder (or to the project folder), sorted. A
    /// query that starts with `/` names workspace paths (`/Project/assets/
    /// *.obj`): it is matched against the files of the rule file's
    /// workspace (the folder holding its project) and of the workspace
    /// roots, which are answered as workspace paths. Once per rule file and
    /// query.
    pub fn search(&self, from: FileId, query: &str) -> Vec<String> {
        cached(&self.searches, from, query, || {
            self.search_files(from, query)
        })
    }

    fn search_files(&self, from: FileId, query: &str) -> Vec<String> {
        let Some(rule_file) = self.files.get(from.0 as usize) else {
            return Vec::new();
        };
        let root = project_root(rule_file);
        let terms: Vec<fancy_regex::Regex> = query
            .split_whitespace()
            .filter_map(|t| {
                let t = t.trim_matches('\'');
                let pattern = match t.strip_prefix('$') {
                    Some(re) => re.to_string(),
                    None => wildcard_regex(t),
                };
                let anchored = if t.starts_with('/') {
                    format!("^{pattern}$")
                } else {
                    format!("^(?:.*/)?{pattern}$")
                };
                fancy_regex::Regex::new(&anchored).ok()
            })
            .collect();
        let matches = |rel: &str| terms.iter().all(|re| re.is_match(rel).unwrap_or(false));
        let mut found: Vec<String> = Vec::new();
        if query.trim_start().trim_start_matches('\'').starts_with('/') {
            // Workspace paths: the project named first, when it has no
            // wildcard, is the only folder listed.
            let first = query
                .trim_start()
                .trim_start_matches(['\'', '/'])
                .split(['/', ' '])
                .next()
                .unwrap_or("");
            let mut workspaces: Vec<PathBuf> =
                root.parent().map(Path::to_path_buf).into_iter().collect();
            workspaces.extend(self.workspaces.roots.iter().cloned());
            for ws in workspaces {
                let mut files = Vec::new();
                if !first.is_empty() && !first.contains(['*', '?', '$']) {
                    list_files(&ws.join(first), &mut files, 0);
                } else {
                    list_files(&ws, &mut files, 0);
                }
                for f in files {
                    let Ok(rel) = f.strip_prefix(&ws) else {
                        continue;
                    };
                    let path = format!("/{}", rel.to_string_lossy().replace('\\', "/"));
                    if matches(&path) && !found.contains(&path) {
                        found.push(path);
                    }
                }
            }
        } else {
            let mut files = Vec::new();
            list_files(&root, &mut files, 0);
            let assets = root.join("assets");
            found = files
                .into_iter()
                .filter_map(|f| {
                    let rel = f
                        .strip_prefix(&assets)
                        .or_else(|_| f.strip_prefix(&root))
                        .ok()?
                        .to_string_lossy()
                        .replace('\\', "/");
                    matches(&rel).then_some(rel)
                })
                .collect();
        }
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
