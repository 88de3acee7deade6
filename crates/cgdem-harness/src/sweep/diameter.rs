//! Diameter sweep of a packing scene (paper B Fig. 2): the scene is rescaled to each diameter,
//! run, and its porosity and pore sizes are gathered beside the published values.
//!
//! **What is held fixed** (the material, as in Yang, Zou & Yu 2000 where each value is one
//! number for all sizes): density, Young's modulus, Poisson's ratio, sliding and rolling
//! friction coefficients, Hamaker constant, `h_min`, gravity, the particle count and the
//! restitution-vs-impact-speed curve.
//!
//! **What scales with `s = d / d_scene`** (geometric similarity):
//! * every length of the scene: box, walls, insertion boxes (so the start porosity and the
//!   10 d period are kept);
//! * the Yang damping time `gamma_n` (Eq. 4): a Hertz impact of two spheres at speed `v` lasts
//!   `~ d v^(-1/5)` for fixed `E` and density, and its restitution depends on `gamma_n` only
//!   through `gamma_n / t_c`; `gamma_n ~ d` keeps `e(v)` the same material curve at every size.
//!   Holding `gamma_n` in seconds instead would make 1 um spheres overdamped 1000 times over
//!   (and need a time step of 1e-10 s);
//! * the time step follows from the scene's `dt_fraction` of the contact period, which scales
//!   with `d` (an explicit `dt` is scaled by `s`);
//! * gravity times: stage durations and output intervals by `sqrt(s)` (free fall over a height
//!   `~ d`), kinetic-energy thresholds per mass by `s` (`~ g d`).
//!
//! The van der Waals cut-off is a gap, not a length of the scene: with `h_min` fixed, the default
//! reach (where Eq. 7 falls to 1e-3 of its value at `h_min`, about `31.6 h_min` while
//! `h << d`) is recomputed from the new radii and stays about 12.6 nm; an explicit
//! `cohesion_cutoff` is kept. So the attraction-to-weight ratio `F_vdw(h_min) / m g ~ d^(-2)`
//! is what changes, and that is the physics of the figure.

use std::path::Path;
use std::time::Instant;

use crate::csv_table::{CsvTable, TableError};
use crate::report::{write_figure, Figure, Series, SeriesStyle};
use cgdem_core::analysis::PackingSummary;
use cgdem_core::contact::cohesion::{vdw_force, vdw_reach};
use cgdem_core::io::{write_atomic, CsvBuffer};
use cgdem_core::math::Real;
use cgdem_core::run::{run, Progress, RunOptions, RunSummary};
use cgdem_core::scene::{
    CohesionKind, ContactSettings, HertzDampingKind, InsertAmount, Scene, StageEnd,
};
use cgdem_core::timestep::TimeStepRequest;

/// The diameters of paper B Fig. 2(b) (pore-size distributions), m.
pub const PAPER_PSD_DIAMETERS: [Real; 4] = [20e-6, 50e-6, 100e-6, 1000e-6];

