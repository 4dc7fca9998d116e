//! `covtrace render`: renders a scene file with covariance tracing (or another method of
//! [`Method`]) through the library's [`Renderer`], and writes the image and the covariance
//! maps; `covtrace render-check`: the maps against reference images.

use std::path::{Path, PathBuf};

use cov_render::covpass::MAX_COV_PATHS;
use cov_render::denoise::Denoise;
use cov_render::film::tile_count;
use cov_render::output::{write_image, write_maps};
use cov_render::parts::{Part, PartFilm};
use cov_render::renderer::timed;
use cov_render::{MAX_SPP, Method, RenderError, RenderSettings, Renderer, World};
use indicatif::{ProgressBar, ProgressStyle};

/// What `covtrace render` was asked (parsed by clap).
#[derive(Clone, Debug, clap::Args)]
pub struct RenderArgs {
    /// The scene file.
    pub scene: PathBuf,
    /// Sampling and reconstruction method: cov (covariance tracing: per-pixel filters from
    /// Σ, checked against the samples by the guard, and samples where they are needed),
    /// cov-unguarded, cov-density, cov-filter (ablations), variance, gauss or uniform
    /// (plain Monte Carlo).
    #[arg(long, default_value = "cov", value_parser = parse_method)]
    pub method: Method,
    /// Average samples per pixel (of each pass, with --time).
    #[arg(long, default_value_t = 16, value_parser = parse_spp)]
    pub spp: u32,
    /// Render progressively: passes of --spp over the same per-pixel sequences until
    /// this many seconds are spent (covariance pass included).
    #[arg(long)]
    pub time: Option<f64>,
    /// Denoise the image with Intel Open Image Denoise: oidn (guided by the first hit's
    /// albedo and normal) or oidn-color (the colour alone); with --method cov the denoiser
    /// receives the box image of the samples the guard allocated (below 3 spp, with no
    /// pilot, uniform samples and no covariance pass). Needs a build with
    /// `--features oidn` (docs/oidn.md).
    #[arg(long, value_parser = parse_denoise, default_value = "none")]
    pub denoise: Denoise,
    /// Output EXR (linear); a PNG and the covariance maps are written beside it.
    #[arg(short, long, default_value = "render.exr")]
    pub output: PathBuf,
    /// Covariance paths per block of the covariance grid.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=i64::from(cov_render::covpass::MAX_COV_PATHS)))]
    pub cov_paths: u32,
    /// Side of the covariance grid's blocks (px): 1, 2, 4, 8 or 16.
    #[arg(long, default_value_t = 4)]
    pub cov_stride: u32,
    /// Surface vertices each covariance path follows: 1 (camera → hit → light; the
    /// default, measured better) to the scene's `max_depth` (every vertex the path tracer
    /// samples; 2 unless the scene says otherwise).
    #[arg(long, default_value_t = cov_render::DEFAULT_DEPTH, value_parser = clap::value_parser!(u32).range(1..=i64::from(cov_render::covpass::MAX_DEPTH)))]
    pub cov_depth: u32,
    /// Seed of the random numbers (the image does not depend on the thread count).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Render at this size instead of the scene's (`WIDTHxHEIGHT`, e.g. `640x480`).
    #[arg(long, value_parser = parse_size, allow_hyphen_values = true)]
    pub size: Option<(u32, u32)>,
    /// Render only part I of N (`I/N`, e.g. `2/4`) and write it as a part file (EXR) for
    /// `covtrace merge`: a job array renders the parts, one merge makes the image, which is
    /// the image of `--parts N` in one process.
    #[arg(long, value_parser = parse_part, allow_hyphen_values = true)]
    pub part: Option<Part>,
    /// Split the allocation of samples into N parts of the rows, each spending its own
    /// pixels' share of the budget, as a render in N parts does (default 1: the budget is
    /// spread over the whole image).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=i64::from(cov_render::renderer::MAX_PARTS)))]
    pub parts: Option<u32>,
    /// Render frame K of an animation: the shutter moves by K / the scene's frame_rate.
    #[arg(long, conflicts_with = "frames", value_parser = clap::value_parser!(u32).range(0..=i64::from(cov_render::world::MAX_FRAME)))]
    pub frame: Option<u32>,
    /// Render frames A to B (`A..B`, B included), each to OUT with its number before the
    /// extension (`out.0007.exr`).
    #[arg(long, value_parser = parse_frames)]
    pub frames: Option<(u32, u32)>,
}

