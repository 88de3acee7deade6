use std::path::{Path, PathBuf};

use super::measurement::floor;
use super::runs::own_rule_sweeps;
use super::*;
use crate::code::Code;
use crate::quantity::flow::FlowSeries;
use crate::runs::Outcome;
use crate::suite::Suite;
use cgdem_core::coarse_graining::CoarseGrainRule;

#[test]
fn the_pareto_front_keeps_only_points_no_cheaper_point_beats() {
    // (wall s, error): 1 is dominated by 0 (dearer and worse); 3 ties 2 in cost but is
    // worse; 4 is the most accurate; 5 has no error (a failed run).
    let points = [
        (1.0, 0.5),
        (2.0, 0.6),
        (4.0, 0.2),
        (4.0, 0.3),
        (10.0, 0.01),
        (0.5, f64::NAN),
    ];
    assert_eq!(pareto_front(&points), vec![0, 2, 4]);
    assert!(pareto_front(&[]).is_empty());
    // Equal points: only one is on the front.
    assert_eq!(pareto_front(&[(1.0, 1.0), (1.0, 1.0)]).len(), 1);
}

#[test]
fn the_cheapest_setting_is_the_least_cost_within_the_target() {
    let points = [(10.0, 0.01), (1.0, 2.0), (3.0, 0.9), (2.0, 1.0), (2.0, 0.5)];
    // Within 1: indices 0, 2, 3, 4; cheapest 2.0 s, of which the smaller error.
    assert_eq!(cheapest_within(&points, 1.0), Some(4));
    assert_eq!(cheapest_within(&points, 0.1), Some(0));
    assert_eq!(cheapest_within(&points, 0.001), None);
    assert_eq!(cheapest_within(&[(f64::NAN, 0.0)], 1.0), None);
}

/// A successful cgdem run at lambda 1 (seed rule) with its angle and cost; shared by
/// the advise tests.
pub(crate) fn run(
    series: &str,
    value: f64,
    seed: u64,
    angle: f64,
    particle_steps: f64,
) -> AccuracyPoint {
    AccuracyPoint {
        case: "c".into(),
        code: Code::Cgdem,
        series: series.into(),
        value,
        setting: format!("{series} = {value}"),
        lambda: 1,
        cg_rule: CoarseGrainRule::RelativeOverlap,
        seed,
        status: Outcome::Ok,
        reason: None,
        dir: PathBuf::from("/nonexistent"),
        reused: false,
        n_particles: Some(100),
        steps: Some(10),
        particle_steps: Some(particle_steps),
        wall_s: Some(particle_steps / 1e6),
        repose_angle_deg: Some(angle),
        angle_error_deg: None,
        profile_distance: None,
        mass_flow_kg_s: None,
        mass_flow_error: None,
        eq7_mass_flow_kg_s: None,
        eq7_error: None,
        t_half_s: None,
        t_half_error: None,
        porosity: None,
        porosity_error: None,
        pore_diameter_d: None,
        pore_size_error: None,
        flow_stage: None,
        front_error: None,
        discharge_rate_kg_s: None,
        discharge_rate_std_error_kg_s: None,
        discharge_rate_error: None,
        bulk_density_kg_m3: None,
        particle_diameter_m: None,
        flow_stopped_at_s: None,
        dynamic_angle_deg: None,
        dynamic_angle_error_deg: None,
        mixing_period_s: None,
        mixing_period_error: None,
        mixing_index: None,
        mixing_index_error: None,
        large_share_zones: None,
    }
}

