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
    // the execute: the last sample before the rudder leaves its approach angle by 0.5°
    let e = off.iter().position(|d| d.abs() > 0.5f64.to_radians()).map_or(0, |k| k.saturating_sub(1));
    // a record without a track (no x0, y0) has no turning metrics, but its overshoots
    let m = n.min(x0.len()).min(y0.len());
    if n > 1 && turn && main.abs() > 1f64.to_radians() && m > e + 1 {
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

/// Metrics read off a simulated run of a ship as off a record (its heading, rudder and track by
/// `names`), so that a prediction is measured as its measurement is; `None` when the run lacks
/// one of them.
pub fn observe_run(run: &crate::sim::Trajectory, names: &super::ShipNames) -> Option<Observed> {
    let column = |name: &str| run.state(name).or_else(|| run.input(name));
    Some(observe(
        &run.time,
        column(&names.psi)?,
        column(&names.rudder)?,
        column(&names.x0)?,
        column(&names.y0)?,
    ))
}

/// A steering gear as zigzag records show it: the dead time from the heading passing the
/// check angle to the rudder starting back, the angular acceleration with which its rate builds
/// up, and its full rate (medians over every reversal). What `[ship] rudder_delay`,
/// `rudder_acceleration` and `rudder_rate` say of a model's gear.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct SteeringGear {
    /// Dead time, s (≥ 0).
    pub delay_s: f64,
    /// Angular acceleration, °/s².
    pub acceleration_deg_s2: f64,
    /// Full rate, °/s.
    pub rate_deg_s: f64,
    /// Reversals read.
    pub reversals: usize,
}

impl SteeringGear {
    /// The gear that a ship model's zigzag runs show, their heading and rudder read by the
    /// model's names; `None` for another model or runs without a reversal to read.
    pub fn of_runs<'a>(
        model: &crate::model::Model,
        runs: impl IntoIterator<Item = &'a crate::data::Frame>,
    ) -> Option<SteeringGear> {
        let spec = super::canonical_spec(model)?;
        let columns: Vec<_> = runs
            .into_iter()
            .filter_map(|f| Some((f.time(), f.column(&spec.names.psi)?, f.column(&spec.names.rudder)?)))
            .collect();
        steering_gear(&columns)
    }

    /// `model` with this gear in its `[ship]` table (unchanged if it is not a ship model).
    pub fn on(&self, model: &crate::model::Model) -> crate::model::Model {
        let mut model = model.clone();
        if let Ok(Some(mut spec)) = super::ShipSpec::of(&model) {
            spec.rudder_delay = self.delay_s;
            spec.rudder_acceleration = Some(self.acceleration_deg_s2);
            spec.rudder_rate = self.rate_deg_s;
            spec.store(&mut model);
        }
        model
    }
}

/// A zigzag record's shape, in degrees: its rudder angle A (the largest, to whole 5°: an
/// indicator overshoots its command a little), the heading change H at which the rudder is
/// first reversed (where the rudder leaves its first plateau, snapped to the usual 1°, 5°, 10°,
/// 15° or 20°: a record does not state it), the side the heading first turns to, the angles
/// the rudder was laid to, the rudder and the heading change in degrees, and where the rudder
/// is first laid.
#[derive(Clone, Debug)]
pub struct ZigZagShape {
    /// Rudder angle A, °.
    pub amplitude: f64,
    /// The angles the rudder held to each side, °: (positive, negative), (+A, −A) for a
    /// rudder laid exactly about 0.
    pub laid_deg: (f64, f64),
    /// Heading change H at the reversals, °.
    pub check: f64,
    /// The first turn to starboard (the heading increasing).
    pub starboard_first: bool,
    rudder: Vec<f64>,
    heading: Vec<f64>,
    laid: usize,
}

