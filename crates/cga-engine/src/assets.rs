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
use cga_world::World;

use crate::locate::{self, Workspaces};

/// Default largest asset file read, in MiB (`--max-asset-mib`).
pub const DEFAULT_MAX_ASSET_MIB: u64 = 512;

/// What is read from files, kept across programs: a reloaded rule file
/// (an editor's save, a preview's regeneration) finds the meshes, texts,
/// image facts it read before, as long as the files did not change (their
/// size and modification time are compared on each new program's first
/// request). Shared by every thread deriving lots.
pub struct AssetStore {
    world: Arc<dyn World>,
    /// Larger asset files are not read: a warning, the model goes on.
    max_file_bytes: u64,
    meshes: ByFile<Result<Arc<Mesh>, String>>,
    texts: ByFile<Option<Arc<str>>>,
    /// Whether a texture file has an alpha channel, by file: reading the
    /// image's header once for all lots.
    alpha: Mutex<FxHashMap<Arc<str>, Stamped<bool>>>,
    /// Image sizes (width, height) by file.
    image_sizes: ByFile<Option<(u32, u32)>>,
}

/// Values read from files, by file.
type ByFile<T> = Mutex<HashMap<PathBuf, Stamped<T>>>;

/// A value read from a file, with the file's size and modification time
/// when it was read.
#[derive(Clone)]
struct Stamped<T> {
    stamp: Option<(u64, Option<std::time::SystemTime>)>,
    value: T,
}

fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

impl AssetStore {
    /// A store reading from `world`.
    pub fn new(world: Arc<dyn World>) -> AssetStore {
        AssetStore {
            world,
            max_file_bytes: DEFAULT_MAX_ASSET_MIB << 20,
            meshes: Default::default(),
            texts: Default::default(),
            alpha: Default::default(),
            image_sizes: Default::default(),
        }
    }

    /// Sets the largest asset file that is read, in MiB.
    pub fn with_max_file_mib(mut self, mib: u64) -> AssetStore {
        self.max_file_bytes = mib.saturating_mul(1 << 20);
        self
    }

    /// The largest asset file that is read, in MiB.
    pub fn max_file_mib(&self) -> u64 {
        self.max_file_bytes >> 20
    }

    /// The world files are read from.
    pub fn world(&self) -> &Arc<dyn World> {
        &self.world
    }

    fn stamp(&self, file: &Path) -> Option<(u64, Option<std::time::SystemTime>)> {
        self.world.metadata(file).map(|m| (m.len, m.modified))
    }

    /// The cached value for `file` if the file did not change since it was
    /// read, else a new one from `make` (not made under the lock: reading
    /// may take a while).
    fn cached<K, T: Clone>(
        &self,
        cache: &Mutex<HashMap<K, Stamped<T>>>,
        key: &K,
        file: &Path,
        make: impl FnOnce() -> T,
    ) -> T
    where
        K: std::hash::Hash + Eq + Clone,
    {
        let stamp = self.stamp(file);
        if let Some(s) = lock(cache).get(key) {
            if s.stamp == stamp {
                return s.value.clone();
            }
        }
        let value = make();
        // Two threads that asked at once made one each: the first one
        // stored is everyone's, so that all lots share one mesh per asset
        // (instancing tells assets apart by their mesh).
        let mut cache = lock(cache);
        match cache.get(key) {
            Some(s) if s.stamp == stamp => s.value.clone(),
            _ => {
                cache.insert(
                    key.clone(),
                    Stamped {
                        stamp,
                        value: value.clone(),
                    },
                );
                value
            }
        }
    }

