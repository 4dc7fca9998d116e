//! `covtrace plot`: one panel per step with the 1-σ ellipse of the spectrum in each
//! (position, direction) plane, drawn with plotters and an embedded font (DejaVu Sans, the
//! `dejavu` crate), so the picture carries its own title, step names, axes with units, tick
//! labels and legend. All panels share one scale per plane, so sizes compare across steps,
//! except a panel of another order (a `Sensor`'s image-space Σ), which is titled "own scale".
//!
//! Planes are told apart by colour and by line style (they stay distinct in greyscale):
//! `(Ωx, Ωu)` solid dark red, `(Ωy, Ωv)` dashed blue, `(Ωx, Ωt)` dotted green on the
//! panel's right axis (cycles/s).

use plotters::coord::Shift;
use plotters::prelude::*;

use covtrace::path::Evaluation;

/// Panel size (px).
const PANEL: (u32, u32) = (300, 260);
/// Panels per row.
const PER_ROW: u32 = 4;
/// Heights of the title band and the legend band (px).
const TITLE_H: u32 = 44;
const LEGEND_H: u32 = 44;

/// Largest number of panels drawn: longer paths are subsampled evenly (the first and last
/// steps always shown), so the picture stays readable and its size bounded.
pub const MAX_PANELS: usize = 24;

/// Registers the embedded font as `sans-serif` (once; later calls do nothing).
///
/// # Errors
/// The embedded font does not parse (never for the bundled bytes).
pub fn register_font() -> Result<(), String> {
    static DONE: std::sync::OnceLock<Result<(), String>> = std::sync::OnceLock::new();
    DONE.get_or_init(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular())
            .map_err(|_| "the embedded DejaVu Sans font does not parse".to_string())
    })
    .clone()
}

/// A picture that draws itself on any plotters backend, saved by [`save`].
pub trait Picture {
    /// Draws on `root`.
    ///
    /// # Errors
    /// What the backend reports.
    fn draw<DB: DrawingBackend>(
        &self,
        root: DrawingArea<DB, Shift>,
    ) -> Result<(), Box<dyn std::error::Error>>
    where
        DB::ErrorType: 'static;
}

/// Saves `pic` at `size` px as SVG (`.svg`) or PNG (any other extension), with the
/// embedded font.
///
/// # Errors
/// The file cannot be written.
pub fn save<P: Picture>(
    path: &std::path::Path,
    size: (u32, u32),
    pic: &P,
) -> Result<(), Box<dyn std::error::Error>> {
    register_font()?;
    let (w, h) = size;
    // Drawn in memory, then written at once (`cov_render::output`): a failed write says
    // why and leaves no partial file. Callers name the path; the error is the reason alone.
    let reason = |e: cov_render::RenderError| match e {
        cov_render::RenderError::File { message, .. } => message,
        other => other.to_string(),
    };
    if path.extension().is_some_and(|e| e == "svg") {
        let mut text = String::new();
        pic.draw(SVGBackend::with_string(&mut text, (w, h)).into_drawing_area())?;
        cov_render::output::write_file(path, text.as_bytes()).map_err(reason)?;
    } else {
        let mut buf = vec![0u8; (w as usize) * (h as usize) * 3];
        pic.draw(BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area())?;
        let img = image::RgbImage::from_raw(w, h, buf).ok_or("image buffer size")?;
        cov_render::output::save(img, path).map_err(reason)?;
    }
    Ok(())
}

/// Colours distinct on white (the first eight also in greyscale, by decreasing
/// luminance), one per series, so that no two of a chart's ten series share one.
pub const COLORS: [RGBColor; 10] = [
    RGBColor(0, 0, 0),
    RGBColor(213, 94, 0),
    RGBColor(0, 114, 178),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(86, 86, 86),
    RGBColor(230, 159, 0),
    RGBColor(120, 28, 129),
    RGBColor(86, 180, 233),
    RGBColor(150, 30, 30),
];

/// Tick labels of a log axis: `1e-7`, `3e2`.
pub fn log_tick(v: &f64) -> String {
    let s = format!("{v:.0e}");
    s.replace("e0", "").replace('+', "")
}

