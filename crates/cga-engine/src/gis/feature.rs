//! Features as every lot file format gives them: an id, properties, and
//! the polygons of the geometry in the file's coordinates; what is not a
//! polygon is named, so that it can be counted and reported.

use std::collections::BTreeMap;
use std::fmt;
use std::sync::Arc;

use cga_geometry::DVec3;
use cga_value::Value;

/// A ring as read: (x, y, z) in the file's coordinate reference system,
/// z NaN where the position had none. Not closed (a repeated first point
/// at the end is dropped).
pub type Ring = Vec<DVec3>;

/// A polygon: outer ring, then holes.
pub type Polygon = Vec<Ring>;

/// Where a feature is in its file, for messages.
#[derive(Clone, Debug, PartialEq)]
pub struct Place {
    /// The file (and layer, for files with several), as given.
    pub file: Arc<str>,
    /// Index of the feature in its file or layer, from 0.
    pub index: usize,
    pub id: Option<String>,
    /// The line the feature starts on (text formats).
    pub line: Option<usize>,
}

impl fmt::Display for Place {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} feature {}", self.file, self.index)?;
        match (&self.id, self.line) {
            (Some(id), Some(line)) => write!(f, " (id {id:?}, line {line})"),
            (Some(id), None) => write!(f, " (id {id:?})"),
            (None, Some(line)) => write!(f, " (line {line})"),
            (None, None) => Ok(()),
        }
    }
}

/// One feature of a lot file.
#[derive(Clone, Debug, Default)]
pub struct Feature {
    pub id: Option<String>,
    pub line: Option<usize>,
    /// Properties that can be attribute values (numbers, booleans, text).
    pub properties: Vec<(String, Value)>,
    pub polygons: Vec<Polygon>,
    /// What the geometry holds besides polygons (`"LineString"`, `"null
    /// geometry"`, `"empty Polygon"`), one entry per part.
    pub others: Vec<&'static str>,
}

/// A JSON-like property value as an attribute value, if it can be one.
pub fn json_value(v: &serde_json::Value) -> Option<Value> {
    Some(match v {
        serde_json::Value::Number(n) => Value::Float(n.as_f64()?),
        serde_json::Value::Bool(b) => Value::Bool(*b),
        serde_json::Value::String(s) => Value::Str(Arc::from(s.as_str())),
        _ => return None,
    })
}

/// The parts of features that give no lot, by kind, with the features
/// they came from: reported in one warning per file.
#[derive(Default)]
pub struct Skipped {
    by_kind: BTreeMap<&'static str, (usize, Vec<String>)>,
}

/// Features named per kind in the warning at most.
const NAMED: usize = 5;

impl Skipped {
    pub fn add(&mut self, kind: &'static str, place: &Place) {
        let (n, names) = self.by_kind.entry(kind).or_default();
        *n += 1;
        if names.len() < NAMED {
            names.push(match &place.id {
                Some(id) => format!("id {id:?}"),
                None => format!("feature {}", place.index),
            });
        }
    }

    pub fn is_empty(&self) -> bool {
        self.by_kind.is_empty()
    }

    /// One line: "3 parts give no lot: 2 LineString (id "a", id "b"), ...".
    pub fn warning(&self, file: &str) -> Option<String> {
        if self.by_kind.is_empty() {
            return None;
        }
        let total: usize = self.by_kind.values().map(|(n, _)| n).sum();
        let kinds: Vec<String> = self
            .by_kind
            .iter()
            .map(|(kind, (n, names))| {
                let more = if *n > names.len() {
                    format!(", {} more", n - names.len())
                } else {
                    String::new()
                };
                format!("{n} {kind} ({}{more})", names.join(", "))
            })
            .collect();
        Some(format!(
            "{file}: {total} geometr{} that {} not polygons gave no lot: {}",
            if total == 1 { "y" } else { "ies" },
            if total == 1 { "is" } else { "are" },
            kinds.join("; ")
        ))
    }
}

/// Collects the polygons of a geometry streamed by `geozero` (FlatGeobuf,
/// GeoPackage WKB), naming every part that is not one.
#[derive(Default)]
pub struct GeomCollector {
    pub polygons: Vec<Polygon>,
    pub others: Vec<&'static str>,
    /// Depth of polygons being read (a polygon's rings are linestrings).
    in_polygon: usize,
    /// Inside a linestring or point that is not a ring: its coordinates
    /// are not kept.
    skipping: usize,
    ring: Ring,
    polygon: Polygon,
}

impl GeomCollector {
    /// Ends a feature's geometry: what was collected, and the collector
    /// ready for the next one.
    pub fn take(&mut self) -> (Vec<Polygon>, Vec<&'static str>) {
        let polygons = std::mem::take(&mut self.polygons);
        let others = std::mem::take(&mut self.others);
        *self = GeomCollector::default();
        (polygons, others)
    }

    fn point(&mut self, x: f64, y: f64, z: Option<f64>) {
        if self.in_polygon > 0 && self.skipping == 0 {
            self.ring.push(DVec3::new(x, y, z.unwrap_or(f64::NAN)));
        }
    }
}

