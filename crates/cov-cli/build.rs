//! With the `oidn` feature, the `covtrace` binary records where Open Image Denoise's
//! libraries are (`$OIDN_DIR/lib`) as its run-time search path, so that it starts without
//! `LD_LIBRARY_PATH` (docs/oidn.md).

fn main() {
    println!("cargo:rerun-if-env-changed=OIDN_DIR");
    if std::env::var_os("CARGO_FEATURE_OIDN").is_some()
        && let Some(dir) = std::env::var_os("OIDN_DIR")
    {
        let lib = std::path::Path::new(&dir).join("lib");
        println!("cargo:rustc-link-arg-bins=-Wl,-rpath,{}", lib.display());
    }
}
