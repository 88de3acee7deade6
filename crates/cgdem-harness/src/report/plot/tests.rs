use super::*;

/// A fresh directory per test; `CGDEM_KEEP_TEST_OUTPUT=DIR` writes there
/// instead so the figures can be looked at.
pub(crate) fn test_dir(name: &str) -> PathBuf {
    let base = std::env::var_os("CGDEM_KEEP_TEST_OUTPUT")
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            std::env::temp_dir().join(format!("cgdem-report-{}", std::process::id()))
        });
    let dir = base.join(name);
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    dir
}

fn read_csv(path: &Path) -> (String, Vec<Vec<String>>) {
    let text = fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().to_string();
    let rows = lines.map(split_csv_line).collect();
    (header, rows)
}

/// RFC 4180 fields of one line (no embedded newlines in these tests).
fn split_csv_line(line: &str) -> Vec<String> {
    let (mut fields, mut cur, mut quoted) = (Vec::new(), String::new(), false);
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                cur.push('"');
                chars.next();
            }
            ('"', _) => quoted = !quoted,
            (',', false) => fields.push(std::mem::take(&mut cur)),
            _ => cur.push(c),
        }
    }
    fields.push(cur);
    fields
}

pub(crate) fn restitution_figure() -> Figure {
    let v: Vec<f64> = (0..12).map(|i| 0.01 * 2f64.powi(i)).collect();
    let dem: Vec<(f64, f64)> = v.iter().map(|&v| (v, 0.9 * v.powf(-0.02))).collect();
    let err: Vec<f64> = v
        .iter()
        .map(|&v| 0.02 + 0.01 * v.ln().abs() / 5.0)
        .collect();
    let theory: Vec<(f64, f64)> = v.iter().map(|&v| (v, 0.88 * v.powf(-0.02))).collect();
    Figure::new(
        "Coefficient of restitution vs impact velocity",
        "impact velocity v [m/s]",
        "restitution e [-]",
    )
    .log_x()
    .log_y()
    .with_series(
        Series::new("cgdem (Hertz + damping)", dem)
            .style(SeriesStyle::LineMarkers)
            .y_err(err),
    )
    .with_series(Series::new("analytic, 1/3 + 1e-17 drift", theory).style(SeriesStyle::Dashed))
}

#[test]
fn two_series_log_axes_error_bars_write_png_svg_and_round_tripping_csv() {
    let dir = test_dir("two_series");
    let fig = restitution_figure();
    let files = write_figure(&dir, "restitution", &fig).unwrap();
    for p in [&files.png, &files.svg, &files.csv] {
        assert!(
            fs::metadata(p).unwrap().len() > 100,
            "{} too small",
            p.display()
        );
    }
    assert_eq!(&fs::read(&files.png).unwrap()[..4], b"\x89PNG");
    let svg = fs::read_to_string(&files.svg).unwrap();
    assert!(svg.contains("<svg") && svg.contains("sans-serif"));
    assert!(svg.contains("impact velocity v [m/s]"));
    assert_eq!(files.plotted, 24);
    assert_eq!(files.note(), None);

    let (header, rows) = read_csv(&files.csv);
    assert_eq!(header, "series,x,y,y_err");
    assert_eq!(rows.len(), 24);
    let mut i = 0;
    for s in &fig.series {
        for (k, &(x, y)) in s.points.iter().enumerate() {
            let row = &rows[i];
            assert_eq!(row[0], s.label);
            // Exact equality: the CSV keeps full precision.
            assert_eq!(row[1].parse::<f64>().unwrap(), x);
            assert_eq!(row[2].parse::<f64>().unwrap(), y);
            match &s.y_err {
                Some(e) => assert_eq!(row[3].parse::<f64>().unwrap(), e[k]),
                None => assert_eq!(row[3], ""),
            }
            i += 1;
        }
    }
}

#[test]
fn nan_and_non_positive_points_are_skipped_and_counted_but_kept_in_csv() {
    let dir = test_dir("nan");
    let fig = Figure::new("Kinetic energy", "time t [s]", "kinetic energy E [J]")
        .log_y()
        .with_series(
            Series::new(
                "run",
                vec![
                    (0.0, 1.0),
                    (1.0, f64::NAN),
                    (f64::INFINITY, 2.0),
                    (2.0, 0.5),
                    (3.0, 0.0),
                    (4.0, -1.0),
                ],
            )
            .style(SeriesStyle::Markers),
        );
    let files = write_figure(&dir, "energy", &fig).unwrap();
    assert_eq!(files.plotted, 2);
    assert_eq!(files.skipped_non_finite, 2);
    assert_eq!(files.skipped_non_positive, 2);
    let note = files.note().unwrap();
    assert!(note.contains("2 points with NaN/inf"), "{note}");
    let (_, rows) = read_csv(&files.csv);
    assert_eq!(rows.len(), 6);
    assert!(rows[1][2].parse::<f64>().unwrap().is_nan());
    assert_eq!(rows[2][1].parse::<f64>().unwrap(), f64::INFINITY);
}

