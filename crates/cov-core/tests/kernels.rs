//! Every kernel against its dense nalgebra reference, at N = 2, 3, 4, 5, for random PSD Σ
//! (with per-axis unit scales spanning 4 decades) and random parameters, in both forms
//! (covariance `Cov` and square-root `CovFactor`); plus symmetry, PSD preservation and
//! composition laws.

use std::f64::consts::TAU;

use cov_core::{Axis, Cov, CovFactor, Form, Spectrum};
use nalgebra::{DMatrix, SMatrix};
use proptest::prelude::*;

const REL: f64 = 1e-12;

/// Σ = D (L Lᵀ + ridge·I) D with D = diag(scales).
fn make_cov<const N: usize>(l: &[f64], scales: &[f64], ridge: f64) -> Cov<N> {
    let l = DMatrix::from_row_slice(N, N, &l[..N * N]);
    let mut m = &l * l.transpose() + DMatrix::identity(N, N) * ridge;
    for i in 0..N {
        for j in 0..N {
            m[(i, j)] *= scales[i] * scales[j];
        }
    }
    let s = SMatrix::<f64, N, N>::from_fn(|i, j| 0.5 * (m[(i, j)] + m[(j, i)]));
    Cov::from_matrix(&s).expect("random PSD matrix is valid")
}

fn dense<const N: usize>(c: &Cov<N>) -> DMatrix<f64> {
    DMatrix::from_fn(N, N, |i, j| c.get(i, j))
}

fn rel_err(a: &DMatrix<f64>, b: &DMatrix<f64>) -> f64 {
    let n = b.norm();
    if n == 0.0 {
        (a - b).norm()
    } else {
        (a - b).norm() / n
    }
}

fn congruence_ref(s: &DMatrix<f64>, a: &DMatrix<f64>) -> DMatrix<f64> {
    a.transpose() * s * a
}

fn assert_psd_sym<const N: usize>(c: &Cov<N>, what: &str) {
    let m = c.to_matrix();
    assert_eq!(m, m.transpose(), "{what}: not exactly symmetric");
    let v = c.validity();
    assert!(v.finite && v.psd, "{what}: {v}");
    // Cross-check the PSD verdict with nalgebra's eigen-solver.
    let d = dense(c);
    let min = d.clone().symmetric_eigen().eigenvalues.min();
    assert!(
        min >= -1e-12 * d.norm().max(f64::MIN_POSITIVE),
        "{what}: λmin {min}"
    );
}

/// Applies `k` to `c` held in `form`; returns Σ afterwards.
fn run<const N: usize>(
    form: Form,
    c: &Cov<N>,
    k: impl Fn(&mut dyn Spectrum) -> Result<(), cov_core::CovError>,
) -> Cov<N> {
    match form {
        Form::Covariance => {
            let mut x = *c;
            k(&mut x).unwrap();
            x
        }
        Form::SquareRoot => {
            let mut f = CovFactor::from_cov(c);
            k(&mut f).unwrap();
            f.to_cov().unwrap()
        }
    }
}

fn axes_subset<const N: usize>(mask: u8) -> Vec<Axis> {
    let all = Cov::<N>::axes();
    let mut v: Vec<Axis> = all
        .iter()
        .enumerate()
        .filter(|(i, _)| mask & (1 << i) != 0)
        .map(|(_, a)| *a)
        .collect();
    if v.is_empty() {
        v.push(all[0]);
    }
    if v.len() == N {
        v.pop();
    }
    v
}

