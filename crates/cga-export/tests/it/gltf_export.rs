//! GLB and glTF output: read back with the `gltf` crate and checked by the
//! Khronos glTF validator.

use std::collections::BTreeSet;

use crate::common::*;
use cga_export::{ExportError, ExportOptions, Format, ModelWriter};
use cga_geometry::{DVec2, DVec3, Material, Mesh};
use gltf::material::AlphaMode;

/// CityEngine's runtime writes colour factors with a 2.2 power curve.
fn color_to_linear(c: f32) -> f32 {
    f64::from(c).powf(2.2) as f32
}

#[test]
fn cube_with_one_material() {
    let dir = out_dir("gltf_cube");
    let cube = box_mesh(
        DVec3::new(1.0, 0.0, -4.0),
        DVec3::new(2.0, 3.0, 4.0),
        colored("wall", [0.5, 0.5, 0.5]),
    );
    for name in ["cube.glb", "cube.gltf"] {
        let path = dir.join(name);
        let stats = write(&path, std::slice::from_ref(&cube), ExportOptions::default());
        assert_eq!(
            (
                stats.vertices,
                stats.triangles,
                stats.faces,
                stats.materials
            ),
            (24, 12, 6, 1)
        );
        assert!(stats.warnings.is_empty(), "{:?}", stats.warnings);
        assert_valid_gltf(&path);

        let g = read_gltf(&path);
        assert_eq!(g.doc.meshes().count(), 1);
        assert_eq!(g.doc.nodes().count(), 1);
        assert_eq!(g.doc.default_scene().unwrap().nodes().count(), 1);
        let prims = primitives(&g);
        assert_eq!(prims.len(), 1);
        let p = &prims[0];
        // Flat shading: 4 own vertices per face.
        assert_eq!(p.positions.len(), 24);
        assert_eq!(p.indices.len(), 36);
        assert!(p.uvs.is_none());
        assert_eq!(p.min, vec![1.0, 0.0, -4.0]);
        assert_eq!(p.max, vec![3.0, 3.0, 0.0]);
        assert!((p.area() - 52.0).abs() < 1e-5);
        // Six distinct axis normals, each on 4 vertices.
        let normals: BTreeSet<[i32; 3]> = p.normals.iter().map(|n| n.map(|c| c as i32)).collect();
        assert_eq!(normals.len(), 6);
        for n in &p.normals {
            assert_eq!(n.iter().map(|c| c.abs()).sum::<f32>(), 1.0);
        }
        // Triangles wind counter-clockwise around their face normal.
        for t in p.indices.chunks_exact(3) {
            let v = |i: u32| DVec3::from(p.positions[i as usize].map(f64::from));
            let n = DVec3::from(p.normals[t[0] as usize].map(f64::from));
            let cross = (v(t[1]) - v(t[0])).cross(v(t[2]) - v(t[0]));
            assert!(cross.dot(n) > 0.0, "triangle {t:?} winds clockwise");
        }

        let m = g.doc.materials().next().unwrap();
        assert_eq!(m.name(), Some("wall"));
        let pbr = m.pbr_metallic_roughness();
        let lin = color_to_linear(0.5);
        assert!((lin - 0.217_637_64).abs() < 1e-6);
        assert_eq!(pbr.base_color_factor(), [lin, lin, lin, 1.0]);
        assert_eq!(pbr.metallic_factor(), 0.0);
        assert_eq!(pbr.roughness_factor(), 1.0);
        assert_eq!(m.alpha_mode(), AlphaMode::Opaque);
        assert!(m.double_sided());
    }
    // The .gltf keeps its data in cube.bin: 24 * (12 + 12) + 36 * 4 bytes.
    let bin = std::fs::metadata(dir.join("cube.bin")).unwrap().len();
    assert_eq!(bin, 24 * 24 + 36 * 4);
}

