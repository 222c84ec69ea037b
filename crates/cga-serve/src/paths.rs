//! Which files a request may name.
//!
//! Requests name workspace files by a path relative to the workspace.
//! The path is percent-decoded once, then refused if any part of it could
//! leave the folder: `..`, `.`, an empty part (`//`), a backslash, a
//! drive letter, a NUL. The confined world the files are read through
//! refuses symbolic links out of the workspace as a second line.

use std::path::{Component, Path, PathBuf};

/// The relative path a request names (`a/b.png` from `a%2Fb.png` or
/// `a/b.png`), or `None` when it could leave the folder.
pub fn relative_path(raw: &str) -> Option<PathBuf> {
    let decoded = percent_encoding::percent_decode_str(raw)
        .decode_utf8()
        .ok()?;
    if decoded.is_empty() || decoded.len() > 1024 {
        return None;
    }
    if decoded.contains(['\\', '\0', ':']) {
        return None;
    }
    let mut out = PathBuf::new();
    for part in decoded.split('/') {
        if part.is_empty() || part == "." || part == ".." {
            return None;
        }
        out.push(part);
    }
    // Belt and braces: nothing but plain names.
    if out.components().all(|c| matches!(c, Component::Normal(_))) {
        Some(out)
    } else {
        None
    }
}

/// A file name of the page's folder (`main.js`): one plain part of
/// letters, digits, `.`, `-` and `_`, not starting with a dot.
pub fn page_file(name: &str) -> Option<&str> {
    let ok = !name.is_empty()
        && name.len() <= 100
        && !name.starts_with('.')
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '.' | '-' | '_'));
    ok.then_some(name)
}

/// The media type of a file, by its extension.
pub fn content_type(path: &Path) -> &'static str {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match ext.as_str() {
        "html" => "text/html; charset=utf-8",
        "js" | "mjs" => "text/javascript; charset=utf-8",
        "css" => "text/css; charset=utf-8",
        "json" | "map" => "application/json",
        "png" => "image/png",
        "jpg" | "jpeg" => "image/jpeg",
        "svg" => "image/svg+xml",
        "glb" => "model/gltf-binary",
        "cga" | "txt" | "obj" | "mtl" | "csv" => "text/plain; charset=utf-8",
        _ => "application/octet-stream",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_plain_relative_paths_pass() {
        assert_eq!(
            relative_path("assets/a%20b.png"),
            Some(PathBuf::from("assets/a b.png"))
        );
        assert_eq!(relative_path("a%2Fb.obj"), Some(PathBuf::from("a/b.obj")));
        for bad in [
            "",
            "../etc/passwd",
            "..%2F..%2Fetc%2Fpasswd",
            "%2e%2e/%2e%2e/etc/passwd",
            "%2E%2E%2Fetc",
            "a/../../b",
            "/etc/passwd",
            "%2Fetc%2Fpasswd",
            "a//b",
            "./a",
            "a\\..\\b",
            "a%5C..%5Cb",
            "c:/windows",
            "a%00b",
            "%ff%fe",
        ] {
            assert_eq!(relative_path(bad), None, "{bad}");
        }
        // Encoded twice: decoded once it is a strange but harmless name.
        assert_eq!(
            relative_path("%252e%252e/x"),
            Some(PathBuf::from("%2e%2e/x"))
        );
    }

    #[test]
    fn page_files_are_single_plain_names() {
        assert_eq!(page_file("main.js"), Some("main.js"));
        for bad in ["", ".env", "a/b", "..", "a%2fb", "x y"] {
            assert_eq!(page_file(bad), None, "{bad}");
        }
    }
}
