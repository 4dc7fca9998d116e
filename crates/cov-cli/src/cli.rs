//! The `covtrace` command line itself, as a library entry ([`run_with`]), so that a third
//! party's binary gives the same commands with its own operators.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use covtrace::path::{Path, Registry};
use indicatif::{ProgressBar, ProgressStyle};

use crate::{format_evaluation, plot, report};

#[derive(Parser)]
#[command(
    name = "covtrace",
    version,
    about = "Covariance tracing: frequency analysis of light transport"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

// A negative number given to an option (`--spp -1`) is read as its value, so that the
// option's own check names it; clap would otherwise take it for an unknown flag and advise
// `-- -1`, which does not work either.
#[derive(Subcommand)]
enum Command {
    /// Trace a RON path: Σ after every step.
    Eval {
        /// The path file.
        path: PathBuf,
        /// Print JSON (axis names, every step's matrix, the final matrix).
        #[arg(long)]
        json: bool,
        /// How Σ is held while tracing: square-root (default, the accurate form) or
        /// covariance (cheaper kernels).
        #[arg(long, value_enum, default_value_t = FormArg::SquareRoot)]
        form: FormArg,
    },
    /// Draw the spectrum ellipses after every step.
    Plot {
        /// The path file.
        path: PathBuf,
        /// Output PNG.
        #[arg(short, long)]
        output: PathBuf,
    },
    /// The brute-force error-against-run-time report.
    Validate {
        /// Add the 512-point grid (slow).
        #[arg(long)]
        full: bool,
        /// Output chart (SVG; a PNG is written beside it).
        #[arg(short, long, default_value = "validate_report.svg")]
        output: String,
    },
    /// The registered operators and their parameters.
    List,
    /// Check the covariance pass against a reference render: the local spectrum of each
    /// 16×16 tile against the predicted bandwidth.
    #[command(allow_negative_numbers = true)]
    RenderCheck(crate::render::CheckArgs),
    /// Render a scene (RON) with covariance tracing (by default; --method picks another
    /// method): the covariance pass, samples where it predicts detail, per-pixel filters
    /// from Σ; writes the image (EXR and PNG) and, when the pass runs, the density and
    /// filter maps.
    #[command(allow_negative_numbers = true)]
    Render(crate::render::RenderArgs),
    /// Merge the parts of a render (`covtrace render --part I/N`) into its image: the
    /// single-process render's, bit for bit; writes what `render` writes.
    #[command(allow_negative_numbers = true)]
    Merge(crate::render::MergeArgs),
    /// Image error against run time: every sampling and reconstruction method (uniform,
    /// Gaussian, variance-driven, covariance-driven) at several budgets against a cached
    /// reference; writes CSV/JSON, the error-time chart and an equal-time strip.
    #[command(allow_negative_numbers = true)]
    RenderBench(crate::bench::BenchArgs),
    /// The stiff suite: extreme chains in both forms and plain f64 against a
    /// double-double reference.
    #[command(allow_negative_numbers = true)]
    Stiff {
        /// Length of the long chains: 4 to 1,000,000 operators, rounded down to whole
        /// bounces of four.
        #[arg(long, default_value_t = 10_000, value_parser = clap::value_parser!(u32).range(4..=1_000_000))]
        length: u32,
    },
}

/// `--form` values.
#[derive(Clone, Copy, clap::ValueEnum)]
enum FormArg {
    /// Σ = L Lᵀ, updated by array algorithms.
    SquareRoot,
    /// Σ itself.
    Covariance,
}

impl From<FormArg> for covtrace::Form {
    fn from(f: FormArg) -> Self {
        match f {
            FormArg::SquareRoot => covtrace::Form::SquareRoot,
            FormArg::Covariance => covtrace::Form::Covariance,
        }
    }
}

/// Prints a line; a closed pipe (`covtrace list | head`) is not an error.
macro_rules! say {
    ($($t:tt)*) => {
        emit(&format!($($t)*))?
    };
}

/// Writes a line to standard output. A closed pipe (`covtrace list | head`) ends the output
/// quietly; any other failure (a full disk, `> /dev/full`) is an error.
pub(crate) fn emit(line: &str) -> Result<(), String> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match writeln!(out, "{line}").and_then(|()| out.flush()) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        Err(e) => Err(format!("cannot write the output: {e}")),
    }
}