/// The scene rescaled to particle diameter `diameter` (see the module comment for what is held
/// and what scales). Errors name the scene file and what is missing.
pub fn scale_to_diameter(scene: &Scene, diameter: Real) -> Result<Scene, String> {
    let file = scene.source.display();
    if !(diameter.is_finite() && diameter > 0.0) {
        return Err(format!(
            "--sweep diameter: value `{diameter}` is not allowed: a finite number > 0 (m)"
        ));
    }
    if scene.species.len() != 1 {
        return Err(format!(
            "{file}: --sweep diameter needs exactly one species (it has {})",
            scene.species.len()
        ));
    }
    if scene.packing.is_none() {
        return Err(format!(
            "{file}: --sweep diameter needs a [packing] section (what the sweep measures)"
        ));
    }
    if !scene.bodies.is_empty() || scene.conveying.is_some() || scene.repose.is_some() {
        return Err(format!(
            "{file}: --sweep diameter rescales a packing scene; bodies, [conveying] and [repose] are not rescaled"
        ));
    }
    if scene.lambda != 1 {
        return Err(format!(
            "{file}: --sweep diameter with --lambda {}: a coarse-grained packing does not represent the fine powder (vdW-to-weight ratio changes by lambda); sweep at lambda = 1",
            scene.lambda
        ));
    }
    let mut out = scene.clone();
    let s = diameter / scene.species[0].diameter;
    let t = s.sqrt();
    out.species[0].diameter = diameter;
    out.domain.lo *= s;
    out.domain.hi *= s;
    for w in &mut out.walls {
        w.point *= s;
    }
    for ins in &mut out.insertions {
        ins.lo *= s;
        ins.hi *= s;
        match &mut ins.amount {
            InsertAmount::SolidVolume(v) => *v *= s * s * s,
            InsertAmount::Lattice(lattice) => {
                lattice.spacing *= s;
                lattice.origin = lattice.origin.map(|o| o * s);
                lattice.radius = lattice.radius.map(|r| r * s);
            }
            InsertAmount::Count(_) => {}
        }
    }
    for (lo, hi) in &mut out.deletions {
        *lo *= s;
        *hi *= s;
    }
    match &mut out.contact {
        ContactSettings::Hertz(h) => {
            if let HertzDampingKind::Yang { gamma_n } = &mut h.damping {
                *gamma_n *= s;
            }
        }
        ContactSettings::Wca(_) => {
            return Err(format!(
                "{file}: --sweep diameter needs model = \"hertz\" (the WCA sigma is tied to the diameter and eps has no size-free meaning)"
            ))
        }
    }
    if let TimeStepRequest::Explicit(dt) = &mut out.time_step {
        *dt *= s;
    }
    for stage in &mut out.stages {
        stage.end = match stage.end {
            StageEnd::Duration(d) => StageEnd::Duration(d * t),
            StageEnd::Settled {
                kinetic_energy_per_mass,
                min_duration,
                max_duration,
            } => StageEnd::Settled {
                kinetic_energy_per_mass: kinetic_energy_per_mass * s,
                min_duration: min_duration * t,
                max_duration: max_duration * t,
            },
        };
    }
    out.output.timeseries_interval *= t;
    out.output.vtk_interval *= t;
    Ok(out)
}

/// One published porosity point.
#[derive(Clone, Debug, PartialEq)]
pub struct PublishedPorosity {
    pub diameter_um: Real,
    pub porosity: Real,
    pub read_uncertainty: Real,
    pub source: String,
}

/// The published points of `reference/packing/porosity_vs_diameter_published.csv` (compiled in).
pub fn published_porosity() -> Result<Vec<PublishedPorosity>, String> {
    parse_published(include_bytes!(
        "../../../../reference/packing/porosity_vs_diameter_published.csv"
    ))
    .map_err(|e| e.to_string())
}

fn parse_published(text: &[u8]) -> Result<Vec<PublishedPorosity>, TableError> {
    let table = CsvTable::parse(
        Path::new("reference/packing/porosity_vs_diameter_published.csv"),
        text,
    )?;
    let [d, porosity, uncertainty, source] =
        ["diameter_um", "porosity", "read_uncertainty", "source"].map(|name| table.column(name));
    let (d, porosity, uncertainty, source) = (d?, porosity?, uncertainty?, source?);
    table
        .rows()
        .map(|row| {
            Ok(PublishedPorosity {
                diameter_um: row.parse(d)?,
                porosity: row.parse(porosity)?,
                read_uncertainty: row.parse(uncertainty)?,
                source: row.text(source)?.trim().to_string(),
            })
        })
        .collect()
}

/// `d` in micrometres as a directory name: `d100um`, `d3um`, `d0.5um`.
fn run_dir_name(diameter: Real) -> String {
    format!("d{}um", format_um(diameter))
}

