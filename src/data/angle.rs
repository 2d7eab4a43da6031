//! Angles that wrap at a full turn — a gyrocompass's 359° → 0°, atan2's ±180° — made one
//! continuous angle, as a model integrates it (ψ̇ = r) and a re-simulation compares it.

use std::f64::consts::{PI, TAU};

use super::{DataError, Frame};

/// The first row at which `angle` (rad) moves by more than half a turn from the row before:
/// no angle a record can follow turns that far in one sample, so the record wraps there.
pub fn wrapped(angle: &[f64]) -> Option<usize> {
    (1..angle.len()).find(|&k| (angle[k] - angle[k - 1]).abs() > PI)
}

/// `angle` (rad) with every jump of more than half a turn taken back by whole turns, and the
/// whole by whole turns to start within half a turn of 0: a compass that reads 359.9° at the
/// start of a run on a northerly course starts it at −0.1°, as a run recorded from 0 does
/// (runs compared together are scaled by their pooled spread, which whole turns between them
/// would inflate).
pub fn unwrap_turns(angle: &mut [f64]) {
    unwrap_turns_of(angle, TAU);
}

/// [`unwrap_turns`] for an angle whose full turn is `turn` (2π in radians, 360 in degrees).
fn unwrap_turns_of(angle: &mut [f64], turn: f64) {
    let mut turns = 0.0;
    for k in 1..angle.len() {
        let jump = angle[k] + turns - angle[k - 1];
        if jump.abs() > 0.5 * turn {
            turns -= turn * (jump / turn).round();
        }
        angle[k] += turns;
    }
    let start = turn * (angle.first().copied().unwrap_or(0.0) / turn).round();
    for a in angle.iter_mut() {
        *a -= start;
    }
}

/// `frame`'s columns `values` names, each shifted by the whole turns (2π or 360) that lay its
/// value at row `at` onto the one given: a piece of a run read in pieces whose angles were
/// unwrapped on their own (each piece starting within half a turn of 0) laid onto the piece
/// before it, whose value at that row is given. A column off by anything but whole turns
/// there (another sample, a repair of its own) is left as it is.
pub fn laid_on_turns(frame: &mut Frame, at: usize, values: &[(String, f64)]) -> Result<(), DataError> {
    for (name, before) in values {
        let Some(column) = frame.column(name) else { continue };
        let Some(now) = column.get(at) else { continue };
        let shift = before - now;
        let whole = [TAU, 360.0].into_iter().any(|turn| {
            let n = (shift / turn).round();
            n != 0.0 && (shift - n * turn).abs() <= 1e-9 * shift.abs().max(1.0)
        });
        if whole {
            let shifted = column.iter().map(|v| v + shift).collect();
            frame.set(name, shifted)?;
        }
    }
    Ok(())
}

/// The full turn (2π or 360) of a record that reads like an angle on a dial, in radians or
/// degrees, its units not declared: it stays within one turn (2 % over, for noise), spans
/// three quarters of it or more, jumps by more than half of it at least once, and moves by
/// less than a quarter of it at every other step (a pendulum swinging over the top, read
/// by atan2 in ±π, a wind direction in 0-360°). A record that so jumps by any other span (a
/// counter that rolls over, a relaxation reset) is no angle: `None`.
///
/// Unwrapped, each wrap's step must also go on as a neighbour's does (the same way, at most
/// four times as far), or be under a twentieth of a turn (noise about the wrap): a
/// concentration that leaps from 0 to 256 at its first sample and then decays is no angle,
/// though it stays within 360 (unwrapped, it would first turn back by 104).
pub fn turn_of(x: &[f64]) -> Option<f64> {
    let (low, high) = x.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(*v), h.max(*v)));
    let steps: Vec<f64> = x.windows(2).map(|w| w[1] - w[0]).collect();
    [TAU, 360.0].into_iter().find(|&turn| {
        let span = high - low;
        let wrap = |s: f64| s.abs() > 0.5 * turn;
        let moves = steps.iter().all(|&s| wrap(s) || s.abs() < 0.25 * turn);
        let mut wraps = (0..steps.len()).filter(|&k| wrap(steps[k])).peekable();
        let some = wraps.peek().is_some();
        let like_neighbours = wraps.all(|k| {
            let unwrapped = steps[k] - turn.copysign(steps[k]);
            let beside = [k.checked_sub(1), Some(k + 1)]
                .into_iter()
                .flatten()
                .filter_map(|j| steps.get(j).copied().filter(|s| !wrap(*s)));
            unwrapped.abs() <= 0.05 * turn
                || beside.into_iter().any(|s| s * unwrapped > 0.0 && unwrapped.abs() <= 4.0 * s.abs())
        });
        span <= 1.02 * turn && span >= 0.75 * turn && some && moves && like_neighbours
    })
}