#[test]
fn several_materials_merge_by_value() {
    let dir = out_dir("gltf_materials");
    let red = || colored("red", [0.8, 0.1, 0.1]);
    let glass = Material {
        name: "glass".into(),
        color: [0.2, 0.4, 0.6],
        opacity: 0.4,
        double_sided: false,
        ..Material::default()
    };
    let metal = Material {
        name: "metal".into(),
        metallic: 0.9,
        roughness: 0.25,
        ..Material::default()
    };
    let meshes = [
        quad(DVec3::ZERO, 2.0, 3.0, red(), false),
        quad(DVec3::new(0.0, 0.0, -1.0), 1.0, 1.0, glass, false),
        // Equal to the first material, though built separately.
        quad(DVec3::new(5.0, 0.0, 0.0), 1.0, 2.0, red(), false),
        box_mesh(DVec3::new(0.0, 5.0, 0.0), DVec3::ONE, metal),
    ];
    for name in ["materials.glb", "materials.gltf"] {
        let path = dir.join(name);
        let stats = write(&path, &meshes, ExportOptions::default());
        assert_eq!(stats.materials, 3);
        assert_eq!(stats.faces, 9);
        assert_eq!(stats.triangles, 18);
        assert_eq!(stats.vertices, 8 + 4 + 24);
        assert_valid_gltf(&path);

        let g = read_gltf(&path);
        let names: Vec<_> = g
            .doc
            .materials()
            .map(|m| m.name().unwrap().to_string())
            .collect();
        assert_eq!(names, ["red", "glass", "metal"]);
        let node_names: Vec<_> = g
            .doc
            .nodes()
            .map(|n| n.name().unwrap().to_string())
            .collect();
        assert_eq!(node_names, names);
        let prims = primitives(&g);
        assert_eq!(prims.len(), 3);
        // The two red quads share one primitive.
        assert_eq!(prims[0].material, Some(0));
        assert_eq!(prims[0].positions.len(), 8);
        assert_eq!(prims[0].indices.len(), 12);
        assert!((prims[0].area() - 8.0).abs() < 1e-6);
        assert_eq!(prims[0].min, vec![0.0, 0.0, 0.0]);
        assert_eq!(prims[0].max, vec![6.0, 3.0, 0.0]);

        let mats: Vec<_> = g.doc.materials().collect();
        let red = mats[0].pbr_metallic_roughness().base_color_factor();
        let want = [0.8, 0.1, 0.1].map(color_to_linear);
        for k in 0..3 {
            assert!((red[k] - want[k]).abs() < 1e-6, "{red:?} vs {want:?}");
        }
        assert_eq!(red[3], 1.0);
        assert_eq!(mats[0].alpha_mode(), AlphaMode::Opaque);

        let glass = &mats[1];
        assert_eq!(glass.alpha_mode(), AlphaMode::Blend);
        assert_eq!(glass.pbr_metallic_roughness().base_color_factor()[3], 0.4);
        assert!(!glass.double_sided());

        let metal = mats[2].pbr_metallic_roughness();
        assert_eq!(metal.metallic_factor(), 0.9);
        assert_eq!(metal.roughness_factor(), 0.25);
        assert_eq!(metal.base_color_factor(), [1.0; 4]);
    }
}

