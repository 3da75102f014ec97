//! [`guard`]: the wrapper every entry point runs under (no panic crosses the boundary).

use std::any::Any;
use std::panic::{catch_unwind, AssertUnwindSafe};

use crate::status::{set_last_error, DcrStatus, Failure};

/// Runs `body` for the C entry point `function`: `Ok` → [`DcrStatus::Ok`]; a [`Failure`] → its
/// status, with `function: message` stored as the thread's last error; a panic →
/// [`DcrStatus::Panic`], with the panic's message stored the same way.
///
/// The closure is asserted unwind-safe: after a panic the handles it touched may hold broken
/// invariants, which is why the documented contract of `DCR_STATUS_PANIC` is to free them.
pub fn guard(function: &'static str, body: impl FnOnce() -> Result<(), Failure>) -> DcrStatus {
    match catch_unwind(AssertUnwindSafe(body)) {
        Ok(Ok(())) => DcrStatus::Ok,
        Ok(Err(f)) => {
            set_last_error(function, &f.message);
            f.status
        }
        Err(payload) => {
            let what = panic_message(payload.as_ref());
            // Storing the message must not unwind either (it only formats and allocates).
            let _ = catch_unwind(|| {
                set_last_error(
                    function,
                    &format!(
                        "internal error (panic: {what}); free the objects this call used \
                         and report the bug"
                    ),
                )
            });
            DcrStatus::Panic
        }
    }
}

fn panic_message(payload: &(dyn Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "non-string payload".to_string()
    }
}
