//! Loading Wavefront OBJ assets (with their MTL materials) into a [`Mesh`].
//!
//! Hand-written rather than `tobj`: `tobj` splits a file into one model per
//! group or material, each with its own vertex arrays, which loses the
//! shared vertices and the file's face order that CGA's `comp(f)` indices
//! and `comp(g)` depend on. This parser keeps polygons as they are (no
//! triangulation), all positions in one array, faces in file order with
//! their group (`g`, or `o`) and material (`usemtl`).
//!
//! Errors are values: a missing or unreadable OBJ file and malformed
//! geometry lines (`v`, `vt`, `vn`, `f`) are errors naming the line; a
//! missing MTL file, an unknown material or a degenerate face are warnings
//! and the asset still loads (with default materials where needed).

use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{DVec2, DVec3};

use crate::material::Material;
use crate::mesh::Mesh;

/// A loaded asset and what was wrong with it short of failing.
#[derive(Clone, Debug)]
pub struct ObjAsset {
    pub mesh: Mesh,
    pub warnings: Vec<String>,
}

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ObjError {
    /// The file could not be read.
    Io { path: String, message: String },
    /// A malformed line (1-based line number).
    Parse { line: usize, message: String },
}

impl fmt::Display for ObjError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ObjError::Io { path, message } => write!(f, "cannot read '{path}': {message}"),
            ObjError::Parse { line, message } => write!(f, "line {line}: {message}"),
        }
    }
}

impl std::error::Error for ObjError {}

