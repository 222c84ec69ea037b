//! Lots: the initial shapes a generation starts from, made in code or read
//! from files by the same specifications the `cga` command takes.

use std::path::Path;

use cga_geometry::DVec3;

pub use cga_engine::geo::GeoOrigin;
pub use cga_engine::lot::Lot;

use crate::Error;

/// Lots read from specifications, and where their frame lies on the globe
/// when some were given in longitude/latitude.
#[derive(Default)]
pub struct LotSet {
    pub lots: Vec<Lot>,
    /// The geographic origin of the lots' metric frame: every geographic
    /// file is projected about the first one's origin, so they share it.
    pub origin: Option<GeoOrigin>,
    /// What reading said on the way (geographic data projected, ...), for
    /// the user.
    pub notes: Vec<String>,
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
/// grid), an `.obj` file (each face one lot), a `.geojson`/`.json` or
/// `.fgb` file (each polygon one lot, feature properties as attributes;
/// longitude/latitude projected to metres). No specification: `rect:20,30`.
pub fn read(specs: &[impl AsRef<str>]) -> Result<LotSet, Error> {
    let mut set = LotSet::default();
    if specs.is_empty() {
        set.lots.push(rect(20.0, 30.0));
        return Ok(set);
    }
    for spec in specs {
        let spec = spec.as_ref();
        if let Some(r) = spec.strip_prefix("rect:") {
            set.lots
                .push(cga_engine::lot::parse_rect(r).map_err(Error::Lot)?);
            continue;
        }
        if let Some(grid) = spec.strip_prefix("grid:") {
            set.lots.extend(grid_lots(grid)?);
            continue;
        }
        let path = Path::new(spec);
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase());
        let more = match ext.as_deref() {
            Some("obj") => cga_engine::lot::from_obj(path),
            Some(ext @ ("geojson" | "json" | "fgb")) => {
                let read = if ext == "fgb" {
                    cga_engine::lot::from_flatgeobuf(path, set.origin)
                } else {
                    cga_engine::lot::from_geojson_georeferenced(path, set.origin)
                };
                read.map(|(lots, origin)| {
                    if let Some(o) = origin {
                        set.notes.push(format!(
                            "{} is in longitude/latitude; lots are in metres east (x) and north (-z) of lon {:.7}, lat {:.7} (recorded in the output)",
                            path.display(),
                            o.lon,
                            o.lat
                        ));
                        set.origin = Some(o);
                    }
                    lots
                })
            }
            _ => {
                return Err(Error::Lot(format!(
                    "unknown lot `{spec}`: expected rect:W,D, grid:COLSxROWS, an .obj, a .geojson or a .fgb (FlatGeobuf) file"
                )))
            }
        };
        set.lots.extend(more.map_err(Error::Lot)?);
    }
    Ok(set)
}

/// `grid:COLSxROWS` (20 x 30 lots) or `grid:COLSxROWS:LOTS.obj` (copies of
/// the OBJ's lots): a synthetic city of lots in a grid, for benchmarks.
fn grid_lots(spec: &str) -> Result<Vec<Lot>, Error> {
    let (dims, source) = match spec.split_once(':') {
        Some((d, s)) => (d, Some(s)),
        None => (spec, None),
    };
    let bad = || {
        Error::Lot(format!(
            "expected grid:COLSxROWS[:LOTS.obj], found `grid:{spec}`"
        ))
    };
    let (c, r) = dims.split_once('x').ok_or_else(bad)?;
    let cols: usize = c.trim().parse().map_err(|_| bad())?;
    let rows: usize = r.trim().parse().map_err(|_| bad())?;
    if cols == 0 || rows == 0 || cols.saturating_mul(rows) > 10_000_000 {
        return Err(bad());
    }
    let base = match source {
        Some(path) => cga_engine::lot::from_obj(Path::new(path)).map_err(Error::Lot)?,
        None => vec![rect(20.0, 30.0)],
    };
    let (lo, hi) = base
        .iter()
        .filter_map(|l| cga_geometry::measure::bounds(&l.mesh))
        .fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), (a, b)| (lo.min(a), hi.max(b)),
        );
    let step = (hi - lo) + DVec3::splat(10.0);
    let mut lots = Vec::with_capacity(cols * rows * base.len());
    for row in 0..rows {
        for col in 0..cols {
            let shift = DVec3::new(col as f64 * step.x, 0.0, -(row as f64) * step.z);
            for b in &base {
                let mut l = b.clone();
                l.mesh.map_positions(|p| p + shift);
                l.name = format!("grid {col},{row} {}", b.name);
                lots.push(l);
            }
        }
    }
    Ok(lots)
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
