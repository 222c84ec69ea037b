//! Meshes encoded on other threads ([`Encoder`]) and appended in order
//! give the file that adding them to the writer one by one gives, however
//! they are cut into batches and whichever thread encoded a batch.

use crate::common::*;
use cga_export::{Encoded, ExportError, ExportOptions, Format, ModelWriter};
use cga_geometry::mesh::SharedVec;
use cga_geometry::{DAffine3, DMat3, DVec2, DVec3, Material, Mesh};

/// Meshes, each with the map that places it: textured (colour, occlusion
/// and normal maps: several UV sets, tangents), coloured, with normals of
/// their own (shared vertices), without UVs after UVs (UV set 0 started
/// late), mirrored, with holes.
fn placed_model() -> Vec<(Mesh, DAffine3)> {
    let mut textured = colored("facade", [1.0, 1.0, 1.0]);
    textured.maps[0].path = "checker.png".into();
    textured.maps[7].path = "checker.png".into();
    let mut bumpy = colored("bumpy", [0.8, 0.8, 0.8]);
    bumpy.maps[0].path = "checker.png".into();
    bumpy.maps[5].path = "checker.png".into();
    let glass = Material {
        name: "glass".into(),
        opacity: 0.5,
        ..Material::default()
    };
    let mut out = Vec::new();
    for i in 0..40 {
        let x = i as f64 * 3.0;
        let turn = DMat3::from_rotation_y(0.1 * i as f64);
        let mirror = if i % 3 == 0 {
            DMat3::from_diagonal(DVec3::new(-1.0, 1.0, 1.0))
        } else {
            DMat3::IDENTITY
        };
        let t = DAffine3::from_mat3_translation(mirror * turn, DVec3::new(x, 0.5, -x));
        let mut q = quad(DVec3::ZERO, 2.0, 3.0, textured.clone(), true);
        q.uvs[0].as_mut().unwrap()[2] = DVec2::new(2.0 + x, 0.75);
        out.push((q, t));
        // Untextured, first without UVs, later with them.
        let mut wall = box_mesh(
            DVec3::ZERO,
            DVec3::new(1.0, 2.0 + x, 1.0),
            colored("wall", [0.5, 0.4, 0.3]),
        );
        if i >= 20 {
            let n = wall.corners.len();
            wall.uvs[0] = Some((0..n).map(|c| DVec2::new(c as f64, 0.5)).collect());
        }
        if i % 2 == 1 {
            // Normals of its own: corners share vertices where they agree.
            let n = wall.corners.len();
            wall.normals = Some(
                (0..n)
                    .map(|c| DVec3::new(0.0, 1.0, (c % 3) as f64))
                    .collect(),
            );
        }
        out.push((wall, t));
        out.push((quad(DVec3::ZERO, 1.0, 1.0, bumpy.clone(), true), t));
        out.push((square_with_hole(glass.clone()), t));
    }
    out
}

fn project(dir: &std::path::Path) -> ExportOptions {
    let project = dir.join("project");
    std::fs::create_dir_all(&project).unwrap();
    std::fs::write(project.join("checker.png"), tiny_png()).unwrap();
    ExportOptions {
        texture_roots: vec![project],
        ..ExportOptions::default()
    }
}

/// Writes the model adding every mesh to the writer.
fn added(path: &std::path::Path, model: &[(Mesh, DAffine3)], options: ExportOptions) {
    let mut w = ModelWriter::create(path, Format::from_path(path).unwrap(), options).unwrap();
    for (m, t) in model {
        w.add_placed(m, Some(t), &m.materials).unwrap();
    }
    let stats = w.finish().unwrap();
    assert_eq!(stats.faces, 40 * 9);
}

/// Writes the model encoding it on `threads` threads in batches of
/// `batch` meshes (thread k takes every k-th batch), appended in order.
fn encoded(
    path: &std::path::Path,
    model: &[(Mesh, DAffine3)],
    options: ExportOptions,
    threads: usize,
    batch: usize,
) {
    let mut w = ModelWriter::create(path, Format::from_path(path).unwrap(), options).unwrap();
    let chunks: Vec<&[(Mesh, DAffine3)]> = model.chunks(batch).collect();
    let encoder = w.encoder().expect("glTF has encoders");
    let mut batches: Vec<(usize, Encoded)> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..threads)
            .map(|k| {
                let mut e = encoder.another();
                let chunks = &chunks;
                s.spawn(move || {
                    let mut mine = Vec::new();
                    for (i, chunk) in chunks.iter().enumerate().skip(k).step_by(threads) {
                        for (m, t) in chunk.iter() {
                            e.add_placed(m, Some(t), &m.materials);
                        }
                        mine.push((i, e.take()));
                    }
                    mine
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().unwrap())
            .collect()
    });
    batches.sort_by_key(|(i, _)| *i);
    assert_eq!(batches.len(), chunks.len());
    for (_, b) in batches {
        assert!(!b.is_empty());
        w.append(b).unwrap();
    }
    let stats = w.finish().unwrap();
    assert_eq!(stats.faces, 40 * 9);
}

