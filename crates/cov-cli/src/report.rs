//! The error-against-run-time report (`covtrace validate`): for a bundled set of flatland
//! chains, the closed-form prediction against the brute-force measurement (cov-validate)
//! at several grid sizes: case | relative error | time to predict | time to measure, and
//! the error-vs-run-time chart as SVG.

use std::sync::Arc;
use std::time::Instant;

use cov_validate::{Field, Grid, Primal, compare};
use covtrace::brdf::{Brdf, Lobe, Reflect};
use covtrace::curvature::Curvature;
use covtrace::occlusion::{BlockerEdge, Texture, Window};
use covtrace::refraction::Refract;
use covtrace::travel::Travel;
use covtrace::{Chain, Cov};
use plotters::prelude::*;

use crate::plot::{COLORS, log_tick};

/// One bundled chain: its operators and its primal field built from docs/physics.md.
pub struct Case {
    /// Name in the table.
    pub name: &'static str,
    /// Whether the chain is Gaussian (exact closed form) or an approximation.
    pub gaussian: bool,
    /// The operators.
    pub chain: Chain,
    /// The same chain as a primal light field.
    pub field: Field,
}

/// One row of the report.
#[derive(Clone, Debug)]
pub struct Row {
    /// Case name.
    pub case: &'static str,
    /// Whether the case is Gaussian.
    pub gaussian: bool,
    /// Grid size per axis.
    pub grid: usize,
    /// Plain Frobenius relative error.
    pub rel_error: f64,
    /// Unit-scaled relative error.
    pub rel_error_scaled: f64,
    /// Mean time to predict (µs).
    pub predict_us: f64,
    /// Time to measure (ms).
    pub measure_ms: f64,
}

const STDS: [f64; 2] = [0.1, 0.2];

/// The bundled cases.
///
/// # Errors
/// Never for the bundled parameters; an operator constructor's error otherwise.
pub fn cases() -> Result<Vec<Case>, covtrace::CovError> {
    let f0 = || Field::gaussian(&STDS);
    let refract = Refract::new(1.0, 1.5, 0.8)?;
    let ggx_a2 = 4.0 * 0.1 * 0.1;
    Ok(vec![
        Case {
            name: "travel 1 m",
            gaussian: true,
            chain: Chain::new().with(Travel::new(1.0)?),
            field: f0().then(Primal::travel(2, 1.0)),
        },
        Case {
            name: "window + travel",
            gaussian: true,
            chain: Chain::new()
                .with(Window::isotropic(0.05)?)
                .with(Travel::new(0.5)?),
            field: f0()
                .then(Primal::gaussian_window(0, 0.05))
                .then(Primal::travel(2, 0.5)),
        },
        Case {
            name: "Phong 100 lobe",
            gaussian: true,
            chain: Chain::new()
                .with(Travel::new(0.3)?)
                .with(Brdf::new(Lobe::phong(100.0)?)?),
            field: f0()
                .then(Primal::travel(2, 0.3))
                .then(Primal::gaussian_lobe(1, 0.01, 129)),
        },
        Case {
            name: "curved glossy reflector",
            gaussian: true,
            chain: Chain::new().with(Reflect::new(
                0.8,
                0.8,
                Curvature::isotropic(2.0)?,
                Lobe::phong(200.0)?,
            )?),
            field: f0().then_all(Primal::reflection_2d(0.8, 0.8, 2.0, 1.0 / 200.0, 129)),
        },
        Case {
            name: "refraction air→glass",
            gaussian: true,
            chain: Chain::new().with(refract),
            field: f0()
                .then(Primal::scale(2, 0, 0.8 / refract.cos_t()))
                .then(Primal::scale(2, 1, 1.0 / refract.angular_scale())),
        },
        Case {
            name: "hard blocker edge",
            gaussian: false,
            chain: Chain::new().with(BlockerEdge::new(0.05)?),
            field: f0().then(Primal::Window(Arc::new(
                |z: &[f64]| if z[0] > -0.05 { 1.0 } else { 0.0 },
            ))),
        },
        Case {
            name: "GGX α=0.1 lobe (heavy tail)",
            gaussian: false,
            chain: Chain::new()
                .with(Travel::new(0.3)?)
                .with(Brdf::new(Lobe::ggx(0.1)?)?),
            field: f0().then(Primal::travel(2, 0.3)).then(Primal::Convolve {
                axis: 1,
                lobe: Arc::new(move |u| (1.0 + u * u / ggx_a2).powf(-1.5)),
                half_width: 3.0,
                nodes: 2001,
            }),
        },
        Case {
            name: "sinusoidal texture",
            gaussian: true,
            chain: Chain::new().with(sinusoid_texture()?),
            field: f0().then(Primal::Window(Arc::new(|z: &[f64]| {
                1.0 + TEX_AMP * (TAU * TEX_FREQ * z[0]).cos()
            }))),
        },
        Case {
            name: "Gaussian-noise texture",
            gaussian: false,
            chain: Chain::new().with(noise_texture()?),
            field: f0().then(Primal::Window(Arc::new(|z: &[f64]| {
                1.0 + noise_terms()
                    .iter()
                    .map(|&(a, f, ph)| a * (TAU * f * z[0] + ph).cos())
                    .sum::<f64>()
            }))),
        },
    ])
}

