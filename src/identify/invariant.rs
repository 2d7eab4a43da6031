//! Linear combinations of the recorded variables that stay the same through the rows (a
//! conservation law, categories that add up to one, a variable recorded twice): they make
//! the candidates in one of those variables candidates in the others, said with the fit.

use crate::data::Frame;
use crate::output as report;
use crate::select::Moments;
use crate::term::Term;

/// The smallest eigenvalue of the candidate variables' correlation matrix below which a
/// combination of them is taken as constant in the rows (round-off of an exact invariant).
const INVARIANT: f64 = 1e-9;

/// A note where a linear combination of the candidates that are a variable alone is the same
/// in every row (a null vector of their covariance): a conservation law (a + b + c of a
/// closed reaction, S + I + R of an epidemic), indicator columns of categories that add up to
/// one, a variable recorded twice, or a fast state that follows the others at once (x of
/// dx/dt = −200 (x − y): x − y + ẏ/200 ≈ 0 at every row). Any candidate in one of them is then one in the others,
/// a back-end keeps one way of writing the equation and leaves the rest out as collinear, and
/// the system's own terms may be among those left out.
pub(super) fn exact_note(moments: &Moments, names: &[String]) -> Option<String> {
    let vars: Vec<usize> = (0..names.len()).filter(|&i| crate::term::is_identifier(&names[i])).collect();
    if vars.len() < 2 || vars.len() > 32 {
        return None;
    }
    let k = vars.len();
    let (d, eigen) = correlation(k, |i, j| moments.corrected(vars[i], vars[j]))?;
    let laws: Vec<String> = (0..k)
        .filter(|&e| eigen.eigenvalues[e] < INVARIANT)
        .filter_map(|e| {
            // in the variables' own scale: w_i / d_i
            let w: Vec<f64> = (0..k).map(|i| eigen.eigenvectors[(i, e)] / d[i]).collect();
            law(&w, &vars.iter().map(|&i| names[i].as_str()).collect::<Vec<_>>())
        })
        .collect();
    (!laws.is_empty()).then(|| {
        format!(
            "{} the same in every row (a conservation law, categories that add up to one, a \
             variable recorded twice, or a fast state that follows the others at once): a \
             candidate in one of these variables is one in the others, so the equation is \
             written in fewer of them and a term left out as collinear may be the system's, \
             written in the others",
            if laws.len() == 1 { format!("{} is", laws[0]) } else { format!("{} are each", laws.join(", ")) }
        )
    })
}

/// The spreads √Cᵢᵢ of `k` variables whose (co)variances `cov` gives and the eigen-
/// decomposition of their correlation matrix, whose near null vectors (`wᵢ / dᵢ` in the
/// variables' own scale) are the combinations that stay the same; `None` where a variable
/// does not vary.
fn correlation(
    k: usize,
    cov: impl Fn(usize, usize) -> f64,
) -> Option<(Vec<f64>, nalgebra::SymmetricEigen<f64, nalgebra::Dyn>)> {
    let d: Vec<f64> = (0..k).map(|i| cov(i, i).max(0.0).sqrt()).collect();
    if d.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
        return None;
    }
    let r = nalgebra::DMatrix::from_fn(k, k, |i, j| cov(i, j) / (d[i] * d[j]));
    Some((d, crate::linalg::symmetric_eigen(r)?))
}

/// A combination `Σ wᵢ·namesᵢ` as a reader writes it, the largest weight scaled to 1 and
/// weights of 1 left out (`S + I + R`, `x − 0.5·y`); `None` for a single variable.
fn law(w: &[f64], names: &[&str]) -> Option<String> {
    let top = w.iter().copied().fold(0.0f64, |a, v| if v.abs() > a.abs() { v } else { a });
    let mut text = String::new();
    for (i, v) in w.iter().map(|v| v / top).enumerate() {
        if v.abs() < 1e-6 {
            continue;
        }
        let sign = match (text.is_empty(), v < 0.0) {
            (true, false) => "",
            (true, true) => "−",
            (false, false) => " + ",
            (false, true) => " − ",
        };
        let weight = if (v.abs() - 1.0).abs() < 1e-3 {
            String::new()
        } else {
            format!("{}·", report::sig(v.abs(), 3))
        };
        text += &format!("{sign}{weight}{}", names[i]);
    }
    text.contains(' ').then(|| format!("`{text}`"))
}