impl geozero::GeomProcessor for GeomCollector {
    fn dimensions(&self) -> geozero::CoordDimensions {
        geozero::CoordDimensions::xyz()
    }

    fn multi_dim(&self) -> bool {
        true
    }

    fn xy(&mut self, x: f64, y: f64, _idx: usize) -> geozero::error::Result<()> {
        self.point(x, y, None);
        Ok(())
    }

    fn coordinate(
        &mut self,
        x: f64,
        y: f64,
        z: Option<f64>,
        _m: Option<f64>,
        _t: Option<f64>,
        _tm: Option<u64>,
        _idx: usize,
    ) -> geozero::error::Result<()> {
        self.point(x, y, z);
        Ok(())
    }

    fn empty_point(&mut self, _idx: usize) -> geozero::error::Result<()> {
        self.others.push("empty Point");
        Ok(())
    }

    fn point_begin(&mut self, _idx: usize) -> geozero::error::Result<()> {
        self.others.push("Point");
        self.skipping += 1;
        Ok(())
    }

    fn point_end(&mut self, _idx: usize) -> geozero::error::Result<()> {
        self.skipping -= 1;
        Ok(())
    }

    fn multipoint_begin(&mut self, size: usize, _idx: usize) -> geozero::error::Result<()> {
        self.others.push(if size == 0 {
            "empty MultiPoint"
        } else {
            "MultiPoint"
        });
        self.skipping += 1;
        Ok(())
    }

    fn multipoint_end(&mut self, _idx: usize) -> geozero::error::Result<()> {
        self.skipping -= 1;
        Ok(())
    }

    fn linestring_begin(
        &mut self,
        tagged: bool,
        size: usize,
        _idx: usize,
    ) -> geozero::error::Result<()> {
        if tagged || self.in_polygon == 0 {
            self.others.push(if size == 0 {
                "empty LineString"
            } else {
                "LineString"
            });
            self.skipping += 1;
        } else {
            self.ring = Vec::with_capacity(size);
        }
        Ok(())
    }

    fn linestring_end(&mut self, tagged: bool, _idx: usize) -> geozero::error::Result<()> {
        if tagged || self.in_polygon == 0 {
            self.skipping -= 1;
        } else if self.skipping == 0 {
            let ring = close_ring(std::mem::take(&mut self.ring));
            self.polygon.push(ring);
        }
        Ok(())
    }

    fn multilinestring_begin(&mut self, size: usize, _idx: usize) -> geozero::error::Result<()> {
        self.others.push(if size == 0 {
            "empty MultiLineString"
        } else {
            "MultiLineString"
        });
        self.skipping += 1;
        Ok(())
    }

    fn multilinestring_end(&mut self, _idx: usize) -> geozero::error::Result<()> {
        self.skipping -= 1;
        Ok(())
    }

    fn polygon_begin(
        &mut self,
        _tagged: bool,
        size: usize,
        _idx: usize,
    ) -> geozero::error::Result<()> {
        if size == 0 && self.skipping == 0 {
            self.others.push("empty Polygon");
        }
        self.in_polygon += 1;
        self.polygon = Vec::with_capacity(size);
        Ok(())
    }

    fn polygon_end(&mut self, _tagged: bool, _idx: usize) -> geozero::error::Result<()> {
        self.in_polygon -= 1;
        let polygon = std::mem::take(&mut self.polygon);
        if !polygon.is_empty() && self.skipping == 0 {
            self.polygons.push(polygon);
        }
        Ok(())
    }

    fn multipolygon_begin(&mut self, size: usize, _idx: usize) -> geozero::error::Result<()> {
        if size == 0 {
            self.others.push("empty MultiPolygon");
        }
        Ok(())
    }

    fn geometrycollection_begin(&mut self, size: usize, _idx: usize) -> geozero::error::Result<()> {
        if size == 0 {
            self.others.push("empty GeometryCollection");
        }
        Ok(())
    }

    fn circularstring_begin(&mut self, _size: usize, _idx: usize) -> geozero::error::Result<()> {
        self.others.push("CircularString");
        self.skipping += 1;
        Ok(())
    }

    fn circularstring_end(&mut self, _idx: usize) -> geozero::error::Result<()> {
        self.skipping -= 1;
        Ok(())
    }

    fn curvepolygon_begin(&mut self, _size: usize, _idx: usize) -> geozero::error::Result<()> {
        self.others.push("CurvePolygon");
        self.skipping += 1;
        Ok(())
    }

    fn curvepolygon_end(&mut self, _idx: usize) -> geozero::error::Result<()> {
        self.skipping -= 1;
        Ok(())
    }

    fn tin_begin(&mut self, _size: usize, _idx: usize) -> geozero::error::Result<()> {
        self.others.push("TIN");
        self.skipping += 1;
        Ok(())
    }

    fn tin_end(&mut self, _idx: usize) -> geozero::error::Result<()> {
        self.skipping -= 1;
        Ok(())
    }
}

/// A ring without the repeated first point at its end.
pub fn close_ring(mut ring: Ring) -> Ring {
    if ring.len() > 1 && ring.first().map(|p| (p.x, p.y)) == ring.last().map(|p| (p.x, p.y)) {
        ring.pop();
    }
    ring
}
