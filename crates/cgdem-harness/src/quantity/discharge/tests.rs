use std::fmt::Write as _;
use std::path::Path;

use super::*;

/// A steady discharge at `rate` from `start` on, sampled every `dt` up to `end`, with a
/// deterministic ripple of amplitude `ripple` kg on the mass.
fn steady(rate: f64, start: f64, dt: f64, end: f64, ripple: f64) -> DischargeSeries {
    let n = (end / dt).round() as usize;
    let time_s: Vec<f64> = (0..=n).map(|i| i as f64 * dt).collect();
    let mass_kg = time_s
        .iter()
        .enumerate()
        .map(|(i, &t)| rate * (t - start).max(0.0) + ripple * ((i * i % 7) as f64 - 3.0))
        .collect();
    DischargeSeries { time_s, mass_kg }
}

#[test]
fn a_steady_discharge_gives_its_rate_and_no_error_without_noise() {
    let r = discharge_rate(&steady(0.7, 0.05, 0.01, 0.6, 0.0), 0.1, 5).unwrap();
    assert!((r.rate_kg_s - 0.7).abs() < 1e-12, "{r:?}");
    assert!(r.std_error_kg_s < 1e-12);
    assert_eq!(r.window_s, [0.1, 0.6]);
    assert_eq!(r.block_rates_kg_s.len(), 5);
    assert!(!r.drifts);
}

#[test]
fn the_start_up_before_the_window_does_not_bias_the_rate() {
    // Flow begins at 0.08 s: a window from 0 would see a lower slope.
    let s = steady(2.0, 0.08, 0.01, 0.6, 0.0);
    assert!((discharge_rate(&s, 0.1, 5).unwrap().rate_kg_s - 2.0).abs() < 1e-9);
    assert!(discharge_rate(&s, 0.0, 5).unwrap().rate_kg_s < 1.95);
}

#[test]
fn the_standard_error_is_the_block_rates_spread_over_root_blocks() {
    let s = steady(1.0, 0.0, 0.01, 0.5, 0.002);
    let r = discharge_rate(&s, 0.0, 5).unwrap();
    let mean = r.block_rates_kg_s.iter().sum::<f64>() / 5.0;
    let sd = (r
        .block_rates_kg_s
        .iter()
        .map(|b| (b - mean).powi(2))
        .sum::<f64>()
        / 4.0)
        .sqrt();
    assert!(sd > 0.0);
    assert!((r.std_error_kg_s - sd / 5f64.sqrt()).abs() < 1e-12);
    // The blocks' mean is the window's end-to-end rate.
    let end_to_end = (s.mass_kg[50] - s.mass_kg[0]) / 0.5;
    assert!((mean - end_to_end).abs() < 1e-12);
}

#[test]
fn a_rate_falling_through_the_window_is_flagged_as_a_drift() {
    // Mass m = a t - b t^2: the rate falls from 1.0 to 0.5 kg/s over the window.
    let time_s: Vec<f64> = (0..=50).map(|i| i as f64 * 0.01).collect();
    let mass_kg = time_s.iter().map(|t| t - 0.5 * t * t).collect();
    let mut s = DischargeSeries { time_s, mass_kg };
    // A little noise so the drift has an error to be judged against.
    for (i, m) in s.mass_kg.iter_mut().enumerate() {
        *m += 1e-4 * ((i * 3 % 7) as f64 - 3.0);
    }
    let r = discharge_rate(&s, 0.0, 5).unwrap();
    assert!(r.drifts && r.drift_kg_s < -0.3, "{r:?}");
    let steady_run = discharge_rate(&steady(1.0, 0.0, 0.01, 0.5, 1e-4), 0.0, 5).unwrap();
    assert!(!steady_run.drifts, "{steady_run:?}");
}

#[test]
fn too_short_a_window_or_too_few_blocks_is_refused_with_the_reason() {
    let s = steady(1.0, 0.0, 0.01, 0.12, 0.0);
    let e = discharge_rate(&s, 0.1, 5).unwrap_err();
    assert!(e.contains("5 blocks need at least 6"), "{e}");
    assert!(discharge_rate(&s, 0.0, 1)
        .unwrap_err()
        .contains("at least 2"));
}

