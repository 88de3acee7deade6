//! Sweeps: one run per value of a scene parameter, then a table and a plot.
//!
//! * `rpm=...`: a conveying scene at several screw speeds, mass flow against speed with
//!   Eq. (7) (paper A Fig. 8).
//! * `diameter=...`: a packing scene at several particle diameters, porosity against diameter
//!   beside the published values and pore-size distributions (paper B Fig. 2).

use std::path::Path;

use crate::report::{write_figure, Figure, Series, SeriesStyle};
use cgdem_core::io::{write_atomic, CsvBuffer};
use cgdem_core::math::Real;
use cgdem_core::run::{run, Progress, RunOptions, RunSummary, StageEnding};
use cgdem_core::scene::{Scene, StageEnd};

mod diameter;
mod dispatch;
pub use diameter::{
    diameter_sweep, published_porosity, scale_to_diameter, PublishedPorosity, PAPER_PSD_DIAMETERS,
};
pub use dispatch::{SweepOutcome, SweepSettings};

/// A parsed `--sweep KEY=V1,V2,...`.
#[derive(Clone, Debug, PartialEq)]
pub enum Sweep {
    /// Screw speeds, rev/min.
    Rpm(Vec<Real>),
    /// Particle diameters, m.
    Diameter(Vec<Real>),
    /// Screw-particle radius over grain radius, r_s / r_p, of a body built of particles.
    ScrewRatio(Vec<Real>),
}

/// The keys `--sweep` knows, with what their values mean.
pub const SWEEP_KEYS: &str =
    "rpm (screw speeds, rev/min, > 0), diameter (particle diameters, m, > 0) or screw_ratio (r_s / r_p of a particle-built screw, > 0)";

/// A bad `--sweep` argument; the message names the option, the key and the value.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SweepError {
    #[error("--sweep: expected KEY=V1,V2,... with KEY {SWEEP_KEYS}; got `{0}`")]
    Syntax(String),
    #[error("--sweep: unknown key `{0}`; allowed: {SWEEP_KEYS}")]
    UnknownKey(String),
    #[error("--sweep {key}: value `{value}` is not allowed: {allowed}")]
    BadValue {
        key: String,
        value: String,
        allowed: String,
    },
}

impl Sweep {
    /// Parses `rpm=20,40` or `diameter=1e-6,3e-6`: every value a finite number > 0, no
    /// value twice.
    pub fn parse(text: &str) -> Result<Sweep, SweepError> {
        let (key, list) = text
            .split_once('=')
            .ok_or_else(|| SweepError::Syntax(text.to_string()))?;
        let key = key.trim();
        let unit = match key {
            "rpm" => "rev/min",
            "diameter" => "m",
            "screw_ratio" => "r_s / r_p",
            _ => return Err(SweepError::UnknownKey(key.to_string())),
        };
        let bad = |value: &str, allowed: String| SweepError::BadValue {
            key: key.to_string(),
            value: value.to_string(),
            allowed,
        };
        let mut values: Vec<Real> = Vec::new();
        for item in list.split(',') {
            let item = item.trim();
            let v: Real = item
                .parse()
                .map_err(|_| bad(item, format!("a number ({unit})")))?;
            if !(v.is_finite() && v > 0.0) {
                return Err(bad(item, format!("a finite number > 0 ({unit})")));
            }
            if values.contains(&v) {
                return Err(bad(item, "each value once".into()));
            }
            values.push(v);
        }
        Ok(match key {
            "rpm" => Sweep::Rpm(values),
            "screw_ratio" => Sweep::ScrewRatio(values),
            _ => Sweep::Diameter(values),
        })
    }
}

/// Runs `scene` into `options.out_dir`, or with `reuse`, takes the run already there when its
/// `summary.json` holds this very scene (same digest) and a conveying measurement.
fn run_or_reuse(scene: &Scene, options: &RunOptions, reuse: bool) -> Result<RunSummary, String> {
    if reuse {
        let path = options.out_dir.join("summary.json");
        if let Some(summary) = std::fs::read_to_string(&path)
            .ok()
            .and_then(|text| serde_json::from_str::<serde_json::Value>(&text).ok())
            .filter(|s| !StageEnding::interrupted_summary(s))
            .and_then(|s| serde_json::from_value::<RunSummary>(s).ok())
            .filter(|s| s.scene_digest == scene.digest() && s.conveying.is_some())
        {
            eprintln!("reusing {}", path.display());
            return Ok(summary);
        }
    }
    run(scene, options).map_err(|e| e.to_string())
}

