//! Geographic lots: the local metric frame that lots given on the globe are
//! projected into, so that rules work in metres.
//!
//! The frame is a transverse Mercator projection on the WGS84 ellipsoid
//! (Poder/Engsager, through `proj4rs`) whose central meridian and origin
//! are the centre of the data's extent, with scale 1 on the central
//! meridian: x is east and -z north of that origin in metres, y up. The
//! projection is conformal (a square stays a square), and its scale error
//! grows with the square of the distance from the central meridian,
//! d² / (2 R²) at a distance d: 0.0001% at 10 km, 0.03% at 150 km
//! (`docs/geographic.md`).
//! The origin is written into the models so that they can be placed back
//! on the globe.

use proj4rs::Proj;

/// The geographic point (WGS84 degrees) at the local frame's origin, on
/// its central meridian.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeoOrigin {
    pub lon: f64,
    pub lat: f64,
}

impl GeoOrigin {
    /// The frame as a PROJ string (what models record).
    pub fn proj_string(&self) -> String {
        format!(
            "+proj=tmerc +lat_0={} +lon_0={} +k_0=1 +x_0=0 +y_0=0 +datum=WGS84 +units=m +no_defs",
            self.lat, self.lon
        )
    }

    /// The frame's projection.
    pub fn proj(&self) -> Result<Proj, String> {
        Proj::from_proj_string(&self.proj_string())
            .map_err(|e| format!("cannot set up the local frame at {self:?}: {e}"))
    }

    /// The (longitude, latitude) of a point `east`, `north` metres from the
    /// origin: the inverse of [`to_local`](GeoOrigin::to_local). NaN if
    /// the point is not on the globe.
    pub fn to_geo(&self, east: f64, north: f64) -> (f64, f64) {
        let Ok(frame) = self.proj() else {
            return (f64::NAN, f64::NAN);
        };
        let mut p = (east, north, 0.0);
        match proj4rs::transform::transform(&frame, &wgs84(), &mut p) {
            Ok(()) => (p.0.to_degrees(), p.1.to_degrees()),
            Err(_) => (f64::NAN, f64::NAN),
        }
    }

    /// Metres east and north of the origin of a (lon, lat) point (degrees).
    pub fn to_local(&self, lon: f64, lat: f64) -> (f64, f64) {
        let Ok(frame) = self.proj() else {
            return (f64::NAN, f64::NAN);
        };
        let mut p = (lon.to_radians(), lat.to_radians(), 0.0);
        match proj4rs::transform::transform(&wgs84(), &frame, &mut p) {
            Ok(()) => (p.0, p.1),
            Err(_) => (f64::NAN, f64::NAN),
        }
    }

    /// The frame for data within `extent`: its centre.
    pub fn centred_on(extent: &GeoExtent) -> Option<GeoOrigin> {
        let (lon, lat) = extent.centre()?;
        Some(GeoOrigin { lon, lat })
    }
}

/// Longitude/latitude on WGS84 (radians in, radians out, as PROJ has it).
pub fn wgs84() -> Proj {
    // A constant, well-formed string: parsing cannot fail.
    Proj::from_proj_string("+proj=longlat +datum=WGS84 +no_defs").expect("WGS84 definition")
}

/// The extent of geographic points, for choosing the frame. Longitudes are
/// kept on two circles' cuts (at ±180° and at 0°/360°) so that data on
/// both sides of the antimeridian has the small extent it really has.
#[derive(Clone, Copy, Debug)]
pub struct GeoExtent {
    /// Longitude min and max in -180..180.
    lon: [f64; 2],
    /// Longitude min and max in 0..360.
    lon360: [f64; 2],
    lat: [f64; 2],
}

impl Default for GeoExtent {
    fn default() -> Self {
        GeoExtent {
            lon: [f64::INFINITY, f64::NEG_INFINITY],
            lon360: [f64::INFINITY, f64::NEG_INFINITY],
            lat: [f64::INFINITY, f64::NEG_INFINITY],
        }
    }
}

impl GeoExtent {
    /// Adds a point (degrees).
    pub fn add(&mut self, lon: f64, lat: f64) {
        if !lon.is_finite() || !lat.is_finite() {
            return;
        }
        let lon = wrap180(lon);
        let l360 = lon.rem_euclid(360.0);
        self.lon = [self.lon[0].min(lon), self.lon[1].max(lon)];
        self.lon360 = [self.lon360[0].min(l360), self.lon360[1].max(l360)];
        self.lat = [self.lat[0].min(lat), self.lat[1].max(lat)];
    }

    /// The centre (lon, lat) of the smaller of the two longitude ranges and
    /// of the latitude range; `None` when no point was added.
    pub fn centre(&self) -> Option<(f64, f64)> {
        if self.lat[0] > self.lat[1] {
            return None;
        }
        let lat = (self.lat[0] + self.lat[1]) / 2.0;
        let lon = if self.lon360[1] - self.lon360[0] < self.lon[1] - self.lon[0] {
            wrap180((self.lon360[0] + self.lon360[1]) / 2.0)
        } else {
            (self.lon[0] + self.lon[1]) / 2.0
        };
        Some((lon, lat))
    }

    /// The east-west and north-south size in degrees (the smaller
    /// longitude range).
    pub fn span(&self) -> (f64, f64) {
        let lon = (self.lon[1] - self.lon[0]).min(self.lon360[1] - self.lon360[0]);
        (lon.max(0.0), (self.lat[1] - self.lat[0]).max(0.0))
    }
}

/// A longitude in -180..180.
fn wrap180(lon: f64) -> f64 {
    let l = (lon + 180.0).rem_euclid(360.0) - 180.0;
    if l == -180.0 && lon > 0.0 {
        180.0
    } else {
        l
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_thousandth_degree_of_latitude_is_about_111_m() {
        let o = GeoOrigin {
            lon: 8.5,
            lat: 47.0,
        };
        let (x, y) = o.to_local(8.5, 47.001);
        assert!(x.abs() < 1e-9);
        // The WGS84 meridian arc at 47 deg N: 111.18 m per 0.001 deg.
        assert!((y - 111.18).abs() < 0.01, "{y}");
        let (lon, lat) = o.to_geo(x, y);
        assert!((lon - 8.5).abs() < 1e-12 && (lat - 47.001).abs() < 1e-12);
    }

    #[test]
    fn extents_across_the_antimeridian_are_small() {
        let mut e = GeoExtent::default();
        e.add(179.99, 10.0);
        e.add(-179.99, 10.2);
        let (lon, lat) = e.centre().unwrap();
        assert!((lon.abs() - 180.0).abs() < 1e-9, "{lon}");
        assert!((lat - 10.1).abs() < 1e-12);
        assert!((e.span().0 - 0.02).abs() < 1e-9);
        let mut e = GeoExtent::default();
        e.add(6.0, 45.0);
        e.add(10.0, 48.0);
        assert_eq!(e.centre(), Some((8.0, 46.5)));
    }
}