#[test]
fn encoded_batches_write_what_added_meshes_write() {
    let dir = out_dir("gltf_encoding");
    let options = project(&dir);
    let model = placed_model();
    for ext in ["glb", "gltf"] {
        // One file name in separate folders: glTF names its `.bin`.
        let in_dir = |name: &str| {
            let d = dir.join(name);
            std::fs::create_dir_all(&d).unwrap();
            d.join(format!("model.{ext}"))
        };
        let reference = in_dir("added");
        added(&reference, &model, options.clone());
        assert_valid_gltf(&reference);
        let want = std::fs::read(&reference).unwrap();
        let data = if ext == "glb" {
            want.len()
        } else {
            std::fs::metadata(reference.with_extension("bin"))
                .unwrap()
                .len() as usize
        };
        assert!(data > 30_000, "{ext}: {data} bytes");
        for (threads, batch) in [(1, model.len()), (1, 1), (2, 7), (3, 5), (4, 64)] {
            let path = in_dir(&format!("encoded_{threads}_{batch}"));
            encoded(&path, &model, options.clone(), threads, batch);
            let got = std::fs::read(&path).unwrap();
            assert!(
                got == want,
                "{ext}: {threads} threads, batches of {batch}: the files differ"
            );
            if ext == "gltf" {
                let bin = |p: &std::path::Path| std::fs::read(p.with_extension("bin")).unwrap();
                assert!(
                    bin(&path) == bin(&reference),
                    "{threads}/{batch}: .bin differs"
                );
            }
        }
    }
}

#[test]
fn equal_chunks_encode_to_equal_batches() {
    let dir = out_dir("gltf_encoding_reuse");
    let model = placed_model();
    let path = dir.join("model.glb");
    let mut w = ModelWriter::create(&path, Format::Glb, project(&dir)).unwrap();
    let mut e = w.encoder().unwrap();
    let mut sizes = Vec::new();
    for chunk in model.chunks(8) {
        for (m, t) in chunk {
            e.add_placed(m, Some(t), &m.materials);
        }
        sizes.push(e.bytes());
        w.append(e.take()).unwrap();
    }
    // Equal chunks encode to equal sizes, whether in the encoder's fresh
    // or kept room (the walls of the second half have UVs).
    assert_eq!(sizes.len(), 20);
    let (first, second) = sizes.split_at(10);
    assert!(first.iter().all(|&s| s == first[0]), "{sizes:?}");
    assert!(second.iter().all(|&s| s == second[0]), "{sizes:?}");
    assert!(second[0] > first[0] && first[0] > 0, "{sizes:?}");
    let stats = w.finish().unwrap();
    assert_eq!(stats.faces, 40 * 9);
    assert_valid_gltf(&path);
}

#[test]
fn an_invalid_mesh_fails_its_batch() {
    let dir = out_dir("gltf_encoding_invalid");
    let path = dir.join("model.glb");
    let mut w = ModelWriter::create(&path, Format::Glb, ExportOptions::default()).unwrap();
    let mut e = w.encoder().unwrap();
    let good = box_mesh(DVec3::ZERO, DVec3::ONE, colored("wall", [1.0, 0.0, 0.0]));
    e.add_placed(&good, None, &good.materials);
    // Its faces use slot 0, but no material is given for it.
    let none: SharedVec<Material> = SharedVec::default();
    e.add_placed(&good, None, &none);
    e.add_placed(&good, None, &good.materials);
    let r = w.append(e.take());
    assert!(
        matches!(&r, Err(ExportError::InvalidMesh(m)) if m.contains("material slot 0 of 0")),
        "{:?}",
        r.err()
    );
    // The encoder goes on with a new batch.
    e.add_placed(&good, None, &good.materials);
    w.append(e.take()).unwrap();
    assert_eq!(w.finish().unwrap().faces, 6);
}

#[test]
fn obj_writers_have_no_encoder() {
    let dir = out_dir("gltf_encoding_obj");
    let w = ModelWriter::create(&dir.join("m.obj"), Format::Obj, ExportOptions::default()).unwrap();
    assert!(w.encoder().is_none());
}
