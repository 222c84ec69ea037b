//! GeoJSON lot files, read as a stream: each feature is handed on as soon
//! as it is parsed, so memory holds one feature's JSON at a time, not the
//! document. Errors name the feature (index and id) and the line and
//! column.

use std::cell::{Cell, RefCell};
use std::fmt;
use std::io::Read;
use std::path::Path;
use std::rc::Rc;

use cga_geometry::DVec3;
use serde::de::{self, DeserializeSeed, Deserializer, IgnoredAny, MapAccess, SeqAccess, Visitor};

use super::crs::Declared;
use super::feature::{close_ring, json_value, Feature, Polygon};

/// Reads the features of a GeoJSON file (a FeatureCollection, a Feature
/// or a bare geometry) into `sink`, in order; returns the CRS its legacy
/// `crs` member declares, if it has one.
pub fn read(
    world: &dyn cga_world::World,
    path: &Path,
    sink: &mut dyn FnMut(Feature),
) -> Result<Option<Declared>, String> {
    let file = world
        .open(path)
        .map_err(|e| format!("cannot read lot file {}: {e}", path.display()))?;
    read_from(path, file, sink)
}

/// [`read`] from any reader (`path` names it in messages).
pub fn read_from(
    path: &Path,
    reader: impl Read,
    sink: &mut dyn FnMut(Feature),
) -> Result<Option<Declared>, String> {
    let line = Rc::new(Cell::new(1usize));
    let counting = LineCounter {
        inner: reader,
        line: line.clone(),
    };
    let ctx = Ctx {
        sink: RefCell::new(sink),
        line,
        feature: Cell::new(None),
        id: RefCell::new(None),
        crs: RefCell::new(None),
    };
    let mut de = serde_json::Deserializer::from_reader(counting);
    let result = ObjectSeed {
        ctx: &ctx,
        role: Role::Top,
    }
    .deserialize(&mut de)
    .and_then(|_| de.end());
    if let Err(e) = result {
        return Err(describe(path, &ctx, &e));
    }
    let crs = ctx.crs.take();
    match crs {
        Some(v) => super::crs::from_geojson_member(&v)
            .map(Some)
            .map_err(|e| format!("{}: {e}", path.display())),
        None => Ok(None),
    }
}

/// `file:line:column: feature N (id "x"): what went wrong`.
fn describe(path: &Path, ctx: &Ctx, e: &serde_json::Error) -> String {
    let text = e.to_string();
    let suffix = format!(" at line {} column {}", e.line(), e.column());
    let message = text.strip_suffix(&suffix).unwrap_or(&text);
    let what = if e.is_syntax() || e.is_eof() {
        "is not valid GeoJSON"
    } else {
        "is not GeoJSON that can be read"
    };
    let feature = match (ctx.feature.get(), ctx.id.borrow().as_ref()) {
        (Some(i), Some(id)) => format!(" in feature {i} (id {id:?})"),
        (Some(i), None) => format!(" in feature {i}"),
        _ => String::new(),
    };
    format!(
        "{}:{}:{}: {} {what}{feature}: {message}",
        path.display(),
        e.line(),
        e.column(),
        path.display()
    )
}

/// Counts the lines of what the parser has read (it reads byte by byte
/// from its buffer, one byte ahead at most), to say where features start.
struct LineCounter<R> {
    inner: R,
    line: Rc<Cell<usize>>,
}

impl<R: Read> Read for LineCounter<R> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.inner.read(buf)?;
        let newlines = buf[..n].iter().filter(|&&b| b == b'\n').count();
        if newlines > 0 {
            self.line.set(self.line.get() + newlines);
        }
        Ok(n)
    }
}

/// What the parse shares: where features go, and where it is.
struct Ctx<'s> {
    sink: RefCell<&'s mut dyn FnMut(Feature)>,
    line: Rc<Cell<usize>>,
    /// The feature being read (index) and its id once read, for errors.
    feature: Cell<Option<usize>>,
    id: RefCell<Option<String>>,
    /// The document's `crs` member.
    crs: RefCell<Option<serde_json::Value>>,
}

/// What an object is read as.
#[derive(Clone, Copy, PartialEq)]
enum Role {
    /// The document: a FeatureCollection, a Feature or a geometry.
    Top,
    /// An element of `features`.
    Feature,
    /// A `geometry`, or an element of `geometries`.
    Geometry,
}

