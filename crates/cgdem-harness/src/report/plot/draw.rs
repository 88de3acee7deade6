//! Drawing a figure or a bar chart on a plotters backend (PNG or SVG alike): the chart,
//! its markers, legend and notes.

use super::*;

pub(super) fn draw_figure<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    fig: &Figure,
    p: &Prepared,
) -> Result<(), String> {
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let (x0, x1) = p.x_range;
    let (y0, y1) = p.y_range;
    match (fig.x_log, fig.y_log) {
        (false, false) => draw_chart(root, fig, p, x0..x1, y0..y1),
        (true, false) => draw_chart(root, fig, p, LogAxis::new(x0, x1), y0..y1),
        (false, true) => draw_chart(root, fig, p, x0..x1, LogAxis::new(y0, y1)),
        (true, true) => draw_chart(root, fig, p, LogAxis::new(x0, x1), LogAxis::new(y0, y1)),
    }?;
    let mut notes = Vec::new();
    if fig.series.iter().all(|s| s.points.is_empty()) {
        notes.push("no data".to_string());
    }
    if let Some(n) = p.files(Path::new(""), "", "").note() {
        notes.push(n);
    }
    draw_note(root, &notes.join(" "))
}

pub(super) fn draw_note<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    note: &str,
) -> Result<(), String> {
    if note.is_empty() {
        return Ok(());
    }
    let (_, h) = root.dim_in_pixel();
    let style = (FONT, 13).into_font().color(&NOTE);
    root.draw(&Text::new(note.to_string(), (8, h as i32 - 18), style))
        .map_err(|e| e.to_string())
}

pub(super) fn draw_chart<DB, XS, YS>(
    root: &DrawingArea<DB, Shift>,
    fig: &Figure,
    p: &Prepared,
    x_spec: XS,
    y_spec: YS,
) -> Result<(), String>
where
    DB: DrawingBackend,
    XS: AsRangedCoord<Value = f64>,
    YS: AsRangedCoord<Value = f64>,
    XS::CoordDescType: Ranged<ValueType = f64> + ValueFormatter<f64>,
    YS::CoordDescType: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    let mut chart = ChartBuilder::on(root)
        .caption(&fig.title, (FONT, 24))
        .margin_top(10)
        .margin_left(10)
        .margin_right(25)
        .margin_bottom(28)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(x_spec, y_spec)
        .map_err(e)?;
    let tick = |v: &f64| format_tick(*v);
    chart
        .configure_mesh()
        .x_desc(&fig.x_label)
        .y_desc(&fig.y_label)
        .axis_desc_style((FONT, 18))
        .label_style((FONT, 14))
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .bold_line_style(GRID)
        .light_line_style(WHITE)
        .draw()
        .map_err(e)?;

    let y_floor = p.y_range.0;
    for (i, (s, pts)) in fig.series.iter().zip(&p.points).enumerate() {
        let mut starts = vec![0];
        starts.extend(&p.breaks[i]);
        starts.push(pts.len());
        let segments = starts.windows(2).map(|w| &pts[w[0]..w[1]]);
        let color = PALETTE[i % PALETTE.len()];
        let line = color.stroke_width(LINE_WIDTH);
        let xy = pts.iter().map(|&(x, y, _)| (x, y));
        let label = if pts.is_empty() && !s.label.is_empty() {
            format!("{} (no data)", s.label)
        } else {
            s.label.clone()
        };
        let marker = Marker::for_series(i);
        let has_line = matches!(s.style, SeriesStyle::Line | SeriesStyle::LineMarkers);
        let has_markers = matches!(s.style, SeriesStyle::Markers | SeriesStyle::LineMarkers);

        // An empty series carries the legend entry, so every style gets one
        // the same way and legend order follows series order.
        if !label.is_empty() {
            let anno = chart
                .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
                .map_err(e)?
                .label(label);
            set_legend(anno, s.style, marker, color);
        }
        match s.style {
            SeriesStyle::Dashed => {
                for seg in segments {
                    let xy = seg.iter().map(|&(x, y, _)| (x, y));
                    chart
                        .draw_series(DashedLineSeries::new(xy, 10, 6, line))
                        .map_err(e)?;
                }
            }
            _ if has_line => {
                for seg in segments {
                    let xy = seg.iter().map(|&(x, y, _)| (x, y));
                    chart.draw_series(LineSeries::new(xy, line)).map_err(e)?;
                }
            }
            _ => {}
        }
        if has_markers {
            let xy: Vec<(f64, f64)> = xy.collect();
            draw_markers(&mut chart, &xy, marker, color)?;
        } else {
            // A line through one point draws nothing: show lone points.
            let lone: Vec<(f64, f64)> = starts
                .windows(2)
                .filter(|w| w[1] - w[0] == 1)
                .map(|w| (pts[w[0]].0, pts[w[0]].1))
                .collect();
            draw_markers(&mut chart, &lone, Marker::Circle, color)?;
        }
        if pts.iter().any(|q| q.2.is_some()) {
            draw_error_bars(&mut chart, pts, fig.y_log, y_floor, color)?;
        }
    }

    if fig.series.iter().any(|s| !s.label.is_empty()) {
        chart
            .configure_series_labels()
            .position(legend_position(fig, p))
            .label_font((FONT, 15))
            .legend_area_size(36)
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK.stroke_width(1))
            .draw()
            .map_err(e)?;
    }
    Ok(())
}

