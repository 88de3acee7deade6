//! Generated bad input for the harness's parsers: LAMMPS/LIGGGHTS dumps and logs, and the
//! nightly history (the history file and a night's summary.json). No input may panic; every
//! error names the file and the line (dumps) or line and column (JSON).
//! `cargo test` runs a few cases (64 per parser); `scripts/fuzz.sh` sets PROPTEST_CASES.

use std::path::Path;
use std::sync::atomic::AtomicU64;

use cgdem_harness::decks::dump::parse_dump;
use cgdem_harness::decks::postprocess::log_timing;
use cgdem_harness::history::{flags, night_metrics, parse_history};
use cgdem_harness::stability::LogFindings;
use proptest::prelude::*;

#[path = "../../../tests/support/fuzz_cases.rs"]
mod fuzz_cases;
use fuzz_cases::{config, counted};

const DUMP_FILE: &str = "fuzz/traj.dump";
const HISTORY_FILE: &str = "fuzz/history.json";

static DUMP_ANY: AtomicU64 = AtomicU64::new(0);
static DUMP_MUTATED: AtomicU64 = AtomicU64::new(0);
static LOG: AtomicU64 = AtomicU64::new(0);
static HISTORY: AtomicU64 = AtomicU64::new(0);
static NIGHT: AtomicU64 = AtomicU64::new(0);

/// Tokens that break numbers and headers.
fn bad_token() -> impl Strategy<Value = String> {
    prop_oneof![
        Just("nan".to_string()),
        Just("-inf".to_string()),
        Just("1e400".to_string()),
        Just("-1".to_string()),
        Just("18446744073709551616".to_string()),
        Just("99999999999999999999999".to_string()),
        Just(String::new()),
        Just("ITEM: TIMESTEP".to_string()),
        Just("ITEM: ATOMS".to_string()),
        Just("ITEM: BOX BOUNDS".to_string()),
        "[ -~]{0,12}",
        any::<f64>().prop_map(|v| v.to_string()),
    ]
}

/// A valid dump of `frames` frames of `atoms` atoms (LIGGGHTS's layout: trailing spaces).
fn dump_text(frames: usize, atoms: usize) -> String {
    let mut s = String::new();
    for f in 0..frames {
        s += &format!(
            "ITEM: TIMESTEP\n{}\nITEM: NUMBER OF ATOMS\n{atoms}\nITEM: BOX BOUNDS ff ff pp\n\
             -0.01 0.01\n-0.01 0.01\n0 0.02\nITEM: ATOMS id type x y z vx vy vz radius \n",
            f * 100
        );
        for a in 0..atoms {
            s += &format!(
                "{} 1 {} {} {} 0.5 -0 0 0.001 \n",
                a + 1,
                a as f64 * 1e-3,
                -(a as f64) * 2e-3,
                f as f64 * 1e-4
            );
        }
    }
    s
}

/// A valid dump with tokens replaced, lines dropped or repeated, or cut anywhere.
fn mutated_dump() -> impl Strategy<Value = String> {
    (1usize..4, 0usize..5).prop_flat_map(|(frames, atoms)| {
        let text = dump_text(frames, atoms);
        let lines: Vec<String> = text.lines().map(str::to_string).collect();
        let n = lines.len();
        prop_oneof![
            (0..n, 0usize..12, bad_token()).prop_map({
                let lines = lines.clone();
                move |(k, field, token)| {
                    let mut l = lines.clone();
                    let mut tokens: Vec<String> =
                        l[k].split_whitespace().map(str::to_string).collect();
                    if tokens.is_empty() {
                        tokens.push(token);
                    } else {
                        let i = field % tokens.len();
                        tokens[i] = token;
                    }
                    l[k] = tokens.join(" ");
                    l.join("\n")
                }
            }),
            (0..n, any::<bool>()).prop_map({
                let lines = lines.clone();
                move |(k, duplicate)| {
                    let mut l = lines.clone();
                    if duplicate {
                        let d = l[k].clone();
                        l.insert(k, d);
                    } else {
                        l.remove(k);
                    }
                    l.join("\n")
                }
            }),
            (0..text.len() + 1).prop_map({
                let text = text.clone();
                move |cut| text[..cut].to_string()
            }),
        ]
    })
}

fn check_dump(text: &str) {
    match parse_dump(text, Path::new(DUMP_FILE)) {
        Err(e) => {
            let m = e.to_string();
            assert!(m.starts_with(&format!("{DUMP_FILE}:")), "{m}");
            assert!(e.line >= 1, "no line in: {m}");
        }
        Ok(frames) => {
            for f in &frames {
                for c in &f.columns {
                    assert_eq!(f.column(c).unwrap().len(), f.len(), "ragged column {c}");
                }
            }
        }
    }
}

