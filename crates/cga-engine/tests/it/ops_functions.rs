//! Shape functions that read the geometry's orientation and the lot's
//! place: `geometry.angle`, `getGeoCoord`, `edgeAttr.*`.

use crate::ops_common::*;
use cga_engine::lot::Lot;

/// func_geometry, geometry.angle: on a gable roof of 30 degrees over
/// `rect:20,30` (ridge along z), the two roof planes slope 30 degrees and
/// face east (azimuth 90) and west (270); the gable ends are vertical
/// (slope 90, zenith 0); zenith is always 90 - maxSlope.
#[test]
fn geometry_angle_on_a_gable_roof() {
    let g = gen("Lot --> roofGable(30) comp(f) { all : print(comp.index + \" \" + geometry.angle(maxSlope) + \" \" + geometry.angle(azimuth) + \" \" + geometry.angle(zenith) + \" \" + geometry.area) }\n").ok();
    let rows: Vec<Vec<f64>> = g.prints().iter().map(|l| numbers(l)).collect();
    assert_eq!(rows.len(), 5);
    let roof: Vec<&Vec<f64>> = rows.iter().filter(|r| (r[1] - 30.0).abs() < 1e-9).collect();
    assert_eq!(roof.len(), 2);
    let mut azimuths: Vec<f64> = roof.iter().map(|r| r[2]).collect();
    azimuths.sort_by(f64::total_cmp);
    assert_all_near(&azimuths, &[90.0, 270.0], 1e-9);
    for r in &roof {
        assert_near(r[3], 60.0, 1e-9);
        assert_near(r[4], 20.0 * 30.0 / 2.0 / 30f64.to_radians().cos(), 1e-9);
    }
    let ends: Vec<&Vec<f64>> = rows.iter().filter(|r| (r[1] - 90.0).abs() < 1e-9).collect();
    assert_eq!(ends.len(), 2);
    for r in &ends {
        assert_near(r[3], 0.0, 1e-9);
    }
    // A flat lot faces straight up: no slope, zenith 90.
    let g = gen("Lot --> print(geometry.angle(maxSlope)) print(geometry.angle(zenith))\n").ok();
    assert_eq!(g.prints(), ["0", "90"]);
}

/// Azimuth is clockwise from north (-z): a plane tilted down towards +z
/// (south) has azimuth 180, towards -x (west) 270.
#[test]
fn geometry_angle_azimuth_directions() {
    let g = gen("Lot --> [ r(20, 0, 0) print(geometry.angle(azimuth)) print(geometry.angle(maxSlope)) ] [ r(0, 0, 45) print(geometry.angle(azimuth)) print(geometry.angle(maxSlope)) ]\n").ok();
    let p: Vec<f64> = g.prints().iter().map(|l| l.parse().unwrap()).collect();
    assert_eq!(p.len(), 4);
    assert_near(p[1], 20.0, 1e-9);
    assert_near(p[3], 45.0, 1e-9);
    // r(20,0,0) turns the up normal towards +z (south), r(0,0,45)
    // towards -x (west).
    assert_near(p[0], 180.0, 1e-9);
    assert_near(p[2], 270.0, 1e-9);
}

