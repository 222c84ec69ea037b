//! The examples of the Boolean operations page (op_boolOp.md): `union`,
//! `subtract`, `intersect`, measured: volumes, areas, bounds, face counts,
//! closedness and the materials of the result's faces.
//!
//! The page's examples run on an initial shape the page does not give;
//! here the lot is 10 × 10 and volumes get a 10 × 10 × 10 scope
//! (`s(10,10,10)`) so that the operands overlap as in the pictures.
//! Component tags (`tag`, `isTagged`, the `bool.*` auto-tags) are not part
//! of this engine: the examples that colour faces by tag are measured before
//! their tag-based `comp`.

use crate::ops_common::*;
use cga_geometry::footprint;
use cga_geometry::skeleton::polygon_area;
use cga_geometry::{DVec2, Mesh};

const COLORS: &str = r##"
Blue   --> color("#0399F5")
Green  --> color("#09DE1F")
Yellow --> color("#FADB19")
Purple --> color("#8D09DE")
Red    --> color("#FF360A")
Orange --> color("#FA9100")
"##;

const BLUE: [u8; 3] = [0x03, 0x99, 0xF5];
const GREEN: [u8; 3] = [0x09, 0xDE, 0x1F];

fn run(rules: &str) -> Gen {
    run_on(rules, 10.0)
}

/// `rules` on a `w` × `w` lot; the start rule is `Lot` or else `Init`.
fn run_on(rules: &str, w: f64) -> Gen {
    let mut opts = Opts::rect(w, w);
    if !rules.contains("Lot ") {
        opts = opts.start("Init");
    }
    gen_with(&format!("{rules}\n{COLORS}"), &opts).ok()
}

/// Printed numbers (`true`/`false` as 1/0).
fn printed(g: &Gen) -> Vec<f64> {
    g.prints()
        .iter()
        .map(|l| match l.as_str() {
            "true" => 1.0,
            "false" => 0.0,
            s => s.parse().unwrap_or_else(|_| panic!("not a number: {s}")),
        })
        .collect()
}

#[track_caller]
fn single(g: &Gen) -> &Mesh {
    assert_eq!(g.meshes().len(), 1, "expected one leaf");
    &g.meshes()[0]
}

/// Area of the disk `primitiveDisk` makes in a `d` × `d` scope, moved by
/// `off` (in the scope's x and z), that lies within the scope's `w` × `w`
/// square, computed in 2D (independently of the 3D Boolean).
fn disk_in_square(d: f64, off: f64, w: f64) -> (f64, f64) {
    // 16 vertices half a step off the axes, the flat sides touching the
    // d x d square (as CityEngine makes its disks and cylinders).
    let step = std::f64::consts::TAU / 16.0;
    let r = d / 2.0 / (step / 2.0).cos();
    let disk: Vec<DVec2> = (0..16)
        .map(|k| {
            let a = step * (k as f64 + 0.5);
            DVec2::new(off + d / 2.0 + r * a.cos(), off + d / 2.0 + r * a.sin())
        })
        .collect();
    let square = vec![
        DVec2::new(0.0, 0.0),
        DVec2::new(w, 0.0),
        DVec2::new(w, w),
        DVec2::new(0.0, w),
    ];
    let full = polygon_area(&disk);
    let outside: f64 = footprint::difference(&[disk], &[square])
        .iter()
        .flatten()
        .map(|l| polygon_area(l))
        .sum();
    (full, full - outside)
}

fn colors(m: &Mesh) -> Vec<[u8; 3]> {
    m.faces
        .iter()
        .map(|f| rgb255(&m.materials[f.material as usize]))
        .collect()
}

// ---------------------------------------------------------------------------
// Order of operands
// ---------------------------------------------------------------------------

