//! The examples of the reference pages of `color`, `set`, `setMaterial`,
//! `resetMaterial` and of the material shape attributes (`material.*`,
//! `material.color`): the colours and material attributes of the output,
//! and what rules read back.

use crate::ops_common::*;

const EPS: f64 = 1e-12;

/// op_color, "Three ways to set a shape's color": the three 2 m slices of
/// the split are all red.
#[test]
fn color_three_ways() {
    let src = "Lot-->\n   extrude(20)\n   split(x) {\n       2 : color(\"#ff0000\") X |\n       2 : color(1, 0, 0) X |\n       2 : set(material.color.r, 1.0)\n           set(material.color.g, 0)\n           set(material.color.b, 0) X\n    }\n";
    let g = gen(src).ok();
    assert_eq!(g.meshes().len(), 3);
    for (i, m) in g.meshes().iter().enumerate() {
        for f in &m.faces {
            assert_eq!(m.materials[f.material as usize].color, [1.0, 0.0, 0.0]);
        }
        let (lo, hi) = mesh_bounds(m);
        assert_near(lo.x, 2.0 * i as f64, 1e-9);
        assert_near(hi.x, 2.0 * i as f64 + 2.0, 1e-9);
    }
}

/// op_color: values outside [0,1] are clamped; "#rrggbboo" sets the
/// opacity too; the colour is what `material.color.*` reads back.
#[test]
fn color_clamps_and_reads_back() {
    let src = "Lot --> color(2, -1, 0.5) print(material.color.r) print(material.color.g) print(material.color.b) \
               print(material.color.rgb) color(\"#00ff0080\") print(material.opacity) print(material.color.rgb) \
               color(0.2, 0.4, 0.6, 0.25) print(material.opacity) X\n";
    let g = gen(src).ok();
    let p = g.prints();
    assert_eq!(p[..4], ["1", "0", "0.5", "#ff0080"]);
    assert_near(numbers(&p[4])[0], 128.0 / 255.0, 1e-12);
    assert_eq!(p[5], "#00ff00");
    assert_eq!(p[6], "0.25");
    let m = g.face_materials()[0];
    assert_eq!(m.color, [0.2, 0.4, 0.6]);
    assert_eq!(m.opacity, 0.25);
}

/// op_color: a colour that is not "#rrggbb" or "#rrggbboo" is refused
/// with a warning; the colour stays as it was and the model is generated.
#[test]
fn color_rejects_bad_hex() {
    let g = gen("Lot --> color(\"#0000ff\") color(\"red\") X\n");
    assert!(g.errors.is_empty());
    assert!(g
        .warnings()
        .iter()
        .any(|w| w.contains("\"red\" is not a colour")));
    let g = g.ok();
    assert_eq!(rgb255(g.face_materials()[0]), [0, 0, 255]);
}

/// op_set, "Builtin Shape Attributes": the four one-liners, read back.
#[test]
fn set_builtin_shape_attributes() {
    let src = "Lot --> print(trim.horizontal) set(trim.horizontal, true) print(trim.horizontal)\n\
               t(3, 0, 0) print(scope.tx) set(scope.tx, 0) print(scope.tx)\n\
               set(material.color.r, 0.5) print(material.color.r)\n\
               set(material.colormap, \"builtin:uvtest.png\") print(material.colormap) X\n";
    let g = gen(src).ok();
    assert_eq!(
        g.prints(),
        ["false", "true", "3", "0", "0.5", "builtin:uvtest.png"]
    );
    let m = g.face_materials()[0];
    assert_eq!(m.color, [0.5, 1.0, 1.0]);
    assert_eq!(m.colormap(), "builtin:uvtest.png");
    // set(scope.tx, 0) moved the shape back to the pivot's x = 0
    assert_near(g.bounds().0.x, 0.0, 1e-12);
}

/// op_set, "Generic Shape Attributes", without the component split: the
/// floors of an extruded block store their index in `floorNumber`; the
/// windows of every third floor are pink.
#[test]
fn set_generic_attribute_floor_number() {
    let src = "attr floorNumber = -1\nconst floorHeight = 4\n\
               Init --> extrude(30) Side\n\
               Side --> split(y) { ~floorHeight : Floor }*\n\
               Floor --> set(floorNumber, split.index) split(x) { ~1 : Wall | {~3 : Tile}* | ~1 : Wall }\n\
               Tile --> split(x) { 0.5 : Wall | ~1 : MidTile | 0.5 : Wall}\n\
               MidTile--> split(y) { 0.5 : Wall | ~1 : Window | 0.5 : Wall }\n\
               Window --> print(floorNumber) Pick\n\
               Pick --> case floorNumber % 3 == 0 : color(1.0, 0.0, 1.0) X.\n       else : X.\n\
               Wall --> NIL\n";
    let g = gen_with(src, &Opts::rect(30.0, 30.0).start("Init")).ok();
    let floors: Vec<f64> = g.prints().iter().map(|l| numbers(l)[0]).collect();
    // 30 m in floors of ~4 m: 7 or 8 floors, all numbered from 0
    let max = floors.iter().cloned().fold(0.0, f64::max);
    assert!((6.0..=7.0).contains(&max), "{max}");
    for k in 0..=(max as usize) {
        assert!(floors.contains(&(k as f64)), "floor {k} has windows");
    }
    assert_eq!(floors.len(), g.meshes().len());
    for (floor, m) in floors.iter().zip(g.meshes()) {
        let c = rgb255(&m.materials[0]);
        let pink = floor % 3.0 == 0.0;
        assert_eq!(c, if pink { [255, 0, 255] } else { [255, 255, 255] });
    }
    // the attribute's default is untouched outside the floors
    let g = gen("attr floorNumber = -1\nLot --> print(floorNumber)\n").ok();
    assert_eq!(g.prints(), ["-1"]);
}

