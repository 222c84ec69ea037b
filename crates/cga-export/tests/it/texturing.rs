//! Texture features of the export: built-in textures, texture transforms
//! (`material.colormap.su/sv/tu/tv/rw`) and opacity from the colour map.

use crate::common::*;
use cga_export::builtin::builtin_texture;
use cga_export::ExportOptions;
use cga_geometry::{DVec2, DVec3};

fn uvtest_material() -> cga_geometry::Material {
    let mut m = colored("street", [1.0, 1.0, 1.0]);
    m.maps[0].path = "builtin:uvtest.png".into();
    m
}

#[test]
fn builtin_texture_is_embedded_in_glb() {
    let dir = out_dir("builtin_glb");
    let glb = dir.join("street.glb");
    let q = quad(DVec3::ZERO, 4.0, 3.0, uvtest_material(), true);
    let stats = write(&glb, &[q], ExportOptions::default());
    assert!(stats.warnings.is_empty(), "{:?}", stats.warnings);
    assert_eq!(stats.textures, 1);
    assert_valid_gltf(&glb);
    let g = read_gltf(&glb);
    let png = builtin_texture("builtin:uvtest.png").unwrap().png;
    match g.doc.images().next().unwrap().source() {
        gltf::image::Source::View { view, mime_type } => {
            assert_eq!(mime_type, "image/png");
            assert_eq!(
                &g.bin[view.offset()..view.offset() + view.length()],
                &png[..]
            );
        }
        gltf::image::Source::Uri { .. } => panic!("GLB image should be embedded"),
    }
    // Nothing written beside the GLB.
    let files: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
    assert_eq!(files.len(), 1);
}

#[test]
fn builtin_textures_are_written_beside_obj_and_gltf() {
    let dir = out_dir("builtin_obj");
    let obj = dir.join("street.obj");
    let mut checker = colored("box", [1.0, 1.0, 1.0]);
    checker.maps[0].path = "builtin:default".into();
    let meshes = [
        quad(DVec3::ZERO, 4.0, 3.0, uvtest_material(), true),
        quad(DVec3::new(5.0, 0.0, 0.0), 1.0, 1.0, checker, true),
    ];
    let stats = write(&obj, &meshes, ExportOptions::default());
    assert!(stats.warnings.is_empty(), "{:?}", stats.warnings);
    assert_eq!(stats.textures, 2);
    let o = read_obj(&obj);
    assert_eq!(o.mtl["street"]["map_Kd"], "builtin_uvtest.png");
    assert_eq!(o.mtl["box"]["map_Kd"], "builtin_default.png");
    assert_eq!(
        std::fs::read(dir.join("builtin_uvtest.png")).unwrap(),
        &builtin_texture("builtin:uvtest.png").unwrap().png[..]
    );
    assert_eq!(
        std::fs::read(dir.join("builtin_default.png")).unwrap(),
        &builtin_texture("builtin:default").unwrap().png[..]
    );

    // Also when textures are referred to where they are: built-ins have
    // no place but beside the model.
    let gltf_path = dir.join("ref/street.gltf");
    std::fs::create_dir_all(gltf_path.parent().unwrap()).unwrap();
    let options = ExportOptions {
        embed_textures: false,
        ..ExportOptions::default()
    };
    write(&gltf_path, &meshes[..1], options);
    assert_valid_gltf(&gltf_path);
    assert!(dir.join("ref/builtin_uvtest.png").is_file());
    let g = read_gltf(&gltf_path);
    match g.doc.images().next().unwrap().source() {
        gltf::image::Source::Uri { uri, .. } => assert_eq!(uri, "builtin_uvtest.png"),
        gltf::image::Source::View { .. } => panic!(".gltf image should be a file"),
    }
}

#[test]
fn unknown_builtin_is_a_warning() {
    let dir = out_dir("builtin_unknown");
    let mut m = colored("x", [1.0, 1.0, 1.0]);
    m.maps[0].path = "builtin:nothing.png".into();
    let stats = write(
        &dir.join("x.glb"),
        &[quad(DVec3::ZERO, 1.0, 1.0, m, true)],
        ExportOptions::default(),
    );
    assert_eq!(stats.textures, 0);
    assert_eq!(stats.warnings.len(), 1, "{:?}", stats.warnings);
    assert!(stats.warnings[0].contains("builtin:nothing.png"));
}

