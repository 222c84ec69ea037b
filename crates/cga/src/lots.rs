//! Lots: the initial shapes a generation starts from, made in code or read
//! from files by the same specifications the `cga` command takes.

use cga_geometry::DVec3;

pub use cga_engine::geo::GeoOrigin;
use cga_engine::gis::Message;
pub use cga_engine::gis::{CrsOption, InvalidPolicy, LotOptions};
pub use cga_engine::lot::Lot;

use crate::Error;

/// Lots read from specifications, and where their frame lies on the globe
/// when some were georeferenced.
#[derive(Default)]
pub struct LotSet {
    pub lots: Vec<Lot>,
    /// The geographic origin of the lots' metric frame (a transverse
    /// Mercator projection on WGS84 centred on all georeferenced lots; see
    /// [`GeoOrigin::proj_string`]).
    pub origin: Option<GeoOrigin>,
    /// What reading said on the way (each file's coordinate reference
    /// system, the frame), for the user.
    pub notes: Vec<String>,
    /// What the user should look at: features that gave no lot, invalid
    /// lots and what was done with them, files without a declared CRS.
    pub warnings: Vec<String>,
}

/// Where a model of `lots` is best written from
/// ([`ExportOptions::origin`](crate::ExportOptions::origin)): the centre of
/// the lots' box in the ground plane, in whole metres, when it lies more
/// than [`FAR_FROM_ORIGIN`] metres from the frame's origin (lots in a
/// national grid's metres); `None` nearer, where 32-bit floats keep a
/// tenth of a millimetre and the model's coordinates stay the lots' own.
pub fn local_origin(lots: &[Lot]) -> Option<DVec3> {
    let mut points = lots.iter().flat_map(|l| l.mesh.positions.iter());
    let first = *points.next()?;
    let (lo, hi) = points.fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    origin_of_box(lo, hi)
}

/// [`local_origin`] of the box `lo`..`hi` (of models or lots).
pub fn origin_of_box(lo: DVec3, hi: DVec3) -> Option<DVec3> {
    let centre = (lo + hi) / 2.0;
    let centre = DVec3::new(centre.x.round(), 0.0, centre.z.round());
    (centre.is_finite() && centre.x.abs().max(centre.z.abs()) > FAR_FROM_ORIGIN).then_some(centre)
}

/// How far from the frame's origin (metres) lots must lie for
/// [`local_origin`] to move the model's origin to them.
pub const FAR_FROM_ORIGIN: f64 = 1000.0;

/// The lot `(0,0,0) (w,0,0) (w,0,-d) (0,0,-d)`: a `w` × `d` rectangle in
/// the x–z plane whose first edge (the street front) runs along x.
pub fn rect(w: f64, d: f64) -> Lot {
    cga_engine::lot::rect(w, d)
}

/// A lot with the outline `points` (counter-clockwise seen from above, in
/// the x–z plane for flat lots; y is up).
pub fn polygon(name: impl Into<String>, points: &[DVec3]) -> Lot {
    Lot {
        name: name.into(),
        mesh: cga_geometry::Mesh::polygon(points),
        attrs: Vec::new(),
        geo_origin: None,
    }
}

/// How the coordinates of rings given to [`from_rings`] are meant.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axes {
    /// As GIS data has them: x east, y north, z up (z may be left 0). A
    /// point `(x, y, z)` is the engine's `(x, z, -y)`, as for lots read
    /// from GIS files with `--crs local`.
    Gis,
    /// The engine's own: y up, lots in the x–z plane (CityEngine's and
    /// PyPRT's initial shape vertices).
    Engine,
}

/// A lot from rings of points: the outer ring first, then its holes. A
/// ring may repeat its first point at its end (as GeoJSON and shapely
/// write them). The outer ring is made counter-clockwise seen from above
/// and the holes clockwise, whatever their order (the engine's
/// convention); the first edge stays the street front. `Err` says what is
/// wrong with the rings (no rings, a ring of fewer than 3 distinct
/// points, a coordinate that is not finite), for hosts that take lots
/// from their users (the Python package).
pub fn from_rings(
    name: impl Into<String>,
    rings: &[Vec<[f64; 3]>],
    axes: Axes,
) -> Result<Lot, String> {
    from_polygons(name, std::slice::from_ref(&rings.to_vec()), axes)
}

