//! Restart files (`--checkpoint-every`, `--resume`): the whole state of a run, so that a run
//! killed at any moment goes on from its last checkpoint and writes exactly the outputs the
//! uninterrupted run writes.
//!
//! File layout: a 32-byte header (magic `CGDEMRST`, format version u32, payload length u64,
//! CRC-32 of the payload u32, 8 reserved zero bytes; little endian), then the payload, a
//! [`Restart`] in bincode. The writer writes `restart.cgr.tmp`, syncs it, renames the current
//! `restart.cgr` to `restart.prev.cgr` and the new file to `restart.cgr`: at every moment one
//! complete, checked file exists. The reader takes `restart.cgr` and falls back to
//! `restart.prev.cgr` when the first is missing, torn or corrupt (named in a warning).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use crate::coarse_graining::CoarseGrainRule;
use crate::decomposition::{BalanceSpec, GridSpec};
use crate::guard::GuardKind;
use crate::math::Real;

use super::StageRecord;

pub const RESTART_FILE: &str = "restart.cgr";
pub const PREVIOUS_RESTART_FILE: &str = "restart.prev.cgr";
const MAGIC: &[u8; 8] = b"CGDEMRST";
/// Bumped whenever the payload's layout changes; an older file is refused by name (2: the
/// world state holds the subdomains of a `--grid` run; 3: the driver keeps the wall time; 4: every
/// run is a grid, the world state is its subdomains).
pub const FORMAT_VERSION: u32 = 4;
const HEADER_LEN: usize = 32;

/// Where in the stage list a checkpoint was taken.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Position {
    /// The stage to continue with.
    pub stage: usize,
    /// Steps of that stage already taken, with the time it began; None: it has not begun
    /// (the checkpoint was taken at the end of the stage before, or at the start).
    pub within: Option<(u64, Real)>,
}

/// The driver's counters and the state of a stage's top-ups.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DriverState {
    pub refilled: u64,
    pub particle_steps: u64,
    pub stages: Vec<StageRecord>,
    pub guard_counts: Vec<(GuardKind, u64)>,
    /// The current stage's top-ups: (insertion, particles at the stage start, top-ups so far).
    pub refills: Vec<(usize, usize, u64)>,
    pub next_checkpoint: Real,
    pub warnings: Vec<String>,
    pub n_inserted: usize,
    pub n_body_particles: usize,
    /// Wall seconds the run had spent stepping when the file was written (over every
    /// process it ran in): a resumed run's `wall_s` goes on from it.
    pub wall_s: Real,
}

/// One restart file's content.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Restart {
    /// What the caller needs to rebuild the scene (the command line of `cgdem run`), opaque
    /// to the solver.
    pub invocation: String,
    /// `Scene::digest` of the scene the run simulates: a resume with another scene is refused.
    pub scene_digest: String,
    /// The scene's law combination (`L`, `W` type names), checked before decoding the world.
    pub laws: String,
    /// `--checkpoint-every`, kept by the resumed run.
    pub checkpoint_every: Real,
    pub position: Position,
    /// `WorldState<L::History, W::History>` in bincode.
    pub world: Vec<u8>,
    pub driver: DriverState,
    /// Each observer's state, in the driver's observer order.
    pub observers: Vec<Vec<u8>>,
}

impl std::fmt::Debug for RestartLoaded {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "RestartLoaded({})", self.path.display())
    }
}

/// A restart file read back, with the file it came from and warnings about newer files
/// that could not be used.
#[derive(Clone)]
pub struct RestartLoaded {
    pub restart: Restart,
    pub path: PathBuf,
    pub warnings: Vec<String>,
}

pub(crate) fn encode<T: Serialize>(value: &T) -> Vec<u8> {
    bincode::serialize(value).expect("in-memory bincode of plain data cannot fail")
}

pub(crate) fn decode<T: DeserializeOwned>(bytes: &[u8]) -> Result<T, String> {
    bincode::deserialize(bytes).map_err(|e| e.to_string())
}

/// The file bytes of a restart: header and payload.
pub fn to_bytes(restart: &Restart) -> Vec<u8> {
    frame(MAGIC, FORMAT_VERSION, &encode(restart))
}

/// Checks the header and checksum and decodes the payload; the error says what is wrong.
pub fn from_bytes(bytes: &[u8]) -> Result<Restart, String> {
    let payload = unframe(MAGIC, FORMAT_VERSION, bytes)?;
    decode(payload).map_err(|e| format!("payload does not decode: {e}"))
}

