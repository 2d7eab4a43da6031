//! A set of terms compiled into one straight-line program. Every sub-expression is
//! computed once (hash-consing): powers and `1/u` are shared between terms, and products
//! share their sorted prefixes (`r*u` is on the way to `r*u*δ^2`). The same program fills
//! a design matrix block by block (cache-sized blocks, no per-row allocation) and evaluates
//! one row for the simulator.

use rustc_hash::FxHashMap as HashMap;

mod levels;
mod tangent;

pub use tangent::Tangents;

use levels::{Group, RowProgram};

use super::canon::{Atom, Monomial, Term};
use super::error::TermError;
use super::functions::function;
use super::vocabulary::Vocabulary;

/// Rows per block when filling columns: the working set (slots × block) stays in L1/L2.
pub const BLOCK: usize = 256;

#[derive(Clone, Debug, PartialEq)]
pub(super) enum Op {
    Input(usize),
    Const(f64),
    Mul(usize, usize),
    Recip(usize),
    Call(usize, Vec<usize>),
    /// Σ coef·slot.
    Lin(Vec<(f64, usize)>),
}

#[derive(Clone, Debug, PartialEq, Eq, Hash)]
enum Key {
    Input(usize),
    Const(u64),
    Mul(usize, usize),
    Recip(usize),
    Call(usize, Vec<usize>),
    Lin(Vec<(u64, usize)>),
}

/// Where an input's values come from when filling columns.
#[derive(Clone, Copy, Debug)]
pub enum Source<'a> {
    /// One value per row.
    Column(&'a [f64]),
    /// The same value on every row (a parameter).
    Constant(f64),
}

/// Scratch space for [`Library::eval_row`]; make one per thread with [`Library::scratch`].
#[derive(Clone, Debug)]
pub struct RowScratch(Vec<f64>);

/// Compiled terms.
#[derive(Clone, Debug)]
pub struct Library {
    inputs: Vec<String>,
    ops: Vec<Op>,
    outputs: Vec<usize>,
    rows: RowProgram,
}

struct Builder<'v> {
    vocab: &'v Vocabulary,
    inputs: Vec<String>,
    ops: Vec<Op>,
    cache: HashMap<Key, usize>,
    derived: HashMap<String, usize>,
    pending: Vec<String>,
}

