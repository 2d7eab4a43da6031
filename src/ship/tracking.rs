//! Tracking filter for measured runs: an extended Kalman filter with Rauch-Tung-Striebel
//! smoother on the ship's kinematics, which is what current identification practice uses
//! to prepare free-running model tests. The state is the position (x0, y0), the heading ψ
//! and, for each of u, v, r, its value, rate and acceleration driven by white jerk; the
//! kinematics couple them (ẋ0 = u cos ψ − v sin ψ, ẏ0 = u sin ψ + v cos ψ, ψ̇ = r, eq. B9), so
//! the track and the gyro inform the velocities the log measures. Every sensor's noise and
//! each velocity's jerk intensity come from the per-signal maximum-likelihood fits of
//! [`crate::data::KalmanSmoother::noise_model`]. Output: smoothed states and their body-frame
//! rates `u_dot`, `v_dot`, `r_dot`, the targets of identification.

use nalgebra::{SMatrix, SVector};

use super::ShipSpec;
use crate::data::{DataError, Frame, KalmanSmoother};

const N: usize = 12;
type State = SVector<f64, N>;
type Cov = SMatrix<f64, N, N>;

// state layout
const X0: usize = 0;
const Y0: usize = 1;
const PSI: usize = 2;
/// First index of the (value, rate, acceleration) blocks of u, v and r.
const U: usize = 3;
const V: usize = 6;
const R: usize = 9;

/// The state after `dt`: velocity blocks as exact polynomials, heading integrated exactly,
/// position by Simpson's rule along the polynomial path.
fn propagate(z: &State, dt: f64) -> State {
    let poly = |b: usize, t: f64| z[b] + z[b + 1] * t + 0.5 * z[b + 2] * t * t;
    let psi = |t: f64| z[PSI] + z[R] * t + 0.5 * z[R + 1] * t * t + z[R + 2] * t * t * t / 6.0;
    let vel = |t: f64| {
        let (u, v, p) = (poly(U, t), poly(V, t), psi(t));
        (u * p.cos() - v * p.sin(), u * p.sin() + v * p.cos())
    };
    let (a, b, c) = (vel(0.0), vel(0.5 * dt), vel(dt));
    let mut out = *z;
    out[X0] += dt / 6.0 * (a.0 + 4.0 * b.0 + c.0);
    out[Y0] += dt / 6.0 * (a.1 + 4.0 * b.1 + c.1);
    out[PSI] = psi(dt);
    for blk in [U, V, R] {
        out[blk] = poly(blk, dt);
        out[blk + 1] = z[blk + 1] + z[blk + 2] * dt;
    }
    out
}

/// ∂propagate/∂z by central differences (the kinematics are smooth; 12 columns).
fn jacobian(z: &State, dt: f64) -> Cov {
    let mut f = Cov::zeros();
    for j in 0..N {
        let h = 1e-6 * (1.0 + z[j].abs());
        let (mut a, mut b) = (*z, *z);
        a[j] += h;
        b[j] -= h;
        f.set_column(j, &((propagate(&a, dt) - propagate(&b, dt)) / (2.0 * h)));
    }
    f
}

/// White-jerk process noise of the three velocity blocks.
fn process_noise(dt: f64, q: [f64; 3]) -> Cov {
    let (d2, d3) = (dt * dt, dt * dt * dt);
    let block = [
        [d2 * d3 / 20.0, d2 * d2 / 8.0, d3 / 6.0],
        [d2 * d2 / 8.0, d3 / 3.0, d2 / 2.0],
        [d3 / 6.0, d2 / 2.0, dt],
    ];
    let mut m = Cov::zeros();
    for (k, blk) in [U, V, R].into_iter().enumerate() {
        for i in 0..3 {
            for j in 0..3 {
                m[(blk + i, blk + j)] = q[k] * block[i][j];
            }
        }
    }
    m
}

/// The measured channels: state index and column name.
fn channels(names: &super::ShipNames) -> [(usize, String); 6] {
    [
        (X0, names.x0.clone()),
        (Y0, names.y0.clone()),
        (PSI, names.psi.clone()),
        (U, names.u.clone()),
        (V, names.v.clone()),
        (R, names.r.clone()),
    ]
}

