//! The texturing examples of the reference that work on facades: the uv
//! split basics of the split page, setupProjection's "default use case" and
//! "scope vs. setupProjection", and the texture and rotateUV pages.
//!
//! On the lot `rect:20,30` extruded, the facades' scopes are: front (z = 0)
//! from (0,0,0) along +x, back (z = -30) from (20,0,-30) along -x, left
//! (x = 0) from (0,0,-30) along +z, right (x = 20) from (20,0,0) along -z;
//! y up, z out of the building.

use crate::texturing_common::*;
use cga_geometry::{DVec2, DVec3, Mesh};

fn uv(u: f64, v: f64) -> DVec2 {
    DVec2::new(u, v)
}

/// Which facade of the 20 x 30 box a mesh lies on, and its horizontal
/// facade coordinate (distance from the facade's scope origin).
fn facade_x(m: &Mesh) -> (&'static str, fn(DVec3) -> f64) {
    let (x0, x1) = span(m, 0);
    let (z0, z1) = span(m, 2);
    if close(z0, 0.0) && close(z1, 0.0) {
        ("front", |p| p.x)
    } else if close(z0, -30.0) && close(z1, -30.0) {
        ("back", |p| 20.0 - p.x)
    } else if close(x0, 0.0) && close(x1, 0.0) {
        ("left", |p| p.z + 30.0)
    } else {
        assert!(close(x0, 20.0) && close(x1, 20.0), "{x0} {x1} {z0} {z1}");
        ("right", |p| -p.z)
    }
}

const UV_SPLIT: &str = r#"
Lot --> extrude(scope.sx * 0.5) comp(f) { front : Facade }
Facade -->
    setupProjection(0, scope.xy, '1, '1)
    projectUV(0)
    texture("builtin:uvtest.png")
    split(u, SPACE, 0) { SIZE : X } *
"#;

#[test]
fn split_page_uv_split_basics() {
    // "u split in uvSpace - the split happens at u = 0.5, independent of
    // facade size."
    for w in [20.0, 14.0] {
        let rules = UV_SPLIT.replace("SPACE", "uvSpace").replace("SIZE", "0.5");
        let out = run("basics_uv", &rules, &rect(w, 30.0));
        let spans: Vec<(f64, f64)> = out.meshes.iter().map(|m| span(m, 0)).collect();
        assert_eq!(spans.len(), 2);
        assert!(
            close(spans[0].0, 0.0) && close(spans[0].1, w / 2.0),
            "{spans:?}"
        );
        assert!(
            close(spans[1].0, w / 2.0) && close(spans[1].1, w),
            "{spans:?}"
        );
        for m in &out.meshes {
            assert!(close(area(m), w / 2.0 * w / 2.0));
            assert_uvs(m, 0, |p| uv(p.x / w, p.y / (w / 2.0)));
            assert_eq!(&*m.materials[0].maps[0].path, "builtin:uvtest.png");
        }
    }
    // "u split in unitSpace - the splits happen at u = 5, dependent of
    // facade size": every 5 units, so 4 parts on 20, 2 and a rest on 14.
    for (w, parts) in [(20.0, vec![5.0; 4]), (14.0, vec![5.0, 5.0, 4.0])] {
        let rules = UV_SPLIT.replace("SPACE", "unitSpace").replace("SIZE", "5");
        let out = run("basics_unit", &rules, &rect(w, 30.0));
        let widths: Vec<f64> = out
            .meshes
            .iter()
            .map(|m| {
                let (a, b) = span(m, 0);
                b - a
            })
            .collect();
        assert_eq!(widths.len(), parts.len(), "{widths:?}");
        for (a, b) in widths.iter().zip(&parts) {
            assert!(close(*a, *b), "{widths:?}");
        }
    }
}

const DEFAULT_USE_CASE: &str = r##"
attr groundfloor_height = 4
attr floor_height = 3.5
attr wallColor = "#ffffff"
attr wall_tex = "facade/walls/bricks.jpg"
attr dirt_tex = "dirtmaps/dirtmap.16.tif"

Lot --> extrude(18) comp(f) { side : Frontfacade }

Frontfacade -->
    SETUP_FACADE
    split(y){ groundfloor_height    : Groundfloor
            | {~floor_height : Floor}* }

Groundfloor --> split(x) { ~3 : Wall }*
Floor --> split(x) { ~2 : Wall | 1.2 : Window. | ~2 : Wall }*

Wall -->
    color(wallColor)
    SETUP_WALL
    set(material.colormap, wall_tex)
    set(material.dirtmap, dirt_tex)
    projectUV(0) projectUV(2)
"##;

