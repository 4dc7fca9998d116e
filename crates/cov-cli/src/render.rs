//! `covtrace render`: a uniform-sampling render of a scene file, with its covariance maps.

use std::path::{Path, PathBuf};

use cov_render::render::{
    covariance_maps_with, render_adaptive, render_clamped, tile_count, timed, write_image, write_maps,
};
use cov_render::{MAX_COV_PATHS, MAX_SPP, World};
use indicatif::{ProgressBar, ProgressStyle};

/// What `covtrace render` was asked (parsed by clap).
#[derive(Clone, Debug, clap::Args)]
pub struct RenderArgs {
    /// The scene file.
    pub scene: PathBuf,
    /// Samples per pixel.
    #[arg(long, default_value_t = 16)]
    pub spp: u32,
    /// Output EXR (linear); a PNG and the maps are written beside it.
    #[arg(short, long, default_value = "render.exr")]
    pub output: PathBuf,
    /// Covariance paths per pixel (0: skip the covariance pass).
    #[arg(long, default_value_t = 4)]
    pub cov_paths: u32,
    /// Seed of the random numbers (the image does not depend on the thread count).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Render at this size instead of the scene's (`WIDTHxHEIGHT`, e.g. `640x480`).
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
}

/// Parses `WIDTHxHEIGHT`.
///
/// # Errors
/// Not of that form, or a side outside 1..=MAX_RESOLUTION.
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let max = cov_render::scene::MAX_RESOLUTION;
    let bad = || {
        format!(
            "--size must be WIDTHxHEIGHT with sides 1 to {max}, got `{}`",
            cov_render::echo(s)
        )
    };
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h) = (
        w.trim().parse::<u32>().map_err(|_| bad())?,
        h.trim().parse::<u32>().map_err(|_| bad())?,
    );
    if !(1..=max).contains(&w) || !(1..=max).contains(&h) {
        return Err(bad());
    }
    Ok((w, h))
}

/// The files a render writes, from the EXR's path `out.exr`: `out.png`, `out.density.png`,
/// `out.filter.png`, `out.cov.json`.
pub fn outputs(exr: &Path) -> [PathBuf; 4] {
    let stem = exr.with_extension("");
    let s = stem.display().to_string();
    [
        exr.with_extension("png"),
        PathBuf::from(format!("{s}.density.png")),
        PathBuf::from(format!("{s}.filter.png")),
        PathBuf::from(format!("{s}.cov.json")),
    ]
}

/// Checks that `out` can be written before any work is done.
///
/// # Errors
/// A wrong extension, a missing or unwritable folder.
pub fn check_output(out: &Path, ext: &str) -> Result<(), String> {
    if out.extension().and_then(|e| e.to_str()) != Some(ext) {
        return Err(format!("{}: the output must be a .{ext} file", out.display()));
    }
    let dir = match out.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if !dir.is_dir() {
        return Err(format!("{}: no such folder", dir.display()));
    }
    let probe = dir.join(format!(".covtrace-write-test-{}", std::process::id()));
    std::fs::write(&probe, b"").map_err(|e| format!("{}: cannot write here: {e}", dir.display()))?;
    let _ = std::fs::remove_file(probe);
    Ok(())
}

/// Checks `--ref-spp` (1 to [`MAX_SPP`]) and `--cov-paths` (1 to [`MAX_COV_PATHS`]).
///
/// # Errors
/// Either out of range, named as the user wrote it.
pub fn check_counts(ref_spp: u32, cov_paths: u32) -> Result<(), String> {
    if ref_spp == 0 || ref_spp > MAX_SPP {
        return Err(format!("--ref-spp must be 1 to {MAX_SPP}, got {ref_spp}"));
    }
    if cov_paths == 0 || cov_paths > MAX_COV_PATHS {
        return Err(format!(
            "--cov-paths must be 1 to {MAX_COV_PATHS}, got {cov_paths}"
        ));
    }
    Ok(())
}

