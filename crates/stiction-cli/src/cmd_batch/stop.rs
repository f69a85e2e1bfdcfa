//! A clean stop. The first SIGINT (Ctrl-C) or SIGTERM (a scheduler's stop) asks the batch to
//! stop handing out loops: running loops finish and the summary of what is done is written. A
//! second signal ends the process at once. A write that fails (a full disk) stops the batch the
//! same way, since every later loop would fail to be saved too.

use anyhow::Result;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

/// Why a batch stopped early.
pub enum Reason {
    /// A signal: SIGINT exits 130, SIGTERM 143 (128 + the signal's number, as shells do).
    Signal(i32),
    /// A file of the batch could not be written: the error.
    Fault(String),
}

#[derive(Default)]
pub struct Stop {
    /// The signal received, 0 if none.
    signal: Arc<AtomicUsize>,
    fault: Mutex<Option<String>>,
}

impl Stop {
    /// Install the handlers of SIGINT and SIGTERM.
    pub fn install() -> Result<Stop> {
        let stop = Stop::default();
        #[cfg(unix)]
        {
            use signal_hook::consts::{SIGINT, SIGTERM};
            let armed = Arc::new(AtomicBool::new(false));
            for sig in [SIGINT, SIGTERM] {
                // registered first, so it runs before `armed` is set: only a second signal exits
                signal_hook::flag::register_conditional_shutdown(
                    sig,
                    128 + sig,
                    Arc::clone(&armed),
                )?;
                signal_hook::flag::register(sig, Arc::clone(&armed))?;
                signal_hook::flag::register_usize(sig, Arc::clone(&stop.signal), sig as usize)?;
            }
        }
        Ok(stop)
    }

    /// Stop handing out loops?
    pub fn requested(&self) -> bool {
        self.signal.load(Ordering::Relaxed) != 0 || self.fault_message().is_some()
    }

    /// A write failed; the first failure is the one reported.
    pub fn fault(&self, why: String) {
        let mut f = self.fault.lock().unwrap_or_else(|p| p.into_inner());
        f.get_or_insert(why);
    }

    fn fault_message(&self) -> Option<String> {
        self.fault.lock().unwrap_or_else(|p| p.into_inner()).clone()
    }

    /// Why the batch stopped, if it did (a fault first: it is the one to fix).
    pub fn reason(&self) -> Option<Reason> {
        if let Some(why) = self.fault_message() {
            return Some(Reason::Fault(why));
        }
        match self.signal.load(Ordering::Relaxed) {
            0 => None,
            s => Some(Reason::Signal(s as i32)),
        }
    }
}