/// A lot of several polygons (a GIS MultiPolygon), each one face of the
/// lot's initial shape (as CityEngine makes shapes of several faces), each
/// given and checked as [`from_rings`] says; the first polygon's first
/// edge is the street front.
pub fn from_polygons(
    name: impl Into<String>,
    polygons: &[Vec<Vec<[f64; 3]>>],
    axes: Axes,
) -> Result<Lot, String> {
    if polygons.is_empty() {
        return Err("a lot needs at least one polygon".into());
    }
    let mut mesh = cga_geometry::Mesh::new();
    for (k, rings) in polygons.iter().enumerate() {
        let polygon = if polygons.len() > 1 {
            format!("polygon {k}: ")
        } else {
            String::new()
        };
        if rings.is_empty() {
            return Err(format!("{polygon}a lot needs an outer ring"));
        }
        let mut loops: Vec<Vec<u32>> = Vec::with_capacity(rings.len());
        for (r, ring) in rings.iter().enumerate() {
            let what = if r == 0 {
                format!("{polygon}the outer ring")
            } else {
                format!("{polygon}hole {r}")
            };
            if let Some(p) = ring.iter().find(|p| p.iter().any(|c| !c.is_finite())) {
                return Err(format!(
                    "{what} has a coordinate that is not a finite number: ({}, {}, {})",
                    p[0], p[1], p[2]
                ));
            }
            // Repeated points (the closing one GeoJSON and shapely write,
            // doubled vertices) are one corner.
            let mut points: Vec<[f64; 3]> = Vec::with_capacity(ring.len());
            for p in ring {
                if points.last() != Some(p) {
                    points.push(*p);
                }
            }
            while points.len() > 1 && points.first() == points.last() {
                points.pop();
            }
            if points.len() < 3 {
                return Err(format!(
                    "{what} has {} distinct point{}; a lot needs at least 3",
                    points.len(),
                    if points.len() == 1 { "" } else { "s" }
                ));
            }
            let start = mesh.positions.len() as u32;
            mesh.positions.extend(points.iter().map(|p| match axes {
                Axes::Gis => DVec3::new(p[0], p[2], -p[1]),
                Axes::Engine => DVec3::new(p[0], p[1], p[2]),
            }));
            loops.push((start..mesh.positions.len() as u32).collect());
        }
        for (i, l) in loops.iter_mut().enumerate() {
            // Twice the signed area in the x-z plane seen from +y: positive
            // is counter-clockwise. Vertical rings (zero area) stay as given.
            let mut a = 0.0;
            for k in 0..l.len() {
                let p = mesh.positions[l[k] as usize];
                let q = mesh.positions[l[(k + 1) % l.len()] as usize];
                a += p.z * q.x - p.x * q.z;
            }
            if a != 0.0 && (i == 0) != (a > 0.0) {
                // Reversed after the first point, so the first edge is kept.
                l[1..].reverse();
            }
        }
        let refs: Vec<&[u32]> = loops.iter().map(|l| l.as_slice()).collect();
        mesh.add_face(&refs, 0);
    }
    Ok(Lot {
        name: name.into(),
        mesh,
        attrs: Vec::new(),
        geo_origin: None,
    })
}

/// Lots from specifications as the `cga` command takes them (`--lot`):
/// `rect:W,D`, `grid:COLSxROWS[:LOTS.obj]` (a synthetic city of lots in a
/// grid), an `.obj` file (each face one lot), or a GIS file: `.geojson`,
/// `.json`, `.fgb`, `.gpkg` or `.shp` (each feature one lot, feature
/// properties as attributes, projected into one local metric frame when
/// georeferenced; see `docs/geographic.md`). No specification:
/// `rect:20,30`. Each file's own CRS, invalid lots repaired: see
/// [`read_with`].
pub fn read(specs: &[impl AsRef<str>]) -> Result<LotSet, Error> {
    read_with(specs, &LotOptions::default())
}

/// [`read`] with a CRS for every lot file (`--crs`) and what to do with
/// invalid lots (`--invalid`).
pub fn read_with(specs: &[impl AsRef<str>], options: &LotOptions) -> Result<LotSet, Error> {
    read_in(&crate::DiskWorld, specs, options)
}

