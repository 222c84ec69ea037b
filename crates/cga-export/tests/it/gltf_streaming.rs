//! glTF and GLB output of models larger than the data held in memory
//! (`ExportOptions::flush_mib`): vertex data written out early, as extra
//! primitives, reads back as the same triangles as when it is all held.

use crate::common::*;
use cga_export::{ExportOptions, ExportStats};
use cga_geometry::{DVec2, DVec3, Material, Mesh};

/// Every triangle corner of each material in order: material name, then
/// per corner position, normal and texture coordinates (0 without).
fn corners_by_material(g: &Gltf) -> Vec<(String, Vec<[f32; 8]>)> {
    let mut out: Vec<(String, Vec<[f32; 8]>)> = Vec::new();
    for mesh in g.doc.meshes() {
        let mut corners = Vec::new();
        let mut name = String::new();
        for p in mesh.primitives() {
            name = p.material().name().unwrap_or_default().to_string();
            let tex = p
                .material()
                .pbr_metallic_roughness()
                .base_color_texture()
                .map_or(0, |t| t.tex_coord());
            let r = p.reader(|_| Some(&g.bin[..]));
            let pos: Vec<[f32; 3]> = r.read_positions().unwrap().collect();
            let nor: Vec<[f32; 3]> = r.read_normals().unwrap().collect();
            let uv: Option<Vec<[f32; 2]>> = r.read_tex_coords(tex).map(|t| t.into_f32().collect());
            for i in r.read_indices().unwrap().into_u32() {
                let i = i as usize;
                let t = uv.as_ref().map_or([0.0; 2], |u| u[i]);
                corners.push([
                    pos[i][0], pos[i][1], pos[i][2], nor[i][0], nor[i][1], nor[i][2], t[0], t[1],
                ]);
            }
        }
        out.push((name, corners));
    }
    out
}

fn project_with_texture(dir: &std::path::Path) -> std::path::PathBuf {
    let project = dir.join("project");
    std::fs::create_dir_all(&project).unwrap();
    std::fs::write(project.join("checker.png"), tiny_png()).unwrap();
    project
}

/// A model of several materials, one textured with its occlusion layer reading
/// UV set 0 too (equal coordinate sets), meshes with and without UVs.
fn model() -> Vec<Mesh> {
    let mut textured = colored("facade", [1.0, 1.0, 1.0]);
    textured.maps[0].path = "checker.png".into();
    textured.maps[7].path = "checker.png".into();
    let mut meshes = Vec::new();
    for i in 0..12 {
        let x = i as f64 * 3.0;
        let mut q = quad(DVec3::new(x, 0.0, 0.0), 2.0, 3.0, textured.clone(), true);
        q.uvs[0].as_mut().unwrap()[2] = DVec2::new(2.0 + x, 0.75);
        meshes.push(q);
        meshes.push(box_mesh(
            DVec3::new(x, 5.0, 0.0),
            DVec3::new(1.0, 2.0 + x, 1.0),
            colored("wall", [0.5, 0.4, 0.3]),
        ));
        meshes.push(quad(
            DVec3::new(x, 0.0, 4.0),
            1.0,
            1.0,
            textured.clone(),
            false,
        ));
        let glass = Material {
            name: "glass".into(),
            opacity: 0.5,
            ..Material::default()
        };
        meshes.push(square_with_hole(glass));
    }
    meshes
}

fn totals(s: &ExportStats) -> (u64, u64, u64, u64, u64) {
    (s.faces, s.triangles, s.vertices, s.materials, s.textures)
}