fn check_all<const N: usize>(
    form: Form,
    l: &[f64],
    scales: &[f64],
    params: &[f64],
    mask: u8,
    a_entries: &[f64],
) {
    let c = make_cov::<N>(l, scales, 0.05);
    let s0 = dense(&c);
    let axes = Cov::<N>::axes();
    let i = (mask as usize) % N;
    let j = (i + 1 + (mask as usize / N) % (N - 1)) % N;
    let (ai, aj) = (axes[i], axes[j]);
    assert_ne!(i, j);

    // shear
    let s = params[0];
    let c1 = run(form, &c, |x| x.shear(ai, aj, s));
    let mut a = DMatrix::identity(N, N);
    a[(i, j)] = s;
    let e = rel_err(&dense(&c1), &congruence_ref(&s0, &a));
    assert!(e <= REL, "shear N={N} {form:?}: {e}");
    assert_psd_sym(&c1, "shear");

    // scale
    let k = params[1];
    let c2 = run(form, &c, |x| x.scale(ai, k));
    let mut a = DMatrix::identity(N, N);
    a[(i, i)] = k;
    let e = rel_err(&dense(&c2), &congruence_ref(&s0, &a));
    assert!(e <= REL, "scale N={N}: {e}");
    assert_psd_sym(&c2, "scale");

    // rotate
    let alpha = params[2];
    let c3 = run(form, &c, |x| x.rotate(ai, aj, alpha));
    let mut a = DMatrix::identity(N, N);
    a[(i, i)] = alpha.cos();
    a[(i, j)] = -alpha.sin();
    a[(j, i)] = alpha.sin();
    a[(j, j)] = alpha.cos();
    let e = rel_err(&dense(&c3), &congruence_ref(&s0, &a));
    assert!(e <= REL, "rotate N={N}: {e}");
    assert_psd_sym(&c3, "rotate");

    // dense congruence
    let am = SMatrix::<f64, N, N>::from_fn(|r, q| a_entries[r * N + q]);
    let c4 = run(form, &c, |x| x.congruence(am.transpose().as_slice()));
    let ad = DMatrix::from_fn(N, N, |r, q| am[(r, q)]);
    let e = rel_err(&dense(&c4), &congruence_ref(&s0, &ad));
    assert!(e <= REL, "congruence N={N}: {e}");
    assert_psd_sym(&c4, "congruence");

    // window and lobe on a subset of axes
    let sub = axes_subset::<N>(mask);
    let kk = sub.len();
    let idx: Vec<usize> = sub.iter().map(|x| Cov::<N>::index(*x).unwrap()).collect();
    let wl = DMatrix::from_fn(kk, kk, |r, q| params[3 + (r * kk + q) % 5]);
    let w = &wl * wl.transpose() * scales[0] + DMatrix::identity(kk, kk) * 0.1;
    let w_flat: Vec<f64> = (0..kk * kk).map(|r| w[(r / kk, r % kk)]).collect();
    let c5 = run(form, &c, |x| x.add_window(&sub, &w_flat));
    let mut r5 = s0.clone();
    for a in 0..kk {
        for b in 0..kk {
            r5[(idx[a], idx[b])] += w[(a, b)];
        }
    }
    let e = rel_err(&dense(&c5), &r5);
    assert!(e <= REL, "add_window N={N}: {e}");
    assert_psd_sym(&c5, "add_window");

    // convolve: Σ − Σ Pᵀ (S + PΣPᵀ)⁻¹ P Σ
    let c6 = run(form, &c, |x| x.convolve(&sub, &w_flat));
    let mut p = DMatrix::zeros(kk, N);
    for (a, &ix) in idx.iter().enumerate() {
        p[(a, ix)] = 1.0;
    }
    let inner = (&w + &p * &s0 * p.transpose()).try_inverse().unwrap();
    let r6 = &s0 - &s0 * p.transpose() * inner * &p * &s0;
    // The dense reference subtracts two terms of size ‖Σ‖ and is only accurate to
    // ε‖Σ‖ when the lobe removes most of Σ (ours uses the cancellation-free forms for the
    // convolved block: checked against a 50-digit evaluation of a failing case, ours was
    // right to 1e-16 where nalgebra's was off by 2e-11). So rules 3 and 4 are compared
    // relative to max(‖Σ‖, ‖Σ'‖).
    let e = (dense(&c6) - &r6).norm() / s0.norm().max(r6.norm());
    assert!(e <= REL, "convolve N={N}: {e}\nours {}\nref {}", dense(&c6), r6);
    assert_psd_sym(&c6, "convolve");

    // integrate: kept block ((Σ⁻¹)_kk)⁻¹, zero on integrated axes
    let c7 = run(form, &c, |x| x.integrate(&sub));
    let inv = s0.clone().try_inverse().unwrap();
    let kept: Vec<usize> = (0..N).filter(|x| !idx.contains(x)).collect();
    let ikk = DMatrix::from_fn(kept.len(), kept.len(), |a, b| inv[(kept[a], kept[b])]);
    let schur = ikk.try_inverse().unwrap();
    let mut r7 = DMatrix::zeros(N, N);
    for (a, &ka) in kept.iter().enumerate() {
        for (b, &kb) in kept.iter().enumerate() {
            r7[(ka, kb)] = schur[(a, b)];
        }
    }
    let e = (dense(&c7) - &r7).norm() / s0.norm().max(r7.norm());
    assert!(e <= REL, "integrate N={N}: {e}");
    assert_psd_sym(&c7, "integrate");
    if form == Form::SquareRoot {
        return;
    }
    // The query form agrees with the in-place form.
    let kept_axes: Vec<Axis> = kept.iter().map(|x| axes[*x]).collect();
    let block = c.integrated(&kept_axes).unwrap();
    for (a, &ka) in kept.iter().enumerate() {
        for (b, &kb) in kept.iter().enumerate() {
            assert_eq!(block.get(a, b), c7.get(ka, kb));
        }
    }
}

