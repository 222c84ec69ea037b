//! The `cga` command answers `inter` context queries across the lots of
//! one run: every lot's first pass is collected before any lot is derived
//! a second time, whatever the number of worker threads.

use crate::common::*;

/// Three lots: two 10 x 10 side by side (sharing the edge x = 10) and one
/// far away at x = 100.
const LOTS: &str = "v 0 0 0\nv 10 0 0\nv 10 0 -10\nv 0 0 -10\n\
                    v 20 0 0\nv 20 0 -10\n\
                    v 100 0 0\nv 110 0 0\nv 110 0 -10\nv 100 0 -10\n\
                    f 1 2 3 4\nf 2 5 6 3\nf 7 8 9 10\n";

fn lots_file(dir: &std::path::Path) -> String {
    let p = dir.join("lots.obj");
    std::fs::write(&p, LOTS).unwrap();
    p.to_str().unwrap().to_string()
}

/// Adjacent masses touch each other across lots (a shared face: no
/// overlap); the far one touches nothing. The lower mass's side on the
/// shared wall lies on the taller mass: inside.
#[test]
fn inter_occlusion_between_lots() {
    let dir = temp_dir("context-occlusion");
    let rules = rule_file(
        &dir,
        "o.cga",
        "Lot --> case initialShape.origin.px > 5 && initialShape.origin.px < 50 : extrude(15) Mass\n\
                 else : extrude(10) Mass\n\
         Mass --> print(\"mass \" + touches(inter) + \" \" + overlaps(inter) + \" \" + inside(inter))\n\
                  comp(f) { side : Side | top : X. }\n\
         Side --> case inside(inter) : print(\"side inside \" + scope.sy) NIL\n\
                  else : X.\n",
    );
    let lots = lots_file(&dir);
    let out = run(&["generate", rules.to_str().unwrap(), "--lot", &lots]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(
        stdout(&out),
        "mass true false false\nside inside 10\nmass true false false\nmass false false false\n"
    );
}

/// `contextCount(inter, ..)` counts the labels of every other lot of the
/// run, `intra` the lot's own; the same output on 1, 2 and 3 threads.
#[test]
fn inter_count_on_a_grid_whatever_the_jobs() {
    let dir = temp_dir("context-count");
    let rules = rule_file(
        &dir,
        "c.cga",
        "Lot --> label(\"lot\") split(x) { ~5 : label(\"part\") Part }*\n\
         Part --> print(contextCount(inter, \"lot\") + \" \" + contextCount(intra, \"part\") + \" \" + contextCount(all, \"part\") + \" \" + contextCompare(all, \"part\", world.easternmost))\n\
                  extrude(1) X.\n",
    );
    let mut seen = Vec::new();
    for jobs in ["1", "2", "3"] {
        // The same file name each time: the OBJ names its material file.
        let sub = dir.join(format!("jobs{jobs}"));
        std::fs::create_dir_all(&sub).unwrap();
        let obj = sub.join("model.obj");
        let out = run(&[
            "generate",
            rules.to_str().unwrap(),
            "--lot",
            "grid:3x2",
            "--jobs",
            jobs,
            "-o",
            obj.to_str().unwrap(),
        ]);
        assert!(out.status.success(), "{}", stderr(&out));
        seen.push((stdout(&out), std::fs::read_to_string(&obj).unwrap()));
    }
    let (prints, model) = &seen[0];
    // 6 lots of 20 x 30 in 2 rows of 3, 30 m apart in x, each split into
    // 4 parts: parts with the same east edge (one per row) share a rank, so
    // the first lot's first part (east edge x = 5) has 22 parts east of it,
    // its last (x = 20) the 16 of the other columns, and the last column's
    // last parts rank 0.
    let lines: Vec<&str> = prints.lines().collect();
    assert_eq!(lines.len(), 24);
    assert_eq!(lines[0], "5 4 24 22");
    assert_eq!(lines[3], "5 4 24 16");
    assert_eq!(lines[11], "5 4 24 0");
    assert_eq!(lines[23], "5 4 24 0");
    assert!(model.lines().filter(|l| l.starts_with("f ")).count() >= 24 * 6);
    for (p, m) in &seen[1..] {
        assert_eq!(p, prints);
        assert!(m == model, "the model depends on the number of threads");
    }
}