/// Smooths a measured run of a ship: the returned frame has the states replaced by their
/// smoothed values (if `smooth`) and `<u>_dot`, `<v>_dot`, `<r>_dot` added.
pub fn track(frame: &Frame, ship: &ShipSpec, smooth: bool) -> Result<Frame, DataError> {
    let t = frame.time();
    let n = t.len();
    if n < 8 {
        return Err(DataError::TooShort {
            file: frame.origin().into(),
            rows: n,
            needed: 8,
            what: "the tracking filter".into(),
        });
    }
    let chans = channels(&ship.names);
    let data: Vec<&[f64]> = chans.iter().map(|(_, c)| frame.require(c)).collect::<Result<_, _>>()?;
    // noise levels from each signal alone; jerk intensities of u, v, r likewise
    let models = data
        .iter()
        .zip(&chans)
        .map(|(x, (_, c))| KalmanSmoother::noise_model(t, x).map_err(|e| e.in_run(frame.origin(), Some(c))))
        .collect::<Result<Vec<_>, _>>()?;
    let variance: Vec<f64> = models.iter().map(|m| m.measurement_variance.max(f64::MIN_POSITIVE)).collect();
    let q = [models[3].jerk_intensity, models[4].jerk_intensity, models[5].jerk_intensity];
    // start: measured values, rates from the first two samples, with generous uncertainty
    let mut z = State::zeros();
    let mut p = Cov::zeros();
    let h0 = t[1] - t[0];
    for (k, (i, _)) in chans.iter().enumerate() {
        z[*i] = data[k][0];
        p[(*i, *i)] = variance[k] * 100.0;
        if *i >= U {
            z[i + 1] = (data[k][1] - data[k][0]) / h0;
            p[(i + 1, i + 1)] = 100.0 * (variance[k] / (h0 * h0) + 1.0);
            p[(i + 2, i + 2)] = 100.0 * (variance[k] / (h0 * h0 * h0 * h0) + 1.0);
        }
    }
    let (mut filtered, mut predicted, mut jacobians) =
        (Vec::with_capacity(n), Vec::with_capacity(n), Vec::with_capacity(n));
    let diverged = |k: usize| {
        DataError::UnknownMethod(
            format!("tracking filter at row {} of {}", k + 1, frame.origin()),
            "the filter diverged".into(),
        )
    };
    for k in 0..n {
        if k > 0 {
            let dt = t[k] - t[k - 1];
            let f = jacobian(&z, dt);
            z = propagate(&z, dt);
            p = f * p * f.transpose() + process_noise(dt, q);
            jacobians.push(f);
        }
        predicted.push((z, p));
        // one scalar update per sensor (their noises are independent), Joseph form
        for (c, (i, _)) in chans.iter().enumerate() {
            let s = p[(*i, *i)] + variance[c];
            let gain: State = p.column(*i) / s;
            let innovation = data[c][k] - z[*i];
            z += gain * innovation;
            let mut ikh = Cov::identity();
            for r in 0..N {
                ikh[(r, *i)] -= gain[r];
            }
            p = ikh * p * ikh.transpose() + gain * gain.transpose() * variance[c];
        }
        if !z.iter().all(|v| v.is_finite()) {
            return Err(diverged(k));
        }
        filtered.push((z, p));
    }
    let mut states: Vec<State> = filtered.iter().map(|(z, _)| *z).collect();
    for k in (0..n - 1).rev() {
        let (zf, pf) = &filtered[k];
        let (zp, pp) = &predicted[k + 1];
        let Some(inv) = pp.try_inverse() else { return Err(diverged(k)) };
        let c = pf * jacobians[k].transpose() * inv;
        states[k] = zf + c * (states[k + 1] - zp);
    }
    let mut out = frame.clone();
    let column = |i: usize| states.iter().map(|s| s[i]).collect::<Vec<f64>>();
    if smooth {
        for (i, name) in &chans {
            out.set(name, column(*i))?;
        }
    }
    for (blk, name) in [(U, &ship.names.u), (V, &ship.names.v), (R, &ship.names.r)] {
        out.set(&format!("{name}_dot"), column(blk + 1))?;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ship::basin::Basin;
    use crate::ship::Manoeuvre;

    /// On a noisy basin record the filter's accelerations are closer to the truth's than the
    /// per-signal smoother's, and its heading closer than the gyro-free record.
    #[test]
    fn fuses_track_heading_and_speeds() {
        let model = crate::ship::default_model();
        let spec = crate::ship::ShipSpec::of(&model).unwrap().unwrap();
        let rec = Basin::default()
            .record(&model, &Manoeuvre::parse("zigzag:20/20").unwrap(), 2.0, 60.0, 4, "zz")
            .unwrap();
        let tracked = track(&rec.measured, &spec, true).unwrap();
        // the truth's accelerations from the model itself
        let truth = &rec.truth;
        let exact = |name: &str| -> Vec<f64> {
            let system = crate::sim::System::new(
                &crate::ship::basin::at_approach_speed(&model, 2.0),
                &Default::default(),
                false,
            )
            .unwrap();
            let mut ws = system.workspace();
            let i = system.state_index(name).unwrap();
            (0..truth.len())
                .map(|k| {
                    let x: Vec<f64> = system.states.iter().map(|s| truth.column(s).unwrap()[k]).collect();
                    let input = [truth.column("δ").unwrap()[k]];
                    let mut d = vec![0.0; x.len()];
                    system.derivatives(&x, &input, &mut ws, &mut d);
                    d[i]
                })
                .collect()
        };
        let rms = |a: &[f64], b: &[f64]| {
            (a.iter().zip(b).skip(20).map(|(x, y)| (x - y).powi(2)).sum::<f64>() / (a.len() - 20) as f64)
                .sqrt()
        };
        for s in ["u", "v", "r"] {
            let want = exact(s);
            let fused = rms(tracked.column(&format!("{s}_dot")).unwrap(), &want);
            let (single, _) =
                KalmanSmoother::default().fit(rec.measured.time(), rec.measured.column(s).unwrap()).unwrap();
            let alone = rms(&single.rate, &want);
            let scale = rms(&want, &vec![0.0; want.len()]);
            assert!(fused < 0.25 * scale, "{s}: fused rate error {fused} vs signal {scale}");
            assert!(fused <= 1.05 * alone, "{s}: fused {fused} vs per-signal {alone}");
        }
        let psi_err = rms(tracked.column("ψ").unwrap(), truth.column("ψ").unwrap());
        assert!(psi_err < 0.1f64.to_radians() / 2.0, "heading error {}°", psi_err.to_degrees());
    }
}