/// Where the legend goes: the figure's choice, or the emptiest corner.
fn legend_position(fig: &Figure, p: &Prepared) -> SeriesLabelPosition {
    match fig.legend {
        LegendPosition::Auto => emptiest_corner(fig, p),
        LegendPosition::UpperLeft => SeriesLabelPosition::UpperLeft,
        LegendPosition::UpperRight => SeriesLabelPosition::UpperRight,
        LegendPosition::LowerLeft => SeriesLabelPosition::LowerLeft,
        LegendPosition::LowerRight => SeriesLabelPosition::LowerRight,
    }
}

/// Vertical error bars of one series; on a log axis a bar that would reach zero or below
/// stops at the axis' floor.
fn draw_error_bars<DB, X, Y>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<X, Y>>,
    pts: &[(f64, f64, Option<f64>)],
    y_log: bool,
    y_floor: f64,
    color: RGBColor,
) -> Result<(), String>
where
    DB: DrawingBackend,
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    chart
        .draw_series(pts.iter().filter_map(|&(x, y, err)| {
            let err = err?;
            let lo = if y_log && y - err <= 0.0 {
                y_floor
            } else {
                y - err
            };
            Some(ErrorBar::new_vertical(
                x,
                lo,
                y,
                y + err,
                color.stroke_width(1),
                8,
            ))
        }))
        .map(|_| ())
        .map_err(|e| e.to_string())
}

/// The plot corner (about a third of the width, a quarter of the height)
/// holding the fewest points; ties keep the conventional upper right.
pub(super) fn emptiest_corner(fig: &Figure, p: &Prepared) -> SeriesLabelPosition {
    let unit = |v: f64, (lo, hi): (f64, f64), log: bool| {
        if log {
            (v.ln() - lo.ln()) / (hi.ln() - lo.ln())
        } else {
            (v - lo) / (hi - lo)
        }
    };
    let corners = [
        (SeriesLabelPosition::UpperRight, true, true),
        (SeriesLabelPosition::UpperLeft, false, true),
        (SeriesLabelPosition::LowerRight, true, false),
        (SeriesLabelPosition::LowerLeft, false, false),
    ];
    let count = |right: bool, upper: bool| {
        p.points
            .iter()
            .flatten()
            .filter(|&&(x, y, _)| {
                let (u, v) = (unit(x, p.x_range, fig.x_log), unit(y, p.y_range, fig.y_log));
                let in_x = if right { u > 0.62 } else { u < 0.38 };
                let in_y = if upper { v > 0.72 } else { v < 0.28 };
                in_x && in_y
            })
            .count()
    };
    corners
        .into_iter()
        .min_by_key(|&(_, r, u)| count(r, u))
        .map(|c| c.0)
        .unwrap_or(SeriesLabelPosition::UpperRight)
}