impl ZigZagShape {
    /// From samples of heading ψ and rudder δ (rad); `None` for a record that is no zigzag.
    pub fn of(psi: &[f64], delta: &[f64]) -> Option<ZigZagShape> {
        let n = psi.len().min(delta.len());
        let rudder: Vec<f64> = delta[..n].iter().map(|d| d.to_degrees()).collect();
        let heading: Vec<f64> = psi[..n].iter().map(|p| (p - psi[0]).to_degrees()).collect();
        let largest = rudder.iter().fold(0.0f64, |m, d| m.max(d.abs()));
        let amplitude = 5.0 * (largest / 5.0).round();
        if amplitude < 5.0 {
            return None;
        }
        let first = *heading.iter().find(|p| p.abs() > 0.5)?;
        let laid = rudder.iter().position(|d| d.abs() > amplitude - 1.5)?;
        let side = rudder[laid].signum();
        let back = rudder[laid..].iter().position(|d| d * side < amplitude - 1.5)?;
        let at = heading[laid + back].abs();
        let check = [1.0, 5.0, 10.0, 15.0, 20.0]
            .into_iter()
            .min_by(|a: &f64, b: &f64| (a - at).abs().total_cmp(&(b - at).abs()))
            .unwrap_or(at);
        // the median of what it held beyond A − 1.5° to a side: the hold, not the ramps to it
        let held = |sign: f64| {
            let mut side: Vec<f64> = rudder.iter().copied().filter(|d| d * sign > amplitude - 1.5).collect();
            side.sort_by(f64::total_cmp);
            side.get(side.len() / 2).copied()
        };
        let laid_deg = (held(1.0)?, held(-1.0)?);
        Some(ZigZagShape { amplitude, laid_deg, check, starboard_first: first > 0.0, rudder, heading, laid })
    }
}

