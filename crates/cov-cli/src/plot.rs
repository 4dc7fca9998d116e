//! `covtrace plot`: one panel per step with the 1-σ ellipse of the spectrum in each
//! (position, direction) plane: red (Ω_x, Ω_u), blue (Ω_y, Ω_v) in 3D, green (Ω_x, Ω_t)
//! with time. All panels share one scale per plane, so sizes compare across steps.

use image::{Rgb, RgbImage};

use covtrace::path::Evaluation;

const PANEL: u32 = 220;
const PER_ROW: u32 = 4;

/// The (row, col) index pairs drawn and their colours for layout `n`.
fn planes(n: usize) -> Vec<((usize, usize), Rgb<u8>, &'static str)> {
    match n {
        2 => vec![((0, 1), Rgb([200, 30, 30]), "red: (Ωx, Ωu)")],
        3 => vec![
            ((0, 1), Rgb([200, 30, 30]), "red: (Ωx, Ωu)"),
            ((0, 2), Rgb([20, 150, 40]), "green: (Ωx, Ωt)"),
        ],
        4 => vec![
            ((0, 2), Rgb([200, 30, 30]), "red: (Ωx, Ωu)"),
            ((1, 3), Rgb([30, 60, 200]), "blue: (Ωy, Ωv)"),
        ],
        _ => vec![
            ((0, 2), Rgb([200, 30, 30]), "red: (Ωx, Ωu)"),
            ((1, 3), Rgb([30, 60, 200]), "blue: (Ωy, Ωv)"),
            ((0, 4), Rgb([20, 150, 40]), "green: (Ωx, Ωt)"),
        ],
    }
}

/// Draws the panels of `e` (source first, then every step) and returns the legend text.
///
/// # Errors
/// The image cannot be written.
pub fn plot(e: &Evaluation, out: &std::path::Path) -> Result<String, image::ImageError> {
    let mut mats: Vec<(&str, Vec<Vec<f64>>)> = vec![("source", e.start.rows())];
    for s in &e.steps {
        mats.push((&s.operator, s.matrix.rows()));
    }
    let count = mats.len() as u32;
    let cols = count.min(PER_ROW);
    let rows = count.div_ceil(PER_ROW);
    let mut img = RgbImage::from_pixel(cols * PANEL, rows * PANEL, Rgb([255, 255, 255]));
    let planes = planes(e.layout);
    // One scale per plane: the largest bandwidth on either of its axes over all steps;
    // the (position, direction) planes share theirs, having the same units.
    let mut scales: Vec<f64> = planes
        .iter()
        .map(|((a, b), _, _)| {
            mats.iter()
                .map(|(_, m)| m[*a][*a].max(m[*b][*b]).max(0.0).sqrt())
                .fold(0.0f64, f64::max)
        })
        .collect();
    let time_axis = if e.layout == 3 { 2 } else { 4 };
    let shared = planes
        .iter()
        .zip(&scales)
        .filter(|(((_, b), _, _), _)| *b != time_axis || e.layout < 3)
        .fold(0.0f64, |m, (_, s)| m.max(*s));
    for (((_, b), _, _), s) in planes.iter().zip(scales.iter_mut()) {
        if *b != time_axis || e.layout < 3 {
            *s = shared;
        }
    }
    for (k, (_, m)) in mats.iter().enumerate() {
        let (ox, oy) = ((k as u32 % PER_ROW) * PANEL, (k as u32 / PER_ROW) * PANEL);
        // Frame and axes.
        for t in 0..PANEL {
            for (x, y) in [(t, 0), (t, PANEL - 1), (0, t), (PANEL - 1, t)] {
                img.put_pixel(ox + x, oy + y, Rgb([180, 180, 180]));
            }
            img.put_pixel(ox + t, oy + PANEL / 2, Rgb([225, 225, 225]));
            img.put_pixel(ox + PANEL / 2, oy + t, Rgb([225, 225, 225]));
        }
        for (((a, b), color, _), scale) in planes.iter().zip(&scales) {
            if *scale <= 0.0 || !scale.is_finite() {
                continue;
            }
            draw_ellipse(
                &mut img,
                (ox, oy),
                [m[*a][*a], m[*a][*b], m[*b][*b]],
                *scale,
                *color,
            );
        }
    }
    img.save(out)?;
    let mut legend = format!(
        "{} panels, left to right, top to bottom: {}\n",
        count,
        mats.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ")
    );
    for ((_, _, name), s) in planes.iter().zip(&scales) {
        legend.push_str(&format!(
            "{name}: half a panel = {:.4e} cycles per unit\n",
            s * 1.1
        ));
    }
    Ok(legend)
}

fn draw_ellipse(img: &mut RgbImage, origin: (u32, u32), s: [f64; 3], scale: f64, color: Rgb<u8>) {
    // 1-σ contour: points Σ^{1/2} (cos φ, sin φ), via the eigen-decomposition of the 2×2 block.
    let (a, b, c) = (s[0], s[1], s[2]);
    let tr = 0.5 * (a + c);
    let disc = (0.25 * (a - c) * (a - c) + b * b).sqrt();
    let (l1, l2) = ((tr + disc).max(0.0), (tr - disc).max(0.0));
    let theta = 0.5 * (2.0 * b).atan2(a - c);
    let (st, ct) = theta.sin_cos();
    let half = f64::from(PANEL) / 2.0;
    let px = |v: f64| v / (scale * 1.1) * (half - 4.0);
    for k in 0..2000 {
        let phi = k as f64 / 2000.0 * std::f64::consts::TAU;
        let (e1, e2) = (l1.sqrt() * phi.cos(), l2.sqrt() * phi.sin());
        let (x, y) = (ct * e1 - st * e2, st * e1 + ct * e2);
        let (ix, iy) = (half + px(x), half - px(y));
        for (dx, dy) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
            let (xx, yy) = (ix + dx, iy + dy);
            if xx >= 0.0 && yy >= 0.0 && xx < f64::from(PANEL) && yy < f64::from(PANEL) {
                img.put_pixel(origin.0 + xx as u32, origin.1 + yy as u32, color);
            }
        }
    }
}
