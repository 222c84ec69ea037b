//! FlatGeobuf lot files, read feature by feature, with the CRS of their
//! header.

use std::path::Path;
use std::sync::Arc;

use flatgeobuf::{FallibleStreamingIterator, FgbReader};
use geozero::{ColumnValue, FeatureProperties, GeozeroGeometry, PropertyProcessor};

use super::crs::Declared;
use super::feature::{Feature, GeomCollector};
use cga_value::Value;

/// Reads the features of a FlatGeobuf file into `sink`; returns the CRS
/// its header declares.
pub fn read(
    world: &dyn cga_world::World,
    path: &Path,
    sink: &mut dyn FnMut(Feature),
) -> Result<Option<Declared>, String> {
    let bad = |e: &dyn std::fmt::Display| format!("cannot read FlatGeobuf {}: {e}", path.display());
    let file = world.open(path).map_err(|e| bad(&e))?;
    let reader = FgbReader::open(file).map_err(|e| bad(&e))?;
    let declared = reader.header().crs().and_then(|crs| {
        let org = crs.org().unwrap_or("EPSG");
        if crs.code() > 0 && org.eq_ignore_ascii_case("EPSG") {
            Some(Declared::Epsg(crs.code() as u32))
        } else if let Some(wkt) = crs.wkt().filter(|w| !w.trim().is_empty()) {
            Some(Declared::Wkt(wkt.to_string()))
        } else if let Some(code) = crs.code_string() {
            Some(super::crs::from_name(&format!("{org}:{code}")))
        } else if crs.code() > 0 {
            Some(Declared::Unknown(format!("{org}:{}", crs.code())))
        } else {
            None
        }
    });
    let mut features = reader.select_all_seq().map_err(|e| bad(&e))?;
    let mut collector = GeomCollector::default();
    let mut index = 0usize;
    while let Some(f) = features
        .next()
        .map_err(|e| bad(&format!("feature {index}: {e}")))?
    {
        let mut props = Properties::default();
        f.process_properties(&mut props)
            .map_err(|e| bad(&format!("feature {index}: {e}")))?;
        let mut feature = Feature {
            id: props.id.take(),
            properties: props.values,
            ..Feature::default()
        };
        if f.geometry().is_some() {
            f.process_geom(&mut collector)
                .map_err(|e| bad(&format!("feature {index}: {e}")))?;
            let (polygons, others) = collector.take();
            feature.polygons = polygons;
            feature.others = others;
        } else {
            feature.others.push("null geometry");
        }
        sink(feature);
        index += 1;
    }
    Ok(declared)
}

/// Feature properties as attribute values; a property called `id` or
/// `fid` (any case) also names the feature, as FlatGeobuf has no feature
/// ids of its own.
#[derive(Default)]
pub struct Properties {
    pub values: Vec<(String, Value)>,
    pub id: Option<String>,
}

impl PropertyProcessor for Properties {
    fn property(&mut self, _i: usize, name: &str, v: &ColumnValue) -> geozero::error::Result<bool> {
        let value = match v {
            ColumnValue::Bool(b) => Value::Bool(*b),
            ColumnValue::Byte(x) => Value::Float(*x as f64),
            ColumnValue::UByte(x) => Value::Float(*x as f64),
            ColumnValue::Short(x) => Value::Float(*x as f64),
            ColumnValue::UShort(x) => Value::Float(*x as f64),
            ColumnValue::Int(x) => Value::Float(*x as f64),
            ColumnValue::UInt(x) => Value::Float(*x as f64),
            ColumnValue::Long(x) => Value::Float(*x as f64),
            ColumnValue::ULong(x) => Value::Float(*x as f64),
            ColumnValue::Float(x) => Value::Float(*x as f64),
            ColumnValue::Double(x) => Value::Float(*x),
            ColumnValue::String(s) | ColumnValue::Json(s) | ColumnValue::DateTime(s) => {
                Value::Str(Arc::from(*s))
            }
            ColumnValue::Binary(_) => return Ok(false),
        };
        if self.id.is_none()
            && (name.eq_ignore_ascii_case("id") || name.eq_ignore_ascii_case("fid"))
        {
            self.id = Some(match &value {
                Value::Float(x) => format!("{x}"),
                Value::Str(s) => s.to_string(),
                Value::Bool(b) => b.to_string(),
                _ => String::new(),
            });
        }
        self.values.push((name.to_string(), value));
        Ok(false)
    }
}
