//! A satellite fix's latitude and longitude as metres north and east of a run's first fix: the
//! positions a track of a ship at sea is recorded in, on the plane that touches the WGS-84
//! ellipsoid there (over a trial's few kilometres the plane shortens distances by s³/6R², half
//! a millimetre at 5 km).

/// WGS-84's semi-major axis, m, and first eccentricity squared (NIMA TR8350.2).
const A: f64 = 6_378_137.0;
const E2: f64 = 6.694_379_990_14e-3;

/// Earth-centred, earth-fixed coordinates of a point on the ellipsoid, m.
fn ecef(lat: f64, lon: f64) -> [f64; 3] {
    let n = A / (1.0 - E2 * lat.sin().powi(2)).sqrt();
    [n * lat.cos() * lon.cos(), n * lat.cos() * lon.sin(), n * (1.0 - E2) * lat.sin()]
}

/// The ellipsoid's radii of curvature at latitude `lat` (rad), m: the meridian's
/// M = a(1 − e²)/(1 − e² sin²φ)^{3/2} and the prime vertical's N = a/(1 − e² sin²φ)^{1/2}. A
/// small step north of dφ is M·dφ, one east of dλ is N·cos φ·dλ.
pub fn radii_of_curvature(lat: f64) -> (f64, f64) {
    let w = 1.0 - E2 * lat.sin().powi(2);
    (A * (1.0 - E2) / w.powf(1.5), A / w.sqrt())
}

/// Positions north and east of the first fix, m, of fixes at latitudes `lat` and longitudes
/// `lon` (rad): each fix's earth-fixed point turned into the first fix's local north and east
/// (the east-north-up frame, height dropped).
pub fn north_east(lat: &[f64], lon: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let (Some(&lat0), Some(&lon0)) = (lat.first(), lon.first()) else { return (vec![], vec![]) };
    let origin = ecef(lat0, lon0);
    let (sin_lat, cos_lat, sin_lon, cos_lon) = (lat0.sin(), lat0.cos(), lon0.sin(), lon0.cos());
    lat.iter()
        .zip(lon)
        .map(|(&p, &l)| {
            let q = ecef(p, l);
            let d = [q[0] - origin[0], q[1] - origin[1], q[2] - origin[2]];
            let east = -sin_lon * d[0] + cos_lon * d[1];
            let north = -sin_lat * cos_lon * d[0] - sin_lat * sin_lon * d[1] + cos_lat * d[2];
            (north, east)
        })
        .unzip()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One minute of arc north and east (through the earth-fixed frame), against the
    /// ellipsoid's radii of curvature in closed form (a minute of latitude at 45° is 1 852.20 m,
    /// the nautical mile's origin). A parallel is a small circle: a minute east lies y² tan φ / 2N north of the
    /// tangent plane's east axis. Across the antimeridian too.
    #[test]
    fn a_minute_of_arc_is_the_ellipsoids_radius_of_curvature() {
        let minute = (1.0f64 / 60.0).to_radians();
        for lat_deg in [0.0f64, 45.0, 60.0, -33.9] {
            let lat = lat_deg.to_radians();
            let (m, n) = radii_of_curvature(lat);
            let (x, y) = north_east(&[lat, lat + minute, lat], &[0.3, 0.3, 0.3 + minute]);
            assert!((x[1] - m * minute).abs() < 0.01 && y[1].abs() < 1e-6, "{lat_deg}: {x:?} {y:?}");
            let bend = y[2] * y[2] * lat.tan() / (2.0 * n);
            assert!((y[2] - n * lat.cos() * minute).abs() < 0.01, "{lat_deg}: {x:?} {y:?}");
            assert!((x[2] - bend).abs() < 0.001, "{lat_deg}: {x:?} {y:?}");
        }
        let (x, _) = north_east(&[45f64.to_radians(), (45.0 + 1.0 / 60.0f64).to_radians()], &[0.0, 0.0]);
        assert!((x[1] - 1852.20).abs() < 0.01, "{}", x[1]);
        let (_, y) = north_east(&[0.0, 0.0], &[179.99f64.to_radians(), (-179.99f64).to_radians()]);
        assert!((y[1] - 0.02f64.to_radians() * A).abs() < 0.01, "{}", y[1]);
    }
}