fn check_laws<const N: usize>(l: &[f64], scales: &[f64], d1: f64, d2: f64, s: f64) {
    let c = make_cov::<N>(l, scales, 0.0);
    let norm = c.norm();
    // Two travels equal one.
    // (Relative to the largest intermediate: d1 and d2 of opposite signs cancel.)
    let mut a = c;
    a.shear(Axis::X, Axis::U, -d1).unwrap();
    let mid = a.norm();
    a.shear(Axis::X, Axis::U, -d2).unwrap();
    let mut b = c;
    b.shear(Axis::X, Axis::U, -(d1 + d2)).unwrap();
    let scale = mid.max(b.norm()).max(norm);
    assert!(
        (dense(&a) - dense(&b)).norm() <= REL * scale,
        "travel composition N={N}"
    );
    // Shear then the opposite shear is the identity (relative to the largest intermediate).
    let mut e = c;
    e.shear(Axis::U, Axis::X, s).unwrap();
    let mid = e.norm();
    e.shear(Axis::U, Axis::X, -s).unwrap();
    assert!(
        (dense(&e) - dense(&c)).norm() <= REL * mid.max(norm),
        "shear inverse N={N}"
    );
    // Rotation by 2π is the identity.
    let mut r = c;
    r.rotate(Axis::X, Axis::U, TAU).unwrap();
    assert!(rel_err(&dense(&r), &dense(&c)) <= REL, "rotation 2π N={N}");
    if N >= 4 {
        let mut r = c;
        r.rotate_frame(TAU).unwrap();
        assert!(rel_err(&dense(&r), &dense(&c)) <= REL, "frame rotation 2π N={N}");
        let mut r = c;
        r.rotate_frame(d1).unwrap();
        r.rotate_frame(-d1).unwrap();
        assert!(
            rel_err(&dense(&r), &dense(&c)) <= REL,
            "frame rotation inverse N={N}"
        );
    }
}

fn entries(n: usize) -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(-1.0f64..1.0, n)
}

fn unit_scales() -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec((-2.0f64..2.0).prop_map(|e| 10f64.powf(e)), 5)
}

fn params() -> impl Strategy<Value = Vec<f64>> {
    (-10.0f64..10.0, 0.01f64..10.0, -7.0f64..7.0, entries(5)).prop_map(|(s, k, a, rest)| {
        let mut v = vec![s, k, a];
        v.extend(rest);
        v
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn kernels_match_dense_n2(l in entries(25), sc in unit_scales(), p in params(), m in 0u8..32, a in entries(25)) {
        check_all::<2>(Form::Covariance, &l, &sc, &p, m, &a);
        check_all::<2>(Form::SquareRoot, &l, &sc, &p, m, &a);
    }
    #[test]
    fn kernels_match_dense_n3(l in entries(25), sc in unit_scales(), p in params(), m in 0u8..32, a in entries(25)) {
        check_all::<3>(Form::Covariance, &l, &sc, &p, m, &a);
        check_all::<3>(Form::SquareRoot, &l, &sc, &p, m, &a);
    }
    #[test]
    fn kernels_match_dense_n4(l in entries(25), sc in unit_scales(), p in params(), m in 0u8..32, a in entries(25)) {
        check_all::<4>(Form::Covariance, &l, &sc, &p, m, &a);
        check_all::<4>(Form::SquareRoot, &l, &sc, &p, m, &a);
    }
    #[test]
    fn kernels_match_dense_n5(l in entries(25), sc in unit_scales(), p in params(), m in 0u8..32, a in entries(25)) {
        check_all::<5>(Form::Covariance, &l, &sc, &p, m, &a);
        check_all::<5>(Form::SquareRoot, &l, &sc, &p, m, &a);
    }

    #[test]
    fn composition_laws(l in entries(25), sc in unit_scales(), d1 in -100.0f64..100.0, d2 in -100.0f64..100.0, s in -10.0f64..10.0) {
        check_laws::<2>(&l, &sc, d1, d2, s);
        check_laws::<3>(&l, &sc, d1, d2, s);
        check_laws::<4>(&l, &sc, d1, d2, s);
        check_laws::<5>(&l, &sc, d1, d2, s);
    }
}