/// `magic`, format `version`, payload length and CRC-32, 8 reserved zero bytes, then the
/// payload: the layout of restart files and of the bench's state files.
pub(crate) fn frame(magic: &[u8; 8], version: u32, payload: &[u8]) -> Vec<u8> {
    let mut bytes = Vec::with_capacity(HEADER_LEN + payload.len());
    bytes.extend_from_slice(magic);
    bytes.extend_from_slice(&version.to_le_bytes());
    bytes.extend_from_slice(&(payload.len() as u64).to_le_bytes());
    bytes.extend_from_slice(&crc32fast::hash(payload).to_le_bytes());
    bytes.extend_from_slice(&[0; 8]);
    bytes.extend_from_slice(payload);
    bytes
}

/// The payload of `frame`'s bytes, after checking the magic, version, length and checksum.
pub(crate) fn unframe<'b>(
    magic: &[u8; 8],
    version: u32,
    bytes: &'b [u8],
) -> Result<&'b [u8], String> {
    if bytes.len() < HEADER_LEN {
        return Err(format!(
            "{} bytes, shorter than the {HEADER_LEN}-byte header (torn write)",
            bytes.len()
        ));
    }
    if &bytes[..8] != magic {
        return Err(format!(
            "not a cgdem {} file (no {} magic)",
            if magic == MAGIC { "restart" } else { "state" },
            String::from_utf8_lossy(magic)
        ));
    }
    let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"));
    let found = word(8);
    if found != version {
        return Err(format!(
            "format version {found}, this cgdem reads version {version}"
        ));
    }
    if bytes[24..HEADER_LEN] != [0; 8] {
        return Err("reserved header bytes are not zero: the file is corrupt".into());
    }
    let len = u64::from_le_bytes(bytes[12..20].try_into().expect("8 bytes"));
    let payload = &bytes[HEADER_LEN..];
    if payload.len() as u64 != len {
        return Err(format!(
            "payload of {} bytes, the header says {len} (torn or truncated)",
            payload.len()
        ));
    }
    let stored = word(20);
    let actual = crc32fast::hash(payload);
    if stored != actual {
        return Err(format!(
            "checksum mismatch (CRC-32 {actual:08x}, the header says {stored:08x}): the file is corrupt"
        ));
    }
    Ok(payload)
}

/// Writes `restart` into `dir` atomically, keeping the previous file as
/// `restart.prev.cgr` until the new one is complete and synced.
pub fn write(dir: &Path, restart: &Restart) -> std::io::Result<PathBuf> {
    let path = dir.join(RESTART_FILE);
    let tmp = dir.join(format!("{RESTART_FILE}.tmp"));
    let written = (|| {
        let mut file = std::fs::File::create(&tmp)?;
        file.write_all(&to_bytes(restart))?;
        file.sync_all()
    })();
    if let Err(e) = written {
        let _ = std::fs::remove_file(&tmp);
        return Err(e);
    }
    if path.exists() {
        std::fs::rename(&path, dir.join(PREVIOUS_RESTART_FILE))?;
    }
    std::fs::rename(&tmp, &path)?;
    // The renames themselves reach the disk with the directory.
    if let Ok(d) = std::fs::File::open(dir) {
        let _ = d.sync_all();
    }
    Ok(path)
}

/// Removes the restart files of an earlier run in `dir` (a fresh run starts its own).
pub fn remove(dir: &Path) -> std::io::Result<()> {
    for name in [RESTART_FILE, PREVIOUS_RESTART_FILE] {
        match std::fs::remove_file(dir.join(name)) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => return Err(e),
            _ => {}
        }
    }
    Ok(())
}

/// Reads the newest usable restart file of `dir`: `restart.cgr`, else `restart.prev.cgr`
/// (with a warning naming the file refused and why); an error naming both when neither is
/// usable.
pub fn read_latest(dir: &Path) -> Result<RestartLoaded, String> {
    let mut warnings = Vec::new();
    let mut reasons = Vec::new();
    for name in [RESTART_FILE, PREVIOUS_RESTART_FILE] {
        let path = dir.join(name);
        let result = std::fs::read(&path)
            .map_err(|e| e.to_string())
            .and_then(|bytes| from_bytes(&bytes));
        match result {
            Ok(restart) => {
                return Ok(RestartLoaded {
                    restart,
                    path,
                    warnings,
                })
            }
            Err(e) => {
                if name == RESTART_FILE {
                    warnings.push(format!(
                        "{}: not usable ({e}); using {PREVIOUS_RESTART_FILE}",
                        path.display()
                    ));
                }
                reasons.push(format!("{}: {e}", path.display()));
            }
        }
    }
    Err(format!(
        "no usable restart file in {}: {}",
        dir.display(),
        reasons.join("; ")
    ))
}

/// The command line of `cgdem run` that a restart file stores (as JSON in
/// [`Restart::invocation`]), to rebuild the same scene on `--resume`; the scene's digest is
/// checked against the stored one.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunInvocation {
    /// Absolute, so a resume from another directory finds it.
    pub case: PathBuf,
    pub lambda: u32,
    pub cg_rule: CoarseGrainRule,
    pub seed: Option<u64>,
    pub set: Vec<String>,
    pub variant: Option<String>,
    pub force_dt: bool,
    pub keep_going: bool,
    /// `--grid` and `--balance` as given (absent in files of runs without them).
    #[serde(default)]
    pub grid: Option<String>,
    #[serde(default)]
    pub balance: Option<String>,
}

