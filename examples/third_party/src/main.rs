//! Evaluates a RON path that uses the third-party `Sparkle` operator next to the
//! built-in ones: `cargo run -p covtrace-sparkle -- examples/third_party/glitter.ron`.

use std::process::ExitCode;

fn main() -> ExitCode {
    let file = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "examples/third_party/glitter.ron".into());
    let mut registry = covtrace::registry();
    covtrace_sparkle::register(&mut registry);
    let result = covtrace::path::Path::load(std::path::Path::new(&file), &registry).and_then(|p| p.eval());
    match result {
        Ok(e) => {
            println!("{file}: layout {} ({})", e.layout, e.axes.join(","));
            for s in &e.steps {
                println!("  {:<10} bandwidths {:?}", s.operator, s.bandwidths);
            }
            ExitCode::SUCCESS
        }
        Err(err) => {
            eprintln!("covtrace-sparkle: {err}");
            ExitCode::from(2)
        }
    }
}
