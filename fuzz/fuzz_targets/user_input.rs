//! Every text a user hands termid, from one fuzzer input: the first byte picks the reader,
//! the rest is the text. Any error is fine; a panic is a bug.
#![no_main]

use libfuzzer_sys::fuzz_target;
use termid::data::{differentiator, Dataset, Frame};
use termid::model::Model;
use termid::ship::Manoeuvre;
use termid::term::Vocabulary;

fuzz_target!(|data: &[u8]| {
    let Some((&kind, rest)) = data.split_first() else { return };
    let Ok(text) = std::str::from_utf8(rest) else { return };
    match kind % 6 {
        0 => {
            // a candidate term in the ship's vocabulary
            let mut v = Vocabulary::new();
            for name in ["u", "v", "r", "δ", "ψ"] {
                let _ = v.variable(name);
            }
            let _ = v.parameter("u0");
            let _ = v.derive("Δu", "u - u0");
            let _ = v.alias("du", "Δu");
            if let Ok(t) = v.parse(text) {
                let _ = t.to_string();
                let _ = termid::term::Library::compile(&[t], &v);
            }
        }
        1 => {
            if let Ok(f) = Frame::parse_csv(text, "fuzz.csv", "t") {
                let _ = termid::data::resample(&f, 0.1);
            }
        }
        2 => {
            let _ = Model::parse(text, "fuzz.toml");
        }
        3 => {
            let _ = Manoeuvre::parse(text);
        }
        4 => {
            if let Ok(d) = differentiator(text) {
                let t: Vec<f64> = (0..40).map(|i| i as f64 * 0.05).collect();
                let x: Vec<f64> = t.iter().map(|t| t.sin()).collect();
                let _ = d.smooth(&t, &x);
            }
        }
        _ => {
            let _ = toml::from_str::<Dataset>(text);
        }
    }
});