#[test]
fn data_written_early_reads_back_as_the_same_triangles() {
    let dir = out_dir("gltf_streaming");
    let project = project_with_texture(&dir);
    let meshes = model();
    for ext in ["glb", "gltf"] {
        let held = dir.join(format!("held.{ext}"));
        let early = dir.join(format!("early.{ext}"));
        let options = ExportOptions {
            texture_roots: vec![project.clone()],
            ..ExportOptions::default()
        };
        let a = write(&held, &meshes, options.clone());
        // Nothing may be held: every mesh's data is written before the next.
        let b = write(
            &early,
            &meshes,
            ExportOptions {
                flush_mib: 0,
                ..options
            },
        );
        assert_eq!(totals(&a), totals(&b), "{ext}");
        assert_eq!(totals(&a), (12 * 9, 12 * 24, 12 * 40, 3, 1), "{ext}");
        assert_valid_gltf(&held);
        assert_valid_gltf(&early);

        let (ga, gb) = (read_gltf(&held), read_gltf(&early));
        // One primitive per material when held; one per input mesh when
        // written early.
        let prims = |g: &Gltf| {
            g.doc
                .meshes()
                .map(|m| m.primitives().count())
                .collect::<Vec<_>>()
        };
        assert_eq!(prims(&ga), [1, 1, 1]);
        assert_eq!(prims(&gb), [24, 12, 12]);
        let (ca, cb) = (corners_by_material(&ga), corners_by_material(&gb));
        assert_eq!(ca.len(), 3);
        for ((na, a), (nb, b)) in ca.iter().zip(&cb) {
            assert_eq!(na, nb);
            assert_eq!(a, b, "corners of {na} ({ext})");
        }
        assert_eq!(ca[0].1.len(), 12 * 2 * 6, "facade corners");
        // Held: the two equal UV sets of the facade share one array; early,
        // every primitive has both.
        let sets = |g: &Gltf| {
            let p = g.doc.meshes().next().unwrap().primitives().next().unwrap();
            p.attributes()
                .filter(|(s, _)| matches!(s, gltf::Semantic::TexCoords(_)))
                .count()
        };
        assert_eq!((sets(&ga), sets(&gb)), (1, 2));
        // The embedded image follows the geometry in the binary chunk.
        if ext == "glb" {
            for g in [&ga, &gb] {
                let image = g.doc.images().next().unwrap();
                let gltf::image::Source::View { view, .. } = image.source() else {
                    panic!("GLB image should be embedded");
                };
                assert_eq!(
                    &g.bin[view.offset()..view.offset() + view.length()],
                    &tiny_png()[..]
                );
            }
        }
    }
}

#[test]
fn glb_json_larger_than_its_room_moves_the_data_up() {
    let dir = out_dir("gltf_streaming_room");
    // 1,500 materials written early as 1,500 primitives: the JSON needs more
    // than the megabyte left for it at the start of the file.
    let meshes: Vec<Mesh> = (0..1500)
        .map(|i| {
            let c = [
                (i % 10) as f64 / 10.0,
                (i / 10 % 15) as f64 / 15.0,
                (i / 150) as f64 / 10.0,
            ];
            quad(
                DVec3::new(i as f64, 0.0, 0.0),
                1.0,
                0.5 + (i % 7) as f64,
                colored(&format!("m{i}"), c),
                false,
            )
        })
        .collect();
    let path = dir.join("many.glb");
    let stats = write(
        &path,
        &meshes,
        ExportOptions {
            flush_mib: 0,
            ..ExportOptions::default()
        },
    );
    assert_eq!(
        (stats.materials, stats.faces, stats.triangles),
        (1500, 1500, 3000)
    );
    let bytes = std::fs::read(&path).unwrap();
    let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    assert!(json_len > 1 << 20, "JSON of {json_len} bytes fits the room");
    assert_eq!(
        u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize,
        bytes.len()
    );
    assert_valid_gltf(&path);
    let g = read_gltf(&path);
    let prims = primitives(&g);
    assert_eq!(prims.len(), 1500);
    for (i, p) in prims.iter().enumerate() {
        let want = 0.5 + (i % 7) as f64;
        assert!(
            (p.area() - want).abs() < 1e-5,
            "quad {i}: {} vs {want}",
            p.area()
        );
        assert_eq!(p.min[0], i as f32);
    }
}
