//! What the bench measured: medians over the repetitions, parallel efficiency, and the
//! ratios of adjacent runs (cgdem over each other code, cgdem's ranks over its threads).

use std::collections::BTreeMap;

use super::{label, BenchFastest, BenchMedian, BenchRatio, BenchRun};
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

/// What makes a row of the tables beside the case and worker count: the code, a reference
/// build, MPI ranks and OpenMP threads.
type RowKey = (Code, Option<String>, Option<usize>, Option<usize>);

fn row_key(r: &BenchRun) -> RowKey {
    (r.code, r.build.clone(), r.ranks, r.openmp_threads)
}

/// cgdem on threads.
const CGDEM: RowKey = (Code::Cgdem, None, None, None);

fn row_label(key: &RowKey) -> String {
    label(key.0, key.1.as_deref(), key.2, key.3)
}

pub(super) fn medians(runs: &[BenchRun]) -> Vec<BenchMedian> {
    let mut groups: BTreeMap<(String, RowKey, usize), Vec<Real>> = BTreeMap::new();
    for r in runs {
        if let Some(v) = r.particle_steps_per_s {
            groups
                .entry((r.case.clone(), row_key(r), r.threads))
                .or_default()
                .push(v);
        }
    }
    let mut out: Vec<BenchMedian> = groups
        .iter()
        .map(|((case, (code, build, ranks, omp), threads), values)| {
            let mut v = values.clone();
            BenchMedian {
                case: case.clone(),
                code: *code,
                build: build.clone(),
                threads: *threads,
                ranks: *ranks,
                openmp_threads: *omp,
                runs: v.len(),
                median_particle_steps_per_s: median(&mut v),
                min_particle_steps_per_s: v[0],
                max_particle_steps_per_s: v[v.len() - 1],
                parallel_efficiency: None,
            }
        })
        .collect();
    // One worker: cgdem in one process (its ranks are measured against it too), a
    // reference build serial; cgdem's single rank when it ran no single thread.
    type Single = (String, Code, Option<String>, Real);
    let mut singles: Vec<Single> = Vec::new();
    let same = |s: &Single, m: &BenchMedian| s.0 == m.case && s.1 == m.code && s.2 == m.build;
    for m in out.iter().filter(|m| m.threads == 1) {
        let base = m.code != Code::Cgdem || m.ranks.is_none();
        match singles.iter().position(|s| same(s, m)) {
            Some(k) if base => singles[k].3 = m.median_particle_steps_per_s,
            Some(_) => {}
            None => singles.push((
                m.case.clone(),
                m.code,
                m.build.clone(),
                m.median_particle_steps_per_s,
            )),
        }
    }
    for m in &mut out {
        if let Some(s) = singles.iter().find(|s| same(s, m)) {
            m.parallel_efficiency = Some(m.median_particle_steps_per_s / (m.threads as Real * s.3));
        }
    }
    out
}

/// The throughput of one run: `case`, row `key` and workers in repetition `rep`.
fn speed_of(
    runs: &[BenchRun],
    case: &str,
    key: &RowKey,
    threads: usize,
    rep: usize,
) -> Option<Real> {
    runs.iter()
        .find(|r| {
            r.case == case && r.threads == threads && r.repetition == rep && row_key(r) == *key
        })
        .and_then(|r| r.particle_steps_per_s)
}