use std::f64::consts::TAU;

/// The sinusoidal texture `1 + a cos(2π f x)`: amplitude and frequency (cycles/m).
const TEX_AMP: f64 = 0.5;
const TEX_FREQ: f64 = 2.0;

/// The texture operator of the sinusoid, from its moments (`⟨A⟩ = 1`, `⟨A²⟩ = 1 + a²/2`,
/// `⟨A'²⟩ = a² (2π f)² / 2`): in covtrace's amplitude convention the window's spectrum of
/// a sinusoid on a constant is exactly `a f² / (1 + a)`, and all spectra involved are
/// positive, so rule 2 is exact here.
fn sinusoid_texture() -> Result<Texture, covtrace::CovError> {
    let a = TEX_AMP;
    Texture::from_moments(
        1.0,
        1.0 + a * a / 2.0,
        [a * a * (TAU * TEX_FREQ).powi(2) / 2.0, 0.0, 0.0],
    )
}

/// Smooth Gaussian noise as a sum of 16 cosines: amplitudes 0.08, frequencies drawn from a
/// normal of std 2 cycles/m, phases uniform (a fixed SplitMix64 stream).
fn noise_terms() -> Vec<(f64, f64, f64)> {
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = move || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..16)
        .map(|_| {
            let (u1, u2) = (next().max(1e-12), next());
            let f = 2.0 * (-2.0 * u1.ln()).sqrt() * (TAU * u2).cos();
            (0.08, f.abs(), TAU * next())
        })
        .collect()
}

/// The texture operator of the noise, from its moments over the ensemble of phases.
fn noise_texture() -> Result<Texture, covtrace::CovError> {
    let t = noise_terms();
    let p: f64 = t.iter().map(|&(a, _, _)| a * a / 2.0).sum();
    let g: f64 = t.iter().map(|&(a, f, _)| a * a * (TAU * f).powi(2) / 2.0).sum();
    Texture::from_moments(1.0, 1.0 + p, [g, 0.0, 0.0])
}

/// Grid sizes of the report: 32 to 256, and 512 with `full`.
pub fn sizes(full: bool) -> Vec<usize> {
    let mut v = vec![32, 64, 128, 256];
    if full {
        v.push(512);
    }
    v
}

/// Runs every case at every size; `tick` is called after each measurement.
///
/// # Errors
/// An operator or validator failure.
pub fn run(sizes: &[usize], mut tick: impl FnMut(&Row)) -> Result<Vec<Row>, Box<dyn std::error::Error>> {
    let start = Cov::<2>::gaussian(STDS)?;
    let mut rows = Vec::new();
    let cases = cases()?;
    // Warm-up, untimed: the first measurement otherwise pays for page faults and FFT plans
    // (the first point of the first series used to lie above the next grid's).
    if let (Some(case), Some(&n)) = (cases.first(), sizes.first()) {
        let predicted = case.chain.eval(start)?;
        compare(&case.field, &predicted, &Grid::auto(&predicted, n, &[1.0, 1.0]))?;
    }
    for case in cases {
        // Prediction time: mean over many evaluations.
        let reps = 20_000;
        let t0 = Instant::now();
        let mut predicted = start;
        for _ in 0..reps {
            predicted = std::hint::black_box(&case.chain).eval(std::hint::black_box(start))?;
        }
        let predict_us = t0.elapsed().as_secs_f64() / f64::from(reps) * 1e6;
        for &n in sizes {
            let r = compare(&case.field, &predicted, &Grid::auto(&predicted, n, &[1.0, 1.0]))?;
            let row = Row {
                case: case.name,
                gaussian: case.gaussian,
                grid: n,
                rel_error: r.rel_error,
                rel_error_scaled: r.rel_error_scaled,
                predict_us,
                measure_ms: r.measure_seconds * 1e3,
            };
            tick(&row);
            rows.push(row);
        }
    }
    Ok(rows)
}

/// The table header.
pub fn header() -> String {
    format!(
        "{:<34} {:>5} {:>12} {:>12} {:>14} {:>13}",
        "case", "grid", "rel error", "scaled err", "predict [µs]", "measure [ms]"
    )
}

/// One table line.
pub fn line(r: &Row) -> String {
    format!(
        "{:<34} {:>5} {:>12.3e} {:>12.3e} {:>14.3} {:>13.3}",
        r.case, r.grid, r.rel_error, r.rel_error_scaled, r.predict_us, r.measure_ms
    )
}

