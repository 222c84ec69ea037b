//! OBJ + MTL output, read back and measured.

use std::process::Command;

use crate::common::*;
use cga_export::ExportOptions;
use cga_geometry::{DVec2, DVec3, Material, Mesh};

#[test]
fn cube_with_one_material() {
    let dir = out_dir("obj_cube");
    let path = dir.join("cube.obj");
    let cube = box_mesh(
        DVec3::new(1.0, 0.0, -4.0),
        DVec3::new(2.0, 3.0, 4.0),
        colored("wall", [0.5, 0.25, 0.125]),
    );
    let stats = write(&path, &[cube], ExportOptions::default());
    assert_eq!(
        (
            stats.vertices,
            stats.triangles,
            stats.faces,
            stats.materials
        ),
        (8, 12, 6, 1)
    );
    let obj = read_obj(&path);
    // Positions shared within the mesh; one normal per face; no UVs.
    assert_eq!((obj.v.len(), obj.vn.len(), obj.vt.len()), (8, 6, 0));
    assert_eq!(obj.faces.len(), 6);
    assert!(obj
        .faces
        .iter()
        .all(|(_, c)| c.len() == 4 && c.iter().all(|k| k[1] == 0)));
    assert_eq!(obj.usemtl, ["wall"]);
    let areas = obj.area_by_material();
    assert!((areas["wall"] - 52.0).abs() < 1e-9);
    // Each face's normal points away from the box centre.
    let centre = DVec3::new(2.0, 1.5, -2.0);
    for (_, corners) in &obj.faces {
        let n = obj.vn[corners[0][2] - 1];
        let p = obj.v[corners[0][0] - 1];
        assert!((p - centre).dot(n) > 0.0);
        assert_eq!(n.length(), 1.0);
    }
    let mtl = &obj.mtl["wall"];
    assert_eq!(mtl["Kd"], "0.5 0.25 0.125");
    assert_eq!(mtl["Ka"], "0 0 0");
    assert_eq!(mtl["Ks"], "0 0 0");
    assert_eq!(mtl["Ns"], "1");
    assert_eq!(mtl["d"], "1");
    assert!(!mtl.contains_key("map_Kd"));
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("\nv 3 3 -4\n"), "{text}");
}

#[test]
fn usemtl_where_the_material_changes() {
    let dir = out_dir("obj_materials");
    let path = dir.join("materials.obj");
    let red = || colored("red", [0.8, 0.1, 0.1]);
    let glass = Material {
        name: "glass".into(),
        color: [0.2, 0.4, 0.6],
        opacity: 0.4,
        specular: [0.5, 0.5, 0.5],
        shininess: 20.0,
        ..Material::default()
    };
    let meshes = [
        quad(DVec3::ZERO, 2.0, 3.0, red(), false),
        quad(DVec3::new(0.0, 0.0, -1.0), 1.0, 1.0, glass, false),
        quad(DVec3::new(5.0, 0.0, 0.0), 1.0, 2.0, red(), false),
        // Same name, other colour: another material with a unique name.
        quad(
            DVec3::new(9.0, 0.0, 0.0),
            1.0,
            1.0,
            colored("red", [0.9, 0.0, 0.0]),
            false,
        ),
    ];
    let stats = write(&path, &meshes, ExportOptions::default());
    assert_eq!((stats.materials, stats.faces, stats.vertices), (3, 4, 16));
    let obj = read_obj(&path);
    // Faces are written as they come: `usemtl` where the material changes.
    assert_eq!(obj.usemtl, ["red", "glass", "red", "red_2"]);
    // All four quads face +z: one shared `vn`.
    assert_eq!(obj.vn, [DVec3::Z]);
    let areas = obj.area_by_material();
    assert!((areas["red"] - 8.0).abs() < 1e-9);
    assert!((areas["glass"] - 1.0).abs() < 1e-9);
    assert!((areas["red_2"] - 1.0).abs() < 1e-9);
    // Vertex indices run on across meshes.
    let red_faces: Vec<_> = obj.faces.iter().filter(|(m, _)| m == "red").collect();
    assert_eq!(red_faces.len(), 2);
    let vs: Vec<usize> = red_faces[1].1.iter().map(|c| c[0]).collect();
    assert_eq!(vs, [9, 10, 11, 12]);
    assert_eq!(obj.v[8], DVec3::new(5.0, 0.0, 0.0));

    let glass = &obj.mtl["glass"];
    assert_eq!(glass["Kd"], "0.2 0.4 0.6");
    assert_eq!(glass["d"], "0.4");
    assert_eq!(glass["Ks"], "0.5 0.5 0.5");
    assert_eq!(glass["Ns"], "20");
    assert_eq!(obj.mtl["red_2"]["Kd"], "0.9 0 0");
}

