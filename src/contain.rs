//! One boundary for panics inside dependencies (the QP solver, Arrow, Parquet, TOML, CSV):
//! a call into one runs under [`call`], and a panic there becomes an error that names what
//! was being done, instead of ending the process. termid's own code is meant not to panic;
//! this catches what a dependency does with input it was never meant to see.

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

#[cfg(test)]
mod tests {
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
