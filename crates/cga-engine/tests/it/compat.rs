//! Rule files as people have them, from every CityEngine version: source
//! encodings, workspace paths, the parser's tolerance for annotations,
//! rules of older CGA versions, deprecated forms the reference still
//! documents, the utility library's pickers, NaN arguments, and what
//! `check` reports before deriving. Every rule file here is our own.

use std::path::{Path, PathBuf};

use crate::ops_common::*;
use cga_engine::{load, load_with, LoadOptions, Workspaces};
use cga_syntax::{Diagnostic, SourceMap};
use cga_world::DiskWorld;

/// A fresh folder for one test.
fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cga-compat-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn write(path: &Path, bytes: &[u8]) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, bytes).unwrap();
}

/// Loads `src` as a rule file and returns its diagnostics (`ok`: whether it
/// loaded).
fn diagnostics(src: &str) -> (bool, Vec<Diagnostic>) {
    let dir = temp_dir(&format!("diag-{:x}", fxhash(src)));
    let path = dir.join("rules.cga");
    write(&path, src.as_bytes());
    let mut sources = SourceMap::new();
    let loaded = load(&DiskWorld, &path, &mut sources);
    (!loaded.has_errors(), loaded.diagnostics)
}

fn fxhash(s: &str) -> u64 {
    s.bytes().fold(0xcbf29ce484222325u64, |h, b| {
        (h ^ b as u64).wrapping_mul(0x100000001b3)
    })
}

fn messages(diags: &[Diagnostic]) -> Vec<String> {
    diags.iter().map(|d| d.message.clone()).collect()
}

// ----- encodings -----

#[test]
fn windows_1252_and_bom_rule_files_load_with_their_text() {
    let dir = temp_dir("encodings");
    // "Höhe 20°" in Windows-1252, in a comment and a string; the import
    // is Windows-1252 too, the main file starts with a UTF-8 byte order mark.
    write(
        &dir.join("lib.cga"),
        b"# Geb\xe4ude\nattr label = \"H\xf6he 20\xb0\"\nL --> print(label)\n",
    );
    write(
        &dir.join("main.cga"),
        "\u{feff}// Straße\nimport lib : \"lib.cga\"\nLot --> print(\"Grüße\") lib.L\n".as_bytes(),
    );
    let g = gen_file(&dir.join("main.cga"), &Opts::default()).ok();
    assert_eq!(g.prints(), ["Grüße", "Höhe 20°"]);
}

// ----- workspaces -----

/// A CityEngine workspace: the project `Lib` beside the project `Proj`.
fn workspace(name: &str) -> PathBuf {
    let ws = temp_dir(name);
    write(
        &ws.join("Lib/rules/lib.cga"),
        b"Tall --> s(0,0,0) i(\"/Lib/assets/box.obj\") Box.\n",
    );
    // A 2 x 3 x 4 box.
    write(
        &ws.join("Lib/assets/box.obj"),
        b"v 0 0 0\nv 2 0 0\nv 2 0 4\nv 0 0 4\nv 0 3 0\nv 2 3 0\nv 2 3 4\nv 0 3 4\n\
f 1 2 3 4\nf 5 8 7 6\nf 1 5 6 2\nf 2 6 7 3\nf 3 7 8 4\nf 4 8 5 1\n",
    );
    write(
        &ws.join("Proj/rules/main.cga"),
        b"import lib : \"/Lib/rules/lib.cga\"\nLot --> lib.Tall\n",
    );
    ws
}

#[test]
fn workspace_paths_resolve_beside_the_rule_files_project() {
    let ws = workspace("ws-ancestor");
    let g = gen_file(&ws.join("Proj/rules/main.cga"), &Opts::default()).ok();
    // The asset `/Lib/assets/box.obj` went in with its own size (zero scope).
    let (lo, hi) = g.bounds();
    assert_vec_near(hi - lo, [2.0, 3.0, 4.0], 1e-9);
}

