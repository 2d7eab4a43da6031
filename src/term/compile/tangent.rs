//! Forward-mode derivatives of the compiled row program: every slot carries, beside its value,
//! its derivatives with respect to a chosen set of inputs (states, parameters), chained
//! through the same levelised groups. One pass gives a right-hand side's Jacobian exactly,
//! where finite differences take one evaluation per input and a step's truncation error.
//! A slot depends on few of the inputs (a hull force on v, r and its own coefficient), so
//! each slot computes only the derivatives that can be nonzero, found once from the program.

use super::levels::Group;
use super::{Library, Op, RowScratch};
use crate::term::functions::{FUNCTIONS, MAX_ARITY};

/// The derivatives of every slot with respect to the directions chosen by
/// [`Library::tangents`]: slot-major, `directions` values per slot, of which each slot
/// computes only those in its pattern (the others are zero and stay so).
#[derive(Clone, Debug)]
pub struct Tangents {
    directions: usize,
    t: Vec<f64>,
    /// Slot i's directions that can be nonzero: `lanes[span[i].0..span[i].1]`, ascending.
    span: Vec<(u32, u32)>,
    lanes: Vec<u32>,
}

impl Tangents {
    /// Number of directions.
    pub fn directions(&self) -> usize {
        self.directions
    }
}

impl Library {
    /// Tangent space for the derivatives with respect to the inputs in scratch slots `slots`
    /// (as [`Library::input_slot`] gives them), one direction each in that order; `None` is a
    /// direction the program does not read (its derivatives stay zero).
    pub fn tangents(&self, slots: &[Option<usize>]) -> Tangents {
        let d = slots.len();
        let mut t = vec![0.0; self.ops.len() * d];
        let mut pattern: Vec<Vec<u32>> = vec![Vec::new(); self.ops.len()];
        // an input's derivative with respect to itself is 1 and never changes
        for (k, slot) in slots.iter().enumerate() {
            if let Some(i) = slot {
                assert!(*i < self.ops.len(), "slot {i} is not in this library (input_slot gives them)");
                t[i * d + k] = 1.0;
                pattern[*i].push(k as u32);
            }
        }
        // operands come before their operation (the builder pushes them first)
        for (i, op) in self.ops.iter().enumerate() {
            let operands: Vec<usize> = match op {
                Op::Input(_) | Op::Const(_) => continue,
                Op::Mul(a, b) => vec![*a, *b],
                Op::Recip(a) => vec![*a],
                Op::Call(_, args) => args.clone(),
                Op::Lin(parts) => parts.iter().map(|(_, a)| *a).collect(),
            };
            let mut union: Vec<u32> = operands.iter().flat_map(|a| pattern[*a].iter().copied()).collect();
            union.sort_unstable();
            union.dedup();
            pattern[i] = union;
        }
        let (mut span, mut lanes) = (Vec::with_capacity(self.ops.len()), Vec::new());
        for p in &pattern {
            let start = lanes.len() as u32;
            lanes.extend_from_slice(p);
            span.push((start, lanes.len() as u32));
        }
        Tangents { directions: d, t, span, lanes }
    }

