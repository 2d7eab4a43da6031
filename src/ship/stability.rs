//! A ship model's linear sway-yaw dynamics at its straight run: ∂(v̇, ṙ)/∂(v, r), the rudder's
//! ∂ṙ/∂δ and the two time constants they make (a negative one is a course-unstable mode). What
//! a model carries into the turns beyond what its zigzags bound; the physical checks read it,
//! and so can a study that sets models side by side.

use super::{Ship, StraightRun};

/// The linearised sway and yaw at a straight run, by central differences of the right-hand
/// side (steps of 10⁻⁴ u0 in v, that over L in r, 0.01° in δ).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SwayYaw {
    /// Speed of the straight run, m/s.
    pub u0: f64,
    /// ∂v̇/∂v, 1/s (sway damping: negative on every hull).
    pub yv: f64,
    /// ∂v̇/∂r, m/s per rad/s.
    pub yr: f64,
    /// ∂ṙ/∂v, rad/s² per m/s.
    pub nv: f64,
    /// ∂ṙ/∂r, 1/s (yaw damping: negative on every hull).
    pub nr: f64,
    /// ∂ṙ/∂δ, 1/s² (the rudder's yaw moment per radian, over the inertia).
    pub n_delta: f64,
}

impl SwayYaw {
    /// The derivatives of `ship` at `start` (its straight run).
    pub fn of(ship: &Ship, start: &StraightRun) -> SwayYaw {
        let r = ship.roles;
        let mut ws = ship.system.workspace();
        let mut d = vec![0.0; start.x.len()];
        let mut rate = |x: &[f64], input: &[f64]| {
            ship.system.derivatives(x, input, &mut ws, &mut d);
            (d[r.v], d[r.r])
        };
        let mut slope = |state: Option<usize>, h: f64| {
            let (mut x, mut input) = (start.x.clone(), start.input.clone());
            let shift = |x: &mut Vec<f64>, input: &mut Vec<f64>, by: f64| match state {
                Some(s) => x[s] += by,
                None => input[r.rudder] += by,
            };
            shift(&mut x, &mut input, h);
            let plus = rate(&x, &input);
            shift(&mut x, &mut input, -2.0 * h);
            let minus = rate(&x, &input);
            ((plus.0 - minus.0) / (2.0 * h), (plus.1 - minus.1) / (2.0 * h))
        };
        let hv = 1e-4 * ship.spec.u0;
        let (yv, nv) = slope(Some(r.v), hv);
        let (yr, nr) = slope(Some(r.r), hv / ship.spec.lpp);
        let (_, n_delta) = slope(None, 0.01f64.to_radians());
        SwayYaw { u0: start.x[r.u], yv, yr, nv, nr, n_delta }
    }

    /// Whether the linear sway-yaw system is stable: trace negative, determinant positive (the
    /// determinant's sign is the classical criterion of straight-line stability).
    pub fn course_stable(&self) -> bool {
        self.trace() < 0.0 && self.determinant() > 0.0
    }

    /// The larger real part of the two eigenvalues, 1/s (positive: a disturbance grows).
    pub fn largest_eigenvalue(&self) -> f64 {
        self.trace() / 2.0 + self.discriminant().max(0.0).sqrt()
    }

    /// The two time constants −1/λ, s, fast first, where both eigenvalues are real (a negative
    /// one is the doubling time of an unstable mode over ln 2); `None` for an oscillating pair.
    pub fn time_constants(&self) -> Option<(f64, f64)> {
        let disc = self.discriminant();
        (disc >= 0.0).then(|| {
            let (a, b) = (self.trace() / 2.0 - disc.sqrt(), self.trace() / 2.0 + disc.sqrt());
            (-1.0 / a, -1.0 / b)
        })
    }

    fn trace(&self) -> f64 {
        self.yv + self.nr
    }

    fn determinant(&self) -> f64 {
        self.yv * self.nr - self.yr * self.nv
    }

    /// (trace/2)² − determinant: the eigenvalues are trace/2 ± its root, real where ≥ 0.
    fn discriminant(&self) -> f64 {
        self.trace() * self.trace() / 4.0 - self.determinant()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper's ship: damped in sway and yaw, course-stable, with a rudder moment; the
    /// eigenvalues from the time constants agree with the trace and the determinant; closed-form
    /// 2×2 cases (triangular: their own time constants; coupled into instability).
    #[test]
    fn the_papers_ship_and_closed_form_cases() {
        let ship = Ship::new(&crate::ship::default_model(), false).unwrap();
        let start = ship.straight_run().unwrap();
        let s = SwayYaw::of(&ship, &start);
        assert!(s.yv < 0.0 && s.nr < 0.0 && s.n_delta != 0.0, "{s:?}");
        assert!(s.course_stable());
        let (t1, t2) = s.time_constants().unwrap();
        assert!(t1 > 0.0 && t2 >= t1, "{t1} {t2}");
        assert!(((-1.0 / t1 - 1.0 / t2) - (s.yv + s.nr)).abs() < 1e-9 * (s.yv + s.nr).abs());
        assert!((s.largest_eigenvalue() + 1.0 / t2).abs() < 1e-12);
        // v̇ = −0.5 v, ṙ = −2 r + 0.1 v: time constants 0.5 s and 2 s; stable
        let d = SwayYaw { u0: 1.0, yv: -0.5, yr: 0.0, nv: 0.1, nr: -2.0, n_delta: 0.0 };
        assert_eq!(d.time_constants(), Some((0.5, 2.0)));
        assert!(d.course_stable());
        // a coupling that makes it unstable: determinant −0.5·−2 − 2·1 < 0
        let u = SwayYaw { yr: 2.0, nv: 1.0, ..d };
        assert!(!u.course_stable() && u.largest_eigenvalue() > 0.0);
        assert!(u.time_constants().unwrap().1 < 0.0);
    }
}
