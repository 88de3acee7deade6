//! `cgdem history`: a night's report added to the nightly history.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Args;

#[derive(Args)]
pub(super) struct HistoryArgs {
    /// The history directory, e.g. reports/nightly.
    dir: PathBuf,
    /// The night's report directory.
    #[arg(long)]
    add: PathBuf,
    /// The night's date (YYYY-MM-DD).
    #[arg(long)]
    date: String,
    /// The cgdem commit the night ran.
    #[arg(long)]
    commit: String,
}

pub(super) fn execute(args: HistoryArgs) -> ExitCode {
    let HistoryArgs {
        dir,
        add,
        date,
        commit,
    } = args;
    let added = cgdem_harness::history::add_night(&dir, &add, &date, &commit);
    super::exit_with(added.map(|flags| {
        for f in &flags {
            println!(
                "flag: {} moved from {:.4e} to {:.4e} (tolerance {}{})",
                f.metric,
                f.previous,
                f.current,
                f.tolerance,
                if f.relative { " relative" } else { "" }
            );
        }
        println!(
            "history: {} ({} flags against the previous night)",
            dir.join("index.html").display(),
            flags.len()
        );
    }))
}