/// The smallest eigenvalue of the recorded variables' correlation matrix up to which a
/// combination of them is looked at as one perhaps constant within the records' noise.
const NEARLY: f64 = 1e-2;

/// The variance of such a combination over its white noise's ([`crate::data::white_noise`])
/// below which it is taken as constant but for the noise: noise alone gives 1, a motion of
/// the combination adds to it.
const WITHIN: f64 = 2.0;

/// The note of [`exact_note`] where a combination of the candidate variables is the same in
/// every row but for the records' noise (an epidemic's S + I + R recorded with 1 % noise on
/// each): their correlation matrix's near null vectors, computed on the samples of `frames`,
/// whose combination spreads no more than its white noise. The rows then tell a candidate in
/// one of them from one in the others only by the noise, and the back-end may write the
/// equation in any of them: dI/dt = 0.5·I·S − 0.1·I came back as 0.3995·I − 0.4999·I·R −
/// 0.4982·I², the same law with S = 1 − I − R. Said with the candidates whose leaving out
/// writes it as the noise-free rows would (those in the variable the pivoting drops: the
/// one whose candidate comes last).
pub(super) fn within_noise_note(frames: &[Frame], candidates: &[Term], names: &[String]) -> Option<String> {
    let vars: Vec<usize> = (0..names.len())
        .filter(|&i| crate::term::is_identifier(&names[i]))
        .filter(|&i| frames.iter().all(|f| f.column(&names[i]).is_some()))
        .collect();
    let k = vars.len();
    if !(2..=32).contains(&k) {
        return None;
    }
    fn columns<'f>(f: &'f Frame, vars: &[usize], names: &[String]) -> Vec<&'f [f64]> {
        vars.iter().filter_map(|&i| f.column(&names[i])).collect()
    }
    let rows: usize = frames.iter().map(Frame::len).sum();
    let mut mean = vec![0.0; k];
    for f in frames {
        for (m, c) in mean.iter_mut().zip(columns(f, &vars, names)) {
            *m += c.iter().sum::<f64>() / rows as f64;
        }
    }
    let mut cov = nalgebra::DMatrix::<f64>::zeros(k, k);
    for f in frames {
        let c = columns(f, &vars, names);
        for i in 0..k {
            for j in 0..=i {
                let s: f64 = c[i].iter().zip(c[j]).map(|(a, b)| (a - mean[i]) * (b - mean[j])).sum();
                cov[(i, j)] += s;
                cov[(j, i)] = cov[(i, j)];
            }
        }
    }
    let (d, eigen) = correlation(k, |i, j| cov[(i, j)])?;
    let mut laws: Vec<String> = Vec::new();
    let mut left: Vec<String> = Vec::new();
    for e in (0..k).filter(|&e| (INVARIANT..NEARLY).contains(&eigen.eigenvalues[e])) {
        let w: Vec<f64> = (0..k).map(|i| eigen.eigenvectors[(i, e)] / d[i]).collect();
        let combined = |f: &Frame| -> Vec<f64> {
            let c = columns(f, &vars, names);
            (0..f.len()).map(|r| (0..k).map(|i| w[i] * c[i][r]).sum()).collect()
        };
        // its spread about its mean over all runs against its white noise, pooled by rows
        let (mut spread, mut noise, mut counted) = (0.0, 0.0, 0usize);
        let centre: f64 = (0..k).map(|i| w[i] * mean[i]).sum();
        for f in frames {
            let c = combined(f);
            let n = crate::data::white_noise(&c).filter(|n| n.measured && n.sd > 0.0)?;
            spread += c.iter().map(|v| (v - centre) * (v - centre)).sum::<f64>();
            noise += n.sd * n.sd * c.len() as f64;
            counted += c.len();
        }
        if counted == 0 || spread > WITHIN * noise {
            continue;
        }
        let Some(text) = law(&w, &vars.iter().map(|&i| names[i].as_str()).collect::<Vec<_>>()) else {
            continue;
        };
        // the variable of the law whose candidate comes last: the one pivoting leaves out
        let scale = w.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        if let Some(&last) =
            vars.iter().zip(&w).filter(|(_, v)| v.abs() >= 1e-6 * scale).map(|(i, _)| i).next_back()
        {
            left.push(names[last].clone());
        }
        laws.push(text);
    }
    if laws.is_empty() {
        return None;
    }
    let holding: Vec<String> = candidates
        .iter()
        .filter(|t| t.variables().iter().any(|v| left.contains(v)))
        .map(|t| format!("`{t}`"))
        .collect();
    let listed = match holding.len() {
        0..=12 => holding.join(", "),
        n => format!("{}, … ({n})", holding[..8].join(", ")),
    };
    Some(format!(
        "{} the same in every row but for the records' noise (spread no more than its white noise): \
         a candidate in one of these variables is one in the others, told apart by the noise alone, \
         so the equation may be written in any of them (the system's own terms read as others); \
         the candidates in {} left out ({listed}) write it in the rest, as noise-free rows would",
        if laws.len() == 1 { format!("{} is", laws[0]) } else { format!("{} are each", laws.join(", ")) },
        left.iter().map(|v| format!("`{v}`")).collect::<Vec<_>>().join(", ")
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// S, I and R adding up to 1 but for noise of about a thousandth on each: named, with the
    /// candidates in R (the last); R moving on its own: nothing said; exactly 1 (noise-free):
    /// left to [`exact_note`], which the fit's statistics say.
    #[test]
    fn a_law_blurred_by_noise_is_told_from_a_motion() {
        let mut seed = 7u64;
        let mut noise = move || {
            // a sum of uniforms: about normal, sd 1e-3
            (0..12)
                .map(|_| {
                    seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                    (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
                })
                .sum::<f64>()
                * 1e-3
        };
        let n = 2000;
        let t: Vec<f64> = (0..n).map(|k| 0.01 * k as f64).collect();
        let s: Vec<f64> = t.iter().map(|t| 0.5 + 0.3 * t.sin()).collect();
        let i: Vec<f64> = t.iter().map(|t| 0.2 + 0.1 * (1.3 * t).cos()).collect();
        let run = |r: Vec<f64>, noise: &mut dyn FnMut() -> f64| {
            let mut f = Frame::new("sir.csv", "t", t.clone()).unwrap();
            f.push("S", s.iter().map(|v| v + noise()).collect()).unwrap();
            f.push("I", i.iter().map(|v| v + noise()).collect()).unwrap();
            f.push("R", r.iter().map(|v| v + noise()).collect()).unwrap();
            f
        };
        let mut vocab = crate::term::Vocabulary::new();
        for v in ["S", "I", "R"] {
            vocab.variable(v).unwrap();
        }
        let texts = ["1", "S", "I", "R", "I*S", "I*R"];
        let candidates: Vec<Term> = texts.iter().map(|t| vocab.parse(t).unwrap()).collect();
        let names: Vec<String> = candidates.iter().map(Term::to_string).collect();
        let conserved: Vec<f64> = s.iter().zip(&i).map(|(s, i)| 1.0 - s - i).collect();
        let said = within_noise_note(&[run(conserved.clone(), &mut noise)], &candidates, &names).unwrap();
        assert!(
            said.starts_with("`S + I + R` is the same in every row but for the records' noise"),
            "{said}"
        );
        assert!(said.contains("the candidates in `R` left out (`R`, `I*R`)"), "{said}");
        let moving: Vec<f64> = conserved.iter().zip(&t).map(|(r, t)| r + 0.05 * (0.7 * t).sin()).collect();
        assert_eq!(within_noise_note(&[run(moving, &mut noise)], &candidates, &names), None);
        assert_eq!(within_noise_note(&[run(conserved, &mut || 0.0)], &candidates, &names), None);
    }
}
