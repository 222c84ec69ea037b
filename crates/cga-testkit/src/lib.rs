//! Test support shared by the crates' tests.
//!
//! The repository holds only what we wrote. Rule files, assets and outputs
//! of others (CityEngine's runtime packages and their golden outputs, the
//! corpus of real rule files) live in the folder `shared` beside the
//! repository (`../shared` from its root), or wherever `CGA_SHARED` points.
//! A test that needs them asks here: when they are absent it says so on
//! standard error and skips, unless `CGA_REQUIRE_SHARED` is set, when the
//! absence is a failure.

use std::path::{Path, PathBuf};

/// The repository's root folder.
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The shared data folder, if it exists.
pub fn shared_dir() -> Option<PathBuf> {
    if let Some(dir) = std::env::var_os("CGA_SHARED") {
        let dir = PathBuf::from(dir);
        return dir.is_dir().then_some(dir);
    }
    let dir = repo_root().join("../shared");
    dir.is_dir().then_some(dir)
}

/// `shared/REL`, when it exists. When it does not, prints that the test
/// is skipped and returns `None`; with `CGA_REQUIRE_SHARED` set, panics.
pub fn shared(rel: &str) -> Option<PathBuf> {
    let found = shared_dir().map(|d| d.join(rel)).filter(|p| p.exists());
    if found.is_none() {
        assert!(
            std::env::var_os("CGA_REQUIRE_SHARED").is_none(),
            "../shared/{rel} is required (CGA_REQUIRE_SHARED is set) but absent"
        );
        eprintln!("skipped: ../shared/{rel} is absent");
    }
    found
}

/// The oracle folder `shared/prt-oracle` (CityEngine's runtime, its rule
/// packages, lots and golden outputs).
pub fn oracle() -> Option<PathBuf> {
    shared("prt-oracle")
}

/// The unpacked rule package `NAME` of the oracle (its `rules/` and
/// `assets/` folders).
pub fn oracle_package(name: &str) -> Option<PathBuf> {
    shared(&format!("prt-oracle/rules/{name}"))
}

/// A rule file of an oracle package: `prt-oracle/rules/PACKAGE/rules/FILE`.
pub fn oracle_rule(package: &str, file: &str) -> Option<PathBuf> {
    shared(&format!("prt-oracle/rules/{package}/rules/{file}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_root_holds_the_workspace_manifest() {
        assert!(repo_root().join("Cargo.toml").is_file());
        assert!(repo_root().join("crates/cga-testkit").is_dir());
    }

    #[test]
    fn a_missing_file_is_none() {
        if std::env::var_os("CGA_REQUIRE_SHARED").is_none() {
            assert_eq!(shared("no/such/file.cga"), None);
        }
    }
}
