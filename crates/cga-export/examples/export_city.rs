//! Writes a synthetic "city" of boxes, for measuring export speed and memory:
//!
//!     cargo run --release -p cga-export --example export_city -- city.glb 100000
//!
//! Each building is one mesh (6 quads) with one of 8 materials in turn (one
//! of them translucent), so every mesh switches material and the per-material
//! merging is exercised.
use std::path::PathBuf;
use std::time::Instant;

use cga_export::{ExportOptions, Format, ModelWriter};
use cga_geometry::{DVec3, Material, Mesh};

fn building(i: usize, materials: &[Material]) -> Mesh {
    let (x, z) = ((i % 300) as f64 * 25.0, (i / 300) as f64 * -35.0);
    let h = 10.0 + (i % 17) as f64 * 3.0;
    let mut m = Mesh::new();
    m.materials[0] = materials[i % materials.len()].clone();
    let s = DVec3::new(20.0, h, 30.0);
    for (a, b, c) in [
        (0., 0., 0.),
        (1., 0., 0.),
        (1., 0., -1.),
        (0., 0., -1.),
        (0., 1., 0.),
        (1., 1., 0.),
        (1., 1., -1.),
        (0., 1., -1.),
    ] {
        m.positions
            .push(DVec3::new(x, 0.0, z) + DVec3::new(a, b, c) * s);
    }
    for q in [
        [0, 3, 2, 1],
        [4, 5, 6, 7],
        [0, 1, 5, 4],
        [1, 2, 6, 5],
        [2, 3, 7, 6],
        [3, 0, 4, 7],
    ] {
        m.add_face(&[&q], 0);
    }
    m
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = PathBuf::from(args.next().unwrap_or_else(|| "city.glb".into()));
    let n: usize = args.next().map_or(Ok(10_000), |s| s.parse())?;
    let format = Format::from_path(&path).ok_or("output must be .glb, .gltf or .obj")?;
    let materials: Vec<Material> = (0..8)
        .map(|k| Material {
            name: format!("colour{k}").into(),
            color: [k as f64 / 8.0, 0.5, 1.0 - k as f64 / 8.0],
            opacity: if k == 7 { 0.5 } else { 1.0 },
            ..Material::default()
        })
        .collect();
    let start = Instant::now();
    let mut w = ModelWriter::create(&path, format, ExportOptions::default())?;
    for i in 0..n {
        w.add_mesh(&building(i, &materials))?;
    }
    let stats = w.finish()?;
    let secs = start.elapsed().as_secs_f64();
    eprintln!(
        "{n} buildings: {} vertices, {} triangles, {} materials in {secs:.3} s ({:.0} buildings/s)",
        stats.vertices,
        stats.triangles,
        stats.materials,
        n as f64 / secs
    );
    Ok(())
}
