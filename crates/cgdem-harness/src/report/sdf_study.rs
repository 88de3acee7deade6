//! The SDF accuracy study (paper A sec. 5): distance and normal error, memory and build
//! time of [`SdfGrid`](cgdem_core::geometry::SdfGrid)s against cell size for a sphere, a
//! cylinder and a helicoid flight, written as CSV and plots.

use std::path::{Path, PathBuf};

use crate::report::{write_figure, Figure, Series, SeriesStyle};
use cgdem_core::geometry::{sdf_accuracy, AccuracyRow, ScrewFlight, TestShape};
use cgdem_core::io::{write_atomic, CsvBuffer};
use cgdem_core::math::Real;

/// The study's shapes: sizes of the seed's screw feeder (0.1 m radius; the flight of the
/// seed's screw, one turn).
pub fn study_shapes() -> Vec<TestShape> {
    vec![
        TestShape::Sphere {
            radius: 0.1,
            subdivisions: 5,
        },
        TestShape::Cylinder {
            radius: 0.1,
            height: 0.2,
            segments: 256,
        },
        TestShape::ScrewFlight {
            flight: ScrewFlight {
                inner_radius: 0.0255,
                outer_radius: 0.1025,
                pitch: 0.15,
                thickness: 0.008,
                turns: 1.0,
            },
            segments_per_turn: 192,
            radial_segments: 8,
        },
    ]
}

/// Runs the study and writes `sdf_accuracy.csv` and three figures into `dir`; returns the
/// rows and the files written.
pub fn write_sdf_accuracy_study(
    dir: &Path,
    cell_sizes: &[Real],
    samples: usize,
) -> Result<(Vec<AccuracyRow>, Vec<PathBuf>), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let mut rows = Vec::new();
    for shape in study_shapes() {
        rows.extend(sdf_accuracy(&shape, cell_sizes, samples, 42).map_err(|e| e.to_string())?);
    }
    let mut csv = CsvBuffer::new([
        "shape",
        "triangles",
        "cell_size_m",
        "max_abs_distance_error_m",
        "rms_distance_error_m",
        "max_normal_error_deg",
        "p95_normal_error_deg",
        "memory_bytes",
        "build_seconds",
        "samples",
        "normal_samples",
    ]);
    for r in &rows {
        csv.row([
            r.shape.to_string(),
            r.triangles.to_string(),
            format!("{:e}", r.cell_size),
            format!("{:e}", r.max_abs_distance_error),
            format!("{:e}", r.rms_distance_error),
            format!("{:e}", r.max_normal_error_deg),
            format!("{:e}", r.p95_normal_error_deg),
            r.memory_bytes.to_string(),
            format!("{:e}", r.build_seconds),
            r.samples.to_string(),
            r.normal_samples.to_string(),
        ]);
    }
    let csv_path = dir.join("sdf_accuracy.csv");
    csv.bytes()
        .and_then(|bytes| write_atomic(&csv_path, bytes))
        .map_err(|e| format!("cannot write {}: {e}", csv_path.display()))?;
    let mut written = vec![csv_path];

    let mut names: Vec<String> = rows.iter().map(|r| r.shape.clone()).collect();
    names.dedup();
    let series = |name: &str, value: &dyn Fn(&AccuracyRow) -> Real| -> Vec<(f64, f64)> {
        rows.iter()
            .filter(|r| r.shape == name)
            .map(|r| (r.cell_size, value(r)))
            .collect()
    };
    let mut error = Figure::new("SDF grid distance error", "cell size (m)", "error (m)")
        .log_x()
        .log_y();
    let mut memory = Figure::new("SDF grid memory", "cell size (m)", "memory (bytes)")
        .log_x()
        .log_y();
    let mut build = Figure::new("SDF grid build time", "cell size (m)", "build time (s)")
        .log_x()
        .log_y();
    for name in &names {
        let short = name.split_whitespace().next().unwrap_or(name);
        error = error
            .with_series(
                Series::new(
                    format!("{short} max"),
                    series(name, &|r| r.max_abs_distance_error),
                )
                .style(SeriesStyle::LineMarkers),
            )
            .with_series(
                Series::new(
                    format!("{short} rms"),
                    series(name, &|r| r.rms_distance_error),
                )
                .style(SeriesStyle::Dashed),
            );
        memory = memory.with_series(
            Series::new(short, series(name, &|r| r.memory_bytes as Real))
                .style(SeriesStyle::LineMarkers),
        );
        build = build.with_series(
            Series::new(short, series(name, &|r| r.build_seconds)).style(SeriesStyle::LineMarkers),
        );
    }
    for (stem, fig) in [
        ("sdf_error", &error),
        ("sdf_memory", &memory),
        ("sdf_build_time", &build),
    ] {
        let files = write_figure(dir, stem, fig).map_err(|e| e.to_string())?;
        written.push(files.png);
        written.push(files.svg);
    }
    Ok((rows, written))
}