#[test]
fn textures_uvs_and_maps() {
    let dir = out_dir("obj_texture");
    let project = dir.join("project");
    std::fs::create_dir_all(project.join("assets")).unwrap();
    let png = tiny_png();
    std::fs::write(project.join("assets/checker.png"), &png).unwrap();
    std::fs::write(project.join("assets/bumps.png"), &png).unwrap();
    let mut mat = colored("facade", [1.0, 1.0, 1.0]);
    mat.maps[0].path = "assets/checker.png".into();
    mat.maps[1].path = "/assets/bumps.png".into(); // workspace-absolute form
    mat.maps[4].path = "assets/checker.png".into();
    mat.maps[5].path = "assets/missing_normals.png".into();
    let mut textured = quad(DVec3::ZERO, 4.0, 3.0, mat.clone(), true);
    textured.uvs[0].as_mut().unwrap()[2] = DVec2::new(2.0, 0.75);
    let plain = quad(DVec3::new(0.0, 4.0, 0.0), 1.0, 1.0, mat, false);
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    let path = out.join("textured.obj");
    let stats = write(
        &path,
        &[textured.clone(), plain.clone()],
        ExportOptions {
            texture_roots: vec![project.clone()],
            embed_textures: true,
            georeference: None,
            ..ExportOptions::default()
        },
    );
    assert_eq!(stats.textures, 2);
    assert_eq!(stats.warnings.len(), 1, "{:?}", stats.warnings);
    assert!(stats.warnings[0].contains("assets/missing_normals.png"));

    let obj = read_obj(&path);
    // OBJ keeps CGA's UV orientation (no flip).
    let vt: Vec<[f64; 2]> = obj.vt.iter().map(|t| t.to_array()).collect();
    assert_eq!(vt, [[0.0, 0.0], [1.0, 0.0], [2.0, 0.75], [0.0, 1.0]]);
    assert_eq!(
        obj.faces[0].1.iter().map(|c| c[1]).collect::<Vec<_>>(),
        [1, 2, 3, 4]
    );
    // The mesh without UVs has `v//vn` corners.
    assert!(obj.faces[1].1.iter().all(|c| c[1] == 0));
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("f 5//1 6//1 7//1 8//1\n"), "{text}");

    let mtl = &obj.mtl["facade"];
    assert_eq!(mtl["map_Kd"], "checker.png");
    assert_eq!(mtl["map_bump"], "bumps.png");
    assert_eq!(mtl["map_d"], "checker.png");
    assert_eq!(mtl["norm"], "assets/missing_normals.png");
    assert_eq!(std::fs::read(out.join("checker.png")).unwrap(), png);
    assert_eq!(std::fs::read(out.join("bumps.png")).unwrap(), png);

    // Referencing instead of copying.
    let out2 = dir.join("out2");
    std::fs::create_dir_all(&out2).unwrap();
    let path2 = out2.join("ref.obj");
    write(
        &path2,
        &[textured],
        ExportOptions {
            texture_roots: vec![project],
            embed_textures: false,
            georeference: None,
            ..ExportOptions::default()
        },
    );
    assert_eq!(
        read_obj(&path2).mtl["facade"]["map_Kd"],
        "../project/assets/checker.png"
    );
    assert!(!out2.join("checker.png").exists());
}

#[test]
fn textures_with_the_same_file_name_get_distinct_copies() {
    let dir = out_dir("obj_texture_names");
    for sub in ["a", "b"] {
        std::fs::create_dir_all(dir.join(sub)).unwrap();
        std::fs::write(dir.join(sub).join("wall.png"), sub.as_bytes()).unwrap();
    }
    // An upper-case extension is written in lower case, as CityEngine does.
    std::fs::write(dir.join("a").join("1.PNG"), b"c").unwrap();
    let textured = |p: &str| {
        let mut m = Material::default();
        m.maps[0].path = p.into();
        quad(DVec3::ZERO, 1.0, 1.0, m, true)
    };
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    let path = out.join("walls.obj");
    write(
        &path,
        &[
            textured("a/wall.png"),
            textured("b/wall.png"),
            textured("a/1.PNG"),
        ],
        ExportOptions {
            texture_roots: vec![dir.clone()],
            embed_textures: true,
            georeference: None,
            ..ExportOptions::default()
        },
    );
    let obj = read_obj(&path);
    // Unnamed materials are named by their colour map.
    assert_eq!(obj.mtl["wall"]["map_Kd"], "wall.png");
    assert_eq!(obj.mtl["wall_2"]["map_Kd"], "wall_2.png");
    assert_eq!(std::fs::read(out.join("wall.png")).unwrap(), b"a");
    assert_eq!(std::fs::read(out.join("wall_2.png")).unwrap(), b"b");
    assert_eq!(obj.mtl["1"]["map_Kd"], "1.png");
    assert_eq!(std::fs::read(out.join("1.png")).unwrap(), b"c");
}