/// What `covtrace merge` was asked (parsed by clap).
#[derive(Clone, Debug, clap::Args)]
pub struct MergeArgs {
    /// The part files (`covtrace render --part I/N -o PART.exr`), in any order.
    #[arg(required = true)]
    pub parts: Vec<PathBuf>,
    /// Output EXR (linear); the PNG, the feature images and the covariance maps are
    /// written beside it, as `render` writes them.
    #[arg(short, long, default_value = "render.exr")]
    pub output: PathBuf,
}

/// Parses `--part I/N`.
///
/// # Errors
/// Not of that form.
pub fn parse_part(s: &str) -> Result<Part, String> {
    Part::parse(s)
}

/// Parses `--frames A..B` (`A ≤ B ≤ MAX_FRAME`, at most [`MAX_FRAMES`] frames).
///
/// # Errors
/// Not of that form, or out of range.
pub fn parse_frames(s: &str) -> Result<(u32, u32), String> {
    let max = cov_render::world::MAX_FRAME;
    let bad = || {
        format!(
            "--frames must be A..B with 0 ≤ A ≤ B ≤ {max} and at most {MAX_FRAMES} frames, got `{}`",
            cov_render::echo(s)
        )
    };
    let (a, b) = s.split_once("..").ok_or_else(bad)?;
    let (a, b) = (
        a.trim().parse::<u32>().map_err(|_| bad())?,
        b.trim().parse::<u32>().map_err(|_| bad())?,
    );
    if a > b || b > max || b - a >= MAX_FRAMES {
        return Err(bad());
    }
    Ok((a, b))
}

/// Parses `--spp`: a whole number of samples per pixel, 1 to [`cov_render::MAX_SPP`].
///
/// # Errors
/// Not a whole number, or out of range.
pub fn parse_spp(s: &str) -> Result<u32, String> {
    let max = cov_render::MAX_SPP;
    s.trim()
        .parse::<u32>()
        .ok()
        .filter(|n| (1..=max).contains(n))
        .ok_or_else(|| format!("must be a whole number of samples per pixel, 1 to {max}"))
}

/// Most frames one `covtrace render --frames A..B` renders.
pub const MAX_FRAMES: u32 = 100_000;

/// Parses a denoiser name: `none`, `oidn` or `oidn-color`.
///
/// # Errors
/// An unknown name, or a denoiser this build does not have.
pub fn parse_denoise(s: &str) -> Result<Denoise, String> {
    let d = match s.trim() {
        "none" => Denoise::None,
        t => Denoise::from_name(t)
            .filter(|d| *d != Denoise::None)
            .ok_or_else(|| {
                format!(
                    "unknown denoiser `{}` (one of: none, oidn, oidn-color)",
                    cov_render::echo(s)
                )
            })?,
    };
    if d != Denoise::None && !cov_render::denoise::AVAILABLE {
        return Err(
            "this covtrace was built without Open Image Denoise: rebuild with `--features oidn` and OIDN_DIR set (docs/oidn.md)"
                .into(),
        );
    }
    Ok(d)
}

/// Parses a method name ([`Method::from_name`]).
///
/// # Errors
/// An unknown name, with the known ones.
pub fn parse_method(s: &str) -> Result<Method, String> {
    Method::from_name(s.trim()).ok_or_else(|| {
        format!(
            "unknown method `{}` (one of: {})",
            cov_render::echo(s),
            Method::ALL.map(Method::name).join(", ")
        )
    })
}

