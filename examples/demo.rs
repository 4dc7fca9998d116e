//! The README's demo placeholder; replaced once the operator crates exist.
fn main() {}
