//! Derivation speed on a facade grammar: a 20 x 30 lot extruded to 60 m,
//! facades split into floors, floors into tiles, tiles into wall and window
//! parts, windows recessed. Criterion reports shapes per second.
//!
//!     cargo bench -p cga-engine --bench facade

use criterion::{criterion_group, criterion_main, Criterion, Throughput};

use cga_engine::assets::Assets;
use cga_engine::{generate_lot, lot, GenerateOptions};
use cga_syntax::SourceMap;

const RULES: &str = r##"
Lot --> extrude(60) comp(f) { side : Facade | top : Roof. }
Facade --> split(y) { 4 : Ground | { ~3.5 : Floor }* }
Ground --> split(x) { ~1 : Wall | { ~4 : Shop }* | ~1 : Wall }
Shop --> split(x) { 0.3 : Wall | ~1 : split(y) { ~1 : Glass | 0.8 : Wall } | 0.3 : Wall }
Floor --> split(x) { 0.5 : Wall | { ~3 : Tile }* | 0.5 : Wall }
Tile --> split(x) { ~1 : Wall | 1.4 : split(y) { 0.9 : Wall | ~1 : Window | 0.5 : Wall } | ~1 : Wall }
Window --> t(0, 0, -0.2) color("#5a7d9a") Glass
Glass --> Glass.
Wall --> color("#d8cfc4") WallSurface.
"##;

fn bench(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("cga-bench-facade-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("facade.cga");
    std::fs::write(&path, RULES).unwrap();
    let mut sources = SourceMap::new();
    let program = cga_engine::load(&cga_world::DiskWorld, &path, &mut sources)
        .usable()
        .expect("the facade grammar loads");
    let assets = Assets::on_disk(&sources);
    let rule = program.start_rule(None).unwrap();
    let lot = lot::rect(20.0, 30.0);
    let options = GenerateOptions::default();
    let shapes = generate_lot(&program, &assets, rule, &lot, 0, &options)
        .0
        .shapes;

    let mut group = c.benchmark_group("facade");
    group.throughput(Throughput::Elements(shapes as u64));
    group.bench_function(format!("20x30x60 building ({shapes} shapes)"), |b| {
        b.iter(|| generate_lot(&program, &assets, rule, &lot, 0, &options))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
