//! The rule files shipped with CityEngine's runtime packages (the oracle's
//! `rules/` directory, including the ESRI.lib rules under `.ws/`) are real
//! CGA written for CityEngine: every one must parse without a diagnostic.

use std::path::{Path, PathBuf};

use cga_syntax::ast::*;
use cga_syntax::{parse, sexpr, FileId, SourceMap};

/// The oracle's `rules/` folder (`../shared/prt-oracle/rules`, outside the
/// repository), or `None` when it is absent.
fn oracle_rules() -> Option<PathBuf> {
    cga_testkit::shared("prt-oracle/rules")
}

fn cga_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let entries = std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    for entry in entries {
        let path = entry.unwrap().path();
        if path.is_dir() {
            cga_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "cga") {
            out.push(path);
        }
    }
}

fn parse_file(path: &Path) -> Module {
    let text = std::fs::read_to_string(path).unwrap();
    let (module, diagnostics) = parse(FileId(0), &text);
    if !diagnostics.is_empty() {
        let mut sources = SourceMap::new();
        sources.add(path, text);
        let rendered: String = diagnostics.iter().map(|d| d.render(&sources)).collect();
        panic!("{} has diagnostics:\n{rendered}", path.display());
    }
    module
}

fn rule<'m>(module: &'m Module, name: &str) -> &'m RuleDecl {
    module
        .items
        .iter()
        .find_map(|item| match item {
            Item::Rule(r) if r.name.name == name => Some(r),
            _ => None,
        })
        .unwrap_or_else(|| panic!("no rule {name}"))
}

fn rule_text(module: &Module, name: &str) -> String {
    let item = module
        .items
        .iter()
        .find(|item| matches!(item, Item::Rule(r) if r.name.name == name))
        .unwrap_or_else(|| panic!("no rule {name}"));
    sexpr::item(item)
}

fn item_text(module: &Module, needle: &str) -> String {
    module
        .items
        .iter()
        .map(sexpr::item)
        .find(|s| s.contains(needle))
        .unwrap_or_else(|| panic!("no item containing {needle}"))
}

#[test]
fn every_oracle_rule_file_parses_without_diagnostics() {
    let Some(rules) = oracle_rules() else { return };
    let mut files = Vec::new();
    cga_files(&rules, &mut files);
    files.sort();
    let names: Vec<String> = files
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    // The packages' rule files, the envelope's imports and ESRI.lib's plant rules.
    for expected in [
        "candler.cga",
        "envelope2002.cga",
        "volume0110.cga",
        "facade.cga",
        "ground_floor_plan.cga",
        "landscape.cga",
        "Plant_Distributor.cga",
        "Plant_Loader.cga",
        "ruleA.cga",
        "ruleB.cga",
        "arrayAttrs2d.cga",
        "extrusion_rule.cga",
    ] {
        assert!(
            names.iter().any(|n| n == expected),
            "{expected} not found in {names:?}"
        );
    }
    assert!(files.len() >= 15, "{names:?}");
    for file in &files {
        let module = parse_file(file);
        assert!(!module.items.is_empty(), "{}", file.display());
    }
}

#[test]
fn candler_structure() {
    let Some(rules) = oracle_rules() else { return };
    let module = parse_file(&rules.join("candler/rules/candler.cga"));
    let count = |f: fn(&Item) -> bool| module.items.iter().filter(|i| f(i)).count();
    assert_eq!(module.items.len(), 76);
    assert_eq!(count(|i| matches!(i, Item::Rule(_))), 57);
    assert_eq!(count(|i| matches!(i, Item::Attr(_))), 14);
    assert_eq!(count(|i| matches!(i, Item::Function(f) if f.is_const)), 4);
    assert!(matches!(&module.items[0], Item::Version { value, .. } if value == "2023.0"));

    // @StartRule on Footprint, and on no other rule.
    let start_rules: Vec<&str> = module
        .items
        .iter()
        .filter_map(|i| match i {
            Item::Rule(r) if r.annotations.iter().any(|a| a.name.name == "StartRule") => {
                Some(r.name.name.as_str())
            }
            _ => None,
        })
        .collect();
    assert_eq!(start_rules, ["Footprint"]);

    // The facade split: four entries, three floating and the 2.5 m top.
    let facade = rule(&module, "Facade");
    assert_eq!(facade.params.len(), 5);
    let Body::Ops(stmts) = &facade.body else {
        panic!()
    };
    assert_eq!(stmts.len(), 5);
    let Stmt::Call(split) = &stmts[4] else {
        panic!()
    };
    assert_eq!(split.name.name, "split");
    let block = split.block.as_ref().unwrap();
    assert!(!block.repeat);
    let heads: Vec<String> = block
        .parts
        .iter()
        .map(|p| match p {
            BlockPart::Entry(e) => sexpr::expr(&e.head),
            _ => panic!("not an entry"),
        })
        .collect();
    assert_eq!(heads, ["(~ 2.3)", "(~ 12)", "(~ 3)", "2.5"]);

    // Nested repeat group and floating heads with an expression.
    assert_eq!(
        rule_text(&module, "Windows"),
        "(rule Windows(n) (split x {{(~ (/ scope.sx n)) : Window | dividerW : Wall}* | (~ (/ scope.sx n)) : Window}))"
    );
    // `'1.85*8` is relative of the whole product; `RoofDoor.` is a leaf.
    assert_eq!(
        rule_text(&module, "RoofDoor"),
        "(rule RoofDoor (WindowOpening 0.15) (t 0 0 (neg 0.15)) (tileUV 0 (' (* 1.85 8)) (' 1.1)) \
         (texture \"facade/misc/groundFloorTiles_2048x256.jpg\") RoofDoor.)"
    );
    // A case chain as a constant's value.
    assert_eq!(
        item_text(&module, "(const sillH"),
        "(const sillH (case ((> FloorHeight (+ WindowHeight SillSize)) (* (- FloorHeight WindowHeight) 0.66)) (else SillSize)))"
    );
    // Comp with `=` and a nested comp inside a push inside an entry body.
    assert_eq!(
        rule_text(&module, "WindowOpening"),
        "(rule WindowOpening(depth) (extrude (neg depth)) (comp f {front : reverseNormals SillTexture | side = WallOpening}))"
    );
    assert_eq!(
        rule_text(&module, "Roof"),
        "(rule Roof (offset (neg 0.8)) (comp f {border : (WallWithoutUVs 5) | inside : [(extrude (neg 0.3)) \
         (comp f {side : reverseNormals (WallWithoutUVs 5)})] (t 0 0 (neg 0.3)) RoofPlane}))"
    );
    // Case chains with dotted shape attributes and function calls as conditions.
    assert_eq!(
        rule_text(&module, "RoofPlaneParts"),
        "(rule RoofPlaneParts (case ((> geometry.area 200) RoofPlanePartLarge) \
         ((call geometry.isRectangular 1) RoofPlanePartRectangular) (else RoofPlanePartOther)))"
    );
    // Two rules named Pipe, overloaded by parameter count.
    let pipes = module
        .items
        .iter()
        .filter(|i| matches!(i, Item::Rule(r) if r.name.name == "Pipe"))
        .count();
    assert_eq!(pipes, 2);
}