/// One plane of the spectrum: its row/column pair, colour, style and name.
struct Plane {
    axes: (usize, usize),
    color: RGBColor,
    style: LineKind,
    name: &'static str,
    time: bool,
}

#[derive(Clone, Copy)]
enum LineKind {
    Solid,
    Dashed,
    Dotted,
}

const RED: RGBColor = RGBColor(178, 24, 43);
const BLUE: RGBColor = RGBColor(33, 102, 172);
const GREEN: RGBColor = RGBColor(27, 120, 55);

fn planes(n: usize) -> Vec<Plane> {
    let xu = |a, b| Plane {
        axes: (a, b),
        color: RED,
        style: LineKind::Solid,
        name: "(Ωx, Ωu)",
        time: false,
    };
    let yv = Plane {
        axes: (1, 3),
        color: BLUE,
        style: LineKind::Dashed,
        name: "(Ωy, Ωv)",
        time: false,
    };
    let xt = |t| Plane {
        axes: (0, t),
        color: GREEN,
        style: LineKind::Dotted,
        name: "(Ωx, Ωt), right axis",
        time: true,
    };
    match n {
        2 => vec![xu(0, 1)],
        3 => vec![xu(0, 1), xt(2)],
        4 => vec![xu(0, 2), yv],
        _ => vec![xu(0, 2), yv, xt(4)],
    }
}

/// Points of the 1-σ contour of the 2×2 block `[a, b, c]` (`Σ^{1/2}` of the unit circle).
fn ellipse(s: [f64; 3]) -> Vec<(f64, f64)> {
    let (a, b, c) = (s[0], s[1], s[2]);
    let tr = 0.5 * (a + c);
    let disc = (0.5 * (a - c)).hypot(b);
    let (l1, l2) = ((tr + disc).max(0.0), (tr - disc).max(0.0));
    let theta = 0.5 * (2.0 * b).atan2(a - c);
    let (st, ct) = theta.sin_cos();
    (0..=180)
        .map(|k| {
            let phi = k as f64 / 180.0 * std::f64::consts::TAU;
            let (e1, e2) = (l1.sqrt() * phi.cos(), l2.sqrt() * phi.sin());
            (ct * e1 - st * e2, st * e1 + ct * e2)
        })
        .collect()
}

/// Tick labels like `1.5e3`: short, with an exponent.
fn tick(v: &f64, range: f64) -> String {
    // A tick meant for 0 carries the rounding of the axis arithmetic (1.2e83 on an axis
    // of ±1e99): anything below 1e-9 of the range is 0.
    if v.abs() <= 1e-9 * range {
        "0".into()
    } else {
        let s = format!("{v:.1e}");
        s.replace(".0e", "e")
    }
}

/// Which steps get a panel: all, or an even subsample of at most [`MAX_PANELS`].
/// A panel whose peak bandwidth exceeds this many times the panels' median takes a scale
/// of its own ([`plot`]).
const OUTLIER: f64 = 20.0;

fn shown(count: usize) -> Vec<usize> {
    if count <= MAX_PANELS {
        return (0..count).collect();
    }
    let mut v: Vec<usize> = (0..MAX_PANELS)
        .map(|i| (i as f64 * (count - 1) as f64 / (MAX_PANELS - 1) as f64).round() as usize)
        .collect();
    v.dedup();
    v
}

