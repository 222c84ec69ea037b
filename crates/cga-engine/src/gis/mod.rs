//! Lots from GIS files: GeoJSON, FlatGeobuf, GeoPackage and Shapefile,
//! in any coordinate reference system, projected into one local metric
//! frame (see [`crate::geo`]), validated and repaired.
//!
//! Reading streams features: a file is never held whole in memory, only
//! the polygons, names and attributes of its lots. Every feature is
//! accounted for: polygons (also inside GeometryCollections and
//! MultiPolygons) are lots, everything else is counted and named in one
//! warning per file.
//!
//! The CRS of a file is, first, `--crs`; else what the file declares;
//! else, for coordinates within longitude/latitude ranges, WGS84
//! longitude/latitude (what RFC 7946 makes GeoJSON); else the
//! coordinates are taken as metres of a plane of their own, with a
//! warning. Nothing is decided from how far the data spans.

pub mod crs;
pub mod feature;
pub mod fgb;
pub mod geojson;
pub mod gpkg;
pub mod shp;
pub mod validate;

use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use cga_geometry::{DVec2, DVec3, Mesh};
use cga_value::Value;

use crate::geo::{GeoExtent, GeoOrigin};
use crate::lot::Lot;
pub use crs::CrsOption;
use crs::{Declared, Resolved};
use feature::{Feature, Place, Polygon, Skipped};
pub use validate::InvalidPolicy;

/// How lot files are read.
#[derive(Clone, Debug, Default)]
pub struct LotOptions {
    /// `--crs`: the CRS of every lot file, whatever they declare.
    pub crs: Option<CrsOption>,
    /// `--invalid`: what to do with invalid lots.
    pub invalid: InvalidPolicy,
    /// `--split-multipolygons`: each polygon of a feature is a lot of its
    /// own (`ID`, `ID.1`, ...). Without it a feature is one lot, its
    /// polygons the faces of one initial shape, as CityEngine imports a
    /// MultiPolygon.
    pub split_multipolygons: bool,
}

/// Something to tell the user about the lots.
#[derive(Clone, Debug, PartialEq)]
pub enum Message {
    Note(String),
    Warning(String),
}

/// The lots of all `--lot` options, in order.
#[derive(Debug, Default)]
pub struct LotSet {
    pub lots: Vec<Lot>,
    /// The local frame the georeferenced lots were projected into.
    pub frame: Option<GeoOrigin>,
    pub messages: Vec<Message>,
}

/// Invalid lots named one by one in warnings at most; the rest are counted.
const NAMED_INVALID: usize = 20;

/// The lot file formats, by extension.
fn is_gis_file(ext: &str) -> bool {
    matches!(ext, "geojson" | "json" | "fgb" | "gpkg" | "shp")
}

/// The warning for the lots of an OBJ file whose normal points down (wound
/// clockwise seen from above): CityEngine keeps them as they are, so their
/// extrusions go down, which is rarely what was meant.
fn clockwise_warning(path: &Path, lots: &[Lot]) -> Option<String> {
    let down: Vec<usize> = lots
        .iter()
        .enumerate()
        .filter(|(_, lot)| {
            lot.mesh.faces.len() == 1 && cga_geometry::measure::face_normal(&lot.mesh, 0).y < -1e-9
        })
        .map(|(i, _)| i)
        .collect();
    if down.is_empty() {
        return None;
    }
    const SHOWN: usize = 10;
    let mut names: Vec<String> = down
        .iter()
        .take(SHOWN)
        .map(|i| format!("face {i}"))
        .collect();
    if down.len() > SHOWN {
        names.push(format!("and {} more", down.len() - SHOWN));
    }
    Some(format!(
        "{}: {} of {} lots are wound clockwise (their normal points down, so extrusions go down, as in CityEngine): {}; reverse their vertex order to build upwards",
        path.display(),
        down.len(),
        lots.len(),
        names.join(", ")
    ))
}

/// Reads the lots of `--lot` options: `rect:W,D`, `grid:COLSxROWS[:LOTS.obj]`,
/// an `.obj` file, or a GIS file (`.geojson`, `.json`, `.fgb`, `.gpkg`,
/// `.shp`). Without any, the 20 x 30 rectangle. Errors are for the user
/// (a usage error: the command's status 2).
pub fn read_lots(specs: &[String], options: &LotOptions) -> Result<LotSet, String> {
    read_lots_in(&cga_world::DiskWorld, specs, options)
}

