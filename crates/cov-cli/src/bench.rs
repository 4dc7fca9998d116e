//! `covtrace render-bench`: every sampling and reconstruction method
//! ([`cov_render::Method`]) at several sample budgets, against a cached
//! high-spp reference; image error against wall-clock time, the equal-error speed-up over
//! plain Monte Carlo, and the timing breakdown.
//!
//! Writes into the output folder: `results.csv`, `results.json`, `error_time.png` and
//! `.svg` (relMSE against seconds, log–log), `strip.png` (each method at about equal
//! time beside the reference) and `reference.png`. The reference is cached as
//! `reference-<key>.exr`, keyed by the scene's fingerprint (its text and every file it
//! reads: textures, meshes), size, reference spp and seed.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use cov_render::adaptive::Guide;
use cov_render::bench::{fit_loglog, speedup};
use cov_render::covpass::STRIDES;
use cov_render::denoise::Denoise;
use cov_render::film::tile_count;
use cov_render::metrics::measure;
use cov_render::output::{read_image, tonemap, write_image};
use cov_render::renderer::timed;
use cov_render::{MAX_SPP, Method, RenderSettings, Rendered, Renderer, World};
use plotters::coord::Shift;
use plotters::prelude::*;

use crate::plot::{COLORS, Picture, log_tick};
use crate::render::{bar, parse_size};

/// A method and the denoiser after it, named as on the command line (`cov`, `cov+oidn`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Variant(pub Method, pub Denoise);

impl Variant {
    /// Plain Monte Carlo, the baseline of every speed-up.
    pub const UNIFORM: Variant = Variant(Method::Uniform, Denoise::None);

    /// Its name in tables and on the command line.
    pub fn name(self) -> String {
        self.0.with_denoiser(self.1)
    }

    /// Whether it needs the covariance pass.
    pub fn uses_covariance(self) -> bool {
        self.0.uses_covariance()
    }
}

/// Largest number of budgets one bench takes.
pub const MAX_BUDGETS: usize = 12;

/// What `covtrace render-bench` was asked (parsed by clap).
#[derive(Clone, Debug, clap::Args)]
pub struct BenchArgs {
    /// The scene file.
    pub scene: PathBuf,
    /// Average samples per pixel of each run, comma-separated (whole numbers, 1 to 65536
    /// each; sorted, a repeated one run once).
    #[arg(long, value_delimiter = ',', default_values_t = [2.0, 4.0, 8.0, 16.0, 32.0])]
    pub budgets: Vec<f64>,
    /// Methods, comma-separated (default: all): uniform, gauss, variance, cov-density,
    /// cov-filter, cov-unguarded, cov; each may be followed by +oidn or +oidn-color (a
    /// build with `--features oidn`). Uniform sampling always runs: it is the line the
    /// equal-error speed-ups are read against.
    #[arg(long, value_delimiter = ',')]
    pub methods: Vec<String>,
    /// Samples per pixel of the reference.
    #[arg(long, default_value_t = 1024)]
    pub ref_spp: u32,
    /// Covariance paths per block of the covariance grid.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=i64::from(cov_render::covpass::MAX_COV_PATHS)))]
    pub cov_paths: u32,
    /// Side of the covariance grid's blocks (px): `cov_paths` paths per block of
    /// `stride × stride` pixels (1, 2, 4, 8 or 16).
    #[arg(long, default_value_t = 4)]
    pub cov_stride: u32,
    /// Surface vertices each covariance path follows: 1 (camera → hit → light; the
    /// default, measured better) to the scene's `max_depth` (every vertex the path tracer
    /// samples; 2 unless the scene says otherwise).
    #[arg(long, default_value_t = cov_render::DEFAULT_DEPTH, value_parser = clap::value_parser!(u32).range(1..=i64::from(cov_render::covpass::MAX_DEPTH)))]
    pub cov_depth: u32,
    /// Render at this size instead of the scene's (`WIDTHxHEIGHT`).
    #[arg(long, value_parser = parse_size, allow_hyphen_values = true)]
    pub size: Option<(u32, u32)>,
    /// Seed of the runs (the reference uses another).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Split each run's allocation into this many parts of the rows, as a render in parts
    /// does (`covtrace render --parts N`): what splitting costs in error.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=i64::from(cov_render::renderer::MAX_PARTS)))]
    pub parts: u32,
    /// Output folder (created with its missing parents).
    #[arg(short, long, default_value = "render-bench")]
    pub output: PathBuf,
    /// Folder of cached references, each with its digest (default: the output folder).
    #[arg(long)]
    pub cache: Option<PathBuf>,
    /// Renders each run this many times with different seeds: errors are averaged, the
    /// fastest time is kept (1 to 10).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=10))]
    pub repeat: u32,
}

