//! Coordinate reference systems of lot files: what a file declares (a
//! legacy GeoJSON `crs` member, a FlatGeobuf header, a GeoPackage's
//! spatial reference system, a Shapefile's `.prj`), what `--crs` says,
//! and how coordinates without a declared CRS are read.
//!
//! Projections are `proj4rs`'s (a pure-Rust PROJ) with the EPSG table of
//! `crs-definitions`; WKT is turned into PROJ parameters by `proj4wkt`,
//! unless it names its EPSG code, which is preferred (the table carries
//! the datum shifts that WKT often leaves out).

use proj4rs::Proj;

/// A CRS as a file declares it.
#[derive(Clone, Debug, PartialEq)]
pub enum Declared {
    Epsg(u32),
    /// WKT (1 or 2), as in `.prj` files and GeoPackages.
    Wkt(String),
    /// A CRS named in a way that cannot be used (kept for the message).
    Unknown(String),
}

/// The `--crs` option: the CRS of every lot file, whatever they declare.
#[derive(Clone, Debug, PartialEq)]
pub enum CrsOption {
    Epsg(u32),
    /// Coordinates are metres in a plane of their own (a drawing, a CAD
    /// plan): used as they are, not georeferenced.
    Local,
}

impl std::str::FromStr for CrsOption {
    type Err = String;

    /// `EPSG:N` (any case) or `local`.
    fn from_str(s: &str) -> Result<CrsOption, String> {
        let s = s.trim();
        if s.eq_ignore_ascii_case("local") {
            return Ok(CrsOption::Local);
        }
        let code = s
            .split_once(':')
            .filter(|(auth, _)| auth.eq_ignore_ascii_case("EPSG"))
            .and_then(|(_, code)| code.trim().parse::<u32>().ok())
            .ok_or_else(|| format!("expected --crs EPSG:N or --crs local, found `{s}`"))?;
        // Checked now, so that a typo is a usage error before any reading.
        epsg(code)?;
        Ok(CrsOption::Epsg(code))
    }
}

/// The CRS a file's coordinates are read in.
#[derive(Clone)]
pub enum Resolved {
    /// Metres in a plane of their own, used as they are.
    Local,
    /// On the globe: projected into the local frame.
    Geo {
        proj: Box<Proj>,
        /// How it is named in messages (`EPSG:3857`, a WKT's name).
        name: String,
    },
}

impl Resolved {
    pub fn name(&self) -> &str {
        match self {
            Resolved::Local => "local metres",
            Resolved::Geo { name, .. } => name,
        }
    }

    pub fn is_geographic(&self) -> bool {
        matches!(self, Resolved::Geo { proj, .. } if proj.is_latlong())
    }
}

/// WGS84 longitude/latitude (EPSG:4326), GeoJSON's CRS (RFC 7946).
pub fn wgs84() -> Resolved {
    Resolved::Geo {
        proj: Box::new(crate::geo::wgs84()),
        name: "EPSG:4326".into(),
    }
}

/// The projection of a declared CRS.
pub fn resolve_declared(d: &Declared) -> Result<Resolved, String> {
    match d {
        Declared::Epsg(code) => Ok(Resolved::Geo {
            proj: Box::new(epsg(*code)?),
            name: format!("EPSG:{code}"),
        }),
        Declared::Wkt(wkt) => {
            if let Some(code) = wkt_epsg_code(wkt) {
                if let Ok(proj) = epsg(code) {
                    return Ok(Resolved::Geo {
                        proj: Box::new(proj),
                        name: format!("EPSG:{code}"),
                    });
                }
            }
            let name = wkt_name(wkt).unwrap_or_else(|| "the file's WKT".into());
            let projstring = proj4wkt::wkt_to_projstring(wkt)
                .map_err(|e| format!("its CRS ({name}) cannot be read: {e}"))?;
            let proj = Proj::from_proj_string(&projstring)
                .map_err(|e| format!("its CRS ({name}) cannot be used: {e}"))?;
            Ok(Resolved::Geo {
                proj: Box::new(proj),
                name,
            })
        }
        Declared::Unknown(what) => Err(format!(
            "its CRS ({what}) is not one known here; give --crs EPSG:N"
        )),
    }
}

/// The projection of an EPSG code.
pub fn epsg(code: u32) -> Result<Proj, String> {
    let code16 = u16::try_from(code)
        .map_err(|_| format!("EPSG:{code} is not a coordinate reference system known here"))?;
    Proj::from_epsg_code(code16).map_err(|e| match e {
        proj4rs::errors::Error::ProjectionNotFound => {
            format!("EPSG:{code} is not a coordinate reference system known here")
        }
        e => format!("EPSG:{code} cannot be used: {e}"),
    })
}

/// The projection of `--crs`.
pub fn resolve_option(o: &CrsOption) -> Result<Resolved, String> {
    match o {
        CrsOption::Local => Ok(Resolved::Local),
        CrsOption::Epsg(code) => resolve_declared(&Declared::Epsg(*code)),
    }
}

