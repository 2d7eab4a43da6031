//! Manoeuvre metrics read off any trajectory, measured or simulated, without knowing the
//! commands that made it: zigzag overshoots from the rudder's reversals (the heading when the
//! rudder starts back is the switching heading), turning-circle advance, transfer and tactical
//! diameter from the track, measured from the rudder execute (the last sample before the rudder
//! leaves its approach angle) along the course at that moment. A record in which the rudder goes
//! to one side and comes back to midship (a turning circle as basins record it) is a turn, not
//! a zigzag. Used to set a model's predictions beside a measurement.

use serde::Serialize;

use super::manoeuvre::turning::at_level;

/// What a trajectory shows.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Observed {
    /// Rudder reversals found.
    pub reversals: usize,
    /// First overshoot beyond the switching heading, degrees (zigzags).
    pub first_overshoot_deg: Option<f64>,
    /// Second overshoot, degrees.
    pub second_overshoot_deg: Option<f64>,
    /// Distance along the initial course at 90° heading change, m (turns).
    pub advance_m: Option<f64>,
    /// Distance across at 90°, m.
    pub transfer_m: Option<f64>,
    /// Distance across at 180°, m.
    pub tactical_diameter_m: Option<f64>,
}

/// When the rudder left its extreme at sample `k` (its last sample there): extrapolated back
/// from the next two samples at the rate it then moves.
fn switch_time(t: &[f64], delta: &[f64], k: usize) -> f64 {
    if k + 2 >= t.len().min(delta.len()) {
        return t[k.min(t.len() - 1)];
    }
    let rate = (delta[k + 2] - delta[k + 1]) / (t[k + 2] - t[k + 1]);
    if rate == 0.0 {
        return t[k];
    }
    (t[k + 1] - (delta[k + 1] - delta[k]) / rate).clamp(t[k], t[k + 1])
}