/// "A cylinder is subtracted from a cube and vice versa." The cube is
/// 10³; the cylinder (16 sides, 10 across, 10 high) is moved by (3,3,3), so
/// it overlaps the cube over 7 of its height, over the part of its 16-gon
/// within the cube's square.
#[test]
fn order_of_operands_subtract() {
    let rules = "
Lot      --> s(10,10,10) Left
Left     --> subtract { Cube | Cylinder }
             print(geometry.volume) print(geometry.isClosedSurface) X.
Cube     --> primitiveCube Blue
Cylinder --> t(3,3,3) primitiveCylinder Green
";
    let (cyl_base, overlap_base) = disk_in_square(10.0, 3.0, 10.0);
    let overlap = 7.0 * overlap_base;
    let g = run(rules);
    let p = printed(&g);
    assert_near(p[0], 1000.0 - overlap, 1e-6);
    assert_eq!(p[1], 1.0);
    let m = single(&g);
    let c = colors(m);
    // The cube's faces, and the cylinder's faces that bound the cut-out.
    // Cut of the cube: its top, right and back faces (3 faces), and of the
    // cylinder its bottom cap and the sides within the cube.
    assert_eq!(c.iter().filter(|&&c| c == BLUE).count(), 6);
    assert!(c.iter().filter(|&&c| c == GREEN).count() >= 2);
    assert_eq!(c.len(), m.faces.len());
    let (lo, hi) = g.bounds();
    assert_near(hi.y - lo.y, 10.0, 1e-9);

    let g = run(&rules.replace("{ Cube | Cylinder }", "{ Cylinder | Cube }"));
    let p = printed(&g);
    assert_near(p[0], 10.0 * cyl_base - overlap, 1e-6);
    assert_eq!(p[1], 1.0);
    let (lo, hi) = g.bounds();
    // What is left of the cylinder: above the cube and beside it, up to 13.
    assert_near(hi.y - lo.y, 10.0, 1e-9);
    let m = single(&g);
    let c = colors(m);
    // The cylinder's faces; the cube's top, right and back faces inside it.
    assert_eq!(c.iter().filter(|&&c| c == BLUE).count(), 3);
    assert!(c.iter().all(|&c| c == BLUE || c == GREEN));
}

/// "The first operand A determines the material of overlapping faces": a
/// quad and a disk in one plane unite into three faces (A outside B, the
/// overlap, B outside A); the overlap is A's.
#[test]
fn order_of_operands_material() {
    let rules = "
Lot    --> Left
Left   --> union { Quad   | Circle }
           print(geometry.nFaces) print(geometry.area) X.
Quad   --> primitiveQuad Blue
Circle --> t(3,0,3) primitiveDisk Green
";
    let (disk, overlap) = disk_in_square(10.0, 3.0, 10.0);
    for (order, overlap_color) in [("{ Quad   | Circle }", BLUE), ("{ Circle | Quad }", GREEN)] {
        let g = run(&rules.replace("{ Quad   | Circle }", order));
        let p = printed(&g);
        assert_eq!(p[0], 3.0);
        assert_near(p[1], 100.0 + disk - overlap, 1e-6);
        let m = single(&g);
        let c = colors(m);
        // A's faces first: the part outside B, then the overlap; then B's.
        assert_eq!(c[1], overlap_color, "{order}");
        assert_eq!(c[0], overlap_color);
        assert_ne!(c[2], overlap_color);
        let areas: Vec<f64> = (0..3)
            .map(|f| cga_geometry::measure::face_area(m, f))
            .collect();
        assert_near(areas[1], overlap, 1e-6);
    }
}

/// "The first operand A determines the attributes of the resulting shape":
/// the intersection is extruded by A's `Height`.
#[test]
fn order_of_operands_attributes() {
    let rules = "
attr Height = 0
Lot    --> Left
Left   --> intersect { Quad   | Circle }
           extrude(Height) print(Height) print(geometry.volume) X.
Quad   --> set(Height, 10)
           primitiveQuad
Circle --> set(Height, 1)
           t(3,0,3)
           primitiveDisk
";
    let (_, overlap) = disk_in_square(10.0, 3.0, 10.0);
    let p = printed(&run(rules));
    assert_eq!(p[0], 10.0);
    assert_near(p[1], 10.0 * overlap, 1e-6);
    let p = printed(&run(
        &rules.replace("{ Quad   | Circle }", "{ Circle | Quad   }")
    ));
    assert_eq!(p[0], 1.0);
    assert_near(p[1], overlap, 1e-6);
}

// ---------------------------------------------------------------------------
// Inlining of operands
// ---------------------------------------------------------------------------

