//! The figure `cgdem run` leaves beside its CSV files, of what the run measured: the heap
//! profile with the fitted line (repose scenes), the mass flow per block (conveying scenes),
//! the pore-size distribution (packing scenes). Each is a PNG, an SVG and the CSV of its
//! points (`write_figure`).

use std::path::Path;

use cgdem_core::analysis::heap::{self, HeapProfile};
use cgdem_core::run::RunSummary;
use cgdem_core::scene::Scene;

use crate::csv_table::CsvTable;

use super::{write_figure, Figure, FigureFiles, Series, SeriesStyle};

/// Writes the figures the run's measurements allow (none for a scene that measures nothing)
/// into `out_dir`, reading the CSV files the run wrote there.
pub fn write_run_figures(
    scene: &Scene,
    summary: &RunSummary,
    out_dir: &Path,
) -> Result<Vec<FigureFiles>, String> {
    let mut files = Vec::new();
    if let Some(figure) = heap_figure(scene, summary, out_dir)? {
        files.push(write_figure(out_dir, "profile_plot", &figure).map_err(|e| e.to_string())?);
    }
    if let Some(figure) = mass_flow_figure(summary) {
        files.push(write_figure(out_dir, "mass_flow_plot", &figure).map_err(|e| e.to_string())?);
    }
    if let Some(figure) = pore_size_figure(summary, out_dir)? {
        files.push(write_figure(out_dir, "pore_size_plot", &figure).map_err(|e| e.to_string())?);
    }
    Ok(files)
}

/// The numbers of the columns `names` of the CSV file `path`, one vector per row.
fn read_numbers(path: &Path, names: &[&str]) -> Result<Vec<Vec<f64>>, String> {
    CsvTable::read(path)
        .and_then(|t| t.numbers(names))
        .map_err(|e| e.to_string())
}

/// The heap profile (`profile.csv`) and the least-squares line through the bins the repose
/// rule keeps; the headline angle in the title.
fn heap_figure(
    scene: &Scene,
    summary: &RunSummary,
    out_dir: &Path,
) -> Result<Option<Figure>, String> {
    let (Some(rule), Some(angle)) = (&scene.repose, summary.repose_angle_deg) else {
        return Ok(None);
    };
    let path = out_dir.join("profile.csv");
    let rows = read_numbers(&path, &["x_m", "height_m"])?;
    if rows.len() < 2 {
        return Ok(None);
    }
    let points: Vec<(f64, f64)> = rows.iter().map(|r| (r[0], r[1])).collect();
    let bin_width = points[1].0 - points[0].0;
    let profile = HeapProfile {
        wall_x: points[0].0 - 0.5 * bin_width,
        bin_width,
        heights: points.iter().map(|p| p.1).collect(),
    };
    let mut figure = Figure::new(
        format!(
            "{} (lambda = {}): repose angle {angle:.1} deg, R^2 = {:.3}",
            summary.case,
            summary.lambda,
            summary.repose_fit_r2.unwrap_or(f64::NAN)
        ),
        "distance from the wall x [m]",
        "surface height h [m]",
    )
    .with_series(
        Series::new("heap surface (profile.csv)", points.clone()).style(SeriesStyle::LineMarkers),
    );
    // The same rule as the run's measurement, on the profile it wrote.
    let fit = heap::repose_angle(
        &profile,
        2.0 * scene.max_diameter(),
        rule.exclude_wall_fraction,
        rule.exclude_toe_fraction,
    );
    if let Ok(fit) = fit {
        let window: Vec<(f64, f64)> = points
            .iter()
            .copied()
            .filter(|&(x, _)| x >= fit.fit_from_x && x <= fit.fit_to_x)
            .collect();
        let n = window.len() as f64;
        let (mx, my) = (
            window.iter().map(|p| p.0).sum::<f64>() / n,
            window.iter().map(|p| p.1).sum::<f64>() / n,
        );
        let slope = -fit.angle_deg.to_radians().tan();
        let line = |x: f64| my + slope * (x - mx);
        figure = figure.with_series(
            Series::new(
                format!("fitted line, {:.1} deg", fit.angle_deg),
                vec![
                    (fit.fit_from_x, line(fit.fit_from_x)),
                    (fit.fit_to_x, line(fit.fit_to_x)),
                ],
            )
            .style(SeriesStyle::Dashed),
        );
    }
    Ok(Some(figure))
}

/// Mass flow through the outlet plane per block of the measuring window, with the mean and
/// its standard error.
fn mass_flow_figure(summary: &RunSummary) -> Option<Figure> {
    let c = summary.conveying.as_ref()?;
    let blocks = c.block_mass_flow_kg_s.len();
    if blocks == 0 {
        return None;
    }
    let width = (c.window_s[1] - c.window_s[0]) / blocks as f64;
    let centre = |k: usize| c.window_s[0] + (k as f64 + 0.5) * width;
    let per_block: Vec<(f64, f64)> = c
        .block_mass_flow_kg_s
        .iter()
        .enumerate()
        .map(|(k, &m)| (centre(k), m))
        .collect();
    let ends = [c.window_s[0], c.window_s[1]];
    Some(
        Figure::new(
            format!(
                "{} at {} rpm: mass flow {:.4} +- {:.4} kg/s ({blocks} blocks)",
                summary.case, c.rpm, c.mass_flow_kg_s, c.mass_flow_std_error_kg_s
            ),
            "time (block centre) t [s]",
            "mass flow [kg/s]",
        )
        .with_series(Series::new("per block", per_block).style(SeriesStyle::Markers))
        .with_series(
            Series::new(
                "mean",
                ends.iter().map(|&t| (t, c.mass_flow_kg_s)).collect(),
            )
            .style(SeriesStyle::Line),
        )
        .with_series(
            Series::new(
                "mean +- standard error",
                ends.iter()
                    .map(|&t| (t, c.mass_flow_kg_s + c.mass_flow_std_error_kg_s))
                    .chain(
                        ends.iter()
                            .rev()
                            .map(|&t| (t, c.mass_flow_kg_s - c.mass_flow_std_error_kg_s)),
                    )
                    .collect(),
            )
            .style(SeriesStyle::Dashed),
        ),
    )
}

/// The volume-weighted pore-size distribution (`pore_size.csv`), porosity in the title.
fn pore_size_figure(summary: &RunSummary, out_dir: &Path) -> Result<Option<Figure>, String> {
    let Some(p) = &summary.packing else {
        return Ok(None);
    };
    let rows = read_numbers(
        &out_dir.join("pore_size.csv"),
        &["diameter_lo", "diameter_hi", "fraction", "cumulative"],
    )?;
    let um = 1e6;
    let fraction: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| (0.5 * (r[0] + r[1]) * um, r[2]))
        .collect();
    let cumulative: Vec<(f64, f64)> = rows.iter().map(|r| (r[1] * um, r[3])).collect();
    Ok(Some(
        Figure::new(
            format!(
                "{}: porosity {:.3}, mean pore diameter {:.3} d (d = {} um)",
                summary.case,
                p.porosity,
                p.mean_pore_diameter_m / p.diameter_m,
                super::plot::format_tick(p.diameter_m * um)
            ),
            "pore diameter [um]",
            "fraction of the void volume",
        )
        .with_series(Series::new("per bin", fraction).style(SeriesStyle::LineMarkers))
        .with_series(Series::new("cumulative", cumulative).style(SeriesStyle::Dashed)),
    ))
}