/// Marker shapes cycle so series stay distinct in greyscale print and when
/// the palette wraps.
#[derive(Clone, Copy, Debug)]
pub(super) enum Marker {
    Circle,
    Triangle,
    Square,
    Cross,
}

impl Marker {
    pub(super) fn for_series(i: usize) -> Self {
        match (i + i / PALETTE.len()) % 4 {
            0 => Self::Circle,
            1 => Self::Triangle,
            2 => Self::Square,
            _ => Self::Cross,
        }
    }
}

/// Draws one marker per point.
pub(super) fn draw_markers<DB, X, Y>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<X, Y>>,
    pts: &[(f64, f64)],
    marker: Marker,
    color: RGBColor,
) -> Result<(), String>
where
    DB: DrawingBackend,
    X: Ranged<ValueType = f64>,
    Y: Ranged<ValueType = f64>,
{
    let r = MARKER_SIZE;
    let fill = color.filled();
    let at = |c: &(f64, f64)| EmptyElement::at(*c);
    let res = match marker {
        Marker::Circle => chart
            .draw_series(pts.iter().map(|c| at(c) + Circle::new((0, 0), r, fill)))
            .map(|_| ()),
        Marker::Triangle => chart
            .draw_series(
                pts.iter()
                    .map(|c| at(c) + TriangleMarker::new((0, 0), r + 1, fill)),
            )
            .map(|_| ()),
        Marker::Square => chart
            .draw_series(
                pts.iter()
                    .map(|c| at(c) + Rectangle::new([(-r, -r), (r, r)], fill)),
            )
            .map(|_| ()),
        Marker::Cross => chart
            .draw_series(
                pts.iter()
                    .map(|c| at(c) + Cross::new((0, 0), r, color.stroke_width(2))),
            )
            .map(|_| ()),
    };
    res.map_err(|e| e.to_string())
}

/// Sets the legend sample: a short stroke in the series' line style and/or
/// its marker. (Each arm has its own element type: plotters' `DynElement`
/// would force `DB: 'static` here.)
pub(super) fn set_legend<'a, DB: DrawingBackend + 'a>(
    anno: &mut SeriesAnno<'a, DB>,
    style: SeriesStyle,
    marker: Marker,
    color: RGBColor,
) {
    let line = color.stroke_width(LINE_WIDTH);
    let thin = color.stroke_width(2);
    let r = MARKER_SIZE;
    let fill = color.filled();
    macro_rules! glyph {
        ($($part:expr),+) => {{
            anno.legend(move |(x, y)| EmptyElement::at((x + 8, y)) $(+ $part)+);
        }};
    }
    let stroke = move || PathElement::new(vec![(-12, 0), (12, 0)], line);
    match (style, marker) {
        (SeriesStyle::Line, _) => glyph!(stroke()),
        (SeriesStyle::Dashed, _) => glyph!(
            PathElement::new(vec![(-12, 0), (-3, 0)], line),
            PathElement::new(vec![(3, 0), (12, 0)], line)
        ),
        (SeriesStyle::Markers, Marker::Circle) => glyph!(Circle::new((0, 0), r, fill)),
        (SeriesStyle::Markers, Marker::Triangle) => {
            glyph!(TriangleMarker::new((0, 0), r + 1, fill))
        }
        (SeriesStyle::Markers, Marker::Square) => {
            glyph!(Rectangle::new([(-r, -r), (r, r)], fill))
        }
        (SeriesStyle::Markers, Marker::Cross) => glyph!(Cross::new((0, 0), r, thin)),
        (SeriesStyle::LineMarkers, Marker::Circle) => {
            glyph!(stroke(), Circle::new((0, 0), r, fill))
        }
        (SeriesStyle::LineMarkers, Marker::Triangle) => {
            glyph!(stroke(), TriangleMarker::new((0, 0), r + 1, fill))
        }
        (SeriesStyle::LineMarkers, Marker::Square) => {
            glyph!(stroke(), Rectangle::new([(-r, -r), (r, r)], fill))
        }
        (SeriesStyle::LineMarkers, Marker::Cross) => {
            glyph!(stroke(), Cross::new((0, 0), r, thin))
        }
    }
}