/// op_set, "Generic Shape Attributes", the page's rule with `comp(f)`.
#[test]
fn set_generic_attribute_page_rule() {
    let src = "attr floorNumber = -1\nconst floorHeight = 4\n\
               Init --> extrude(30) comp(f) {side : Side }\n\
               Side --> split(y) { ~floorHeight : Floor }*\n\
               Floor --> set(floorNumber, split.index) split(x) { ~1 : Wall | {~3 : Tile}* | ~1 : Wall }\n\
               Tile --> split(x) { 0.5 : Wall | ~1 : MidTile | 0.5 : Wall}\n\
               MidTile--> split(y) { 0.5 : Wall | ~1 : Window | 0.5 : Wall }\n\
               Window --> case floorNumber % 3 == 0 : color(1.0, 0.0, 1.0) X.\n       else : X.\n";
    let g = gen_with(src, &Opts::rect(30.0, 30.0).start("Init")).ok();
    let pink = g
        .face_materials()
        .iter()
        .filter(|m| rgb255(m) == [255, 0, 255])
        .count();
    assert!(pink > 0);
}

/// op_set: an attribute keeps its type; setting a float attribute to a
/// string is an error.
#[test]
fn set_keeps_the_attribute_type() {
    let g = gen("attr h = 1\nLot --> set(h, \"high\") X\n");
    assert_eq!(g.errors.len(), 1);
    assert!(g.errors[0].message.contains("cannot be set"));
}

/// op_setMaterial, example 1: red, with the opacity map "builtin:default".
/// (scaleUV is the texturing engineer's; unsupported, it only warns.)
#[test]
fn set_material_from_pairs() {
    let src = "myMaterial = [ \"color.r\",    \"1.0\",\n\
                              \"color.g\",    \"0.0\",\n\
                              \"color.b\",    \"0.0\",\n\
                              \"opacitymap\", \"builtin:default\" ]\n\
               Lot --> primitiveCube()\n        scaleUV(0,0.25,0.25)\n        setMaterial(myMaterial)\n";
    let g = gen(src).ok();
    assert_eq!(g.meshes()[0].faces.len(), 6);
    for m in g.face_materials() {
        assert_eq!(m.color, [1.0, 0.0, 0.0]);
        assert_eq!(&*m.maps[4].path, "builtin:default");
    }
}

/// op_setMaterial: "The result will be the same as using set() to set each
/// material attribute individually."
#[test]
fn set_material_equals_individual_sets() {
    let a = gen("Lot --> setMaterial([\"color.rgb\", \"#336699\", \"opacity\", \"0.5\", \"shininess\", \"20\", \"colormap\", \"a.png\", \"colormap.su\", \"2\"]) X\n").ok();
    let b = gen("Lot --> set(material.color.rgb, \"#336699\") set(material.opacity, 0.5) set(material.shininess, 20) set(material.colormap, \"a.png\") set(material.colormap.su, 2) X\n").ok();
    assert_eq!(a.face_materials()[0], b.face_materials()[0]);
    let m = a.face_materials()[0];
    assert_eq!(rgb255(m), [0x33, 0x66, 0x99]);
    assert_eq!((m.opacity, m.shininess, m.maps[0].su), (0.5, 20.0, 2.0));
}

/// op_setMaterial, example 3: a material from a CSV table read with
/// readStringTable (color.r 1, color.g 0.5, color.b 0, colormap).
#[test]
fn set_material_from_a_csv_table() {
    let src = "RefExampleCSV-->\n\tprimitiveCube()\n\tsetMaterial(readStringTable(\"exampleMaterial.csv\"))\n";
    let g = gen_with(src, &Opts::default().start("RefExampleCSV")).ok();
    for m in g.face_materials() {
        assert_eq!(m.color, [1.0, 0.5, 0.0]);
        assert_eq!(m.colormap(), "builtin:default");
    }
}