fn format_um(diameter: Real) -> String {
    let um = diameter * 1e6;
    let rounded = (um * 1e6).round() / 1e6;
    format!("{rounded}")
}

/// Attraction at contact over weight, `F_vdw(h_min) / (m g)`.
fn bond_number(scene: &Scene) -> Option<Real> {
    let ContactSettings::Hertz(h) = &scene.contact else {
        return None;
    };
    let CohesionKind::VanDerWaals {
        hamaker_constant,
        h_min,
        ..
    } = h.cohesion
    else {
        return Some(0.0);
    };
    let sp = &scene.species[0];
    let r = sp.radius();
    Some(vdw_force(hamaker_constant, r, r, h_min) / (sp.mass() * scene.gravity.length()))
}

fn vdw_cutoff(scene: &Scene) -> Option<Real> {
    let ContactSettings::Hertz(h) = &scene.contact else {
        return None;
    };
    match h.cohesion {
        CohesionKind::VanDerWaals { h_min, cutoff, .. } => {
            let r = scene.species[0].radius();
            Some(cutoff.unwrap_or_else(|| vdw_reach(r, r, h_min, 1e-3)))
        }
        CohesionKind::None => None,
    }
}

/// Runs `scene` rescaled to each diameter into `out/d<um>um/`, writing after each run
/// `out/porosity_vs_diameter.csv` and `out/pore_size_vs_diameter.csv`, and at the end the plots
/// `out/porosity_vs_diameter_plot.png|svg|csv` (with the published points) and
/// `out/pore_size_distribution_plot.png|svg|csv` (the runs at paper B's Fig. 2(b) diameters, or
/// all runs if none of them was swept).
pub fn diameter_sweep(
    scene: &Scene,
    diameters: &[Real],
    out: &Path,
    progress: Option<Progress>,
    force_dt: bool,
    keep_going: bool,
) -> Result<Vec<(Real, RunSummary)>, String> {
    // Check every diameter before the first (long) run.
    let scenes = diameters
        .iter()
        .map(|&d| scale_to_diameter(scene, d).map(|s| (d, s)))
        .collect::<Result<Vec<_>, _>>()?;
    let published = published_porosity()?;
    let write = |name: &str, table: &mut CsvBuffer| {
        table
            .bytes()
            .and_then(|bytes| write_atomic(&out.join(name), bytes))
            .map_err(|e| format!("cannot write {}: {e}", out.join(name).display()))
    };
    std::fs::create_dir_all(out).map_err(|e| format!("cannot create {}: {e}", out.display()))?;
    let mut csv = porosity_csv();
    let mut psd_csv = CsvBuffer::new([
        "diameter_um",
        "pore_diameter_lo_um",
        "pore_diameter_hi_um",
        "fraction",
        "cumulative",
    ]);
    let mut results: Vec<(Real, RunSummary)> = Vec::new();
    let mut psd: Vec<(Real, Vec<(Real, Real)>)> = Vec::new();
    for (d, s) in &scenes {
        let run_dir = out.join(run_dir_name(*d));
        let options = RunOptions {
            out_dir: run_dir.clone(),
            progress: progress.clone(),
            force_dt,
            keep_going,
            ..Default::default()
        };
        let started = Instant::now();
        let summary = run(s, &options).map_err(|e| e.to_string())?;
        let wall = started.elapsed().as_secs_f64();
        let published_here = published
            .iter()
            .find(|p| (p.diameter_um / (d * 1e6) - 1.0).abs() < 1e-6)
            .map(|p| p.porosity);
        porosity_row(&mut csv, *d, s, &summary, wall, published_here);
        write("porosity_vs_diameter.csv", &mut csv)?;
        if summary.packing.is_some() {
            let points = pore_size_rows(&run_dir.join("pore_size.csv"), *d, &mut psd_csv)?;
            write("pore_size_vs_diameter.csv", &mut psd_csv)?;
            psd.push((*d, points));
        }
        results.push((*d, summary));
    }
    write_porosity_figure(out, &results, &published)?;
    if !psd.is_empty() {
        write_pore_size_figure(out, &psd)?;
    }
    Ok(results)
}