#[test]
fn embedded_png_texture_and_flipped_uvs() {
    let dir = out_dir("gltf_texture");
    let project = dir.join("project");
    std::fs::create_dir_all(project.join("assets")).unwrap();
    let png = tiny_png();
    std::fs::write(project.join("assets/checker.png"), &png).unwrap();
    let mut mat = colored("facade", [1.0, 1.0, 1.0]);
    mat.maps[0].path = "assets/checker.png".into();
    let mut textured = quad(DVec3::ZERO, 4.0, 3.0, mat.clone(), true);
    textured.uvs[0].as_mut().unwrap()[2] = DVec2::new(2.0, 0.75);
    // Same material, but no UVs: gets TEXCOORD_0 = (0, 0).
    let plain = quad(DVec3::new(0.0, 4.0, 0.0), 1.0, 1.0, mat, false);
    let options = ExportOptions {
        texture_roots: vec![dir.join("elsewhere"), project.clone()],
        embed_textures: true,
        georeference: None,
        ..ExportOptions::default()
    };

    let glb = dir.join("out/textured.glb");
    std::fs::create_dir_all(glb.parent().unwrap()).unwrap();
    let stats = write(&glb, &[textured.clone(), plain.clone()], options.clone());
    assert_eq!(stats.textures, 1);
    assert!(stats.warnings.is_empty(), "{:?}", stats.warnings);
    assert_valid_gltf(&glb);
    let g = read_gltf(&glb);
    let image = g.doc.images().next().unwrap();
    match image.source() {
        gltf::image::Source::View { view, mime_type } => {
            assert_eq!(mime_type, "image/png");
            assert_eq!(
                &g.bin[view.offset()..view.offset() + view.length()],
                &png[..]
            );
        }
        gltf::image::Source::Uri { .. } => panic!("GLB image should be embedded"),
    }
    let m = g.doc.materials().next().unwrap();
    let info = m.pbr_metallic_roughness().base_color_texture().unwrap();
    assert_eq!(info.tex_coord(), 0);
    assert_eq!(info.texture().source().index(), 0);
    let p = &primitives(&g)[0];
    let uvs = p.uvs.as_ref().unwrap();
    assert_eq!(uvs.len(), 8);
    // v flipped: (0,0) (1,0) (2,0.75) (0,1) become (0,1) (1,1) (2,0.25) (0,0).
    assert_eq!(
        &uvs[..4],
        &[[0.0, 1.0], [1.0, 1.0], [2.0, 0.25], [0.0, 0.0]]
    );
    assert_eq!(&uvs[4..], &[[0.0, 0.0]; 4]);

    // glTF: the texture is copied next to the output and referred to by name.
    let gltf_path = dir.join("out/textured.gltf");
    write(
        &gltf_path,
        &[textured.clone(), plain.clone()],
        options.clone(),
    );
    assert_valid_gltf(&gltf_path);
    assert_eq!(std::fs::read(dir.join("out/checker.png")).unwrap(), png);
    let g = read_gltf(&gltf_path);
    match g.doc.images().next().unwrap().source() {
        gltf::image::Source::Uri { uri, .. } => assert_eq!(uri, "checker.png"),
        gltf::image::Source::View { .. } => panic!(".gltf image should be a file"),
    }

    // Not embedding: the glTF refers to the texture where it is.
    let dir2 = dir.join("out2");
    std::fs::create_dir_all(&dir2).unwrap();
    let referencing = ExportOptions {
        embed_textures: false,
        ..options
    };
    for name in ["ref.gltf", "ref.glb"] {
        let path = dir2.join(name);
        write(&path, &[textured.clone()], referencing.clone());
        assert_valid_gltf(&path);
        let g = read_gltf(&path);
        match g.doc.images().next().unwrap().source() {
            gltf::image::Source::Uri { uri, .. } => {
                assert_eq!(uri, "../project/assets/checker.png")
            }
            gltf::image::Source::View { .. } => panic!("image should be referenced"),
        }
    }
    assert!(!dir2.join("checker.png").exists());
}

#[test]
fn face_with_hole() {
    let dir = out_dir("gltf_hole");
    for name in ["hole.glb", "hole.gltf"] {
        let path = dir.join(name);
        let stats = write(
            &path,
            &[square_with_hole(Material::default())],
            ExportOptions::default(),
        );
        assert_eq!((stats.faces, stats.triangles, stats.vertices), (1, 8, 8));
        assert_valid_gltf(&path);
        let g = read_gltf(&path);
        let p = &primitives(&g)[0];
        assert_eq!(p.indices.len(), 24);
        assert!((p.area() - 12.0).abs() < 1e-6);
        assert!(p.normals.iter().all(|n| *n == [0.0, 1.0, 0.0]));
        assert_eq!(p.min, vec![0.0, 0.0, -4.0]);
        assert_eq!(p.max, vec![4.0, 0.0, 0.0]);
        // The default material (white, unnamed) is named by its colour.
        assert_eq!(
            g.doc.materials().next().unwrap().name(),
            Some("color_ffffff")
        );
    }
}

