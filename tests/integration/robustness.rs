//! No panic on any user input: mutated model files and CSV files get errors, never panics.

use proptest::prelude::*;
use termid::data::Frame;
use termid::model::{Model, DEFAULT_MODEL};

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    /// The default model with one line replaced by noise, deleted, or duplicated.
    #[test]
    fn mutated_model_files_never_panic(line in 0usize..400, noise in "\\PC{0,30}", how in 0u8..3) {
        let mut lines: Vec<String> = DEFAULT_MODEL.lines().map(str::to_string).collect();
        let k = line % lines.len();
        match how {
            0 => lines[k] = noise,
            1 => { lines.remove(k); }
            _ => { let l = lines[k].clone(); lines.insert(k, l); }
        }
        let text = lines.join("\n");
        if let Ok(m) = Model::parse(&text, "mutated.toml") {
            // a model that loads must also compile or refuse cleanly
            let _ = m.compile_rhs(false);
            let _ = termid::ship::Ship::new(&m, false).and_then(|s| s.straight_run());
        }
    }

    /// Any small CSV text: a frame or an error naming the file.
    #[test]
    fn csv_text_never_panics(text in "[t,u0-9.eE+\\-\\n NaNinf#x]{0,120}") {
        match Frame::parse_csv(&text, "any.csv", "t") {
            Ok(f) => prop_assert!(!f.time().is_empty()),
            Err(e) => prop_assert!(e.to_string().contains("any.csv") || e.to_string().contains("derivative")),
        }
    }

    /// Manoeuvre strings from the command line.
    #[test]
    fn manoeuvre_strings_never_panic(text in "[a-z:/0-9.\\-]{0,20}") {
        let _ = termid::ship::Manoeuvre::parse(&text);
    }
}