/// The run with its angle columns `angles` (rad) unwrapped where they wrap ([`wrapped`]), with
/// what to say of each; `None` where none wraps.
pub fn unwrapped(frame: &Frame, angles: &[&str]) -> Result<Option<(Frame, Vec<String>)>, DataError> {
    unwrapped_by(frame, angles, |name, column| {
        let row = wrapped(column)?;
        Some((
            TAU,
            format!(
                "{}: `{name}` jumps by a full turn (row {}: {:.1}° after {:.1}°), as a compass wraps at 360°: read as one continuous angle",
                frame.origin(),
                row + 1,
                column[row].to_degrees(),
                column[row - 1].to_degrees()
            ),
        ))
    })
}

/// The run with the columns `names` whose units are not known unwrapped where they read as
/// an angle on a dial ([`turn_of`]), with what to say of each; `None` where none does.
pub fn unwrapped_dials(frame: &Frame, names: &[&str]) -> Result<Option<(Frame, Vec<String>)>, DataError> {
    unwrapped_by(frame, names, |name, column| {
        let turn = turn_of(column)?;
        let wraps: Vec<usize> =
            (1..column.len()).filter(|&k| (column[k] - column[k - 1]).abs() > 0.5 * turn).collect();
        let row = *wraps.first()?;
        let (full, unit) = if turn == TAU { ("2π", "radians") } else { ("360", "degrees") };
        Some((
            turn,
            format!(
                "{}: `{name}` stays within {full} and jumps by about that at {} (row {}: {:.4} after {:.4}), as an angle read on a dial wraps at a full turn: read as one continuous angle, in {unit} (forces that turn with it are periodic in it, which no polynomial is: sin({name}) and cos({name}) among the candidates hold them)",
                frame.origin(),
                match wraps.len() {
                    1 => "one row".to_string(),
                    n => format!("{n} rows"),
                },
                row + 1,
                column[row],
                column[row - 1]
            ),
        ))
    })
}