/// One row of the results.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Row {
    /// Method name (with its denoiser: `cov+oidn`).
    pub method: String,
    /// Average samples per pixel asked for.
    pub budget: f64,
    /// Samples taken.
    pub samples: u64,
    /// Wall-clock seconds in all.
    pub seconds: f64,
    /// Of which the covariance pass.
    pub covariance_s: f64,
    /// Tracing samples.
    pub sampling_s: f64,
    /// Splatting through filters.
    pub reconstruction_s: f64,
    /// Allocating samples.
    pub allocation_s: f64,
    /// Root mean square error against the reference.
    pub rmse: f64,
    /// Relative mean square error against the reference.
    pub relmse: f64,
    /// Equal-error speed-up over uniform Monte Carlo (`null` when undefined).
    pub speedup: Option<f64>,
}

impl Row {
    fn new(v: Variant, r: &Rendered, reference: &cov_render::Image) -> Result<Row, String> {
        let e = measure(&r.image, reference).map_err(|e| e.to_string())?;
        Ok(Row {
            method: v.name(),
            budget: r.budget,
            samples: r.samples,
            seconds: r.timing.total(),
            covariance_s: r.timing.covariance,
            sampling_s: r.timing.sampling,
            reconstruction_s: r.timing.reconstruction,
            allocation_s: r.timing.allocation,
            rmse: e.rmse,
            relmse: e.relmse,
            speedup: None,
        })
    }
}

/// FNV-1a, 64 bits: the cache key of a reference (stable across builds and machines).
fn fnv(bytes: &[u8], mut h: u64) -> u64 {
    for &b in bytes {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x100_0000_01b3);
    }
    h
}

fn methods(names: &[String]) -> Result<Vec<Variant>, String> {
    if names.is_empty() {
        return Ok(Method::ALL.map(|m| Variant(m, Denoise::None)).to_vec());
    }
    let mut out = Vec::new();
    for n in names {
        let (m, d) = Method::parse_with_denoiser(n.trim()).ok_or_else(|| {
            format!(
                "--methods: unknown method `{}` (one of: {}; each may be followed by +oidn or +oidn-color)",
                cov_render::echo(n),
                Method::ALL.map(Method::name).join(", ")
            )
        })?;
        if d != Denoise::None && !cov_render::denoise::AVAILABLE {
            return Err(format!(
                "--methods: `{}` needs Open Image Denoise, and this covtrace was built without it: rebuild with `--features oidn` and OIDN_DIR set (docs/oidn.md)",
                cov_render::echo(n)
            ));
        }
        let v = Variant(m, d);
        if !out.contains(&v) {
            out.push(v);
        }
    }
    if out.iter().any(|m| *m != Variant::UNIFORM) && !out.contains(&Variant::UNIFORM) {
        // Speed-ups are measured against uniform Monte Carlo: always run it.
        out.insert(0, Variant::UNIFORM);
    }
    Ok(out)
}

/// Checks the arguments before any work.
fn check_args(a: &BenchArgs) -> Result<(Vec<Variant>, Vec<f64>), String> {
    if a.budgets.is_empty() || a.budgets.len() > MAX_BUDGETS {
        return Err(format!(
            "--budgets: give 1 to {MAX_BUDGETS} values, got {}",
            a.budgets.len()
        ));
    }
    for &b in &a.budgets {
        // Whole numbers, as `covtrace render --spp` takes, so that every run can be
        // rendered again on its own.
        if !(b.is_finite() && (1.0..=f64::from(MAX_SPP)).contains(&b) && b.fract() == 0.0) {
            return Err(format!(
                "--budgets: each must be a whole number of samples per pixel, 1 to {MAX_SPP}, got {b}"
            ));
        }
    }
    crate::render::check_counts(a.ref_spp, a.cov_paths)?;
    if !(1..=10).contains(&a.repeat) {
        return Err(format!("--repeat must be 1 to 10, got {}", a.repeat));
    }
    if !STRIDES.contains(&a.cov_stride) {
        return Err(format!(
            "--cov-stride must be one of {STRIDES:?}, got {}",
            a.cov_stride
        ));
    }
    let mut budgets = a.budgets.clone();
    budgets.sort_by(f64::total_cmp);
    budgets.dedup();
    Ok((methods(&a.methods)?, budgets))
}

