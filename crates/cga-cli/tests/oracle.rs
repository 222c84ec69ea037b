//! Conformance: the rule packages of `tests/oracle/` generate what
//! CityEngine's runtime generated for them (golden prints, reports and model
//! summaries; see `tests/oracle/README.md` for their origin).

mod common;

use std::path::PathBuf;

use common::*;

fn oracle() -> PathBuf {
    manifest_dir().join("tests/oracle")
}

struct Case {
    package: &'static str,
    rule: &'static str,
    golden: &'static str,
    args: Vec<String>,
    /// Round our coordinates to this many decimals before measuring, as
    /// CityEngine's OBJ writer rounded those the golden was measured from.
    round: Option<i32>,
}

/// Runs one package and compares prints, reports and the model summary.
fn check(case: &Case) {
    let dir = temp_dir(case.golden);
    let obj = dir.join("model.obj");
    let report = dir.join("report.json");
    let rule = oracle().join(case.package).join(case.rule);
    let mut args: Vec<String> = vec![
        "generate".into(),
        rule.display().to_string(),
        "-o".into(),
        obj.display().to_string(),
        "--report".into(),
        report.display().to_string(),
    ];
    args.extend(case.args.iter().cloned());
    let out = cga().args(&args).output().unwrap();
    assert!(out.status.success(), "{}: {}", case.package, stderr(&out));
    let golden = oracle().join("golden").join(case.golden);

    let prints = std::fs::read_to_string(golden.join("prints.txt")).unwrap();
    assert_eq!(
        stdout(&out).trim_end(),
        prints.trim_end(),
        "prints of {}",
        case.package
    );

    let ours: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let expected: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(golden.join("reports.json")).unwrap())
            .unwrap();
    assert_eq!(ours, expected, "reports of {}", case.package);

    let diffs = compare(
        &golden_summary(&golden.join("summary.json")),
        &summarize_rounded(&obj, case.round),
        1e-3,
    );
    assert!(
        diffs.is_empty(),
        "model of {} differs: {diffs:#?}",
        case.package
    );
}

#[test]
fn identity() {
    check(&Case {
        package: "identity",
        rule: "rules/identity.cga",
        golden: "identity.rect20x30",
        args: Vec::new(),
        round: None,
    });
}

#[test]
fn faces_holes_vertices() {
    check(&Case {
        package: "FacesHolesVerticesrule",
        rule: "rules/FacesHolesVerticesrule.cga",
        golden: "FacesHolesVerticesrule.rect20x30",
        args: Vec::new(),
        round: None,
    });
}

#[test]
fn array_attributes() {
    check(&Case {
        package: "arrayAttrs",
        rule: "rules/arrayAttrs.cga",
        golden: "arrayAttrs.rect20x30",
        args: Vec::new(),
        round: None,
    });
}

#[test]
fn array_attributes_2d() {
    check(&Case {
        package: "arrayAttrs2d",
        rule: "rules/arrayAttrs2d.cga",
        golden: "arrayAttrs2d.rect20x30",
        args: Vec::new(),
        round: None,
    });
}

#[test]
fn dynamic_imports() {
    check(&Case {
        package: "dynamic_imports",
        rule: "rules/prt3_dynamic_imports/ruleA.cga",
        golden: "dynamic_imports.rect20x30",
        args: Vec::new(),
        round: None,
    });
}

#[test]
fn extrusion_rule_with_pinned_height() {
    // The rule draws its height with rand(min, max); pinning both to 23
    // makes the result independent of the random generator.
    check(&Case {
        package: "extrusion_rule",
        rule: "rules/extrusion_rule.cga",
        golden: "extrusion_rule.rect20x30.h23",
        args: [
            "--attr",
            "minBuildingHeight=23",
            "--attr",
            "maxBuildingHeight=23",
        ]
        .map(String::from)
        .to_vec(),
        round: None,
    });
}

/// The Candler building: a 12 kB real building rule (split, comp, offset,
/// envelope, convexify, i, texturing, trim planes) gives CityEngine's model:
/// bounding box, total area and the area of each of its ten appearances
/// (textures and colours) within 1e-3, on a rectangle and on its footprint.
/// Its random choices only pick texture tiles, which the summary does not
/// see.
#[test]
fn candler_on_a_rectangle() {
    check(&Case {
        package: "candler",
        rule: "rules/candler.cga",
        golden: "candler.rect20x30",
        args: vec!["--lot".into(), "rect:20,30".into()],
        round: Some(3),
    });
}

#[test]
fn candler_on_its_footprint() {
    let lot = oracle().join("lots/candler_footprint.obj");
    let args = vec!["--lot".into(), lot.to_str().unwrap().into()];
    check(&Case {
        package: "candler",
        rule: "rules/candler.cga",
        golden: "candler.candler_footprint",
        args,
        round: Some(3),
    });
}

/// Every rule file of the packages parses and resolves without errors.
#[test]
fn every_package_rule_file_checks() {
    let mut files = Vec::new();
    let mut stack = vec![oracle()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "cga") {
                files.push(p);
            }
        }
    }
    assert!(files.len() >= 14, "found {} rule files", files.len());
    for f in files {
        let out = run(&["check", f.to_str().unwrap()]);
        assert!(
            out.status.success(),
            "{} does not check: {}",
            f.display(),
            stderr(&out)
        );
    }
}