/// Draws the panels of `e` (source first, then every step, subsampled beyond
/// [`MAX_PANELS`]) into a PNG at `out`, titled with `name`; returns a text summary.
///
/// # Errors
/// The image cannot be drawn or written.
pub fn plot(e: &Evaluation, name: &str, out: &std::path::Path) -> Result<String, String> {
    register_font()?;
    let mut mats: Vec<(String, Vec<Vec<f64>>)> = vec![("source".into(), e.start.rows())];
    for (i, s) in e.steps.iter().enumerate() {
        mats.push((format!("{i}: {}", s.operator), s.matrix.rows()));
    }
    let idx = shown(mats.len());
    let count = idx.len() as u32;
    let cols = count.min(PER_ROW);
    let rows = count.div_ceil(PER_ROW);
    let (w, h) = (cols * PANEL.0, TITLE_H + rows * PANEL.1 + LEGEND_H);
    let planes = planes(e.layout);
    // One scale per kind of axis (position, direction, time) over the panels shown, but
    // for a panel whose Σ is of another order (a `Sensor`'s image-space Σ, in cycles per
    // metre of sensor): past OUTLIER × the panels' median peak, it takes a scale of its
    // own, said in its title, so that the others do not shrink to a sliver.
    let pos_axes: Vec<usize> = planes.iter().map(|p| p.axes.0).collect();
    let dir_axes: Vec<usize> = planes.iter().filter(|p| !p.time).map(|p| p.axes.1).collect();
    let time_axis: Vec<usize> = planes.iter().filter(|p| p.time).map(|p| p.axes.1).collect();
    let peak = |m: &[Vec<f64>], axes: &[usize]| -> f64 {
        axes.iter()
            .map(|&a| m[a][a].max(0.0).sqrt())
            .filter(|v| v.is_finite())
            .fold(0.0f64, f64::max)
    };
    let kinds = [&pos_axes, &dir_axes, &time_axis];
    let peaks: Vec<[f64; 3]> = idx
        .iter()
        .map(|&k| kinds.map(|axes| peak(&mats[k].1, axes)))
        .collect();
    let median = |kind: usize| -> f64 {
        let mut v: Vec<f64> = peaks.iter().map(|p| p[kind]).filter(|v| *v > 0.0).collect();
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(0.0)
    };
    let medians = [median(0), median(1), median(2)];
    let own: Vec<bool> = peaks
        .iter()
        .map(|p| (0..3).any(|k| medians[k] > 0.0 && p[k] > OUTLIER * medians[k]))
        .collect();
    let fit = |v: f64| {
        let s = v * 1.15;
        if s.is_finite() && s > 0.0 { s } else { 1.0 }
    };
    let shared: [f64; 3] = std::array::from_fn(|k| {
        fit(peaks
            .iter()
            .zip(&own)
            .filter(|(_, o)| !**o)
            .map(|(p, _)| p[k])
            .fold(0.0f64, f64::max))
    });
    let has_time = !time_axis.is_empty();
    let scale_of = |i: usize| -> (f64, f64, Option<f64>) {
        let s = if own[i] { peaks[i].map(fit) } else { shared };
        (s[0], s[1], has_time.then_some(s[2]))
    };
    let mut buf = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let (top, rest) = root.split_vertically(TITLE_H);
        let (body, legend) = rest.split_vertically(rows * PANEL.1);
        top.draw(&Text::new(
            format!(
                "Spectrum ellipses (1σ) after each step: {name} (layout {}: {})",
                e.layout,
                e.axes.join(",")
            ),
            (12, 12),
            ("sans-serif", 20).into_font().color(&BLACK),
        ))
        .map_err(|e| e.to_string())?;
        let panels = body.split_evenly((rows as usize, PER_ROW.min(count) as usize));
        for (i, (area, &k)) in panels.iter().zip(&idx).enumerate() {
            let (title, m) = &mats[k];
            let title = if own[i] {
                format!("{title} (own scale)")
            } else {
                title.clone()
            };
            draw_panel(area, &title, m, &planes, scale_of(i)).map_err(|e| e.to_string())?;
        }
        draw_legend(&legend, &planes, count as usize, mats.len(), own.contains(&true))
            .map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    let img = image::RgbImage::from_raw(w, h, buf).ok_or("image buffer size")?;
    cov_render::output::save(img, out).map_err(|e| e.to_string())?;
    Ok(format!(
        "{} panels of {} steps ({}), {}×{} px",
        count,
        mats.len(),
        planes.iter().map(|p| p.name).collect::<Vec<_>>().join(", "),
        w,
        h
    ))
}

type DrawResult = Result<(), Box<dyn std::error::Error>>;

