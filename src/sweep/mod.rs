//! Screw-speed sweep: runs a conveying scene at several rpm and writes the mass flow against
//! speed with Eq. (7) (paper A Fig. 8).

use std::path::Path;
use std::time::Instant;

use crate::io::write_atomic;
use crate::math::Real;
use crate::report::{write_figure, Figure, Series, SeriesStyle};
use crate::run::{run, RunOptions, RunSummary};
use crate::scene::Scene;

/// Runs `scene` once per speed (|rpm|; the scene's sense of rotation is kept) into
/// `out/rpm<N>/`, then writes `out/mass_flow_vs_rpm.csv` and the plot `out/mass_flow_vs_rpm_plot.png|svg|csv`.
pub fn rpm_sweep(
    scene: &Scene,
    speeds: &[Real],
    out: &Path,
    quiet: bool,
    force_dt: bool,
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
    let mut results = Vec::new();
    let mut csv = String::from("rpm,mass_flow_kg_s,mass_flow_std_error_kg_s,fill_ratio,bulk_density_kg_m3,eq7_mass_flow_kg_s,eq7_full_mass_flow_kg_s,drive_torque_nm,drive_power_w,wall_s\n");
    for &rpm in speeds {
        let mut s = scene.clone();
        for b in s.bodies.iter_mut().filter(|b| b.name == body) {
            b.rpm = if b.rpm < 0.0 { -rpm.abs() } else { rpm.abs() };
        }
        let options = RunOptions {
            out_dir: out.join(format!("rpm{rpm}")),
            quiet,
            force_dt,
        };
        let started = Instant::now();
        let summary = run(&s, &options).map_err(|e| e.to_string())?;
        let wall = started.elapsed().as_secs_f64();
        let c = summary.conveying.as_ref();
        let f = |v: Option<Real>| v.map_or(String::new(), |x| format!("{x:.6e}"));
        csv += &format!(
            "{rpm},{},{},{},{},{},{},{},{},{wall:.1}\n",
            f(c.map(|c| c.mass_flow_kg_s)),
            f(c.map(|c| c.mass_flow_std_error_kg_s)),
            f(c.map(|c| c.fill_ratio)),
            f(c.map(|c| c.bulk_density_kg_m3)),
            f(c.map(|c| c.eq7_mass_flow_kg_s)),
            f(c.map(|c| c.eq7_full_mass_flow_kg_s)),
            f(c.map(|c| c.drive_torque_nm)),
            f(c.map(|c| c.drive_power_w)),
        );
        write_atomic(&out.join("mass_flow_vs_rpm.csv"), csv.as_bytes()).map_err(|e| {
            format!(
                "cannot write {}: {e}",
                out.join("mass_flow_vs_rpm.csv").display()
            )
        })?;
        results.push((rpm, summary));
    }
    let points = |v: &dyn Fn(&crate::analysis::conveying::ConveyingSummary) -> Real| {
        results
            .iter()
            .filter_map(|(rpm, s)| s.conveying.as_ref().map(|c| (*rpm, v(c))))
            .collect::<Vec<_>>()
    };
    let measured = points(&|c| c.mass_flow_kg_s);
    let errors: Vec<Real> = points(&|c| c.mass_flow_std_error_kg_s)
        .iter()
        .map(|p| p.1)
        .collect();
    let fig = Figure::new(
        "Screw feeder: mass flow vs speed",
        "screw speed (rpm)",
        "mass flow (kg/s)",
    )
    .with_series(
        Series::new("DEM (SDF screw)", measured)
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
    write_figure(out, "mass_flow_vs_rpm_plot", &fig).map_err(|e| e.to_string())?;
    Ok(results)
}