#[test]
fn workspace_paths_resolve_in_the_workspace_roots_and_name_every_place_searched() {
    let ws = workspace("ws-roots");
    // The rule file alone, far from the workspace.
    let other = temp_dir("ws-roots-elsewhere");
    let main = other.join("rules/main.cga");
    write(
        &main,
        &std::fs::read(ws.join("Proj/rules/main.cga")).unwrap(),
    );

    let mut sources = SourceMap::new();
    let loaded = load(&DiskWorld, &main, &mut sources);
    assert!(loaded.has_errors());
    let d = &loaded.diagnostics[0];
    assert_eq!(
        d.message,
        "cannot find the imported rule file \"/Lib/rules/lib.cga\""
    );
    let note = d.notes.join("\n");
    // Every ancestor of the rule file was searched, nearest first.
    let canonical = other.canonicalize().unwrap();
    let here = canonical.join("rules/Lib/rules/lib.cga");
    let project = canonical.join("Lib/rules/lib.cga");
    let at = |p: &Path| note.find(&p.display().to_string()).unwrap_or(usize::MAX);
    assert!(
        at(&here) < at(&project) && at(&project) < note.len(),
        "{note}"
    );

    let mut sources = SourceMap::new();
    let options = LoadOptions {
        workspaces: Workspaces::new(vec![ws.clone()]),
        ..LoadOptions::default()
    };
    let loaded = load_with(&DiskWorld, &main, &mut sources, &options);
    assert!(!loaded.has_errors(), "{:?}", messages(&loaded.diagnostics));
    assert!(loaded.diagnostics.is_empty());
}

#[test]
fn workspace_search_order_is_a_pure_function_of_its_inputs() {
    use cga_engine::locate::candidates;
    let roots = Workspaces::new(vec![PathBuf::from("/ws2")]);
    let c = candidates(Path::new("/a/P/rules/x.cga"), "/Lib/y.obj", &roots);
    assert_eq!(c.first().unwrap(), Path::new("/Lib/y.obj"));
    assert_eq!(c[1], Path::new("/a/P/rules/Lib/y.obj"));
    assert_eq!(c.last().unwrap(), Path::new("/ws2/Lib/y.obj"));
    assert!(c.contains(&PathBuf::from("/a/Lib/y.obj")));
}

// ----- parser -----