    /// Evaluates every term on the inputs in `scratch` (as [`Library::eval_row_prepared`], the
    /// same values) and their derivatives: `partials` row-major, one row of
    /// `tangents.directions()` per term.
    pub fn eval_row_tangents(
        &self,
        scratch: &mut RowScratch,
        tangents: &mut Tangents,
        out: &mut [f64],
        partials: &mut [f64],
    ) {
        self.eval_row_prepared(scratch, out);
        let s = scratch.0.as_slice();
        let d = tangents.directions;
        // With these checks every index below is valid: the program's slot indices are all
        // < ops.len() by construction (Builder), as eval_row_prepared relies on too, and every
        // pattern's lanes are < d (Library::tangents).
        assert!(tangents.t.len() == self.ops.len() * d, "tangents of another library");
        assert!(tangents.span.len() == self.ops.len() && s.len() == self.ops.len());
        let Tangents { t, span, lanes, .. } = tangents;
        let (span, lanes) = (&*span, &*lanes);
        // SAFETY: see the assertions above; an operation's slot is never one of its operands.
        unsafe {
            let pattern = |i: usize| {
                let (a, b) = *span.get_unchecked(i);
                lanes.get_unchecked(a as usize..b as usize)
            };
            let v = |i: usize| *s.get_unchecked(i);
            let t = t.as_mut_ptr();
            // slot i's derivative with respect to direction k
            let at = |i: usize, k: u32| t.add(i * d + k as usize);
            for g in &self.rows.groups {
                match g {
                    Group::Mul(ops) => {
                        for &(i, a, b) in ops {
                            let (i, a, b) = (i as usize, a as usize, b as usize);
                            let (sa, sb) = (v(a), v(b));
                            for &k in pattern(i) {
                                *at(i, k) = sa * *at(b, k) + sb * *at(a, k);
                            }
                        }
                    }
                    Group::Recip(ops) => {
                        for &(i, a) in ops {
                            let (i, a) = (i as usize, a as usize);
                            let f = -v(i) * v(i);
                            for &k in pattern(i) {
                                *at(i, k) = f * *at(a, k);
                            }
                        }
                    }
                    Group::Call(ops) => {
                        let (mut values, mut grad) = ([0.0; MAX_ARITY], [0.0; MAX_ARITY]);
                        for (i, f, args) in ops {
                            let i = *i;
                            if pattern(i).is_empty() {
                                continue;
                            }
                            // a built-in function's arity, checked when the term was parsed
                            let (values, grad) = (&mut values[..args.len()], &mut grad[..args.len()]);
                            for (x, &a) in values.iter_mut().zip(args) {
                                *x = v(a);
                            }
                            (FUNCTIONS[*f].grad)(values, v(i), grad);
                            for &k in pattern(i) {
                                *at(i, k) = 0.0;
                            }
                            // an argument that does not move moves nothing, even where the
                            // function's slope is infinite (sqrt(v²) at v = 0: ∞·0 would be NaN)
                            for (&a, &w) in args.iter().zip(grad.iter()) {
                                for &k in pattern(a) {
                                    let ta = *at(a, k);
                                    if ta != 0.0 {
                                        *at(i, k) += w * ta;
                                    }
                                }
                            }
                        }
                    }
                    Group::SinCos(ops) => {
                        for &(i_sin, i_cos, a) in ops {
                            let (i_sin, i_cos, a) = (i_sin as usize, i_cos as usize, a as usize);
                            let (sin, cos) = (v(i_sin), v(i_cos));
                            for &k in pattern(a) {
                                let ta = *at(a, k);
                                *at(i_sin, k) = cos * ta;
                                *at(i_cos, k) = -sin * ta;
                            }
                        }
                    }
                    Group::Lin(ops) => {
                        for &(i, start, len) in ops {
                            let i = i as usize;
                            if pattern(i).is_empty() {
                                continue;
                            }
                            for &k in pattern(i) {
                                *at(i, k) = 0.0;
                            }
                            for &(c, a) in self.rows.lin.get_unchecked(start as usize..(start + len) as usize)
                            {
                                let a = a as usize;
                                for &k in pattern(a) {
                                    *at(i, k) += c * *at(a, k);
                                }
                            }
                        }
                    }
                }
            }
        }
        let t = &tangents.t;
        if d > 0 {
            for (row, &slot) in partials.chunks_exact_mut(d).zip(&self.outputs) {
                row.copy_from_slice(&t[slot * d..(slot + 1) * d]);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::term::{Library, Term, Vocabulary};

    /// Where a function's slope is infinite but its argument does not move, the derivative is
    /// zero, not NaN: sqrt(v² + w²) at v = w = 0 (and atan2's 0/0 slope at the origin).
    #[test]
    fn a_still_argument_of_an_infinitely_steep_function_gives_zero() {
        let v = Vocabulary::open();
        let terms: Vec<Term> =
            ["sqrt(v^2 + w^2)", "atan2(v^2, w^2)"].iter().map(|t| v.parse(t).unwrap()).collect();
        let lib = Library::compile(&terms, &v).unwrap();
        let slots: Vec<Option<usize>> = (0..lib.inputs().len()).map(|j| lib.input_slot(j)).collect();
        let mut tangents = lib.tangents(&slots);
        let mut scratch = lib.scratch();
        for &slot in slots.iter().flatten() {
            lib.set_input(&mut scratch, slot, 0.0);
        }
        let (mut out, mut partials) = (vec![0.0; 2], vec![f64::NAN; 2 * slots.len()]);
        lib.eval_row_tangents(&mut scratch, &mut tangents, &mut out, &mut partials);
        assert_eq!(out, [0.0, 0.0]);
        assert!(partials.iter().all(|p| *p == 0.0), "{partials:?}");
    }

    /// The forward-mode partials equal central differences of the values, on terms that use
    /// every kind of operation: products and powers, a reciprocal, functions of one and two
    /// arguments, sine and cosine of one argument, sums.
    #[test]
    fn partials_equal_central_differences() {
        let v = Vocabulary::open();
        let texts =
            ["u*v^2/w", "sin(p*u)*v", "cos(p*u)", "atan2(v, u)*abs(w)", "sqrt(u)*exp(p)", "tanh(v*w)", "3"];
        let terms: Vec<Term> = texts.iter().map(|t| v.parse(t).unwrap()).collect();
        let lib = Library::compile(&terms, &v).unwrap();
        let names = lib.inputs().to_vec();
        let at = [("u", 1.3), ("v", -0.7), ("w", 0.4), ("p", 0.9)];
        let value = |name: &str, shift: (&str, f64)| {
            at.iter().find(|(n, _)| *n == name).unwrap().1 + if name == shift.0 { shift.1 } else { 0.0 }
        };
        let eval = |shift: (&str, f64)| {
            let inputs: Vec<f64> = names.iter().map(|n| value(n, shift)).collect();
            let mut out = vec![0.0; terms.len()];
            lib.eval_row(&inputs, &mut lib.scratch(), &mut out);
            out
        };
        // derivatives with respect to v, p and w (u left out: a direction set need not be all)
        let directions = ["v", "p", "w"];
        let slots: Vec<Option<usize>> = directions
            .iter()
            .map(|d| names.iter().position(|n| n == d).and_then(|j| lib.input_slot(j)))
            .collect();
        let mut tangents = lib.tangents(&slots);
        let mut scratch = lib.scratch();
        for (j, n) in names.iter().enumerate() {
            lib.set_input(&mut scratch, lib.input_slot(j).unwrap(), value(n, ("", 0.0)));
        }
        let (mut out, mut partials) = (vec![0.0; terms.len()], vec![0.0; terms.len() * directions.len()]);
        lib.eval_row_tangents(&mut scratch, &mut tangents, &mut out, &mut partials);
        assert_eq!(out, eval(("", 0.0)));
        for (k, d) in directions.iter().enumerate() {
            let h = 1e-6;
            let (up, down) = (eval((d, h)), eval((d, -h)));
            for (i, text) in texts.iter().enumerate() {
                let fd = (up[i] - down[i]) / (2.0 * h);
                let got = partials[i * directions.len() + k];
                assert!((got - fd).abs() < 1e-7 * fd.abs().max(1.0), "∂({text})/∂{d}: {got} vs {fd}");
            }
        }
    }
}