/// Creates (if needed, with its missing parents, as `mkdir -p`) and checks a folder for
/// writing.
fn folder(dir: &Path, what: &str) -> Result<(), String> {
    if dir.exists() && !dir.is_dir() {
        return Err(format!(
            "{what} {}: there is a file there, not a folder",
            crate::render::shown(dir)
        ));
    }
    if !dir.is_dir() {
        std::fs::create_dir_all(dir)
            .map_err(|e| format!("{what} {}: cannot create it: {e}", crate::render::shown(dir)))?;
    }
    crate::render::check_output(&dir.join("probe.json"), "json")
}

/// The cached reference's file, and its image when the cache holds a sound one.
fn cached(a: &BenchArgs, world: &World, cache: &Path) -> (PathBuf, Option<cov_render::Image>) {
    let (w, h) = (world.camera.width, world.camera.height);
    // Keyed by the estimator's revision (`ESTIMATOR_REVISION`), so that a reference an
    // older tracer rendered is never measured against, and by the scene's fingerprint, so
    // that a texture or a mesh changed under the same scene text is a new reference.
    let key = fnv(
        format!(
            "covtrace-reference-v{} {w}x{h} {} {} {:016x}",
            cov_render::trace::ESTIMATOR_REVISION,
            a.ref_spp,
            a.seed,
            world.fingerprint
        )
        .as_bytes(),
        0xcbf2_9ce4_8422_2325,
    );
    let exr = cache.join(format!("reference-{key:016x}.exr"));
    // Sound: its size, finite pixels, and the digest written beside it when it was
    // rendered (a damaged file that still decodes, a byte flipped in a tile, is rendered
    // again rather than measured against).
    let img = read_image(&exr).ok().filter(|img| {
        (img.width, img.height) == (w, h)
            && img.pixels.iter().all(|p| p.is_finite())
            && std::fs::read_to_string(digest_path(&exr)).is_ok_and(|d| d.trim() == pixel_digest(img))
    });
    (exr, img)
}

/// The file beside a cached reference `exr` that holds its [`pixel_digest`].
fn digest_path(exr: &Path) -> PathBuf {
    exr.with_extension("digest")
}

/// FNV-1a (64 bits, hex) of an image's pixels as its EXR stores them (32-bit floats).
fn pixel_digest(img: &cov_render::Image) -> String {
    let bytes: Vec<u8> = img
        .pixels
        .iter()
        .flat_map(|p| [p.x, p.y, p.z])
        .flat_map(|v| (v as f32).to_le_bytes())
        .collect();
    format!("{:016x}", fnv(&bytes, 0xcbf2_9ce4_8422_2325))
}

/// The reference image: the cached one (`cached`), else rendered and cached as `exr`.
fn reference(
    a: &BenchArgs,
    world: &World,
    (exr, cached): (PathBuf, Option<cov_render::Image>),
) -> Result<(cov_render::Image, String), String> {
    if let Some(img) = cached {
        return Ok((img, format!("reference: {} (cached)", exr.display())));
    }
    let b = bar(tile_count(world), "reference");
    let settings = RenderSettings {
        method: Method::Uniform,
        spp: f64::from(a.ref_spp),
        seed: a.seed.wrapping_add(0x5eed_0000_0000),
        ..RenderSettings::default()
    };
    let (img, secs) = timed(|| Renderer::new(world, settings)?.render(Some(&|| b.inc(1))));
    b.finish_and_clear();
    let img = img.map_err(|e| e.to_string())?.image;
    // A cache file there that was not sound (`cached`): said, as it is replaced.
    let again = if exr.exists() {
        " (the cached file was damaged or had no digest: rendered again)"
    } else {
        ""
    };
    write_image(&img, &exr, &exr.with_extension("png")).map_err(|e| e.to_string())?;
    // The digest of what the file holds, as it reads back.
    let back = read_image(&exr).map_err(|e| e.to_string())?;
    cov_render::output::write_file(&digest_path(&exr), pixel_digest(&back).as_bytes())
        .map_err(|e| e.to_string())?;
    Ok((
        img,
        format!(
            "reference: {} spp in {secs:.1} s, cached as {}{again}",
            a.ref_spp,
            exr.display()
        ),
    ))
}