/// The run with each column of `names` that `wraps` finds wrapping (its full turn and what
/// to say) unwrapped; `None` where none wraps.
fn unwrapped_by(
    frame: &Frame,
    names: &[&str],
    wraps: impl Fn(&str, &[f64]) -> Option<(f64, String)>,
) -> Result<Option<(Frame, Vec<String>)>, DataError> {
    let mut out: Option<Frame> = None;
    let mut notes = Vec::new();
    for name in names {
        let Some(column) = frame.column(name) else { continue };
        let Some((turn, note)) = wraps(name, column) else { continue };
        let mut angle = column.to_vec();
        unwrap_turns_of(&mut angle, turn);
        notes.push(note);
        out.get_or_insert_with(|| frame.clone()).set(name, angle)?;
    }
    Ok(out.map(|f| (f, notes)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_compass_heading_through_north_is_one_turning_angle() {
        // two full turns to starboard, read by a compass in [0°, 360°)
        let truth: Vec<f64> = (0..200).map(|k| (-10.0 + 4.0 * k as f64).to_radians()).collect();
        let mut compass: Vec<f64> = truth.iter().map(|a| a.rem_euclid(TAU)).collect();
        assert!(compass[0] > 6.0 && wrapped(&compass) == Some(3));
        unwrap_turns(&mut compass);
        assert!(compass.iter().zip(&truth).all(|(a, b)| (a - b).abs() < 1e-12));
        assert_eq!(wrapped(&compass), None);
        // atan2's ±180° to port
        let mut port: Vec<f64> = (0..100).map(|k| -(100.0 + 3.0 * k as f64).to_radians()).collect();
        let want = port.clone();
        for a in &mut port {
            *a = a.sin().atan2(a.cos());
        }
        unwrap_turns(&mut port);
        assert!(port.iter().zip(&want).all(|(a, b)| (a - b).abs() < 1e-12));
    }

    /// A pendulum over the top read by atan2 (±π) and a wind direction in 0-360° read as
    /// angles on a dial, and unwrapped back to their turning; a counter that rolls over at
    /// 100, a swing of ±1 rad that never wraps, a record that leaps by a turn but moves by
    /// more than a quarter of one elsewhere: not.
    /// A piece unwrapped on its own lies whole turns off the piece before: laid onto it at the
    /// shared row (in radians and in degrees); a column off by anything else is left alone.
    #[test]
    fn a_piece_is_laid_onto_the_one_before_by_whole_turns() {
        let mut f = Frame::new("p.csv", "t", vec![0.0, 1.0, 2.0]).unwrap();
        f.push("a", vec![0.1, 0.2, 0.3]).unwrap();
        f.push("d", vec![10.0, 20.0, 30.0]).unwrap();
        f.push("x", vec![1.0, 2.0, 3.0]).unwrap();
        let before = [("a".to_string(), 0.2 + 2.0 * TAU), ("d".to_string(), -700.0), ("x".to_string(), 2.5)];
        laid_on_turns(&mut f, 1, &before).unwrap();
        assert!((f.column("a").unwrap()[0] - (0.1 + 2.0 * TAU)).abs() < 1e-12);
        assert_eq!(f.column("d").unwrap(), [-710.0, -700.0, -690.0]);
        assert_eq!(f.column("x").unwrap(), [1.0, 2.0, 3.0]);
    }

    #[test]
    fn an_angle_on_a_dial_is_found_by_its_full_turns() {
        let truth: Vec<f64> = (0..3000).map(|k| 0.01 * k as f64 + 2.0 * (0.003 * k as f64).sin()).collect();
        let dial: Vec<f64> = truth.iter().map(|a| a.sin().atan2(a.cos())).collect();
        assert_eq!(turn_of(&dial), Some(TAU));
        let mut back = dial.clone();
        unwrap_turns_of(&mut back, TAU);
        assert!(back.iter().zip(&truth).all(|(a, b)| (a - b).abs() < 1e-9));
        let wind: Vec<f64> = truth.iter().map(|a| a.to_degrees().rem_euclid(360.0)).collect();
        assert_eq!(turn_of(&wind), Some(360.0));
        let counter: Vec<f64> = (0..3000).map(|k| f64::from(k % 100)).collect();
        assert_eq!(turn_of(&counter), None);
        let swing: Vec<f64> = (0..3000).map(|k| (0.01 * k as f64).sin()).collect();
        assert_eq!(turn_of(&swing), None);
        let mut leaps = dial;
        leaps[1500] = leaps[1499] + 2.0;
        assert_eq!(turn_of(&leaps), None);
        // a concentration dosed from 0, sampled hourly: it leaps by 71 % of 360 at its first
        // sample and stays within 360, but unwrapped that leap would run backwards
        let plasma = [0.0, 255.8, 297.2, 279.0, 247.1, 214.6, 185.5, 160.1, 137.7, 118.4, 101.8, 87.5, 75.6];
        assert_eq!(turn_of(&plasma), None);
    }

    #[test]
    fn a_frame_is_unwrapped_and_says_where() {
        let t: Vec<f64> = (0..10).map(f64::from).collect();
        let mut f = Frame::new("run.csv", "t", t).unwrap();
        f.push("ψ", (0..10).map(|k| (355.0 + 2.0 * f64::from(k)).to_radians().rem_euclid(TAU)).collect())
            .unwrap();
        f.push("δ", vec![0.1; 10]).unwrap();
        let (g, notes) = unwrapped(&f, &["ψ", "δ"]).unwrap().unwrap();
        assert!(g.names().len() == 3 && g.column("δ") == f.column("δ"));
        assert!((g.column("ψ").unwrap()[9].to_degrees() - 13.0).abs() < 1e-9);
        assert!(notes.len() == 1 && notes[0].contains("row 4: 1.0° after 359.0°"), "{notes:?}");
        assert!(unwrapped(&g, &["ψ"]).unwrap().is_none());
    }
}
