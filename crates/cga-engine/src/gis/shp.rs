//! Shapefile lot files: the `.shp` geometry, the `.dbf` attributes beside
//! it and the CRS of its `.prj` (WKT), record by record. A record's holes
//! are given to the outer ring that contains them.

use std::io::{Cursor, Read, Seek};
use std::path::Path;
use std::sync::Arc;

use cga_world::World;
use shapefile::dbase;

use cga_geometry::DVec3;
use cga_value::Value;
use shapefile::dbase::FieldValue;
use shapefile::{PolygonRing, Shape};

use super::crs::Declared;
use super::feature::{close_ring, Feature, Polygon, Ring};

/// Reads the records of a Shapefile into `sink`; returns the CRS of its
/// `.prj`, if there is one. Files on disk are read record by record; the
/// files of other worlds (in memory) are read whole first.
pub fn read(
    world: &dyn World,
    path: &Path,
    sink: &mut dyn FnMut(Feature),
) -> Result<Option<Declared>, String> {
    let bad = |e: &dyn std::fmt::Display| format!("cannot read Shapefile {}: {e}", path.display());
    let declared = match world.read(&path.with_extension("prj")) {
        Ok(bytes) => {
            let wkt = String::from_utf8_lossy(&bytes).trim().to_string();
            (!wkt.is_empty()).then_some(Declared::Wkt(wkt))
        }
        Err(_) => None,
    };
    let dbf = path.with_extension("dbf");
    if let (Some(shp_file), Some(dbf_file)) = (world.disk_path(path), world.disk_path(&dbf)) {
        // The .dbf's columns in order: a record hands its values over in
        // no particular order.
        let columns = dbase::Reader::from_path(&dbf_file)
            .map(|r| columns(&r))
            .unwrap_or_default();
        let reader = shapefile::Reader::from_path(&shp_file).map_err(|e| bad(&e))?;
        records(reader, &columns, sink, &bad)?;
    } else {
        let shp_bytes = world.read(path).map_err(|e| bad(&e))?;
        let dbf_bytes = world.read(&dbf).map_err(|e| bad(&e))?;
        let columns = dbase::Reader::new(Cursor::new(&dbf_bytes))
            .map(|r| columns(&r))
            .unwrap_or_default();
        let shapes = shapefile::ShapeReader::new(Cursor::new(shp_bytes)).map_err(|e| bad(&e))?;
        let table = dbase::Reader::new(Cursor::new(dbf_bytes)).map_err(|e| bad(&e))?;
        records(shapefile::Reader::new(shapes, table), &columns, sink, &bad)?;
    }
    Ok(declared)
}

/// The names of a `.dbf`'s columns, in order.
fn columns<T: Read + Seek>(table: &dbase::Reader<T>) -> Vec<String> {
    table
        .fields()
        .iter()
        .map(|f| f.name().to_string())
        .collect()
}

/// Every record of `reader` as a feature into `sink`, its properties in
/// the order of `columns`.
fn records<T: Read + Seek, D: Read + Seek>(
    mut reader: shapefile::Reader<T, D>,
    columns: &[String],
    sink: &mut dyn FnMut(Feature),
    bad: &dyn Fn(&dyn std::fmt::Display) -> String,
) -> Result<(), String> {
    let column = |name: &str| columns.iter().position(|c| c == name).unwrap_or(usize::MAX);
    for (index, item) in reader.iter_shapes_and_records().enumerate() {
        let (shape, record) = item.map_err(|e| bad(&format!("record {index}: {e}")))?;
        let mut feature = Feature::default();
        for (name, value) in record {
            let v = match value {
                FieldValue::Character(Some(s)) | FieldValue::Memo(s) => {
                    Value::Str(Arc::from(s.trim_end()))
                }
                FieldValue::Numeric(Some(x)) | FieldValue::Double(x) | FieldValue::Currency(x) => {
                    Value::Float(x)
                }
                FieldValue::Float(Some(x)) => Value::Float(x as f64),
                FieldValue::Integer(x) => Value::Float(x as f64),
                FieldValue::Logical(Some(b)) => Value::Bool(b),
                _ => continue,
            };
            feature.properties.push((name, v));
        }
        feature.properties.sort_by_key(|(name, _)| column(name));
        match shape {
            Shape::Polygon(p) => {
                feature.polygons = group_rings(p.rings(), |pt| DVec3::new(pt.x, pt.y, f64::NAN))
            }
            Shape::PolygonM(p) => {
                feature.polygons = group_rings(p.rings(), |pt| DVec3::new(pt.x, pt.y, f64::NAN))
            }
            Shape::PolygonZ(p) => {
                feature.polygons = group_rings(p.rings(), |pt| DVec3::new(pt.x, pt.y, pt.z))
            }
            Shape::NullShape => feature.others.push("null geometry"),
            Shape::Point(_) | Shape::PointM(_) | Shape::PointZ(_) => feature.others.push("Point"),
            Shape::Polyline(_) | Shape::PolylineM(_) | Shape::PolylineZ(_) => {
                feature.others.push("LineString")
            }
            Shape::Multipoint(_) | Shape::MultipointM(_) | Shape::MultipointZ(_) => {
                feature.others.push("MultiPoint")
            }
            Shape::Multipatch(_) => feature.others.push("Multipatch"),
        }
        if feature.polygons.is_empty() && feature.others.is_empty() {
            feature.others.push("empty Polygon");
        }
        sink(feature);
    }
    Ok(())
}

/// Polygons from a record's rings: each outer ring with the inner rings
/// that lie inside it (the first that contains a hole's first point; the
/// last outer ring read before the hole if none does).
fn group_rings<P>(rings: &[PolygonRing<P>], point: impl Fn(&P) -> DVec3) -> Vec<Polygon> {
    let mut polygons: Vec<Polygon> = Vec::new();
    let mut holes: Vec<(usize, Ring)> = Vec::new();
    for r in rings {
        let ring: Ring = close_ring(r.points().iter().map(&point).collect());
        match r {
            PolygonRing::Outer(_) => polygons.push(vec![ring]),
            PolygonRing::Inner(_) => holes.push((polygons.len().saturating_sub(1), ring)),
        }
    }
    for (last_outer, hole) in holes {
        let Some(first) = hole.first().copied() else {
            continue;
        };
        let host = polygons
            .iter()
            .position(|p| contains(&p[0], first))
            .unwrap_or(last_outer);
        match polygons.get_mut(host) {
            Some(p) => p.push(hole),
            // A hole without any outer ring: kept as a polygon, for
            // validation to report.
            None => polygons.push(vec![hole]),
        }
    }
    polygons
}

/// Whether a point lies inside a ring (even-odd rule, in x-y).
fn contains(ring: &[DVec3], p: DVec3) -> bool {
    let mut inside = false;
    for i in 0..ring.len() {
        let a = ring[i];
        let b = ring[(i + 1) % ring.len()];
        if (a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) / (b.y - a.y) * (b.x - a.x) {
            inside = !inside;
        }
    }
    inside
}
