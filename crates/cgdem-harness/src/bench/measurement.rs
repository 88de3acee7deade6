//! What the bench measured: medians over the repetitions, parallel efficiency, and the
//! ratios of adjacent runs (cgdem over each other code, cgdem's ranks over its threads).

use std::collections::BTreeMap;

use super::{label, BenchMedian, BenchRatio, BenchRun};
use crate::suite::Code;
use cgdem_core::math::{Real, Vec3};
use cgdem_core::particles::Particles;

/// Centre (x, y) of the mobile particles: the heap's axis.
pub(super) fn mobile_centroid(p: &Particles) -> Vec3 {
    let (mut sum, mut n) = (Vec3::ZERO, 0usize);
    for k in (0..p.len()).filter(|&k| !p.is_frozen(k)) {
        sum += p.position[k];
        n += 1;
    }
    if n == 0 {
        Vec3::ZERO
    } else {
        Vec3::new(sum.x / n as Real, sum.y / n as Real, 0.0)
    }
}

pub(super) fn median(values: &mut [Real]) -> Real {
    values.sort_by(|a, b| a.total_cmp(b));
    let n = values.len();
    if n % 2 == 1 {
        values[n / 2]
    } else {
        0.5 * (values[n / 2 - 1] + values[n / 2])
    }
}

pub(super) fn medians(runs: &[BenchRun]) -> Vec<BenchMedian> {
    let mut groups: BTreeMap<(String, Code, usize, Option<usize>), Vec<Real>> = BTreeMap::new();
    for r in runs {
        if let Some(v) = r.particle_steps_per_s {
            groups
                .entry((r.case.clone(), r.code, r.threads, r.ranks))
                .or_default()
                .push(v);
        }
    }
    let mut out: Vec<BenchMedian> = groups
        .iter()
        .map(|((case, code, threads, ranks), values)| {
            let mut v = values.clone();
            BenchMedian {
                case: case.clone(),
                code: *code,
                threads: *threads,
                ranks: *ranks,
                runs: v.len(),
                median_particle_steps_per_s: median(&mut v),
                min_particle_steps_per_s: v[0],
                max_particle_steps_per_s: v[v.len() - 1],
                parallel_efficiency: None,
            }
        })
        .collect();
    // One worker: cgdem in one process (its ranks are measured against it too), a
    // reference code serial; cgdem's single rank when it ran no single thread.
    let mut singles: Vec<(String, Code, Real)> = Vec::new();
    for m in out.iter().filter(|m| m.threads == 1) {
        let base = m.code != Code::Cgdem || m.ranks.is_none();
        let known = singles.iter().position(|s| s.0 == m.case && s.1 == m.code);
        match known {
            Some(k) if base => singles[k].2 = m.median_particle_steps_per_s,
            Some(_) => {}
            None => singles.push((m.case.clone(), m.code, m.median_particle_steps_per_s)),
        }
    }
    for m in &mut out {
        if let Some((_, _, one)) = singles.iter().find(|s| s.0 == m.case && s.1 == m.code) {
            m.parallel_efficiency = Some(m.median_particle_steps_per_s / (m.threads as Real * one));
        }
    }
    out
}

/// The throughput of one run: `case`, `code` and workers in repetition `rep`, cgdem's
/// threaded run unless `cgdem_ranks`.
fn speed_of(
    runs: &[BenchRun],
    (case, code, threads, rep): (&str, Code, usize, usize),
    cgdem_ranks: bool,
) -> Option<Real> {
    runs.iter()
        .find(|r| {
            r.case == case
                && r.code == code
                && r.threads == threads
                && r.repetition == rep
                && (code != Code::Cgdem || r.ranks.is_some() == cgdem_ranks)
        })
        .and_then(|r| r.particle_steps_per_s)
}

