//! Every picture the project writes carries its own text: a title band with text, labelled
//! axes, a legend; no system font is needed (DejaVu Sans is embedded). Pixel-exact output
//! is not checked: dimensions, and dark (text) pixels where the title and legend stand.

use std::path::PathBuf;

mod common;
use common::covtrace;

fn tmp(name: &str) -> PathBuf {
    common::tmp("plots", name)
}

/// Dark pixels (luminance below 100) in the rectangle `x0..x1 × y0..y1`.
fn dark(img: &image::RgbImage, (x0, y0, x1, y1): (u32, u32, u32, u32)) -> usize {
    let mut n = 0;
    for y in y0..y1.min(img.height()) {
        for x in x0..x1.min(img.width()) {
            let p = img.get_pixel(x, y);
            if (u32::from(p[0]) * 2126 + u32::from(p[1]) * 7152 + u32::from(p[2]) * 722) / 10000 < 100 {
                n += 1;
            }
        }
    }
    n
}

#[test]
fn the_spectrum_plot_has_a_title_axes_and_a_legend() {
    let out = tmp("demo.png");
    let o = covtrace(&[
        "plot",
        "examples/paths/demo.ron",
        "-o",
        out.to_str().expect("utf-8"),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let img = image::open(&out).expect("png").to_rgb8();
    // 6 panels of 300×260 in rows of 4, a 44 px title band and a 44 px legend band.
    assert_eq!(img.dimensions(), (1200, 2 * 260 + 88));
    assert!(dark(&img, (0, 0, 900, 40)) > 300, "no title text");
    assert!(dark(&img, (0, 608 - 44, 700, 608)) > 150, "no legend");
    // Axis descriptions and tick labels beside and below the first panel.
    assert!(dark(&img, (0, 60, 50, 300)) > 150, "no y-axis labels");
    assert!(dark(&img, (50, 270, 300, 304)) > 150, "no x-axis labels");
}

#[test]
fn a_long_path_is_plotted_in_a_bounded_picture() {
    let ops = vec!["Travel(distance: 0.1)"; 500].join(", ");
    let ron = tmp("long.ron");
    std::fs::write(
        &ron,
        format!("Path(source: Gaussian(x: 0.1), operators: [{ops}])"),
    )
    .expect("write");
    let out = tmp("long.png");
    let o = covtrace(&[
        "plot",
        ron.to_str().expect("utf-8"),
        "-o",
        out.to_str().expect("utf-8"),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains("24 panels of 501 steps"));
    let img = image::open(&out).expect("png").to_rgb8();
    assert_eq!(img.dimensions(), (1200, 6 * 260 + 88));
}

#[test]
fn the_validation_chart_is_written_as_svg_and_png_with_text() {
    let rows: Vec<cov_cli::report::Row> = [("travel 1 m", true), ("GGX lobe", false)]
        .iter()
        .flat_map(|&(case, gaussian)| {
            [32usize, 64, 128]
                .into_iter()
                .enumerate()
                .map(move |(i, grid)| cov_cli::report::Row {
                    case,
                    gaussian,
                    grid,
                    rel_error: 1e-3 / 10f64.powi(3 * i as i32),
                    rel_error_scaled: 1e-3,
                    predict_us: 0.1,
                    measure_ms: 0.1 * 4f64.powi(i as i32),
                })
        })
        .collect();
    let png = tmp("chart.png");
    cov_cli::report::chart(png.to_str().expect("utf-8"), &rows).expect("png chart");
    let img = image::open(&png).expect("png").to_rgb8();
    assert_eq!(img.dimensions(), (1180, 560));
    assert!(dark(&img, (150, 0, 700, 40)) > 300, "no title");
    assert!(dark(&img, (780, 30, 1180, 130)) > 300, "no legend column");
    let svg = tmp("chart.svg");
    cov_cli::report::chart(svg.to_str().expect("utf-8"), &rows).expect("svg chart");
    let text = std::fs::read_to_string(&svg).expect("svg");
    assert!(
        text.contains("Brute-force validation") && text.contains("1e-9"),
        "title or tick label missing"
    );
    assert!(!text.contains("0000000"), "long digit strings in tick labels");
}

#[test]
fn outputs_are_checked_before_the_work() {
    let o = covtrace(&["validate", "-o", "/nonexistent-dir/report.svg"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("no such folder"));
    let o = covtrace(&["plot", "examples/paths/demo.ron", "-o", "/tmp/x.svg"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("must be a .png file"));
}
