//! The builds of each reference code the bench times: those named with `--build
//! CODE=LABEL:PATH`, else the one found as the harness finds it (`$CGDEM_LMP` or `lmp` on
//! `PATH`, likewise LIGGGHTS), labelled by its release. Each is probed once before anything
//! runs: its banner, the MPI launcher that goes with it (an `mpirun` beside the binary, as
//! in a Python environment with its own MPI, else the one on `PATH`), and whether it has
//! LAMMPS's OPENMP package (`lmp -h` lists the installed packages).

use std::path::{Path, PathBuf};
use std::str::FromStr;

use super::BenchError;
use crate::decks::lammps::WallModulus;
use crate::decks::version::{version_of, CodeVersion};
use crate::decks::{dialect, find_program, runner};
use crate::suite::Code;

/// A build as the user names it: `lammps=LABEL:PATH` or `liggghts=LABEL:PATH`.
#[derive(Clone, Debug, PartialEq)]
pub struct BuildSpec {
    pub code: Code,
    pub label: String,
    pub program: PathBuf,
}

impl FromStr for BuildSpec {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        let shape = "give CODE=LABEL:PATH, e.g. lammps=native:/opt/lammps/build/lmp";
        let (code, rest) = text
            .split_once('=')
            .ok_or_else(|| format!("`{text}`: {shape}"))?;
        let code = match Code::from_name(code) {
            Some(c @ (Code::Lammps | Code::Liggghts)) => c,
            _ => {
                return Err(format!(
                    "`{code}` is not a reference code: lammps or liggghts"
                ))
            }
        };
        let (label, program) = rest
            .split_once(':')
            .ok_or_else(|| format!("`{text}`: {shape}"))?;
        check_label(label)?;
        if program.is_empty() {
            return Err(format!("`{text}`: no PATH after the label; {shape}"));
        }
        Ok(BuildSpec {
            code,
            label: label.into(),
            program: program.into(),
        })
    }
}

/// A label names run directories and table rows: letters, digits, `.`, `_`, `+`, `-`.
fn check_label(label: &str) -> Result<(), String> {
    let allowed = |c: char| c.is_ascii_alphanumeric() || "._+-".contains(c);
    if label.is_empty() || !label.chars().all(allowed) {
        return Err(format!(
            "build label `{label}`: use letters, digits, `.`, `_`, `+` and `-` only"
        ));
    }
    Ok(())
}

/// How a build's MPI ranks are started.
#[derive(Clone, Debug, PartialEq)]
pub enum Launcher {
    /// Open MPI's `mpirun` (root allowed, oversubscription when ranks exceed cores).
    OpenMpi(PathBuf),
    /// Another `mpirun`, e.g. MPICH's: `mpirun -np N`.
    Plain(PathBuf),
}

/// How one run of a build uses its workers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Launch {
    /// `n` MPI ranks of one thread each (one process without `mpirun` when `n` is 1).
    Ranks(usize),
    /// One process of `n` OpenMP threads (`-sf omp -pk omp n`).
    OpenMp(usize),
}

impl Launch {
    /// MPI ranks when started by `mpirun`.
    pub fn ranks(self) -> Option<usize> {
        match self {
            Launch::Ranks(n) if n > 1 => Some(n),
            _ => None,
        }
    }

    /// Ranks or threads.
    pub fn workers(self) -> usize {
        match self {
            Launch::Ranks(n) | Launch::OpenMp(n) => n,
        }
    }

    /// OpenMP threads of an OPENMP run.
    pub fn openmp_threads(self) -> Option<usize> {
        match self {
            Launch::OpenMp(n) => Some(n),
            Launch::Ranks(_) => None,
        }
    }
}

/// A reference build found and probed.
#[derive(Clone, Debug)]
pub struct Found {
    pub version: CodeVersion,
    /// LAMMPS's OPENMP package is installed: at more than one worker the build also runs as
    /// one process of OpenMP threads.
    pub openmp: bool,
    pub launcher: Launcher,
}

/// One build of a reference code the bench runs.
#[derive(Clone, Debug)]
pub struct Build {
    pub code: Code,
    pub label: String,
    /// Err: the code's default build is not installed; its runs are skipped, saying why.
    pub found: Result<Found, String>,
}

impl Build {
    /// How this build reads a LAMMPS wall's modulus (the verified release's when unknown).
    pub fn wall_modulus(&self) -> WallModulus {
        let release = self.found.as_ref().ok();
        WallModulus::of_release(release.and_then(|f| f.version.release.as_deref()))
    }

    /// The runs of this build at `workers`: as many MPI ranks, and with OPENMP also one
    /// process of as many threads.
    pub fn launches(&self, workers: usize) -> Vec<Launch> {
        let mut out = vec![Launch::Ranks(workers)];
        if workers > 1 && self.found.as_ref().is_ok_and(|f| f.openmp) {
            out.push(Launch::OpenMp(workers));
        }
        out
    }
}

