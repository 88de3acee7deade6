//! The shell entry points' decisions, with fake binaries in place of cgdem builds: what the
//! speed guard (`scripts/speed-guard.sh`) calls slow. Its timings are scripted here, so the
//! verdicts are exact; that it fires on a real planted slowdown is
//! `scripts/speed-guard-planted.sh` (a benchmark, not a test).

use std::path::{Path, PathBuf};
use std::process::Command;

/// A fake cgdem build at `dir/name`: its k-th `bench` reports `heap[k]` particle-steps/s and
/// its k-th `run` a step loop of `main_s[k]` seconds, in the files the guard reads.
fn fake_build(dir: &Path, name: &str, heap: &[f64], main_s: &[f64]) -> PathBuf {
    let list = |v: &[f64]| {
        v.iter()
            .map(|x| x.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let path = dir.join(name);
    let script = format!(
        r#"#!/usr/bin/env python3
import json, os, sys
heap, main_s = [{heap}], [{main}]
args = sys.argv[1:]
out = args[args.index("--out") + 1]
os.makedirs(out, exist_ok=True)
counter = os.path.join(os.path.dirname(os.path.abspath(__file__)), "{name}." + args[0])
k = int(open(counter).read()) if os.path.exists(counter) else 0
open(counter, "w").write(str(k + 1))
if args[0] == "bench":
    json.dump({{"medians": [{{"median_particle_steps_per_s": heap[k]}}]}}, open(os.path.join(out, "bench.json"), "w"))
else:
    json.dump({{"wall_s": main_s[k]}}, open(os.path.join(out, "summary.json"), "w"))
"#,
        heap = list(heap),
        main = list(main_s),
    );
    std::fs::write(&path, script).unwrap();
    Command::new("chmod").arg("+x").arg(&path).status().unwrap();
    path
}

/// Runs the guard with 3 pairs on the two fakes; its exit code and speed_guard.json.
fn guard(dir: &Path, base: &Path, new: &Path) -> (i32, serde_json::Value) {
    let json = dir.join("speed_guard.json");
    let output = Command::new("bash")
        .arg(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scripts/speed-guard.sh"
        ))
        .args(["--pairs", "3", "--json"])
        .arg(&json)
        .arg(base)
        .arg(new)
        .env("SPEED_GUARD_WORK", dir.join("work"))
        .output()
        .unwrap();
    let code = output.status.code().unwrap();
    assert!(
        code != 2,
        "the guard failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    let value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    (code, value)
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cgdem-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn the_speed_guard_looks_again_before_it_calls_a_dip_that_does_not_repeat_slow() {
    let dir = scratch("guard-dip");
    let base = fake_build(&dir, "base", &[1e7; 6], &[30.0; 6]);
    // Two of the first three main jobs 10% slower (a busy host), then as fast as the base.
    let new = fake_build(
        &dir,
        "new",
        &[1e7; 6],
        &[33.0, 33.0, 30.0, 30.0, 30.0, 30.0],
    );
    let (code, json) = guard(&dir, &base, &new);
    assert_eq!(code, 0, "{json}");
    assert_eq!(json["pairs"], 6, "a second look of as many pairs: {json}");
    assert_eq!(json["second_look_pairs"], 3);
    assert_eq!(json["flagged"], false);
    assert_eq!(json["mainjob_ratio_median"], 1.0);
}

#[test]
fn the_speed_guard_flags_a_slowdown_that_holds_on_the_second_look() {
    let dir = scratch("guard-slow");
    let base = fake_build(&dir, "base", &[1e7; 6], &[30.0; 6]);
    // The heap bench 20% slower in every pair.
    let new = fake_build(&dir, "new", &[8e6; 6], &[30.0; 6]);
    let (code, json) = guard(&dir, &base, &new);
    assert_eq!(code, 1, "{json}");
    assert_eq!(json["pairs"], 6);
    assert_eq!(json["flagged"], true);
    assert!((json["heap_ratio_median"].as_f64().unwrap() - 0.8).abs() < 1e-12);
}

#[test]
fn the_speed_guard_takes_one_look_when_no_median_is_below_the_threshold() {
    let dir = scratch("guard-even");
    let base = fake_build(&dir, "base", &[1e7; 3], &[30.0; 3]);
    // One slow pair of three: the medians stay at 1.
    let new = fake_build(&dir, "new", &[9e6, 1e7, 1e7], &[30.0; 3]);
    let (code, json) = guard(&dir, &base, &new);
    assert_eq!(code, 0, "{json}");
    assert_eq!(json["pairs"], 3);
    assert_eq!(json["second_look_pairs"], 0);
}
