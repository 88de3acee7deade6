//! The stability suite: `[[stability]]` cases of a suite file, each run by cgdem and, where the
//! physics exists there, LAMMPS and LIGGGHTS, with one verdict per code:
//!
//! - **stable**: ran to the end; no particle lost; no non-finite value written; kinetic plus
//!   gravitational energy never above what the start held (kinetic + gravitational + the
//!   elastic energy of overlaps placed at the start) by more than the case's tolerance; the
//!   largest overlap below the case's limit.
//! - **detected**: the code stopped with a clear message (a cgdem guard or refusal, a
//!   reference code's `ERROR`) before any non-finite value or lost particle.
//! - **failed**: non-finite values, lost particles, an energy blow-up or drift, an overlap
//!   beyond the limit, or a crash without a message.
//!
//! Energy balance: with no work done (no moving body) and no attraction, `E0 + U0 = E(t) +
//! U(t) + D(t)` (`E` kinetic + gravitational, `U` elastic, `D` dissipated), so `E(t) <= E0 +
//! U0` and `E0 + U0 - E(t)` is what was dissipated or is stored at `t`. The reference decks
//! run with `thermo_modify lost error` (the codes' own default) instead of the validation
//! decks' `lost ignore`, so that a lost atom is the code's own error.
//!
//! Its phases, one file each: `suite` (the `[[stability]]` entry), `runs` (each code's run),
//! `measurement` (the evidence and the verdict) and `report` (the section and
//! `stability.csv`).

mod measurement;
mod report;
mod runs;
mod suite;
#[cfg(test)]
mod tests;

pub use measurement::{Evidence, LogFindings, Verdict};
pub(crate) use runs::run_cgdem;
pub use suite::StabilityCase;
pub(crate) use suite::{parse_cases, RawStabilityCase};

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::code::Code;
use crate::report::Report;
use crate::runs::ValidateOptions;
use cgdem_core::coarse_graining::coarse_grain;
use report::{write_csv, write_section};
use runs::{record, run_reference};

/// One code's run of one case.
#[derive(Clone, Debug, Serialize)]
pub struct StabilityRecord {
    pub case: String,
    pub code: Code,
    pub verdict: Verdict,
    /// Why: the guard's or the code's message, what failed, or why not applicable.
    pub message: String,
    /// The last lines of a reference code's log, when it stopped or failed.
    pub log_tail: Option<String>,
    pub dir: PathBuf,
    pub force_dt: bool,
    pub evidence: Option<Evidence>,
}

/// Runs every stability case of a suite in its codes under `RUNS/stability/` (the options'
/// runs directory), adds the "Stability" section to `report` and writes
/// `OUT/stability.csv` (none of it for a suite without stability cases).
pub fn run_stability(
    cases: &[StabilityCase],
    options: &ValidateOptions,
    report: &mut Report,
) -> Result<Vec<StabilityRecord>, String> {
    if cases.is_empty() {
        return Ok(Vec::new());
    }
    let (out, runs) = (&options.out, options.runs_dir());
    let (quiet, keep_going) = (options.quiet, options.keep_going);
    let (reference_timeout_s, decomposition) =
        (options.reference_timeout_s, &options.decomposition);
    let mut records = Vec::new();
    let mut described = Vec::new();
    for case in cases {
        let base = case
            .load_scene()
            .map_err(|e| format!("{}: {e}", case.file.display()))?;
        let mut label = base.name.clone();
        if case.lambda != 1 {
            label += &format!("-lambda{}", case.lambda);
        }
        let mut description = base.description.clone();
        if let Some(v) = &case.variant {
            description += &format!(" (variant `{v}`: {})", case.set.join(", "));
        }
        described.push((label.clone(), description, case.clone()));
        // A level cgdem refuses to build is its clear error; the reference codes get no scene.
        let scene = match coarse_grain(&base, case.lambda) {
            Ok(mut scene) => {
                scene.name = label.clone();
                scene
            }
            Err(e) => {
                for &code in &case.codes {
                    let mut rec = record(&base, code, case, Path::new(""));
                    rec.case = label.clone();
                    if code == Code::Cgdem {
                        rec.verdict = Verdict::Detected;
                        rec.message = format!("refused before the run: {e}");
                    } else {
                        rec.message = format!("no scene at lambda = {}: {e}", case.lambda);
                    }
                    if !quiet {
                        eprintln!(
                            "stability {label} {}: {}: {}",
                            code.name(),
                            rec.verdict.name(),
                            first_line(&rec.message)
                        );
                    }
                    records.push(rec);
                }
                continue;
            }
        };
        for &code in &case.codes {
            let dir = runs.join("stability").join(&scene.name).join(code.name());
            let _ = std::fs::remove_dir_all(&dir);
            let record = match code {
                Code::Cgdem => run_cgdem(&scene, case, &dir, keep_going, decomposition),
                Code::Lammps | Code::Liggghts => {
                    run_reference(code, &scene, case, &dir, reference_timeout_s)
                }
            };
            if !quiet {
                eprintln!(
                    "stability {} {}: {}: {}",
                    scene.name,
                    code.name(),
                    record.verdict.name(),
                    first_line(&record.message)
                );
            }
            records.push(record);
        }
    }
    write_csv(&records, &out.join("stability.csv"))?;
    write_section(report, &described, &records);
    Ok(records)
}

fn first_line(s: &str) -> String {
    s.lines().next().unwrap_or("").chars().take(200).collect()
}
