//! Progress of a run, reported to whoever drives it (the command draws a bar; libraries and
//! tests pass nothing). Called once per 256 steps and per stage, never per particle.

use std::fmt;
use std::sync::Arc;

/// Makes one progress display per run; shared by the runs of a sweep or a suite.
pub trait ProgressReporter: Send + Sync {
    /// A run of about `total_steps` steps begins.
    fn start(&self, total_steps: u64) -> Box<dyn RunProgress>;
}

/// The progress display of one run.
pub trait RunProgress {
    /// The run entered the stage `name`.
    fn stage(&mut self, name: &str);
    /// `steps` more steps are done.
    fn advance(&mut self, steps: u64);
    /// The run ended (normally or not); the display may go.
    fn finish(&mut self);
}

/// A shared reporter, as [`super::RunOptions`] holds it.
#[derive(Clone)]
pub struct Progress(pub Arc<dyn ProgressReporter>);

impl fmt::Debug for Progress {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("Progress(..)")
    }
}

/// Reports nothing: runs without a reporter use it.
pub(super) struct Silent;

impl RunProgress for Silent {
    fn stage(&mut self, _name: &str) {}
    fn advance(&mut self, _steps: u64) {}
    fn finish(&mut self) {}
}