impl Builder<'_> {
    fn push(&mut self, op: Op) -> usize {
        let key = match &op {
            Op::Input(i) => Key::Input(*i),
            Op::Const(c) => Key::Const(c.to_bits()),
            Op::Mul(a, b) => Key::Mul(*a.min(b), *a.max(b)),
            Op::Recip(a) => Key::Recip(*a),
            Op::Call(f, a) => Key::Call(*f, a.clone()),
            Op::Lin(v) => Key::Lin(v.iter().map(|(c, s)| (c.to_bits(), *s)).collect()),
        };
        if let Some(&slot) = self.cache.get(&key) {
            return slot;
        }
        self.ops.push(op);
        let slot = self.ops.len() - 1;
        self.cache.insert(key, slot);
        slot
    }

    fn term(&mut self, t: &Term) -> Result<usize, TermError> {
        match t.monomials() {
            [] => Ok(self.push(Op::Const(0.0))),
            [m] => self.monomial(m),
            ms => {
                let parts = ms
                    .iter()
                    .map(|m| Ok((m.coef, self.product(&m.factors)?)))
                    .collect::<Result<Vec<_>, TermError>>()?;
                Ok(self.push(Op::Lin(parts)))
            }
        }
    }

    fn monomial(&mut self, m: &Monomial) -> Result<usize, TermError> {
        if m.factors.is_empty() {
            return Ok(self.push(Op::Const(m.coef)));
        }
        let p = self.product(&m.factors)?;
        Ok(if m.coef == 1.0 { p } else { self.push(Op::Lin(vec![(m.coef, p)])) })
    }

    fn product(&mut self, factors: &[(Atom, i32)]) -> Result<usize, TermError> {
        let mut acc: Option<usize> = None;
        for (atom, k) in factors {
            let base = self.atom(atom)?;
            let f = self.power(base, *k);
            acc = Some(match acc {
                None => f,
                Some(a) => self.push(Op::Mul(a, f)),
            });
        }
        Ok(acc.unwrap_or_else(|| self.push(Op::Const(1.0))))
    }

    /// The same recipe as `canon::ipow`: 1/u^k for negative powers (u^-1 is one reciprocal,
    /// shared by every term that divides by u).
    fn power(&mut self, base: usize, k: i32) -> usize {
        if k < 0 {
            let p = self.power(base, k.checked_neg().unwrap_or(i32::MAX));
            return self.push(Op::Recip(p));
        }
        match k {
            0 => self.push(Op::Const(1.0)),
            1 => base,
            _ if k % 2 == 0 => {
                let h = self.power(base, k / 2);
                self.push(Op::Mul(h, h))
            }
            _ => {
                let p = self.power(base, k - 1);
                self.push(Op::Mul(p, base))
            }
        }
    }

    fn atom(&mut self, a: &Atom) -> Result<usize, TermError> {
        match a {
            Atom::Var(name) => {
                if let Some(&s) = self.derived.get(name) {
                    return Ok(s);
                }
                if let Some(def) = self.vocab.derived_definition(name) {
                    if self.pending.contains(name) {
                        return Err(TermError::Declaration(format!("`{name}` is defined through itself")));
                    }
                    self.pending.push(name.clone());
                    let s = self.term(&def.clone())?;
                    self.pending.pop();
                    self.derived.insert(name.clone(), s);
                    return Ok(s);
                }
                let i = match self.inputs.iter().position(|n| n == name) {
                    Some(i) => i,
                    None => {
                        self.inputs.push(name.clone());
                        self.inputs.len() - 1
                    }
                };
                Ok(self.push(Op::Input(i)))
            }
            Atom::Group(t) => self.term(t),
            Atom::Call(name, args) => {
                let (f, _) = function(name)
                    .ok_or_else(|| TermError::Undeclared { term: a.to_string(), name: name.clone() })?;
                let args = args.iter().map(|t| self.term(t)).collect::<Result<Vec<_>, _>>()?;
                Ok(self.push(Op::Call(f, args)))
            }
        }
    }
}

impl Library {
    /// Compiles terms; derived variables are expanded through `vocab`.
    pub fn compile(terms: &[Term], vocab: &Vocabulary) -> Result<Library, TermError> {
        let mut b = Builder {
            vocab,
            inputs: Vec::new(),
            ops: Vec::new(),
            cache: HashMap::default(),
            derived: HashMap::default(),
            pending: Vec::new(),
        };
        let outputs = terms.iter().map(|t| b.term(t)).collect::<Result<Vec<_>, _>>()?;
        if b.ops.len() > u32::MAX as usize {
            return Err(TermError::Declaration("the terms compile to more than 2³² operations".into()));
        }
        let rows = RowProgram::new(&b.ops);
        // the terms themselves are not kept: their caller has them, in the columns' order
        Ok(Library { inputs: b.inputs, ops: b.ops, outputs, rows })
    }

    /// Names of the base variables and parameters the program reads, in input order.
    pub fn inputs(&self) -> &[String] {
        &self.inputs
    }

    /// Number of terms (columns).
    pub fn len(&self) -> usize {
        self.outputs.len()
    }

    /// True if there are no terms.
    pub fn is_empty(&self) -> bool {
        self.outputs.is_empty()
    }

    /// Number of operations in the program (after sharing).
    pub fn op_count(&self) -> usize {
        self.ops.len()
    }

    /// The program, one operation per line (for inspection and tuning).
    pub fn describe(&self) -> String {
        self.ops.iter().enumerate().map(|(i, op)| format!("{i:>4}: {op:?}\n")).collect()
    }

    /// Scratch space for row evaluation (constants already in place).
    pub fn scratch(&self) -> RowScratch {
        let mut s = vec![0.0; self.ops.len()];
        for &(i, c) in &self.rows.constants {
            s[i] = c;
        }
        RowScratch(s)
    }

    /// Evaluates every term on one row; `inputs` is aligned with [`Library::inputs`].
    #[inline]
    pub fn eval_row(&self, inputs: &[f64], scratch: &mut RowScratch, out: &mut [f64]) {
        assert!(inputs.len() >= self.inputs.len(), "too few inputs");
        self.eval_row_with(|j| inputs[j], scratch, out)
    }

