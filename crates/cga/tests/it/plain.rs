//! Plain meshes written back into model files (`cga::write_plain`), and
//! lots made from rings (`cga::lots::from_rings`): what hosts that keep
//! models or take polygons from their users (the Python package) use.

use cga::lots::{from_rings, Axes};
use cga::{Engine, MemoryWorld, ModelWriter, Options, Target};

const RULES: &str = "attr h = 9\n\
    Lot --> extrude(h) comp(f) { top : color(\"#ff0000\") Roof. | side : split(y) { ~3 : Floor. }* }\n";

#[test]
fn plain_models_write_the_triangles_a_writer_would() {
    let rules = Engine::new(MemoryWorld::new()).load_text("/p/r.cga", RULES);
    assert!(!rules.has_errors(), "{}", rules.render_diagnostics());
    // A lot with a hole: 10 x 10 minus 2 x 2 (eight outline edges).
    let lot = from_rings(
        "holed",
        &[
            vec![
                [0.0, 0.0, 0.0],
                [10.0, 0.0, 0.0],
                [10.0, 10.0, 0.0],
                [0.0, 10.0, 0.0],
            ],
            vec![
                [4.0, 4.0, 0.0],
                [6.0, 4.0, 0.0],
                [6.0, 6.0, 0.0],
                [4.0, 6.0, 0.0],
            ],
        ],
        Axes::Gis,
    )
    .unwrap();
    let lots = [lot, cga::lots::rect(20.0, 30.0)];
    let results = rules.generate_all(&lots, &Options::default()).unwrap();
    // 8 walls of 3 floors, 2 triangles each; the holed roof's triangles.
    let first = &results[0];
    assert_eq!(first.model.materials.len(), 2);
    let roof = first
        .model
        .meshes
        .iter()
        .find(|m| m.positions.iter().all(|p| p[1] == 9.0))
        .expect("a roof mesh");
    assert_eq!(roof.indices.len(), 8);
    let walls: usize = first.model.triangles() - roof.indices.len();
    assert_eq!(walls, 8 * 3 * 2);

    let mut direct = ModelWriter::glb_in_memory(rules.export_options()).unwrap();
    rules
        .generate_lots(
            &lots,
            &Options::default(),
            Target::Writer(&mut direct),
            |_| {},
        )
        .unwrap();
    let (_, direct) = direct.finish_bytes().unwrap();

    let mut plain = ModelWriter::glb_in_memory(rules.export_options()).unwrap();
    for r in &results {
        cga::write_plain(&mut plain, &r.model).unwrap();
    }
    let (glb, stats) = plain.finish_bytes().unwrap();
    assert_eq!(&glb[..4], b"glTF");
    assert_eq!(stats.triangles, direct.triangles);
    assert_eq!(
        stats.triangles as usize,
        results.iter().map(|r| r.model.triangles()).sum::<usize>()
    );

    // A triangle past the mesh's vertices is an error, not a panic.
    let mut broken = results[1].model.clone();
    broken.meshes[0].indices.push([0, 1, 999_999]);
    let mut w = ModelWriter::glb_in_memory(rules.export_options()).unwrap();
    let e = cga::write_plain(&mut w, &broken).unwrap_err();
    assert!(e.to_string().contains("past its"), "{e}");
}

/// A lot generated into a model file says how many triangles it wrote: as
/// many as its plain meshes have, an asset inserted many times (written
/// once, placed as instances) counted once per placement, with one job or
/// two, and for one lot with two jobs (where the calling thread encodes).
#[test]
fn lots_written_count_the_triangles_of_their_meshes() {
    // A tetrahedron: 4 triangles, inserted on every tile.
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";
    let world = MemoryWorld::new().with("/p/assets/tet.obj", obj);
    let rules = Engine::new(world).load_text(
        "/p/rules/r.cga",
        "Lot --> extrude(6) comp(f) { side : split(x) { ~2 : Tile }* | top : Roof. }\n\
         Tile --> split(y) { 3 : i(\"tet.obj\") s(0.5, 0.5, 0.5) Asset. | ~1 : Wall. }\n",
    );
    assert!(!rules.has_errors(), "{}", rules.render_diagnostics());
    let lots = [
        cga::lots::rect(20.0, 10.0),
        cga::lots::rect(6.0, 4.0),
        cga::lots::rect(9.0, 30.0),
    ];
    let kept = rules.generate_all(&lots, &Options::default()).unwrap();
    assert!(kept.iter().all(|r| r.triangles_written.is_none()));
    // 20 x 10: 10 + 5 tiles a side, each an asset and a wall.
    assert_eq!(kept[0].model.triangles(), 2 * (10 + 5) * (4 + 2) + 2);
    for (jobs, count) in [(1, 3), (2, 3), (2, 1)] {
        let mut writer = ModelWriter::glb_in_memory(rules.export_options()).unwrap();
        let mut written = Vec::new();
        rules
            .generate_lots(
                &lots[..count],
                &Options::default().jobs(jobs),
                Target::Writer(&mut writer),
                |r| written.push(r),
            )
            .unwrap();
        let (glb, stats) = writer.finish_bytes().unwrap();
        let instanced = b"EXT_mesh_gpu_instancing";
        assert!(glb.windows(instanced.len()).any(|w| w == instanced));
        let counts: Vec<Option<u64>> = written.iter().map(|r| r.triangles_written).collect();
        let want: Vec<Option<u64>> = kept[..count]
            .iter()
            .map(|r| Some(r.model.triangles() as u64))
            .collect();
        assert_eq!(counts, want, "jobs {jobs}");
        assert_eq!(stats.triangles, want.iter().flatten().sum::<u64>());
    }
}