#[test]
fn empty_single_point_and_empty_series_still_draw() {
    let dir = test_dir("edge");
    let empty = Figure::new("Nothing yet", "x [m]", "y [m]");
    assert_eq!(write_figure(&dir, "empty", &empty).unwrap().plotted, 0);
    let one = Figure::new("One point", "x [m]", "y [m]")
        .with_series(Series::new("single", vec![(2.0, 3.0)]).style(SeriesStyle::Markers))
        .with_series(Series::new("missing", vec![]));
    assert_eq!(write_figure(&dir, "one", &one).unwrap().plotted, 1);
    let close =
        |a: (f64, f64), b: (f64, f64)| (a.0 - b.0).abs() < 1e-12 && (a.1 - b.1).abs() < 1e-12;
    assert!(close(fit_range(&[3.0], false), (2.67, 3.33)));
    assert!(close(fit_range(&[0.0], false), (-1.1, 1.1)));
    let (lo, hi) = fit_range(&[100.0], true);
    assert!(lo < 100.0 && hi > 100.0);
}

#[test]
fn mismatched_errors_and_bad_stems_are_rejected() {
    let dir = test_dir("reject");
    let fig = Figure::new("t", "x", "y")
        .with_series(Series::new("a", vec![(0.0, 1.0)]).y_err(vec![0.1, 0.2]));
    assert!(matches!(
        write_figure(&dir, "a", &fig),
        Err(PlotError::ErrorLengthMismatch {
            points: 1,
            errors: 2,
            ..
        })
    ));
    for stem in ["", "../x", "a/b", ".hidden", "a b"] {
        assert!(matches!(
            write_figure(&dir, stem, &Figure::new("t", "x", "y")),
            Err(PlotError::InvalidStem(_))
        ));
    }
}

#[test]
fn grouped_bar_chart_writes_all_three_files() {
    let dir = test_dir("bars");
    let mut bars = Vec::new();
    for (case, base) in [
        ("WCA 4k", 2.0e6),
        ("hopper 50k", 8.0e5),
        ("drum, 200k", 3.1e5),
    ] {
        for (code, f) in [("cgdem", 1.0), ("LIGGGHTS", 0.7), ("LAMMPS", 0.8)] {
            bars.push((
                case.to_string(),
                code.to_string(),
                base * f,
                Some(0.05 * base),
            ));
        }
    }
    bars.push(("drum, 200k".into(), "cgdem".into(), f64::NAN, None));
    let files = write_bar_chart(
        &dir,
        "throughput",
        "Throughput per code and case",
        "throughput [particle steps/s]",
        &bars,
    )
    .unwrap();
    assert_eq!(files.skipped_non_finite, 1);
    let (header, rows) = read_csv(&files.csv);
    assert_eq!(header, "series,x,y,y_err");
    assert_eq!(rows.len(), 10);
    assert_eq!(rows[6][1], "drum, 200k");
    assert!(fs::metadata(&files.png).unwrap().len() > 1000);
}

#[test]
fn log_ticks_suit_wide_and_narrow_spans() {
    assert_eq!(log_ticks(0.008, 25.0, 10), vec![0.01, 0.1, 1.0, 10.0]);
    assert_eq!(log_ticks(1e-12, 1e12, 10).len(), 9);
    assert_eq!(log_ticks(0.15, 2.5, 10), vec![0.2, 0.5, 1.0, 2.0]);
    let narrow = log_ticks(0.75, 1.05, 10);
    assert!(narrow.len() >= 3, "{narrow:?}");
    assert!(narrow.iter().all(|v| (0.75..=1.05).contains(v)));
}

#[test]
fn tick_labels_are_short() {
    assert_eq!(format_tick(0.30000000000000004), "0.3");
    assert_eq!(format_tick(1e-6), "1e-6");
    assert_eq!(format_tick(2.5e7), "2.5e7");
    assert_eq!(format_tick(1000.0), "1000");
    assert_eq!(format_tick(0.0), "0");
}