/// A geometry as read: its type and members; checked when converted.
struct Geometry {
    kind: String,
    coordinates: Option<Coords>,
    geometries: Option<Vec<Geometry>>,
}

/// Nested arrays of numbers (`coordinates`).
enum Coords {
    Number(f64),
    List(Vec<Coords>),
}

/// An object being read: every member any role may have.
#[derive(Default)]
struct Object {
    kind: Option<String>,
    id: Option<String>,
    properties: Vec<(String, cga_value::Value)>,
    /// `Some(None)`: `"geometry": null`.
    geometry: Option<Option<Geometry>>,
    coordinates: Option<Coords>,
    geometries: Option<Vec<Geometry>>,
    features: bool,
}

/// What reading an object gives: a geometry (for the geometry roles).
struct ObjectSeed<'c, 's> {
    ctx: &'c Ctx<'s>,
    role: Role,
}

impl<'de> DeserializeSeed<'de> for ObjectSeed<'_, '_> {
    type Value = Option<Geometry>;

    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
        d.deserialize_any(self)
    }
}

impl<'de> Visitor<'de> for ObjectSeed<'_, '_> {
    type Value = Option<Geometry>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(match self.role {
            Role::Top => "a GeoJSON object",
            Role::Feature => "a Feature object",
            Role::Geometry => "a geometry object or null",
        })
    }

    fn visit_unit<E: de::Error>(self) -> Result<Self::Value, E> {
        if self.role == Role::Geometry {
            return Ok(None);
        }
        Err(E::invalid_type(de::Unexpected::Unit, &self))
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
        let ctx = self.ctx;
        // The parser has just read the object's `{`: its line.
        let line = ctx.line.get();
        let mut o = Object::default();
        while let Some(key) = map.next_key::<std::borrow::Cow<'de, str>>()? {
            match key.as_ref() {
                "type" => o.kind = Some(map.next_value()?),
                "id" if self.role != Role::Geometry => {
                    let id = match map.next_value::<serde_json::Value>()? {
                        serde_json::Value::String(s) => Some(s),
                        serde_json::Value::Number(n) => Some(n.to_string()),
                        _ => None,
                    };
                    *ctx.id.borrow_mut() = id.clone();
                    o.id = id;
                }
                "properties" if self.role != Role::Geometry => {
                    let props: Option<serde_json::Map<String, serde_json::Value>> =
                        map.next_value()?;
                    o.properties = props
                        .into_iter()
                        .flatten()
                        .filter_map(|(k, v)| Some((k, json_value(&v)?)))
                        .collect();
                }
                "geometry" if self.role != Role::Geometry => {
                    if self.role == Role::Top && ctx.feature.get().is_none() {
                        ctx.feature.set(Some(0));
                    }
                    o.geometry = Some(map.next_value_seed(ObjectSeed {
                        ctx,
                        role: Role::Geometry,
                    })?);
                }
                "coordinates" => o.coordinates = Some(map.next_value()?),
                "geometries" => {
                    o.geometries = Some(map.next_value_seed(GeometriesSeed { ctx })?);
                }
                "features" if self.role == Role::Top => {
                    map.next_value_seed(FeaturesSeed { ctx })?;
                    o.features = true;
                }
                "crs" if self.role == Role::Top => {
                    *ctx.crs.borrow_mut() = Some(map.next_value()?);
                }
                _ => {
                    map.next_value::<IgnoredAny>()?;
                }
            }
        }
        let kind = o
            .kind
            .take()
            .ok_or_else(|| de::Error::custom("the object has no \"type\" member"))?;
        match (self.role, kind.as_str()) {
            (Role::Top, "FeatureCollection") => {
                if !o.features {
                    return Err(de::Error::custom(
                        "the FeatureCollection has no \"features\" member",
                    ));
                }
                Ok(None)
            }
            (Role::Top | Role::Feature, "Feature") => {
                let geometry = o.geometry.ok_or_else(|| {
                    de::Error::custom("the Feature has no \"geometry\" member (it may be null)")
                })?;
                let mut feature = Feature {
                    id: o.id,
                    line: Some(line),
                    properties: o.properties,
                    ..Feature::default()
                };
                match geometry {
                    Some(g) => add_geometry(&g, &mut feature).map_err(de::Error::custom)?,
                    None => feature.others.push("null geometry"),
                }
                (ctx.sink.borrow_mut())(feature);
                Ok(None)
            }
            (Role::Feature, other) => Err(de::Error::custom(format!(
                "an element of \"features\" is a {other}, not a Feature"
            ))),
            (Role::Top | Role::Geometry, _) => {
                let g = Geometry {
                    kind,
                    coordinates: o.coordinates,
                    geometries: o.geometries,
                };
                if self.role == Role::Top {
                    // A bare geometry: one feature.
                    let mut feature = Feature::default();
                    add_geometry(&g, &mut feature).map_err(de::Error::custom)?;
                    (ctx.sink.borrow_mut())(feature);
                    return Ok(None);
                }
                Ok(Some(g))
            }
        }
    }
}

