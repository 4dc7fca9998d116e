//! The stiff suite (issue 6): no NaN, no panic, no silent non-PSD result anywhere, in
//! either form; typed errors where the answer is undefined; ≤ 1e-9 relative error against
//! the double-double reference on every well-posed case in the default (square-root)
//! form, 10⁴-operator chains included. The covariance form is held to 1e-8 there (it
//! measures 4.1e-9: the reason the square-root form is the default), except on the cases
//! well conditioned in the parameters but not in Σ's entries (a 1e-9 m window refocused
//! by a lobe: 2.4e-4 to 8.6e-3 in both forms, reported and not yet asserted). The cases
//! whose small answer sits next to entries 1e16–1e22 larger (a window far below a beam's
//! size, a picometre source) are compared without the resolution floor, so losing the
//! beam's angular spread fails here. The report:
//! `cargo run --release -p cov-cli -- stiff`.

use cov_stiff::{cases, run};

#[test]
fn stiff_suite() {
    let outcomes = run(&cases(10_000));
    println!("{}", cov_stiff::report(&outcomes));
    assert!(outcomes.len() >= 30);
    for o in &outcomes {
        assert!(!o.ours_non_psd, "{}: ours is not PSD", o.name);
        if o.expect_error {
            let msg = o.ours_error.as_deref().unwrap_or("");
            assert!(
                msg.contains("total internal reflection"),
                "{}: expected a typed error, got {msg:?}",
                o.name
            );
            continue;
        }
        let err = o
            .ours
            .unwrap_or_else(|| panic!("{}: ours failed: {:?}", o.name, o.ours_error));
        assert!(err.is_finite(), "{}", o.name);
        let cov = o
            .ours_cov
            .unwrap_or_else(|| panic!("{}: covariance form failed: {:?}", o.name, o.ours_error));
        if o.well_posed {
            assert!(err <= 1e-9, "{}: square-root form {err:e} > 1e-9", o.name);
            if o.factor_only {
                // The covariance form snaps this class (towards a smaller bandwidth):
                // reported, finite.
                assert!(cov.is_finite(), "{}", o.name);
                continue;
            }
            let limit = if o.ops >= 1000 { 1e-8 } else { 1e-9 };
            assert!(cov <= limit, "{}: covariance form {cov:e} > {limit:e}", o.name);
        }
    }
}

/// The reason for the default: on the long bounce chains the square-root form is at least
/// 100× more accurate than the covariance form and than plain f64.
#[test]
fn square_root_form_wins_on_long_chains() {
    let outcomes = run(&cases(10_000));
    let long: Vec<_> = outcomes.iter().filter(|o| o.ops >= 1000).collect();
    assert_eq!(long.len(), 2);
    for o in long {
        let (sqrt, cov, plain) = (o.ours.unwrap(), o.ours_cov.unwrap(), o.plain.unwrap());
        assert!(sqrt * 100.0 < cov, "{}: sqrt {sqrt:e} cov {cov:e}", o.name);
        assert!(sqrt * 100.0 < plain, "{}: sqrt {sqrt:e} plain {plain:e}", o.name);
    }
}

#[test]
fn ours_beats_plain_where_plain_breaks() {
    let outcomes = run(&cases(100));
    let by = |name: &str| {
        outcomes
            .iter()
            .find(|o| o.name == name)
            .unwrap_or_else(|| panic!("{name}"))
    };
    // Plain overflows at 1e300 and cannot invert a rank-deficient block; ours does both,
    // in both forms.
    assert!(by("entries 1e300 (N=4)").plain.is_none());
    assert!(by("entries 1e300 (N=4)").ours.is_some_and(|e| e <= 1e-9));
    assert!(by("entries 1e300 (N=4)").ours_cov.is_some_and(|e| e <= 1e-9));
    assert!(by("rank-deficient Σ, lobe and diffuse (N=4)").plain.is_none());
    assert!(
        by("rank-deficient Σ, lobe and diffuse (N=4)")
            .ours
            .is_some_and(|e| e <= 1e-9)
    );
    // The cancellation-free lobe forms: a broad lobe on a sharp signal.
    let p = by("Phong 1 (N=2)");
    for ours in [p.ours, p.ours_cov] {
        assert!(
            ours.unwrap() * 10.0 < p.plain.unwrap(),
            "ours {ours:?} plain {:?}",
            p.plain
        );
    }
}

#[test]
fn reference_division_is_double_double() {
    use cov_stiff::reference::Real;
    use twofloat::TwoFloat;
    let a = TwoFloat::from(2.5330295910584446e10);
    let r = a * TwoFloat::from(0.25) - (a * a).div_full(TwoFloat::from(4.0) * a);
    assert_eq!(f64::from(r), 0.0);
}