    /// Refuses files larger than the limit, before reading them.
    fn check_size(&self, file: &Path) -> Result<(), String> {
        let len = self.world.metadata(file).map_or(0, |m| m.len);
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

    /// The geometry of the asset file `file` (OBJ, COLLADA, glTF).
    fn mesh(&self, file: &Path) -> Result<Arc<Mesh>, String> {
        self.check_size(file)?;
        self.cached(&self.meshes, &file.to_path_buf(), file, || {
            load_any(&*self.world, file).map(Arc::new)
        })
    }

    /// The text of `file`, decoded as rule files are, with line endings
    /// normalised.
    fn text(&self, file: &Path) -> Option<Arc<str>> {
        self.check_size(file).ok()?;
        self.cached(&self.texts, &file.to_path_buf(), file, || {
            self.world
                .read_text(file)
                .ok()
                .map(|s| Arc::from(s.replace("\r\n", "\n").as_str()))
        })
    }

    /// Whether the texture `file` has an alpha channel, asking `read` (given
    /// the file's first bytes) the first time for each file.
    pub fn texture_alpha(&self, file: &Arc<str>, read: impl FnOnce(&[u8]) -> bool) -> bool {
        let path = Path::new(&**file);
        let stamp = self.stamp(path);
        if let Some(s) = lock(&self.alpha).get(file) {
            if s.stamp == stamp {
                return s.value;
            }
        }
        // PNG chunks before the image data are small; 64 KiB covers them.
        let value = self
            .world
            .read_prefix(path, 1 << 16)
            .map(|head| read(&head))
            .unwrap_or(false);
        lock(&self.alpha).insert(file.clone(), Stamped { stamp, value });
        value
    }

    /// Whether `mesh` is a loaded asset file's own geometry.
    fn is_loaded_mesh(&self, mesh: &Arc<Mesh>) -> bool {
        lock(&self.meshes)
            .values()
            .any(|m| m.value.as_ref().is_ok_and(|m| Arc::ptr_eq(m, mesh)))
    }

    /// Width and height of the image `file`, from its header.
    fn image_size(&self, file: &Path) -> Option<(u32, u32)> {
        self.cached(&self.image_sizes, &file.to_path_buf(), file, || {
            // Headers come first, but JPEG may put large metadata before
            // its frame header: try a prefix, then the whole file.
            let size = |bytes: &[u8]| {
                imagesize::blob_size(bytes)
                    .ok()
                    .map(|s| (s.width as u32, s.height as u32))
            };
            let head = self.world.read_prefix(file, 1 << 18).ok()?;
            size(&head).or_else(|| size(&self.world.read(file).ok()?))
        })
    }
}

/// The assets of one program: files named in its rule files are searched
/// from the file that names them (see the module docs), and what is found
/// is read through the shared [`AssetStore`].
pub struct Assets {
    store: Arc<AssetStore>,
    /// The rule file of each source file id.
    files: Vec<PathBuf>,
    /// More places for workspace paths (`/Project/...`).
    workspaces: Workspaces,
    /// Answers by request (rule file, path as written), shared by all lots:
    /// a search looks at the file system several times, and a building may
    /// insert thousands of assets and name thousands of textures. A path
    /// not found keeps the places searched, for the message.
    found: Requests<Result<PathBuf, Arc<[PathBuf]>>>,
    mesh_requests: Requests<Result<Arc<Mesh>, String>>,
    texture_files: Requests<Option<Arc<str>>>,
    /// `fileSearch` answers by rule file and query: a search lists folders.
    searches: Requests<Vec<String>>,
    /// The addresses of the meshes [`Assets::mesh`] handed out (each kept
    /// alive by the caches above or the built-ins), to tell a leaf that is
    /// an asset as inserted from one whose geometry was made or changed.
    handed_out: Mutex<std::collections::HashSet<usize>>,
}

/// A cache by rule file and path as written.
type Requests<T> = Mutex<FxHashMap<u32, FxHashMap<Box<str>, T>>>;

fn cached<T: Clone>(cache: &Requests<T>, from: FileId, path: &str, make: impl FnOnce() -> T) -> T {
    if let Some(v) = lock(cache).get(&from.0).and_then(|m| m.get(path)) {
        return v.clone();
    }
    // Not under the lock: making it may take a while (loading a mesh).
    let v = make();
    // The first answer stored wins (see `AssetStore::cached`).
    lock(cache)
        .entry(from.0)
        .or_default()
        .entry(path.into())
        .or_insert(v)
        .clone()
}

impl Assets {
    /// The assets of the rule files in `sources`, read through `store`.
    pub fn new(store: Arc<AssetStore>, sources: &SourceMap) -> Assets {
        let files = sources
            .files()
            .map(|(_, f)| store.world.canonical(&f.path))
            .collect();
        Assets {
            store,
            files,
            workspaces: Workspaces::default(),
            found: Default::default(),
            mesh_requests: Default::default(),
            texture_files: Default::default(),
            searches: Default::default(),
            handed_out: Default::default(),
        }
    }

    /// Sets the workspace roots searched for workspace paths (`/Project/...`).
    pub fn with_workspaces(mut self, workspaces: Workspaces) -> Assets {
        self.workspaces = workspaces;
        self
    }

    /// Assets of the rule files in `sources`, read from disk with a store
    /// of their own (tests, one-off tools).
    pub fn on_disk(sources: &SourceMap) -> Assets {
        Assets::new(
            Arc::new(AssetStore::new(Arc::new(cga_world::DiskWorld))),
            sources,
        )
    }

    /// An asset set with no rule files (tests).
    pub fn empty() -> Assets {
        Assets::on_disk(&SourceMap::new())
    }