/// Clap's message for a bad command line, in one line: its error and tips, without the
/// usage block (`covtrace X --help` shows that).
fn one_line_usage_error(e: &clap::Error) -> String {
    let text = e.render().to_string();
    let parts: Vec<String> = text
        .lines()
        .take_while(|l| !l.starts_with("Usage:"))
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with("For more information"))
        .map(|l| {
            let l = l.strip_prefix("error: ").unwrap_or(l);
            whole_number_words(l.strip_prefix("tip: ").unwrap_or(l))
        })
        .collect();
    // A line that ends in `:` introduces the next one.
    let mut line = String::new();
    for p in &parts {
        if !line.is_empty() {
            line.push_str(if line.ends_with(':') { " " } else { "; " });
        }
        line.push_str(p);
    }
    format!("{line} (see --help)")
}

/// Rust's messages for a whole-number option that does not parse, in a user's words: a
/// decimal or an exponent (`1.5`, `1e9`) is "not a whole number", and a negative value
/// for an unsigned option is "below 0" rather than outside the type's range.
fn whole_number_words(line: &str) -> String {
    let line = line
        .replace("invalid digit found in string", "expected a whole number")
        .replace(
            "cannot parse integer from empty string",
            "expected a whole number",
        )
        .replace("number too large to fit in target type", "too large")
        .replace("cannot parse float from empty string", "expected a number")
        .replace("invalid float literal", "expected a number");
    match line.split_once(": -") {
        Some((head, tail)) if tail.contains(" is not in 0..=") => {
            format!("{head}: expected a whole number ≥ 0")
        }
        // Past the type's range (`4294967296 is not in 0..=4294967295`): the option's own
        // range is narrower, and --help gives it.
        _ => match line.rsplit_once(": ") {
            Some((head, tail))
                if [u32::MAX.to_string(), u64::MAX.to_string()]
                    .iter()
                    .any(|max| tail.ends_with(&format!(" is not in 0..={max}"))) =>
            {
                format!("{head}: too large")
            }
            _ => line,
        },
    }
}

/// Largest block (bytes) glibc serves from its heap rather than from a mapping of its own:
/// glibc's own ceiling for the setting (32 MiB on 64-bit systems).
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const MMAP_THRESHOLD: libc::c_int = 32 << 20;

/// How much address space (bytes) glibc adds beyond each request when its heap must grow:
/// the heap grows a few times per render instead of at every stage of the guard. It is
/// address space, not memory: pages count once they are written (peak resident size of
/// chess at 1280×960, 4 spp: 1.24–1.26 GB without, 1.27–1.28 GB with).
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const TOP_PAD: libc::c_int = 256 << 20;

/// Makes glibc keep the memory a render frees for the next allocation. By default a block
/// above its (adaptive) mapping threshold is a mapping of its own, and the heap's free top
/// goes back to the system, so the renderer's per-pixel maps, made and dropped at every
/// stage of the guard, come back as fresh pages that the kernel must clear: at 1280×960 a
/// quarter of a render's CPU time went to page faults. With blocks up to
/// [`MMAP_THRESHOLD`] kept in the heap and its top never trimmed (docs/render-bench.md,
/// "Page faults"): chess at 1280×960, 4 spp, faults 634 k → 429 k, CPU 9.6 → 8.4 s,
/// allocation + reconstruction 2.4 → 1.7 s. With the heap grown by [`TOP_PAD`] at a time
/// (2026-12-02): faults 515 k → 419 k there, and a render of cornell at 256×192, 4 spp,
/// 0.21–0.23 s → 0.20–0.21 s (four runs each). A process keeps its peak heap until it
/// exits, which a command line run can afford. Nothing to do on other systems.
fn keep_freed_memory() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: `mallopt` only sets three of the allocator's parameters; glibc takes its
    // lock for it, and any value of these three is valid (a larger threshold is clamped).
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, MMAP_THRESHOLD);
        libc::mallopt(libc::M_TRIM_THRESHOLD, libc::c_int::MAX);
        libc::mallopt(libc::M_TOP_PAD, TOP_PAD);
    }
}

/// Runs the `covtrace` command line on this process's arguments, with the built-in
/// operators and those `register` adds: a third party's `main` is
/// `fn main() -> std::process::ExitCode { cov_cli::run_with(my_ops::register) }`
/// and gets `eval`, `plot` and `list` (and the rest) with its operators next to the
/// built-in ones, with covtrace's output and one-line errors (exit code 2).
pub fn run_with(register: impl FnOnce(&mut Registry)) -> ExitCode {
    keep_freed_memory();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) if !e.use_stderr() => e.exit(),
        Err(e) => {
            eprintln!("covtrace: {}", one_line_usage_error(&e));
            return ExitCode::from(2);
        }
    };
    let mut registry = covtrace::registry();
    register(&mut registry);
    match run(cli, &registry) {
        Ok(()) => ExitCode::SUCCESS,
        Err(message) => {
            eprintln!("covtrace: {message}");
            ExitCode::from(2)
        }
    }
}

