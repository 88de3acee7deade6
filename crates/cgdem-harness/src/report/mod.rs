//! Validation reports: figures (PNG + SVG + CSV) and a self-contained HTML
//! page. Only the harness uses this module; the solver core never does.

pub mod html;
pub mod plot;
pub mod run_figures;
pub mod sdf_study;

pub use html::{Cell, Report, Section, Status, Table};
pub use plot::{
    write_bar_chart, write_figure, Figure, FigureFiles, LegendPosition, PlotError, Series,
    SeriesStyle,
};
