//! Where a path written in a rule file (an import, an asset, a texture, a
//! file a built-in reads) is looked for. The one place that decides it:
//! [`candidates`] lists the places in search order from the rule file, the
//! path as written and the workspace roots alone (no file system), and
//! [`locate`] takes the first that exists.
//!
//! A path that starts with `/` names a project of the CityEngine workspace
//! (`/ESRI.lib/rules/Plants/Plant_Loader.cga`: the file
//! `rules/Plants/Plant_Loader.cga` of the project `ESRI.lib`). A workspace
//! holds its projects side by side, so the project is looked for beside the
//! rule file's own project: in each ancestor folder of the rule file,
//! nearest first (and in its `.ws` folder, where rule packages keep the
//! files of other projects), then in each workspace root given by the user
//! (`--workspace DIR`, then the folders of `CGA_WORKSPACE`). An absolute
//! path of this machine that exists is taken as it is.
//!
//! Any other path is relative to the rule file: its folder first, then each
//! ancestor's `assets/` folder and the ancestor itself (the project root,
//! so that `assets/x.obj` and `rules/x.cga` work from inside `rules/`).
//!
//! Rule files written on Windows separate folders with `\` and do not
//! always match the case of the names on disk (CityEngine on Windows found
//! such files until 2025.0): `\` is read as `/`, and when no place holds
//! the file with the exact name, the same places are searched again
//! ignoring the case of ASCII letters.

use std::path::{Path, PathBuf};

use cga_world::World;

/// The environment variable with more workspace roots (a path list, as
/// `PATH` is written on this platform).
pub const WORKSPACE_ENV: &str = "CGA_WORKSPACE";

/// The workspace roots a user named, searched after the rule file's own
/// workspace for paths that start with `/`.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Workspaces {
    pub roots: Vec<PathBuf>,
}

impl Workspaces {
    pub fn new(roots: Vec<PathBuf>) -> Workspaces {
        Workspaces { roots }
    }

    /// `dirs` (the `--workspace` options, in order), then the folders of
    /// the `CGA_WORKSPACE` environment variable.
    pub fn with_env(dirs: &[PathBuf]) -> Workspaces {
        let mut roots = dirs.to_vec();
        if let Some(list) = std::env::var_os(WORKSPACE_ENV) {
            roots.extend(std::env::split_paths(&list).filter(|p| !p.as_os_str().is_empty()));
        }
        Workspaces { roots }
    }
}

/// Every place `target`, written in the rule file `from`, may be, in search
/// order. Pure: the file system is not consulted.
pub fn candidates(from: &Path, target: &str, workspaces: &Workspaces) -> Vec<PathBuf> {
    let folder = from.parent().unwrap_or(Path::new(""));
    let mut out = Vec::new();
    let mut push = |p: PathBuf| {
        if !out.contains(&p) {
            out.push(p);
        }
    };
    let target = target.trim().replace('\\', "/");
    let target = target.as_str();
    if target.is_empty() {
        return out;
    }
    if let Some(rel) = target.strip_prefix('/') {
        let rel = rel.trim_start_matches('/');
        if !rel.is_empty() {
            push(PathBuf::from(target));
            for dir in folder.ancestors() {
                push(dir.join(rel));
                push(dir.join(".ws").join(rel));
            }
            for root in &workspaces.roots {
                push(root.join(rel));
            }
        }
        return out;
    }
    let own = Path::new(target);
    if own.is_absolute() {
        // A path of this machine (`C:\...` on Windows).
        push(own.to_path_buf());
        return out;
    }
    push(folder.join(target));
    for dir in folder.ancestors() {
        push(dir.join("assets").join(target));
        push(dir.join(target));
    }
    out
}

/// The file `target` names from the rule file `from`, or every place that
/// was searched.
pub fn locate(
    world: &dyn World,
    from: &Path,
    target: &str,
    workspaces: &Workspaces,
) -> Result<PathBuf, Vec<PathBuf>> {
    let places = candidates(from, target, workspaces);
    if let Some(found) = places.iter().find(|p| world.is_file(p)) {
        return Ok(found.clone());
    }
    match places.iter().find_map(|p| with_any_case(world, p)) {
        Some(found) => Ok(found),
        None => Err(places),
    }
}