/// A legacy GeoJSON `crs` member (GeoJSON 2008): `{"type": "name",
/// "properties": {"name": "urn:ogc:def:crs:EPSG::3857"}}` (or `EPSG:3857`,
/// or OGC's CRS84), or `{"type": "EPSG", "properties": {"code": 3857}}`.
pub fn from_geojson_member(v: &serde_json::Value) -> Result<Declared, String> {
    let props = &v["properties"];
    match v["type"].as_str() {
        Some("name") => {
            let name = props["name"]
                .as_str()
                .ok_or("its \"crs\" member has no name")?;
            Ok(from_name(name))
        }
        Some("EPSG") => props["code"]
            .as_u64()
            .and_then(|c| u32::try_from(c).ok())
            .map(Declared::Epsg)
            .ok_or_else(|| "its \"crs\" member has no EPSG code".into()),
        _ => Ok(Declared::Unknown(v.to_string())),
    }
}

/// A CRS name: `EPSG:N`, `urn:ogc:def:crs:EPSG:VERSION:N`, OGC's CRS84.
pub fn from_name(name: &str) -> Declared {
    let n = name.trim();
    let upper = n.to_ascii_uppercase();
    if upper.ends_with("CRS84") || upper.ends_with("CRS:84") {
        return Declared::Epsg(4326);
    }
    if upper.contains("EPSG") {
        if let Some(code) = n.rsplit(':').next().and_then(|c| c.trim().parse().ok()) {
            return Declared::Epsg(code);
        }
    }
    Declared::Unknown(n.to_string())
}

/// The EPSG code a WKT names for the whole CRS: the `AUTHORITY["EPSG", N]`
/// (WKT 1) or `ID["EPSG", N]` (WKT 2) of its outermost element.
pub fn wkt_epsg_code(wkt: &str) -> Option<u32> {
    let mut depth = 0i32;
    let bytes = wkt.as_bytes();
    let mut found = None;
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'[' | b'(' => depth += 1,
            b']' | b')' => depth -= 1,
            b'"' => {
                // Skip quoted text ("" is an escaped quote).
                i += 1;
                while i < bytes.len() && bytes[i] != b'"' {
                    i += 1;
                }
            }
            _ if depth == 1 => {
                let rest = &wkt[i..];
                let upper: String = rest
                    .chars()
                    .take(10)
                    .collect::<String>()
                    .to_ascii_uppercase();
                let tag = if upper.starts_with("AUTHORITY[") {
                    Some(10)
                } else if upper.starts_with("ID[") {
                    Some(3)
                } else {
                    None
                };
                if let Some(len) = tag {
                    let inner = &rest[len..rest.find(']').unwrap_or(rest.len())];
                    let mut parts = inner.split(',').map(|p| p.trim().trim_matches('"'));
                    if parts.next().is_some_and(|a| a.eq_ignore_ascii_case("EPSG")) {
                        found = parts.next().and_then(|c| c.parse().ok());
                    }
                }
            }
            _ => {}
        }
        i += 1;
    }
    found
}

/// The name of a WKT CRS (its first quoted text).
fn wkt_name(wkt: &str) -> Option<String> {
    let start = wkt.find('"')? + 1;
    let len = wkt[start..].find('"')?;
    Some(wkt[start..start + len].to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_members() {
        assert_eq!(
            from_name("urn:ogc:def:crs:EPSG::3857"),
            Declared::Epsg(3857)
        );
        assert_eq!(from_name("EPSG:2056"), Declared::Epsg(2056));
        assert_eq!(
            from_name("urn:ogc:def:crs:OGC:1.3:CRS84"),
            Declared::Epsg(4326)
        );
        let member = serde_json::json!({"type": "EPSG", "properties": {"code": 25832}});
        assert_eq!(from_geojson_member(&member), Ok(Declared::Epsg(25832)));
        assert!(matches!(from_name("somewhere"), Declared::Unknown(_)));
    }

    #[test]
    fn the_outermost_authority_of_a_wkt_is_its_code() {
        let wkt = r#"PROJCS["WGS 84 / Pseudo-Mercator",GEOGCS["WGS 84",DATUM["WGS_1984",SPHEROID["WGS 84",6378137,298.257223563,AUTHORITY["EPSG","7030"]],AUTHORITY["EPSG","6326"]],PRIMEM["Greenwich",0],UNIT["degree",0.0174532925199433],AUTHORITY["EPSG","4326"]],PROJECTION["Mercator_1SP"],PARAMETER["central_meridian",0],PARAMETER["scale_factor",1],PARAMETER["false_easting",0],PARAMETER["false_northing",0],UNIT["metre",1],AUTHORITY["EPSG","3857"]]"#;
        assert_eq!(wkt_epsg_code(wkt), Some(3857));
        assert_eq!(
            wkt_epsg_code(r#"GEOGCS["x",DATUM["y",SPHEROID["z",1,2]]]"#),
            None
        );
    }

    #[test]
    fn the_option() {
        assert_eq!("epsg:3857".parse::<CrsOption>(), Ok(CrsOption::Epsg(3857)));
        assert_eq!("local".parse::<CrsOption>(), Ok(CrsOption::Local));
        assert!("EPSG:1".parse::<CrsOption>().is_err());
        assert!("3857".parse::<CrsOption>().is_err());
    }
}