#[test]
fn envelope_and_imports_structure() {
    let Some(rules) = oracle_rules() else { return };
    let dir = rules.join("envelope2002/rules/typology");
    let module = parse_file(&dir.join("envelope2002.cga"));
    let imports: Vec<(String, String)> = module
        .items
        .iter()
        .filter_map(|i| match i {
            Item::Import(imp) => Some((imp.alias.as_ref().unwrap().name.clone(), imp.path.clone())),
            _ => None,
        })
        .collect();
    assert_eq!(
        imports,
        [
            ("volume", "volume0110.cga"),
            ("facade", "facade.cga"),
            ("ground_floor_plan", "ground_floor_plan.cga"),
            ("landscape_rule", "landscape.cga"),
            (
                "plant_distributor",
                "/ESRI.lib/rules/Plants/Plant_Distributor.cga"
            ),
            ("plant_loader", "/ESRI.lib/rules/Plants/Plant_Loader.cga"),
        ]
        .map(|(a, b)| (a.to_string(), b.to_string()))
    );
    // Rules that redefine rules of imported files have dotted names.
    assert_eq!(rule(&module, "volume.Glazing").params.len(), 1);
    // A case chain whose else branch is a stochastic chain.
    assert_eq!(
        item_text(&module, "slab_material"),
        "(attr @Order(6) slab_material (case ((== type_of_wall_on_glazing_facade \"vertical\") \"plaster\") \
         (else (stoch (80 \"concrete\") (else \"plaster\")))))"
    );
    // A stochastic chain inline as an operation argument.
    assert!(rule_text(&module, "Big_plant_position")
        .contains("(set plant_loader.Name (stoch (25 \"Sassafras\") (25 \"Apricot\") (else \"Common Hawthorn\")))"));
    // Stochastic rule body with fractional percentages.
    assert!(rule_text(&module, "Green_tile").starts_with("(rule Green_tile (stoch (0.3 "));
    // The comp function as an argument, and a block on the line after the call.
    assert_eq!(
        rule_text(&module, "First_volume_top"),
        "(rule First_volume_top (setback (compfn (fe) {all : first_setback_size}) \
         {all : Remaining_around_first_setback | remainder : To_be_developped_further}))"
    );

    let loader = parse_file(&rules.join("envelope2002/.ws/ESRI.lib/rules/Plants/Plant_Loader.cga"));
    // Ranges with a negative step inside a 2D index, and a case chain as an argument.
    assert_eq!(
        item_text(&loader, "(const nModels"),
        "(const nModels (- nPlants (call findFirst (index _metadata (range nPlants (neg 1) 1) 4) \"\")))"
    );
    assert!(item_text(&loader, "(fn isPlantInLibrary(genus, species)")
        .contains("(case ((== species \"\") genus) (else (+ (+ genus \" \") species)))"));
}

#[test]
fn dynamic_imports_and_arrays() {
    let Some(dir) = oracle_rules() else { return };
    let rule_a = parse_file(&dir.join("dynamic_imports/rules/prt3_dynamic_imports/ruleA.cga"));
    assert_eq!(
        sexpr::module(&rule_a),
        "(version \"2023.0\")\n\
         (import ruleB \"rules/prt3_dynamic_imports/ruleB.cga\" (h = 10))\n\
         (rule @StartRule Init ruleB.foo)\n"
    );
    let arrays = parse_file(&dir.join("arrayAttrs2d/rules/arrayAttrs2d.cga"));
    assert_eq!(
        item_text(&arrays, "arrayAttrFloat"),
        "(attr arrayAttrFloat [1 2 3; 4 5 6])"
    );
    let identity = parse_file(&dir.join("identity/rules/identity.cga"));
    // `X.` at the very end of a file without a final newline.
    assert_eq!(sexpr::item(&identity.items[1]), "(rule @StartRule Init X.)");
}