#[test]
fn empty_model() {
    let dir = out_dir("gltf_empty");
    // A mesh with only an edge and a point: nothing to export.
    let mut lines = Mesh::new();
    lines.positions.extend([DVec3::ZERO, DVec3::X]);
    lines.add_face(&[&[0, 1]], 0);
    lines.add_face(&[&[0]], 0);
    for name in ["empty.glb", "empty.gltf"] {
        let path = dir.join(name);
        let stats = write(
            &path,
            &[Mesh::new(), lines.clone()],
            ExportOptions::default(),
        );
        assert_eq!(stats, cga_export::ExportStats::default());
        assert_valid_gltf(&path);
        let g = read_gltf(&path);
        assert_eq!(g.doc.meshes().count(), 0);
        assert_eq!(g.doc.buffers().count(), 0);
    }
    assert!(!dir.join("empty.bin").exists());
}

#[test]
fn missing_texture_is_a_warning() {
    let dir = out_dir("gltf_missing_texture");
    let mut mat = colored("brick", [0.7, 0.3, 0.2]);
    mat.maps[0].path = "assets/nowhere.jpg".into();
    let path = dir.join("missing.glb");
    let meshes = [
        quad(DVec3::ZERO, 1.0, 1.0, mat.clone(), true),
        quad(DVec3::X, 1.0, 1.0, mat, true),
    ];
    let stats = write(
        &path,
        &meshes,
        ExportOptions {
            texture_roots: vec![dir.clone()],
            ..Default::default()
        },
    );
    assert_eq!(stats.warnings.len(), 1, "{:?}", stats.warnings);
    assert!(stats.warnings[0].contains("assets/nowhere.jpg"));
    assert_eq!(stats.textures, 0);
    assert_valid_gltf(&path);
    let g = read_gltf(&path);
    assert_eq!(g.doc.textures().count(), 0);
    let m = g.doc.materials().next().unwrap();
    assert!(m.pbr_metallic_roughness().base_color_texture().is_none());
    // The UVs are still there.
    assert_eq!(primitives(&g)[0].uvs.as_ref().unwrap().len(), 8);
}

#[test]
fn unsupported_texture_format_is_a_warning() {
    let dir = out_dir("gltf_tiff_texture");
    std::fs::write(dir.join("wall.tif"), b"II*\0 not really a tiff").unwrap();
    let mut mat = Material::default();
    mat.maps[0].path = "wall.tif".into();
    let path = dir.join("tif.glb");
    let stats = write(
        &path,
        &[quad(DVec3::ZERO, 1.0, 1.0, mat, true)],
        ExportOptions {
            texture_roots: vec![dir.clone()],
            ..Default::default()
        },
    );
    assert_eq!(stats.warnings.len(), 1, "{:?}", stats.warnings);
    assert!(stats.warnings[0].contains("neither PNG nor JPEG"));
    assert_valid_gltf(&path);
}