    /// Like [`Library::eval_row`], input `j` fetched by `fetch(j)` (no intermediate buffer:
    /// the simulator reads states and inputs where they are).
    #[inline]
    pub fn eval_row_with(&self, fetch: impl Fn(usize) -> f64, scratch: &mut RowScratch, out: &mut [f64]) {
        for &(i, j) in &self.rows.inputs {
            scratch.0[i as usize] = fetch(j as usize);
        }
        self.eval_row_prepared(scratch, out);
    }

    /// The scratch slot that holds input `j` (for callers that keep some inputs, e.g. the
    /// parameters of a simulation, in place between rows).
    pub fn input_slot(&self, j: usize) -> Option<usize> {
        self.rows.inputs.iter().find(|(_, k)| *k as usize == j).map(|(i, _)| *i as usize)
    }

    /// Sets input `j`'s value in a scratch (see [`Library::input_slot`]).
    #[inline]
    pub fn set_input(&self, scratch: &mut RowScratch, slot: usize, value: f64) {
        scratch.0[slot] = value;
    }

    /// Evaluates every term on the inputs already in `scratch` (set by
    /// [`Library::set_input`]).
    #[inline]
    pub fn eval_row_prepared(&self, scratch: &mut RowScratch, out: &mut [f64]) {
        let s = scratch.0.as_mut_slice();
        // This check makes every slot index below valid: the program's slot indices are all
        // < ops.len() by construction (Builder).
        assert!(s.len() == self.ops.len(), "scratch of another library");
        let p = &self.rows;
        let u = |i: u32| i as usize;
        // SAFETY: see the assert above.
        unsafe {
            for g in &p.groups {
                match g {
                    Group::Mul(v) => {
                        for &(i, a, b) in v {
                            *s.get_unchecked_mut(u(i)) = *s.get_unchecked(u(a)) * *s.get_unchecked(u(b));
                        }
                    }
                    Group::Recip(v) => {
                        for &(i, a) in v {
                            *s.get_unchecked_mut(u(i)) = 1.0 / *s.get_unchecked(u(a));
                        }
                    }
                    Group::Call(v) => {
                        for (i, f, args) in v {
                            *s.get_unchecked_mut(*i) = call_scalar(*f, args, s);
                        }
                    }
                    Group::SinCos(v) => {
                        for &(i_sin, i_cos, a) in v {
                            let (sin, cos) = libm::sincos(*s.get_unchecked(u(a)));
                            *s.get_unchecked_mut(u(i_sin)) = sin;
                            *s.get_unchecked_mut(u(i_cos)) = cos;
                        }
                    }
                    Group::Lin(v) => {
                        for &(i, start, len) in v {
                            let parts = p.lin.get_unchecked(u(start)..u(start) + u(len));
                            *s.get_unchecked_mut(u(i)) = lin_sum_unchecked(parts, s);
                        }
                    }
                }
            }
        }
        for (o, &slot) in out.iter_mut().zip(&self.outputs) {
            *o = s[slot];
        }
    }