/// The render settings of `covtrace render`'s arguments, named as the user wrote them
/// when out of range.
///
/// # Errors
/// `--spp`, `--time`, `--cov-paths`, `--cov-stride` or `--parts` out of range; `--part`
/// and `--parts` that disagree.
pub fn settings(a: &RenderArgs) -> Result<RenderSettings, String> {
    let s = RenderSettings {
        method: a.method,
        spp: f64::from(a.spp),
        seed: a.seed,
        time: a.time,
        cov_paths: a.cov_paths,
        cov_stride: a.cov_stride,
        cov_depth: a.cov_depth,
        max_luminance: f64::INFINITY,
        denoise: a.denoise,
        parts: match (a.part, a.parts) {
            (Some(p), Some(n)) if p.count != n => {
                return Err(format!(
                    "--part {p} renders a part of {} parts, but --parts is {n}",
                    p.count
                ));
            }
            (Some(p), _) => p.count,
            (None, n) => n.unwrap_or(1),
        },
    };
    // The library's own check, its setting named as the flag the user wrote.
    s.check().map_err(|e| match e {
        RenderError::Setting { name, expected, got } => {
            format!("--{} must be {expected}, got {got}", name.replace('_', "-"))
        }
        other => other.to_string(),
    })?;
    Ok(s)
}

/// Parses `WIDTHxHEIGHT`.
///
/// # Errors
/// Not of that form, or a side outside 1..=MAX_RESOLUTION.
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let max = cov_render::scene::MAX_RESOLUTION;
    let bad = || {
        format!(
            "--size must be WIDTHxHEIGHT (or WIDTH×HEIGHT) with sides 1 to {max}, got `{}`",
            cov_render::echo(s)
        )
    };
    // `×` too, as the reports print sizes.
    let (w, h) = s.split_once(['x', 'X', '×']).ok_or_else(bad)?;
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
/// `out.filter.png`, `out.cov.json`, and the feature images `out.aov.exr`.
pub fn outputs(exr: &Path) -> [PathBuf; 5] {
    // The stem as the system has it (not as text, which would turn a byte that is not
    // UTF-8 into U+FFFD and write these files under another name than the image).
    let with = |suffix: &str| {
        let mut s = exr.with_extension("").into_os_string();
        s.push(suffix);
        PathBuf::from(s)
    };
    [
        exr.with_extension("png"),
        with(".density.png"),
        with(".filter.png"),
        with(".cov.json"),
        with(".aov.exr"),
    ]
}

/// Checks that `out` can be written before any work is done.
///
/// # Errors
/// A wrong extension, a missing or unwritable folder.
pub fn check_output(out: &Path, ext: &str) -> Result<(), String> {
    if out.extension().and_then(|e| e.to_str()) != Some(ext) {
        return Err(format!("{}: the output must be a .{ext} file", shown(out)));
    }
    let dir = match out.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if !dir.is_dir() {
        let what = if dir.exists() {
            "not a folder"
        } else {
            "no such folder"
        };
        return Err(format!("{}: {what}", shown(&dir)));
    }
    let probe = dir.join(format!(".covtrace-write-test-{}", std::process::id()));
    std::fs::write(&probe, b"").map_err(|e| format!("{}: cannot write here: {e}", shown(&dir)))?;
    let _ = std::fs::remove_file(probe);
    Ok(())
}

/// A renderer's error as the command line says it: a setting is named by its option
/// (`--cov-depth`, not `cov_depth`).
pub fn said(e: cov_render::RenderError) -> String {
    match e {
        cov_render::RenderError::Setting { name, expected, got } => {
            format!("--{} must be {expected}, got {got}", name.replace('_', "-"))
        }
        e => e.to_string(),
    }
}

/// A path as an error shows it: on one line, shortened ([`cov_render::echo`]).
pub fn shown(p: &Path) -> String {
    cov_render::echo(&p.display().to_string())
}

/// Refuses to write any of `outputs` (named by the option `option`) over one of `inputs`,
/// by whatever path it is reached (`./x`, a link, a hard link): an input lost is work to
/// do again, or gone.
///
/// # Errors
/// An output that is an input, in one line.
pub fn not_an_input(outputs: &[PathBuf], inputs: &[PathBuf], option: &str) -> Result<(), String> {
    for o in outputs {
        if let Some(i) = inputs.iter().find(|i| same_file(o, i)) {
            return Err(format!(
                "{}: an input of this run, which the outputs of {option} would overwrite (as {}); give {option} another name",
                shown(i),
                shown(o)
            ));
        }
    }
    Ok(())
}

