//! One boundary for panics inside dependencies (the QP solver, Arrow, Parquet, TOML, CSV):
//! a call into one runs under [`call`], and a panic there becomes an error that names what
//! was being done, instead of ending the process. termid's own code is meant not to panic;
//! this catches what a dependency does with input it was never meant to see. And where a
//! user's file breaks a dependency's rule (TOML's bare keys), its message says what to do.

use std::cell::Cell;
use std::panic::{catch_unwind, AssertUnwindSafe};

thread_local! {
    static DEPTH: Cell<u32> = const { Cell::new(0) };
}

/// Whether this thread is inside [`call`]: a panic hook stays quiet then, since the panic
/// becomes an ordinary error.
pub fn active() -> bool {
    DEPTH.with(Cell::get) > 0
}

/// Runs `f`, a call into a dependency; a panic in it is returned as `Err` with its message.
pub fn call<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    DEPTH.with(|d| d.set(d.get() + 1));
    let result = catch_unwind(AssertUnwindSafe(f));
    DEPTH.with(|d| d.set(d.get() - 1));
    result.map_err(|payload| {
        payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "(no message)".into())
    })
}

/// toml's message for a syntax error in `text`, with what to do where a bare key holds a
/// letter beyond ASCII: TOML allows only A-Z, a-z, 0-9, `_` and `-` in a bare key, and a naval
/// architect's names (σ, ε, δ_0, ψ) are not among them.
pub fn toml_message(error: &toml::de::Error, text: &str) -> String {
    let message = error.to_string();
    let Some(at) = error.span().map(|s| s.start) else {
        return message;
    };
    // the key of the error's line: a table header whole, else what stands before `=`
    let start = text.get(..at).map_or(0, |before| before.rfind('\n').map_or(0, |i| i + 1));
    let line = text.get(start..).and_then(|rest| rest.lines().next()).unwrap_or("");
    let key = if line.trim_start().starts_with('[') { line } else { line.split('=').next().unwrap_or("") };
    let mut quote = None;
    let bare_key = key.chars().any(|c| match (quote, c) {
        (None, '"' | '\'') => {
            quote = Some(c);
            false
        }
        (Some(q), c) if c == q => {
            quote = None;
            false
        }
        (None, c) => !c.is_ascii(),
        _ => false,
    });
    if bare_key {
        format!(
            "{message}a name with a letter beyond ASCII is quoted in TOML: [parameters.\"σ\"], \"δ_0\" = 0.0\n"
        )
    } else {
        message
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_bare_key_beyond_ascii_is_answered_with_its_quoting() {
        let text = "[parameters.σ]\nvalue = 1.0\n";
        let e = toml::from_str::<toml::Value>(text).unwrap_err();
        let m = super::toml_message(&e, text);
        assert!(m.contains("quoted in TOML: [parameters.\"σ\"]"), "{m} {:?}", e.span());
        let text = "x = \n";
        let e = toml::from_str::<toml::Value>(text).unwrap_err();
        assert!(!super::toml_message(&e, text).contains("quoted"));
    }

    #[test]
    fn a_panic_becomes_an_error_and_the_depth_returns() {
        let hook = std::panic::take_hook();
        std::panic::set_hook(Box::new(|_| {}));
        let r: Result<u8, String> = super::call(|| {
            assert!(super::active());
            panic!("index out of bounds")
        });
        std::panic::set_hook(hook);
        assert_eq!(r.unwrap_err(), "index out of bounds");
        assert!(!super::active());
        assert_eq!(super::call(|| 4), Ok(4));
    }
}