    /// Binds every input to a source by name (columns by `column`, else parameters).
    pub fn bind<'a>(
        &self,
        column: &dyn Fn(&str) -> Option<&'a [f64]>,
        parameter: &dyn Fn(&str) -> Option<f64>,
    ) -> Result<Vec<Source<'a>>, TermError> {
        self.inputs
            .iter()
            .map(|name| {
                column(name)
                    .map(Source::Column)
                    .or_else(|| parameter(name).map(Source::Constant))
                    .ok_or_else(|| TermError::Unbound(name.clone()))
            })
            .collect()
    }

    /// Evaluates the terms on `rows` block by block; `visit(first_row, block)` gets each
    /// block's columns, one slice per term, all of the block's length.
    pub fn for_each_block(
        &self,
        sources: &[Source<'_>],
        rows: std::ops::Range<usize>,
        mut visit: impl FnMut(usize, &[&[f64]]),
    ) {
        // every slot row is written before it is read, so a reused buffer needs no clearing
        let mut slots = BLOCK_SPARE.with(|s| std::mem::take(&mut *s.borrow_mut()));
        if slots.len() < self.ops.len() * BLOCK {
            slots.resize(self.ops.len() * BLOCK, 0.0);
        }
        let mut start = rows.start;
        while start < rows.end {
            let len = BLOCK.min(rows.end - start);
            self.eval_block(sources, start, len, &mut slots);
            let columns: Vec<&[f64]> =
                self.outputs.iter().map(|&slot| self.operand(sources, &slots, slot, start, len)).collect();
            visit(start, &columns);
            start += len;
        }
        BLOCK_SPARE.with(|s| *s.borrow_mut() = slots);
    }

    /// Fills a column-major `n × len()` design matrix.
    pub fn fill(&self, sources: &[Source<'_>], n: usize, out: &mut [f64]) {
        assert_eq!(out.len(), n * self.len(), "design buffer must hold n × terms values");
        self.for_each_block(sources, 0..n, |start, columns| {
            for (j, column) in columns.iter().enumerate() {
                out[j * n + start..j * n + start + column.len()].copy_from_slice(column);
            }
        });
    }

    /// The values of `slot` on rows `start..start + len` of the block: an input column is read
    /// where it is (copying it into its slot cost ~6 µs of a 2 505-row fit on a finished
    /// 29-column matrix, where every term is an input), any other slot from the block's buffer.
    #[inline(always)]
    fn operand<'a>(
        &self,
        sources: &[Source<'a>],
        done: &'a [f64],
        slot: usize,
        start: usize,
        len: usize,
    ) -> &'a [f64] {
        match self.ops[slot] {
            Op::Input(j) => match sources[j] {
                Source::Column(c) => &c[start..start + len],
                Source::Constant(_) => &done[slot * BLOCK..slot * BLOCK + len],
            },
            _ => &done[slot * BLOCK..slot * BLOCK + len],
        }
    }

    /// One block of every operation. The loops are plain Rust; on x86-64 they are compiled a
    /// second time for AVX2 (four lanes instead of SSE2's two) and that copy is chosen at run
    /// time: 9 µs of a 2 505-row fit's 19 µs of term evaluation. Same operations, same results.
    fn eval_block(&self, sources: &[Source<'_>], start: usize, len: usize, slots: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU supports AVX2.
            unsafe { self.eval_block_avx2(sources, start, len, slots) };
            return;
        }
        self.eval_block_portable(sources, start, len, slots);
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn eval_block_avx2(&self, sources: &[Source<'_>], start: usize, len: usize, slots: &mut [f64]) {
        self.eval_block_portable(sources, start, len, slots);
    }

    #[inline(always)]
    fn eval_block_portable(&self, sources: &[Source<'_>], start: usize, len: usize, slots: &mut [f64]) {
        for (i, op) in self.ops.iter().enumerate() {
            let (done, rest) = slots.split_at_mut(i * BLOCK);
            let done = &*done;
            let dst = &mut rest[..len];
            let at = |a: usize| self.operand(sources, done, a, start, len);
            match op {
                Op::Input(j) => match sources[*j] {
                    Source::Column(_) => {} // read in place by `operand`
                    Source::Constant(v) => dst.fill(v),
                },
                Op::Const(c) => dst.fill(*c),
                Op::Mul(a, b) => {
                    for ((d, x), y) in dst.iter_mut().zip(at(*a)).zip(at(*b)) {
                        *d = x * y;
                    }
                }
                Op::Recip(a) => {
                    for (d, x) in dst.iter_mut().zip(at(*a)) {
                        *d = 1.0 / x;
                    }
                }
                Op::Call(f, args) => {
                    let func = super::functions::FUNCTIONS[*f].eval;
                    let columns: Vec<&[f64]> = args.iter().map(|&a| at(a)).collect();
                    let mut buf = vec![0.0; args.len()];
                    for (r, d) in dst.iter_mut().enumerate() {
                        for (b, column) in buf.iter_mut().zip(&columns) {
                            *b = column[r];
                        }
                        *d = func(&buf);
                    }
                }
                Op::Lin(parts) => {
                    dst.fill(0.0);
                    for &(c, k) in parts {
                        for (d, x) in dst.iter_mut().zip(at(k)) {
                            *d += c * x;
                        }
                    }
                }
            }
        }
    }
}

thread_local! {
    /// The block evaluator's slot buffer, kept between calls on this thread: identification
    /// evaluates run after run, and a fresh buffer of this size came back from the system as
    /// fresh pages every time.
    static BLOCK_SPARE: std::cell::RefCell<Vec<f64>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Σ c·s[k] with four independent partial sums: one running sum is a chain of dependent
/// additions, and an equation's right-hand side is a long one. No bounds checks.
///
/// # Safety
/// Every slot index in `parts` must be < `s.len()`.
#[inline]
unsafe fn lin_sum_unchecked(parts: &[(f64, u32)], s: &[f64]) -> f64 {
    let mut acc = [0.0f64; 4];
    let chunks = parts.chunks_exact(4);
    let rest = chunks.remainder();
    for c in chunks {
        for l in 0..4 {
            acc[l] += c[l].0 * *s.get_unchecked(c[l].1 as usize);
        }
    }
    let mut tail = 0.0;
    for (c, k) in rest {
        tail += c * *s.get_unchecked(*k as usize);
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

fn call_scalar(f: usize, args: &[usize], s: &[f64]) -> f64 {
    let func = super::functions::FUNCTIONS[f].eval;
    match args {
        [a] => func(&[s[*a]]),
        _ => func(&args.iter().map(|&a| s[a]).collect::<Vec<_>>()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shares_powers_and_prefixes() {
        let v = Vocabulary::open();
        let terms: Vec<Term> =
            ["u*r", "u*r*d^2", "d^2", "r^2/u", "v/u"].iter().map(|t| v.parse(t).unwrap()).collect();
        let lib = Library::compile(&terms, &v).unwrap();
        // inputs d,r,u,v (4) + d^2, r*u, d^2*r, d^2*r*u, r^2, 1/u, r^2/u, v/u: 12, with
        // d^2 and 1/u computed once though three terms use them
        assert_eq!(lib.op_count(), 12);
        let x = [2.0, 3.0, 5.0, 7.0];
        let mut out = vec![0.0; 5];
        let idx = |n: &str| lib.inputs().iter().position(|i| i == n).unwrap();
        let mut inp = [0.0; 4];
        for (n, val) in [("d", x[0]), ("r", x[1]), ("u", x[2]), ("v", x[3])] {
            inp[idx(n)] = val;
        }
        lib.eval_row(&inp, &mut lib.scratch(), &mut out);
        for (got, want) in out.iter().zip([15.0, 60.0, 4.0, 9.0 / 5.0, 7.0 / 5.0]) {
            assert!((got - want).abs() <= 1e-15 * want, "{got} vs {want}");
        }
    }

    /// sin and cos of the same argument are evaluated as one pair (the ship's track needs
    /// both of ψ); a lone sin or a cos of another argument stays a plain call.
    #[test]
    fn pairs_sine_and_cosine_of_one_argument() {
        let v = Vocabulary::open();
        let texts = ["u*cos(p)", "v*sin(p)", "sin(p)", "cos(2*p)", "sin(u)"];
        let terms: Vec<Term> = texts.iter().map(|t| v.parse(t).unwrap()).collect();
        let lib = Library::compile(&terms, &v).unwrap();
        let pairs: usize =
            lib.rows.groups.iter().map(|g| if let Group::SinCos(p) = g { p.len() } else { 0 }).sum();
        assert_eq!(pairs, 1);
        let (p, u, w) = (40.3, 1.7, -0.4);
        let mut inp = vec![0.0; lib.inputs().len()];
        for (n, val) in [("p", p), ("u", u), ("v", w)] {
            inp[lib.inputs().iter().position(|i| i == n).unwrap()] = val;
        }
        let mut out = vec![0.0; texts.len()];
        lib.eval_row(&inp, &mut lib.scratch(), &mut out);
        let want = [u * p.cos(), w * p.sin(), p.sin(), (2.0 * p).cos(), u.sin()];
        for (got, want) in out.iter().zip(want) {
            assert!((got - want).abs() <= 4e-16 * want.abs().max(1.0), "{got} vs {want}");
        }
    }
}