/// A log of LAMMPS/LIGGGHTS lines, some with broken numbers.
fn log_text() -> impl Strategy<Value = String> {
    let line = prop_oneof![
        Just("Loop time of 1.5 on 2 procs for 1000 steps with 40 atoms".to_string()),
        Just("Per MPI rank memory allocation (min/avg/max) = 5.1 | 5.2 | 5.3 Mbytes".to_string()),
        Just("Memory usage per processor = 4.5 Mbytes".to_string()),
        Just("ERROR: Lost atoms: original 79 current 70 (../thermo.cpp:481)".to_string()),
        Just("ERROR: Lost atoms: original current".to_string()),
        Just("   100   1.5e-3   nan   0.1".to_string()),
        Just("Step Atoms KinEng".to_string()),
        (bad_token(), bad_token(), bad_token(), bad_token()).prop_map(|(a, b, c, d)| {
            format!("Loop time of {a} on {b} procs for {c} steps with {d} atoms")
        }),
        (bad_token(), bad_token())
            .prop_map(|(a, b)| { format!("ERROR: Lost atoms: original {a} current {b}") }),
        (bad_token(), bad_token(), bad_token()).prop_map(|(a, b, c)| format!(
            "Per MPI rank memory (min/avg/max) = {a} | {b} | {c} Mbytes"
        )),
        "[ -~]{0,40}",
    ];
    proptest::collection::vec(line, 0..12).prop_map(|l| l.join("\n"))
}

/// JSON with the history's shape, values that may have the wrong type or be missing.
fn json_value(depth: u32) -> impl Strategy<Value = serde_json::Value> {
    let leaf = prop_oneof![
        Just(serde_json::Value::Null),
        any::<bool>().prop_map(serde_json::Value::from),
        any::<f64>().prop_map(serde_json::Value::from),
        any::<i64>().prop_map(serde_json::Value::from),
        "[a-z_ ]{0,8}".prop_map(serde_json::Value::from),
    ];
    leaf.prop_recursive(depth, 24, 6, |inner| {
        prop_oneof![
            proptest::collection::vec(inner.clone(), 0..4).prop_map(serde_json::Value::from),
            proptest::collection::btree_map(
                prop_oneof![
                    Just("date".to_string()),
                    Just("commit".to_string()),
                    Just("runs".to_string()),
                    Just("metrics".to_string()),
                    Just("comparisons".to_string()),
                    Just("suite".to_string()),
                    Just("value".to_string()),
                    Just("tolerance".to_string()),
                    Just("cases".to_string()),
                    Just("status".to_string()),
                    Just("pass".to_string()),
                    "[a-z_]{1,8}",
                ],
                inner,
                0..5
            )
            .prop_map(|m| serde_json::Value::Object(m.into_iter().collect())),
        ]
    })
}

/// A valid history of one night, then cut or with a value replaced.
fn history_text() -> impl Strategy<Value = String> {
    let valid = r#"[{"date":"2026-11-25","commit":"abc","report":"r","runs":3,"runs_failed":0,"comparisons_failed":1,"metrics":{"m":{"quantity":"angle [deg]","value":1.5,"tolerance":0.5,"relative":false}}}]"#;
    prop_oneof![
        (0..valid.len() + 1).prop_map(move |cut| valid[..cut].to_string()),
        json_value(4).prop_map(|v| v.to_string()),
        json_value(3).prop_map(|v| format!("[{v}]")),
        "[ -~]{0,60}",
    ]
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn dump_parser_takes_any_text(text in "(ITEM: [A-Z ]{0,20}\n|[ -~]{0,30}\n){0,20}") {
        check_dump(&text);
        counted(&DUMP_ANY, "dump (any lines)");
    }

    #[test]
    fn dump_parser_takes_mutated_dumps(text in mutated_dump()) {
        check_dump(&text);
        counted(&DUMP_MUTATED, "dump (mutated LAMMPS/LIGGGHTS dumps)");
    }

    #[test]
    fn log_readers_take_any_log(text in log_text()) {
        let _ = log_timing(&text);
        let _ = LogFindings::of(&text);
        counted(&LOG, "logs (loop time, memory, errors, thermo)");
    }

    #[test]
    fn history_reader_takes_bad_history_files(text in history_text()) {
        match parse_history(&text, Path::new(HISTORY_FILE)) {
            Err(e) => {
                let m = e.to_string();
                assert!(m.starts_with(HISTORY_FILE), "{m}");
                assert!(m.contains("line ") || m.contains("EOF"), "{m}");
            }
            Ok(nights) => {
                for pair in nights.windows(2) {
                    let _ = flags(&pair[0], &pair[1]);
                }
            }
        }
        counted(&HISTORY, "history file");
    }

    #[test]
    fn night_metrics_take_any_summary(value in json_value(4)) {
        let _ = night_metrics(&value);
        counted(&NIGHT, "night summary.json (metrics)");
    }
}