/// What a run continues from: the command line that rebuilds its scene and, with
/// `--resume`, the restart file it goes on from.
pub type Resumed = (RunInvocation, Option<Arc<RestartLoaded>>);

impl RunInvocation {
    /// What rebuilds the scene of `cgdem run`: `given` (this command line), or, with
    /// `--resume DIR` and no scene file (`case_given` false), the command line the newest
    /// usable restart file of DIR stored; with the restart file to go on from.
    pub fn resolve(
        given: RunInvocation,
        case_given: bool,
        resume: Option<&Path>,
    ) -> Result<Resumed, String> {
        let loaded = resume.map(read_latest).transpose()?;
        let Some(loaded) = loaded else {
            return Ok((given, None));
        };
        if case_given {
            return Ok((given, Some(Arc::new(loaded))));
        }
        let stored = serde_json::from_str(&loaded.restart.invocation).map_err(|e| {
            format!(
                "{}: the stored command line does not decode: {e}",
                loaded.path.display()
            )
        })?;
        Ok((stored, Some(Arc::new(loaded))))
    }

    /// The grid and balance the run steps on: each as given, or, when not given, as this
    /// (resumed) command line stored it (the balance applies to the scene's own grid too, so
    /// a run resumed without `--balance` goes on as it started), else the scene's grid and
    /// the default balance; with the command line naming them, so that the restart files
    /// the run writes from now on name what it runs on. The error names the stored value
    /// that does not parse.
    pub fn with_grid(
        self,
        grid: Option<GridSpec>,
        balance: Option<BalanceSpec>,
    ) -> Result<(RunInvocation, Option<GridSpec>, BalanceSpec), String> {
        let stored = |e: String| format!("the stored --grid/--balance: {e}");
        let grid = match grid {
            Some(g) => Some(g),
            None => self
                .grid
                .as_deref()
                .map(str::parse)
                .transpose()
                .map_err(stored)?,
        };
        let balance = match balance {
            Some(b) => Some(b),
            None => self
                .balance
                .as_deref()
                .map(str::parse)
                .transpose()
                .map_err(stored)?,
        };
        let invocation = RunInvocation {
            grid: grid.map(|g| g.to_string()),
            balance: balance.map(|b| b.to_string()),
            ..self
        };
        Ok((invocation, grid, balance.unwrap_or_default()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Restart {
        Restart {
            invocation: "case.toml".into(),
            scene_digest: "abc".into(),
            laws: "L W".into(),
            checkpoint_every: 0.1,
            position: Position {
                stage: 1,
                within: Some((7, 0.5)),
            },
            world: vec![1, 2, 3, 4, 5],
            driver: DriverState {
                refilled: 3,
                particle_steps: 99,
                stages: Vec::new(),
                guard_counts: vec![(GuardKind::Overlap, 2)],
                refills: vec![(0, 10, 1)],
                next_checkpoint: 0.25,
                warnings: vec!["w".into()],
                n_inserted: 10,
                n_body_particles: 0,
                wall_s: 12.5,
            },
            observers: vec![vec![9; 17]],
        }
    }

    #[test]
    fn round_trip_and_every_flipped_byte_is_refused() {
        let bytes = to_bytes(&sample());
        let back = from_bytes(&bytes).unwrap();
        assert_eq!(back.position, sample().position);
        assert_eq!(back.world, sample().world);
        for k in 0..bytes.len() {
            let mut bad = bytes.clone();
            bad[k] ^= 0x10;
            assert!(from_bytes(&bad).is_err(), "flipped byte {k} accepted");
        }
        for n in 0..bytes.len() {
            assert!(
                from_bytes(&bytes[..n]).is_err(),
                "truncated to {n} accepted"
            );
        }
    }

    #[test]
    fn falls_back_to_the_previous_file_and_names_the_bad_one() {
        let dir = std::env::temp_dir().join(format!("cgdem-restart-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        remove(&dir).unwrap();
        assert!(read_latest(&dir).unwrap_err().contains(RESTART_FILE));
        let mut first = sample();
        first.driver.refilled = 1;
        write(&dir, &first).unwrap();
        write(&dir, &sample()).unwrap();
        assert_eq!(read_latest(&dir).unwrap().restart.driver.refilled, 3);
        // Truncate the newest: the previous one is used, with a warning naming the file.
        let path = dir.join(RESTART_FILE);
        let bytes = std::fs::read(&path).unwrap();
        std::fs::write(&path, &bytes[..bytes.len() - 3]).unwrap();
        let loaded = read_latest(&dir).unwrap();
        assert_eq!(loaded.restart.driver.refilled, 1);
        assert!(
            loaded.warnings[0].contains("restart.cgr"),
            "{:?}",
            loaded.warnings
        );
        // Both bad: an error naming both.
        let prev = dir.join(PREVIOUS_RESTART_FILE);
        let mut bytes = std::fs::read(&prev).unwrap();
        bytes[40] ^= 1;
        std::fs::write(&prev, &bytes).unwrap();
        let err = read_latest(&dir).unwrap_err();
        assert!(
            err.contains("restart.cgr")
                && err.contains("restart.prev.cgr")
                && err.contains("checksum"),
            "{err}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    fn invocation(grid: Option<&str>, balance: Option<&str>) -> RunInvocation {
        RunInvocation {
            case: PathBuf::from("/cases/heap.toml"),
            lambda: 2,
            cg_rule: CoarseGrainRule::RelativeOverlap,
            seed: None,
            set: Vec::new(),
            variant: None,
            force_dt: false,
            keep_going: false,
            grid: grid.map(str::to_string),
            balance: balance.map(str::to_string),
        }
    }

    #[test]
    fn a_resumed_run_keeps_its_stored_grid_unless_given_another() {
        let stored = invocation(Some("2x1x1"), Some("1.2"));
        let (kept, grid, balance) = stored.clone().with_grid(None, None).unwrap();
        assert_eq!(grid, Some("2x1x1".parse().unwrap()));
        assert_eq!(balance, "1.2".parse().unwrap());
        assert_eq!(kept, stored);
        // Another grid: the stored one is replaced, in the command line too.
        let other: GridSpec = "1x2x1".parse().unwrap();
        let (moved, grid, balance) = stored.clone().with_grid(Some(other), None).unwrap();
        assert_eq!(grid, Some(other));
        assert_eq!(balance, "1.2".parse().unwrap());
        assert_eq!(moved.grid.as_deref(), Some("1x2x1"));
        // Another balance: the stored one is replaced.
        let (_, _, balance) = stored.with_grid(None, Some(BalanceSpec::Off)).unwrap();
        assert_eq!(balance, BalanceSpec::Off);
        // No grid given or stored: none, and none recorded.
        let (plain, grid, balance) = invocation(None, None).with_grid(None, None).unwrap();
        assert_eq!((grid, plain.grid, plain.balance), (None, None, None));
        assert_eq!(balance, BalanceSpec::default());
    }

    #[test]
    fn a_balance_given_without_a_grid_is_stored_and_resumed() {
        // `cgdem run case.toml --balance off`: the scene's own grid, planes never moved.
        let (given, grid, balance) = invocation(None, None)
            .with_grid(None, Some(BalanceSpec::Off))
            .unwrap();
        assert_eq!((grid, balance), (None, BalanceSpec::Off));
        assert_eq!(given.balance.as_deref(), Some("off"));
        // `cgdem run --resume DIR` with no --balance: the stored one, not the default.
        let (resumed, _, balance) = given.clone().with_grid(None, None).unwrap();
        assert_eq!(balance, BalanceSpec::Off);
        assert_eq!(resumed, given);
    }

    #[test]
    fn a_stored_grid_that_does_not_parse_is_named() {
        let err = invocation(Some("2y1"), None)
            .with_grid(None, None)
            .unwrap_err();
        assert!(err.starts_with("the stored --grid/--balance:"), "{err}");
        let err = invocation(Some("2x1x1"), Some("0.5"))
            .with_grid(None, None)
            .unwrap_err();
        assert!(err.starts_with("the stored --grid/--balance:"), "{err}");
        let err = invocation(None, Some("0.5"))
            .with_grid(None, None)
            .unwrap_err();
        assert!(err.starts_with("the stored --grid/--balance:"), "{err}");
    }

    #[test]
    fn resolve_takes_the_stored_command_line_only_without_a_scene_file() {
        let dir = std::env::temp_dir().join(format!("cgdem-resolve-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let stored = invocation(Some("2x1x1"), Some("1.1"));
        let mut restart = sample();
        restart.invocation = serde_json::to_string(&stored).unwrap();
        write(&dir, &restart).unwrap();
        let given = invocation(None, None);
        let (inv, loaded) = RunInvocation::resolve(given.clone(), false, Some(&dir)).unwrap();
        assert_eq!((inv, loaded.is_some()), (stored, true));
        let (inv, loaded) = RunInvocation::resolve(given.clone(), true, Some(&dir)).unwrap();
        assert_eq!((inv, loaded.is_some()), (given.clone(), true));
        let (inv, loaded) = RunInvocation::resolve(given.clone(), false, None).unwrap();
        assert_eq!((inv, loaded.is_none()), (given, true));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