#[test]
fn face_with_hole_is_triangulated() {
    let dir = out_dir("obj_hole");
    let path = dir.join("hole.obj");
    let stats = write(
        &path,
        &[square_with_hole(colored("ground", [0.3, 0.3, 0.3]))],
        ExportOptions::default(),
    );
    assert_eq!((stats.faces, stats.triangles, stats.vertices), (1, 8, 8));
    let obj = read_obj(&path);
    assert_eq!(obj.v.len(), 8);
    assert_eq!(obj.vn, [DVec3::Y]);
    assert_eq!(obj.faces.len(), 8);
    assert!(obj.faces.iter().all(|(_, c)| c.len() == 3));
    assert!((obj.area_by_material()["ground"] - 12.0).abs() < 1e-9);
    // Every triangle winds counter-clockwise seen from +y.
    for (_, c) in &obj.faces {
        let p = |k: usize| obj.v[c[k][0] - 1];
        assert!((p(1) - p(0)).cross(p(2) - p(0)).y > 0.0);
    }
}

#[test]
fn mesh_normals_are_written_normalised() {
    let dir = out_dir("obj_normals");
    let mut m = Mesh::polygon(&[DVec3::ZERO, DVec3::X, DVec3::Y]);
    m.normals = Some(vec![
        DVec3::Z * 2.0,
        DVec3::new(0.0, 0.0, 5.0),
        DVec3::new(3.0, 0.0, 4.0),
    ]);
    let path = dir.join("normals.obj");
    write(&path, &[m], ExportOptions::default());
    let obj = read_obj(&path);
    assert_eq!(obj.vn, [DVec3::Z, DVec3::new(0.6, 0.0, 0.8)]);
    let vn: Vec<usize> = obj.faces[0].1.iter().map(|c| c[2]).collect();
    assert_eq!(vn, [1, 1, 2]);
}

#[test]
fn empty_model() {
    let dir = out_dir("obj_empty");
    let path = dir.join("empty.obj");
    let stats = write(&path, &[Mesh::new()], ExportOptions::default());
    assert_eq!(stats, cga_export::ExportStats::default());
    assert_eq!(
        std::fs::read_to_string(&path).unwrap(),
        "# CGA engine model\nmtllib empty.mtl\n"
    );
    assert_eq!(std::fs::read_to_string(dir.join("empty.mtl")).unwrap(), "");
}

/// The reference summary (area per appearance = Kd to 3 decimals + colour
/// map file name) must see a written quad exactly as it is.
#[test]
fn quad_summary_matches_the_reference_summary_script() {
    let Some(script) = prt_summary_script() else {
        return;
    };
    let dir = out_dir("obj_summary");
    std::fs::write(dir.join("bricks.jpg"), [0xff, 0xd8, 0xff, 0xe0]).unwrap();
    let mut brick = colored("brick", [0.988, 0.937, 0.886]);
    brick.maps[0].path = "bricks.jpg".into();
    let meshes = [
        // 2.5 x 3 quad on the street front, 0.5 x 0.25 quad of plain grey.
        quad(DVec3::new(1.0, 0.0, 0.0), 2.5, 3.0, brick, true),
        quad(
            DVec3::new(0.0, 3.0, -1.0),
            0.5,
            0.25,
            colored("grey", [0.0666667; 3]),
            false,
        ),
    ];
    let path = dir.join("model.obj");
    write(
        &path,
        &meshes,
        ExportOptions {
            texture_roots: vec![dir.clone()],
            embed_textures: true,
            georeference: None,
            ..ExportOptions::default()
        },
    );
    let out = match Command::new("python3").arg(&script).arg(&path).output() {
        Ok(out) => out,
        Err(e) => {
            eprintln!("note: cannot run python3 ({e}); skipping");
            return;
        }
    };
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        summary["totals"],
        serde_json::json!({"vertices": 8, "faces": 2, "triangles": 4, "area": 7.625})
    );
    assert_eq!(
        summary["area_by_appearance"],
        serde_json::json!({"0.988,0.937,0.886|bricks.jpg": 7.5, "0.067,0.067,0.067|-": 0.125})
    );
    assert_eq!(
        summary["bbox"],
        serde_json::json!({"min": [0.0, 0.0, -1.0], "max": [3.5, 3.25, 0.0]})
    );
}
