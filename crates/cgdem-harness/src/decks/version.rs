//! Which release of a reference code the harness runs, read from the banner it prints on
//! start-up, and whether the deck writers were verified against it.
//!
//! The decks are written for, and checked by golden collisions against, one release of
//! each code: LIGGGHTS 3.8.0 and LAMMPS 29 Sep 2021. Keywords and defaults move between
//! releases (LAMMPS's GRANULAR package was reworked in 2023, `fix wall/gran` with it), so a
//! deck that runs in another release may mean something else there. Another release is
//! run, with a warning that names the verified one, and recorded in every report.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};

use super::Dialect;
use crate::code::Code;

/// The releases the deck writers were verified against, as the banner names them.
pub fn verified_release(code: Code) -> Option<&'static str> {
    match code {
        Code::Liggghts => Some("3.8.0"),
        Code::Lammps => Some("29 Sep 2021"),
        Code::Cgdem => None,
    }
}

/// A reference code as found: its binary and the release its banner names.
#[derive(Clone, Debug, PartialEq)]
pub struct CodeVersion {
    pub code: Code,
    pub program: PathBuf,
    /// The banner's first line, e.g. `LAMMPS (29 Sep 2021 - Update 2)`.
    pub banner: String,
    /// The release read from it (`3.8.0`, `29 Sep 2021`), if the banner has the usual shape.
    pub release: Option<String>,
}

impl CodeVersion {
    /// Whether the deck writers were verified against this release.
    pub fn verified(&self) -> bool {
        self.release.as_deref() == verified_release(self.code)
    }

    /// The warning for a release the decks were not verified against, if this is one.
    pub fn warning(&self) -> Option<String> {
        if self.verified() {
            return None;
        }
        Some(format!(
            "{} at {} is {}; the harness's decks were verified against {} {} only (golden \
             collisions, reference/MAPPING.md): keywords and defaults may mean something else \
             in this release, so its comparisons may differ for that reason alone",
            self.code.label(),
            self.program.display(),
            match &self.release {
                Some(r) => format!("release {r}"),
                None => format!("of an unknown release (banner: {:?})", self.banner),
            },
            self.code.label(),
            verified_release(self.code).unwrap_or("?"),
        ))
    }

    /// In words for a report's provenance: the release and the binary.
    pub fn describe(&self) -> String {
        let verified = if self.verified() {
            "verified"
        } else {
            "NOT verified"
        };
        format!(
            "{} ({}; {verified} for the decks)",
            self.banner,
            self.program.display()
        )
    }
}

/// The release from a banner line: LIGGGHTS prints `LIGGGHTS (Version LIGGGHTS-PUBLIC
/// 3.8.0, compiled ...)`, LAMMPS `LAMMPS (29 Sep 2021 - Update 2)` or `LAMMPS (22 Jul 2025)`.
pub fn parse_release(code: Code, banner: &str) -> Option<String> {
    let inside = banner.split_once('(')?.1.split(')').next()?;
    match code {
        Code::Liggghts => {
            let version = inside.strip_prefix("Version ")?.split(',').next()?.trim();
            Some(version.rsplit(' ').next()?.to_string())
        }
        Code::Lammps => {
            let date = inside.split(" - ").next()?.trim();
            (date.split_whitespace().count() == 3).then(|| date.to_string())
        }
        Code::Cgdem => None,
    }
}

/// A LAMMPS release's date (`29 Sep 2021`) as (year, month, day), to compare releases.
pub fn lammps_date(release: &str) -> Option<(i32, u32, u32)> {
    const MONTHS: [&str; 12] = [
        "Jan", "Feb", "Mar", "Apr", "May", "Jun", "Jul", "Aug", "Sep", "Oct", "Nov", "Dec",
    ];
    let mut words = release.split_whitespace();
    let day: u32 = words.next()?.parse().ok()?;
    let month = words.next()?;
    let month = MONTHS.iter().position(|m| *m == month)? as u32 + 1;
    let year: i32 = words.next()?.parse().ok()?;
    (words.next().is_none() && (1..=31).contains(&day)).then_some((year, month, day))
}

/// The code's version, read once per binary (the code is started with an empty input,
/// which makes both print their banner and stop); an error when it is not installed.
pub fn find_version(dialect: &Dialect) -> Result<CodeVersion, String> {
    version_of(dialect.code, &super::find_program(dialect)?)
}