/// The `features` array: each feature goes to the sink as it is read.
struct FeaturesSeed<'c, 's> {
    ctx: &'c Ctx<'s>,
}

impl<'de> DeserializeSeed<'de> for FeaturesSeed<'_, '_> {
    type Value = ();

    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<(), D::Error> {
        d.deserialize_seq(self)
    }
}

impl<'de> Visitor<'de> for FeaturesSeed<'_, '_> {
    type Value = ();

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("an array of features")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<(), A::Error> {
        let ctx = self.ctx;
        let mut index = 0usize;
        loop {
            ctx.feature.set(Some(index));
            *ctx.id.borrow_mut() = None;
            let read = seq.next_element_seed(ObjectSeed {
                ctx,
                role: Role::Feature,
            })?;
            if read.is_none() {
                break;
            }
            index += 1;
        }
        ctx.feature.set(None);
        *ctx.id.borrow_mut() = None;
        Ok(())
    }
}

/// A GeometryCollection's `geometries`.
struct GeometriesSeed<'c, 's> {
    ctx: &'c Ctx<'s>,
}

impl<'de> DeserializeSeed<'de> for GeometriesSeed<'_, '_> {
    type Value = Vec<Geometry>;

    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<Self::Value, D::Error> {
        d.deserialize_seq(self)
    }
}

impl<'de> Visitor<'de> for GeometriesSeed<'_, '_> {
    type Value = Vec<Geometry>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("an array of geometries")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut out = Vec::new();
        while let Some(g) = seq.next_element_seed(ObjectSeed {
            ctx: self.ctx,
            role: Role::Geometry,
        })? {
            match g {
                Some(g) => out.push(g),
                None => out.push(Geometry {
                    kind: "null".into(),
                    coordinates: None,
                    geometries: None,
                }),
            }
        }
        Ok(out)
    }
}

impl<'de> serde::Deserialize<'de> for Coords {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(CoordsVisitor)
    }
}

struct CoordsVisitor;