/// Metrics from samples of time, heading ψ (rad), rudder δ (rad) and position (x0, y0).
pub fn observe(t: &[f64], psi: &[f64], delta: &[f64], x0: &[f64], y0: &[f64]) -> Observed {
    let n = t.len().min(psi.len()).min(delta.len());
    // a reversal: the rudder's motion changes direction after moving at least 1° one way; the
    // switch itself lies between the last sample at the rudder's extreme and the next one
    let mut rev: Vec<f64> = Vec::new(); // switch times
    let mut dir = 0.0f64;
    let mut anchor = (delta.first().copied().unwrap_or(0.0), 0usize);
    for k in 1..n {
        if (delta[k] - anchor.0).abs() < 1e-9 || (dir != 0.0 && (delta[k] - anchor.0) * dir > 0.0) {
            anchor = (delta[k], k);
            continue;
        }
        if (delta[k] - anchor.0).abs() > 1f64.to_radians() {
            let d = (delta[k] - anchor.0).signum();
            if dir != 0.0 && d != dir {
                // a measured rudder jitters at its extreme: the highest sample is anywhere in
                // the hold; it left the extreme at the last sample still within 0.2° of it
                let level = 0.2f64.to_radians();
                let left =
                    (anchor.1..k).rev().find(|&j| (delta[j] - anchor.0).abs() <= level).unwrap_or(anchor.1);
                rev.push(switch_time(t, delta, left));
            }
            dir = d;
            anchor = (delta[k], k);
        }
    }
    let at = |ts: f64, v: &[f64]| -> f64 {
        let i = t[..n].iter().position(|x| *x >= ts).unwrap_or(n - 1).max(1);
        let w = ((ts - t[i - 1]) / (t[i] - t[i - 1])).clamp(0.0, 1.0);
        v[i - 1] + w * (v[i] - v[i - 1])
    };
    let mut out = Observed { reversals: rev.len(), ..Observed::default() };
    let overshoot = |i: usize| -> Option<f64> {
        let ts = *rev.get(i)?;
        let te = rev.get(i + 1).copied().unwrap_or(t[n - 1]);
        let h = at(ts, psi);
        // the turn continues the way the heading was going at the switch
        let way = (h - at(ts - 1.0, psi)).signum();
        let extreme = (0..n)
            .filter(|&k| t[k] >= ts && t[k] <= te)
            .map(|k| (psi[k] - h) * way)
            .fold(f64::NEG_INFINITY, f64::max);
        Some(extreme.to_degrees())
    };
    if rev.len() >= 2 {
        out.first_overshoot_deg = overshoot(0);
        out.second_overshoot_deg = overshoot(1);
    }
    // a turn: the rudder never goes more than 1° past its approach angle to the other side
    // (back at midship at the end of the record is still a turn)
    let off: Vec<f64> = delta[..n].iter().map(|d| d - delta[0]).collect();
    let main = off.iter().copied().fold(0.0f64, |m, d| if d.abs() > m.abs() { d } else { m });
    let turn = off.iter().all(|d| d * main.signum() > -1f64.to_radians());
    if n > 1 && turn && main.abs() > 1f64.to_radians() {
        // the execute: the last sample before the rudder leaves its approach angle by 0.5°
        let e = off.iter().position(|d| d.abs() > 0.5f64.to_radians()).map_or(0, |k| k.saturating_sub(1));
        let m = n.min(x0.len()).min(y0.len());
        let (ce, se) = (psi[e].cos(), psi[e].sin());
        let sign = if psi[m - 1] >= psi[e] { 1.0 } else { -1.0 };
        let turned: Vec<f64> = psi[e..m].iter().map(|p| sign * (p - psi[e]).to_degrees()).collect();
        // along and across the course at the execute
        let x: Vec<f64> = (e..m).map(|k| (x0[k] - x0[e]) * ce + (y0[k] - y0[e]) * se).collect();
        let y: Vec<f64> = (e..m).map(|k| (-(x0[k] - x0[e]) * se + (y0[k] - y0[e]) * ce).abs()).collect();
        out.advance_m = at_level(&turned, &x, 90.0);
        out.transfer_m = at_level(&turned, &y, 90.0);
        out.tactical_diameter_m = at_level(&turned, &y, 180.0);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ship::basin::{Artefacts, Basin};
    use crate::ship::{Manoeuvre, Metrics};

    /// A turning circle as a basin records it — an approach, then the turn, the rudder back at
    /// midship at the end, noise, and an approach course that is not the x axis — reads as
    /// the manoeuvre's own metrics, measured from the rudder execute.
    #[test]
    fn a_recorded_turn_ending_at_midship_is_a_turn_measured_from_the_execute() {
        let model = crate::ship::default_model();
        let basin =
            Basin { artefacts: Artefacts { midship_end_s: 8.0, ..Artefacts::default() }, ..Basin::default() };
        let rec =
            basin.record(&model, &Manoeuvre::parse("turning:-35").unwrap(), 2.01, 60.0, 7, "tc.dat").unwrap();
        let Metrics::Turning(truth) = &rec.metrics else { panic!("a turn") };
        let f = &rec.measured;
        let c = |n: &str| f.column(n).unwrap();
        // the whole record turned by 40°: the approach course is 40° off the x axis
        let a = 40f64.to_radians();
        let (x, y) = (c("x0"), c("y0"));
        let xr: Vec<f64> = x.iter().zip(y).map(|(x, y)| x * a.cos() - y * a.sin()).collect();
        let yr: Vec<f64> = x.iter().zip(y).map(|(x, y)| x * a.sin() + y * a.cos()).collect();
        let psi: Vec<f64> = c("ψ").iter().map(|p| p + a).collect();
        let seen = observe(f.time(), &psi, c("δ"), &xr, &yr);
        assert_eq!(seen.reversals, 1, "the rudder back to midship is one reversal");
        for (got, want) in [
            (seen.advance_m, truth.advance_m),
            (seen.tactical_diameter_m, truth.tactical_diameter_m),
            (seen.transfer_m, truth.transfer_m),
        ] {
            let (g, w) = (got.expect("read off the record"), want.unwrap());
            assert!((g - w).abs() < 0.1, "{g} m vs the manoeuvre's {w} m");
        }
        assert!(seen.first_overshoot_deg.is_none());
    }
}
