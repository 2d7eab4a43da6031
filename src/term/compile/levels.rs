//! The compiled program levelised for one row at a time: operations grouped by dependency
//! depth and kind, so the simulator's per-step evaluation runs tight loops, not a dispatch per
//! operation.

use super::Op;

/// The same program for one row, levelised: operations grouped by dependency depth and by
/// kind, so that each group runs as one tight loop instead of one dispatch per operation
/// (the simulator evaluates a row at every step; dispatch dominated there).
#[derive(Clone, Debug, Default)]
pub(super) struct RowProgram {
    pub(super) constants: Vec<(usize, f64)>,
    pub(super) inputs: Vec<(u32, u32)>,
    pub(super) groups: Vec<Group>,
    pub(super) lin: Vec<(f64, u32)>,
}

#[derive(Clone, Debug)]
pub(super) enum Group {
    Mul(Vec<(u32, u32, u32)>),
    Recip(Vec<(u32, u32)>),
    Call(Vec<(usize, usize, Vec<usize>)>),
    /// (sine destination, cosine destination, argument): sin and cos of one argument share
    /// their argument reduction (a ship's track needs both of ψ at every step).
    SinCos(Vec<(u32, u32, u32)>),
    /// (destination, start, length) into `RowProgram::lin`.
    Lin(Vec<(u32, u32, u32)>),
}

impl Group {
    fn is_empty(&self) -> bool {
        match self {
            Group::Mul(v) | Group::Lin(v) => v.is_empty(),
            Group::Recip(v) => v.is_empty(),
            Group::Call(v) => v.is_empty(),
            Group::SinCos(v) => v.is_empty(),
        }
    }
}

impl RowProgram {
    pub(super) fn new(ops: &[Op]) -> RowProgram {
        let mut level = vec![0usize; ops.len()];
        for (i, op) in ops.iter().enumerate() {
            let deps: Vec<usize> = match op {
                Op::Input(_) | Op::Const(_) => vec![],
                Op::Mul(a, b) => vec![*a, *b],
                Op::Recip(a) => vec![*a],
                Op::Call(_, args) => args.clone(),
                Op::Lin(parts) => parts.iter().map(|p| p.1).collect(),
            };
            level[i] = deps.iter().map(|&d| level[d] + 1).max().unwrap_or(0);
        }
        let mut prog = RowProgram::default();
        let depth = level.iter().copied().max().unwrap_or(0);
        let n = |i: usize| i as u32;
        for l in 1..=depth {
            let idx: Vec<usize> = (0..ops.len()).filter(|i| level[*i] == l).collect();
            let mut muls = Vec::new();
            let mut recips = Vec::new();
            let mut calls = Vec::new();
            let mut lins = Vec::new();
            for &i in &idx {
                match &ops[i] {
                    Op::Mul(a, b) => muls.push((n(i), n(*a), n(*b))),
                    Op::Recip(a) => recips.push((n(i), n(*a))),
                    Op::Call(f, a) => calls.push((i, *f, a.clone())),
                    Op::Lin(parts) => {
                        lins.push((n(i), n(prog.lin.len()), n(parts.len())));
                        prog.lin.extend(parts.iter().map(|(c, k)| (*c, n(*k))));
                    }
                    Op::Input(_) | Op::Const(_) => {}
                }
            }
            let sincos = pair_sin_cos(&mut calls);
            for g in [
                Group::Mul(muls),
                Group::Recip(recips),
                Group::Call(calls),
                Group::SinCos(sincos),
                Group::Lin(lins),
            ] {
                if !g.is_empty() {
                    prog.groups.push(g);
                }
            }
        }
        for (i, op) in ops.iter().enumerate() {
            match op {
                Op::Input(j) => prog.inputs.push((n(i), n(*j))),
                Op::Const(c) => prog.constants.push((i, *c)),
                _ => {}
            }
        }
        prog
    }
}

/// Takes the pairs sin(a), cos(a) of one argument out of a level's calls.
fn pair_sin_cos(calls: &mut Vec<(usize, usize, Vec<usize>)>) -> Vec<(u32, u32, u32)> {
    let id = |name: &str| crate::term::functions::FUNCTIONS.iter().position(|f| f.name == name);
    let (Some(sin), Some(cos)) = (id("sin"), id("cos")) else { return vec![] };
    let mut pairs = Vec::new();
    let mut k = 0;
    while k < calls.len() {
        let (i, f, args) = &calls[k];
        let partner = (*f == sin && args.len() == 1)
            .then(|| calls.iter().position(|(_, g, b)| *g == cos && *b == *args))
            .flatten();
        match partner {
            Some(j) => {
                let (i_sin, arg) = (*i as u32, args[0] as u32);
                let i_cos = calls[j].0 as u32;
                pairs.push((i_sin, i_cos, arg));
                let (hi, lo) = (k.max(j), k.min(j));
                calls.remove(hi);
                calls.remove(lo);
                k = 0;
            }
            None => k += 1,
        }
    }
    pairs
}