#[test]
fn errors_pair_runs_by_seed_and_settings_average_over_seeds() {
    let mut points = vec![
        run("reference", 0.02, 1, 30.0, 1e7),
        run("reference", 0.02, 2, 31.0, 1e7),
        run("reference", 0.02, 3, 29.5, 1e7),
        run("dt", 0.1, 1, 30.5, 2e6),
        run("dt", 0.1, 2, 31.2, 2e6),
        run("dt", 0.1, 3, 29.0, 2e6),
        run("dt", 0.3, 1, 31.0, 1e6),
        run("dt", 0.3, 2, 30.0, 1e6),
        run("dt", 0.3, 3, 30.5, 1e6),
    ];
    // Seed 1's dynamics and packing: t_half 20% longer, porosity 0.01 higher.
    points[0].t_half_s = Some(1.0);
    points[3].t_half_s = Some(1.2);
    points[0].porosity = Some(0.40);
    points[3].porosity = Some(0.41);
    // Pores of 0.8 diameters in the reference, 0.6 in the point: 25% smaller.
    points[0].pore_diameter_d = Some(0.8);
    points[3].pore_diameter_d = Some(0.6);
    measure(&mut points);
    assert!((points[3].t_half_error.unwrap() - 0.2).abs() < 1e-12);
    assert!((points[3].porosity_error.unwrap() - 0.01).abs() < 1e-12);
    assert!((points[3].pore_size_error.unwrap() - 0.25).abs() < 1e-12);
    assert_eq!(points[4].pore_size_error, None);
    assert_eq!(points[4].t_half_error, None);
    // Against the reference with the same seed: 0.5, 0.2, 0.5 (against seed 1's
    // reference alone they would be 0.5, 1.2, 1.0).
    let errors: Vec<f64> = points[3..6]
        .iter()
        .map(|p| p.angle_error_deg.unwrap())
        .collect();
    for (e, want) in errors.iter().zip([0.5, 0.2, 0.5]) {
        assert!((e - want).abs() < 1e-12, "{errors:?}");
    }
    let all = settings(Code::Cgdem, &points);
    assert_eq!(all.len(), 3);
    let dt = all[1].mean(Measure::Angle, Cost::ParticleSteps).unwrap();
    assert_eq!(dt.n, 3);
    assert!((dt.error - 0.4).abs() < 1e-12, "{dt:?}");
    // Sample standard deviation sqrt(0.03), over sqrt(3).
    assert!((dt.se.unwrap() - 0.1).abs() < 1e-12, "{dt:?}");
    // The reference runs' largest difference between seeds: 31.0 against 29.5.
    assert_eq!(floor(Code::Cgdem, Measure::Angle, &points), Some(1.5));
    // dt 0.3 errs by 1.0, 1.0, 1.0: within 1.0 it is the cheapest. dt 0.1's mean, 0.4,
    // is within 0.5 but its mean plus spread (2 x 0.1) is not: nothing within 0.5, dt
    // 0.1 within 0.65.
    let targets = Targets {
        angle_deg: 0.5,
        profile: 0.05,
        mass_flow: 0.05,
        t_half: 0.1,
        front: 0.1,
        porosity: 0.02,
        pore_size: 0.1,
        discharge_rate: 0.05,
        dynamic_angle_deg: 2.0,
        mixing_period: 0.1,
        mixing_index: 0.05,
    };
    let c = cheapest_setting("c", Code::Cgdem, Measure::Angle, &targets, &points);
    assert_eq!(c.setting, None);
    let within = |angle_deg| Targets {
        angle_deg,
        ..targets
    };
    let c = cheapest_setting("c", Code::Cgdem, Measure::Angle, &within(0.65), &points);
    assert_eq!(c.setting.as_deref(), Some("dt = 0.1"));
    assert_eq!((c.seeds, c.particle_steps), (3, Some(2e6)));
    let c = cheapest_setting("c", Code::Cgdem, Measure::Angle, &within(1.0), &points);
    assert_eq!(c.setting.as_deref(), Some("dt = 0.3"));
    assert_eq!(c.error_se, Some(0.0));
    // A seed of dt 0.3 stopped by a guard: the setting does not hold, dt 0.1 is chosen.
    points[7].status = Outcome::Failed;
    let c = cheapest_setting("c", Code::Cgdem, Measure::Angle, &within(1.0), &points);
    assert_eq!(c.setting.as_deref(), Some("dt = 0.1"));
    points[7].status = Outcome::Ok;
    // A failed run drops out of its setting's mean.
    points[4].status = Outcome::Failed;
    let all = settings(Code::Cgdem, &points);
    assert_eq!(
        all[1].mean(Measure::Angle, Cost::ParticleSteps).unwrap().n,
        2
    );
}

#[test]
fn profile_distance_is_zero_for_equal_heaps_and_scales_with_the_gap() {
    let heap: Vec<(f64, f64)> = (0..20)
        .map(|k| (0.005 + 0.01 * k as f64, (0.1 - 0.005 * k as f64).max(0.0)))
        .collect();
    assert_eq!(profile_distance(&heap, &heap), Some(0.0));
    // Uniformly 1 cm higher where the heap is: 0.01 / 0.1 over every point.
    let higher: Vec<(f64, f64)> = heap.iter().map(|&(x, h)| (x, h + 0.01)).collect();
    let d = profile_distance(&heap, &higher).unwrap();
    assert!((d - 0.1).abs() < 1e-12, "{d}");
    // Coarser bins of the same straight heap: only the interpolation differs.
    let coarse: Vec<(f64, f64)> = heap.iter().step_by(2).copied().collect();
    assert!(profile_distance(&heap, &coarse).unwrap() < 0.05);
    assert_eq!(profile_distance(&[], &heap), None);
}