#[test]
fn beverloo_c_inverts_the_law_and_k_free_recovers_both_constants() {
    let (rho, d) = (1500.0, 0.004);
    let w40 = beverloo_rate(0.6, rho, 0.04, d, 1.5).unwrap();
    let w60 = beverloo_rate(0.6, rho, 0.06, d, 1.5).unwrap();
    // 0.6 x 1500 x sqrt(9.81) x 0.034^2.5
    assert!((w40 - 0.6 * 1500.0 * 9.81f64.sqrt() * 0.034f64.powf(2.5)).abs() < 1e-12);
    let (c, se) = beverloo_c(w40, 0.01, rho, 0.04, d, 1.5).unwrap();
    assert!((c - 0.6).abs() < 1e-12 && (se / c - 0.01 / w40).abs() < 1e-12);
    let (c, k) = fit_c_and_k((0.04, w40), (0.06, w60), d, rho).unwrap();
    assert!((c - 0.6).abs() < 1e-9 && (k - 1.5).abs() < 1e-9, "{c} {k}");
    // With k = 2.5 the same rates need another C.
    let (c, k) = fit_c_and_k(
        (0.04, beverloo_rate(0.5, rho, 0.04, d, 2.5).unwrap()),
        (0.06, beverloo_rate(0.5, rho, 0.06, d, 2.5).unwrap()),
        d,
        rho,
    )
    .unwrap();
    assert!((c - 0.5).abs() < 1e-9 && (k - 2.5).abs() < 1e-9);
    assert!(beverloo_rate(0.58, rho, 0.005, d, 1.5).is_none());
}

#[test]
fn combined_c_weights_by_inverse_variance_and_reports_disagreement() {
    let (c, se, chi2) = combined_c(&[(0.6, 0.01), (0.6, 0.02)]).unwrap();
    assert!((c - 0.6).abs() < 1e-12 && chi2 < 1e-12);
    assert!((se - (1.0f64 / (1e4 + 2.5e3)).sqrt()).abs() < 1e-12);
    let (c, _, chi2) = combined_c(&[(0.5, 0.01), (0.7, 0.01)]).unwrap();
    assert!((c - 0.6).abs() < 1e-12 && (chi2 - 200.0).abs() < 1e-9);
    assert!(combined_c(&[(0.5, 0.0)]).is_none());
}

#[test]
fn bulk_density_counts_the_grains_centred_in_the_box() {
    let grains = [
        ([0.5, 0.5, 0.5], 2.0),
        ([0.1, 0.9, 0.2], 3.0),
        ([1.5, 0.5, 0.5], 7.0),
    ];
    let rho = bulk_density(grains, [0.0; 3], [1.0, 1.0, 0.5]);
    assert!((rho - 3.0 / 0.5).abs() < 1e-12);
}