/// [`read_lots`] with every file read through `world` (a GeoPackage must
/// still be a file on disk: SQLite opens it by its path).
pub fn read_lots_in(
    world: &dyn cga_world::World,
    specs: &[String],
    options: &LotOptions,
) -> Result<LotSet, String> {
    if specs.is_empty() {
        return Ok(LotSet {
            lots: vec![crate::lot::rect(20.0, 30.0)],
            ..LotSet::default()
        });
    }
    let mut reader = Reader::new(options)?;
    // Lots in order: ready ones, and places for the GIS lots, which are
    // made once every file is read (they share one frame).
    let mut parts: Vec<Result<Vec<Lot>, std::ops::Range<usize>>> = Vec::new();
    for spec in specs {
        if let Some(rect) = spec.strip_prefix("rect:") {
            parts.push(Ok(vec![crate::lot::parse_rect(rect)?]));
            continue;
        }
        if let Some(grid) = spec.strip_prefix("grid:") {
            parts.push(Ok(crate::lot::grid_in(world, grid)?));
            continue;
        }
        let path = Path::new(spec);
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase())
            .unwrap_or_default();
        if ext == "obj" {
            let lots = crate::lot::from_obj_in(world, path)?;
            if let Some(w) = clockwise_warning(path, &lots) {
                reader.messages.push(Message::Warning(w));
            }
            parts.push(Ok(lots));
        } else if is_gis_file(&ext) {
            let start = reader.pending.len();
            reader.read_file(world, path, &ext)?;
            parts.push(Err(start..reader.pending.len()));
        } else {
            return Err(format!(
                "unknown lot `{spec}`: expected rect:W,D, grid:COLSxROWS, an .obj, .geojson, .fgb (FlatGeobuf), .gpkg (GeoPackage) or .shp (Shapefile) file"
            ));
        }
    }
    let made = reader.finish()?;
    let mut set = LotSet {
        lots: Vec::new(),
        frame: made.frame,
        messages: made.messages,
    };
    // Where each pending polygon's lots start in `made.lots`.
    let mut starts = Vec::with_capacity(made.counts.len() + 1);
    starts.push(0usize);
    for &n in &made.counts {
        starts.push(starts[starts.len() - 1] + n as usize);
    }
    if let [Err(range)] = parts.as_slice() {
        // Only GIS files: their lots are the set, without a copy.
        if range.start == 0 && range.end == made.counts.len() {
            set.lots = made.lots;
            return Ok(set);
        }
    }
    let total = parts
        .iter()
        .map(|p| match p {
            Ok(lots) => lots.len(),
            Err(range) => starts[range.end] - starts[range.start],
        })
        .sum();
    set.lots.reserve_exact(total);
    let mut made_lots = made.lots.into_iter();
    for part in parts {
        match part {
            Ok(lots) => set.lots.extend(lots),
            Err(range) => set.lots.extend(
                made_lots
                    .by_ref()
                    .take(starts[range.end] - starts[range.start]),
            ),
        }
    }
    Ok(set)
}

/// A feature's polygon on its way to being a lot.
struct Pending {
    source: u32,
    place: Place,
    name: String,
    attrs: Vec<(Arc<str>, Value)>,
    polygon: Polygon,
}

/// A file (or a GeoPackage table) and the CRS of its coordinates.
struct Source {
    label: Arc<str>,
    declared: Option<Declared>,
    crs: Option<Resolved>,
}

/// Reads GIS files, then makes their lots in one frame.
pub struct Reader {
    options: LotOptions,
    forced: Option<Resolved>,
    sources: Vec<Source>,
    pending: Vec<Pending>,
    messages: Vec<Message>,
    /// Property names, one allocation each for all lots.
    names: HashMap<String, Arc<str>>,
}

/// What [`Reader::finish`] made: the lots of all pending polygons in
/// order, and how many each gave (none, one, or the pieces of a repair).
struct Made {
    lots: Vec<Lot>,
    counts: Vec<u32>,
    frame: Option<GeoOrigin>,
    messages: Vec<Message>,
}

impl Reader {
    pub fn new(options: &LotOptions) -> Result<Reader, String> {
        let forced = options.crs.as_ref().map(crs::resolve_option).transpose()?;
        Ok(Reader {
            options: options.clone(),
            forced,
            sources: Vec::new(),
            pending: Vec::new(),
            messages: Vec::new(),
            names: HashMap::new(),
        })
    }