/// Reads `KHR_texture_transform` of the first material's base colour texture.
fn transform_of(path: &std::path::Path) -> serde_json::Value {
    let bytes = std::fs::read(path).unwrap();
    let g = gltf::Gltf::from_slice(&bytes).unwrap();
    let json: serde_json::Value = serde_json::to_value(g.document.into_json()).unwrap();
    assert_eq!(
        json["extensionsUsed"],
        serde_json::json!(["KHR_texture_transform"])
    );
    json["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"]
        ["KHR_texture_transform"]
        .clone()
}

#[test]
fn channel_transform_becomes_khr_texture_transform() {
    let dir = out_dir("transform");
    let mut m = uvtest_material();
    m.maps[0].su = 2.0;
    m.maps[0].sv = 0.5;
    m.maps[0].tu = 0.25;
    m.maps[0].tv = 0.1;
    let glb = dir.join("t.glb");
    let stats = write(
        &glb,
        &[quad(DVec3::ZERO, 1.0, 1.0, m.clone(), true)],
        ExportOptions::default(),
    );
    assert!(stats.warnings.is_empty(), "{:?}", stats.warnings);
    assert_valid_gltf(&glb);
    let t = transform_of(&glb);
    // uv' = (2u + 0.25, 0.5v + 0.1) in CGA; in glTF's flipped v the offset
    // is (0.25, 1 - 0.1 - 0.5).
    assert_eq!(t["scale"], serde_json::json!([2.0, 0.5]));
    assert_eq!(t["rotation"], serde_json::json!(0.0));
    let off: Vec<f64> = serde_json::from_value(t["offset"].clone()).unwrap();
    assert!(
        (off[0] - 0.25).abs() < 1e-6 && (off[1] - 0.4).abs() < 1e-6,
        "{off:?}"
    );

    // A quarter turn: (u, v) -> (-v, u) in CGA, i.e. glTF (u, 1 - v) ->
    // (-v, 1 - u), which the extension gives with rotation pi/2 and offset
    // (-1, 1).
    let mut r = uvtest_material();
    r.maps[0].rw = 90.0;
    let glb = dir.join("r.glb");
    write(
        &glb,
        &[quad(DVec3::ZERO, 1.0, 1.0, r, true)],
        ExportOptions::default(),
    );
    assert_valid_gltf(&glb);
    let t = transform_of(&glb);
    let rot: f64 = serde_json::from_value(t["rotation"].clone()).unwrap();
    assert!((rot - std::f64::consts::FRAC_PI_2).abs() < 1e-6);
    let off: Vec<f64> = serde_json::from_value(t["offset"].clone()).unwrap();
    assert!(
        (off[0] + 1.0).abs() < 1e-6 && (off[1] - 1.0).abs() < 1e-6,
        "{off:?}"
    );
    // Check the claim on a point: KHR maps q to R q + o with
    // R = [[cos, sin], [-sin, cos]].
    let q = DVec2::new(0.3, 1.0 - 0.8); // CGA (0.3, 0.8)
    let (s, c) = rot.sin_cos();
    let mapped = DVec2::new(c * q.x + s * q.y + off[0], -s * q.x + c * q.y + off[1]);
    let cga = DVec2::new(-0.8, 0.3); // rotated a quarter turn
    assert!((mapped - DVec2::new(cga.x, 1.0 - cga.y)).length() < 1e-6);
}

#[test]
fn opacity_from_the_colour_maps_alpha() {
    let dir = out_dir("alpha");
    std::fs::write(dir.join("leaf.png"), tiny_png()).unwrap();
    let mut m = colored("leaf", [1.0, 1.0, 1.0]);
    m.maps[0].path = dir.join("leaf.png").to_string_lossy().as_ref().into();
    m.maps[4].path = m.maps[0].path.clone();
    let mut masked = m.clone();
    masked.name = "masked".into();
    masked.opacitymap_mode = "mask".into();
    masked.opacitymap_cutoff = 0.25;
    let glb = dir.join("alpha.glb");
    let stats = write(
        &glb,
        &[
            quad(DVec3::ZERO, 1.0, 1.0, m, true),
            quad(DVec3::X * 2.0, 1.0, 1.0, masked, true),
        ],
        ExportOptions::default(),
    );
    assert!(stats.warnings.is_empty(), "{:?}", stats.warnings);
    assert_valid_gltf(&glb);
    let g = read_gltf(&glb);
    let mats: Vec<_> = g.doc.materials().collect();
    assert_eq!(mats[0].alpha_mode(), gltf::material::AlphaMode::Blend);
    assert_eq!(mats[1].alpha_mode(), gltf::material::AlphaMode::Mask);
    assert_eq!(mats[1].alpha_cutoff(), Some(0.25));

    // An opacity map of its own cannot be written: a warning.
    let mut other = colored("glass", [1.0, 1.0, 1.0]);
    other.maps[0].path = dir.join("leaf.png").to_string_lossy().as_ref().into();
    other.maps[4].path = "glass_alpha.png".into();
    let stats = write(
        &dir.join("other.glb"),
        &[quad(DVec3::ZERO, 1.0, 1.0, other, true)],
        ExportOptions::default(),
    );
    assert_eq!(stats.warnings.len(), 1, "{:?}", stats.warnings);
    assert!(stats.warnings[0].contains("glass_alpha.png"));
    let g = read_gltf(&dir.join("other.glb"));
    assert_eq!(
        g.doc.materials().next().unwrap().alpha_mode(),
        gltf::material::AlphaMode::Opaque
    );
}

