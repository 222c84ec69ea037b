//! Writes a synthetic city of COUNT lots as GeoJSON, FlatGeobuf and
//! GeoPackage, for measuring how reading lot files scales
//! (`tools/perf/gis_memory.sh`, `docs/performance.md`).
//!
//! ```text
//! cargo run --release -p cga-engine --example gis_lots -- COUNT OUT_DIR
//! ```
//!
//! The lots are those of `cga generate --lot grid:COLSxROWS` (20 x 30 m,
//! 10 m apart, 400 per row), placed on the globe around 8.5 E, 47.3 N
//! (WGS84 longitude/latitude), each with an id and a `height` property.

use std::io::Write;
use std::path::Path;

use cga_engine::geo::GeoOrigin;
use flatgeobuf::{ColumnType, FgbCrs, FgbWriter, FgbWriterOptions, GeometryType};
use geozero::{ColumnValue, PropertyProcessor};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let (Some(count), Some(dir)) = (args.get(1), args.get(2)) else {
        eprintln!("usage: gis_lots COUNT OUT_DIR");
        std::process::exit(2);
    };
    let count: usize = count.parse()?;
    let dir = Path::new(dir);
    std::fs::create_dir_all(dir)?;
    let lots = city(count)?;
    write_geojson(&dir.join("lots.geojson"), &lots)?;
    write_fgb(&dir.join("lots.fgb"), &lots)?;
    write_gpkg(&dir.join("lots.gpkg"), &lots)?;
    Ok(())
}

/// Each lot's corners (lon, lat), counter-clockwise.
fn city(count: usize) -> Result<Vec<[(f64, f64); 4]>, String> {
    let frame = GeoOrigin {
        lon: 8.5,
        lat: 47.3,
    };
    let tm = frame.proj()?;
    let wgs84 = cga_engine::geo::wgs84();
    let mut lots = Vec::with_capacity(count);
    for i in 0..count {
        let (col, row) = ((i % 400) as f64, (i / 400) as f64);
        let (x, y) = (col * 30.0, row * 40.0);
        let corners = [(x, y), (x + 20.0, y), (x + 20.0, y + 30.0), (x, y + 30.0)].map(|(e, n)| {
            let mut p = (e, n, 0.0);
            proj4rs::transform::transform(&tm, &wgs84, &mut p).expect("on the globe");
            (p.0.to_degrees(), p.1.to_degrees())
        });
        lots.push(corners);
    }
    Ok(lots)
}

fn height(i: usize) -> f64 {
    6.0 + (i % 7) as f64 * 3.0
}

fn write_geojson(path: &Path, lots: &[[(f64, f64); 4]]) -> std::io::Result<()> {
    let mut out = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(out, "{{\"type\":\"FeatureCollection\",\"features\":[")?;
    for (i, c) in lots.iter().enumerate() {
        let ring: Vec<String> = c
            .iter()
            .chain(&c[..1])
            .map(|(x, y)| format!("[{x:.8},{y:.8}]"))
            .collect();
        writeln!(
            out,
            "{{\"type\":\"Feature\",\"id\":\"lot{i}\",\"properties\":{{\"height\":{}}},\"geometry\":{{\"type\":\"Polygon\",\"coordinates\":[[{}]]}}}}{}",
            height(i),
            ring.join(","),
            if i + 1 < lots.len() { "," } else { "" }
        )?;
    }
    writeln!(out, "]}}")?;
    out.flush()
}

/// A polygon of one ring for geozero writers.
struct Ring<'a>(&'a [(f64, f64); 4]);

impl geozero::GeozeroGeometry for Ring<'_> {
    fn process_geom<P: geozero::GeomProcessor>(&self, p: &mut P) -> geozero::error::Result<()> {
        p.polygon_begin(true, 1, 0)?;
        p.linestring_begin(false, 5, 0)?;
        for (i, &(x, y)) in self.0.iter().chain(&self.0[..1]).enumerate() {
            p.xy(x, y, i)?;
        }
        p.linestring_end(false, 0)?;
        p.polygon_end(true, 0)
    }
}

fn write_fgb(path: &Path, lots: &[[(f64, f64); 4]]) -> Result<(), Box<dyn std::error::Error>> {
    let options = FgbWriterOptions {
        write_index: false,
        crs: FgbCrs {
            code: 4326,
            ..Default::default()
        },
        ..Default::default()
    };
    let mut fgb = FgbWriter::create_with_options("lots", GeometryType::Polygon, options)?;
    fgb.add_column("id", ColumnType::String, |_, _| {});
    fgb.add_column("height", ColumnType::Double, |_, _| {});
    for (i, c) in lots.iter().enumerate() {
        fgb.add_feature_geom(Ring(c), |f| {
            let _ = f.property(0, "id", &ColumnValue::String(&format!("lot{i}")));
            let _ = f.property(1, "height", &ColumnValue::Double(height(i)));
        })?;
    }
    fgb.write(&mut std::io::BufWriter::new(std::fs::File::create(path)?))?;
    Ok(())
}

fn write_gpkg(path: &Path, lots: &[[(f64, f64); 4]]) -> Result<(), Box<dyn std::error::Error>> {
    let _ = std::fs::remove_file(path);
    let mut db = rusqlite::Connection::open(path)?;
    db.execute_batch(
        "CREATE TABLE gpkg_spatial_ref_sys (srs_name TEXT, srs_id INTEGER PRIMARY KEY, organization TEXT, organization_coordsys_id INTEGER, definition TEXT, description TEXT);
         INSERT INTO gpkg_spatial_ref_sys VALUES ('WGS 84', 4326, 'EPSG', 4326, 'GEOGCS[\"WGS 84\"]', NULL);
         CREATE TABLE gpkg_contents (table_name TEXT PRIMARY KEY, data_type TEXT, identifier TEXT, srs_id INTEGER);
         CREATE TABLE gpkg_geometry_columns (table_name TEXT, column_name TEXT, geometry_type_name TEXT, srs_id INTEGER, z INTEGER, m INTEGER);
         INSERT INTO gpkg_contents VALUES ('lots', 'features', 'lots', 4326);
         INSERT INTO gpkg_geometry_columns VALUES ('lots', 'geom', 'POLYGON', 4326, 0, 0);
         CREATE TABLE lots (fid INTEGER PRIMARY KEY, geom BLOB, height REAL);",
    )?;
    let tx = db.transaction()?;
    {
        let mut insert = tx.prepare("INSERT INTO lots VALUES (?1, ?2, ?3)")?;
        for (i, c) in lots.iter().enumerate() {
            // "GP", version 0, little-endian header without envelope, srs
            // 4326, then a little-endian WKB polygon of one closed ring.
            let mut b = vec![b'G', b'P', 0, 1];
            b.extend_from_slice(&4326i32.to_le_bytes());
            b.push(1);
            b.extend_from_slice(&3u32.to_le_bytes());
            b.extend_from_slice(&1u32.to_le_bytes());
            b.extend_from_slice(&5u32.to_le_bytes());
            for &(x, y) in c.iter().chain(&c[..1]) {
                b.extend_from_slice(&x.to_le_bytes());
                b.extend_from_slice(&y.to_le_bytes());
            }
            insert.execute(rusqlite::params![i as i64, b, height(i)])?;
        }
    }
    tx.commit()?;
    Ok(())
}
