//! Geographic lots: GeoJSON in longitude/latitude projected into a local
//! metric frame, so that rules work in metres.
//!
//! The projection is a local tangent plane (equirectangular about the
//! centre of the data): x = R·cos(lat0)·Δlon, y = R·Δlat, with the WGS84
//! mean radius. Over the extent of a city (tens of kilometres) its scale
//! error stays below a few parts in ten thousand, which is what a building
//! model tolerates; the origin is returned so that models can be placed
//! back on the globe.

/// Mean Earth radius (WGS84), metres.
pub const EARTH_RADIUS: f64 = 6_371_008.8;

/// The geographic point at the local frame's origin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeoOrigin {
    pub lon: f64,
    pub lat: f64,
}

impl GeoOrigin {
    /// The (longitude, latitude) of a point `east`, `north` metres from the
    /// origin: the inverse of [`to_local`](GeoOrigin::to_local).
    pub fn to_geo(&self, east: f64, north: f64) -> (f64, f64) {
        let k = std::f64::consts::PI / 180.0;
        (
            self.lon + east / (EARTH_RADIUS * (self.lat * k).cos() * k),
            self.lat + north / (EARTH_RADIUS * k),
        )
    }

    /// Metres east and north of the origin of a (lon, lat) point.
    pub fn to_local(&self, lon: f64, lat: f64) -> (f64, f64) {
        let k = std::f64::consts::PI / 180.0;
        (
            EARTH_RADIUS * (self.lat * k).cos() * (lon - self.lon) * k,
            EARTH_RADIUS * (lat - self.lat) * k,
        )
    }
}

/// Whether coordinates look geographic: all within longitude/latitude
/// ranges, spanning less than a degree (a city, not a planar drawing whose
/// numbers happen to be small: a 20 x 30 m lot at the origin spans 30
/// "degrees"), and not all integers.
pub fn looks_geographic(points: &[[f64; 2]]) -> bool {
    if points.is_empty() {
        return false;
    }
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    for p in points {
        for k in 0..2 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let in_range = lo[0] >= -180.0 && hi[0] <= 180.0 && lo[1] >= -90.0 && hi[1] <= 90.0;
    let small = hi[0] - lo[0] < 1.0 && hi[1] - lo[1] < 1.0;
    let fractional = points
        .iter()
        .any(|p| p[0].fract() != 0.0 || p[1].fract() != 0.0);
    in_range && small && fractional
}

/// Projects a GeoJSON document's coordinates to local metres (x east, y
/// north, z kept) if they look geographic; returns the origin used: `frame`
/// when given (so that several files share one frame), else the centre of
/// the data.
pub fn localize_geojson(gj: &mut geojson::GeoJson, frame: Option<GeoOrigin>) -> Option<GeoOrigin> {
    let mut points = Vec::new();
    for_each_position(gj, &mut |p| {
        if p.len() >= 2 {
            points.push([p[0], p[1]]);
        }
    });
    if !looks_geographic(&points) {
        return None;
    }
    let n = points.len() as f64;
    let origin = frame.unwrap_or(GeoOrigin {
        lon: points.iter().map(|p| p[0]).sum::<f64>() / n,
        lat: points.iter().map(|p| p[1]).sum::<f64>() / n,
    });
    for_each_position(gj, &mut |p| {
        if p.len() >= 2 {
            let (x, y) = origin.to_local(p[0], p[1]);
            p[0] = x;
            p[1] = y;
        }
    });
    Some(origin)
}

fn for_each_position(gj: &mut geojson::GeoJson, f: &mut impl FnMut(&mut Vec<f64>)) {
    fn geometry(g: &mut geojson::Geometry, f: &mut impl FnMut(&mut Vec<f64>)) {
        use geojson::Value::*;
        match &mut g.value {
            Point(p) => f(p),
            MultiPoint(ps) | LineString(ps) => ps.iter_mut().for_each(&mut *f),
            MultiLineString(ls) | Polygon(ls) => ls.iter_mut().flatten().for_each(&mut *f),
            MultiPolygon(pss) => pss.iter_mut().flatten().flatten().for_each(&mut *f),
            GeometryCollection(gs) => gs.iter_mut().for_each(|g| geometry(g, f)),
        }
    }
    match gj {
        geojson::GeoJson::Geometry(g) => geometry(g, f),
        geojson::GeoJson::Feature(feat) => {
            if let Some(g) = &mut feat.geometry {
                geometry(g, f)
            }
        }
        geojson::GeoJson::FeatureCollection(fc) => {
            for feat in &mut fc.features {
                if let Some(g) = &mut feat.geometry {
                    geometry(g, f)
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_degree_of_latitude_is_about_111_km() {
        let o = GeoOrigin {
            lon: 8.5,
            lat: 47.0,
        };
        let (x, y) = o.to_local(8.5, 47.001);
        assert!(x.abs() < 1e-9);
        assert!((y - 111.195).abs() < 0.01, "{y}");
        // East-west distances shrink with cos(latitude).
        let (x, _) = o.to_local(8.501, 47.0);
        assert!((x - 111.195 * 47f64.to_radians().cos()).abs() < 0.01, "{x}");
    }

    #[test]
    fn planar_drawings_are_not_taken_for_geographic_data() {
        assert!(!looks_geographic(&[[0.0, 0.0], [20.0, 0.0], [20.0, 30.0]]));
        assert!(!looks_geographic(&[[2600000.5, 1200000.5]]));
        assert!(looks_geographic(&[[8.5401, 47.3769], [8.5409, 47.3771]]));
    }
}