/// Whether `a` and `b` are the same existing file (on Unix the same device and inode, so
/// a hard link counts).
fn same_file(a: &Path, b: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (std::fs::metadata(a), std::fs::metadata(b)) {
            (Ok(x), Ok(y)) => x.dev() == y.dev() && x.ino() == y.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        matches!((a.canonicalize(), b.canonicalize()), (Ok(x), Ok(y)) if x == y)
    }
}

/// The files `render` writes for the EXR `exr`, the EXR first.
fn written(exr: &Path) -> Vec<PathBuf> {
    std::iter::once(exr.to_path_buf()).chain(outputs(exr)).collect()
}

/// The files a run on `world`, loaded from `scene`, reads.
fn read_by(scene: &Path, world: &World) -> Vec<PathBuf> {
    std::iter::once(scene.to_path_buf())
        .chain(world.inputs.iter().cloned())
        .collect()
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

/// Loads the scene of `covtrace render`, `render-check` or `render-bench`, at `size` when
/// given.
///
/// The scene's warnings ([`World::warnings`]) go to the standard error, one line each,
/// beside the errors.
///
/// # Errors
/// The scene's own error, one positioned line.
pub fn load(scene: &Path, size: Option<(u32, u32)>) -> Result<World, String> {
    let world = World::load(scene).map_err(|e| e.to_string())?;
    for w in &world.warnings {
        eprintln!("warning: {w}");
    }
    Ok(match size {
        Some((w, h)) => world.with_resolution(w, h),
        None => world,
    })
}

/// Runs `covtrace render`; returns the lines to print.
///
/// # Errors
/// A bad scene (one positioned line), bad arguments, unwritable outputs.
pub fn run(a: &RenderArgs) -> Result<String, String> {
    let settings = settings(a)?;
    check_output(&a.output, "exr")?;
    if a.part.is_some() && a.time.is_some() {
        return Err("--part and --time exclude each other: a part renders a fixed budget".into());
    }
    let world = load(&a.scene, a.size)?;
    let index = a.part.map_or(1, |p| p.index);
    cov_render::renderer::part_rows(world.camera.height, index, settings.parts).map_err(|e| {
        match a.part {
            // The count came with the part: say so of `--part`.
            Some(p) => {
                let (h, tile) = (world.camera.height, cov_render::film::TILE);
                let rows = cov_render::renderer::tile_rows(h);
                let (s, sp) = if rows == 1 { ("", "") } else { ("s", "s") };
                format!(
                    "--part {p}: this image's {h} rows make {rows} tile row{s} of {tile}, so it splits into 1 to {rows} part{sp}, not {}",
                    p.count
                )
            }
            None => said(e),
        }
    })?;
    match (a.frame, a.frames) {
        (_, Some((first, last))) => {
            // Every frame checked before any is rendered. Motion is linear in time, so a
            // shape's distance from the origin is convex in it: with the first frame in
            // range, the frames out of range are those from the first one out to the last,
            // found by bisection.
            if let Some(expected) = world.frame_problem(first) {
                return Err(format!(
                    "--frames {first}..{last}: frame {first} is out of range: must be {expected}"
                ));
            }
            if world.frame_problem(last).is_some() {
                let (mut ok, mut bad) = (first, last);
                while bad - ok > 1 {
                    let mid = ok + (bad - ok) / 2;
                    if world.frame_problem(mid).is_some() {
                        bad = mid;
                    } else {
                        ok = mid;
                    }
                }
                let expected = world.frame_problem(bad).unwrap_or_default();
                let which = if bad == last {
                    format!("frame {last} is")
                } else {
                    format!("frames {bad} to {last} are")
                };
                return Err(format!(
                    "--frames {first}..{last}: {which} out of range: must be {expected}"
                ));
            }
            // No frame's outputs over an input (the scene, its textures and meshes, the
            // same for every frame), also checked before any frame is rendered.
            let inputs = read_by(&a.scene, &world);
            for k in first..=last {
                not_an_input(&written(&frame_path(&a.output, k)), &inputs, "-o")?;
            }
            // One scene, retimed for each frame; each frame's report printed as it is
            // done, the last one returned.
            let mut world = world;
            let mut k = first;
            loop {
                world = world.at_frame(k).map_err(said)?;
                let report = format!(
                    "frame {k}:\n{}",
                    render_one(a, &settings, &world, &frame_path(&a.output, k))?
                );
                if k == last {
                    return Ok(report);
                }
                crate::cli::emit(report.trim_end())?;
                k += 1;
            }
        }
        (k, None) => {
            let world = world.at_frame(k.unwrap_or(0)).map_err(said)?;
            render_one(a, &settings, &world, &a.output)
        }
    }
}

/// `out.exr` with frame `k`'s number before the extension: `out.0007.exr`.
pub fn frame_path(out: &Path, k: u32) -> PathBuf {
    out.with_extension(format!("{k:04}.exr"))
}

/// Renders one frame (or one part of it) of `world` to `output`.
fn render_one(
    a: &RenderArgs,
    settings: &RenderSettings,
    world: &World,
    output: &Path,
) -> Result<String, String> {
    not_an_input(&written(output), &read_by(&a.scene, world), "-o")?;
    if let Some(p) = a.part {
        return render_part(a, settings, world, p, output);
    }
    let (w, h) = (world.camera.width, world.camera.height);
    let [png, density, filter, json, aov] = outputs(output);
    // "1 light", "2 lights".
    let count = |n: usize, what: &str| format!("{n} {what}{}", if n == 1 { "" } else { "s" });
    let mut out = format!(
        "scene: {} ({w}×{h} px, {}, {})\n",
        cov_render::echo(&a.scene.display().to_string()),
        count(world.geometry.len(), "primitive"),
        count(world.lights.len(), "light"),
    );
    let mut renderer = Renderer::new(world, settings.clone()).map_err(said)?;
    let (b, start) = match a.time {
        None => (bar(renderer.progress_len(), "rendering"), None),
        Some(t) => (seconds_bar(t), Some(std::time::Instant::now())),
    };
    let tick = || match start {
        None => b.inc(1),
        Some(s) => b.set_position(s.elapsed().as_millis() as u64),
    };
    let r = renderer.render(Some(&tick)).map_err(|e| e.to_string());
    b.finish_and_clear();
    let r = r?;
    write_image(&r.image, output, &png).map_err(|e| e.to_string())?;
    cov_render::output::write_aovs(&r.film.aovs(), &aov).map_err(|e| e.to_string())?;
    let total = r.timing.total();
    if let Some(maps) = renderer.maps() {
        let sp = covtrace::sensor::SensorParams::default();
        write_maps(maps, sp.filter, sp.max_filter, &density, &filter, &json).map_err(|e| e.to_string())?;
        let mean_spp = maps.pixels.iter().map(|p| p.spp).sum::<f64>() / maps.pixels.len().max(1) as f64;
        out.push_str(&format!(
            "covariance: {} path(s) per {s}×{s} block, layout {} ({}), in {:.2} s ({:.1}% of the render); predicted {mean_spp:.1} spp on average (density map: log scale, 1 to {:.0} spp)\n",
            maps.paths_per_block,
            maps.layout,
            layout_axes(maps.layout),
            r.timing.covariance,
            100.0 * r.timing.covariance / total.max(1e-9),
            cov_render::output::density_scale_top(maps),
            s = maps.stride,
        ));
    } else if r.method.uses_covariance() {
        out.push_str(
            "covariance: not traced (with a denoiser, Σ only allocates samples after a pilot, and this budget has none: below 3 spp)\n",
        );
    }
    let n = f64::from(w) * f64::from(h);
    let reached = match a.time {
        None => String::new(),
        Some(t) => format!(
            "; {} pass{} of {} spp in the {} s asked, {:.1} spp on average reached{}",
            r.passes,
            if r.passes == 1 { "" } else { "es" },
            a.spp,
            // As typed, unless its decimals would run on (1e-300).
            if (1e-3..1e6).contains(&t) {
                t.to_string()
            } else {
                format!("{t:e}")
            },
            r.samples as f64 / n,
            if r.capped {
                format!(
                    " (stopped before the time: every pixel holds {} samples, the most a pixel takes)",
                    cov_render::film::MAX_SPP
                )
            } else {
                String::new()
            }
        ),
    };
    out.push_str(&format!("image digest: {:016x}\n", r.image.digest()));
    out.push_str(&format!(
        "render: {}, {} samples ({:.1} spp on average) in {total:.2} s (sampling {:.2} s, allocation {:.2} s, reconstruction {:.2} s{}){reached}\n",
        r.method.with_denoiser(a.denoise),
        r.samples,
        r.samples as f64 / n,
        r.timing.sampling,
        r.timing.allocation,
        r.timing.reconstruction,
        if a.denoise == Denoise::None {
            String::new()
        } else {
            format!(", denoising {:.2} s", r.timing.denoising)
        },
    ));
    if r.image
        .pixels
        .iter()
        .all(|p| p.x == 0.0 && p.y == 0.0 && p.z == 0.0)
    {
        // The likely causes this scene can have: a light facing away, or no radiance.
        let rect = world
            .lights
            .iter()
            .any(|l| matches!(l, cov_render::world::Light::Rect { .. }));
        // A warning, on the standard error beside the errors, not among the results.
        eprintln!(
            "warning: the image is black: no light reached the camera (is every light's radiance 0, or does the camera see only what no light reaches?{})",
            if rect {
                " A Rect light emits on the side of edge_u × edge_v."
            } else {
                ""
            }
        );
    }
    let mut written = vec![output.to_path_buf(), png, aov];
    if renderer.maps().is_some() {
        written.extend([density, filter, json]);
    }
    out.push_str("wrote:\n");
    for f in written {
        out.push_str(&format!("  {}\n", cov_render::echo(&f.display().to_string())));
    }
    Ok(out)
}

/// Renders part `part` of `world` and writes it to `output` (a part file).
fn render_part(
    a: &RenderArgs,
    settings: &RenderSettings,
    world: &World,
    part: Part,
    output: &Path,
) -> Result<String, String> {
    let mut renderer = Renderer::new(world, settings.clone()).map_err(said)?;
    let b = bar(
        renderer.part_progress_len(part).map_err(|e| e.to_string())?,
        "rendering",
    );
    let p = renderer.render_part(part, Some(&|| b.inc(1)));
    b.finish_and_clear();
    let p = p.map_err(|e| e.to_string())?;
    p.write(output).map_err(|e| e.to_string())?;
    let n = f64::from(world.camera.width) * f64::from(p.rows.end - p.rows.start);
    Ok(format!(
        "scene: {} ({}×{} px), frame {}\npart {part}: rows {}..{}, {} samples ({:.1} spp on average) in {:.2} s (covariance {:.2} s, sampling {:.2} s, allocation {:.2} s)\nwrote:\n  {}\n",
        cov_render::echo(&a.scene.display().to_string()),
        world.camera.width,
        world.camera.height,
        world.frame,
        p.rows.start,
        p.rows.end,
        p.samples(),
        p.samples() as f64 / n.max(1.0),
        p.timing.total(),
        p.timing.covariance,
        p.timing.sampling,
        p.timing.allocation,
        cov_render::echo(&output.display().to_string()),
    ))
}

/// Runs `covtrace merge`; returns the lines to print.
///
/// # Errors
/// A part file that cannot be read or is not a part; parts that do not make one render;
/// unwritable outputs.
pub fn merge(a: &MergeArgs) -> Result<String, String> {
    check_output(&a.output, "exr")?;
    let max = cov_render::parts::MAX_PARTS as usize;
    if a.parts.len() > max {
        return Err(format!(
            "{} part files given; a render has at most {max} parts",
            a.parts.len()
        ));
    }
    let [png, density, filter, json, aov] = outputs(&a.output);
    // A merge must not overwrite the parts it reads: a part lost is a job to run again.
    not_an_input(&written(&a.output), &a.parts, "-o")?;
    let parts = a
        .parts
        .iter()
        .map(|p| PartFilm::read(p).map_err(|e| e.to_string()))
        .collect::<Result<Vec<_>, _>>()?;
    let m = cov_render::parts::merge(&parts).map_err(|e| e.to_string())?;
    write_image(&m.image, &a.output, &png).map_err(|e| e.to_string())?;
    cov_render::output::write_aovs(&m.film.aovs(), &aov).map_err(|e| e.to_string())?;
    let mut written = vec![a.output.clone(), png, aov];
    if let Some(maps) = &m.maps {
        let sp = covtrace::sensor::SensorParams::default();
        write_maps(maps, sp.filter, sp.max_filter, &density, &filter, &json).map_err(|e| e.to_string())?;
        written.extend([density, filter, json]);
    }
    let k = &m.key;
    let mut out = format!(
        "render: {}×{} px, frame {}, {} at {} spp, seed {}, in {} part{}\n",
        k.width,
        k.height,
        k.frame,
        m.method
            .with_denoiser(cov_render::denoise::Denoise::from_name(&k.denoise).unwrap_or_default()),
        k.spp,
        k.seed,
        k.parts,
        if k.parts == 1 { "" } else { "s" }
    );
    let mut sorted: Vec<&PartFilm> = parts.iter().collect();
    sorted.sort_by_key(|p| p.part.index);
    for p in sorted {
        out.push_str(&format!(
            "  part {}: rows {}..{}, {} samples in {:.2} s ({})\n",
            p.part,
            p.rows.start,
            p.rows.end,
            p.samples(),
            p.timing.total(),
            p.source
        ));
    }
    out.push_str(&format!("image digest: {:016x}\n", m.image.digest()));
    out.push_str(&format!(
        "merge: reconstruction {:.2} s{}\nwrote:\n",
        m.timing.reconstruction,
        if m.timing.denoising > 0.0 {
            format!(", denoising {:.2} s", m.timing.denoising)
        } else {
            String::new()
        }
    ));
    for f in written {
        out.push_str(&format!("  {}\n", cov_render::echo(&f.display().to_string())));
    }
    Ok(out)
}

/// The axes of a covariance layout.
fn layout_axes(n: usize) -> &'static str {
    match n {
        2 => "x, u",
        3 => "x, u, t",
        4 => "x, y, u, v",
        _ => "x, y, u, v, t",
    }
}