fn json_with_decisions(
    e: &covtrace::path::Evaluation,
    d: Option<&covtrace::sensor::PixelDecisions>,
) -> String {
    match d {
        None => e.to_json(),
        Some(d) => {
            let mut v = serde_json::to_value(e).unwrap_or_default();
            if let (Some(obj), Ok(dv)) = (v.as_object_mut(), serde_json::to_value(d)) {
                obj.insert("pixel".into(), dv);
            }
            serde_json::to_string_pretty(&v).unwrap_or_default()
        }
    }
}

fn run(cli: Cli, registry: &Registry) -> Result<(), String> {
    match cli.command {
        Command::Eval { path, json, form } => {
            let p = Path::load(&path, registry).map_err(|e| e.to_string())?;
            let name = path.display().to_string();
            let e = p.eval_in(form.into()).map_err(|e| e.to_string())?;
            // A sensor reports its per-pixel decisions as a typed value of the evaluation.
            let decisions = e.report::<covtrace::sensor::PixelDecisions>().cloned();
            if json {
                say!("{}", json_with_decisions(&e, decisions.as_ref()));
            } else {
                say!("{}", format_evaluation(&name, &e).trim_end());
                if let Some(d) = decisions {
                    say!("\n{}", crate::format_decisions(&d).trim_end());
                }
            }
        }
        Command::Plot { path, output } => {
            crate::render::check_output(&output, "png")?;
            crate::render::not_an_input(std::slice::from_ref(&output), std::slice::from_ref(&path), "-o")?;
            let p = Path::load(&path, registry).map_err(|e| e.to_string())?;
            let e = p.eval().map_err(|e| e.to_string())?;
            let legend = plot::plot(&e, &path.display().to_string(), &output)?;
            say!("{}", legend.trim_end());
            say!("written to {}", output.display());
        }
        Command::Validate { full, output } => {
            // The chart is written as SVG and as PNG beside it; both paths are checked first.
            let out = std::path::PathBuf::from(&output);
            crate::render::check_output(&out, "svg")?;
            let png = out.with_extension("png");
            let sizes = report::sizes(full);
            let total = report::cases().map_err(|e| e.to_string())?.len() * sizes.len();
            let bar = ProgressBar::new(total as u64);
            bar.set_style(
                ProgressStyle::with_template("{bar:40} {pos}/{len} {msg} [{elapsed}]")
                    .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            say!("{}", report::header());
            let rows = report::run(&sizes, |r| {
                if bar.is_hidden() {
                    // A failed write shows at the next line printed outside this callback.
                    let _ = emit(&report::line(r));
                } else {
                    bar.println(report::line(r));
                }
                bar.set_message(r.case);
                bar.inc(1);
            })
            .map_err(|e| e.to_string())?;
            bar.finish_and_clear();
            report::chart(&output, &rows).map_err(|e| format!("{output}: {e}"))?;
            let png_name = png.display().to_string();
            report::chart(&png_name, &rows).map_err(|e| format!("{png_name}: {e}"))?;
            say!("chart written to {output} and {png_name}");
        }
        Command::Stiff { length } => {
            let cases = cov_stiff::cases(length as usize);
            let bar = ProgressBar::new(cases.len() as u64);
            let mut outcomes = Vec::with_capacity(cases.len());
            for case in &cases {
                bar.set_message(case.name.clone());
                outcomes.push(cov_stiff::run_case(case));
                bar.inc(1);
            }
            bar.finish_and_clear();
            say!("{}", cov_stiff::report(&outcomes).trim_end());
        }
        Command::Render(args) => say!("{}", crate::render::run(&args)?.trim_end()),
        Command::Merge(args) => say!("{}", crate::render::merge(&args)?.trim_end()),
        Command::RenderBench(args) => say!("{}", crate::bench::bench(&args)?.trim_end()),
        Command::RenderCheck(args) => say!("{}", crate::render::check(&args)?.trim_end()),
        Command::List => {
            for e in registry.entries() {
                say!("{}: {}", e.name, e.summary);
                if e.params.is_empty() {
                    say!("    (no parameters: write `{0}` or `{0}()`)", e.name);
                }
                for p in e.params {
                    let default = match p.default {
                        None => String::new(),
                        Some(covtrace::spec::OPTIONAL) => " (optional)".to_string(),
                        Some(d) => format!(" (default {d})"),
                    };
                    let unit = if p.unit.is_empty() { "–" } else { p.unit };
                    let domain = if p.domain.is_empty() { "–" } else { p.domain };
                    say!(
                        "    {:<10} {:<13} {:<16} {}{default}",
                        p.name,
                        unit,
                        domain,
                        p.doc
                    );
                }
            }
        }
    }
    Ok(())
}