/// "An operand can result in a single shape (Left) or multiple shapes
/// (operand B in Right). In case of multiple shapes, they are first merged."
/// Cubes of 2: A at 0, B at 1 (Left); B at 1, 2 and 3 (Right).
#[test]
fn operand_of_one_or_several_shapes() {
    let left = "
Lot  --> s(2,2,2) Left
Left --> primitiveCube
         union { Blue
               | t(1,1,1) Green }
         print(geometry.volume) print(geometry.isClosedSurface) print(geometry.nFaces) X.
";
    let p = printed(&run(left));
    assert_near(p[0], 8.0 + 8.0 - 1.0, 1e-9);
    assert_eq!(p[1], 1.0);
    assert_eq!(p[2], 12.0);
    let right = "
Lot   --> s(2,2,2) Right
Right --> primitiveCube
          union { Blue
                | t(1,1,1) Green
                  t(1,1,1) Green
                  t(1,1,1) Green }
          print(geometry.volume) print(geometry.isClosedSurface) X.
";
    let g = run(right);
    let p = printed(&g);
    // B: three cubes at 1, 2, 3 overlapping by 1 in turn (22); A meets the
    // first by 1.
    assert_near(p[0], 8.0 + 22.0 - 1.0, 1e-9);
    assert_eq!(p[1], 1.0);
    let (lo, hi) = g.bounds();
    assert_near(hi.y - lo.y, 5.0, 1e-9);
    let c = colors(single(&g));
    assert!(c.contains(&BLUE) && c.contains(&GREEN));
}

/// "In case an operand results in multiple shapes, they are unified even if
/// they do not intersect operand A": the three green cubes moved 10 away.
#[test]
fn operand_shapes_unified_apart_from_a() {
    let rules = "
Lot  --> s(2,2,2) Init
Init --> primitiveCube
         union { Blue
               | t(1,1,1+10) Green
                 t(1,1,1)    Green
                 t(1,1,1)    Green }
         print(geometry.volume) print(geometry.isClosedSurface) print(geometry.nFaces) X.
";
    let g = run(rules);
    let p = printed(&g);
    assert_near(p[0], 8.0 + 22.0, 1e-9);
    assert_eq!(p[1], 1.0);
    // A's cube (6 faces) apart from the three green cubes united: each
    // green cube keeps its 6 faces (those around an overlap as L-shapes).
    assert_eq!(p[2], 6.0 + 3.0 * 6.0);
    let (lo, hi) = g.bounds();
    assert_near(hi.y - lo.y, 5.0, 1e-9);
    let c = colors(single(&g));
    assert_eq!(c.iter().filter(|&&c| c == BLUE).count(), 6);
    assert_eq!(c.iter().filter(|&&c| c == GREEN).count(), 18);
}

// ---------------------------------------------------------------------------
// Mass modeling
// ---------------------------------------------------------------------------

const MASS: &str = "
Envelope -->
    extrude(40)