/// getGeoCoord: X and Y are the scope origin's easting and northing (x
/// and -z); lon/lat need a lot given in longitude/latitude and invert the
/// projection that placed it.
#[test]
fn get_geo_coord() {
    let src = "Lot --> print(getGeoCoord(X)) print(getGeoCoord(Y)) print(getGeoCoord(lon)) print(getGeoCoord(lat))\n";
    let g = gen(src);
    let p = g.prints();
    assert_eq!(p[..2], ["0", "30"]);
    assert_eq!(p[2..], ["nan", "nan"]);
    assert!(g.warnings().iter().any(|w| w.contains("not georeferenced")));

    let origin = cga_engine::geo::GeoOrigin {
        lon: 8.54,
        lat: 47.37,
    };
    let mut lot: Lot = cga_engine::lot::rect(20.0, 30.0);
    lot.geo_origin = Some(origin);
    let g = gen_with(
        src,
        &Opts {
            lots: vec![lot],
            ..Opts::default()
        },
    )
    .ok();
    let p: Vec<f64> = g.prints().iter().map(|l| l.parse().unwrap()).collect();
    // The scope origin is 30 m north of the frame's origin, on its central
    // meridian: 30 m along the meridian on the WGS84 ellipsoid.
    assert_near(p[2], 8.54, 1e-12);
    use geographiclib_rs::DirectGeodesic;
    let (lat, _lon): (f64, f64) =
        geographiclib_rs::Geodesic::wgs84().direct(47.37, 8.54, 0.0, 30.0);
    assert_near(p[3], lat, 1e-10);
    let back = origin.to_local(p[2], p[3]);
    assert_near(back.0, 0.0, 1e-6);
    assert_near(back.1, 30.0, 1e-6);
}

/// func_edgeAttr: without an edge attribute array of that name, each
/// function returns its type's default (0, "", false).
#[test]
fn edge_attributes_default_when_missing() {
    let g = gen("getColor = edgeAttr.getString(\"colors\")\nLot --> print(\"[\" + getColor + \"]\") print(edgeAttr.getFloat(\"w\")) print(edgeAttr.getBool(\"b\"))\n").ok();
    assert_eq!(g.prints(), ["[]", "0", "false"]);
}

/// func_assetsSortSize, func_assetsSortRatio: assets ordered by how well
/// they fit the scope (box.obj is 2 x 3 x 1, plant.obj 1 x 1 x 0,
/// flat2.obj 20 x 0 x 10), in the form they were given; a maximum scale
/// error keeps only the assets within it.
#[test]
fn assets_sorted_by_size_and_ratio() {
    let src = "Lot --> s(2, 3, 1) primitiveCube()\n\
               print(assetsSortSize(\"plant.obj;box.obj;\", xyz, 0))\n\
               print(assetsSortSize(\"plant.obj;box.obj;\", xyz, 0.1))\n\
               print(assetsSortSize([\"plant.obj\", \"box.obj\"], xy, 0))\n\
               print(assetsSortSize(\"box.obj;plant.obj;\", x, 1))\n\
               print(assetsSortRatio(\"flat2.obj;plant.obj;box.obj;\", xy))\n\
               print(assetsSortRatio(\"box.obj;flat2.obj;\", xz))\n\
               print(assetMetadata(\"box.obj\", \"author\", \"nobody\"))\n\
               print(sel(\"x\"))\n";
    let g = gen(src).ok();
    assert_eq!(
        g.prints(),
        [
            "box.obj;plant.obj;",
            "box.obj;",
            "(2)[box.obj,plant.obj]",
            // x: box fits (0), plant needs twice its size (error 1).
            "box.obj;plant.obj;",
            // xy ratio 2/3: box exact, plant 1/1, flat2 has no height.
            "box.obj;plant.obj;flat2.obj;",
            // xz ratio 2: both fit; ties keep the given order.
            "box.obj;flat2.obj;",
            "nobody",
            "x",
        ]
    );
}

/// CGA functions this engine does not compute give a warning and an empty
/// value instead of failing the rule file.
#[test]
fn unsupported_functions_warn_and_return_empty_values() {
    let g = gen("Lot --> print(\"[\" + assetNamingInfo(\"a.obj\", m) + \"]\") print(readMaterial(\"m.mtl\"))\n");
    assert_eq!(g.prints(), ["[]", "(0)[]"]);
    let w = g.warnings();
    assert!(
        w.iter()
            .any(|w| w.contains("`assetNamingInfo` is not supported")),
        "{w:?}"
    );
    assert!(
        w.iter()
            .any(|w| w.contains("`readMaterial` is not supported")),
        "{w:?}"
    );
}