#[test]
fn other_texture_layers_become_pbr_textures_with_their_uv_sets() {
    let dir = out_dir("pbr");
    let png = dir.join("t.png");
    std::fs::write(&png, tiny_png()).unwrap();
    let path: std::sync::Arc<str> = png.to_string_lossy().as_ref().into();
    let mut m = colored("pbr", [1.0, 1.0, 1.0]);
    for k in [0, 5, 6, 7, 8] {
        m.maps[k].path = path.clone();
    }
    // The normal map's layer 5 has its own coordinates on one quad; the
    // other quad lacks set 5 and reads set 0. No quad has sets 6, 7 or 8.
    let mut a = quad(DVec3::ZERO, 1.0, 1.0, m.clone(), true);
    a.uvs[5] = Some(vec![DVec2::new(0.5, 0.5); 4]);
    let b = quad(DVec3::X * 2.0, 1.0, 1.0, m, true);
    let glb = dir.join("pbr.glb");
    let stats = write(&glb, &[a, b], ExportOptions::default());
    assert!(stats.warnings.is_empty(), "{:?}", stats.warnings);
    assert_valid_gltf(&glb);
    let g = read_gltf(&glb);
    let mat = g.doc.materials().next().unwrap();
    let pbr = mat.pbr_metallic_roughness();
    assert_eq!(pbr.base_color_texture().unwrap().tex_coord(), 0);
    assert_eq!(mat.normal_texture().unwrap().tex_coord(), 1);
    assert_eq!(mat.emissive_texture().unwrap().tex_coord(), 0);
    assert_eq!(mat.occlusion_texture().unwrap().tex_coord(), 0);
    assert_eq!(pbr.metallic_roughness_texture().unwrap().tex_coord(), 0);
    // A map replaces its scalar: emissive 1, roughness 1; metalness stays 0
    // (a roughness map alone is written for non-metals only).
    assert_eq!(mat.emissive_factor(), [1.0; 3]);
    assert_eq!(pbr.roughness_factor(), 1.0);
    assert_eq!(pbr.metallic_factor(), 0.0);
    // One image, shared by all five.
    assert_eq!(g.doc.images().count(), 1);
    let prim = g.doc.meshes().next().unwrap().primitives().next().unwrap();
    let r = prim.reader(|_| Some(&g.bin[..]));
    let t0: Vec<[f32; 2]> = r.read_tex_coords(0).unwrap().into_f32().collect();
    let t1: Vec<[f32; 2]> = r.read_tex_coords(1).unwrap().into_f32().collect();
    assert!(r.read_tex_coords(2).is_none());
    assert_eq!(&t1[..4], &[[0.5, 0.5]; 4]);
    assert_eq!(&t1[4..], &t0[4..]);
    // The normal map needs tangents: on the second quad (facing +z, u along
    // +x, v up) the tangent is +x and glTF's bitangent, whose v runs down
    // the image, is -y = cross(+z, +x) * -1.
    let tangents: Vec<[f32; 4]> = r.read_tangents().unwrap().collect();
    assert_eq!(tangents.len(), 8);
    assert_eq!(&tangents[4..], &[[1.0, 0.0, 0.0, -1.0]; 4]);

    // Roughness and metalness from two images cannot be packed: a warning.
    let mut two = colored("two", [1.0, 1.0, 1.0]);
    two.maps[8].path = path.clone();
    two.maps[9].path = "metal.png".into();
    let stats = write(
        &dir.join("two.glb"),
        &[quad(DVec3::ZERO, 1.0, 1.0, two, true)],
        ExportOptions::default(),
    );
    assert_eq!(stats.warnings.len(), 1, "{:?}", stats.warnings);
    assert!(stats.warnings[0].contains("metal.png"));
}