#[test]
fn mesh_normals_are_used_and_shared() {
    let dir = out_dir("gltf_normals");
    // Two triangles of a bent strip with smooth normals: 4 positions, 6
    // corners, and corners of the same position carry the same normal.
    let mut m = Mesh::new();
    m.positions.extend([
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(1.0, 1.0, 0.5),
        DVec3::new(0.0, 1.0, 0.0),
    ]);
    m.normals = Some(Vec::new());
    m.add_face(&[&[0, 1, 2]], 0);
    m.add_face(&[&[0, 2, 3]], 0);
    let up = DVec3::new(0.0, -0.2, 1.0);
    let n = |p: u32| if p == 2 { up * 3.0 } else { DVec3::Z * 2.0 };
    m.normals = Some(m.corners.iter().map(|&p| n(p)).collect());
    let path = dir.join("smooth.glb");
    let stats = write(&path, &[m], ExportOptions::default());
    assert_eq!((stats.vertices, stats.triangles), (4, 2));
    assert_valid_gltf(&path);
    let g = read_gltf(&path);
    let p = &primitives(&g)[0];
    assert_eq!(p.positions.len(), 4);
    assert_eq!(p.indices, vec![0, 1, 2, 0, 2, 3]);
    // Normalised on output.
    let want = up.normalize().as_vec3().to_array();
    assert_eq!(p.normals[2], want);
    assert_eq!(p.normals[0], [0.0, 0.0, 1.0]);
}

#[test]
fn bad_meshes_are_errors_or_warnings_not_panics() {
    let dir = out_dir("gltf_bad");
    let path = dir.join("bad.glb");
    let mut w = ModelWriter::create(&path, Format::Glb, ExportOptions::default()).unwrap();

    let mut out_of_range = Mesh::polygon(&[DVec3::ZERO, DVec3::X, DVec3::Y]);
    out_of_range.corners[1] = 7;
    assert!(matches!(
        w.add_mesh(&out_of_range),
        Err(ExportError::InvalidMesh(_))
    ));

    let mut bad_slot = Mesh::polygon(&[DVec3::ZERO, DVec3::X, DVec3::Y]);
    bad_slot.faces[0].material = 3;
    assert!(matches!(
        w.add_mesh(&bad_slot),
        Err(ExportError::InvalidMesh(_))
    ));

    let mut short_uvs = Mesh::polygon(&[DVec3::ZERO, DVec3::X, DVec3::Y]);
    short_uvs.uvs[0] = Some(vec![DVec2::ZERO]);
    assert!(matches!(
        w.add_mesh(&short_uvs),
        Err(ExportError::InvalidMesh(_))
    ));

    // NaN coordinates: the face is left out with a warning.
    let nan = Mesh::polygon(&[DVec3::ZERO, DVec3::X, DVec3::new(f64::NAN, 1.0, 0.0)]);
    w.add_mesh(&nan).unwrap();
    // Zero area: left out silently.
    let flat = Mesh::polygon(&[DVec3::ZERO, DVec3::X, DVec3::X * 2.0]);
    w.add_mesh(&flat).unwrap();
    w.add_mesh(&Mesh::polygon(&[DVec3::ZERO, DVec3::X, DVec3::Y]))
        .unwrap();
    let stats = w.finish().unwrap();
    assert_eq!((stats.faces, stats.triangles, stats.vertices), (1, 1, 3));
    assert_eq!(
        stats.warnings,
        ["1 face(s) with non-finite coordinates left out"]
    );
    assert_valid_gltf(&path);
}

#[test]
fn unwritable_output_is_an_io_error() {
    let dir = out_dir("gltf_unwritable");
    let path = dir.join("no/such/folder/model.glb");
    let err = ModelWriter::create(&path, Format::Glb, ExportOptions::default()).err();
    match err {
        Some(ExportError::Io { path: p, .. }) => assert_eq!(p, path),
        other => panic!("expected an I/O error, got {other:?}"),
    }
}

#[test]
fn bounds_of_inexact_coordinates_match_the_f32_data() {
    // 0.1 and 1/3 have no exact f32; min/max must equal the stored f32
    // values or the validator reports ACCESSOR_MIN_MISMATCH.
    let dir = out_dir("gltf_inexact");
    let origin = DVec3::new(0.1, -0.3, 1.0 / 3.0);
    let path = dir.join("inexact.glb");
    write(
        &path,
        &[box_mesh(origin, DVec3::splat(0.7), Material::default())],
        ExportOptions::default(),
    );
    assert_valid_gltf(&path);
    let p = &primitives(&read_gltf(&path))[0];
    assert_eq!(p.min, origin.as_vec3().to_array().to_vec());
    assert_eq!(p.max, (origin + 0.7).as_vec3().to_array().to_vec());
}