/// func_geometry, geometry.materials: the material names in the order of
/// `comp(m)`; op_comp's example selects the component whose index
/// `findFirst` gives.
#[test]
fn geometry_materials_in_component_order() {
    let dir = std::env::temp_dir().join(format!("cga-materials-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("tree.obj"),
        "mtllib tree.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 2 0\nusemtl Leaves\nf 1 2 3\nusemtl Bark\nf 1 3 4\nusemtl Leaves\nf 4 3 5\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("tree.mtl"),
        "newmtl Leaves\nKd 0 1 0\nnewmtl Bark\nKd 0.5 0.3 0.1\n",
    )
    .unwrap();
    let rules = dir.join("m.cga");
    std::fs::write(
        &rules,
        "Lot --> i(\"tree.obj\") print(geometry.materials)\n    comp(m) { findFirst(geometry.materials, \"Bark\") : print(\"trunk \" + geometry.area) | all = print(\"foliage \" + geometry.area) }\n",
    )
    .unwrap();
    let g = gen_file(&rules, &Opts::default()).ok();
    let prints = g.prints();
    assert_eq!(prints[0], "(2)[Leaves,Bark]");
    let mut rest: Vec<&str> = prints[1..].iter().map(String::as_str).collect();
    rest.sort();
    // The asset is fitted to the lot's scope; the leaves have twice the
    // bark's area.
    assert_eq!(rest.len(), 2);
    assert!(rest[0].starts_with("foliage ") && rest[1].starts_with("trunk "));
    assert_near(numbers(rest[0])[0], 2.0 * numbers(rest[1])[0], 1e-9);
}

/// A colour string that is not a colour (here an empty edge attribute)
/// leaves the colour unchanged with a warning; the lot is still generated.
#[test]
fn invalid_colour_strings_warn() {
    let g = gen("Lot --> color(\"#ff0000\") color(edgeAttr.getString(\"colors\")) X.\n");
    let g = g.ok();
    assert_eq!(rgb255(g.face_materials()[0]), [255, 0, 0]);
    assert!(g.warnings().iter().any(|w| w.contains("is not a colour")));
}

/// func_getTreeKey, "Simple Example": the path of child indices from the
/// initial shape, printed generation by generation as CityEngine does.
#[test]
fn tree_keys_of_the_simple_example() {
    let src = r#"
Init-->
    print(getTreeKey() + " - Init")
    center(xz)
    extrude(10)
    comp(f) { front: Facade}

Facade-->
    print(getTreeKey() + " - Facade")
    split(y) {'0.5 : Floor }*

Floor-->
    print(getTreeKey() + " - Floor")
    split(x) { '0.1 : Wall | '0.3 : Window | '0.1 : Wall }*

Wall-->
    print(getTreeKey() + " - Wall")

Window-->
    print(getTreeKey() + " - Window")
"#;
    let g = gen_with(src, &Opts::default().start("Init")).ok();
    let expected = [
        "0; - Init",
        "0;0; - Facade",
        "0;0;0; - Floor",
        "0;0;1; - Floor",
        "0;0;0;0; - Wall",
        "0;0;0;1; - Window",
        "0;0;0;2; - Wall",
        "0;0;0;3; - Wall",
        "0;0;0;4; - Window",
        "0;0;0;5; - Wall",
        "0;0;1;0; - Wall",
        "0;0;1;1; - Window",
        "0;0;1;2; - Wall",
        "0;0;1;3; - Wall",
        "0;0;1;4; - Window",
        "0;0;1;5; - Wall",
    ];
    assert_eq!(g.prints(), expected);
}

/// func_getTreeKey: the key stays the same while a rule is derived, also
/// in the operations of split parts.
#[test]
fn tree_key_is_the_rules_during_its_derivation() {
    let g = gen("Lot --> extrude(5) ShapeA\nShapeA -->\n    print(getTreeKey)\n    split(x){ 2: ShapeB print(getTreeKey) | 3: ShapeC print(getTreeKey) }\n").ok();
    assert_eq!(g.prints(), ["0;0;", "0;0;", "0;0;"]);
}