/// The builds of every reference code in `codes`: the ones given for it, else its default
/// build. A given build that cannot be run, or a build for a code not among `codes`, is an
/// error naming it.
pub fn resolve(codes: &[Code], specs: &[BuildSpec]) -> Result<Vec<Build>, BenchError> {
    if let Some(s) = specs.iter().find(|s| !codes.contains(&s.code)) {
        return Err(BenchError::Build(format!(
            "--build {}={}: {} is not among --codes",
            s.code.name(),
            s.label,
            s.code.name()
        )));
    }
    let mut builds = Vec::new();
    for &code in codes.iter().filter(|&&c| c != Code::Cgdem) {
        let given: Vec<&BuildSpec> = specs.iter().filter(|s| s.code == code).collect();
        if given.is_empty() {
            builds.push(default_build(code)?);
        }
        for spec in given {
            if builds
                .iter()
                .any(|b: &Build| b.code == code && b.label == spec.label)
            {
                return Err(BenchError::Build(format!(
                    "--build {}={}: the label is given twice",
                    code.name(),
                    spec.label
                )));
            }
            let found = probe(code, &spec.program).map_err(|e| {
                BenchError::Build(format!("--build {}={}: {e}", code.name(), spec.label))
            })?;
            builds.push(Build {
                code,
                label: spec.label.clone(),
                found: Ok(found),
            });
        }
    }
    Ok(builds)
}

/// The build the harness finds by itself, labelled by its release; one that is not
/// installed is kept (its runs are skipped), one that cannot be probed is an error.
fn default_build(code: Code) -> Result<Build, BenchError> {
    let Some(dialect) = dialect(code) else {
        return Err(BenchError::Build(format!("{} has no builds", code.name())));
    };
    let program = match find_program(dialect) {
        Ok(p) => p,
        Err(reason) => {
            return Ok(Build {
                code,
                label: code.name().into(),
                found: Err(reason),
            })
        }
    };
    let found = probe(code, &program).map_err(|e| {
        BenchError::Build(format!(
            "the {} at {}: {e}",
            code.label(),
            program.display()
        ))
    })?;
    Ok(Build {
        code,
        label: default_label(&found.version),
        found: Ok(found),
    })
}

/// A label from the banner: LAMMPS's date and update (`29Sep2021-Update2`), LIGGGHTS's
/// version (`3.8.0`).
pub fn default_label(version: &CodeVersion) -> String {
    let inside = version
        .banner
        .split_once('(')
        .and_then(|(_, rest)| rest.split(')').next())
        .unwrap_or("");
    let text = match version.code {
        Code::Lammps => inside.replace(" - ", "-"),
        _ => version.release.clone().unwrap_or_default(),
    };
    let label: String = text.chars().filter(|c| !c.is_whitespace()).collect();
    if check_label(&label).is_ok() {
        label
    } else {
        version.code.name().into()
    }
}

/// The binary's banner, its launcher and (LAMMPS) whether it has OPENMP.
fn probe(code: Code, program: &Path) -> Result<Found, String> {
    if !program.is_file() {
        return Err(format!("{} is not a file", program.display()));
    }
    let version = version_of(code, program)?;
    let openmp = code == Code::Lammps && has_openmp(&help_text(program)?);
    Ok(Found {
        version,
        openmp,
        launcher: launcher_for(program),
    })
}

/// What `program -h` prints.
fn help_text(program: &Path) -> Result<String, String> {
    let output = std::process::Command::new(program)
        .arg("-h")
        .current_dir(std::env::temp_dir())
        .stdin(std::process::Stdio::null())
        .output()
        .map_err(|e| format!("cannot start {} -h: {e}", program.display()))?;
    Ok(String::from_utf8_lossy(&output.stdout).into_owned())
}

/// Whether LAMMPS's help text lists OPENMP among the installed packages.
pub fn has_openmp(help: &str) -> bool {
    help.lines()
        .skip_while(|l| !l.starts_with("Installed packages:"))
        .skip(1)
        .take_while(|l| !l.starts_with("List of"))
        .any(|l| l.split_whitespace().any(|w| w == "OPENMP"))
}

/// The `mpirun` beside the binary (a Python environment's own MPI), else the one on `PATH`;
/// Open MPI's when its `--version` says so.
fn launcher_for(program: &Path) -> Launcher {
    let beside = program.parent().map(|d| d.join("mpirun"));
    let mpirun = beside
        .filter(|p| p.is_file())
        .unwrap_or_else(|| PathBuf::from("mpirun"));
    let version = std::process::Command::new(&mpirun)
        .arg("--version")
        .stdin(std::process::Stdio::null())
        .output()
        .map(|o| String::from_utf8_lossy(&o.stdout).into_owned())
        .unwrap_or_default();
    if version.contains("Open MPI") || version.contains("OpenRTE") {
        Launcher::OpenMpi(mpirun)
    } else {
        Launcher::Plain(mpirun)
    }
}

/// The command line of one run: `env OMP_NUM_THREADS=T`, the launcher for more than one
/// rank, the binary with the deck and log, and `-sf omp -pk omp T` for an OpenMP run.
pub fn command(found: &Found, launch: Launch, deck: &str, log: &str, cores: usize) -> Vec<String> {
    let threads = launch.openmp_threads().unwrap_or(1);
    let mut argv = vec!["env".to_string(), format!("OMP_NUM_THREADS={threads}")];
    if let Some(n) = launch.ranks() {
        match &found.launcher {
            Launcher::OpenMpi(mpirun) => {
                let mut open = runner::mpirun_argv(n as u32, cores);
                open[0] = mpirun.display().to_string();
                argv.extend(open);
            }
            Launcher::Plain(mpirun) => {
                argv.extend([mpirun.display().to_string(), "-np".into(), n.to_string()])
            }
        }
    }
    argv.extend([
        found.version.program.display().to_string(),
        "-in".into(),
        deck.into(),
        "-log".into(),
        log.into(),
    ]);
    if launch.openmp_threads().is_some() {
        argv.extend(["-sf", "omp", "-pk", "omp"].map(String::from));
        argv.push(threads.to_string());
    }
    argv
}