/// Loads an OBJ file and the MTL files it names (relative to its folder).
/// Texture paths in the materials are made relative to the OBJ's folder
/// (joined with it), as CGA resolves asset textures.
pub fn load_obj(path: &Path) -> Result<ObjAsset, ObjError> {
    let text = std::fs::read(path).map_err(|e| ObjError::Io {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let text = String::from_utf8_lossy(&text);
    parse_obj(&text, &dir, |name| {
        let p = dir.join(name);
        std::fs::read(&p)
            .map(|b| String::from_utf8_lossy(&b).into_owned())
            .map_err(|e| format!("cannot read material library '{}': {e}", p.display()))
    })
}

/// Parses OBJ text. `dir` is the folder texture paths are relative to;
/// `read_mtl` returns the text of a material library named by `mtllib`.
pub fn parse_obj(
    text: &str,
    dir: &Path,
    mut read_mtl: impl FnMut(&str) -> Result<String, String>,
) -> Result<ObjAsset, ObjError> {
    let mut warnings = Vec::new();
    let mut mesh = Mesh::new();
    mesh.materials.clear();
    mesh.groups.clear();
    let mut library: Vec<Material> = Vec::new();
    let mut vts: Vec<DVec2> = Vec::new();
    let mut vns: Vec<DVec3> = Vec::new();
    // Per-corner indices into vts / vns (u32::MAX: none).
    let mut corner_vt: Vec<u32> = Vec::new();
    let mut corner_vn: Vec<u32> = Vec::new();
    let mut group: String = String::new();
    let mut material: Option<String> = None;
    let mut face_buf: Vec<u32> = Vec::new();

    let mut lines = text.lines().enumerate().peekable();
    let mut joined = String::new();
    while let Some((no, raw)) = lines.next() {
        let line_no = no + 1;
        // Line continuation with a trailing backslash.
        let mut line: &str = raw;
        if raw.trim_end().ends_with('\\') {
            joined.clear();
            joined.push_str(raw.trim_end().trim_end_matches('\\'));
            while let Some((_, next)) = lines.peek() {
                let next = *next;
                lines.next();
                let t = next.trim_end();
                if let Some(s) = t.strip_suffix('\\') {
                    joined.push(' ');
                    joined.push_str(s);
                } else {
                    joined.push(' ');
                    joined.push_str(t);
                    break;
                }
            }
            line = &joined;
        }
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let mut tok = line.split_whitespace();
        let key = tok.next().unwrap_or("");
        let err = |message: String| ObjError::Parse {
            line: line_no,
            message,
        };
        match key {
            "v" => {
                let p = parse_floats::<3>(&mut tok, 3)
                    .ok_or_else(|| err(format!("expected three coordinates in '{line}'")))?;
                mesh.positions.push(DVec3::from(p));
            }
            "vt" => {
                let t = parse_floats::<2>(&mut tok, 1)
                    .ok_or_else(|| err(format!("expected texture coordinates in '{line}'")))?;
                vts.push(DVec2::from(t));
            }
            "vn" => {
                let n = parse_floats::<3>(&mut tok, 3)
                    .ok_or_else(|| err(format!("expected three normal components in '{line}'")))?;
                vns.push(DVec3::from(n));
            }
            "f" | "fo" => {
                face_buf.clear();
                let first_corner = corner_vt.len();
                for t in tok {
                    let mut parts = t.split('/');
                    let resolve =
                        |s: Option<&str>, n: usize, what: &str| -> Result<u32, ObjError> {
                            match s {
                                None | Some("") => Ok(u32::MAX),
                                Some(s) => {
                                    let i: i64 = s.parse().map_err(|_| {
                                        err(format!("bad {what} index '{s}' in '{line}'"))
                                    })?;
                                    let idx = if i > 0 { i - 1 } else { n as i64 + i };
                                    if i == 0 || idx < 0 || idx >= n as i64 {
                                        return Err(err(format!(
                                            "{what} index {i} out of range (1..={n}) in '{line}'"
                                        )));
                                    }
                                    Ok(idx as u32)
                                }
                            }
                        };
                    let p = resolve(parts.next(), mesh.positions.len(), "vertex")?;
                    if p == u32::MAX {
                        return Err(err(format!("missing vertex index in '{line}'")));
                    }
                    let vt = resolve(parts.next(), vts.len(), "texture coordinate")?;
                    let vn = resolve(parts.next(), vns.len(), "normal")?;
                    face_buf.push(p);
                    corner_vt.push(vt);
                    corner_vn.push(vn);
                }
                if face_buf.len() < 3 {
                    warnings.push(format!(
                        "line {line_no}: face with {} vertices skipped",
                        face_buf.len()
                    ));
                    corner_vt.truncate(first_corner);
                    corner_vn.truncate(first_corner);
                    continue;
                }
                let g = match mesh.groups.iter().position(|x| *x == group) {
                    Some(g) => g,
                    None => {
                        mesh.groups.push(group.clone());
                        mesh.groups.len() - 1
                    }
                };
                let name = material.as_deref().unwrap_or("");
                let m = match mesh.materials.iter().position(|x| &*x.name == name) {
                    Some(m) => m,
                    None => {
                        let mat = match library.iter().find(|x| &*x.name == name) {
                            Some(mat) => mat.clone(),
                            None => {
                                if !name.is_empty() {
                                    warnings.push(format!(
                                        "line {line_no}: material '{name}' not defined, using the default"
                                    ));
                                }
                                Material {
                                    name: Arc::from(name),
                                    ..Material::default()
                                }
                            }
                        };
                        mesh.materials.push(mat);
                        mesh.materials.len() - 1
                    }
                };
                let f = mesh.add_face(&[&face_buf], m as u32);
                mesh.faces[f].group = g as u32;
            }
            "g" | "o" => {
                let rest: Vec<&str> = tok.collect();
                // `o` names an object; a following `g` refines it. Either
                // names the group faces are put in.
                group = rest.join(" ");
            }
            "usemtl" => {
                material = Some(tok.collect::<Vec<_>>().join(" "));
            }
            "mtllib" => {
                // File names may contain spaces; try the whole rest first.
                let rest: Vec<&str> = tok.collect();
                let whole = rest.join(" ");
                let names: Vec<String> = if rest.len() > 1 {
                    match read_mtl(&whole) {
                        Ok(text) => {
                            library.extend(parse_mtl(&text, dir, &mut warnings));
                            continue;
                        }
                        Err(_) => rest.iter().map(|s| s.to_string()).collect(),
                    }
                } else {
                    vec![whole]
                };
                for name in names {
                    match read_mtl(&name) {
                        Ok(text) => library.extend(parse_mtl(&text, dir, &mut warnings)),
                        Err(e) => warnings.push(format!("line {line_no}: {e}")),
                    }
                }
            }
            _ => {} // s, l, p, curves, ...: not geometry CGA uses
        }
    }
    if mesh.materials.is_empty() {
        mesh.materials.push(Material::default());
    }
    if mesh.groups.is_empty() {
        mesh.groups.push(String::new());
    }
    if corner_vt.iter().any(|&i| i != u32::MAX) {
        mesh.uvs[0] = Some(
            corner_vt
                .iter()
                .map(|&i| vts.get(i as usize).copied().unwrap_or(DVec2::ZERO))
                .collect(),
        );
    }
    if corner_vn.iter().any(|&i| i != u32::MAX) {
        mesh.normals = Some(
            corner_vn
                .iter()
                .map(|&i| vns.get(i as usize).copied().unwrap_or(DVec3::ZERO))
                .collect(),
        );
    }
    Ok(ObjAsset { mesh, warnings })
}

/// Parses `N` floats, of which at least `min` must be present (missing
/// ones are 0). Extra values (w, vertex colours) are ignored.
fn parse_floats<'a, const N: usize>(
    tok: &mut impl Iterator<Item = &'a str>,
    min: usize,
) -> Option<[f64; N]> {
    let mut out = [0.0; N];
    for (k, o) in out.iter_mut().enumerate() {
        match tok.next() {
            Some(t) => {
                let x: f64 = t.parse().ok()?;
                if !x.is_finite() {
                    return None;
                }
                *o = x;
            }
            None if k >= min => break,
            None => return None,
        }
    }
    Some(out)
}

/// Parses an MTL material library. Texture paths are joined to `dir`.
/// Unparsable values are reported in `warnings` and skipped.
pub fn parse_mtl(text: &str, dir: &Path, warnings: &mut Vec<String>) -> Vec<Material> {
    let mut out: Vec<Material> = Vec::new();
    for (no, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let mut tok = line.split_whitespace();
        let key = tok.next().unwrap_or("");
        if key == "newmtl" {
            out.push(Material {
                name: Arc::from(tok.collect::<Vec<_>>().join(" ")),
                ..Material::default()
            });
            continue;
        }
        let Some(m) = out.last_mut() else {
            continue; // statements before any newmtl
        };
        let args: Vec<&str> = tok.collect();
        let color = |args: &[&str]| -> Option<[f64; 3]> {
            let v: Vec<f64> = args.iter().map_while(|a| a.parse().ok()).collect();
            match v.len() {
                0 => None,
                1 | 2 => Some([v[0]; 3]),
                _ => Some([v[0], v[1], v[2]]),
            }
        };
        let scalar = |args: &[&str]| args.first().and_then(|a| a.parse::<f64>().ok());
        let mut bad = false;
        match key.to_ascii_lowercase().as_str() {
            "kd" => color(&args)
                .map(|c| m.color = c)
                .unwrap_or_else(|| bad = true),
            "ka" => color(&args)
                .map(|c| m.ambient = c)
                .unwrap_or_else(|| bad = true),
            "ks" => color(&args)
                .map(|c| m.specular = c)
                .unwrap_or_else(|| bad = true),
            "ke" => color(&args)
                .map(|c| m.emissive = c)
                .unwrap_or_else(|| bad = true),
            "ns" => scalar(&args)
                .map(|x| m.shininess = x)
                .unwrap_or_else(|| bad = true),
            "d" => {
                // `d -halo 0.5` is the halo form; take the number.
                let a: Vec<&str> = args.iter().copied().filter(|a| *a != "-halo").collect();
                scalar(&a)
                    .map(|x| m.opacity = x)
                    .unwrap_or_else(|| bad = true)
            }
            "tr" => scalar(&args)
                .map(|x| m.opacity = 1.0 - x)
                .unwrap_or_else(|| bad = true),
            "map_kd" => set_map(m, 0, &args, dir),
            "map_bump" | "bump" => set_map(m, 1, &args, dir),
            "map_ks" => set_map(m, 3, &args, dir),
            "map_d" => set_map(m, 4, &args, dir),
            "norm" | "map_kn" => set_map(m, 5, &args, dir),
            "map_ke" => set_map(m, 6, &args, dir),
            _ => {}
        }
        if bad {
            warnings.push(format!(
                "material library line {}: cannot read '{line}'",
                no + 1
            ));
        }
    }
    out
}

/// Sets texture channel `k` from a `map_*` statement: options (`-s u v w`,
/// `-o u v w`, `-bm x`, `-clamp on`, ...) are skipped, the rest is the file
/// name (which may contain spaces), joined to `dir`.
fn set_map(m: &mut Material, k: usize, args: &[&str], dir: &Path) {
    let mut i = 0;
    while i < args.len() && args[i].starts_with('-') && args[i].len() > 1 {
        let opt = args[i];
        i += 1;
        let max_args = match opt {
            "-o" | "-s" | "-t" => 3,
            "-mm" => 2,
            _ => 1, // -bm, -boost, -blendu/v, -cc, -clamp, -texres, -imfchan
        };
        let mut n = 0;
        while n < max_args && i < args.len() {
            let is_value = args[i].parse::<f64>().is_ok()
                || matches!(args[i], "on" | "off")
                || (opt == "-imfchan" && args[i].len() == 1);
            if !is_value {
                break;
            }
            i += 1;
            n += 1;
        }
    }
    if i >= args.len() {
        return;
    }
    let name = args[i..].join(" ");
    let p = Path::new(&name);
    let full: PathBuf = if p.is_absolute() || dir.as_os_str().is_empty() {
        p.to_path_buf()
    } else {
        dir.join(p)
    };
    m.maps[k].path = Arc::from(full.to_string_lossy().as_ref());
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::{bounds, face_area, mesh_area, volume};
    use crate::topology::Topology;

    /// The Candler assets live outside the repository, in the oracle's
    /// package (`../shared/prt-oracle/rules/candler/assets`).
    fn candler(rel: &str) -> Option<PathBuf> {
        cga_testkit::shared(&format!("prt-oracle/rules/candler/assets/{rel}"))
    }

    fn load_candler(rel: &str) -> Option<ObjAsset> {
        let p = candler(rel)?;
        Some(load_obj(&p).expect("asset loads"))
    }

    #[test]
    fn candler_cylinder_loads_closed() {
        let Some(a) = load_candler("primitives/cylinder.hor.obj") else {
            return;
        };
        let m = &a.mesh;
        assert_eq!(m.positions.len(), 32);
        assert_eq!(m.faces.len(), 18);
        assert_eq!(m.groups, vec!["cyl".to_string()]);
        assert_eq!(m.materials.len(), 1);
        assert_eq!(m.face_loops(16)[0].len, 16);
        assert_eq!(m.uvs[0].as_ref().unwrap().len(), m.corners.len());
        assert_eq!(m.normals.as_ref().unwrap().len(), m.corners.len());
        assert_eq!(m.uvs[0].as_ref().unwrap()[0], DVec2::new(0.0, 0.083333));
        let (lo, hi) = bounds(m).unwrap();
        assert_eq!((lo.x, hi.x), (-5.0, 5.0));
        assert!(Topology::new(m).is_closed(m));
        // A 16-gon prism of circumradius 1 and length 10.
        let expected = 10.0 * 0.5 * 16.0 * (std::f64::consts::TAU / 16.0).sin();
        assert!((volume(m) - expected).abs() < 1e-4, "{}", volume(m));
        assert!(a.warnings.is_empty());
    }

    #[test]
    fn seed_split_of_the_horizontal_cylinder_gives_closed_slabs() {
        // split(x) { { ~0.75 : XX | ~1 : NIL } * | ~0.5 : XX } over the
        // cylinder's 10 units: five repetitions, stretched by 10 / 9.25.
        let Some(a) = load_candler("primitives/cylinder.hor.obj") else {
            return;
        };
        let m = &a.mesh;
        let k = 10.0 / 9.25;
        let mut cuts = Vec::new();
        let mut x = -5.0;
        for _ in 0..5 {
            x += 0.75 * k;
            cuts.push(x);
            x += 1.0 * k;
            cuts.push(x);
        }
        let parts = crate::cut::split_along_axis(m, 0, &cuts);
        assert_eq!(parts.len(), 11);
        let section = 0.5 * 16.0 * (std::f64::consts::TAU / 16.0).sin();
        let mut total = 0.0;
        let mut prev = -5.0;
        for (i, p) in parts.iter().enumerate() {
            let next = cuts.get(i).copied().unwrap_or(5.0);
            assert!(Topology::new(p).is_closed(p), "slab {i} not closed");
            assert_eq!(p.faces.len(), 18, "slab {i}: 16 sides and two caps");
            let v = volume(p);
            assert!((v - section * (next - prev)).abs() < 1e-4, "slab {i}: {v}");
            total += v;
            prev = next;
        }
        assert!((total - volume(m)).abs() <= 1e-9 * volume(m));
    }

    #[test]
    fn candler_sash_window_loads() {
        let Some(a) = load_candler("facade/windows/win.single.05.sashwindow.obj") else {
            return;
        };
        let m = &a.mesh;
        assert_eq!(m.faces.len(), 37);
        assert_eq!(m.groups, vec!["sashwindow".to_string()]);
        assert!(m.faces.iter().all(|f| f.loop_count == 1 && f.group == 0));
        assert!(mesh_area(m) > 0.0);
        let positions = std::fs::read_to_string(
            candler("facade/windows/win.single.05.sashwindow.obj").unwrap(),
        )
        .unwrap()
        .lines()
        .filter(|l| l.starts_with("v "))
        .count();
        assert_eq!(m.positions.len(), positions);
    }

    #[test]
    fn every_candler_asset_loads() {
        for (rel, faces) in [
            ("facade/ledges/ledgeLarge.obj", 33),
            ("facade/ledges/ledgeSmall.obj", 12),
            ("facade/ledges/modillion2.obj", 150),
            ("facade/misc/shopwin_frame.obj", 12),
            ("primitives/cylinder.half.obj", 13),
        ] {
            let Some(a) = load_candler(rel) else {
                return;
            };
            assert_eq!(a.mesh.faces.len(), faces, "{rel}");
        }
    }

    const MTL: &str = "\
# a library
newmtl brick
Kd 0.8 0.4 0.2
Ka 0.1 0.1 0.1
Ks 0.5 0.5 0.5
Ns 20
d 0.75
map_Kd -s 2 2 1 textures/brick wall.jpg
map_bump -bm 0.5 textures/brick_n.png
newmtl glass
Kd 0.2 0.3 0.9
Tr 0.6
map_d glass_alpha.png
norm glass_normal.png
";

    const OBJ: &str = "\
mtllib walls.mtl
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 2 0 0
v 2 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 0 1
g wall
usemtl brick
f 1/1/1 2/2/1 3/3/1 4/4/1
g pane
usemtl glass
f 2/1 5/2 -1/3 3/4
usemtl nothing
f 1 2 3
";

    #[test]
    fn obj_with_materials_groups_uvs_normals() {
        let a = parse_obj(OBJ, Path::new("assets/win"), |name| {
            assert_eq!(name, "walls.mtl");
            Ok(MTL.to_string())
        })
        .unwrap();
        let m = &a.mesh;
        assert_eq!(m.faces.len(), 3);
        assert_eq!(m.groups, vec!["wall".to_string(), "pane".to_string()]);
        assert_eq!(
            m.faces.iter().map(|f| f.group).collect::<Vec<_>>(),
            vec![0, 1, 1]
        );
        assert_eq!(
            m.faces.iter().map(|f| f.material).collect::<Vec<_>>(),
            vec![0, 1, 2]
        );
        let brick = &m.materials[0];
        assert_eq!(&*brick.name, "brick");
        assert_eq!(brick.color, [0.8, 0.4, 0.2]);
        assert_eq!(brick.ambient, [0.1; 3]);
        assert_eq!(brick.specular, [0.5; 3]);
        assert_eq!(brick.shininess, 20.0);
        assert_eq!(brick.opacity, 0.75);
        assert_eq!(&*brick.maps[0].path, "assets/win/textures/brick wall.jpg");
        assert_eq!(&*brick.maps[1].path, "assets/win/textures/brick_n.png");
        let glass = &m.materials[1];
        assert!((glass.opacity - 0.4).abs() < 1e-15);
        assert_eq!(&*glass.maps[4].path, "assets/win/glass_alpha.png");
        assert_eq!(&*glass.maps[5].path, "assets/win/glass_normal.png");
        assert_eq!(&*m.materials[2].name, "nothing");
        assert_eq!(m.materials[2].color, [1.0; 3]);
        assert_eq!(a.warnings.len(), 1);
        assert!(a.warnings[0].contains("'nothing'"));
        // Negative index -1 is the last vertex so far (6).
        assert_eq!(m.loop_indices(m.outer_loop(1)), &[1, 4, 5, 2]);
        let uv = m.uvs[0].as_ref().unwrap();
        assert_eq!(
            uv[4..8],
            [
                DVec2::new(0., 0.),
                DVec2::new(1., 0.),
                DVec2::new(1., 1.),
                DVec2::new(0., 1.)
            ]
        );
        assert_eq!(uv[8], DVec2::ZERO); // no vt on the last face
        let n = m.normals.as_ref().unwrap();
        assert_eq!(n[0], DVec3::Z);
        assert_eq!(n[4], DVec3::ZERO);
        assert_eq!(face_area(m, 0), 1.0);
    }

    #[test]
    fn missing_mtl_is_a_warning_and_bad_lines_are_errors() {
        let a = parse_obj(
            "mtllib gone.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n",
            Path::new(""),
            |_| Err("cannot read material library 'gone.mtl'".into()),
        )
        .unwrap();
        assert_eq!(a.mesh.faces.len(), 1);
        assert_eq!(a.warnings.len(), 2);
        assert_eq!(a.mesh.materials.len(), 1);
        assert_eq!(a.mesh.materials[0].color, [1.0; 3]);

        let e = parse_obj("v 0 0 0\nv 1 x 0\n", Path::new(""), |_| Err(String::new())).unwrap_err();
        assert!(matches!(e, ObjError::Parse { line: 2, .. }));
        let e = parse_obj("v 0 0 0\nf 1 2 3\n", Path::new(""), |_| Err(String::new())).unwrap_err();
        assert_eq!(
            e.to_string(),
            "line 2: vertex index 2 out of range (1..=1) in 'f 1 2 3'"
        );
        let e = load_obj(Path::new("/nonexistent/asset.obj")).unwrap_err();
        assert!(matches!(e, ObjError::Io { .. }));
        // Two-vertex faces are skipped with a warning.
        let a = parse_obj("v 0 0 0\nv 1 0 0\nf 1 2\n", Path::new(""), |_| {
            Err(String::new())
        })
        .unwrap();
        assert!(a.mesh.is_empty());
        assert_eq!(a.mesh.groups.len(), 1);
        assert_eq!(a.warnings.len(), 1);
    }
}
