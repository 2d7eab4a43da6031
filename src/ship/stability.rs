//! A ship model's linear sway-yaw dynamics at its straight run: ∂(v̇, ṙ)/∂(v, r), the rudder's
//! ∂ṙ/∂δ and the two time constants they make (a negative one is a course-unstable mode). What
//! a model carries into the turns beyond what its zigzags bound; the physical checks read it,
//! and so can a study that sets models side by side.

use nalgebra::{DMatrix, DVector, Matrix2, Vector2};

use super::{Ship, StraightRun};

/// The linearised sway and yaw at a straight run, by central differences of the right-hand
/// side (steps of 10⁻⁴ u0 in v, that over L in r, 0.01° in δ). States of the model's own
/// beyond the ship's (a lag of the hull's forces, a filter) enter at their steady values
/// (static condensation), so the derivatives are the steady ones a captive test measures and
/// the determinant's criterion of straight-line stability holds for such a model too (its own
/// states stable by themselves, as a lag is).
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
        let own = ship.own_states(&start.x, &start.input);
        let rows: Vec<usize> = [r.v, r.r].into_iter().chain(own.iter().copied()).collect();
        let mut ws = ship.system.workspace();
        let mut d = vec![0.0; start.x.len()];
        let mut rate = |x: &[f64], input: &[f64]| {
            ship.system.derivatives(x, input, &mut ws, &mut d);
            rows.iter().map(|&i| d[i]).collect::<Vec<f64>>()
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
            DVector::from_iterator(plus.len(), plus.iter().zip(&minus).map(|(p, m)| (p - m) / (2.0 * h)))
        };
        let hv = 1e-4 * ship.spec.u0;
        let mut columns = vec![slope(Some(r.v), hv), slope(Some(r.r), hv / ship.spec.lpp)];
        columns.extend(own.iter().map(|&i| slope(Some(i), 1e-6 * start.x[i].abs().max(1.0))));
        let jacobian = DMatrix::from_columns(&columns);
        let rudder = slope(None, 0.01f64.to_radians());
        let (a, b) = condensed(&jacobian, &rudder);
        SwayYaw {
            u0: start.x[r.u],
            yv: a[(0, 0)],
            yr: a[(0, 1)],
            nv: a[(1, 0)],
            nr: a[(1, 1)],
            n_delta: b[1],
        }
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

