//! Every operator crate's docs show its parameter table, generated from the specs
//! (`#[derive(OperatorSpec)]`): a parameter is declared once, on its field, and the docs
//! cannot drift from it. `COVTRACE_BLESS=1 cargo test --test param_tables` rewrites the
//! tables after a spec changes.

use covtrace::spec::Catalogue;

const BEGIN: &str = "//! <!-- parameters: generated from the specs";
const END: &str = "//! <!-- end of parameters -->";

/// An operator crate's `spec::register`, for a catalogue.
type Register = fn(&mut Catalogue);

fn check(crate_dir: &str, register: Register) -> Result<(), String> {
    let mut c = Catalogue::default();
    register(&mut c);
    let table: String = c.markdown().lines().map(|l| format!("//! {l}\n")).collect();
    let path =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("crates/{crate_dir}/src/lib.rs"));
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let b = text
        .find(BEGIN)
        .ok_or(format!("{crate_dir}: no parameter table marker"))?;
    let b = b + text[b..].find('\n').ok_or("marker line")? + 1;
    let e = text[b..].find(END).ok_or(format!("{crate_dir}: no end marker"))? + b;
    if text[b..e] == table {
        return Ok(());
    }
    if std::env::var_os("COVTRACE_BLESS").is_some() {
        let new = format!("{}{}{}", &text[..b], table, &text[e..]);
        std::fs::write(&path, new).map_err(|e| e.to_string())?;
        return Ok(());
    }
    Err(format!(
        "{crate_dir}: the parameter table in src/lib.rs differs from the specs; run COVTRACE_BLESS=1 cargo test --test param_tables\nexpected:\n{table}"
    ))
}

/// Every operator crate, with its `spec::register`.
const CRATES: [(&str, Register); 10] = [
    ("cov-travel", covtrace::travel::spec::register),
    ("cov-occlusion", covtrace::occlusion::spec::register),
    ("cov-projection", covtrace::projection::spec::register),
    ("cov-curvature", covtrace::curvature::spec::register),
    ("cov-brdf", covtrace::brdf::spec::register),
    ("cov-refraction", covtrace::refraction::spec::register),
    ("cov-motion", covtrace::motion::spec::register),
    ("cov-defocus", covtrace::defocus::spec::register),
    ("cov-sensor", covtrace::sensor::spec::register),
    ("cov-media", covtrace::media::spec::register),
];

#[test]
fn crate_docs_show_the_generated_parameter_tables() {
    let errors: Vec<String> = CRATES.iter().filter_map(|(d, r)| check(d, *r).err()).collect();
    assert!(errors.is_empty(), "{}", errors.join("\n\n"));
}

#[test]
fn every_parameter_is_documented_with_a_unit_or_a_reason_not_to() {
    let mut c = Catalogue::default();
    covtrace::register_all(&mut c);
    assert!(c.entries.len() >= 25, "{} operators", c.entries.len());
    for e in &c.entries {
        assert!(!e.summary.is_empty(), "{}: summary", e.name);
        for p in e.params {
            assert!(!p.doc.is_empty(), "{}.{}: no doc comment", e.name, p.name);
        }
    }
}

/// A parameter is named once, by its field: no operator crate spells a parameter's name
/// in a string literal (errors name parameters through the spec's constants, `arg!` or
/// the derive's generated checks), so a renamed field cannot leave a stale name behind.
#[test]
fn no_operator_crate_spells_a_parameter_name_in_a_string() {
    let mut found = Vec::new();
    for (dir, register) in CRATES {
        let mut c = Catalogue::default();
        register(&mut c);
        let names: Vec<&str> = c
            .entries
            .iter()
            .flat_map(|e| e.params.iter().map(|p| p.name))
            .collect();
        let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("crates/{dir}/src"));
        for entry in std::fs::read_dir(&src).expect("src dir") {
            let path = entry.expect("entry").path();
            let text = std::fs::read_to_string(&path).expect("source");
            for (i, line) in text.lines().enumerate() {
                let code = line.split("//").next().unwrap_or("");
                // The string literals of the line (no escaped quotes in these crates'
                // code lines).
                for (k, lit) in code.split('"').enumerate() {
                    if k % 2 == 1 && names.contains(&lit) {
                        found.push(format!("{}:{}: \"{lit}\"", path.display(), i + 1));
                    }
                }
            }
        }
    }
    assert!(
        found.is_empty(),
        "parameter names typed as strings:\n{}",
        found.join("\n")
    );
}

/// A default is shown as a path file writes it: an enum variant by its own name, a
/// negative number with its sign against it (the derive's `quote` text read `Which :: B`
/// and `- 1.5`).
#[test]
fn defaults_read_as_a_file_writes_them() {
    use covtrace::{Build, Checked, CovError, Operator, OperatorSpec, Spectrum};

    #[derive(Clone, Copy, Debug, Default, serde::Deserialize)]
    enum Which {
        #[default]
        A,
        B,
    }
    #[derive(Debug)]
    struct Nothing;
    impl Operator for Nothing {
        fn apply(&self, _: &mut dyn Spectrum) -> Result<(), CovError> {
            Ok(())
        }
    }
    #[derive(Debug, OperatorSpec)]
    #[operator(summary = "a test of defaults")]
    struct ShowSpec {
        /// An enum with a default variant.
        #[param(default = Which::B)]
        which: Which,
        /// A negative default.
        #[param(default = -1.5)]
        shift: f64,
    }
    impl Build for ShowSpec {
        type Op = Nothing;
        fn make(p: Checked<Self>) -> Result<Nothing, CovError> {
            let _ = (p.which, p.shift);
            Ok(Nothing)
        }
    }
    assert_eq!(ShowSpec::WHICH.default, Some("B"));
    assert_eq!(ShowSpec::SHIFT.default, Some("-1.5"));
}