#[test]
fn setup_projection_default_use_case() {
    // Set up on the facade: 1.5 x 1 m tiles for the colour map, one tile
    // over the whole facade for the dirt map, both continuous over all
    // the walls of the facade.
    let rules = DEFAULT_USE_CASE
        .replace(
            "SETUP_FACADE",
            "setupProjection(0, scope.xy, 1.5, 1, 0, 0, 1) setupProjection(2, scope.xy, scope.sx, scope.sy, 0, 0, 1)",
        )
        .replace("SETUP_WALL", "");
    let out = run("default_use_case", &rules, &rect(20.0, 30.0));
    let walls: Vec<&Mesh> = out.meshes.iter().filter(|m| m.uvs[0].is_some()).collect();
    assert!(walls.len() > 40, "{}", walls.len());
    for m in walls {
        let (side, x) = facade_x(m);
        let width = if matches!(side, "front" | "back") {
            20.0
        } else {
            30.0
        };
        assert_uvs(m, 0, |p| uv(x(p) / 1.5, p.y));
        assert_uvs(m, 2, |p| uv(x(p) / width, p.y / 18.0));
        assert_eq!(m.materials[0].colormap(), "facade/walls/bricks.jpg");
        assert_eq!(&*m.materials[0].maps[2].path, "dirtmaps/dirtmap.16.tif");
    }
}

#[test]
fn setup_projection_in_the_wall_restarts_per_wall() {
    // "Scope vs. setupProjection", second variant: the colour map's
    // projection set up in each wall restarts at the wall's corner ("the
    // brick texture does not span over the whole facade anymore"); the
    // dirt map's, set up on the facade, still spans it.
    let rules = DEFAULT_USE_CASE
        .replace(
            "SETUP_FACADE",
            "setupProjection(2, scope.xy, scope.sx, scope.sy, 0, 0, 1)",
        )
        .replace(
            "SETUP_WALL",
            "setupProjection(0, scope.xy, 1.5, 1, 0, 0, 1)",
        );
    let out = run("wall_use_case", &rules, &rect(20.0, 30.0));
    let mut restarted = 0;
    for m in out.meshes.iter().filter(|m| m.uvs[0].is_some()) {
        let (side, x) = facade_x(m);
        let width = if matches!(side, "front" | "back") {
            20.0
        } else {
            30.0
        };
        let x0 = corners(m, 0)
            .iter()
            .map(|(p, _)| x(*p))
            .fold(f64::INFINITY, f64::min);
        let y0 = span(m, 1).0;
        assert_uvs(m, 0, |p| uv((x(p) - x0) / 1.5, p.y - y0));
        assert_uvs(m, 2, |p| uv(x(p) / width, p.y / 18.0));
        if x0 > 0.1 {
            restarted += 1;
        }
    }
    assert!(restarted > 30, "{restarted}");
}

const TEXTURE_PAGE: &str = r#"
brickMap = "assets/bricks.jpg"
randBuildingHeight = rand(3,20)

Lot -->
s('.75,'1,'.75)
center(xz)
extrude(world.up, randBuildingHeight)
comp(f){side: Facade | top: Roof.}

Facade -->
	# color, uv set 0
	setupProjection(0, scope.xy, SIZE)
	texture(brickMap)
	// = set(material.colormap,brickMap)
	projectUV(0)
	ROTATE
"#;

/// The front facade of the texture and rotateUV pages' building: the lot
/// scaled to 15 x 22.5 and centred, so the front is at z = -3.75 from
/// x = 2.5 to 17.5.
fn front(out: &cga_engine::LotOutput) -> &Mesh {
    out.meshes
        .iter()
        .find(|m| {
            let (z0, z1) = span(m, 2);
            close(z0, -3.75) && close(z1, -3.75)
        })
        .expect("the front facade")
}

#[test]
fn texture_page_example() {
    // (The page's roof sets `material.color.a`, which is not a material
    // attribute of the reference; the roof is left plain here.)
    let rules = TEXTURE_PAGE.replace("SIZE", "5, 5").replace("ROTATE", "");
    let out = run("texture_page", &rules, &rect(20.0, 30.0));
    assert_eq!(out.meshes.len(), 5);
    let m = front(&out);
    assert_eq!(m.materials[0].colormap(), "assets/bricks.jpg");
    assert_uvs(m, 0, |p| uv((p.x - 2.5) / 5.0, p.y / 5.0));
}

#[test]
fn rotate_uv_page_example() {
    let rules = TEXTURE_PAGE.replace("SIZE", "scope.sx, scope.sy").replace(
        "ROTATE",
        "rotateUV(0,10)		# rotate command after the projection",
    );
    let out = run("rotate_page", &rules, &rect(20.0, 30.0));
    let m = front(&out);
    let h = span(m, 1).1;
    let (s, c) = 10f64.to_radians().sin_cos();
    assert_uvs(m, 0, |p| {
        let (u, v) = ((p.x - 2.5) / 15.0, p.y / h);
        uv(c * u - s * v, s * u + c * v)
    });
}