fn draw_panel(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    title: &str,
    m: &[Vec<f64>],
    planes: &[Plane],
    (sx, sy, st): (f64, f64, Option<f64>),
) -> DrawResult {
    let mut chart = ChartBuilder::on(area)
        .caption(title, ("sans-serif", 14))
        .margin(6)
        .x_label_area_size(34)
        .y_label_area_size(50)
        .right_y_label_area_size(if st.is_some() { 50 } else { 0 })
        .build_cartesian_2d(-sx..sx, -sy..sy)?
        .set_secondary_coord(-sx..sx, -st.unwrap_or(1.0)..st.unwrap_or(1.0));
    chart
        .configure_mesh()
        .x_labels(5)
        .y_labels(5)
        .x_label_formatter(&|v| tick(v, sx))
        .y_label_formatter(&|v| tick(v, sy))
        .x_desc("Ω position [cycles/m]")
        .y_desc("Ω direction [cycles/tan]")
        .label_style(("sans-serif", 11))
        .axis_desc_style(("sans-serif", 11))
        .light_line_style(WHITE)
        .bold_line_style(RGBColor(235, 235, 235))
        .draw()?;
    if st.is_some() {
        chart
            .configure_secondary_axes()
            .y_labels(5)
            .y_label_formatter(&|v| tick(v, st.unwrap_or(1.0)))
            .y_desc("Ω time [cycles/s]")
            .label_style(("sans-serif", 11))
            .axis_desc_style(("sans-serif", 11))
            .draw()?;
    }
    // A Σ of zeros draws nothing: say so rather than leave the panel looking broken.
    if planes
        .iter()
        .all(|p| m[p.axes.0][p.axes.0] == 0.0 && m[p.axes.1][p.axes.1] == 0.0)
    {
        chart.draw_series(std::iter::once(Text::new(
            "Σ = 0: constant on every axis",
            (-0.6 * sx, 0.0),
            ("sans-serif", 12).into_font().color(&RGBColor(90, 90, 90)),
        )))?;
    }
    for p in planes {
        let (a, b) = p.axes;
        let pts = ellipse([m[a][a], m[a][b], m[b][b]]);
        let style = ShapeStyle::from(&p.color).stroke_width(2);
        if p.time {
            chart.draw_secondary_series(DashedLineSeries::new(pts, 2, 4, style))?;
        } else {
            match p.style {
                LineKind::Solid => {
                    chart.draw_series(LineSeries::new(pts, style))?;
                }
                LineKind::Dashed | LineKind::Dotted => {
                    chart.draw_series(DashedLineSeries::new(pts, 7, 5, style))?;
                }
            }
        }
    }
    Ok(())
}

fn draw_legend(
    area: &DrawingArea<BitMapBackend<'_>, Shift>,
    planes: &[Plane],
    shown: usize,
    total: usize,
    any_own: bool,
) -> DrawResult {
    let font = ("sans-serif", 14).into_font().color(&BLACK);
    let mut x = 12;
    for p in planes {
        let style = ShapeStyle::from(&p.color).stroke_width(3);
        let (y, x1) = (18, x + 36);
        match p.style {
            LineKind::Solid => area.draw(&PathElement::new(vec![(x, y), (x1, y)], style))?,
            LineKind::Dashed => {
                area.draw(&PathElement::new(vec![(x, y), (x + 12, y)], style))?;
                area.draw(&PathElement::new(vec![(x + 20, y), (x1, y)], style))?;
            }
            LineKind::Dotted => {
                for k in 0..5 {
                    area.draw(&PathElement::new(vec![(x + 8 * k, y), (x + 8 * k + 3, y)], style))?;
                }
            }
        }
        area.draw(&Text::new(p.name, (x1 + 8, 10), font.clone()))?;
        x += 250;
    }
    let scales = if any_own {
        "one scale for all panels but those of their own"
    } else {
        "one scale for all panels"
    };
    let note = if shown < total {
        format!("1σ contours; {scales}; {shown} of {total} steps shown")
    } else {
        format!("1σ contours; {scales}")
    };
    area.draw(&Text::new(
        note,
        (x + 10, 10),
        ("sans-serif", 13).into_font().color(&RGBColor(80, 80, 80)),
    ))?;
    Ok(())
}
