//! The terminal progress bar for runs: the command's implementation of the core's
//! [`ProgressReporter`], drawn with indicatif on stderr when it is a terminal.

use std::io::IsTerminal;
use std::sync::Arc;

use cgdem_core::run::{Progress, ProgressReporter, RunProgress};
use indicatif::{ProgressBar, ProgressStyle};

struct TerminalBars;

struct Bar(ProgressBar);

impl ProgressReporter for TerminalBars {
    fn start(&self, total_steps: u64) -> Box<dyn RunProgress> {
        let bar = ProgressBar::new(total_steps);
        bar.set_style(
            ProgressStyle::with_template(
                "{msg:>10} [{elapsed_precise}] {wide_bar} {percent:>3}% ETA {eta}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        Box::new(Bar(bar))
    }
}

impl RunProgress for Bar {
    fn stage(&mut self, name: &str) {
        self.0.set_message(name.to_string());
    }
    fn advance(&mut self, steps: u64) {
        self.0.inc(steps);
    }
    fn finish(&mut self) {
        self.0.finish_and_clear();
    }
}

/// A bar per run unless `quiet` or stderr is not a terminal.
pub fn progress(quiet: bool) -> Option<Progress> {
    (!quiet && std::io::stderr().is_terminal()).then(|| Progress(Arc::new(TerminalBars)))
}