/// A front 0.1 s behind the reference's has covered a tenth of its run-out less at worst;
/// equal fronts, or the same shape shorter and offset, are 0 apart; a front that stops
/// halfway at the same pace has covered all of its run-out when the reference has
/// covered half: 0.5 apart.
#[test]
fn front_history_gap_compares_the_fraction_of_run_out_covered() {
    let flow = |front: &dyn Fn(f64) -> f64| {
        let time_s: Vec<f64> = (0..=200).map(|k| 0.01 * k as f64).collect();
        FlowSeries {
            front_m: time_s.iter().map(|&t| front(t)).collect(),
            wall_height_m: vec![0.3; time_s.len()],
            kinetic_energy_per_mass: vec![1.0; time_s.len()],
            time_s,
        }
    };
    // 0.2 m to 0.6 m at 0.4 m/s over the first second, then at rest.
    let reference = flow(&|t: f64| 0.2 + 0.4 * t.min(1.0));
    assert_eq!(front_history_gap(&reference, &reference), Some(0.0));
    let late = flow(&|t: f64| 0.2 + 0.4 * (t - 0.1).clamp(0.0, 1.0));
    let gap = front_history_gap(&reference, &late).unwrap();
    assert!((gap - 0.1).abs() < 1e-9, "{gap}");
    // Half the run-out at the same pace: done at 0.5 s, when the reference has covered
    // half of its own.
    let halfway = flow(&|t: f64| 0.2 + 0.4 * t.min(0.5));
    let gap = front_history_gap(&reference, &halfway).unwrap();
    assert!((gap - 0.5).abs() < 1e-9, "{gap}");
    // The same shape, shorter and offset (a coarser front's definition): no gap.
    let shorter = flow(&|t: f64| 0.15 + 0.3 * t.min(1.0));
    let gap = front_history_gap(&reference, &shorter).unwrap();
    assert!(gap < 1e-9, "{gap}");
    // A front that never moved has no run-out to measure against.
    let still = flow(&|_| 0.2);
    assert_eq!(front_history_gap(&still, &reference), None);
    assert_eq!(front_history_gap(&reference, &still), None);
}

#[test]
fn shipped_suites_parse_and_every_accuracy_point_is_a_valid_scene() {
    crate::at_repo_root();
    for entry in std::fs::read_dir("validation/suites").unwrap() {
        let path = entry.unwrap().path();
        let suite = Suite::load(&path).unwrap_or_else(|e| panic!("{e}"));
        for sweep in &suite.accuracy {
            for s in &sweep.series {
                for &v in &s.values {
                    let mut knobs = sweep.reference.clone();
                    knobs.insert(s.knob.clone(), v);
                    let (scene, lambda) = sweep.scene(&knobs, &path).unwrap_or_else(|e| {
                        panic!("{}: {} = {v}: {e}", path.display(), s.knob.name())
                    });
                    // The level fits the box under the series' rule (e.g. lambda 8 in
                    // the fidelity suite's deep Hertz box).
                    cgdem_core::coarse_graining::coarse_grain_by(&scene, lambda, s.rule)
                        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
                }
            }
        }
    }
}

/// A series under another rule that includes the reference's level is that rule's own
/// matrix too: its runs at the reference's level become the reference, the others keep
/// their errors to be measured against it; a series without that level adds nothing.
#[test]
fn a_rule_series_at_the_reference_level_is_also_its_own_matrix() {
    crate::at_repo_root();
    let suite = Suite::parse(
        "name = \"a\"\n[[accuracy]]\nfile = \"validation/cases/aor_collapse.toml\"\n\
         variant = \"f\"\nseeds = [1, 2]\n[accuracy.reference]\nlambda = 8\n\
         [[accuracy.series]]\nknob = \"lambda\"\nvalues = [16]\n\
         [[accuracy.series]]\nknob = \"lambda\"\nvalues = [8, 16]\ncg_rule = \"bulk-viscosity\"\n\
         [[accuracy.series]]\nknob = \"lambda\"\nvalues = [32]\ncg_rule = \"bulk-viscosity\"\n",
        Path::new("s.toml"),
    )
    .unwrap();
    let sweep = &suite.accuracy[0];
    let point = |series: &str, lambda: u32, rule: CoarseGrainRule, seed: u64, angle: f64| {
        let mut p = run(series, lambda as f64, seed, angle, 1e6 / lambda as f64);
        p.lambda = lambda;
        p.cg_rule = rule;
        p.angle_error_deg = Some(99.0);
        p
    };
    let (seed_rule, bv) = (
        CoarseGrainRule::RelativeOverlap,
        CoarseGrainRule::BulkViscosity,
    );
    let mut points = Vec::new();
    for seed in [1, 2] {
        points.push(point("reference", 8, seed_rule, seed, 40.0));
        points.push(point("lambda", 16, seed_rule, seed, 45.0));
        points.push(point(
            "lambda (bulk-viscosity)",
            8,
            bv,
            seed,
            20.0 + seed as f64,
        ));
        points.push(point(
            "lambda (bulk-viscosity)",
            16,
            bv,
            seed,
            23.0 + seed as f64,
        ));
    }
    let own = own_rule_sweeps(sweep, "c", &points);
    assert_eq!(own.len(), 1, "the lambda-32-only series has no reference");
    let (own_sweep, mut own_points) = own.into_iter().next().unwrap();
    assert_eq!(own_sweep.rule, bv);
    assert_eq!(own_sweep.series.len(), 1);
    assert_eq!(own_sweep.series[0].values, vec![16.0]);
    assert_eq!(own_points.len(), 4);
    assert!(own_points.iter().all(|p| p.case == "c-bulk-viscosity-rule"));
    assert!(own_points.iter().all(|p| p.angle_error_deg.is_none()));
    let settings: Vec<&str> = own_points.iter().map(|p| p.setting.as_str()).collect();
    assert_eq!(
        settings,
        ["reference", "lambda = 16", "reference", "lambda = 16"]
    );
    measure(&mut own_points);
    // 24 - 21 and 25 - 22: 3 deg in each seed, against the rule's own lambda 8.
    assert_eq!(own_points[1].angle_error_deg, Some(3.0));
    assert_eq!(own_points[3].angle_error_deg, Some(3.0));
}