    /// The store files are read through.
    pub fn store(&self) -> &Arc<AssetStore> {
        &self.store
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
            let world = &*self.store.world;
            let Some(rule_file) = self.files.get(from.0 as usize) else {
                let p = Path::new(path);
                return if p.is_absolute() && world.is_file(p) {
                    Ok(p.to_path_buf())
                } else {
                    Err(Arc::from(Vec::new()))
                };
            };
            locate::locate(world, rule_file, path, &self.workspaces).map_err(Arc::from)
        })
    }

    /// Whether `mesh` is an asset's own geometry as loaded (a built-in or a
    /// file), which `geometry.isInstanced` asks.
    pub fn is_asset_mesh(&self, mesh: &Arc<Mesh>) -> bool {
        self.store.is_loaded_mesh(mesh)
            || ["cube", "quad", "disk", "sphere", "cylinder", "cone"]
                .iter()
                .filter_map(|n| builtin_geometry(n))
                .any(|m| Arc::ptr_eq(&m, mesh))
    }

    /// The texture file `path` names, searched from the rule file `from`
    /// like an asset or else as a path from the working folder, as an
    /// absolute path (once per rule file and path).
    pub fn texture_file(&self, from: FileId, path: &str) -> Option<Arc<str>> {
        cached(&self.texture_files, from, path, || {
            let world = &*self.store.world;
            // Textures of inserted assets come as paths next to the asset
            // file, which may be relative to the working folder.
            let file = self.resolve(from, path).or_else(|| {
                let p = Path::new(path);
                world.is_file(p).then(|| p.to_path_buf())
            });
            file.map(|f| Arc::from(world.canonical(&f).to_string_lossy().as_ref()))
        })
    }

    /// The geometry of the asset `path`: a built-in (`builtin:cube`, ...)
    /// or an OBJ, COLLADA or glTF file, loaded once.
    pub fn mesh(&self, from: FileId, path: &str) -> Result<Arc<Mesh>, String> {
        let mesh = self.find_mesh(from, path)?;
        lock(&self.handed_out).insert(Arc::as_ptr(&mesh) as usize);
        Ok(mesh)
    }

    /// Whether `mesh` is an asset as [`Assets::mesh`] gave it: one mesh
    /// shared by every shape that inserted the asset and changed nothing
    /// of its geometry since (writers may write it once, as instances).
    pub fn is_asset(&self, mesh: &Arc<Mesh>) -> bool {
        // An asset is held by the caches too: a mesh held once (most
        // leaves, cut pieces of their own) is not one, and is told without
        // taking the lock, once per leaf.
        Arc::strong_count(mesh) > 1
            && lock(&self.handed_out).contains(&(Arc::as_ptr(mesh) as usize))
    }

    fn find_mesh(&self, from: FileId, path: &str) -> Result<Arc<Mesh>, String> {
        if let Some(name) = path.strip_prefix("builtin:") {
            return builtin_geometry(name)
                .ok_or_else(|| format!("there is no built-in asset \"{path}\""));
        }
        cached(&self.mesh_requests, from, path, || {
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
            self.store.mesh(&file)
        })
    }

    /// Whether the texture `file` (as [`Assets::texture_file`] found it) has
    /// an alpha channel, asking `read` with the file's first bytes the
    /// first time for each file.
    pub fn texture_alpha(&self, file: &Arc<str>, read: impl FnOnce(&[u8]) -> bool) -> bool {
        self.store.texture_alpha(file, read)
    }

    /// Width and height of the image `path` names, searched from `from`.
    pub fn image_size(&self, from: FileId, path: &str) -> Option<(u32, u32)> {
        let file = self.resolve(from, path)?;
        self.store.image_size(&file)
    }

    /// The text of a file found like an asset (`readTextFile`, tables),
    /// with line endings normalised; cached.
    pub fn text(&self, from: FileId, path: &str) -> Option<Arc<str>> {
        let file = self.resolve(from, path)?;
        self.store.text(&file)
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
        let world = &*self.store.world;
        let root = project_root(world, rule_file);
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
                    list_files(world, &ws.join(first), &mut files, 0);
                } else {
                    list_files(world, &ws, &mut files, 0);
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
            list_files(world, &root, &mut files, 0);
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

/// Loads an asset from `world` in any format the engine reads (OBJ with
/// its material libraries, COLLADA, glTF with its buffers; see
/// `cga_geometry::load_asset`); its warnings (missing MTL, unknown
/// materials, skipped polygons) are dropped here: the asset still loads.
/// A file that cannot be read, in a format that is not read, or without
/// polygons is an error message: the caller warns, naming it.
fn load_any(world: &dyn World, path: &Path) -> Result<Mesh, String> {
    cga_geometry::load_asset(path, &|p: &Path| {
        world
            .read(p)
            .map_err(|e| format!("cannot read '{}': {e}", p.display()))
    })
    .map(|asset| asset.mesh)
}

/// The project folder of a rule file: the nearest ancestor holding an
/// `assets/` or `rules/` folder, else the rule file's folder.
fn project_root(world: &dyn World, rule_file: &Path) -> PathBuf {
    let dir = rule_file.parent().unwrap_or(Path::new("."));
    dir.ancestors()
        .find(|d| world.is_dir(&d.join("assets")) || world.is_dir(&d.join("rules")))
        .unwrap_or(dir)
        .to_path_buf()
}

fn list_files(world: &dyn World, dir: &Path, out: &mut Vec<PathBuf>, depth: usize) {
    if depth > 16 {
        return;
    }
    let Ok(entries) = world.read_dir(dir) else {
        return;
    };
    for p in entries {
        if world.is_dir(&p) {
            list_files(world, &p, out, depth + 1);
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
