//! GeoPackage lot files (an SQLite database, OGC 12-128): every feature
//! table, row by row, with the CRS of its geometry column; the other
//! columns are attributes and the primary key names the feature.

use std::path::Path;
use std::sync::Arc;

use cga_value::Value;
use geozero::GeozeroGeometry;
use rusqlite::types::ValueRef;

use super::crs::Declared;
use super::feature::{Feature, GeomCollector};

/// One feature table.
pub struct Layer {
    pub table: String,
    /// Its geometry column's CRS (`None`: undefined, srs_id 0 or -1).
    pub crs: Option<Declared>,
}

/// Reads every feature table of a GeoPackage: `begin` is told of each
/// table before its features go to `sink`.
pub fn read(
    world: &dyn cga_world::World,
    path: &Path,
    begin: &mut dyn FnMut(&Layer),
    sink: &mut dyn FnMut(Feature),
) -> Result<(), String> {
    let bad = |e: &dyn std::fmt::Display| format!("cannot read GeoPackage {}: {e}", path.display());
    // SQLite opens files by their path: a GeoPackage must be a file on disk.
    let Some(file) = world.disk_path(path) else {
        return Err(match world.metadata(path) {
            Some(_) => bad(&"a GeoPackage is read from a file on disk, and this one is not"),
            None => bad(&"no such file"),
        });
    };
    let db = rusqlite::Connection::open_with_flags(
        file,
        rusqlite::OpenFlags::SQLITE_OPEN_READ_ONLY | rusqlite::OpenFlags::SQLITE_OPEN_NO_MUTEX,
    )
    .map_err(|e| bad(&e))?;
    let layers: Vec<(String, String, i64)> = db
        .prepare(
            "SELECT c.table_name, g.column_name, g.srs_id FROM gpkg_contents c \
             JOIN gpkg_geometry_columns g ON g.table_name = c.table_name \
             WHERE c.data_type = 'features' ORDER BY c.rowid",
        )
        .and_then(|mut s| {
            s.query_map([], |r| Ok((r.get(0)?, r.get(1)?, r.get(2)?)))?
                .collect()
        })
        .map_err(|e| bad(&e))?;
    if layers.is_empty() {
        return Err(format!("{} has no feature tables", path.display()));
    }
    for (table, column, srs_id) in layers {
        let layer = Layer {
            crs: layer_crs(&db, srs_id).map_err(|e| bad(&e))?,
            table,
        };
        begin(&layer);
        read_table(&db, &layer.table, &column, sink).map_err(|e| bad(&e))?;
    }
    Ok(())
}

/// The CRS of a spatial reference system id: its EPSG code when the
/// organisation is EPSG, else its WKT definition.
fn layer_crs(db: &rusqlite::Connection, srs_id: i64) -> Result<Option<Declared>, String> {
    // 0 and -1 are the specification's undefined geographic and
    // undefined Cartesian systems.
    if srs_id == 0 || srs_id == -1 {
        return Ok(None);
    }
    let row: Option<(String, i64, String)> = db
        .query_row(
            "SELECT organization, organization_coordsys_id, definition \
             FROM gpkg_spatial_ref_sys WHERE srs_id = ?1",
            [srs_id],
            |r| Ok((r.get(0)?, r.get(1)?, r.get(2)?)),
        )
        .map(Some)
        .or_else(|e| match e {
            rusqlite::Error::QueryReturnedNoRows => Ok(None),
            e => Err(e.to_string()),
        })?;
    Ok(Some(match row {
        Some((org, code, _)) if org.eq_ignore_ascii_case("EPSG") && code > 0 => {
            Declared::Epsg(code as u32)
        }
        Some((_, _, wkt)) if !wkt.trim().is_empty() && wkt.trim() != "undefined" => {
            Declared::Wkt(wkt)
        }
        Some((org, code, _)) => Declared::Unknown(format!("{org}:{code}")),
        None => Declared::Unknown(format!("srs_id {srs_id}, not in gpkg_spatial_ref_sys")),
    }))
}

fn read_table(
    db: &rusqlite::Connection,
    table: &str,
    geometry_column: &str,
    sink: &mut dyn FnMut(Feature),
) -> Result<(), String> {
    let quote = |name: &str| format!("\"{}\"", name.replace('"', "\"\""));
    // The primary key (the feature id) and the declared column types.
    let mut pk = None;
    let mut bool_columns = Vec::new();
    {
        let mut info = db
            .prepare(&format!("PRAGMA table_info({})", quote(table)))
            .map_err(|e| e.to_string())?;
        let mut rows = info.query([]).map_err(|e| e.to_string())?;
        while let Some(r) = rows.next().map_err(|e| e.to_string())? {
            let name: String = r.get(1).map_err(|e| e.to_string())?;
            let kind: String = r.get(2).unwrap_or_default();
            let key: i64 = r.get(5).unwrap_or(0);
            if key == 1 {
                pk = Some(name.clone());
            }
            if kind.eq_ignore_ascii_case("BOOLEAN") {
                bool_columns.push(name);
            }
        }
    }
    let mut stmt = db
        .prepare(&format!("SELECT * FROM {}", quote(table)))
        .map_err(|e| e.to_string())?;
    let names: Vec<String> = stmt.column_names().iter().map(|s| s.to_string()).collect();
    let mut rows = stmt.query([]).map_err(|e| e.to_string())?;
    let mut collector = GeomCollector::default();
    let mut index = 0usize;
    while let Some(row) = rows.next().map_err(|e| e.to_string())? {
        let mut feature = Feature::default();
        let mut geometry = None;
        for (i, name) in names.iter().enumerate() {
            let v = row.get_ref(i).map_err(|e| e.to_string())?;
            if name == geometry_column {
                if let ValueRef::Blob(b) = v {
                    geometry = Some(b);
                }
                continue;
            }
            if Some(name) == pk.as_ref() {
                feature.id = match v {
                    ValueRef::Integer(x) => Some(x.to_string()),
                    ValueRef::Text(t) => Some(String::from_utf8_lossy(t).into_owned()),
                    _ => None,
                };
                continue;
            }
            let value = match v {
                ValueRef::Integer(x) if bool_columns.contains(name) => Value::Bool(x != 0),
                ValueRef::Integer(x) => Value::Float(x as f64),
                ValueRef::Real(x) => Value::Float(x),
                ValueRef::Text(t) => Value::Str(Arc::from(String::from_utf8_lossy(t).as_ref())),
                ValueRef::Null | ValueRef::Blob(_) => continue,
            };
            feature.properties.push((name.clone(), value));
        }
        match geometry {
            Some(blob) => {
                geozero::wkb::GpkgWkb(blob)
                    .process_geom(&mut collector)
                    .map_err(|e| {
                        format!(
                            "table {table} feature {index}{}: its geometry cannot be read: {e}",
                            feature
                                .id
                                .as_ref()
                                .map(|id| format!(" (id {id:?})"))
                                .unwrap_or_default()
                        )
                    })?;
                let (polygons, others) = collector.take();
                feature.polygons = polygons;
                feature.others = others;
            }
            None => feature.others.push("null geometry"),
        }
        sink(feature);
        index += 1;
    }
    Ok(())
}