impl<'de> Visitor<'de> for CoordsVisitor {
    type Value = Coords;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a coordinate (a number) or an array")
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<Coords, E> {
        Ok(Coords::Number(v))
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Coords, E> {
        Ok(Coords::Number(v as f64))
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Coords, E> {
        Ok(Coords::Number(v as f64))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Coords, A::Error> {
        let mut items = Vec::with_capacity(seq.size_hint().unwrap_or(4));
        while let Some(c) = seq.next_element()? {
            items.push(c);
        }
        Ok(Coords::List(items))
    }
}

/// Adds a geometry's polygons to a feature, and names its other parts.
fn add_geometry(g: &Geometry, feature: &mut Feature) -> Result<(), String> {
    let coords = || {
        g.coordinates
            .as_ref()
            .ok_or_else(|| format!("the {} has no \"coordinates\" member", g.kind))
    };
    match g.kind.as_str() {
        "Polygon" => {
            let rings = list(coords()?, "Polygon coordinates")?;
            if rings.is_empty() {
                feature.others.push("empty Polygon");
            } else {
                feature.polygons.push(polygon(rings)?);
            }
        }
        "MultiPolygon" => {
            let polygons = list(coords()?, "MultiPolygon coordinates")?;
            if polygons.is_empty() {
                feature.others.push("empty MultiPolygon");
            }
            for p in polygons {
                let rings = list(p, "a MultiPolygon's polygon")?;
                if rings.is_empty() {
                    feature.others.push("empty Polygon");
                } else {
                    feature.polygons.push(polygon(rings)?);
                }
            }
        }
        "GeometryCollection" => {
            let members = g
                .geometries
                .as_ref()
                .ok_or("the GeometryCollection has no \"geometries\" member")?;
            if members.is_empty() {
                feature.others.push("empty GeometryCollection");
            }
            for m in members {
                add_geometry(m, feature)?;
            }
        }
        "null" => feature.others.push("null geometry"),
        kind @ ("Point" | "MultiPoint" | "LineString" | "MultiLineString") => {
            coords()?;
            feature.others.push(match kind {
                "Point" => "Point",
                "MultiPoint" => "MultiPoint",
                "LineString" => "LineString",
                _ => "MultiLineString",
            });
        }
        other => return Err(format!("unknown geometry type {other:?}")),
    }
    Ok(())
}

fn list<'a>(c: &'a Coords, what: &str) -> Result<&'a [Coords], String> {
    match c {
        Coords::List(items) => Ok(items),
        Coords::Number(_) => Err(format!("{what} must be an array, not a number")),
    }
}

fn polygon(rings: &[Coords]) -> Result<Polygon, String> {
    rings
        .iter()
        .map(|r| {
            let ring = list(r, "a ring")?
                .iter()
                .map(position)
                .collect::<Result<Vec<DVec3>, String>>()?;
            Ok(close_ring(ring))
        })
        .collect()
}

fn position(c: &Coords) -> Result<DVec3, String> {
    let items = list(c, "a position")?;
    let num = |i: usize| match items.get(i) {
        Some(Coords::Number(x)) => Ok(Some(*x)),
        Some(Coords::List(_)) => Err("a position's coordinates must be numbers".to_string()),
        None => Ok(None),
    };
    match (num(0)?, num(1)?) {
        (Some(x), Some(y)) => Ok(DVec3::new(x, y, num(2)?.unwrap_or(f64::NAN))),
        _ => Err(format!(
            "a position needs two coordinates, found {}",
            items.len()
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_text(text: &str) -> Result<(Vec<Feature>, Option<Declared>), String> {
        let mut features = Vec::new();
        let crs = read_from(Path::new("t.geojson"), text.as_bytes(), &mut |f| {
            features.push(f)
        })?;
        Ok((features, crs))
    }

    #[test]
    fn features_are_read_in_order_with_their_lines() {
        let (f, crs) = read_text(
            "{\"type\":\"FeatureCollection\",\"features\":[\n\
             {\"type\":\"Feature\",\"id\":7,\"properties\":{\"h\":3,\"n\":\"x\",\"o\":{}},\n\
              \"geometry\":{\"coordinates\":[[[0,0,1],[1,0],[1,1],[0,0,1]]],\"type\":\"Polygon\"}},\n\
             {\"geometry\":null,\"type\":\"Feature\",\"properties\":null}]}",
        )
        .unwrap();
        assert!(crs.is_none());
        assert_eq!(f.len(), 2);
        assert_eq!(f[0].id.as_deref(), Some("7"));
        assert_eq!(f[0].line, Some(2));
        assert_eq!(f[0].properties.len(), 2);
        assert_eq!(f[0].polygons[0][0].len(), 3);
        assert_eq!(f[0].polygons[0][0][0].z, 1.0);
        assert!(f[0].polygons[0][0][1].z.is_nan());
        assert_eq!(f[1].others, vec!["null geometry"]);
        assert_eq!(f[1].line, Some(4));
    }

    #[test]
    fn errors_say_where() {
        let e = read_text(
            "{\"type\":\"FeatureCollection\",\"features\":[\n\
             {\"type\":\"Feature\",\"id\":\"a\",\"properties\":{},\"geometry\":{\"type\":\"Point\",\"coordinates\":[0,0]}},\n\
             {\"type\":\"Feature\",\"id\":\"b\",\"properties\":{},\n\
              \"geometry\":{\"type\":\"Polygon\",\"coordinates\":[[[0,0],[1,null],[1,1]]]}}]}",
        )
        .unwrap_err();
        assert!(e.starts_with("t.geojson:4:"), "{e}");
        assert!(e.contains("in feature 1 (id \"b\")"), "{e}");
        assert!(e.contains("invalid type: null"), "{e}");
    }
}