/// `scene` with the conveying body at `rpm` (its sense kept) and the conveying stage's
/// duration and `discard` scaled by `|rpm_scene| / rpm`: the same number of screw turns at
/// every speed (the discharge pulses once per turn, so a window must hold whole turns).
pub fn at_speed(scene: &Scene, body: &str, rpm: Real) -> Scene {
    let mut s = scene.clone();
    let Some(old) = s
        .bodies
        .iter()
        .find(|b| b.name == body)
        .map(|b| b.rpm.abs())
    else {
        return s;
    };
    for b in s.bodies.iter_mut().filter(|b| b.name == body) {
        b.rpm = if b.rpm < 0.0 { -rpm.abs() } else { rpm.abs() };
    }
    if old > 0.0 {
        let factor = old / rpm.abs();
        if let Some(c) = &mut s.conveying {
            c.discard *= factor;
            for stage in s.stages.iter_mut().filter(|st| st.name == c.stage) {
                match &mut stage.end {
                    StageEnd::Duration(d) => *d *= factor,
                    StageEnd::Settled {
                        min_duration,
                        max_duration,
                        ..
                    } => {
                        *min_duration *= factor;
                        *max_duration *= factor;
                    }
                }
            }
        }
    }
    s
}

/// Runs `scene` once per speed (|rpm|; the scene's sense of rotation kept, the conveying
/// stage and its discarded start-up scaled to the same number of turns, [`at_speed`]) into
/// `out/rpm<N>/`, then writes `out/mass_flow_vs_rpm.csv` and the plot `out/mass_flow_vs_rpm_plot.png|svg|csv`.
pub fn rpm_sweep(
    scene: &Scene,
    speeds: &[Real],
    out: &Path,
    progress: Option<Progress>,
    force_dt: bool,
    keep_going: bool,
    reuse: bool,
) -> Result<Vec<(Real, RunSummary)>, String> {
    let body = scene
        .conveying
        .as_ref()
        .map(|c| c.body.clone())
        .ok_or_else(|| {
            format!(
                "{}: --sweep needs a [conveying] section",
                scene.source.display()
            )
        })?;
    let variants = speeds
        .iter()
        .map(|&rpm| (rpm, at_speed(scene, &body, rpm)))
        .collect();
    let sweep = ConveyingSweep {
        variable: "rpm",
        run_prefix: "rpm",
        name: "mass_flow_vs_rpm",
        title: "Screw feeder: mass flow vs speed",
        ratio_title: "Screw feeder: mass flow over Eq. (7) (measured fill) vs speed",
        x_label: "screw speed (rpm)",
        dem_label: "DEM (SDF screw)",
    };
    sweep.run(variants, out, progress, force_dt, keep_going, reuse)
}

/// Runs a scene whose conveying body is built of particles once per r_s / r_p (the body's
/// species diameter set to the ratio times the first mobile species' diameter) into
/// `out/ratio<R>/`, then writes `out/mass_flow_vs_screw_ratio.csv` and the plot
/// `out/mass_flow_vs_screw_ratio_plot.png|svg|csv` and `..._ratio_plot` (DEM / Eq. (7), paper
/// A Fig. 4).
pub fn screw_ratio_sweep(
    scene: &Scene,
    ratios: &[Real],
    out: &Path,
    progress: Option<Progress>,
    force_dt: bool,
    keep_going: bool,
    reuse: bool,
) -> Result<Vec<(Real, RunSummary)>, String> {
    let file = scene.source.display();
    let c = scene
        .conveying
        .as_ref()
        .ok_or_else(|| format!("{file}: --sweep screw_ratio needs a [conveying] section"))?;
    let screw_species = scene
        .bodies
        .iter()
        .find(|b| b.name == c.body)
        .and_then(|b| b.particles.as_ref())
        .map(|p| p.species)
        .ok_or_else(|| {
            format!(
                "{file}: --sweep screw_ratio needs the conveying body `{}` built of particles (particles = {{ species = ..., lattice = \"fcc\" }})",
                c.body
            )
        })?;
    let grain = scene
        .species
        .iter()
        .find(|s| !s.frozen)
        .map(|s| s.diameter)
        .ok_or_else(|| format!("{file}: --sweep screw_ratio: no mobile species"))?;
    let variants = ratios
        .iter()
        .map(|&ratio| {
            let mut s = scene.clone();
            s.species[screw_species].diameter = ratio * grain;
            (ratio, s)
        })
        .collect();
    let sweep = ConveyingSweep {
        variable: "screw_ratio",
        run_prefix: "ratio",
        name: "mass_flow_vs_screw_ratio",
        title: "Particle-built screw at 100 rpm: mass flow vs screw-particle size",
        ratio_title: "Particle-built screw: mass flow over Eq. (7) (measured fill) vs r_s / r_p",
        x_label: "r_s / r_p",
        dem_label: "DEM (particle screw)",
    };
    sweep.run(variants, out, progress, force_dt, keep_going, reuse)
}

