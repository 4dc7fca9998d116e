//! The `covtrace` command line (see the crate docs of `cov-cli`): the built-in operators.

fn main() -> std::process::ExitCode {
    cov_cli::run_with(|_| {})
}