#[test]
fn a_sweep_needs_its_knobs_reference_values() {
    crate::at_repo_root();
    let suite = |series: &str| {
        format!(
            "name = \"a\"\n[[accuracy]]\nfile = \"validation/cases/aor_hertz_smoke.toml\"\n\
             variant = \"acc\"\n[accuracy.reference]\nlambda = 1\n\"time.dt_fraction\" = 0.02\n\
             [[accuracy.series]]\n{series}\n"
        )
    };
    let ok = Suite::parse(
        &suite(
            "knob = \"time.dt_fraction\"\nvalues = [0.05, 0.1]\ncodes = [\"cgdem\", \"lammps\"]",
        ),
        Path::new("s.toml"),
    )
    .unwrap();
    let sweep = &ok.accuracy[0];
    assert_eq!(sweep.codes(), vec![Code::Cgdem, Code::Lammps]);
    assert_eq!(sweep.targets.angle_deg, 1.0);
    let (scene, lambda) = sweep.scene(&sweep.reference, Path::new("s.toml")).unwrap();
    assert_eq!(lambda, 1);
    assert_eq!(scene.name, "aor_hertz_smoke-acc");
    let e = Suite::parse(
        &suite("knob = \"neighbor.skin_fraction\"\nvalues = [0.1]"),
        Path::new("s.toml"),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("accuracy[0].series[0].knob"), "{e}");
    let e = Suite::parse(
        &suite("knob = \"lambda\"\nvalues = [3]"),
        Path::new("s.toml"),
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("accuracy[0].series[0].values"), "{e}");
    let with_seeds = |seeds: &str| {
        suite("knob = \"time.dt_fraction\"\nvalues = [0.1]").replace(
            "variant = \"acc\"\n",
            &format!("variant = \"acc\"\n{seeds}\n"),
        )
    };
    let ok = Suite::parse(&with_seeds("seeds = [3, 1, 2]"), Path::new("s.toml")).unwrap();
    assert_eq!(ok.accuracy[0].seeds, vec![3, 1, 2]);
    for bad in ["seeds = [1, 1]", "seeds = []"] {
        let e = Suite::parse(&with_seeds(bad), Path::new("s.toml"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("accuracy[0].seeds"), "{bad}: {e}");
    }
    // A series under another coarse-graining rule is its own series, named by the rule.
    let ruled = suite("knob = \"lambda\"\nvalues = [2]\ncg_rule = \"bulk-viscosity\"");
    let ok = Suite::parse(&ruled, Path::new("s.toml")).unwrap();
    let s0 = &ok.accuracy[0].series[0];
    assert_eq!(s0.rule, CoarseGrainRule::BulkViscosity);
    assert_eq!(s0.name(ok.accuracy[0].rule), "lambda (bulk-viscosity)");
    let e = Suite::parse(&ruled.replace("bulk-viscosity", "pfm"), Path::new("s.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("accuracy[0].series[0].cg_rule") && e.contains("pfm"),
        "{e}"
    );
    // The former single seed is refused by name, not silently ignored.
    let e = Suite::parse(&with_seeds("seed = 1"), Path::new("s.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("seed"), "{e}");
}