/// Runs `covtrace render-bench`; returns the report.
///
/// # Errors
/// Bad arguments or scene, unwritable outputs.
pub fn bench(a: &BenchArgs) -> Result<String, String> {
    let (methods, budgets) = check_args(a)?;
    let world = crate::render::load(&a.scene, a.size)?;
    let settings = |Variant(method, denoise): Variant, spp: f64, seed: u64| RenderSettings {
        method,
        spp,
        seed,
        denoise,
        cov_paths: a.cov_paths,
        cov_stride: a.cov_stride,
        cov_depth: a.cov_depth,
        parts: a.parts,
        ..RenderSettings::default()
    };
    // The runs' settings checked against the scene (`--parts` against its rows,
    // `--cov-depth` against its depth) before any folder is made or the reference, which
    // may take minutes, is rendered.
    Renderer::new(&world, settings(Variant::UNIFORM, budgets[0], 1)).map_err(crate::render::said)?;
    folder(&a.output, "output folder")?;
    let cache = a.cache.clone().unwrap_or_else(|| a.output.clone());
    // The cache must take a new reference, unless it holds this one (it may be read-only).
    let found = cached(a, &world, &cache);
    if found.1.is_none() {
        folder(&cache, "cache folder")?;
    }
    // What the run writes in the output folder must not be what it reads.
    let mut written: Vec<std::path::PathBuf> = [
        "results.csv",
        "results.json",
        "error_time.png",
        "error_time.svg",
        "strip.png",
    ]
    .iter()
    .map(|f| a.output.join(f))
    .collect();
    for m in &methods {
        for ext in ["exr", "png", "error.png"] {
            written.push(a.output.join(format!("{}.{ext}", m.name())));
        }
    }
    let read: Vec<std::path::PathBuf> = std::iter::once(a.scene.clone())
        .chain(world.inputs.iter().cloned())
        .collect();
    crate::render::not_an_input(&written, &read, "-o")?;
    let (w, h) = (world.camera.width, world.camera.height);
    let mut out = format!(
        "scene: {} ({w}×{h} px)\n",
        cov_render::echo(&a.scene.display().to_string())
    );
    let (reference, line) = reference(a, &world, found)?;
    out.push_str(&line);
    out.push('\n');
    cov_render::output::save(tonemap(&reference), &a.output.join("reference.png"))
        .map_err(|e| e.to_string())?;

    // Every run goes through the library's renderer, with a covariance guide traced here
    // (its time is added to every covariance run that reads it: not to `cov` followed by a
    // denoiser below 3 spp, which has no pilot, `cov_render::renderer::reads_covariance`).
    let run = |m: Variant, budget: f64, guide: Option<&Guide>, seed: u64| -> Result<Rendered, String> {
        let mut r = Renderer::new(&world, settings(m, budget, seed)).map_err(crate::render::said)?;
        if let Some(g) = guide {
            r = r.with_guide(g.clone()).map_err(|e| e.to_string())?;
        }
        r.render(None).map_err(|e| e.to_string())
    };
    // Warm-up (caches, the thread pool): one uniform pass at 1 spp, not recorded.
    run(Variant::UNIFORM, 1.0, None, a.seed ^ 0x77)?;
    // Repeat k renders with seed k, the first with `--seed`: the errors are averaged over
    // them (a low-spp image's error depends on where its rare bright paths fell).
    let seeds: Vec<u64> = (0..a.repeat)
        .map(|k| a.seed.wrapping_add(u64::from(k) * 1_000_003))
        .collect();
    // The covariance pass, once per repeat with that repeat's seed: the map is part of
    // the method's randomness (one path per block is a noisy estimate), so the repeats
    // average over maps too. Its fastest time is added to every covariance run that reads
    // it (the pass does not depend on the budget).
    let guides: Vec<Guide> = if methods.iter().any(|m| m.uses_covariance()) {
        let mut guides = Vec::with_capacity(seeds.len());
        for &seed in &seeds {
            let b = bar(tile_count(&world), "covariance");
            let mut r = Renderer::new(&world, settings(Variant(Method::Cov, Denoise::None), 1.0, seed))
                .map_err(|e| e.to_string())?;
            let traced = r.trace_covariance(Some(&|| b.inc(1))).map(|_| ());
            b.finish_and_clear();
            traced.map_err(|e| e.to_string())?;
            guides.extend(r.guide().cloned());
        }
        let fastest = guides.iter().map(|g| g.secs).fold(f64::INFINITY, f64::min);
        for g in &mut guides {
            g.secs = fastest;
        }
        if let Some(g) = guides.first() {
            let _ = writeln!(
                out,
                "covariance pass: {} path(s) of depth {} per {s}×{s} block, {:.3} s (with the matched filters; one map per seed)",
                a.cov_paths,
                a.cov_depth,
                g.secs,
                s = a.cov_stride
            );
        }
        guides
    } else {
        Vec::new()
    };

    let total = budgets.len() * methods.len();
    let b = indicatif::ProgressBar::new(total as u64);
    b.set_style(
        indicatif::ProgressStyle::with_template("{msg:12} {bar:40} {pos}/{len} runs [{elapsed}]")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    b.set_message("render-bench");
    let mut rows: Vec<Row> = Vec::new();
    let mut images: Vec<(Variant, f64, f64, cov_render::Image)> = Vec::new();
    for &budget in &budgets {
        for &m in &methods {
            // The errors are averaged over the repeats' seeds, the fastest time is kept.
            let first = run(m, budget, guides.first(), seeds[0])?;
            let mut row = Row::new(m, &first, &reference)?;
            for (k, &seed) in seeds.iter().enumerate().skip(1) {
                let again = Row::new(m, &run(m, budget, guides.get(k), seed)?, &reference)?;
                row.rmse += again.rmse;
                row.relmse += again.relmse;
                if again.seconds < row.seconds {
                    row = Row {
                        rmse: row.rmse,
                        relmse: row.relmse,
                        ..again
                    };
                }
            }
            row.rmse /= f64::from(a.repeat);
            row.relmse /= f64::from(a.repeat);
            images.push((m, budget, row.seconds, first.image));
            rows.push(row);
            b.inc(1);
        }
    }
    b.finish_and_clear();
    let curve = |name: &str| -> Vec<(f64, f64)> {
        rows.iter()
            .filter(|r| r.method == name)
            .map(|r| (r.seconds, r.relmse))
            .collect()
    };
    let uniform = curve("uniform");
    for r in &mut rows {
        r.speedup = speedup(&uniform, r.seconds, r.relmse);
    }
    write_results(&a.output, &rows, &uniform, at_error(&rows, &methods))?;
    let chart = a.output.join("error_time.png");
    let title = format!(
        "{}: relMSE against wall-clock time ({w}×{h} px, 2-core CPU)",
        a.scene
            .file_name()
            .map_or_else(String::new, |s| s.to_string_lossy().into_owned())
    );
    for ext in ["png", "svg"] {
        let p = chart.with_extension(ext);
        crate::plot::save(
            &p,
            (1100, 560),
            &ErrorChart {
                rows: &rows,
                methods: &methods,
                title: &title,
            },
        )
        .map_err(|e| format!("{}: {e}", crate::render::shown(&p)))?;
    }
    let strip = a.output.join("strip.png");
    let (target, picked) = write_strip(&strip, &images, &reference)?;
    out.push_str(&summary(&rows, &methods, &budgets));
    let _ = writeln!(
        out,
        "equal-time strip (≈{target:.2} s per image): {}\nwrote {}, {}, {}, {}, {}, reference.png and, per method, METHOD.exr, METHOD.png and METHOD.error.png in {}",
        picked,
        a.output.join("results.csv").display(),
        a.output.join("results.json").display(),
        chart.display(),
        chart.with_extension("svg").display(),
        strip.display(),
        a.output.display()
    );
    Ok(out)
}

/// The table printed at the end: relMSE per method and budget, the median equal-error
/// speed-up, and the covariance share of time.
fn summary(rows: &[Row], methods: &[Variant], budgets: &[f64]) -> String {
    let mut s = String::from(
        "\nrelMSE (seconds) per budget; equal-error speed-up over uniform (median over budgets)\n",
    );
    let _ = write!(s, "{:<18}", "method");
    for b in budgets {
        let _ = write!(s, "{:>20}", format!("{b} spp"));
    }
    let _ = writeln!(s, "{:>10}{:>12}", "speed-up", "cov share");
    for m in methods {
        let mine: Vec<&Row> = rows.iter().filter(|r| r.method == m.name()).collect();
        let _ = write!(s, "{:<18}", m.name());
        for r in &mine {
            let _ = write!(s, "{:>20}", format!("{:.3e} ({:.2})", r.relmse, r.seconds));
        }
        let mut sp: Vec<f64> = mine.iter().filter_map(|r| r.speedup).collect();
        sp.sort_by(f64::total_cmp);
        let med = if sp.is_empty() {
            "n/a".to_string()
        } else {
            format!("{:.2}×", sp[sp.len() / 2])
        };
        let share: f64 = mine
            .iter()
            .map(|r| r.covariance_s / r.seconds.max(1e-12))
            .sum::<f64>()
            / mine.len().max(1) as f64;
        let _ = writeln!(s, "{med:>10}{:>11.1}%", 100.0 * share);
    }
    if let Some((target, times)) = at_error(rows, methods) {
        let _ = writeln!(
            s,
            "\nat relMSE {target:.3e} (uniform's error at its largest budget): seconds to reach it, and the speed-up over uniform"
        );
        let base = times.iter().find(|(m, _)| *m == "uniform").and_then(|(_, t)| *t);
        for (m, t) in &times {
            let _ = match (t, base) {
                (Some((t, exact)), Some((b, _))) => {
                    let ge = if *exact { "" } else { "≥ " };
                    writeln!(s, "{m:<18}{t:>10.3} s{:>12}", format!("{ge}{:.2}×", b / t))
                }
                _ => writeln!(s, "{m:<18}{:>12}", "not reached"),
            };
        }
        let _ = writeln!(s, "(≥: the method's smallest budget is already below that error)");
    } else if rows.iter().any(|r| r.method == "uniform") {
        let _ = writeln!(
            s,
            "\nuniform's error at its largest budget is 0 (a black reference, or an image every sample gets exactly): no equal-error time to compare"
        );
    }
    s
}

/// The error uniform Monte Carlo reaches at its largest budget, and the time each method
/// needs to reach it ([`cov_render::bench::time_to_reach`]).
fn at_error(rows: &[Row], methods: &[Variant]) -> AtError {
    let target = rows
        .iter()
        .filter(|r| r.method == "uniform")
        .max_by(|a, b| a.budget.total_cmp(&b.budget))?
        .relmse;
    // No error to reach: every time would read 0 or "not reached", neither meaningful.
    if target <= 0.0 {
        return None;
    }
    let times = methods
        .iter()
        .map(|m| {
            let curve: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.method == m.name())
                .map(|r| (r.seconds, r.relmse))
                .collect();
            (m.name(), cov_render::bench::time_to_reach(&curve, target))
        })
        .collect();
    Some((target, times))
}