/// The file at `path` with the case of its names' ASCII letters ignored
/// (each missing name matched against its folder's entries), if exactly
/// one way leads to a file.
fn with_any_case(world: &dyn World, path: &Path) -> Option<PathBuf> {
    let mut found = PathBuf::new();
    for part in path.components() {
        let next = found.join(part.as_os_str());
        if !matches!(part, std::path::Component::Normal(_)) || world.metadata(&next).is_some() {
            found = next;
            continue;
        }
        let want = part.as_os_str().to_str()?;
        let dir = if found.as_os_str().is_empty() {
            Path::new(".")
        } else {
            found.as_path()
        };
        let mut matches = world.read_dir(dir).ok()?.into_iter().filter(|e| {
            e.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.eq_ignore_ascii_case(want))
        });
        let entry = matches.next()?;
        if matches.next().is_some() {
            return None;
        }
        found = entry;
    }
    world.is_file(&found).then_some(found)
}

/// A not-found message's list of the places searched, one per line.
pub fn searched_note(places: &[PathBuf]) -> String {
    let mut note = String::from("searched:");
    for p in places {
        note.push_str("\n  ");
        note.push_str(&p.display().to_string());
    }
    note
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn workspace_paths_search_ancestors_then_roots() {
        let ws = Workspaces::new(vec![PathBuf::from("/elsewhere/ws")]);
        let c = candidates(
            Path::new("/w/Proj/rules/a.cga"),
            "/ESRI.lib/rules/x.cga",
            &ws,
        );
        let shown: Vec<String> = c.iter().map(|p| p.display().to_string()).collect();
        assert_eq!(
            shown,
            [
                "/ESRI.lib/rules/x.cga",
                "/w/Proj/rules/ESRI.lib/rules/x.cga",
                "/w/Proj/rules/.ws/ESRI.lib/rules/x.cga",
                "/w/Proj/ESRI.lib/rules/x.cga",
                "/w/Proj/.ws/ESRI.lib/rules/x.cga",
                "/w/ESRI.lib/rules/x.cga",
                "/w/.ws/ESRI.lib/rules/x.cga",
                "/.ws/ESRI.lib/rules/x.cga",
                "/elsewhere/ws/ESRI.lib/rules/x.cga",
            ]
        );
    }

    #[test]
    fn relative_paths_search_the_folder_then_assets_and_project_roots() {
        let c = candidates(
            Path::new("/w/Proj/rules/a.cga"),
            "win/w.obj",
            &Workspaces::default(),
        );
        let shown: Vec<String> = c.iter().map(|p| p.display().to_string()).collect();
        assert_eq!(
            shown[..4],
            [
                "/w/Proj/rules/win/w.obj",
                "/w/Proj/rules/assets/win/w.obj",
                "/w/Proj/assets/win/w.obj",
                "/w/Proj/win/w.obj",
            ]
        );
        assert!(candidates(Path::new("/a/b.cga"), "  ", &Workspaces::default()).is_empty());
        // Folders separated by `\\` (rule files written on Windows).
        let c = candidates(
            Path::new("/w/P/a.cga"),
            "win\\w.obj",
            &Workspaces::default(),
        );
        assert_eq!(c[0], Path::new("/w/P/win/w.obj"));
    }

    #[test]
    fn names_in_another_case_are_found_when_no_exact_name_is() {
        let dir = std::env::temp_dir().join(format!("cga-locate-case-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("assets/Windows")).unwrap();
        std::fs::write(dir.join("assets/Windows/Win1.OBJ"), "v 0 0 0\n").unwrap();
        let from = dir.join("rules.cga");
        let world = cga_world::DiskWorld;
        let found = locate(&world, &from, "windows/win1.obj", &Workspaces::default()).unwrap();
        assert_eq!(found, dir.join("assets/Windows/Win1.OBJ"));
        assert!(locate(&world, &from, "windows/win2.obj", &Workspaces::default()).is_err());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