/// Writes the error-vs-run-time chart (SVG) of `rows`.
///
/// # Errors
/// The file cannot be written.
pub fn chart(path: &str, rows: &[Row]) -> Result<(), Box<dyn std::error::Error>> {
    let mut series: Vec<Series> = Vec::new();
    for r in rows {
        match series.last_mut() {
            Some(s) if s.0 == r.case => s.3.push((r.measure_ms, r.rel_error.max(1e-16))),
            _ => series.push((
                r.case,
                r.gaussian,
                r.predict_us,
                vec![(r.measure_ms, r.rel_error.max(1e-16))],
            )),
        }
    }
    draw(path, &series)
}

/// (case, gaussian, predict µs, (measure ms, error) per grid).
type Series = (&'static str, bool, f64, Vec<(f64, f64)>);

/// Draws the chart on any plotters backend: the chart on the left, the legend in its own
/// column on the right (it covers no data).
struct ValidateChart<'a>(&'a [Series]);

impl crate::plot::Picture for ValidateChart<'_> {
    fn draw<DB: DrawingBackend>(
        &self,
        root: DrawingArea<DB, plotters::coord::Shift>,
    ) -> Result<(), Box<dyn std::error::Error>>
    where
        DB::ErrorType: 'static,
    {
        draw_on(root, self.0)
    }
}

fn draw_on<DB: DrawingBackend>(
    root: DrawingArea<DB, plotters::coord::Shift>,
    series: &[Series],
) -> Result<(), Box<dyn std::error::Error>>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let (w, _) = root.dim_in_pixel();
    let (left, right) = root.split_horizontally(w.saturating_sub(400));
    let (mut tmin, mut tmax, mut emin, mut emax) = (f64::MAX, 0.0f64, f64::MAX, 0.0f64);
    for (_, _, _, pts) in series {
        for &(t, e) in pts {
            tmin = tmin.min(t);
            tmax = tmax.max(t);
            emin = emin.min(e);
            emax = emax.max(e);
        }
    }
    if !(tmin.is_finite() && tmax > 0.0 && emin.is_finite() && emax > 0.0) {
        (tmin, tmax, emin, emax) = (1e-3, 1.0, 1e-16, 1.0);
    }
    let mut chart = ChartBuilder::on(&left)
        .caption(
            "Brute-force validation: error against time to measure",
            ("sans-serif", 20),
        )
        .margin(15)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(
            (tmin * 0.5..tmax * 2.0).log_scale(),
            (emin * 0.3..emax * 3.0).log_scale(),
        )?;
    chart
        .configure_mesh()
        .x_label_formatter(&log_tick)
        .y_label_formatter(&log_tick)
        .x_desc("time to measure [ms] (grids of 32 to 256 points per axis)")
        .y_desc("relative error ‖Σ_measured − Σ_predicted‖ / ‖Σ_predicted‖")
        .label_style(("sans-serif", 13))
        .axis_desc_style(("sans-serif", 13))
        .draw()?;
    for (i, (_, _, _, pts)) in series.iter().enumerate() {
        let color = COLORS[i % COLORS.len()];
        chart.draw_series(LineSeries::new(pts.iter().copied(), color.stroke_width(2)))?;
        match i % 3 {
            0 => chart.draw_series(pts.iter().map(|&p| Circle::new(p, 4, color.filled())))?,
            1 => chart.draw_series(pts.iter().map(|&p| TriangleMarker::new(p, 5, color.filled())))?,
            _ => chart.draw_series(pts.iter().map(|&p| Cross::new(p, 4, color.stroke_width(2))))?,
        };
    }
    // The legend, in its own column.
    let font = ("sans-serif", 13).into_font().color(&BLACK);
    right.draw(&Text::new(
        "case (prediction time per chain)",
        (6, 40),
        font.clone(),
    ))?;
    for (i, (name, gaussian, predict_us, _)) in series.iter().enumerate() {
        let color = COLORS[i % COLORS.len()];
        let y = 70 + 22 * i as i32;
        right.draw(&PathElement::new(vec![(6, y), (30, y)], color.stroke_width(2)))?;
        match i % 3 {
            0 => right.draw(&Circle::new((18, y), 4, color.filled()))?,
            1 => right.draw(&TriangleMarker::new((18, y), 5, color.filled()))?,
            _ => right.draw(&Cross::new((18, y), 4, color.stroke_width(2)))?,
        }
        let label = format!(
            "{name}{} — {predict_us:.2} µs",
            if *gaussian { "" } else { " (approx.)" }
        );
        right.draw(&Text::new(label, (38, y - 8), font.clone()))?;
    }
    root.present()?;
    Ok(())
}

/// Writes the chart as SVG (`.svg`) or PNG (any other extension), with the embedded font.
fn draw(path: &str, series: &[Series]) -> Result<(), Box<dyn std::error::Error>> {
    crate::plot::save(std::path::Path::new(path), (1180, 560), &ValidateChart(series))
}