/// `porosity_vs_diameter.csv` before its first row.
fn porosity_csv() -> CsvBuffer {
    CsvBuffer::new([
        "diameter_m",
        "diameter_um",
        "n_particles",
        "steps",
        "dt_s",
        "contact_period_s",
        "vdw_cutoff_gap_m",
        "bond_number",
        "simulated_s",
        "settled",
        "porosity",
        "published_porosity",
        "region_z_lo_m",
        "region_z_hi_m",
        "region_height_d",
        "bed_height_d",
        "mean_pore_diameter_m",
        "median_pore_diameter_m",
        "wall_s",
    ])
}

/// One run's row of `porosity_vs_diameter.csv`.
fn porosity_row(
    csv: &mut CsvBuffer,
    d: Real,
    s: &Scene,
    summary: &RunSummary,
    wall: f64,
    published: Option<Real>,
) {
    let p: Option<&PackingSummary> = summary.packing.as_ref();
    let f = |v: Option<Real>| v.map_or(String::new(), |x| format!("{x:.6e}"));
    let settled = summary
        .stages
        .last()
        .is_some_and(|st| st.ended_by.starts_with("kinetic energy"));
    csv.row([
        format!("{d:e}"),
        format_um(d),
        summary.n_particles.to_string(),
        summary.steps.to_string(),
        format!("{:.6e}", summary.dt_s),
        format!("{:.6e}", summary.contact_period_s),
        f(vdw_cutoff(s)),
        f(bond_number(s)),
        format!("{:.6e}", summary.simulated_s),
        settled.to_string(),
        p.map_or(String::new(), |p| format!("{:.5}", p.porosity)),
        published.map_or(String::new(), |v| format!("{v}")),
        f(p.map(|p| p.region_z_m[0])),
        f(p.map(|p| p.region_z_m[1])),
        p.map_or(String::new(), |p| {
            format!("{:.2}", p.region_height_diameters)
        }),
        p.map_or(String::new(), |p| format!("{:.2}", p.bed_height_diameters)),
        f(p.map(|p| p.mean_pore_diameter_m)),
        f(p.map(|p| p.median_pore_diameter_m)),
        format!("{wall:.1}"),
    ]);
}

/// Reads a run's `pore_size.csv` (at `path`) into `psd_csv`'s rows for diameter `d`; returns
/// the distribution as (bin centre in um, fraction).
fn pore_size_rows(
    path: &Path,
    d: Real,
    psd_csv: &mut CsvBuffer,
) -> Result<Vec<(Real, Real)>, String> {
    let rows = CsvTable::read(path)
        .and_then(|t| t.numbers(&["diameter_lo", "diameter_hi", "fraction", "cumulative"]))
        .map_err(|e| e.to_string())?;
    let mut points = Vec::new();
    for row in rows {
        let (lo, hi, fraction, cumulative) = (row[0], row[1], row[2], row[3]);
        psd_csv.row([
            format_um(d),
            format!("{:.6}", lo * 1e6),
            format!("{:.6}", hi * 1e6),
            format!("{fraction:.6e}"),
            format!("{cumulative:.6e}"),
        ]);
        points.push((0.5 * (lo + hi) * 1e6, fraction));
    }
    Ok(points)
}