    /// Reads one file's features.
    fn read_file(
        &mut self,
        world: &dyn cga_world::World,
        path: &Path,
        ext: &str,
    ) -> Result<(), String> {
        let label: Arc<str> = Arc::from(path.display().to_string());
        let first_source = self.sources.len();
        let mut skipped = Skipped::default();
        let pending = &mut self.pending;
        let names = &mut self.names;
        // The source (file or table) and feature index being read.
        let source = std::cell::Cell::new(first_source as u32);
        let index = std::cell::Cell::new(0usize);
        let mut add = |f: Feature, label: &Arc<str>| {
            add_feature(
                f,
                source.get(),
                label,
                index.get(),
                names,
                pending,
                &mut skipped,
            );
            index.set(index.get() + 1);
        };
        if ext == "gpkg" {
            let layers = std::cell::RefCell::new(Vec::new());
            gpkg::read(
                world,
                path,
                &mut |layer| {
                    let mut layers = layers.borrow_mut();
                    layers.push(Source {
                        label: Arc::from(format!("{label} table {}", layer.table)),
                        declared: layer.crs.clone(),
                        crs: None,
                    });
                    source.set((first_source + layers.len() - 1) as u32);
                    index.set(0);
                },
                &mut |f| {
                    let l = layers
                        .borrow()
                        .last()
                        .map_or(label.clone(), |s: &Source| s.label.clone());
                    add(f, &l)
                },
            )?;
            self.sources.extend(layers.into_inner());
        } else {
            let sink = &mut |f| add(f, &label);
            let declared = match ext {
                "fgb" => fgb::read(world, path, sink)?,
                "shp" => shp::read(world, path, sink)?,
                _ => geojson::read(world, path, sink)?,
            };
            self.sources.push(Source {
                label: label.clone(),
                declared,
                crs: None,
            });
        }
        let skipped = skipped.warning(&label);
        let lots_read = self
            .pending
            .iter()
            .rev()
            .take_while(|p| p.source as usize >= first_source)
            .count();
        if lots_read == 0 {
            return Err(format!(
                "{label} has no polygons to use as lots{}",
                skipped.map(|w| format!(" ({w})")).unwrap_or_default()
            ));
        }
        if let Some(w) = skipped {
            self.messages.push(Message::Warning(w));
        }
        for s in first_source..self.sources.len() {
            self.resolve_source(s)?;
        }
        Ok(())
    }

    /// Decides a source's CRS and converts its coordinates to
    /// longitude/latitude (degrees) when it is on the globe.
    fn resolve_source(&mut self, s: usize) -> Result<(), String> {
        let source = &self.sources[s];
        let label = source.label.clone();
        let mine = || self.pending.iter().filter(move |p| p.source as usize == s);
        let in_lonlat_range = |p: &Pending| {
            p.polygon
                .iter()
                .flatten()
                .all(|q| (-180.0..=180.0).contains(&q.x) && (-90.0..=90.0).contains(&q.y))
        };
        let resolved = match (&self.forced, &source.declared) {
            (Some(forced), _) => forced.clone(),
            (None, Some(declared)) => {
                crs::resolve_declared(declared).map_err(|e| format!("{label}: {e}"))?
            }
            (None, None) => {
                if mine().all(in_lonlat_range) {
                    if !label.ends_with(".geojson") && !label.ends_with(".json") {
                        self.messages.push(Message::Warning(format!(
                            "{label} declares no coordinate reference system; its coordinates are within longitude/latitude ranges and are read as WGS84 longitude/latitude (give --crs EPSG:N or --crs local to say otherwise)"
                        )));
                    }
                    crs::wgs84()
                } else {
                    self.messages.push(Message::Warning(format!(
                        "{label} declares no coordinate reference system and its coordinates are not longitude/latitude: they are used as metres, not georeferenced (give --crs EPSG:N to place them on the globe)"
                    )));
                    Resolved::Local
                }
            }
        };
        if resolved.is_geographic() {
            if let Some(p) = mine().find(|p| !in_lonlat_range(p)) {
                return Err(format!(
                    "{}: coordinates outside longitude/latitude ranges in a geographic CRS ({}); give --crs EPSG:N for the CRS they are in",
                    p.place,
                    resolved.name()
                ));
            }
        }
        if let Resolved::Geo { proj, name } = &resolved {
            let wgs84 = crate::geo::wgs84();
            let to_radians = proj.is_latlong();
            for p in self.pending.iter_mut().filter(|p| p.source as usize == s) {
                for q in p.polygon.iter_mut().flatten() {
                    let mut xyz = if to_radians {
                        (q.x.to_radians(), q.y.to_radians(), 0.0)
                    } else {
                        (q.x, q.y, 0.0)
                    };
                    proj4rs::transform::transform(proj, &wgs84, &mut xyz).map_err(|e| {
                        format!(
                            "{}: ({}, {}) cannot be converted from {name}: {e}",
                            p.place, q.x, q.y
                        )
                    })?;
                    q.x = xyz.0.to_degrees();
                    q.y = xyz.1.to_degrees();
                }
            }
        }
        self.sources[s].crs = Some(resolved);
        Ok(())
    }

