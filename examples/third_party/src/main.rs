//! The `covtrace` command line with the third-party `Sparkle` operator next to the
//! built-in ones: `cargo run -- eval glitter.ron`, `-- list`, `-- plot glitter.ron -o g.png`.

fn main() -> std::process::ExitCode {
    cov_cli::run_with(covtrace_sparkle::register)
}