/// The sway-yaw block of `jacobian` (rows and columns v, r, then the model's own states) and
/// the rudder's column with the own states at their steady values: A − B E⁻¹ C. Where the own
/// states have no steady value of their own (E singular), the block as it stands.
fn condensed(jacobian: &DMatrix<f64>, rudder: &DVector<f64>) -> (Matrix2<f64>, Vector2<f64>) {
    let a = Matrix2::from_fn(|i, j| jacobian[(i, j)]);
    let b = Vector2::new(rudder[0], rudder[1]);
    let n = jacobian.nrows();
    if n == 2 {
        return (a, b);
    }
    let e = jacobian.view((2, 2), (n - 2, n - 2)).into_owned();
    let Some(e_inv) = e.try_inverse() else { return (a, b) };
    let coupling = jacobian.view((0, 2), (2, n - 2)) * e_inv;
    let a = a - Matrix2::from_iterator((&coupling * jacobian.view((2, 0), (n - 2, 2))).iter().copied());
    let b = b - Vector2::from_iterator((&coupling * rudder.rows(2, n - 2)).iter().copied());
    (a, b)
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

    /// A linear ship whose hull moment reaches ṙ through a first-order lag (a state of the
    /// model's own) has the plain ship's straight run and steady derivatives, and the lag's
    /// state sits at its steady value; before, the straight run held the lag at 0 and the yaw
    /// damping read 0 (the hull's moment only through the lag). A distance run (ṡ = u), which
    /// nothing depends on, only integrates, as the track does.
    #[test]
    fn a_lag_of_the_models_own_is_steady_in_the_straight_run() {
        let hull = "-0.3*v - 0.8*r + 0.004";
        let ship = |lagged: bool| {
            let (yaw, lag) = if lagged {
                (
                    "\"h\" = 1.0".to_string(),
                    format!(
                        "[[states]]\nname = \"h\"\nunit = \"rad/s²\"\n[equations.h_dot]\nstate = \"h\"\n\
                         identify = false\ncoefficients = {{ \"({hull} - h)/1.5\" = 1.0 }}\n\
                         [[states]]\nname = \"s\"\nunit = \"m\"\n[equations.s_dot]\nstate = \"s\"\n\
                         identify = false\ncoefficients = {{ u = 1.0 }}\n"
                    ),
                )
            } else {
                (format!("\"{hull}\" = 1.0"), String::new())
            };
            let text = format!(
                "[model]\nname = \"linear\"\nintercept = false\n\
                 [[states]]\nname = \"u\"\nunit = \"m/s\"\n[[states]]\nname = \"v\"\nunit = \"m/s\"\n\
                 [[states]]\nname = \"r\"\nunit = \"rad/s\"\n[[states]]\nname = \"ψ\"\nunit = \"rad\"\n\
                 [[states]]\nname = \"x0\"\nunit = \"m\"\n[[states]]\nname = \"y0\"\nunit = \"m\"\n\
                 [[inputs]]\nname = \"δ\"\nunit = \"rad\"\n\
                 [equations.u_dot]\nstate = \"u\"\nidentify = false\ncoefficients = {{ \"0*u\" = 1.0 }}\n\
                 [equations.v_dot]\nstate = \"v\"\nidentify = false\n\
                 coefficients = {{ \"-0.5*v - 0.2*r + 0.05*δ + 0.002\" = 1.0 }}\n\
                 [equations.r_dot]\nstate = \"r\"\nidentify = false\ncoefficients = {{ {yaw}, \"0.1*δ\" = 1.0 }}\n\
                 [equations.psi_dot]\nstate = \"ψ\"\nidentify = false\ncoefficients = {{ r = 1.0 }}\n\
                 [equations.x0_dot]\nstate = \"x0\"\nidentify = false\ncoefficients = {{ \"u*cos(ψ)\" = 1.0 }}\n\
                 [equations.y0_dot]\nstate = \"y0\"\nidentify = false\ncoefficients = {{ \"u*sin(ψ)\" = 1.0 }}\n\
                 {lag}\
                 [ship]\nlpp = 7.0\nrudder_rate = 15.0\nrudder_limit = 35.0\nu0 = 1.0\n"
            );
            Ship::new(&crate::model::Model::parse(&text, "linear.toml").unwrap(), false).unwrap()
        };
        let (plain, lagged) = (ship(false), ship(true));
        let (p, l) = (plain.straight_run().unwrap(), lagged.straight_run().unwrap());
        // closed form: −0.5 v + 0.05 δ = −0.002, −0.3 v + 0.1 δ = −0.004
        let (v0, delta0) = (0.0, -0.04);
        assert!((p.v0 - v0).abs() < 1e-9 && (p.delta0_deg.to_radians() - delta0).abs() < 1e-9, "{p:?}");
        assert!((l.v0 - v0).abs() < 1e-9 && (l.delta0_deg - p.delta0_deg).abs() < 1e-9, "{l:?}");
        let h = lagged.system.states.iter().position(|s| s == "h").unwrap();
        assert!((l.x[h] - (-0.3 * v0 + 0.004)).abs() < 1e-9, "{l:?}");
        let (sp, sl) = (SwayYaw::of(&plain, &p), SwayYaw::of(&lagged, &l));
        for (a, b, exact) in
            [(sp.yv, sl.yv, -0.5), (sp.yr, sl.yr, -0.2), (sp.nv, sl.nv, -0.3), (sp.nr, sl.nr, -0.8)]
        {
            assert!((a - exact).abs() < 1e-6 && (b - exact).abs() < 1e-6, "{sp:?} {sl:?}");
        }
        assert!((sl.n_delta - 0.1).abs() < 1e-6 && sl.course_stable(), "{sl:?}");
    }
}
