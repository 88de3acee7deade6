//! SIGINT and SIGTERM during `run`, `validate` and `reference`: the first raises a stop flag
//! that the run (at the end of its current step) and the reference runners (which end their
//! child's process tree) poll, so partial outputs are written; the command then exits with
//! 128 + the signal (130, 143). A second signal exits at once with that code.

use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;

use signal_hook::consts::{SIGINT, SIGTERM};

pub struct Interrupt {
    stop: Arc<AtomicBool>,
    signal: Arc<AtomicUsize>,
}

impl Interrupt {
    /// Installs the handlers. Only commands that poll the flag may call this: the others keep
    /// the default action (end the process).
    pub fn install() -> std::io::Result<Interrupt> {
        let stop = Arc::new(AtomicBool::new(false));
        let signal = Arc::new(AtomicUsize::new(0));
        for sig in [SIGINT, SIGTERM] {
            // The shutdown goes first: it is armed by the flag the first signal raises.
            signal_hook::flag::register_conditional_shutdown(sig, 128 + sig, stop.clone())?;
            signal_hook::flag::register_usize(sig, signal.clone(), sig as usize)?;
            signal_hook::flag::register(sig, stop.clone())?;
        }
        Ok(Interrupt { stop, signal })
    }

    /// The flag for `RunOptions::stop` and `RunnerOptions::stop`.
    pub fn flag(&self) -> Arc<AtomicBool> {
        self.stop.clone()
    }

    /// The signal's name and the exit code 128 + signal, once one arrived.
    pub fn received(&self) -> Option<(&'static str, ExitCode)> {
        if !self.stop.load(Ordering::SeqCst) {
            return None;
        }
        let sig = self.signal.load(Ordering::SeqCst) as i32;
        let name = if sig == SIGTERM { "SIGTERM" } else { "SIGINT" };
        let sig = if sig == 0 { SIGINT } else { sig };
        Some((name, ExitCode::from((128 + sig) as u8)))
    }
}