    /// Projects every georeferenced polygon into one frame centred on
    /// them, validates and repairs, and makes the lots.
    fn finish(self) -> Result<Made, String> {
        let mut messages = self.messages;
        let geo_sources: Vec<bool> = self
            .sources
            .iter()
            .map(|s| matches!(s.crs, Some(Resolved::Geo { .. })))
            .collect();
        let mut extent = GeoExtent::default();
        for p in &self.pending {
            if geo_sources[p.source as usize] {
                for q in p.polygon.iter().flatten() {
                    extent.add(q.x, q.y);
                }
            }
        }
        let frame = GeoOrigin::centred_on(&extent);
        let projection = frame.map(|f| f.proj()).transpose()?;
        for s in &self.sources {
            if let Some(crs @ Resolved::Geo { name, .. }) = &s.crs {
                let kind = if crs.is_geographic() {
                    "longitude/latitude"
                } else {
                    "projected"
                };
                messages.push(Message::Note(format!("{}: {name} ({kind})", s.label)));
            }
        }
        if let Some(f) = frame {
            let (w, h) = extent.span();
            messages.push(Message::Note(format!(
                "lots are in metres east (x) and north (-z) of lon {:.7}, lat {:.7} (transverse Mercator on WGS84, recorded in the output); the data spans {w:.4} x {h:.4} degrees",
                f.lon, f.lat
            )));
        }
        let wgs84 = crate::geo::wgs84();
        let mut lots = Vec::with_capacity(self.pending.len());
        let mut counts = Vec::with_capacity(self.pending.len());
        let mut invalid = 0usize;
        // The feature (source, index) whose lot was made last.
        let mut last_feature: Option<(u32, usize)> = None;
        for mut p in self.pending {
            let georeferenced = geo_sources[p.source as usize];
            if let (true, Some(tm)) = (georeferenced, &projection) {
                for q in p.polygon.iter_mut().flatten() {
                    let mut xyz = (q.x.to_radians(), q.y.to_radians(), 0.0);
                    proj4rs::transform::transform(&wgs84, tm, &mut xyz).map_err(|e| {
                        format!("{}: ({}, {}) cannot be projected: {e}", p.place, q.x, q.y)
                    })?;
                    q.x = xyz.0;
                    q.y = xyz.1;
                }
            }
            let checked = validate::check(std::mem::take(&mut p.polygon));
            if !checked.problems.is_empty() {
                let place_of =
                    |at: Option<DVec2>| match (at, georeferenced.then_some(frame).flatten()) {
                        (Some(a), Some(f)) => {
                            let (lon, lat) = f.to_geo(a.x, a.y);
                            format!(" near lon {lon:.7}, lat {lat:.7}")
                        }
                        (Some(a), None) => format!(" at ({}, {})", a.x, a.y),
                        (None, _) => String::new(),
                    };
                let problems: Vec<String> = checked
                    .problems
                    .iter()
                    .map(|pr| format!("{}{}", pr.what, place_of(pr.at)))
                    .collect();
                let outcome = match (self.options.invalid, checked.repaired.len()) {
                    (InvalidPolicy::Error, _) => {
                        return Err(format!(
                            "{}: lot `{}` is invalid: {} (--invalid error)",
                            p.place,
                            p.name,
                            problems.join("; ")
                        ))
                    }
                    (InvalidPolicy::Skip, _) | (InvalidPolicy::Repair, 0) => "left out".to_string(),
                    (InvalidPolicy::Repair, 1) => "repaired".to_string(),
                    (InvalidPolicy::Repair, n) if self.options.split_multipolygons => {
                        format!("repaired into {n} lots")
                    }
                    (InvalidPolicy::Repair, n) => format!("repaired into {n} polygons"),
                };
                invalid += 1;
                if invalid <= NAMED_INVALID {
                    messages.push(Message::Warning(format!(
                        "{}: lot `{}` is invalid ({}): {outcome}",
                        p.place,
                        p.name,
                        problems.join("; ")
                    )));
                }
                if self.options.invalid == InvalidPolicy::Skip {
                    counts.push(0);
                    continue;
                }
            }
            if !self.options.split_multipolygons {
                // One shape per feature: its polygons (and a repair's
                // pieces) are the faces of one lot.
                let feature = (p.source, p.place.index);
                if checked.repaired.is_empty() {
                    counts.push(0);
                    continue;
                }
                let lot = match lots.last_mut() {
                    Some(lot) if last_feature == Some(feature) => {
                        counts.push(0);
                        lot
                    }
                    _ => {
                        counts.push(1);
                        last_feature = Some(feature);
                        lots.push(Lot {
                            name: p.name.clone(),
                            mesh: Mesh::new(),
                            attrs: p.attrs,
                            geo_origin: if georeferenced { frame } else { None },
                        });
                        lots.last_mut().expect("just pushed")
                    }
                };
                for polygon in &checked.repaired {
                    add_polygon(&mut lot.mesh, polygon);
                }
                continue;
            }
            counts.push(checked.repaired.len() as u32);
            for (k, polygon) in checked.repaired.into_iter().enumerate() {
                lots.push(Lot {
                    name: if k == 0 {
                        p.name.clone()
                    } else {
                        format!("{}-{k}", p.name)
                    },
                    mesh: polygon_mesh(&polygon),
                    attrs: p.attrs.clone(),
                    geo_origin: if georeferenced { frame } else { None },
                });
            }
        }
        if invalid > NAMED_INVALID {
            messages.push(Message::Warning(format!(
                "{} more invalid lots ({invalid} in all)",
                invalid - NAMED_INVALID
            )));
        }
        Ok(Made {
            lots,
            counts,
            frame,
            messages,
        })
    }
}

