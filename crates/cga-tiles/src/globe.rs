//! Placing a tileset on the globe: the local east-north-up frame at a
//! longitude and latitude (WGS84, height 0) as a transform into
//! Earth-centred, Earth-fixed coordinates (ECEF), which is what 3D Tiles'
//! root `transform` holds.

/// WGS84 semi-major axis (m) and first eccentricity squared.
const A: f64 = 6_378_137.0;
const E2: f64 = 6.694_379_990_141_316e-3;

/// The ECEF position of (lon, lat) in degrees at height `h` metres.
pub fn ecef(lon: f64, lat: f64, h: f64) -> [f64; 3] {
    let (l, p) = (lon.to_radians(), lat.to_radians());
    let n = A / (1.0 - E2 * p.sin().powi(2)).sqrt();
    [
        (n + h) * p.cos() * l.cos(),
        (n + h) * p.cos() * l.sin(),
        (n * (1.0 - E2) + h) * p.sin(),
    ]
}

/// The column-major 4 x 4 matrix taking east-north-up metres at (lon, lat)
/// to ECEF.
pub fn enu_to_ecef(lon: f64, lat: f64) -> [f64; 16] {
    let (l, p) = (lon.to_radians(), lat.to_radians());
    let east = [-l.sin(), l.cos(), 0.0];
    let north = [-p.sin() * l.cos(), -p.sin() * l.sin(), p.cos()];
    let up = [p.cos() * l.cos(), p.cos() * l.sin(), p.sin()];
    let o = ecef(lon, lat, 0.0);
    [
        east[0], east[1], east[2], 0.0, //
        north[0], north[1], north[2], 0.0, //
        up[0], up[1], up[2], 0.0, //
        o[0], o[1], o[2], 1.0,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_equator_and_the_pole() {
        let e = ecef(0.0, 0.0, 0.0);
        assert!((e[0] - A).abs() < 1e-6 && e[1].abs() < 1e-6 && e[2].abs() < 1e-6);
        // The polar radius: a * sqrt(1 - e2) = 6,356,752.314 m.
        let n = ecef(0.0, 90.0, 0.0);
        assert!((n[2] - 6_356_752.314).abs() < 1e-3, "{n:?}");
    }

    #[test]
    fn east_north_up_is_a_rotation_at_the_point() {
        let m = enu_to_ecef(8.5, 47.3);
        let col = |k: usize| [m[4 * k], m[4 * k + 1], m[4 * k + 2]];
        let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        for i in 0..3 {
            assert!((dot(col(i), col(i)) - 1.0).abs() < 1e-12);
            for j in 0..i {
                assert!(dot(col(i), col(j)).abs() < 1e-12);
            }
        }
        // Up points away from the Earth's centre, near the position.
        let o = col(3);
        let r = dot(o, o).sqrt();
        assert!((dot(col(2), o) / r - 1.0).abs() < 1e-2);
    }
}