/// A progress bar over the seconds of a time-limited render.
fn seconds_bar(secs: f64) -> ProgressBar {
    let b = ProgressBar::new((secs * 1000.0) as u64);
    b.set_style(
        ProgressStyle::with_template("{msg:12} {bar:40} {elapsed} of the time asked")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    b.set_message("rendering");
    b
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
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=i64::from(cov_render::covpass::MAX_COV_PATHS)))]
    pub cov_paths: u32,
    /// Surface vertices each covariance path follows: 1 (camera → hit → light; the
    /// default, measured better) to the scene's `max_depth` (every vertex the path tracer
    /// samples; 2 unless the scene says otherwise).
    #[arg(long, default_value_t = cov_render::DEFAULT_DEPTH, value_parser = clap::value_parser!(u32).range(1..=i64::from(cov_render::covpass::MAX_DEPTH)))]
    pub cov_depth: u32,
    /// Render at this size instead of the scene's (`WIDTHxHEIGHT`).
    #[arg(long, value_parser = parse_size, allow_hyphen_values = true)]
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
    let world = load(&a.scene, a.size)?;
    if let Some(j) = &a.json {
        not_an_input(std::slice::from_ref(j), &read_by(&a.scene, &world), "--json")?;
    }
    let (w, h) = (world.camera.width, world.camera.height);
    let t = cov_render::validate::T as u32;
    if w < t || h < t {
        return Err(format!(
            "render-check compares tiles of {t}×{t} px: the image ({w}×{h} px) must be at least that (--size)"
        ));
    }
    let tiles = tile_count(&world);
    let uniform = |spp: u32, seed: u64, max_luminance: f64| RenderSettings {
        method: Method::Uniform,
        spp: f64::from(spp),
        seed,
        max_luminance,
        ..RenderSettings::default()
    };
    // The covariance pass's renderer first: its settings are checked before any
    // reference is rendered.
    let mut renderer = Renderer::new(
        &world,
        RenderSettings {
            cov_paths: a.cov_paths,
            cov_stride: 1,
            cov_depth: a.cov_depth,
            seed: a.seed,
            ..RenderSettings::default()
        },
    )
    .map_err(said)?;
    let render = |s: RenderSettings, b: &ProgressBar| -> Result<cov_render::Image, String> {
        let mut r = Renderer::new(&world, s).map_err(said)?;
        Ok(r.render(Some(&|| b.inc(1))).map_err(|e| e.to_string())?.image)
    };
    // Two independent references (other seeds): their cross-spectrum has no noise term.
    // Samples are clamped at 4× the image's mean luminance (from a 4-spp preview), so
    // that rare caustic fireflies, which no pair of renders cancels, do not read as detail.
    let preview = render(
        uniform(4, a.seed.wrapping_add(3000), f64::INFINITY),
        &ProgressBar::hidden(),
    )?;
    let mean_l = preview
        .pixels
        .iter()
        .map(|p| cov_render::trace::luminance(*p))
        .sum::<f64>()
        / (w * h) as f64;
    let clamp = if mean_l > 0.0 { 4.0 * mean_l } else { f64::INFINITY };
    let b = bar(2 * tiles, "reference");
    let reference = |k: u64| render(uniform(a.ref_spp, a.seed.wrapping_add(k * 1000), clamp), &b);
    let (refs, t_ref) = timed(|| (reference(1), reference(2)));
    b.finish_and_clear();
    let (ref_a, ref_b) = (refs.0?, refs.1?);
    // The maps at one prediction per pixel (the finest grid), `cov_paths` paths each.
    let b = bar(tiles, "covariance");
    let (maps, t_cov) = timed(|| renderer.trace_covariance(Some(&|| b.inc(1))).cloned());
    b.finish_and_clear();
    let maps = maps.map_err(|e| e.to_string())?;
    let filter = covtrace::sensor::SensorParams::default().filter;
    let agreement = cov_render::validate::compare(&ref_a, &ref_b, &maps, filter);
    if let Some(j) = &a.json {
        let text = serde_json::to_string_pretty(&agreement).map_err(|e| e.to_string())?;
        cov_render::output::write_file(j, text.as_bytes()).map_err(|e| e.to_string())?;
    }
    let n = agreement.tiles.len();
    // A rank correlation needs two tiles with detail; fewer, and it is not defined.
    let defined = |v: f64| if agreement.detail_tiles >= 2 { v } else { f64::NAN };
    Ok(format!(
        "scene: {} ({w}×{h} px), two references of {} spp in {t_ref:.1} s, covariance {} path(s) per pixel in {t_cov:.2} s\n\
         tiles of {t}×{t} px: {n}, with detail: {}\n\
         predicted / measured bandwidth (median over tiles with detail): {}\n\
         rank correlation (Spearman) over tiles with detail: {}\n\
         for comparison: predicted against the variation's bandwidth alone (mean removed): {}; the references' own contrast against the measurement: {}\n\
         under-sampled tiles (predicted < half the measured bandwidth): {} of tiles with detail",
        cov_render::echo(&a.scene.display().to_string()),
        a.ref_spp,
        a.cov_paths,
        agreement.detail_tiles,
        fmt_num(agreement.median_ratio),
        fmt_num(defined(agreement.rank_correlation)),
        fmt_num(defined(agreement.variation_correlation)),
        fmt_num(defined(agreement.contrast_correlation)),
        if agreement.detail_tiles > 0 {
            format!("{:.1}%", 100.0 * agreement.undersampled)
        } else {
            "n/a (none)".to_string()
        },
        t = cov_render::validate::T,
    ) + &a
        .json
        .as_ref()
        .map_or(String::new(), |j| format!("\nwrote {}", shown(j))))
}

/// A number for a report: three significant digits, `n/a` when undefined.
fn fmt_num(v: f64) -> String {
    if v.is_finite() {
        format!("{v:.3}")
    } else {
        "n/a".into()
    }
}