/// The steering gear that zigzag records of time, heading ψ and rudder δ (rad) show; `None`
/// when they hold no reversal it can be read at. At each reversal: when the rudder leaves its
/// hold by 0.5° (ten times a good indicator's noise), its full rate between a quarter and three
/// quarters of its swing, and where that swing, drawn back at the full rate, leaves the hold.
/// A gear that builds its rate up at α reaches that line r/(2α) after it starts and has moved
/// 0.5° after 1/√α, which gives α; the dead time runs from the heading passing the check angle
/// to the start.
pub fn steering_gear(records: &[(&[f64], &[f64], &[f64])]) -> Option<SteeringGear> {
    let (mut delays, mut accelerations, mut rates) = (Vec::new(), Vec::new(), Vec::new());
    for &(t, psi, delta) in records {
        let Some(z) = ZigZagShape::of(psi, delta) else { continue };
        let n = z.rudder.len().min(t.len());
        // the time at which `v` passes `level` between samples j − 1 and j
        let when = |v: &dyn Fn(usize) -> f64, j: usize, level: f64| {
            let (a, b) = (v(j - 1), v(j));
            t[j - 1] + (t[j] - t[j - 1]) * ((level - a) / (b - a)).clamp(0.0, 1.0)
        };
        let mut i = z.laid;
        let mut side = z.rudder[i].signum();
        loop {
            let laid = |j: usize| z.rudder[j] * side;
            // the hold on this side and on the other, as angles towards this side
            let (hold, other) = if side > 0.0 { z.laid_deg } else { (-z.laid_deg.1, -z.laid_deg.0) };
            let swing = hold - other;
            let Some(held) = (i..n).find(|&j| laid(j) >= hold - 0.5) else { break };
            let Some(a) = (held..n).find(|&j| laid(j) < hold - 0.5) else { break };
            let (l1, l3) = (hold - 0.25 * swing, hold - 0.75 * swing);
            let Some(q1) = (a..n).find(|&j| laid(j) < l1) else { break };
            let Some(q3) = (q1..n).find(|&j| laid(j) < l3) else { break };
            let (t1, t3) = (when(&laid, q1, l1), when(&laid, q3, l3));
            let rate = 0.5 * swing / (t3 - t1);
            let moved = when(&laid, a, hold - 0.5);
            let line = t1 - (hold - l1) / rate;
            // r·s²/2 − s − (line − moved) = 0 for s = 1/√α
            let root = (1.0 + 2.0 * rate * (line - moved)).max(0.0).sqrt();
            let s = (1.0 + root) / rate;
            let start = moved - s;
            // the heading passed the check angle last before the rudder left its hold
            let sign = z.heading[a].signum();
            let beyond = |j: usize| sign * z.heading[j];
            if let Some(c) = (z.laid..a).rev().find(|&j| beyond(j) < z.check) {
                delays.push(start - when(&beyond, c + 1, z.check));
                accelerations.push(1.0 / (s * s));
                rates.push(rate);
            }
            side = -side;
            let Some(next) = (q3..n).find(|&j| z.rudder[j] * side > z.amplitude - 1.5) else { break };
            i = next;
        }
    }
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let reversals = delays.len();
    (reversals > 0).then(|| SteeringGear {
        delay_s: median(delays).max(0.0),
        acceleration_deg_s2: median(accelerations),
        rate_deg_s: median(rates),
        reversals,
    })
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
        // without its track the same record has no turning metrics (and reads without a fault)
        let seen = observe(f.time(), &psi, c("δ"), &[], &[]);
        assert!(seen.advance_m.is_none() && seen.tactical_diameter_m.is_none() && seen.transfer_m.is_none());
    }

    /// A zigzag recorded without its track (heading and rudder only) still has its overshoots,
    /// the same as with it.
    #[test]
    fn a_zigzag_without_its_track_has_its_overshoots() {
        let model = crate::ship::default_model();
        let rec = Basin::default()
            .record(&model, &Manoeuvre::parse("zigzag:20/20").unwrap(), 2.01, 60.0, 3, "zz.dat")
            .unwrap();
        let f = &rec.measured;
        let c = |n: &str| f.column(n).unwrap();
        let with = observe(f.time(), c("ψ"), c("δ"), c("x0"), c("y0"));
        let without = observe(f.time(), c("ψ"), c("δ"), &[], &[]);
        assert!(with.first_overshoot_deg.is_some() && with.second_overshoot_deg.is_some());
        assert_eq!(
            (with.first_overshoot_deg, with.second_overshoot_deg),
            (without.first_overshoot_deg, without.second_overshoot_deg)
        );
    }

    /// Zigzags recorded from the default ship with a gear of 0.25 s dead time, 20°/s² and
    /// 12.65°/s (the paper's rate) read back as that gear: the dead time within a control step
    /// (the controller sees the check at its next step), the rate and acceleration within 5 %.
    #[test]
    fn a_zigzag_record_shows_its_steering_gear() {
        let text = crate::ship::DEFAULT_MODEL.replace(
            "rudder_limit = 35.0",
            "rudder_limit = 35.0\nrudder_delay = 0.25\nrudder_acceleration = 20.0",
        );
        let model = crate::plugins::parse(&text, "geared.toml").unwrap();
        let basin = Basin::default();
        let records: Vec<_> = ["zigzag:20/20", "zigzag:10/10:port"]
            .iter()
            .enumerate()
            .map(|(k, m)| {
                basin.record(&model, &Manoeuvre::parse(m).unwrap(), 2.01, 80.0, k as u64, "z.dat").unwrap()
            })
            .collect();
        let columns: Vec<_> = records
            .iter()
            .map(|r| (r.measured.time(), r.measured.column("ψ").unwrap(), r.measured.column("δ").unwrap()))
            .collect();
        let gear = steering_gear(&columns).expect("reversals to read");
        assert!(gear.reversals >= 4, "{gear:?}");
        assert!(gear.delay_s >= 0.25 - 0.02 && gear.delay_s <= 0.25 + 0.05, "{gear:?}");
        assert!((gear.acceleration_deg_s2 / 20.0 - 1.0).abs() < 0.05, "{gear:?}");
        assert!((gear.rate_deg_s / 12.65 - 1.0).abs() < 0.05, "{gear:?}");
        let shape = ZigZagShape::of(columns[1].1, columns[1].2).unwrap();
        assert_eq!((shape.amplitude, shape.check, shape.starboard_first), (10.0, 10.0, false));
        // the basin's zigzags lay the rudder about the default ship's δ0 = −0.8°
        let (plus, minus) = shape.laid_deg;
        assert!((plus - 9.2).abs() < 0.05 && (minus + 10.8).abs() < 0.05, "{plus} {minus}");
    }
}
