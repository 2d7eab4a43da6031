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
    let mut turns = 0.0;
    for k in 1..angle.len() {
        let jump = angle[k] + turns - angle[k - 1];
        if jump.abs() > PI {
            turns -= TAU * (jump / TAU).round();
        }
        angle[k] += turns;
    }
    let start = TAU * (angle.first().copied().unwrap_or(0.0) / TAU).round();
    for a in angle.iter_mut() {
        *a -= start;
    }
}

/// The run with its angle columns `angles` (rad) unwrapped where they wrap ([`wrapped`]), with
/// what to say of each; `None` where none wraps.
pub fn unwrapped(frame: &Frame, angles: &[&str]) -> Result<Option<(Frame, Vec<String>)>, DataError> {
    let mut out: Option<Frame> = None;
    let mut notes = Vec::new();
    for name in angles {
        let Some(column) = frame.column(name) else { continue };
        let Some(row) = wrapped(column) else { continue };
        let mut angle = column.to_vec();
        unwrap_turns(&mut angle);
        notes.push(format!(
            "{}: `{name}` jumps by a full turn (row {}: {:.1}° after {:.1}°), as a compass wraps at 360°: read as one continuous angle",
            frame.origin(),
            row + 1,
            column[row].to_degrees(),
            column[row - 1].to_degrees()
        ));
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