/// What [`at_error`] gives: the target error and each method's time to reach it (and
/// whether interpolated).
type AtError = Option<(f64, Vec<(String, Option<(f64, bool)>)>)>;

fn write_results(dir: &Path, rows: &[Row], uniform: &[(f64, f64)], at: AtError) -> Result<(), String> {
    let mut csv = String::from(
        "method,budget_spp,samples,seconds,covariance_s,sampling_s,reconstruction_s,allocation_s,rmse,relmse,speedup_vs_uniform\n",
    );
    for r in rows {
        let _ = writeln!(
            csv,
            "{},{},{},{:.6},{:.6},{:.6},{:.6},{:.6},{:.6e},{:.6e},{}",
            r.method,
            r.budget,
            r.samples,
            r.seconds,
            r.covariance_s,
            r.sampling_s,
            r.reconstruction_s,
            r.allocation_s,
            r.rmse,
            r.relmse,
            r.speedup.map_or_else(String::new, |v| format!("{v:.4}"))
        );
    }
    let p = dir.join("results.csv");
    cov_render::output::write_file(&p, csv.as_bytes()).map_err(|e| e.to_string())?;
    let fit = fit_loglog(uniform).map(|(a, b)| serde_json::json!({ "log_relmse_at_1s": a, "slope": b }));
    let json = serde_json::json!({
        "units": { "seconds": "wall-clock s", "relmse": "mean over pixels and channels of (I-R)^2/(R^2+0.01)" },
        "uniform_fit": fit,
        "at_uniform_best_error": at.map(|(e, times)| serde_json::json!({
            "relmse": e,
            // Per method: seconds to reach the error, and whether interpolated (false: the
            // method's smallest budget is already below it, so the time is an upper bound).
            "methods": times.into_iter().map(|(m, t)| (m.to_string(), serde_json::json!(t.map(|(s, i)| serde_json::json!({ "seconds": s, "interpolated": i }))))).collect::<serde_json::Map<_, _>>(),
        })),
        "runs": rows,
    });
    let p = dir.join("results.json");
    let text = serde_json::to_string_pretty(&json).map_err(|e| e.to_string())?;
    cov_render::output::write_file(&p, text.as_bytes()).map_err(|e| e.to_string())
}