/// The version of `program`, a build of `code`, read once per binary.
pub fn version_of(code: Code, program: &Path) -> Result<CodeVersion, String> {
    static SEEN: OnceLock<Mutex<HashMap<PathBuf, CodeVersion>>> = OnceLock::new();
    let seen = SEEN.get_or_init(Default::default);
    if let Some(v) = seen.lock().unwrap_or_else(|e| e.into_inner()).get(program) {
        return Ok(v.clone());
    }
    let banner = read_banner(program)?;
    let version = CodeVersion {
        code,
        release: parse_release(code, &banner),
        program: program.to_path_buf(),
        banner,
    };
    seen.lock()
        .unwrap_or_else(|e| e.into_inner())
        .insert(program.to_path_buf(), version.clone());
    Ok(version)
}

/// The first line the program prints that names it, run in a scratch directory (LAMMPS
/// would otherwise leave a log file in the working directory).
fn read_banner(program: &Path) -> Result<String, String> {
    // One directory per call: threads that read banners at once must not share one.
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let scratch = std::env::temp_dir().join(format!("cgdem-version-{}-{call}", std::process::id()));
    std::fs::create_dir_all(&scratch)
        .map_err(|e| format!("cannot make {}: {e}", scratch.display()))?;
    let output = std::process::Command::new(program)
        .args(["-log", "none", "-echo", "none"])
        .current_dir(&scratch)
        .stdin(std::process::Stdio::null())
        .output();
    let _ = std::fs::remove_dir_all(&scratch);
    let output = output.map_err(|e| format!("cannot start {}: {e}", program.display()))?;
    let text = String::from_utf8_lossy(&output.stdout);
    text.lines()
        .map(str::trim)
        .find(|l| l.starts_with("LAMMPS (") || l.starts_with("LIGGGHTS ("))
        .map(str::to_string)
        .ok_or_else(|| {
            format!(
                "{} printed no LAMMPS or LIGGGHTS banner (is it one of them?)",
                program.display()
            )
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_release_is_read_from_each_codes_banner() {
        let liggghts = "LIGGGHTS (Version LIGGGHTS-PUBLIC 3.8.0, compiled 2022-01-26-19:42:32 by buildd, git commit unknown)";
        assert_eq!(
            parse_release(Code::Liggghts, liggghts).as_deref(),
            Some("3.8.0")
        );
        let lammps = "LAMMPS (29 Sep 2021 - Update 2)";
        assert_eq!(
            parse_release(Code::Lammps, lammps).as_deref(),
            Some("29 Sep 2021")
        );
        let newer = "LAMMPS (22 Jul 2025)";
        assert_eq!(
            parse_release(Code::Lammps, newer).as_deref(),
            Some("22 Jul 2025")
        );
        assert_eq!(parse_release(Code::Lammps, "LAMMPS"), None);
    }

    #[test]
    fn lammps_releases_compare_by_date() {
        assert_eq!(lammps_date("29 Sep 2021"), Some((2021, 9, 29)));
        assert_eq!(lammps_date("22 Jul 2025"), Some((2025, 7, 22)));
        assert_eq!(lammps_date("8 Feb 2023"), Some((2023, 2, 8)));
        assert!(lammps_date("28 Mar 2023") > lammps_date("8 Feb 2023"));
        for bad in [
            "",
            "Sep 2021",
            "29 Sept 2021",
            "32 Sep 2021",
            "29 Sep 2021 x",
        ] {
            assert_eq!(lammps_date(bad), None, "{bad}");
        }
    }

    #[test]
    fn only_the_verified_releases_go_without_a_warning() {
        let version = |code, banner: &str| CodeVersion {
            code,
            program: PathBuf::from("/usr/bin/x"),
            banner: banner.into(),
            release: parse_release(code, banner),
        };
        let debian = version(Code::Lammps, "LAMMPS (29 Sep 2021 - Update 2)");
        assert!(debian.verified() && debian.warning().is_none());
        let newer = version(Code::Lammps, "LAMMPS (22 Jul 2025 - Update 4)");
        let warning = newer.warning().expect("a newer LAMMPS is warned about");
        assert!(warning.contains("22 Jul 2025") && warning.contains("29 Sep 2021"));
        let master = version(
            Code::Liggghts,
            "LIGGGHTS (Version LIGGGHTS-PUBLIC 3.8.1, compiled today)",
        );
        assert!(master.warning().unwrap().contains("3.8.0"));
    }

    #[test]
    fn a_program_that_is_not_a_reference_code_is_named() {
        let dialect = Dialect {
            program: "true",
            program_variable: "CGDEM_TEST_NO_SUCH_VARIABLE",
            ..super::super::lammps::DIALECT
        };
        let e = find_version(&dialect).unwrap_err();
        assert!(e.contains("no LAMMPS or LIGGGHTS banner"), "{e}");
    }
}