#[test]
fn annotations_the_engine_does_not_understand_are_kept() {
    let src = r#"version "2014.0"
@Handle(shape=Mass^1, axis=y, translate={.1,0,0}, slip=screen)
@Enum("Off", "Transit Highlight","
 Highlight","Solid")
@Range(min=0, max=10)
attr h = 10
@Description("Night")
style Night
attr h = 3
"#;
    let dir = temp_dir("annotations");
    let path = dir.join("rules.cga");
    write(&path, src.as_bytes());
    let mut sources = SourceMap::new();
    let loaded = load(&DiskWorld, &path, &mut sources);
    assert!(
        loaded.diagnostics.is_empty(),
        "{:?}",
        messages(&loaded.diagnostics)
    );
    let program = loaded.program;
    let attr = &program.attrs[program.main_attr("h").unwrap() as usize];
    let names: Vec<&str> = attr.annotations.iter().map(|a| a.name.as_str()).collect();
    assert_eq!(names, ["Handle", "Enum", "Range"]);
    let handle: Vec<(Option<&str>, String)> = attr.annotations[0]
        .args
        .iter()
        .map(|(k, v)| {
            (
                k.as_deref(),
                v.as_ref().map(cga_value::to_text).unwrap_or_default(),
            )
        })
        .collect();
    assert_eq!(
        handle,
        [
            (Some("shape"), "Mass^1".to_string()),
            (Some("axis"), String::new()),
            (Some("translate"), "{.1,0,0}".to_string()),
            (Some("slip"), String::new()),
        ]
    );
    // The string broken over a line keeps its line break.
    let values: Vec<String> = attr.annotations[1]
        .args
        .iter()
        .map(|(_, v)| cga_value::to_text(v.as_ref().unwrap()))
        .collect();
    assert_eq!(
        values,
        ["Off", "Transit Highlight", "\n Highlight", "Solid"]
    );
}

#[test]
fn an_annotated_style_runs_as_without_the_annotation() {
    let with = gen(
        "Lot --> extrude(5)\n@Description(\"A Variation in Red\")\nstyle Red\nLot --> extrude(9)\n",
    )
    .ok();
    let without = gen("Lot --> extrude(5)\nstyle Red\nLot --> extrude(9)\n").ok();
    assert_near(with.volume(), 3000.0, 1e-9);
    assert_near(without.volume(), with.volume(), 1e-12);
}

#[test]
fn nil_with_a_dot_is_a_leaf_named_nil() {
    let g = gen("Lot --> split(x){ 5 : NIL | ~1 : NIL. }").ok();
    assert_eq!(g.meshes().len(), 1);
    assert_near(g.area(), 450.0, 1e-9);
    let (lo, hi) = g.bounds();
    assert_near(lo.x, 5.0, 1e-9);
    assert_near(hi.x, 20.0, 1e-9);
}

#[test]
fn unicode_escapes_and_the_is_null_page() {
    let g = gen(r#"Lot -->
    print(len("\ue000"))
    print(isNull("CityEngine"))
    print(isNull("\ue000"))
    print(isNull(ln(-1)))
    print(isNull(["CityEngine", "\ue000"]))
    print("\u00e4\u0041")
"#)
    .ok();
    assert_eq!(
        g.prints(),
        ["1", "false", "true", "true", "(2)[false,true]", "äA"]
    );
}

// ----- older CGA versions -----

#[test]
fn attributes_with_parameters_before_2019_1() {
    // No version: 2009.1 (version.md).
    for header in ["", "version \"2014.1\"\n"] {
        let g = gen(&format!(
            "{header}attr P(idx) = idx * 2\nLot --> print(P(3)) extrude(P(4))\n"
        ))
        .ok();
        assert_eq!(g.prints(), ["6"]);
        assert_near(g.volume(), 4800.0, 1e-9);
    }
    let (ok, diags) = diagnostics("version \"2019.1\"\nattr P(idx) = 0\nLot --> X.\n");
    assert!(!ok);
    assert!(messages(&diags)[0].contains("only before version 2019.1"));
    // streetWidth(i) is still an attribute with a parameter.
    let (ok, _) =
        diagnostics("version \"2023.0\"\nattr streetWidth(i) = 8\nLot --> print(streetWidth(0))\n");
    assert!(ok);
}

#[test]
fn a_rule_called_with_parameters_it_lacks_is_a_warning_and_a_leaf() {
    let src = "Lot --> extrude(10) Mass(3)\nMass --> split(y) { 1 : X. }\n";
    let (ok, diags) = diagnostics(src);
    assert!(ok);
    assert_eq!(diags.len(), 1);
    assert!(!diags[0].is_error());
    assert!(diags[0]
        .message
        .starts_with("rule `Mass` takes 0 parameter(s), called with 1"));
    // The shape is kept as it is: the whole 20 x 10 x 30 volume.
    let g = gen(src).ok();
    assert_eq!(g.meshes().len(), 1);
    assert_near(g.volume(), 6000.0, 1e-9);
}

// ----- non-finite arguments -----

#[test]
fn an_operation_given_nan_is_skipped_with_a_warning() {
    let g = gen(
        "Lot --> extrude(assetInfo(\"missing.obj\", \"sx\") / 0) s(0/0, 1, 1) Mass\nMass --> extrude(4)\n",
    )
    .ok();
    let w = g.warnings();
    assert!(
        w.iter()
            .any(|m| m.starts_with("`extrude` in rule `Lot` skipped: argument 1 is nan")),
        "{w:?}"
    );
    assert!(w.iter().any(|m| m.starts_with("`s` in rule `Lot` skipped")));
    // The derivation went on: Mass extruded the unchanged lot.
    assert_near(g.volume(), 2400.0, 1e-9);
}

// ----- deprecated forms the reference documents -----

#[test]
fn extrude_along_world_axes_the_old_way() {
    for sel in ["world.y", "y"] {
        let g = gen(&format!("Lot --> extrude({sel}, 10)")).ok();
        assert_near(g.volume(), 6000.0, 1e-9);
        let (lo, hi) = g.bounds();
        assert_near(hi.y - lo.y, 10.0, 1e-9);
    }
}

#[test]
fn envelope_without_a_direction_is_along_the_normal() {
    let old = gen("Lot --> envelope(12, 4, 45)").ok();
    let new = gen("Lot --> envelope(normal, 12, 4, 45)").ok();
    assert_near(old.volume(), new.volume(), 1e-9);
    assert!(old.volume() > 2400.0);
}

#[test]
fn offset_uv_is_translate_uv() {
    let src = |op: &str| {
        format!(
            "Lot --> setupProjection(0, scope.xz, 10, 10) projectUV(0) {op}(0, 0.25, 0.5) print(geometry.uMin(0)) print(geometry.vMin(0))"
        )
    };
    let old = gen(&src("offsetUV")).ok();
    let new = gen(&src("translateUV")).ok();
    assert_eq!(old.prints(), new.prints());
    assert_eq!(old.prints()[0], "0.25");
}

#[test]
fn old_scope_selectors() {
    // alignScopeToGeometry(upAxis, auto): on a flat lot every edge is
    // lowest, the longest (30 m) gives x.
    let g = gen("Lot --> alignScopeToGeometry(yUp, auto) print(scope.sx) print(scope.sz)").ok();
    assert_eq!(g.prints(), ["30", "20"]);
    let old = gen("Lot --> extrude(5) setPivot(yUp, 2) print(pivot.px) print(pivot.pz)").ok();
    let new = gen("Lot --> extrude(5) setPivot(xyz, 2) print(pivot.px) print(pivot.pz)").ok();
    assert_eq!(old.prints(), new.prints());
}

#[test]
fn street_side_selectors_without_street_data() {
    let g = gen(
        "Lot --> extrude(10) comp(f) { streetSide : print(\"street\") A. | noStreetSide : print(\"other\") B. }",
    )
    .ok();
    let mut p = g.prints();
    p.sort();
    assert_eq!(p, ["other", "other", "other", "street"]);
}

#[test]
fn deprecated_shape_attributes_still_read() {
    let g = gen(
        "@StartRule\nStart --> print(initialShape.symbol) print(uid == getTreeKey()) set(material.bump, 0.5) print(material.bumpValue) set(material.map4, \"o.png\") print(material.opacitymap)",
    )
    .ok();
    assert_eq!(g.prints(), ["Start", "true", "0.5", "o.png"]);
}

#[test]
fn deprecated_operations_warn_by_name() {
    let (ok, _) = diagnostics("Lot --> roof(30) setupUV(0, scope.xy, 1, 1) bakeUV(0) X.");
    assert!(ok);
    let g = gen("Lot --> roof(30) X.").ok();
    assert_eq!(
        g.warnings(),
        ["operation `roof` was deprecated in CGA 2009.3 and is not run; the shape is left unchanged"]
    );
    assert_near(g.area(), 600.0, 1e-9);
}

// ----- functions of the index -----

#[test]
fn geometry_groups_and_is_instanced() {
    let g = gen(
        "Lot --> i(\"builtin:cube\") print(geometry.isInstanced()) t(1, 0, 0) print(geometry.isInstanced()) split(x) { ~1 : print(geometry.isInstanced()) X. }",
    )
    .ok();
    assert_eq!(g.prints(), ["true", "true", "false"]);
    let dir = temp_dir("groups");
    write(
        &dir.join("two.obj"),
        b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\ng left\nf 1 2 3 4\ng right\nf 2 5 6 3\n",
    );
    write(
        &dir.join("rules.cga"),
        b"Lot --> i(\"two.obj\") print(geometry.groups()) comp(g) { all : print(comp.index) X. }\n",
    );
    let g = gen_file(&dir.join("rules.cga"), &Opts::default()).ok();
    assert_eq!(g.prints(), ["(2)[left,right]", "0", "1"]);
}

#[test]
fn list_random_draws_an_item() {
    let g = gen("Lot --> print(listRandom(\"rule;your;city;\")) print(listRandom(\"\"))").ok();
    let p = g.prints();
    assert!(["rule", "your", "city"].contains(&p[0].as_str()), "{p:?}");
    assert_eq!(p[1], "");
    // Every item comes up over seeds.
    let src = "Lot --> print(listRandom(\"a;b;c;\"))";
    let seen: std::collections::BTreeSet<String> =
        gen_seeds(src, &Opts::default(), &(0..40).collect::<Vec<_>>())
            .iter()
            .flat_map(|g| g.prints())
            .collect();
    assert_eq!(seen.into_iter().collect::<Vec<_>>(), ["a", "b", "c"]);
}

/// An OBJ box of the given size.
fn box_obj(x: f64, y: f64, z: f64) -> Vec<u8> {
    format!(
        "v 0 0 0\nv {x} 0 0\nv {x} 0 {z}\nv 0 0 {z}\nv 0 {y} 0\nv {x} {y} 0\nv {x} {y} {z}\nv 0 {y} {z}\n\
f 1 2 3 4\nf 5 8 7 6\nf 1 5 6 2\nf 2 6 7 3\nf 3 7 8 4\nf 4 8 5 1\n"
    )
    .into_bytes()
}

/// The bytes of a PNG header of the given size (what image size readers look at).
fn png_header(w: u32, h: u32) -> Vec<u8> {
    let mut v = b"\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR".to_vec();
    v.extend_from_slice(&w.to_be_bytes());
    v.extend_from_slice(&h.to_be_bytes());
    v.extend_from_slice(&[8, 2, 0, 0, 0, 0, 0, 0, 0]);
    v
}

#[test]
fn asset_and_image_pickers_follow_their_pages() {
    let dir = temp_dir("pickers");
    // A project: assets of three sizes, textures of three ratios.
    write(&dir.join("assets/box_small.obj"), &box_obj(2.0, 1.0, 3.0));
    write(&dir.join("assets/box_mid.obj"), &box_obj(10.0, 1.0, 15.0));
    write(&dir.join("assets/box_long.obj"), &box_obj(40.0, 1.0, 4.0));
    write(&dir.join("assets/tex_square.png"), &png_header(64, 64));
    write(&dir.join("assets/tex_wide.png"), &png_header(256, 64));
    write(&dir.join("assets/tex_tall.png"), &png_header(60, 90));
    write(
        &dir.join("rules/rules.cga"),
        br#"Lot -->
    print(assetBestSize("box_*.obj", "xz"))
    print(assetBestRatio("box_*.obj", "xz"))
    print(assetApproxSize("box_*.obj", "xz", 1))
    print(assetFitSize("box_*.obj", "xz", 0.1))
    print(imageBestRatio("tex_*.png", "xz"))
    print(imageApproxRatio("tex_*.png", "xz", 1))
    s(30, 0, 3) print(assetBestRatio("box_*.obj", "xz")) print(imageBestRatio("tex_*.png", "xz"))
    print(assetFitSize("box_*.obj", "xz", 0.01))
"#,
    );
    let g = gen_file(&dir.join("rules/rules.cga"), &Opts::default()).ok();
    // The lot's scope is 20 x 30: the 10 x 15 box needs the least scaling
    // (2x) of the three and has the lot's ratio; the 60 x 90 texture too.
    assert_eq!(
        g.prints(),
        [
            "box_mid.obj",
            "box_mid.obj",
            "box_mid.obj",
            "",
            "tex_tall.png",
            "tex_tall.png",
            "box_long.obj",
            "tex_wide.png",
            "",
        ]
    );
}

#[test]
fn every_function_and_operation_of_the_index_resolves() {
    // One call of each name of cgaindex.md that needs no data of its own:
    // none is an unknown name or a wrong arity.
    let src = r##"version "2025.0"
attr a = 1
Lot --> extrude(5)
    print(abs(-1)) print(acos(0.5)) print(asin(0.5)) print(atan(1)) print(atan2(1,1)) print(ceil(1.2))
    print(cos(1)) print(exp(1)) print(floor(1.5)) print(isinf(1)) print(isnan(1)) print(ln(2))
    print(log10(2)) print(pow(2,3)) print(rint(1.5)) print(sin(1)) print(sqrt(2)) print(tan(1))
    print(p(0.5)) print(rand(1,2)) print(bool(1)) print(boolArray([1,0])) print(float("1"))
    print(floatArray(["1"])) print(isNull("x")) print(str(1)) print(stringArray([1,2]))
    print(count("aba","a")) print(find("aba","a",0)) print(len("ab")) print(splitString("a;b",";"))
    print(substring("abc",0,1)) print(geometry.area) print(geometry.angle(maxSlope))
    print(geometry.boundaryLength) print(geometry.du(0, unitSpace)) print(geometry.groups())
    print(geometry.hasTags()) print(geometry.hasUVs(0)) print(geometry.height)
    print(geometry.isClosedSurface) print(geometry.isConcave) print(geometry.isInstanced())
    print(geometry.isOriented(world.up)) print(geometry.isPlanar(0.1)) print(geometry.isRectangular(1))
    print(geometry.materials()) print(geometry.nEdges) print(geometry.nFaces) print(geometry.nHoles)
    print(geometry.nVertices) print(geometry.tags()) print(geometry.uMin(0)) print(geometry.volume)
    print(fileExists("x")) print(fileSearch("*.none")) print(filesSearch("*.none"))
    print(assetsSortRatio("", xy)) print(assetsSortSize("", x, 0.1)) print(imagesSortRatio("", xy))
    print(inside()) print(minimumDistance(inter, "a")) print(contextCompare(inter, "a", area.largest))
    print(contextCount(inter, "a")) print(comp(f) { top : 1 | all : 2 }) print(findFirst([1,2], 2, 0))
    print(nColumns([1,2])) print(nRows([1,2])) print(setElems([1,2], 0, 5)) print(size([1,2]))
    print(sortIndices([2,1])) print(sortRowIndices([2,1;1,2])) print(sum([1,2])) print(transpose([1,2]))
    print(edgeAttr.getFloat("a")) print(convert(x, scope, world, pos, 0, 0, 0)) print(getGeoCoord(X))
    print(getTreeKey()) print(findFirst("abc", "b")) print(findLast("abcb", "b")) print(getPrefix("ab", "b"))
    print(getRange("abc", "a", "c")) print(getSuffix("ab", "a")) print(replace("ab", "a", "c"))
    print(listAdd("a;", "b")) print(listClean("a;;b;")) print(listCount("a;b;", "a")) print(listFirst("a;b;"))
    print(listFromArray(["a","b"])) print(listIndex("a;b;", "b")) print(listItem("a;b;", 1))
    print(listLast("a;b;")) print(listRandom("a;b;")) print(listRange("a;b;c;", 0, 1))
    print(listRemove("a;b;", "a")) print(listRemoveAll("a;b;", "a")) print(listRetainAll("a;b;", "a"))
    print(listSize("a;b;")) print(listTerminate("a;b")) print(listToArray("a;b;"))
    print(assetApproxRatio("*.none", xy, 3)) print(assetApproxSize("*.none", x, 3))
    print(assetBestRatio("*.none", xy)) print(assetBestSize("*.none", x)) print(assetFitSize("*.none", x, 0.1))
    print(fileBasename("a/b.obj")) print(fileDirectory("a/b.obj")) print(fileExtension("a/b.obj"))
    print(fileName("a/b.obj")) print(fileRandom("*.none")) print(imageApproxRatio("*.none", xy, 3))
    print(imageBestRatio("*.none", xy)) print(clamp(1,0,2)) print(max(1,2)) print(min(1,2))
    print(colorHexToB("#ff0000")) print(colorHexToH("#ff0000")) print(colorHexToO("#ff0000"))
    print(colorHSVToHex(1,1,1)) print(colorHSVOToHex(1,1,1,1)) print(colorRamp("spectrum", 0.5))
    print(colorRGBToHex(1,1,1)) print(colorRGBOToHex(1,1,1,1)) print(comp.sel) print(initialShape.name)
    print(initialShape.origin.px) print(material.color.rgb) print(pivot.px) print(scope.elevation)
    print(seedian) print(split.index) print(trim.horizontal)
    A
A --> i("builtin:cube", yUp, keepSizeAndPosition, noCleanup) taper(3) B
B --> roofGable(byHeight, 3, 1, 1, true) roofHip(30) roofPyramid(30) roofRidge(byAngle, 30) roofShed(30, 1)
    offset(-1, inside) primitiveQuad(1,2) primitiveDisk(8, 1) primitiveCube(1,1,1) primitiveSphere(8, 8, 1)
    primitiveCylinder(8, 1, 1) primitiveCone(8, 1, 1) footprint() cleanupGeometry(all, 0.1) convexify(2)
    deleteHoles() reverseNormals() setNormals(hard) softenNormals(30) mirror(true, false, false) rectify(5)
    reduceGeometry(0.1) resetGeometry() trim() tag("a", faces) deleteTags("a", edges) setTagsFromEdgeAttrs()
    texture("") setupProjection(0, scope.xy, 1, 1, 0, 0, 1) projectUV(0) translateUV(0, 1, 1) scaleUV(0, 1, 1)
    normalizeUV(0, uv, separatePerFace) tileUV(0, 1, 1) rotateUV(0, 30) deleteUV(0) copyUV(0, 1) t(1,1,1)
    translate(rel, world, 1, 1, 1) s(1,1,1) r(scopeCenter, 1, 1, 1) rotate(rel, world, 1, 1, 1) center(xz)
    alignScopeToAxes(y) alignScopeToGeometry(yUp, any, longest) alignScopeToGeometryBBox(xz) rotateScope(0, 1, 0)
    setPivot(xyz, 0) mirrorScope(true, false, false) label("a") set(a, 2) color(1, 0, 0, 1) resetMaterial(geometry)
    setMaterial(getMaterial(shape, all)) report("a", 1) print(1) insertAlongUV(0, "builtin:cube", 1, scope.y, alignPosition)
    modify(f) { top : C } C
C --> split(x, noAdjust) { 1 : D }* splitArea(x) { 1 : D } comp(f, noAlign) { top : D }
    innerRectangle(edge) { shape : D | remainder : D } setback(1, 0) { front : D | remainder : D }
    setbackPerEdge(1) { all : D } setbackToArea(10, [1], [2], 0) { all : D } shapeL(2, 2) { shape : D }
    shapeU(2, 2, 2) { shape : D } shapeO(2, 2, 2, 2) { shape : D } scatter(surface, 10, uniform) { D }
    splitAndSetbackPerimeter(0, 0, [true]) { 5 : 2 : D } { remainder : D } inline(unify) split(x) { 1 : D }
    union { D | D } subtract { D | D } intersect { D | D } envelope(normal, 10, [5,5,5,5], [45,45,45,45]) [ D ] NIL
D --> X.
"##;
    let (ok, diags) = diagnostics(src);
    let errors: Vec<String> = diags
        .iter()
        .filter(|d| d.is_error())
        .map(|d| d.message.clone())
        .collect();
    assert!(ok && errors.is_empty(), "{errors:?}");
}

// ----- what check reports -----

#[test]
fn check_reports_type_mismatches_and_likely_misspelt_rules() {
    let (ok, diags) = diagnostics(
        "attr floors = 6\nLot --> case floors == \"six\" : Facde else : Facade\nFacade --> X.\n",
    );
    assert!(!ok);
    let m = messages(&diags);
    assert_eq!(
        m[0],
        "type mismatch: operator == cannot be applied to float and string"
    );
    assert_eq!(
        m[1],
        "rule `Facde` is not defined; the shape becomes a leaf"
    );
    assert_eq!(diags[1].notes, ["help: did you mean `Facade`?"]);
    assert!(!diags[1].is_error());
    // A leaf name far from every rule is no warning (terminal shapes).
    let (ok, diags) = diagnostics("Lot --> Window\nFacade --> X.\n");
    assert!(ok && diags.is_empty());
}

#[test]
fn wrong_arity_and_array_messages_name_the_function_once() {
    let (_, diags) =
        diagnostics("f(a, b) = a + b\nLot --> print(f(1)) print(rand(1,2,3)) print(abs(1,2))\n");
    assert_eq!(
        messages(&diags),
        [
            "`f` takes 2 arguments, found 1",
            "`rand` takes 0 to 2 arguments, found 3",
            "`abs` takes 1 arguments, found 2",
        ]
    );
    let g = gen("Lot --> print(size(1))");
    assert_eq!(
        g.errors[0].message,
        "size: argument 1 must be an array, not float"
    );
}

#[test]
fn quarter_turns_leave_no_rounding_noise() {
    let g = gen("Lot --> extrude(10) r(0,90,0) comp(f) { side : print(pivot.px) X. }").ok();
    for p in g.prints() {
        assert!(!p.contains('e'), "{p}");
    }
}

#[test]
fn boolean_operations_in_their_syntax_before_2025() {
    let cutter = "B --> s(5, 20, 5) primitiveCube()\n";
    let vol = |body: &str| {
        gen(&format!("Lot --> extrude(10) {body}\n{cutter}"))
            .ok()
            .volume()
    };
    let old = vol("subtract B");
    assert_near(old, 6000.0 - 5.0 * 10.0 * 5.0, 1e-6);
    assert_near(old, vol("subtract { A. | B }"), 1e-9);
    // swap: the rule's shape minus the current one.
    assert_near(vol("subtract(swap) B"), 5.0 * 10.0 * 5.0, 1e-6);
    assert_near(vol("intersect B"), 5.0 * 10.0 * 5.0, 1e-6);
}
