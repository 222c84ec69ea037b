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

use cga_geometry::Mesh;
use cga_syntax::{FileId, SourceMap};

use crate::resolve::find_relative;

pub struct Assets {
    /// The rule file of each source file id.
    files: Vec<PathBuf>,
    meshes: Mutex<HashMap<PathBuf, Result<Arc<Mesh>, String>>>,
}

impl Assets {
    pub fn new(sources: &SourceMap) -> Assets {
        Assets {
            files: sources.files().map(|(_, f)| f.path.clone()).collect(),
            meshes: Mutex::new(HashMap::new()),
        }
    }

    /// An asset set with no rule files (tests).
    pub fn empty() -> Assets {
        Assets {
            files: Vec::new(),
            meshes: Mutex::new(HashMap::new()),
        }
    }

    /// The file `path` names, searched from the rule file `from`.
    pub fn resolve(&self, from: FileId, path: &str) -> Option<PathBuf> {
        let p = std::path::Path::new(path);
        if p.is_absolute() && p.is_file() {
            return Some(p.to_path_buf());
        }
        let rule_file = self.files.get(from.0 as usize)?;
        find_relative(rule_file, path)
    }

    /// The geometry of the asset file `path` (OBJ), loaded once.
    pub fn mesh(&self, from: FileId, path: &str) -> Result<Arc<Mesh>, String> {
        let file = self
            .resolve(from, path)
            .ok_or_else(|| format!("asset \"{path}\" not found"))?;
        let mut cache = self.meshes.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(r) = cache.get(&file) {
            return r.clone();
        }
        let r = load_obj(&file).map(Arc::new);
        cache.insert(file, r.clone());
        r
    }
}

/// Loads an OBJ asset; its warnings (missing MTL, unknown materials) are
/// dropped here: the asset still loads with default materials.
fn load_obj(path: &std::path::Path) -> Result<Mesh, String> {
    cga_geometry::load_obj(path)
        .map(|asset| asset.mesh)
        .map_err(|e| format!("cannot load asset {}: {e}", path.display()))
}