/// A progress bar over `len` tiles labelled `what`.
pub fn bar(len: usize, what: &str) -> ProgressBar {
    let b = ProgressBar::new(len as u64);
    b.set_style(
        ProgressStyle::with_template("{msg:12} {bar:40} {pos}/{len} tiles [{elapsed}]")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    b.set_message(what.to_string());
    b
}

/// Runs `covtrace render`; returns the lines to print.
///
/// # Errors
/// A bad scene (one positioned line), bad arguments, unwritable outputs.
pub fn run(a: &RenderArgs) -> Result<String, String> {
    if a.spp == 0 || a.spp > MAX_SPP {
        return Err(format!("--spp must be 1 to {MAX_SPP}, got {}", a.spp));
    }
    if a.cov_paths > MAX_COV_PATHS {
        return Err(format!(
            "--cov-paths must be 0 to {MAX_COV_PATHS}, got {}",
            a.cov_paths
        ));
    }
    check_output(&a.output, "exr")?;
    let mut world = World::load(&a.scene).map_err(|e| e.to_string())?;
    if let Some((w, h)) = a.size {
        world = world.with_resolution(w, h);
    }
    let (w, h) = (world.camera.width, world.camera.height);
    let [png, density, filter, json] = outputs(&a.output);
    let tiles = tile_count(&world);
    let mut out = format!(
        "scene: {} ({w}×{h} px, {} primitives, {} lights, covariance layout {})\n",
        a.scene.display(),
        world.geometry.len(),
        world.lights.len(),
        if world.has_motion {
            "5 (x,y,u,v,t)"
        } else {
            "4 (x,y,u,v)"
        }
    );
    let b = bar(tiles, "rendering");
    let counts = vec![a.spp; (w * h) as usize];
    let ((img, _), t_render) = timed(|| render_adaptive(&world, &counts, a.seed, Some(&|| b.inc(1))));
    b.finish_and_clear();
    write_image(&img, &a.output, &png)?;
    out.push_str(&format!(
        "render: {} spp in {t_render:.2} s ({:.3e} camera samples/s)\n  {}\n  {}\n",
        a.spp,
        (w as f64 * h as f64 * a.spp as f64) / t_render.max(1e-9),
        a.output.display(),
        png.display()
    ));
    if a.cov_paths > 0 {
        let b = bar(tiles, "covariance");
        let (maps, t_cov) = timed(|| covariance_maps_with(&world, a.cov_paths, a.seed, Some(&|| b.inc(1))));
        b.finish_and_clear();
        let maps = maps?;
        let sp = covtrace::sensor::SensorParams::default();
        write_maps(&maps, sp.filter, sp.max_filter, &density, &filter, &json)?;
        let mean_spp = maps.pixels.iter().map(|p| p.spp).sum::<f64>() / maps.pixels.len().max(1) as f64;
        out.push_str(&format!(
            "covariance: {} paths per pixel in {t_cov:.2} s ({:.1}% of the total); predicted {mean_spp:.2} spp on average\n  {}\n  {}\n  {}\n",
            a.cov_paths,
            100.0 * t_cov / (t_cov + t_render).max(1e-9),
            density.display(),
            filter.display(),
            json.display()
        ));
    }
    Ok(out)
}

/// What `covtrace render-check` was asked (parsed by clap).
#[derive(Clone, Debug, clap::Args)]
pub struct CheckArgs {
    /// The scene file.
    pub scene: PathBuf,
    /// Samples per pixel of each of the two references.
    #[arg(long, default_value_t = 256)]
    pub ref_spp: u32,
    /// Covariance paths per pixel.
    #[arg(long, default_value_t = 8)]
    pub cov_paths: u32,
    /// Render at this size instead of the scene's (`WIDTHxHEIGHT`).
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Write the per-tile comparison as JSON.
    #[arg(long)]
    pub json: Option<PathBuf>,
}

/// Runs `covtrace render-check`: a reference at `ref_spp`, the covariance maps, and their
/// agreement tile by tile ([`cov_render::validate::compare`]); returns the report.
///
/// # Errors
/// A bad scene or arguments, an unwritable JSON file.
pub fn check(a: &CheckArgs) -> Result<String, String> {
    check_counts(a.ref_spp, a.cov_paths)?;
    if let Some(j) = &a.json {
        check_output(j, "json")?;
    }
    let mut world = World::load(&a.scene).map_err(|e| e.to_string())?;
    if let Some((w, h)) = a.size {
        world = world.with_resolution(w, h);
    }
    let (w, h) = (world.camera.width, world.camera.height);
    let tiles = tile_count(&world);
    // Two independent references (other seeds): their cross-spectrum has no noise term.
    // Samples are clamped at 4× the image's mean luminance (from a 4-spp preview), so
    // that rare caustic fireflies, which no pair of renders cancels, do not read as detail.
    let preview = render_adaptive(
        &world,
        &vec![4; (w * h) as usize],
        a.seed.wrapping_add(3000),
        None,
    )
    .0;
    let mean_l = preview
        .pixels
        .iter()
        .map(|p| cov_render::trace::luminance(*p))
        .sum::<f64>()
        / (w * h) as f64;
    let clamp = if mean_l > 0.0 { 4.0 * mean_l } else { f64::INFINITY };
    let b = bar(2 * tiles, "reference");
    let counts = vec![a.ref_spp; (w * h) as usize];
    let reference = |k: u64| {
        render_clamped(
            &world,
            &counts,
            a.seed.wrapping_add(k * 1000),
            clamp,
            Some(&|| b.inc(1)),
        )
        .0
    };
    let ((ref_a, ref_b), t_ref) = timed(|| (reference(1), reference(2)));
    b.finish_and_clear();
    let b = bar(tiles, "covariance");
    let (maps, t_cov) = timed(|| covariance_maps_with(&world, a.cov_paths, a.seed, Some(&|| b.inc(1))));
    b.finish_and_clear();
    let maps = maps?;
    let filter = covtrace::sensor::SensorParams::default().filter;
    let agreement = cov_render::validate::compare(&ref_a, &ref_b, &maps, filter);
    if let Some(j) = &a.json {
        let text = serde_json::to_string_pretty(&agreement).map_err(|e| e.to_string())?;
        std::fs::write(j, text).map_err(|e| format!("{}: {e}", j.display()))?;
    }
    let n = agreement.tiles.len();
    Ok(format!(
        "scene: {} ({w}×{h} px), two references of {} spp in {t_ref:.1} s, covariance {} paths/px in {t_cov:.2} s\n\
         tiles of {t}×{t} px: {n}, with detail: {}\n\
         predicted / measured bandwidth (median over tiles with detail): {}\n\
         rank correlation (Spearman) over tiles with detail: {}\n\
         under-sampled tiles (predicted < half the measured bandwidth): {:.1}% of tiles with detail",
        a.scene.display(),
        a.ref_spp,
        a.cov_paths,
        agreement.detail_tiles,
        fmt_num(agreement.median_ratio),
        fmt_num(agreement.rank_correlation),
        100.0 * agreement.undersampled,
        t = cov_render::validate::T,
    ))
}

/// A number for a report: three significant digits, `n/a` when undefined.
fn fmt_num(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.3}")
    } else {
        "n/a".into()
    }
}
