//! Texture paths: `texture()` and its opacity map, reading paths back, and
//! how the emitted geometry names the files (resolved from the rule file
//! that emits the shape; assets keep their own textures).

use std::path::Path;

use crate::texturing_common::*;

/// The first bytes of a PNG file (signature and header) with colour type
/// `color` (6: RGBA, 2: RGB): all the engine reads of it.
fn png_header(color: u8) -> Vec<u8> {
    let mut b = b"\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR\0\0\0\x02\0\0\0\x02\x08".to_vec();
    b.extend_from_slice(&[color, 0, 0, 0, 0, 0, 0, 0]);
    b.extend_from_slice(b"\0\0\0\0IEND\xae\x42\x60\x82");
    b
}

fn write(dir: &Path, rel: &str, bytes: &[u8]) -> String {
    let p = dir.join(rel);
    std::fs::create_dir_all(p.parent().unwrap()).unwrap();
    std::fs::write(&p, bytes).unwrap();
    p.canonicalize().unwrap().to_string_lossy().into_owned()
}

#[test]
fn texture_sets_the_opacity_map_for_images_with_alpha() {
    let dir = project("alpha");
    let leaf = write(&dir, "assets/tex/leaf.png", &png_header(6));
    write(&dir, "assets/tex/wall.png", &png_header(2));
    write(&dir, "assets/tex/wall.jpg", b"\xff\xd8\xff\xe0");
    let out = run_in(
        &dir,
        r#"Lot --> set(material.opacitymap, "old.png")
                   [ texture("tex/leaf.png") print(material.colormap) print(material.opacitymap) X. ]
                   [ texture("tex/wall.png") print(material.opacitymap) X. ]
                   [ texture("tex/wall.jpg") print(material.opacitymap) X. ]
                   [ texture("builtin:uvtest.png") print(material.colormap) print(material.opacitymap) X. ]"#,
        &rect(10.0, 10.0),
    );
    assert_eq!(
        out.prints,
        [
            "tex/leaf.png",
            "tex/leaf.png",
            "",
            "",
            "builtin:uvtest.png",
            ""
        ]
    );
    // Emitted: the file found, for both maps; built-ins stay names.
    let m = &out.meshes[0].materials[0];
    assert_eq!(&*m.maps[0].path, leaf);
    assert_eq!(&*m.maps[4].path, leaf);
    assert_eq!(&*out.meshes[2].materials[0].maps[4].path, "");
    assert_eq!(
        &*out.meshes[3].materials[0].maps[0].path,
        "builtin:uvtest.png"
    );
}

#[test]
fn paths_resolve_from_the_rule_file_and_missing_ones_stay_as_written() {
    let dir = project("paths");
    let bricks = write(&dir, "assets/facade/bricks.jpg", b"\xff\xd8\xff");
    let dirt = write(&dir, "rules/dirt.jpg", b"\xff\xd8\xff");
    let out = run_in(
        &dir,
        r#"Lot --> set(material.colormap, "facade/bricks.jpg")
                   set(material.dirtmap, "dirt.jpg")
                   set(material.normalmap, "nowhere/normals.png") X."#,
        &rect(10.0, 10.0),
    );
    let m = &out.meshes[0].materials[0];
    assert_eq!(&*m.maps[0].path, bricks);
    assert_eq!(&*m.maps[2].path, dirt);
    assert_eq!(&*m.maps[5].path, "nowhere/normals.png");
}

#[test]
fn imported_rules_resolve_from_their_own_folder() {
    let dir = project("imports");
    let brick = write(&dir, "rules/lib/brick.png", &png_header(2));
    std::fs::write(
        dir.join("rules/lib/style.cga"),
        r#"Wall --> texture("brick.png") X."#,
    )
    .unwrap();
    let out = run_in(
        &dir,
        r#"import walls : "lib/style.cga"
           Lot --> walls.Wall"#,
        &rect(10.0, 10.0),
    );
    assert_eq!(&*out.meshes[0].materials[0].maps[0].path, brick);
}

#[test]
fn assets_keep_their_textures_and_coordinates() {
    let dir = project("asset_textures");
    let win = write(&dir, "assets/windows/win.png", &png_header(2));
    write(
        &dir,
        "assets/windows/win.obj",
        b"mtllib win.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0.1 0.2\nvt 0.9 0.2\nvt 0.9 0.8\nvt 0.1 0.8\nusemtl glass\nf 1/1 2/2 3/3 4/4\n",
    );
    write(
        &dir,
        "assets/windows/win.mtl",
        b"newmtl glass\nKd 0.5 0.5 0.5\nmap_Kd win.png\n",
    );
    let out = run_in(
        &dir,
        r##"Lot --> s(2, 3, 0) i("windows/win.obj") color("#ff0000") X."##,
        &rect(10.0, 10.0),
    );
    let m = &out.meshes[0];
    assert_eq!(&*m.materials[0].maps[0].path, win);
    // The rule's colour applies over the asset's material; the map stays.
    assert_eq!(m.materials[0].color, [1.0, 0.0, 0.0]);
    let uvs: Vec<_> = corners(m, 0).into_iter().map(|(_, t)| t).collect();
    assert_eq!(
        uvs,
        [
            cga_geometry::DVec2::new(0.1, 0.2),
            cga_geometry::DVec2::new(0.9, 0.2),
            cga_geometry::DVec2::new(0.9, 0.8),
            cga_geometry::DVec2::new(0.1, 0.8)
        ]
    );
}