/// `porosity_vs_diameter_plot`: the runs' porosity against diameter with the published points.
fn write_porosity_figure(
    out: &Path,
    results: &[(Real, RunSummary)],
    published: &[PublishedPorosity],
) -> Result<(), String> {
    let measured: Vec<(Real, Real)> = results
        .iter()
        .filter_map(|(d, s)| s.packing.as_ref().map(|p| (d * 1e6, p.porosity)))
        .collect();
    let fig = Figure::new(
        "Porosity of the packed bed against particle diameter",
        "particle diameter (um)",
        "porosity",
    )
    .log_x()
    .with_series(Series::new("cgdem (this work)", measured).style(SeriesStyle::LineMarkers))
    .with_series(
        Series::new(
            "paper B Fig. 2(a): coarse plateau, read from the figure summary",
            published
                .iter()
                .map(|p| (p.diameter_um, p.porosity))
                .collect(),
        )
        .style(SeriesStyle::Markers)
        .y_err(published.iter().map(|p| p.read_uncertainty).collect()),
    );
    write_figure(out, "porosity_vs_diameter_plot", &fig).map_err(|e| e.to_string())?;
    Ok(())
}

/// `pore_size_distribution_plot`: the runs at paper B's Fig. 2(b) diameters, or every run if
/// none of them was swept.
fn write_pore_size_figure(out: &Path, psd: &[(Real, Vec<(Real, Real)>)]) -> Result<(), String> {
    let at_paper: Vec<&(Real, Vec<(Real, Real)>)> = psd
        .iter()
        .filter(|(d, _)| {
            PAPER_PSD_DIAMETERS
                .iter()
                .any(|p| (p / d - 1.0).abs() < 1e-6)
        })
        .collect();
    let chosen: Vec<&(Real, Vec<(Real, Real)>)> = if at_paper.is_empty() {
        psd.iter().collect()
    } else {
        at_paper
    };
    let mut fig = Figure::new(
        "Pore-size distribution (Gelb & Gubbins), volume fraction per bin of 0.1 d",
        "pore diameter (um)",
        "void volume fraction",
    )
    .log_x();
    for (d, points) in chosen {
        fig = fig.with_series(
            Series::new(format!("d = {} um", format_um(*d)), points.clone())
                .style(SeriesStyle::LineMarkers),
        );
    }
    write_figure(out, "pore_size_distribution_plot", &fig).map_err(|e| e.to_string())?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use cgdem_core::contact::cohesion::VanDerWaals;
    use cgdem_core::contact::damping::YangDamping;
    use cgdem_core::contact::rolling::ConstantTorque;
    use cgdem_core::contact::tangential::YangTangential;
    use cgdem_core::run::{hertz_law, hertz_wall, FromScene};

    fn case() -> Scene {
        let path = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
            .join("validation/cases/packing_vdw.toml");
        Scene::load(&path).unwrap()
    }

    fn hertz(scene: &Scene) -> cgdem_core::scene::HertzSettings {
        let ContactSettings::Hertz(h) = &scene.contact else {
            panic!("not hertz")
        };
        h.clone()
    }

    #[test]
    fn rescaling_keeps_the_material_and_scales_lengths_damping_and_gravity_times() {
        let base = case();
        let d0 = base.species[0].diameter;
        let scaled = scale_to_diameter(&base, 1e-6).unwrap();
        let s = 1e-6 / d0;
        assert_eq!(scaled.species[0].diameter, 1e-6);
        assert_eq!(scaled.species[0].density, base.species[0].density);
        // The period stays 10 d, the start porosity the same (same count, box scaled).
        let period = scaled.domain.hi.x - scaled.domain.lo.x;
        assert!((period / 1e-6 - 10.0).abs() < 1e-9, "{period}");
        let (a, b) = (&base.insertions[0], &scaled.insertions[0]);
        assert!(((b.hi - b.lo) / (a.hi - a.lo) - s).abs().max_element() < 1e-12);
        assert_eq!(a.amount, b.amount);
        let (h0, h1) = (hertz(&base), hertz(&scaled));
        assert_eq!(h1.youngs_modulus, h0.youngs_modulus);
        assert_eq!(h1.poisson_ratio, h0.poisson_ratio);
        assert_eq!(h1.friction, h0.friction);
        assert_eq!(h1.rolling_friction, h0.rolling_friction);
        assert_eq!(
            h1.cohesion, h0.cohesion,
            "H_a, h_min and the cut-off gap held"
        );
        let (HertzDampingKind::Yang { gamma_n: g0 }, HertzDampingKind::Yang { gamma_n: g1 }) =
            (h0.damping, h1.damping)
        else {
            panic!("the case uses the Yang dashpot")
        };
        assert!((g1 / g0 / s - 1.0).abs() < 1e-12);
        match (&base.stages[0].end, &scaled.stages[0].end) {
            (
                StageEnd::Settled {
                    kinetic_energy_per_mass: k0,
                    max_duration: m0,
                    ..
                },
                StageEnd::Settled {
                    kinetic_energy_per_mass: k1,
                    max_duration: m1,
                    ..
                },
            ) => {
                assert!((k1 / k0 / s - 1.0).abs() < 1e-12);
                assert!((m1 / m0 / s.sqrt() - 1.0).abs() < 1e-12);
            }
            other => panic!("{other:?}"),
        }
        assert!(
            (scaled.output.timeseries_interval / base.output.timeseries_interval / s.sqrt() - 1.0)
                .abs()
                < 1e-12
        );
    }

    #[test]
    fn time_step_scales_with_the_diameter_and_the_vdw_reach_stays_a_fixed_gap() {
        let base = case();
        let mut previous: Option<(Real, Real, Real)> = None;
        for d in [1e-6, 1e-5, 1e-4, 1e-3] {
            let scene = scale_to_diameter(&base, d).unwrap();
            let h = hertz(&scene);
            let law =
                hertz_law::<YangDamping, YangTangential, ConstantTorque, VanDerWaals>(&scene, &h);
            let (dt, _, warning) =
                cgdem_core::run::time_step_for(&scene, &law, &hertz_wall(&scene, &h), false)
                    .unwrap();
            assert!(warning.is_none());
            let reach = VanDerWaals::from_scene(&scene, &h).reach;
            if let Some((d0, dt0, reach0)) = previous {
                assert!(
                    ((dt / dt0) / (d / d0) - 1.0).abs() < 1e-9,
                    "dt {dt} vs {dt0}"
                );
                assert!(
                    (reach / reach0 - 1.0).abs() < 0.03,
                    "reach {reach} vs {reach0}"
                );
            }
            // About 31.6 h_min = 12.6 nm while the gap is small against d (12.35 nm at 1 um,
            // where the gap is 2.5% of the radius).
            assert!((reach / 12.65e-9 - 1.0).abs() < 0.03, "{reach}");
            previous = Some((d, dt, reach));
        }
    }

    #[test]
    fn scenes_the_sweep_cannot_rescale_are_refused_with_the_reason() {
        let base = case();
        let message = scale_to_diameter(&base, -1e-6).unwrap_err();
        assert!(
            message.contains("--sweep diameter") && message.contains("> 0"),
            "{message}"
        );
        let mut no_packing = base.clone();
        no_packing.packing = None;
        let message = scale_to_diameter(&no_packing, 1e-5).unwrap_err();
        assert!(
            message.contains("packing_vdw.toml") && message.contains("[packing]"),
            "{message}"
        );
        let mut coarse = base.clone();
        coarse.lambda = 2;
        assert!(scale_to_diameter(&coarse, 1e-5)
            .unwrap_err()
            .contains("lambda"));
    }

    #[test]
    fn published_points_are_read_with_their_source() {
        let p = published_porosity().unwrap();
        assert!(!p.is_empty());
        assert!(p.iter().all(|p| p.source.contains("paper B")
            && p.source.contains("read from the figure")
            && (0.3..0.95).contains(&p.porosity)));
        assert_eq!(run_dir_name(1e-6), "d1um");
        assert_eq!(run_dir_name(3e-5), "d30um");
        assert_eq!(run_dir_name(1e-3), "d1000um");
    }
}