#[test]
fn format_from_extension() {
    use std::path::Path;
    assert_eq!(
        Format::from_path(Path::new("a/city.GLB")),
        Some(Format::Glb)
    );
    assert_eq!(
        Format::from_path(Path::new("city.gltf")),
        Some(Format::Gltf)
    );
    assert_eq!(Format::from_path(Path::new("city.obj")), Some(Format::Obj));
    assert_eq!(Format::from_path(Path::new("city.fbx")), None);
    assert_eq!(Format::from_path(Path::new("city")), None);
}

/// Lots begun with `begin_lot` are nodes of their own (named, with their
/// extras, a primitive per material), also when data was written out early;
/// with `Granularity::Material` everything is merged by material.
#[test]
fn a_node_per_lot_or_a_mesh_per_material() {
    use cga_export::{serde_json::json, Granularity};
    let dir = out_dir("gltf_lots");
    let red = colored("red", [1.0, 0.0, 0.0]);
    let blue = colored("blue", [0.0, 0.0, 1.0]);
    let lot_a = [
        box_mesh(DVec3::ZERO, DVec3::ONE, red.clone()),
        box_mesh(DVec3::Y, DVec3::ONE, blue.clone()),
    ];
    let lot_b = [box_mesh(DVec3::new(5.0, 0.0, 0.0), DVec3::ONE, red.clone())];
    for (name, granularity, flush_mib) in [
        ("lots.glb", Granularity::Lot, 64),
        ("lots.gltf", Granularity::Lot, 0),
        ("merged.glb", Granularity::Material, 64),
    ] {
        let path = dir.join(name);
        let options = ExportOptions {
            granularity,
            flush_mib,
            ..ExportOptions::default()
        };
        let mut w = ModelWriter::create(&path, Format::from_path(&path).unwrap(), options).unwrap();
        w.expect_lots(3);
        w.begin_lot("a", Some(json!({"lot": 0, "attributes": {"height": 12.5}})))
            .unwrap();
        for m in &lot_a {
            w.add_mesh(m).unwrap();
        }
        // A lot without geometry gets no node.
        w.begin_lot("empty", None).unwrap();
        w.begin_lot("b", Some(json!({"lot": 2}))).unwrap();
        for m in &lot_b {
            w.add_mesh(m).unwrap();
        }
        let stats = w.finish().unwrap();
        assert_eq!((stats.materials, stats.faces), (2, 18), "{name}");
        assert_valid_gltf(&path);
        let g = read_gltf(&path);
        let nodes: Vec<(String, usize, Option<String>)> = g
            .doc
            .nodes()
            .map(|n| {
                (
                    n.name().unwrap().to_string(),
                    n.mesh().unwrap().primitives().count(),
                    n.extras().as_ref().map(|e| e.get().to_string()),
                )
            })
            .collect();
        let areas: Vec<f64> = primitives(&g).iter().map(Prim::area).collect();
        match granularity {
            Granularity::Lot => {
                assert_eq!(
                    nodes,
                    [
                        (
                            "a".to_string(),
                            2,
                            Some(r#"{"attributes":{"height":12.5},"lot":0}"#.to_string())
                        ),
                        ("b".to_string(), 1, Some(r#"{"lot":2}"#.to_string())),
                    ],
                    "{name}"
                );
                // Lot a: a red and a blue cube; lot b: a red cube.
                assert_eq!(areas, [6.0, 6.0, 6.0], "{name}");
            }
            Granularity::Material => {
                assert_eq!(
                    nodes,
                    [("red".to_string(), 1, None), ("blue".to_string(), 1, None)]
                );
                assert_eq!(areas, [12.0, 6.0]);
            }
        }
    }
}
