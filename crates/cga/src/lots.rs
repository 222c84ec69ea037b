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
}