/// A feature's polygons become pending lots, named by the feature's id
/// (its index without one), `.1`, `.2`... for a feature's further
/// polygons; the rest is tallied.
fn add_feature(
    f: Feature,
    source: u32,
    label: &Arc<str>,
    index: usize,
    names: &mut HashMap<String, Arc<str>>,
    pending: &mut Vec<Pending>,
    skipped: &mut Skipped,
) {
    let place = Place {
        file: label.clone(),
        index,
        id: f.id,
        line: f.line,
    };
    for kind in &f.others {
        skipped.add(kind, &place);
    }
    let base = place.id.clone().unwrap_or_else(|| index.to_string());
    let count = f.polygons.len();
    let mut attrs = Some(
        f.properties
            .into_iter()
            .map(|(k, v)| {
                let name = names
                    .entry(k)
                    .or_insert_with_key(|k| Arc::from(k.as_str()))
                    .clone();
                (name, v)
            })
            .collect::<Vec<_>>(),
    );
    for (k, polygon) in f.polygons.into_iter().enumerate() {
        let attrs = if k + 1 == count {
            attrs.take().unwrap_or_default()
        } else {
            attrs.clone().unwrap_or_default()
        };
        pending.push(Pending {
            source,
            place: place.clone(),
            name: if k == 0 {
                base.clone()
            } else {
                format!("{base}.{k}")
            },
            attrs,
            polygon,
        });
    }
}

/// A lot's mesh from a polygon in frame metres (x east, y north, z up):
/// `(x, z, -y)`, outer ring counter-clockwise seen from above.
fn polygon_mesh(polygon: &Polygon) -> Mesh {
    let mut mesh = Mesh::new();
    add_polygon(&mut mesh, polygon);
    mesh
}

/// Adds `polygon` to `mesh` as a face (x east, y up, z south).
fn add_polygon(mesh: &mut Mesh, polygon: &Polygon) {
    let mut loops: Vec<Vec<u32>> = Vec::with_capacity(polygon.len());
    for ring in polygon {
        let start = mesh.positions.len() as u32;
        mesh.positions
            .extend(ring.iter().map(|p| DVec3::new(p.x, p.z, -p.y)));
        loops.push((start..mesh.positions.len() as u32).collect());
    }
    crate::lot::orient_rings(&mesh.positions, &mut loops);
    let refs: Vec<&[u32]> = loops.iter().map(|l| l.as_slice()).collect();
    mesh.add_face(&refs, 0);
}