/// [`read_with`], every lot file read through `world` (see
/// [`Engine::read_lots`](crate::Engine::read_lots)).
pub fn read_in(
    world: &dyn crate::World,
    specs: &[impl AsRef<str>],
    options: &LotOptions,
) -> Result<LotSet, Error> {
    let specs: Vec<String> = specs.iter().map(|s| s.as_ref().to_string()).collect();
    let read = cga_engine::gis::read_lots_in(world, &specs, options).map_err(Error::Lot)?;
    let mut set = LotSet {
        lots: read.lots,
        origin: read.frame,
        ..LotSet::default()
    };
    for m in read.messages {
        match m {
            Message::Note(n) => set.notes.push(n),
            Message::Warning(w) => set.warnings.push(w),
        }
    }
    Ok(set)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn specifications_make_lots() {
        let set = read(&["rect:10,5", "grid:3x2"]).unwrap();
        assert_eq!(set.lots.len(), 7);
        assert!(set.origin.is_none());
        let (lo, hi) = cga_geometry::measure::bounds(&set.lots[0].mesh).unwrap();
        assert_eq!(
            (lo, hi),
            (DVec3::new(0.0, 0.0, -5.0), DVec3::new(10.0, 0.0, 0.0))
        );
        // Grid lots are 20 x 30 apart by 10 m.
        let (lo, _) = cga_geometry::measure::bounds(&set.lots[2].mesh).unwrap();
        assert_eq!(lo.x, 30.0);
        assert_eq!(read(&[] as &[&str]).unwrap().lots.len(), 1);
        for bad in ["rect:1", "grid:0x3", "grid:2y3", "lots.shp.txt"] {
            assert!(matches!(read(&[bad]), Err(Error::Lot(_))), "{bad}");
        }
    }

    #[test]
    fn rings_make_lots_with_holes_in_either_orientation() {
        let area = |lot: &Lot| cga_geometry::measure::mesh_area(&lot.mesh);
        // GIS axes, clockwise outer ring closed as GeoJSON writes it, a
        // counter-clockwise hole: 10 x 10 minus 2 x 2.
        let outer = vec![
            [0.0, 0.0, 0.0],
            [0.0, 10.0, 0.0],
            [10.0, 10.0, 0.0],
            [10.0, 0.0, 0.0],
            [0.0, 0.0, 0.0],
        ];
        let hole = vec![
            [4.0, 4.0, 0.0],
            [6.0, 4.0, 0.0],
            [6.0, 6.0, 0.0],
            [4.0, 6.0, 0.0],
        ];
        let lot = from_rings("a", &[outer.clone(), hole], Axes::Gis).unwrap();
        assert!((area(&lot) - 96.0).abs() < 1e-9);
        assert_eq!(lot.mesh.positions.len(), 8);
        // North is -z; the first point stays first.
        assert_eq!(lot.mesh.positions[0], DVec3::ZERO);
        let (lo, hi) = cga_geometry::measure::bounds(&lot.mesh).unwrap();
        assert_eq!(
            (lo, hi),
            (DVec3::new(0.0, 0.0, -10.0), DVec3::new(10.0, 0.0, 0.0))
        );
        // Seen from above (+y) the outer ring is counter-clockwise: the
        // face normal points up.
        let n = cga_geometry::measure::face_normal(&lot.mesh, 0);
        assert!(n.y > 0.99, "{n:?}");
        // Engine axes are taken as they are.
        let e = from_rings(
            "b",
            &[vec![[0.0, 0.0, 0.0], [4.0, 0.0, 0.0], [4.0, 0.0, -3.0]]],
            Axes::Engine,
        )
        .unwrap();
        assert!((area(&e) - 6.0).abs() < 1e-12);
        assert_eq!(e.mesh.positions[1], DVec3::new(4.0, 0.0, 0.0));
    }

    #[test]
    fn bad_rings_say_what_is_wrong() {
        let nan = from_rings(
            "a",
            &[vec![[0.0, 0.0, 0.0], [f64::NAN, 1.0, 0.0], [1.0, 1.0, 0.0]]],
            Axes::Gis,
        );
        assert!(nan.unwrap_err().contains("not a finite number"));
        let two = from_rings(
            "a",
            &[vec![[0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 0.0, 0.0]]],
            Axes::Gis,
        );
        assert_eq!(
            two.unwrap_err(),
            "the outer ring has 2 distinct points; a lot needs at least 3"
        );
        let hole = from_rings(
            "a",
            &[
                vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]],
                vec![],
            ],
            Axes::Gis,
        );
        assert_eq!(
            hole.unwrap_err(),
            "hole 1 has 0 distinct points; a lot needs at least 3"
        );
        assert!(from_rings("a", &[], Axes::Gis).is_err());
        let square = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]];
        let e = from_polygons(
            "m",
            &[vec![square.clone()], vec![square[..2].to_vec()]],
            Axes::Gis,
        );
        assert_eq!(
            e.unwrap_err(),
            "polygon 1: the outer ring has 2 distinct points; a lot needs at least 3"
        );
        let two = from_polygons("m", &[vec![square.clone()], vec![square]], Axes::Gis).unwrap();
        assert_eq!(two.mesh.faces.len(), 2);
    }
}