/// op_resetMaterial, example 1: the stones keep their texture, reflectivity
/// and specular colour; after resetMaterial() the inserted asset shows its
/// own material (here plant.obj: green, leaves.png), none of the changes.
#[test]
fn reset_material_lets_the_asset_material_through() {
    let src = "Lot --> primitiveQuad()\n        texture(\"stones.jpg\")\n        set(material.reflectivity, 0.75)\n\
               set(material.specular.r, 1)\n        set(material.specular.g, 1)\n        set(material.specular.b, 1)\n\
               Stones.\n        i(\"plant.obj\")\n        resetMaterial()\n        Flowers.\n";
    let g = gen(src).ok();
    assert_eq!(g.meshes().len(), 2);
    let stones = &g.meshes()[0].materials[0];
    assert_eq!(stones.colormap(), "stones.jpg");
    assert_eq!((stones.reflectivity, stones.specular), (0.75, [1.0; 3]));
    let flowers = &g.meshes()[1].materials[0];
    assert_eq!(flowers.color, [0.0, 0.5, 0.0]);
    // the asset's texture, resolved next to the asset
    assert!(flowers.colormap().ends_with("leaves.png"));
    assert_eq!((flowers.reflectivity, flowers.specular), (0.0, [0.0; 3]));
}

/// op_resetMaterial with a target: `geometry` resets the geometry's own
/// materials to the CGA default, `shape` (the default) only the shape's,
/// `all` both.
#[test]
fn reset_material_targets() {
    let src = "Lot --> color(1,0,0) i(\"plant.obj\") [ resetMaterial(shape) A. ] [ resetMaterial(geometry) B. ] [ resetMaterial(all) C. ]\n";
    let g = gen(src).ok();
    let m: Vec<_> = g.meshes().iter().map(|m| &m.materials[0]).collect();
    // shape: the asset's own material
    assert_eq!(m[0].color, [0.0, 0.5, 0.0]);
    assert!(m[0].colormap().ends_with("leaves.png"));
    // geometry: default material, coloured red by the shape
    assert_eq!((m[1].color, m[1].colormap()), ([1.0, 0.0, 0.0], ""));
    // all: the default material
    assert_eq!((m[2].color, m[2].colormap()), ([1.0, 1.0, 1.0], ""));
}

/// attr_material: the defaults the page's table gives, read by rules.
#[test]
fn material_attribute_defaults() {
    let src = "Lot --> print(material.shader) print(material.color.rgb) print([material.color.r, material.color.g, material.color.b]) \
               print([material.ambient.r, material.specular.g, material.emissive.b]) print(material.opacity) \
               print(material.reflectivity) print(material.shininess) print(material.bumpValue) print(material.metallic) \
               print(material.roughness) print(material.doubleSided) print(material.colormap) print(material.opacitymap.mode) \
               print(material.opacitymap.cutoff) print([material.colormap.su, material.colormap.sv, material.dirtmap.tu, material.normalmap.rw])\n";
    let g = gen(src).ok();
    assert_eq!(
        g.prints(),
        [
            "CityEngineShader",
            "#ffffff",
            "(3)[1,1,1]",
            "(3)[0,0,0]",
            "1",
            "0",
            "1",
            "1",
            "0",
            "1",
            "true",
            "",
            "blend",
            "0.5",
            "(4)[1,1,0,0]",
        ]
    );
}

/// attr_material, example: a wall cube with colour and two texture layers
/// (projectUV belongs to the texturing engineer; it only warns here).
#[test]
fn material_attribute_example() {
    let src = "attr wallC       = \"#FFFFFF\"\nattr wallTexture = \"facade/walls/wall.c.09.tif\"\nattr dirtTexture = \"dirtmaps/dirtmap.16.tif\"\n\
               Wall --> \n    primitiveCube() color(wallC)\n    set(material.colormap, wallTexture) projectUV(0)\n    set(material.dirtmap, dirtTexture) projectUV(2)\n";
    let g = gen_with(src, &Opts::default().start("Wall")).ok();
    for m in g.face_materials() {
        assert_eq!(m.color, [1.0; 3]);
        assert_eq!(m.colormap(), "facade/walls/wall.c.09.tif");
        assert_eq!(&*m.maps[2].path, "dirtmaps/dirtmap.16.tif");
    }
}

/// attr_material_color, "Rainbow building": ten 2 m slices of a 20 m wide
/// block; slice i has red i/10, green 0, blue 1 - i/10.
#[test]
fn material_color_rainbow() {
    let src = "Lot-->\n   extrude(20)\n   set(material.color.g, 0)\n   split(x) {\n       2 : set(material.color.r, split.index/split.total)\n           set(material.color.b, 1.0 - split.index/split.total)\n           X\n    }*\n";
    let g = gen(src).ok();
    assert_eq!(g.meshes().len(), 10);
    for (i, m) in g.meshes().iter().enumerate() {
        let c = m.materials[m.faces[0].material as usize].color;
        let t = i as f64 / 10.0;
        assert_all_near(&c, &[t, 0.0, 1.0 - t], EPS);
        assert_near(mesh_bounds(m).0.x, 2.0 * i as f64, 1e-9);
    }
}

/// attr_material_color: `material.color.rgb` reads and writes the colour
/// as a hex string.
#[test]
fn material_color_rgb() {
    let g = gen("Lot --> set(material.color.rgb, \"#ff8000\") print(material.color.rgb) print(material.color.g) X\n").ok();
    assert_eq!(g.prints()[0], "#ff8000");
    assert_near(numbers(&g.prints()[1])[0], 128.0 / 255.0, EPS);
    assert_eq!(rgb255(g.face_materials()[0]), [255, 128, 0]);
}