Sphere -->
    s('1, 40, '2)
    center(z)
    t(0, '-0.2, 0)
    primitiveSphere
";

/// Step 1: the extruded lot (40 × 40 here) intersected with a sphere (an
/// ellipsoid 40 × 40 × 80, centred in z, moved down by 8): its part above
/// the ground and within the lot. The union of the same operands and the
/// intersection add up to both.
#[test]
fn mass_modeling_intersect_envelope_and_sphere() {
    let g = run_on(
        &format!(
            "Init --> intersect {{ Envelope | Sphere }} print(geometry.volume) print(geometry.isClosedSurface) X.\n{MASS}"
        ),
        40.0,
    );
    let p = printed(&g);
    let vi = p[0];
    assert_eq!(p[1], 1.0);
    let (lo, hi) = g.bounds();
    // Ground to the (moved) north pole at 40 - 8; the lot in x and z.
    assert_near(lo.y, 0.0, 1e-9);
    assert_near(hi.y, 32.0, 1e-9);
    assert_near(hi.x - lo.x, 40.0, 1e-9);
    assert_near(hi.z - lo.z, 40.0, 1e-9);
    let p = printed(&run_on(
        &format!(
            "Init --> union {{ Envelope | Sphere }} print(geometry.volume) print(geometry.isClosedSurface) X.\n{MASS}"
        ),
        40.0,
    ));
    let vu = p[0];
    assert_eq!(p[1], 1.0);
    let p = printed(&run_on(
        &format!("Init --> inline Sphere print(geometry.volume) X.\n{MASS}"),
        40.0,
    ));
    let v_sph = p[0];
    // The 16 × 16 polygon sphere is a little smaller than the ellipsoid.
    let ellipsoid = std::f64::consts::PI / 6.0 * 40.0 * 40.0 * 80.0;
    assert!(v_sph > 0.9 * ellipsoid && v_sph < ellipsoid, "{v_sph}");
    assert_near(vu + vi, 64000.0 + v_sph, 1e-6 * vu);
    // Cut off: the bottom (y < 0) and the ends beyond the lot in z.
    assert!(vi > 0.4 * v_sph && vi < 0.8 * v_sph, "{vi} of {v_sph}");
}

/// Steps 2 to 4 run through: the intersection split in two halves unified
/// again, a cylinder subtracted (it takes volume away), and the tag-based
/// `comp` of step 4 (no tags here: no face selected).
#[test]
fn mass_modeling_split_unify_subtract() {
    let steps = "
Init -->
    intersect { Envelope | Sphere }
    print(geometry.volume)
    inline(unify) split(y) { ~1: LowerHalf
                           | 20: UpperHalf }
    print(geometry.volume)
    subtract { CurrentMass. | Hole }
    print(geometry.volume)
    X.
LowerHalf --> X.
UpperHalf --> t(10, 0, 0)
              r(scopeCenter, 0, 7.2, 0)
Hole -->
    s(16, 16, '1.2)
    center(z)
    t(30, 5, 0)
    rotateScope(-90, 0, 0)
    primitiveCylinder
";
    let g = run_on(&format!("{steps}\n{MASS}"), 40.0);
    let p = printed(&g);
    // Unifying the halves keeps the volume.
    assert_near(p[1], p[0], 1e-6 * p[0]);
    assert!(p[2] < p[1] && p[2] > 0.0, "{p:?}");
}

// ---------------------------------------------------------------------------
// Boolean 3D and auto-tags
// ---------------------------------------------------------------------------

/// The extruded lot minus a moved and rotated copy of itself; the removed
/// part is what `intersect` with the same operands keeps.
#[test]
fn subtract_a_rotated_copy() {
    let b = "t(20, -15, -15) rotate(rel, scope, 15, 12, 25)";
    let rules = format!(
        "Init --> extrude(40) S I
S --> subtract {{ Mass. | {b} }} print(geometry.volume) print(geometry.isClosedSurface) X.
I --> intersect {{ Mass. | {b} }} print(geometry.volume) print(geometry.isClosedSurface) X.
"
    );
    let g = run_on(&rules, 30.0);
    let p = printed(&g);
    assert_near(p[0] + p[2], 30.0 * 30.0 * 40.0, 1e-6);
    assert!(p[2] > 1000.0, "{p:?}");
    assert_eq!(p[1], 1.0);
    assert_eq!(p[3], 1.0);
}

// ---------------------------------------------------------------------------
// Layout modeling
// ---------------------------------------------------------------------------

/// Step 1: a pentagon (in a 20 × 20 lot) united with a copy shrunk to
/// 10 × 10 and moved a third out to the front:
/// "the resulting geometry consists of 3 faces".
#[test]
fn layout_union_of_footprints() {
    let rules = "
Init -->
    primitiveDisk(5)
    print(geometry.area)
    union { HouseFootprint. | FrontyardFootprint }
    print(geometry.nFaces) print(geometry.area) X.
FrontyardFootprint -->
    s(10, 0, 10)
    center(x)
    t(0, 0, '-0.33)
";
    let g = run_on(rules, 20.0);
    let p = printed(&g);
    assert_eq!(p[1], 3.0);
    let (pentagon, union) = (p[0], p[2]);
    let m = single(&g);
    // All three faces in the lot's plane, facing up.
    assert!((0..3).all(|f| cga_geometry::measure::face_normal(m, f).y > 0.999));
    let (lo, hi) = mesh_bounds(m);
    assert_near(hi.y - lo.y, 0.0, 1e-9);
    // union + intersection = both areas; B is the pentagon shrunk from
    // 20 × 20 to 10 × 10 ("a shrunk copy"): a quarter of its area.
    let p = printed(&run_on(&rules.replace("union", "intersect"), 20.0));
    assert_eq!(p[1], 1.0);
    assert_near(union + p[2], pentagon * 1.25, 1e-6);
    assert!(p[2] > 1.0 && p[2] < pentagon / 4.0, "{p:?}");
}

// ---------------------------------------------------------------------------
// Behavior with open operands
// ---------------------------------------------------------------------------

/// Operand B is a cube without one face. Left: its opening (front) lies
/// outside A, B acts as the closed cube it bounds; the union is two
/// overlapping 10-cubes without B's front face. Right: the opening (left
/// face) lies inside A; this engine then treats B as the prism open to the
/// left (the region behind all its faces).
#[test]
fn open_cube_operand() {
    let rules = "
Lot   --> s(10,10,10) Left
Left  --> primitiveCube
          union { Blue
                | t(5,5,5)
                  comp(f) { front: NIL | all= Green } }
          print(geometry.area) print(geometry.isClosedSurface) print(geometry.nFaces) X.
";
    let p = printed(&run(rules));
    // Two 10-cubes overlapping by 5³: each loses 3 quarter faces inside the
    // other; B's front face is missing.
    assert_near(p[0], 2.0 * 600.0 - 2.0 * 75.0 - 100.0, 1e-6);
    assert_eq!(p[1], 0.0);
    assert_eq!(p[2], 11.0);
    let right = rules.replace("front: NIL", "left: NIL");
    let p = printed(&run(&right));
    // A loses what the prism (x < 15, 5 < y, z < 15) covers: halves of its
    // top and back faces, quarters of its left and right faces; B loses
    // the quarters of its bottom and front faces inside A.
    assert_near(p[0], (600.0 - 100.0 - 50.0) + (500.0 - 50.0), 1e-6);
    assert_eq!(p[1], 0.0);
}

/// Operand B is a quad. Left: the 12 × 12 quad through the middle of the
/// cube cuts it fully: "everything below the plane is regarded as inside
/// and thus disappears". Right: the quad (12 × 10, moved) only partially
/// cuts the cube; this engine still treats it as the half-space below it.
#[test]
fn plane_operand() {
    let rules = "
Lot   --> s(10,10,10) Left
Left  --> primitiveCube
          union { Blue
                | primitiveQuad
                  s(12,0,12)
                  center(xyz)
                  Green }
          print(geometry.area) print(geometry.nFaces) X.
";
    let g = run(rules);
    let p = printed(&g);
    // The quad with the cube's section cut out, and the upper half of the cube.
    assert_near(p[0], 144.0 - 100.0 + 100.0 + 4.0 * 50.0, 1e-6);
    assert_eq!(p[1], 6.0);
    let (lo, hi) = g.bounds();
    assert_near(hi.y - lo.y, 5.0, 1e-9);
    assert_near(hi.x - lo.x, 12.0, 1e-9);
    let c = colors(single(&g));
    assert_eq!(c.iter().filter(|&&c| c == BLUE).count(), 5);
    assert_eq!(c.iter().filter(|&&c| c == GREEN).count(), 1);

    let right = rules.replace(
        "s(12,0,12)\n                  center(xyz)",
        "s(12,0,10)\n                  t(-1,5,2)",
    );
    let g = run(&right);
    let p = printed(&g);
    // 12 × 10 minus the cube's 10 × 8 section under it.
    assert_near(p[0], 120.0 - 80.0 + 100.0 + 4.0 * 50.0, 1e-6);
}

// ---------------------------------------------------------------------------
// Errors
// ---------------------------------------------------------------------------

#[test]
fn one_operand_is_an_error() {
    let g = gen_with(
        "Lot --> s(1,1,1) union { primitiveCube } X.\n",
        &Opts::rect(10.0, 10.0),
    );
    assert!(g
        .errors
        .first()
        .is_some_and(|e| e.message.contains("needs two operands")));
}

/// cga_componentTags, Boolean auto-tags: after `subtract { Cube | Sphere }`
/// the cube's six (cut) faces are `bool.A`, the sphere's faces left inside
/// the cube are `bool.B`, and together they are the whole surface.
#[test]
fn boolean_auto_tags() {
    let src = "Lot --> s(10, 10, 10) Left\n\
               Left --> subtract { Cube | Sphere } print(\"total \" + geometry.area)\n    \
               comp(f) { isTagged(\"bool.A\") : print(\"A \" + geometry.area) | isTagged(\"bool.B\") : print(\"B \" + geometry.area) }\n\
               Cube   --> primitiveCube\n\
               Sphere --> t(3,3,3) primitiveSphere\n";
    let g = gen(src).ok();
    let p = g.prints();
    let sum = |k: &str| -> (usize, f64) {
        let v: Vec<f64> = p
            .iter()
            .filter(|l| l.starts_with(k))
            .map(|l| numbers(l)[0])
            .collect();
        (v.len(), v.iter().sum())
    };
    let (na, aa) = sum("A ");
    let (nb, ab) = sum("B ");
    let (_, total) = sum("total ");
    assert_eq!(na, 6);
    assert!(nb > 0);
    assert!(ab > 0.0 && aa < 600.0, "{aa} {ab}");
    assert!(
        (aa + ab - total).abs() < 1e-6 * total,
        "{aa} + {ab} vs {total}"
    );
}