pub(super) struct BarSpec<'a> {
    pub(super) title: &'a str,
    pub(super) y_label: &'a str,
    pub(super) bars: &'a [(String, String, f64, Option<f64>)],
    pub(super) groups: &'a [&'a str],
    pub(super) codes: &'a [&'a str],
    pub(super) y_range: (f64, f64),
    pub(super) note: Option<String>,
}

pub(super) fn draw_bars<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    b: &BarSpec,
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
    root.fill(&WHITE).map_err(e)?;
    let n_groups = b.groups.len().max(1) as f64;
    let mut chart = ChartBuilder::on(root)
        .caption(b.title, (FONT, 24))
        .margin_top(10)
        .margin_left(10)
        .margin_right(25)
        .margin_bottom(28)
        .x_label_area_size(40)
        .y_label_area_size(80)
        .build_cartesian_2d(0.0..n_groups, b.y_range.0..b.y_range.1)
        .map_err(e)?;
    let tick = |v: &f64| format_tick(*v);
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(0)
        .y_desc(b.y_label)
        .axis_desc_style((FONT, 18))
        .label_style((FONT, 14))
        .y_label_formatter(&tick)
        .bold_line_style(GRID)
        .light_line_style(WHITE)
        .draw()
        .map_err(e)?;

    let slot = 0.8 / b.codes.len().max(1) as f64;
    let x_of = |g: &str, c: &str| {
        let gi = b.groups.iter().position(|x| *x == g).unwrap_or(0) as f64;
        let ci = b.codes.iter().position(|x| *x == c).unwrap_or(0) as f64;
        gi + 0.1 + ci * slot
    };
    for (ci, code) in b.codes.iter().enumerate() {
        let color = PALETTE[ci % PALETTE.len()];
        let mine = b
            .bars
            .iter()
            .filter(|(_, c, v, _)| c == code && v.is_finite());
        chart
            .draw_series(mine.clone().map(|(g, c, v, _)| {
                let x = x_of(g, c);
                Rectangle::new(
                    [(x + 0.05 * slot, 0.0), (x + 0.95 * slot, *v)],
                    color.filled(),
                )
            }))
            .map_err(e)?
            .label(code.to_string())
            .legend(move |(x, y)| Rectangle::new([(x - 6, y - 6), (x + 6, y + 6)], color.filled()));
        chart
            .draw_series(mine.filter_map(|(g, c, v, err)| {
                let err = err.filter(|e| e.is_finite())?.abs();
                let x = x_of(g, c) + 0.5 * slot;
                Some(ErrorBar::new_vertical(
                    x,
                    v - err,
                    *v,
                    v + err,
                    BLACK.stroke_width(1),
                    8,
                ))
            }))
            .map_err(e)?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font((FONT, 15))
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK.stroke_width(1))
        .draw()
        .map_err(e)?;

    // Group names under the axis, centred on each group.
    let style = (FONT, 15)
        .into_font()
        .color(&BLACK)
        .pos(Pos::new(HPos::Center, VPos::Top));
    for (gi, g) in b.groups.iter().enumerate() {
        let (px, py) = chart
            .plotting_area()
            .map_coordinate(&(gi as f64 + 0.5, b.y_range.0));
        root.draw(&Text::new(g.to_string(), (px, py + 10), style.clone()))
            .map_err(e)?;
    }
    let mut notes = Vec::new();
    if b.bars.is_empty() {
        notes.push("no data".to_string());
    }
    notes.extend(b.note.clone());
    draw_note(root, &notes.join(" "))
}