/// Log-axis tick labels at 1, 2 and 5 of each decade only (the other grid lines unlabelled).
fn sparse_log_tick(v: &f64) -> String {
    let m = *v / 10f64.powf(v.log10().floor());
    if [1.0, 2.0, 5.0].iter().any(|k| (m - k).abs() < 1e-6 * k) {
        log_tick(v)
    } else {
        String::new()
    }
}

/// The log–log chart of relMSE against seconds, a line per method.
struct ErrorChart<'a> {
    rows: &'a [Row],
    methods: &'a [Variant],
    title: &'a str,
}

impl Picture for ErrorChart<'_> {
    fn draw<DB: DrawingBackend>(&self, root: DrawingArea<DB, Shift>) -> Result<(), Box<dyn std::error::Error>>
    where
        DB::ErrorType: 'static,
    {
        root.fill(&WHITE)?;
        let (w, _) = root.dim_in_pixel();
        let (left, right) = root.split_horizontally(w.saturating_sub(260));
        let ok = |r: &&Row| r.seconds > 0.0 && r.relmse > 0.0 && r.relmse.is_finite();
        let (mut t0, mut t1, mut e0, mut e1) = (f64::MAX, 0.0f64, f64::MAX, 0.0f64);
        for r in self.rows.iter().filter(ok) {
            t0 = t0.min(r.seconds);
            t1 = t1.max(r.seconds);
            e0 = e0.min(r.relmse);
            e1 = e1.max(r.relmse);
        }
        if !(t0 < t1 && e0 < e1) {
            (t0, t1, e0, e1) = (1e-2, 1.0, 1e-4, 1.0);
        }
        let mut chart = ChartBuilder::on(&left)
            .caption(self.title, ("sans-serif", 18))
            .margin(15)
            .x_label_area_size(45)
            .y_label_area_size(70)
            .build_cartesian_2d((t0 / 1.5..t1 * 1.5).log_scale(), (e0 / 1.5..e1 * 1.5).log_scale())?;
        chart
            .configure_mesh()
            .x_label_formatter(&sparse_log_tick)
            .y_label_formatter(&sparse_log_tick)
            .x_desc("wall-clock time [s] (covariance pass included)")
            .y_desc("relMSE against the reference")
            .label_style(("sans-serif", 13))
            .axis_desc_style(("sans-serif", 13))
            // The log axes' minor lines bunch towards each decade: the ticks' lines alone.
            .light_line_style(TRANSPARENT)
            .bold_line_style(RGBColor(215, 215, 215))
            .draw()?;
        let font = ("sans-serif", 14).into_font().color(&BLACK);
        right.draw(&Text::new("method", (6, 40), font.clone()))?;
        for (i, m) in self.methods.iter().enumerate() {
            let color = COLORS[i % COLORS.len()];
            let pts: Vec<(f64, f64)> = self
                .rows
                .iter()
                .filter(|r| r.method == m.name())
                .filter(ok)
                .map(|r| (r.seconds, r.relmse))
                .collect();
            let width = if m.uses_covariance() { 3 } else { 2 };
            chart.draw_series(LineSeries::new(pts.iter().copied(), color.stroke_width(width)))?;
            chart.draw_series(pts.iter().map(|&p| Circle::new(p, 4, color.filled())))?;
            let y = 70 + 24 * i as i32;
            right.draw(&PathElement::new(
                vec![(6, y), (34, y)],
                color.stroke_width(width),
            ))?;
            right.draw(&Circle::new((20, y), 4, color.filled()))?;
            right.draw(&Text::new(m.name(), (42, y - 8), font.clone()))?;
        }
        root.present()?;
        Ok(())
    }
}