/// The worker counts among the runs `include` accepts, each with its repetitions, in order.
fn repetitions_by_workers(
    runs: &[BenchRun],
    include: impl Fn(&BenchRun) -> bool,
) -> Vec<(usize, Vec<usize>)> {
    let mut keys: Vec<(usize, usize)> = runs
        .iter()
        .filter(|r| include(r))
        .map(|r| (r.threads, r.repetition))
        .collect();
    keys.sort();
    keys.dedup();
    let mut out: Vec<(usize, Vec<usize>)> = Vec::new();
    for (workers, rep) in keys {
        match out.last_mut() {
            Some((w, reps)) if *w == workers => reps.push(rep),
            _ => out.push((workers, vec![rep])),
        }
    }
    out
}

/// The row `numerator / denominator` at `workers`: `ratio(rep)` for every repetition that
/// measured both, with their median; None when none did.
fn ratio_row(
    numerator: String,
    denominator: String,
    workers: usize,
    reps: &[usize],
    ratio: impl Fn(usize) -> Option<Real>,
) -> Option<BenchRatio> {
    let per_repetition: Vec<Real> = reps.iter().filter_map(|&rep| ratio(rep)).collect();
    if per_repetition.is_empty() {
        return None;
    }
    let mut sorted = per_repetition.clone();
    Some(BenchRatio {
        numerator,
        denominator,
        threads: workers,
        median: median(&mut sorted),
        per_repetition,
    })
}

/// Per repetition, cgdem over each other code on the same case, and cgdem on each case over
/// cgdem on the first case (cgdem on threads).
pub(super) fn ratios(runs: &[BenchRun], cases: &[String]) -> Vec<BenchRatio> {
    let speed = |case: &str, code: Code, threads: usize, rep: usize| {
        speed_of(runs, (case, code, threads, rep), false)
    };
    let mut out = Vec::new();
    for (threads, reps) in repetitions_by_workers(runs, |_| true) {
        for case in cases {
            for other in [Code::Liggghts, Code::Lammps] {
                out.extend(ratio_row(
                    format!("{case} cgdem"),
                    format!("{case} {}", other.name()),
                    threads,
                    &reps,
                    |rep| {
                        Some(
                            speed(case, Code::Cgdem, threads, rep)?
                                / speed(case, other, threads, rep)?,
                        )
                    },
                ));
            }
        }
        for case in cases.iter().skip(1) {
            out.extend(ratio_row(
                format!("{case} cgdem"),
                format!("{} cgdem", cases[0]),
                threads,
                &reps,
                |rep| {
                    Some(
                        speed(case, Code::Cgdem, threads, rep)?
                            / speed(&cases[0], Code::Cgdem, threads, rep)?,
                    )
                },
            ));
        }
    }
    out
}

/// Per repetition, cgdem's ranks on each decomposed case (`(case, base)`) over: cgdem on
/// the same case on as many threads, cgdem on the undecomposed base case, and each
/// reference code on the base case, at the same worker count.
pub(super) fn rank_ratios(runs: &[BenchRun], cases: &[(String, String)]) -> Vec<BenchRatio> {
    let mut out = Vec::new();
    let with_ranks = |r: &BenchRun| r.code == Code::Cgdem && r.ranks.is_some();
    for (n, reps) in repetitions_by_workers(runs, with_ranks) {
        for (case, base) in cases {
            let ranks = |rep| speed_of(runs, (case.as_str(), Code::Cgdem, n, rep), true);
            let others = [
                (case.as_str(), Code::Cgdem),
                (base.as_str(), Code::Cgdem),
                (base.as_str(), Code::Liggghts),
                (base.as_str(), Code::Lammps),
            ];
            for (other_case, other) in others {
                out.extend(ratio_row(
                    format!("{case} {}", label(Code::Cgdem, Some(n))),
                    format!("{other_case} {}", other.name()),
                    n,
                    &reps,
                    |rep| Some(ranks(rep)? / speed_of(runs, (other_case, other, n, rep), false)?),
                ));
            }
        }
    }
    out
}
