//! # cov-cli: the `covtrace` command line
//!
//! - `covtrace eval PATH.ron [--json] [--form square-root|covariance]`: Σ after every step
//!   (axis names, bandwidths); with `--json`, the axis names, each step's operator and full
//!   matrix, and the final matrix, readable back with `cov_path::Evaluation::from_json`.
//!   `--form` chooses how Σ is held while tracing (default: square root, the accurate one).
//! - `covtrace plot PATH.ron -o FILE.png`: the spectrum ellipses after each step.
//! - `covtrace validate [--full] [-o FILE.svg]`: the brute-force error-against-run-time report.
//! - `covtrace stiff [--length N]`: the stiff suite (cov-stiff): extreme chains in both
//!   forms and in plain f64, against a double-double reference.
//! - `covtrace list`: the registered operators with their parameters and units.
//! - `covtrace render SCENE.ron [--method M] [--spp N] [--time S] [--denoise D] [-o OUT.exr]`:
//!   a render through the library's `Renderer`, with covariance tracing by default
//!   (`--method cov`); writes the image, the covariance pass's density and filter maps,
//!   and the feature images a denoiser takes ([`mod@render`]).
//! - `covtrace render-check SCENE.ron`: predicted against measured local spectra, tile by tile.
//! - `covtrace render-bench SCENE.ron [--budgets 2,4,…] [-o DIR]`: every sampling and
//!   reconstruction method against a cached reference: error against time, the equal-error
//!   speed-up, an equal-time strip ([`mod@bench`]).
//!
//! Every error is one line, `file:line:column: message`, with exit code 2.
//!
//! The command line is also a library entry, [`run_with`]: a binary of a few lines gives
//! all of it with a third party's operators registered next to the built-in ones
//! (`examples/third_party`).

#![warn(missing_docs)]

pub mod bench;
mod cli;
pub mod plot;
pub mod render;
pub mod report;

pub use cli::run_with;
use covtrace::path::Evaluation;

/// The human-readable table of an evaluation.
pub fn format_evaluation(name: &str, e: &Evaluation) -> String {
    let mut out = String::new();
    let how = if e.inferred {
        "inferred from what the path needs"
    } else {
        "declared"
    };
    let form = match e.form {
        covtrace::Form::SquareRoot => "square root (Σ = L Lᵀ)",
        covtrace::Form::Covariance => "covariance",
    };
    out.push_str(&format!(
        "path: {name}\nlayout: {} ({}), {how}\nform: {form}\n\n",
        e.layout,
        e.axes.join(",")
    ));
    out.push_str(&format!("{:>5}  {:<14}", "step", "operator"));
    for a in &e.axes {
        out.push_str(&format!(" {:>12}", format!("bw {a}")));
    }
    out.push_str("   [bandwidth √Σ_ii, cycles per unit]\n");
    let bw = |m: &Vec<Vec<f64>>| -> Vec<f64> { (0..m.len()).map(|i| m[i][i].max(0.0).sqrt()).collect() };
    let mut row = |label: &str, name: &str, b: &[f64]| {
        out.push_str(&format!("{label:>5}  {name:<14}"));
        for v in b {
            out.push_str(&format!(" {v:>12.4e}"));
        }
        out.push('\n');
    };
    row("-", "source", &bw(&e.start.rows()));
    for (i, s) in e.steps.iter().enumerate() {
        row(&i.to_string(), &s.operator, &s.bandwidths);
    }
    out.push_str("\nfinal Σ:\n     ");
    for a in &e.axes {
        out.push_str(&format!(" {a:>12}"));
    }
    out.push('\n');
    for (i, r) in e.result.rows().iter().enumerate() {
        out.push_str(&format!("  {:>2} ", e.axes[i]));
        for v in r {
            out.push_str(&format!(" {v:>12.4e}"));
        }
        out.push('\n');
    }
    out
}

/// The per-pixel decisions as text.
pub fn format_decisions(d: &covtrace::sensor::PixelDecisions) -> String {
    let mut out = String::from("per pixel (sensor):\n");
    out.push_str(&format!(
        "  image bandwidth     {} cycles/px (axes {})\n",
        d.image_bandwidth_px
            .iter()
            .map(|v| format!("{v:.4}"))
            .collect::<Vec<_>>()
            .join(", "),
        d.image_axes.join(",")
    ));
    out.push_str(&format!(
        "  filter std          {} px (principal axes, the image's content){}\n",
        d.filter_std_px
            .iter()
            .map(|v| format!("{v:.3}"))
            .collect::<Vec<_>>()
            .join(", "),
        if d.filter_clamped { ", clamped" } else { "" }
    ));
    out.push_str(&format!("  sampled domain      {}\n", d.sampled_axes.join(" × ")));
    // The sampled domain's unit volume: px per image axis, m per lens axis, s for time.
    let units: Vec<&str> = d
        .sampled_axes
        .iter()
        .map(|a| match a.as_str() {
            "t" => "s",
            a if a.starts_with("lens_") => "m",
            _ => "px",
        })
        .collect();
    let mut volume: Vec<String> = Vec::new();
    for u in ["px", "m", "s"] {
        match units.iter().filter(|v| **v == u).count() {
            0 => {}
            1 => volume.push(u.to_string()),
            n => volume.push(format!("{u}{}", if n == 2 { "²" } else { "³" })),
        }
    }
    out.push_str(&format!(
        "  density             {:.4e} samples per {}\n",
        d.density,
        volume.join("·")
    ));
    out.push_str(&format!(
        "  samples per pixel   {:.3}{}\n",
        d.samples_per_pixel,
        if d.samples_per_pixel < 1.0 {
            " (below one: a renderer still takes one; check that the Sensor's distance, aperture and shutter match the lens and shutter of the path)"
        } else {
            ""
        }
    ));
    out
}
