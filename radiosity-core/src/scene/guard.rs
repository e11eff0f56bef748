//! Containing a third-party parser's panic: [`contain`] runs a closure and turns a panic into the
//! panic's message, so a reader can report it as its one-line error instead of crashing. Readers
//! validate lines first so that known panics are not reached; this is the backstop.
//!
//! A contained panic prints nothing: the first call installs a panic hook that stays silent while
//! the panicking thread is inside [`contain`] and otherwise calls the hook that was there before
//! (the default one prints the message and, with `RUST_BACKTRACE`, the backtrace).

use std::cell::Cell;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Once;

thread_local! {
    /// How many [`contain`] calls the current thread is inside.
    static DEPTH: Cell<u32> = const { Cell::new(0) };
}

static HOOK: Once = Once::new();

/// Runs `f`; a panic inside it becomes `Err(message)`. The closure's state may be half updated
/// after a panic: the caller drops it and reports the error.
pub fn contain<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if DEPTH.with(Cell::get) == 0 {
                previous(info);
            }
        }));
    });
    DEPTH.with(|d| d.set(d.get() + 1));
    let result = catch_unwind(AssertUnwindSafe(f));
    DEPTH.with(|d| d.set(d.get() - 1));
    result.map_err(|payload| {
        let msg = payload
            .downcast_ref::<&str>()
            .map(|s| (*s).to_owned())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".to_owned());
        msg.replace('\n', "; ")
    })
}

#[cfg(test)]
mod tests {
    use super::contain;

    #[test]
    fn a_panic_becomes_its_message() {
        let r: Result<(), String> = contain(|| panic!("index {} out of range", 3));
        assert_eq!(r, Err("index 3 out of range".to_owned()));
        assert_eq!(contain(|| 7), Ok(7));
        // Nested: the inner panic is contained, the outer call returns normally.
        assert_eq!(contain(|| contain(|| -> u8 { panic!("inner") })), Ok(Err("inner".to_owned())));
    }
}
