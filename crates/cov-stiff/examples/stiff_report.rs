//! Prints the stiff-suite report: `cargo run --release -p cov-stiff --example stiff_report`.
fn main() {
    let outcomes = cov_stiff::run(&cov_stiff::cases(10_000));
    print!("{}", cov_stiff::report(&outcomes));
}
