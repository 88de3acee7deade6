//! `cgdem geometry`: the seed's screw-feeder meshes and the SDF accuracy study.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::Subcommand;

use cgdem_core::geometry::accuracy::format_accuracy_table;
use cgdem_core::geometry::screw_feeder::{self, ScrewFeederSpec};
use cgdem_harness::report::sdf_study::write_sdf_accuracy_study;

#[derive(Subcommand)]
pub(super) enum GeometryCommand {
    /// Write screw.stl, casing.stl, hopper.stl and insertion.stl of the screw feeder of
    /// Hirose's paper (reference/SCREW_GEOMETRY.md) and print the layout.
    ScrewFeeder {
        #[arg(long)]
        out: PathBuf,
    },
    /// Measure SDF-grid error, memory and build time against cell size (sphere, cylinder,
    /// helicoid flight); writes sdf_accuracy.csv and plots.
    SdfAccuracy {
        #[arg(long)]
        out: PathBuf,
        /// Cell sizes, m.
        #[arg(long, value_delimiter = ',', default_values_t = [0.016, 0.008, 0.004, 0.002])]
        cells: Vec<f64>,
        /// Sample points per grid (within 2 cells of the surface).
        #[arg(long, default_value_t = 5000)]
        samples: usize,
    },
}

pub(super) fn execute(command: GeometryCommand) -> ExitCode {
    match command {
        GeometryCommand::ScrewFeeder { out } => {
            let spec = ScrewFeederSpec::default();
            super::exit_with(screw_feeder::write_stl_files(&spec, &out).map(|paths| {
                for p in paths {
                    println!("wrote {}", p.display());
                }
                println!("{:#?}", spec.layout());
            }))
        }
        GeometryCommand::SdfAccuracy {
            out,
            cells,
            samples,
        } => {
            if cells.is_empty() || cells.iter().any(|&h| !(h > 0.0 && h.is_finite())) {
                eprintln!("error: --cells must be positive cell sizes in metres, got {cells:?}");
                return ExitCode::from(2);
            }
            let study = write_sdf_accuracy_study(&out, &cells, samples);
            super::exit_with(study.map(|(rows, paths)| {
                print!("{}", format_accuracy_table(&rows));
                for p in paths {
                    println!("wrote {}", p.display());
                }
            }))
        }
    }
}