/// Writes the equal-time strip: for each method the run nearest (in log time) to uniform
/// Monte Carlo's time at the middle budget, beside the reference, each labelled with
/// method, spp, seconds and relMSE, above the centre quarter of each enlarged 4×.
/// Returns the target time and what was picked.
fn write_strip(
    path: &Path,
    images: &[(Variant, f64, f64, cov_render::Image)],
    reference: &cov_render::Image,
) -> Result<(f64, String), String> {
    let uni: Vec<&(Variant, f64, f64, cov_render::Image)> =
        images.iter().filter(|i| i.0 == Variant::UNIFORM).collect();
    let target = uni.get(uni.len() / 2).map_or(1.0, |u| u.2).max(1e-9);
    let mut methods: Vec<Variant> = Vec::new();
    for i in images {
        if !methods.contains(&i.0) {
            methods.push(i.0);
        }
    }
    let mut panels: Vec<(String, String, &cov_render::Image)> = Vec::new();
    let mut picked = Vec::new();
    for m in methods {
        let best = images
            .iter()
            .filter(|i| i.0 == m)
            .min_by(|a, b| (a.2 / target).ln().abs().total_cmp(&(b.2 / target).ln().abs()));
        if let Some((m, budget, secs, img)) = best {
            // This image's own error (the table averages over repeats).
            let rel = measure(img, reference).map_err(|e| e.to_string())?.relmse;
            panels.push((
                format!("{} · {budget} spp · {secs:.2} s", m.name()),
                format!("relMSE {rel:.2e}"),
                img,
            ));
            picked.push(format!("{} {budget} spp", m.name()));
            let dir = path.parent().unwrap_or(Path::new("."));
            let name = dir.join(format!("{}.exr", m.name()));
            write_image(img, &name, &name.with_extension("png")).map_err(|e| e.to_string())?;
            let err = dir.join(format!("{}.error.png", m.name()));
            let map = cov_render::output::error_map(img, reference).map_err(|e| e.to_string())?;
            cov_render::output::save(map, &err).map_err(|e| e.to_string())?;
        }
    }
    panels.push(("reference".into(), String::new(), reference));
    // Small images are enlarged (nearest pixel) so that labels fit and pixels show.
    let scale = (300 / reference.width.max(1)).clamp(1, 8);
    let (iw, ih) = (reference.width * scale, reference.height * scale);
    let gap = 6u32;
    let band = 40u32;
    // A second row: the centre quarter of each image, enlarged 4× (nearest pixel).
    let (cw, ch) = ((reference.width / 4).max(1), (reference.height / 4).max(1));
    let (cx, cy) = ((reference.width - cw) / 2, (reference.height - ch) / 2);
    let (w, h) = (panels.len() as u32 * (iw + gap) + gap, 2 * ih + band + 2 * gap);
    crate::plot::register_font()?;
    let mut buf = vec![255u8; w as usize * h as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        let font = ("sans-serif", 13).into_font().color(&BLACK);
        for (k, (a, b, _)) in panels.iter().enumerate() {
            let x = (gap + k as u32 * (iw + gap)) as i32;
            root.draw(&Text::new(a.as_str(), (x, 4), font.clone()))
                .map_err(|e| e.to_string())?;
            root.draw(&Text::new(b.as_str(), (x, 21), font.clone()))
                .map_err(|e| e.to_string())?;
        }
        root.present().map_err(|e| e.to_string())?;
    }
    let mut pic = image::RgbImage::from_raw(w, h, buf).ok_or("strip buffer size")?;
    for (k, (_, _, img)) in panels.iter().enumerate() {
        let full = tonemap(img);
        let zoom = image::imageops::crop_imm(&full, cx, cy, cw, ch).to_image();
        let zoom = image::imageops::resize(&zoom, iw, ih, image::imageops::FilterType::Nearest);
        image::imageops::replace(
            &mut pic,
            &zoom,
            i64::from(gap + k as u32 * (iw + gap)),
            i64::from(band + ih + gap),
        );
        let t = image::imageops::resize(&full, iw, ih, image::imageops::FilterType::Nearest);
        image::imageops::replace(
            &mut pic,
            &t,
            i64::from(gap + k as u32 * (iw + gap)),
            i64::from(band),
        );
    }
    cov_render::output::save(pic, path).map_err(|e| e.to_string())?;
    Ok((target, picked.join(", ")))
}