/// The reference codes' rows of `case` at `threads`, in the order they ran.
fn reference_rows(runs: &[BenchRun], case: &str, threads: usize) -> Vec<RowKey> {
    let mut keys: Vec<RowKey> = Vec::new();
    for r in runs {
        let key = row_key(r);
        if r.case == case && r.threads == threads && r.code != Code::Cgdem && !keys.contains(&key) {
            keys.push(key);
        }
    }
    keys
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

/// Per repetition, cgdem over each reference row (build, ranks or threads) on the same
/// case, and cgdem on each case over cgdem on the first case (cgdem on threads).
pub(super) fn ratios(runs: &[BenchRun], cases: &[String]) -> Vec<BenchRatio> {
    let mut out = Vec::new();
    for (threads, reps) in repetitions_by_workers(runs, |_| true) {
        for case in cases {
            let cgdem = |rep| speed_of(runs, case, &CGDEM, threads, rep);
            for key in reference_rows(runs, case, threads) {
                out.extend(ratio_row(
                    format!("{case} cgdem"),
                    format!("{case} {}", row_label(&key)),
                    threads,
                    &reps,
                    |rep| Some(cgdem(rep)? / speed_of(runs, case, &key, threads, rep)?),
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
                        speed_of(runs, case, &CGDEM, threads, rep)?
                            / speed_of(runs, &cases[0], &CGDEM, threads, rep)?,
                    )
                },
            ));
        }
    }
    out
}

/// Per repetition, cgdem's ranks on each decomposed case (`(case, base)`) over: cgdem on
/// the same case on as many threads, cgdem on the undecomposed base case, and each
/// reference row on the base case, at the same worker count.
pub(super) fn rank_ratios(runs: &[BenchRun], cases: &[(String, String)]) -> Vec<BenchRatio> {
    let mut out = Vec::new();
    let with_ranks = |r: &BenchRun| r.code == Code::Cgdem && r.ranks.is_some();
    for (n, reps) in repetitions_by_workers(runs, with_ranks) {
        let ranks_key: RowKey = (Code::Cgdem, None, Some(n), None);
        for (case, base) in cases {
            let ranks = |rep| speed_of(runs, case, &ranks_key, n, rep);
            let mut others = vec![(case.as_str(), CGDEM), (base.as_str(), CGDEM)];
            others.extend(
                reference_rows(runs, base, n)
                    .into_iter()
                    .map(|k| (base.as_str(), k)),
            );
            for (other_case, other) in others {
                out.extend(ratio_row(
                    format!("{case} {}", row_label(&ranks_key)),
                    format!("{other_case} {}", row_label(&other)),
                    n,
                    &reps,
                    |rep| Some(ranks(rep)? / speed_of(runs, other_case, &other, n, rep)?),
                ));
            }
        }
    }
    out
}

/// For each case, reference code and worker count: the row with the highest median, and
/// cgdem on threads over it (median of the per-repetition ratios).
pub(super) fn fastest(runs: &[BenchRun]) -> Vec<BenchFastest> {
    let medians = medians(runs);
    let mut out: Vec<BenchFastest> = Vec::new();
    for m in medians.iter().filter(|m| m.code != Code::Cgdem) {
        let faster =
            |f: &BenchFastest| f.case == m.case && f.code == m.code && f.threads == m.threads;
        match out.iter_mut().find(|f| faster(f)) {
            Some(f) if f.median_particle_steps_per_s >= m.median_particle_steps_per_s => {}
            Some(f) => *f = fastest_row(runs, m),
            None => out.push(fastest_row(runs, m)),
        }
    }
    out
}

fn fastest_row(runs: &[BenchRun], m: &BenchMedian) -> BenchFastest {
    let key: RowKey = (m.code, m.build.clone(), m.ranks, m.openmp_threads);
    let reps: Vec<usize> = runs.iter().map(|r| r.repetition).collect();
    let mut ratios: Vec<Real> = (0..=reps.iter().copied().max().unwrap_or(0))
        .filter_map(|rep| {
            Some(
                speed_of(runs, &m.case, &CGDEM, m.threads, rep)?
                    / speed_of(runs, &m.case, &key, m.threads, rep)?,
            )
        })
        .collect();
    BenchFastest {
        case: m.case.clone(),
        code: m.code,
        threads: m.threads,
        row: m.label(),
        median_particle_steps_per_s: m.median_particle_steps_per_s,
        cgdem_over_fastest: (!ratios.is_empty()).then(|| median(&mut ratios)),
    }
}
