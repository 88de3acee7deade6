//! Stored golden numbers of the reference codes (`reference/golden/*.csv`), as LAMMPS keeps its
//! golden force files: the tests compare cgdem with the stored numbers always, and, when the
//! reference code is installed, its live numbers with the stored ones.
//!
//! A file is `case,quantity,code,value` rows after `#` comment lines that say where the numbers
//! come from. `CGDEM_BLESS=1` (with the codes installed) rewrites the rows a test measured live
//! instead of comparing them; the comments are kept.

#![allow(dead_code)] // each test binary uses part of it

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Mutex;

use cgdem_core::io::CsvBuffer;
use cgdem_harness::csv_table::CsvTable;

/// Live reference numbers must match the stored ones to this relative difference: the same
/// version built elsewhere may round differently in the last digits, not in the sixth.
pub const LIVE_TOLERANCE: f64 = 1e-6;

/// Tests of one binary run in parallel; blessing rewrites a shared file.
static WRITE: Mutex<()> = Mutex::new(());

type Key = (String, String, String);

pub struct GoldenFile {
    pub path: PathBuf,
    comments: Vec<String>,
    rows: BTreeMap<Key, f64>,
    /// Rows measured live by this test (written back when blessing).
    live: BTreeMap<Key, f64>,
    drift: Vec<String>,
}

pub fn blessing() -> bool {
    std::env::var_os("CGDEM_BLESS").is_some_and(|v| v == "1")
}

fn parse(path: &std::path::Path, text: &str) -> (Vec<String>, BTreeMap<Key, f64>) {
    // The comments are kept for blessing; the rows are read as CSV by the harness's reader.
    let comments = text
        .lines()
        .filter(|l| l.starts_with('#'))
        .map(String::from)
        .collect();
    let table = CsvTable::parse(path, text.as_bytes()).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        table.header(),
        ["case", "quantity", "code", "value"],
        "{}: header",
        path.display()
    );
    let column = |name: &str| table.column(name).unwrap_or_else(|e| panic!("{e}"));
    let (case, quantity, code, value) = (
        column("case"),
        column("quantity"),
        column("code"),
        column("value"),
    );
    let mut rows = BTreeMap::new();
    for row in table.rows() {
        let text = |c| row.text(c).unwrap_or_else(|e| panic!("{e}")).to_string();
        let key = (text(case), text(quantity), text(code));
        let value: f64 = row.parse(value).unwrap_or_else(|e| panic!("{e}"));
        assert!(
            rows.insert(key, value).is_none(),
            "{}:{}: duplicate row",
            path.display(),
            row.line()
        );
    }
    (comments, rows)
}

impl GoldenFile {
    /// `reference/golden/<name>`; a missing file is a failure unless blessing.
    pub fn load(name: &str) -> GoldenFile {
        let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("reference/golden")
            .join(name);
        let (comments, rows) = match std::fs::read_to_string(&path) {
            Ok(text) => parse(&path, &text),
            Err(_) if blessing() => (Vec::new(), BTreeMap::new()),
            Err(e) => panic!(
                "{}: {e}; write it with `CGDEM_BLESS=1` and the reference codes installed",
                path.display()
            ),
        };
        GoldenFile {
            path,
            comments,
            rows,
            live: BTreeMap::new(),
            drift: Vec::new(),
        }
    }

    pub fn has(&self, case: &str, quantity: &str, code: &str) -> bool {
        let key = (case.to_string(), quantity.to_string(), code.to_string());
        self.rows.contains_key(&key) || (blessing() && self.live.contains_key(&key))
    }

    /// The stored number; panics naming the file and the row when it is absent.
    pub fn get(&self, case: &str, quantity: &str, code: &str) -> f64 {
        let key = (case.to_string(), quantity.to_string(), code.to_string());
        if let Some(&v) = self.live.get(&key) {
            if blessing() {
                return v;
            }
        }
        *self.rows.get(&key).unwrap_or_else(|| {
            panic!(
                "{}: no row `{case},{quantity},{code}`; write it with `CGDEM_BLESS=1`",
                self.path.display()
            )
        })
    }

    /// A number the installed reference code just produced: compared with the stored one (or
    /// stored, when blessing). Differences are collected and asserted by [`Self::finish`].
    pub fn live(&mut self, case: &str, quantity: &str, code: &str, value: f64) {
        let key = (case.to_string(), quantity.to_string(), code.to_string());
        self.live.insert(key.clone(), value);
        if blessing() {
            return;
        }
        match self.rows.get(&key) {
            None => self.drift.push(format!(
                "no stored row `{case},{quantity},{code}` (live {value:e})"
            )),
            Some(&stored) => {
                let rel = (value - stored).abs() / stored.abs().max(1e-300);
                let both_zero = value == 0.0 && stored == 0.0;
                if !both_zero && (rel.is_nan() || rel > LIVE_TOLERANCE) {
                    self.drift.push(format!(
                        "{case}: {quantity}: {code} live {value:e} vs stored {stored:e} (rel. diff {rel:.3e})"
                    ));
                }
            }
        }
    }

    /// Asserts the live numbers matched the stored ones; when blessing, merges them into the
    /// file on disk instead (re-read under a lock: parallel tests bless different cases).
    pub fn finish(&self) {
        if blessing() {
            if self.live.is_empty() {
                return;
            }
            let _guard = WRITE.lock().unwrap_or_else(|e| e.into_inner());
            let (comments, mut rows) = match std::fs::read_to_string(&self.path) {
                Ok(text) => parse(&self.path, &text),
                Err(_) => (self.comments.clone(), BTreeMap::new()),
            };
            rows.extend(self.live.iter().map(|(k, v)| (k.clone(), *v)));
            let mut text = comments.join("\n");
            if !text.is_empty() {
                text.push('\n');
            }
            let mut table = CsvBuffer::new(["case", "quantity", "code", "value"]);
            for ((case, quantity, code), value) in &rows {
                // `{:e}` is the shortest form that reads back to the same f64.
                table.row([
                    case.clone(),
                    quantity.clone(),
                    code.clone(),
                    format!("{value:e}"),
                ]);
            }
            text.push_str(std::str::from_utf8(table.bytes().unwrap()).unwrap());
            std::fs::create_dir_all(self.path.parent().unwrap()).unwrap();
            std::fs::write(&self.path, text).unwrap();
            println!("blessed {} ({} rows)", self.path.display(), self.live.len());
            return;
        }
        assert!(
            self.drift.is_empty(),
            "the installed reference code no longer gives the stored numbers of {} (update them with `CGDEM_BLESS=1` if the change is understood):\n{}",
            self.path.display(),
            self.drift.join("\n")
        );
    }
}