/// A sweep of a conveying scene over one variable: one run per value into
/// `out/<run_prefix><value>/`, the table `out/<name>.csv` (rewritten after every run, so an
/// interrupted sweep keeps what it measured), the plot `out/<name>_plot.png|svg|csv` against
/// Eq. (7) and `out/<name>_ratio_plot.png|svg|csv` of DEM / Eq. (7).
struct ConveyingSweep {
    /// The CSV's first column.
    variable: &'static str,
    run_prefix: &'static str,
    name: &'static str,
    title: &'static str,
    /// Title of the DEM / Eq. (7) plot.
    ratio_title: &'static str,
    x_label: &'static str,
    dem_label: &'static str,
}

impl ConveyingSweep {
    fn run(
        &self,
        variants: Vec<(Real, Scene)>,
        out: &Path,
        progress: Option<Progress>,
        force_dt: bool,
        keep_going: bool,
        reuse: bool,
    ) -> Result<Vec<(Real, RunSummary)>, String> {
        let mut results = Vec::new();
        let mut csv = CsvBuffer::new([
            self.variable,
            "screw_particles",
            "mass_flow_kg_s",
            "mass_flow_std_error_kg_s",
            "fill_ratio",
            "bulk_density_kg_m3",
            "eq7_mass_flow_kg_s",
            "eq7_full_mass_flow_kg_s",
            "ratio_to_eq7",
            "drive_torque_nm",
            "drive_power_w",
            "wall_s",
        ]);
        let path = out.join(format!("{}.csv", self.name));
        for (x, scene) in variants {
            let options = RunOptions {
                out_dir: out.join(format!("{}{x}", self.run_prefix)),
                progress: progress.clone(),
                force_dt,
                keep_going,
                ..Default::default()
            };
            let summary = run_or_reuse(&scene, &options, reuse)?;
            let c = summary.conveying.as_ref();
            let f = |v: Option<Real>| v.map_or(String::new(), |x| format!("{x:.6e}"));
            csv.row([
                x.to_string(),
                summary.n_body_particles.to_string(),
                f(c.map(|c| c.mass_flow_kg_s)),
                f(c.map(|c| c.mass_flow_std_error_kg_s)),
                f(c.map(|c| c.fill_ratio)),
                f(c.map(|c| c.bulk_density_kg_m3)),
                f(c.map(|c| c.eq7_mass_flow_kg_s)),
                f(c.map(|c| c.eq7_full_mass_flow_kg_s)),
                f(c.map(|c| c.ratio_to_eq7)),
                f(c.map(|c| c.drive_torque_nm)),
                f(c.map(|c| c.drive_power_w)),
                format!("{:.1}", summary.wall_s),
            ]);
            csv.bytes()
                .and_then(|bytes| write_atomic(&path, bytes))
                .map_err(|e| format!("cannot write {}: {e}", path.display()))?;
            results.push((x, summary));
        }
        let points = |v: &dyn Fn(&cgdem_core::analysis::conveying::ConveyingSummary) -> Real| {
            results
                .iter()
                .filter_map(|(x, s)| s.conveying.as_ref().map(|c| (*x, v(c))))
                .collect::<Vec<_>>()
        };
        let errors: Vec<Real> = points(&|c| c.mass_flow_std_error_kg_s)
            .iter()
            .map(|p| p.1)
            .collect();
        let fig = Figure::new(self.title, self.x_label, "mass flow (kg/s)")
            .with_series(
                Series::new(self.dem_label, points(&|c| c.mass_flow_kg_s))
                    .style(SeriesStyle::Markers)
                    .y_err(errors),
            )
            .with_series(
                Series::new(
                    "Eq. (7), measured a and bulk density",
                    points(&|c| c.eq7_mass_flow_kg_s),
                )
                .style(SeriesStyle::Line),
            )
            .with_series(
                Series::new("Eq. (7), a = 1", points(&|c| c.eq7_full_mass_flow_kg_s))
                    .style(SeriesStyle::Dashed),
            );
        write_figure(out, &format!("{}_plot", self.name), &fig).map_err(|e| e.to_string())?;
        // The same runs as DEM / Eq. (7) with the measured fill ratio: each point carries
        // its own fill, so this is the plot where a trend towards theory (1) shows.
        let ratios = points(&|c| c.ratio_to_eq7);
        let span = ratios
            .iter()
            .map(|p| p.0)
            .fold(None, |acc: Option<(Real, Real)>, x| {
                Some(acc.map_or((x, x), |(lo, hi)| (lo.min(x), hi.max(x))))
            });
        let ratio_errors: Vec<Real> =
            points(&|c| c.mass_flow_std_error_kg_s / c.eq7_mass_flow_kg_s)
                .iter()
                .map(|p| p.1)
                .collect();
        let mut fig = Figure::new(self.ratio_title, self.x_label, "mass flow / Eq. (7)")
            .with_series(
                Series::new(self.dem_label, ratios)
                    .style(SeriesStyle::Markers)
                    .y_err(ratio_errors),
            );
        if let Some((lo, hi)) = span {
            fig = fig.with_series(
                Series::new("Eq. (7) (theory)", vec![(lo, 1.0), (hi, 1.0)])
                    .style(SeriesStyle::Dashed),
            );
        }
        write_figure(out, &format!("{}_ratio_plot", self.name), &fig).map_err(|e| e.to_string())?;
        Ok(results)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_speed_sweep_runs_the_same_turns_at_every_speed() {
        crate::at_repo_root();
        let scene = Scene::load(Path::new("validation/cases/screw_feeder_nightly.toml")).unwrap();
        let s = at_speed(&scene, "screw", 20.0);
        let screw = s.bodies.iter().find(|b| b.name == "screw").unwrap();
        assert_eq!(screw.rpm, -20.0);
        let c = s.conveying.as_ref().unwrap();
        // 100 rpm: 1.2 s discarded (2 turns) of 2.4 s (4 turns); 20 rpm: 6 s of 12 s.
        assert!((c.discard - 6.0).abs() < 1e-12);
        let convey = s.stages.iter().find(|st| st.name == "convey").unwrap();
        assert_eq!(convey.end, StageEnd::Duration(12.0));
        let settle = s.stages.iter().find(|st| st.name == "settle").unwrap();
        assert_eq!(settle.end, StageEnd::Duration(0.5));
    }

    #[test]
    fn sweep_lists_parse_with_their_key() {
        assert_eq!(
            Sweep::parse("diameter=1e-6, 3e-6,1e-3").unwrap(),
            Sweep::Diameter(vec![1e-6, 3e-6, 1e-3])
        );
        assert_eq!(
            Sweep::parse("rpm=20,40").unwrap(),
            Sweep::Rpm(vec![20.0, 40.0])
        );
    }

    #[test]
    fn bad_sweeps_name_the_key_the_value_and_what_is_allowed() {
        let cases = [
            ("size=1e-6", "unknown key `size`", "diameter"),
            ("diameter 1e-6", "expected KEY=V1,V2", "rpm"),
            ("diameter=1e-6,-3e-6", "value `-3e-6`", "> 0 (m)"),
            ("diameter=0", "value `0`", "> 0 (m)"),
            ("diameter=1e-6,abc", "value `abc`", "a number (m)"),
            ("diameter=", "value ``", "a number"),
            ("diameter=1e-6,1e-6", "value `1e-6`", "each value once"),
            ("rpm=20,inf", "value `inf`", "rev/min"),
        ];
        for (text, what, allowed) in cases {
            let message = Sweep::parse(text).unwrap_err().to_string();
            assert!(
                message.starts_with("--sweep")
                    && message.contains(what)
                    && message.contains(allowed),
                "{text}: {message}"
            );
        }
    }
}
