//! Rough timing of the plane cut: `cargo run --release --example cut_timing`.
use cga_geometry::{measure, primitive, split_along_axis, triangulate_face, DVec3};
use std::time::Instant;

fn main() {
    let s = primitive::sphere(64, 64, DVec3::splat(10.0));
    let cuts: Vec<f64> = (1..50).map(|i| i as f64 * 0.2).collect();
    let t = Instant::now();
    let mut n = 0;
    for _ in 0..20 {
        let parts = split_along_axis(&s, 0, &cuts);
        n += parts.iter().map(|p| p.faces.len()).sum::<usize>();
    }
    println!(
        "sphere 64x64 ({} faces) into 50 slabs: {:.2} ms per split ({} faces out)",
        s.faces.len(),
        t.elapsed().as_secs_f64() * 1000.0 / 20.0,
        n / 20
    );
    let lot = cga_geometry::Mesh::polygon(&[
        DVec3::new(0., 0., 0.),
        DVec3::new(20., 0., 0.),
        DVec3::new(20., 0., -30.),
        DVec3::new(0., 0., -30.),
    ]);
    let mass = cga_geometry::extrude(&lot, cga_geometry::Extrusion::FaceNormal, 10.0);
    let t = Instant::now();
    for _ in 0..10000 {
        let floors = split_along_axis(&mass, 1, &[3.0, 6.0, 9.0]);
        assert_eq!(floors.len(), 4);
    }
    println!(
        "box into 4 floors: {:.2} us per split",
        t.elapsed().as_secs_f64() * 1e6 / 10000.0
    );
    let t = Instant::now();
    let mut tris = Vec::new();
    for _ in 0..100 {
        tris.clear();
        for f in 0..s.faces.len() {
            triangulate_face(&s, f, &mut tris);
        }
    }
    println!(
        "triangulate sphere: {:.2} us",
        t.elapsed().as_secs_f64() * 1e6 / 100.0
    );
    println!("volume {}", measure::volume(&s));
}
