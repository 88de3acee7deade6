//! The `cgdem` command: a thin layer that turns arguments into validated settings, calls the
//! library and reports errors as messages with a non-zero exit code. Each subcommand is a
//! file of `cli/`.

mod cli;
mod interrupt;
mod progress_bar;

use std::process::ExitCode;

use clap::Parser;

/// Rust starts programs with SIGPIPE ignored, so a closed pipe (`cgdem advise ... | head -1`)
/// makes every later `println!` panic with "Broken pipe". With the default action the process
/// ends quietly when its reader has gone, as `grep` or `lmp` do; files are written through
/// their own handles, which a closed stdout does not touch.
fn restore_default_sigpipe() {
    // SAFETY: called first in `main`, before any thread starts; `signal` with `SIG_DFL` only
    // resets the disposition.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

fn main() -> ExitCode {
    restore_default_sigpipe();
    cli::Cli::parse().execute()
}