#[test]
fn the_series_counts_grains_gone_since_the_gate_opened() {
    let dir = std::env::temp_dir().join(format!("cgdem-silo-series-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("timeseries.csv"),
        "time_s,stage,kinetic_energy_j,kinetic_energy_per_mass_j_kg,n_particles\n\
         0.29,fill,0,0,1000\n0.30,fill,0,0,1000\n0.31,discharge,0,0,990\n0.32,discharge,0,0,970\n",
    )
    .unwrap();
    let s = discharge_series(&dir, "discharge", 0.30, 0.5).unwrap();
    let t: Vec<f64> = s.time_s.iter().map(|t| (t * 1e6).round() / 1e6).collect();
    assert_eq!(t, [0.0, 0.01, 0.02]);
    assert_eq!(s.mass_kg, [0.0, 5.0, 15.0]);
    let e = discharge_series(&dir, "drain", 0.30, 0.5).unwrap_err();
    assert!(
        e.contains("timeseries.csv") && e.contains("no row of stage `drain`"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_suite_case_with_a_bad_discharge_table_names_the_field() {
    crate::at_repo_root();
    let base = "[[case]]\nfile = \"validation/cases/silo_reduced.toml\"\ncodes = [\"cgdem\"]\nlambdas = [1]\nseeds = [1]\n";
    let table = |blocks: u32, d0: f64| {
        format!("{base}discharge = {{ stage = \"discharge\", orifice_diameter = {d0}, discard = 0.1, blocks = {blocks}, bulk_lo = [-0.028, -0.028, 0.03], bulk_hi = [0.028, 0.028, 0.07] }}\n")
    };
    let suite = crate::suite::Suite::parse(
        &format!("name = \"s\"\ndescription = \"d\"\n{}", table(5, 0.04)),
        Path::new("s.toml"),
    )
    .unwrap();
    let d = suite.cases[0].discharge.as_ref().unwrap();
    assert_eq!((d.blocks, d.orifice_diameter_m), (5, 0.04));
    for (text, field) in [
        (table(1, 0.04), "discharge.blocks"),
        (table(5, -0.04), "discharge.orifice_diameter"),
    ] {
        let e = crate::suite::Suite::parse(
            &format!("name = \"s\"\ndescription = \"d\"\n{text}"),
            Path::new("s.toml"),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("s.toml") && e.contains(field), "{e}");
    }
}

#[test]
fn cgdems_bulk_density_comes_from_the_data_file_it_writes_at_the_fills_end() {
    use cgdem_core::math::Vec3;
    use cgdem_core::particles::Particles;
    let dir = std::env::temp_dir().join(format!("cgdem-silo-data-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // Two grains of d = 4 mm, 2500 kg/m3 in the unit-volume box, one outside it.
    let grain = 2500.0 * std::f64::consts::PI / 6.0 * 0.004f64.powi(3);
    let mut p = Particles::new(false);
    for z in [0.25, 0.5, 1.5] {
        p.push(0, Vec3::new(0.5, 0.5, z), 0.002, grain);
    }
    let path = dir.join("stage_fill_end.data");
    let text = cgdem_core::lammps_data::data_text(
        "t",
        Vec3::ZERO,
        Vec3::splat(2.0),
        &p,
        &[0.004],
        &[2500.0],
        1,
    );
    std::fs::write(&path, text).unwrap();
    let rho = data_bulk_density(&path, [0.0; 3], [1.0; 3]).unwrap();
    assert!((rho - 2.0 * grain).abs() < 1e-12 * grain, "{rho}");
    let e = data_bulk_density(&dir.join("none.data"), [0.0; 3], [1.0; 3]);
    assert!(e.unwrap_err().contains("none.data"));
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A measured run of `code` with `rate` +- `se` kg/s.
fn measured(code: crate::code::Code, rate: f64, se: f64) -> SiloRun {
    SiloRun {
        code,
        lambda: 1,
        seed: 1,
        dir: std::path::PathBuf::new(),
        grain_diameter_m: 0.004,
        series: None,
        rate: Some(DischargeRate {
            rate_kg_s: rate,
            std_error_kg_s: se,
            window_s: [0.1, 0.6],
            block_rates_kg_s: vec![rate; 5],
            drift_kg_s: 0.0,
            drifts: false,
        }),
        bulk_density: None,
        c_fixed_k: None,
        problem: None,
        bulk_density_problem: None,
    }
}

#[test]
fn cgdem_outside_the_reference_codes_spread_fails_its_criterion_unless_declared() {
    use crate::code::Code::{Cgdem, Lammps, Liggghts};
    use crate::verdict::{KnownDifference, Verdict};
    // The reduced suite's 60 mm rates (reports/silo/NOTE.md): within.
    let within = [
        measured(Cgdem, 2.0116, 0.0122),
        measured(Liggghts, 2.0110, 0.0197),
        measured(Lammps, 1.9951, 0.0142),
    ];
    let (c, _) = rate_criterion(&within, &[]).unwrap();
    assert_eq!((c.verdict, c.value), (Verdict::Pass, 0.0), "{c:?}");
    // Its 40 mm rates: cgdem 0.6773 - 2 x 0.0022 = 0.6729 above the spread's top, LAMMPS's
    // 0.6597 + 2 x 0.0044 = 0.6685, by 0.0044 kg/s of the reference codes' mean 0.65325.
    let outside = [
        measured(Cgdem, 0.6773, 0.0022),
        measured(Liggghts, 0.6468, 0.0058),
        measured(Lammps, 0.6597, 0.0044),
    ];
    let (c, text) = rate_criterion(&outside, &[]).unwrap();
    assert_eq!(c.verdict, Verdict::Fail);
    assert!((c.value - 0.0044 / 0.65325).abs() < 1e-9, "{c:?}");
    assert!(text.contains("outside"), "{text}");
    // A declared difference holds it in its band (amber); one whose band it leaves does not.
    let declared = |band: [f64; 2]| KnownDifference {
        comparison: COMPARISON.into(),
        criterion: CRITERION.into(),
        reason: "test".into(),
        evidence: "reports/silo/NOTE.md".into(),
        band,
    };
    let (c, _) = rate_criterion(&outside, &[declared([0.0, 0.01])]).unwrap();
    assert_eq!(c.verdict, Verdict::KnownDifference);
    let (c, _) = rate_criterion(&outside, &[declared([0.0, 0.005])]).unwrap();
    assert_eq!(c.verdict, Verdict::Fail);
    // No reference rate: nothing to compare.
    assert!(rate_criterion(&outside[..1], &[]).is_none());
}

#[test]
fn a_reference_run_whose_trajectory_is_gone_keeps_its_rate_and_says_why_it_has_no_density() {
    // The nightly deletes the dumps after its report; a report rebuilt from the night
    // (`--reuse`) must still judge the rates, which come from timeseries.csv alone.
    crate::at_repo_root();
    let dir = std::env::temp_dir().join(format!("cgdem-silo-no-dump-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // A LIGGGHTS run's summary as the silo suite wrote it (the gate opened at 0.25 s).
    std::fs::copy(
        "reports/silo/suite/runs/silo_reduced/liggghts-lambda1-seed1/summary.json",
        dir.join("summary.json"),
    )
    .unwrap();
    // 100 grains leave every 0.01 s from the gate's opening.
    let mut csv = String::from("time_s,stage,n_particles\n0.24,fill,24000\n0.25,fill,24000\n");
    for k in 1..=60 {
        let _ = writeln!(
            csv,
            "{},discharge,{}",
            0.25 + 0.01 * k as f64,
            24000 - 100 * k
        );
    }
    std::fs::write(dir.join("timeseries.csv"), csv).unwrap();
    let suite = crate::suite::Suite::parse(
        "name = \"s\"\ndescription = \"d\"\n[[case]]\nfile = \"validation/cases/silo_reduced.toml\"\ncodes = [\"liggghts\"]\nlambdas = [1]\nseeds = [1]\ndischarge = { stage = \"discharge\", orifice_diameter = 0.04, discard = 0.1, blocks = 5, bulk_lo = [-0.028, -0.028, 0.03], bulk_hi = [0.028, 0.028, 0.07] }\n",
        Path::new("s.toml"),
    )
    .unwrap();
    let settings = suite.cases[0].discharge.as_ref().unwrap();
    let scene =
        cgdem_core::scene::Scene::load(Path::new("validation/cases/silo_reduced.toml")).unwrap();
    let record = crate::runs::RunRecord::ok(
        "silo_reduced".into(),
        crate::code::Code::Liggghts,
        1,
        cgdem_core::scene::CoarseGrainRule::RelativeOverlap,
        1,
        dir.clone(),
    );
    let runs = measure_runs(&scene, settings, &[record]);
    let run = &runs[0];
    let grain = 2500.0 * std::f64::consts::PI / 6.0 * 0.004f64.powi(3);
    let rate = run.rate.as_ref().expect("the rate stands without the dump");
    assert!(
        (rate.rate_kg_s - 100.0 * grain / 0.01).abs() < 1e-9,
        "{rate:?}"
    );
    assert!(run.problem.is_none() && run.bulk_density.is_none() && run.c_fixed_k.is_none());
    let why = run.bulk_density_problem.as_deref().unwrap();
    assert!(
        why.starts_with("no bulk density") && why.contains("dump"),
        "{why}"
    );
    let verdict = cgdem_verdict(&[
        measured(crate::code::Code::Cgdem, rate.rate_kg_s, 0.001),
        run.clone(),
    ]);
    assert_eq!(verdict.map(|v| v.gap), Some(0.0));
    std::fs::remove_dir_all(&dir).unwrap();
}
