//! Unit tests of cov-core's building blocks: axes and layouts, the small dense linear
//! algebra (`linalg`), and `Cov`'s constructors, storage and validity.

use cov_core::linalg::*;
use cov_core::*;
use nalgebra::SMatrix;

// ---- axes and layouts

#[test]
fn layouts_and_indices() {
    assert_eq!(axis_index(2, Axis::U).unwrap(), 1);
    assert_eq!(axis_index(3, Axis::T).unwrap(), 2);
    assert_eq!(axis_index(4, Axis::V).unwrap(), 3);
    assert_eq!(axis_index(5, Axis::T).unwrap(), 4);
    assert!(axis_index(4, Axis::T).is_err());
    assert!(axis_index(2, Axis::Y).is_err());
}

#[test]
fn smallest_layout() {
    assert_eq!(AxisSet::FLAT.smallest_layout(), 2);
    assert_eq!(AxisSet::FLAT_TIME.smallest_layout(), 3);
    assert_eq!(AxisSet::SPACE.smallest_layout(), 4);
    assert_eq!(AxisSet::ALL.smallest_layout(), 5);
    assert_eq!(AxisSet::of(&[Axis::X, Axis::V]).smallest_layout(), 4);
    for n in 2..=5 {
        assert_eq!(layout_set(n).smallest_layout(), n);
    }
    assert_eq!(AxisSet::of(&[Axis::X, Axis::T]).to_string(), "{x,t}");
}

// ---- linalg

use nalgebra::DMatrix;

fn to_small(m: &DMatrix<f64>) -> Small {
    let mut a = [[0.0; MAX]; MAX];
    for i in 0..m.nrows() {
        for j in 0..m.ncols() {
            a[i][j] = m[(i, j)];
        }
    }
    a
}

/// A seeded linear congruential generator of numbers in [0, 1).
fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[test]
fn eigen_matches_nalgebra() {
    let mut lcg = uniform(12345);
    let mut rnd = || lcg() * 2.0 - 1.0;
    for n in 1..=5 {
        for _ in 0..50 {
            let l = DMatrix::from_fn(n, n, |_, _| rnd());
            let m = &l * l.transpose();
            let (vals, vecs) = sym_eigen(n, &to_small(&m));
            let mut reference: Vec<f64> = m.clone().symmetric_eigen().eigenvalues.iter().copied().collect();
            reference.sort_by(|a, b| a.total_cmp(b));
            let norm = m.norm();
            for k in 0..n {
                assert!(
                    (vals[k] - reference[k]).abs() <= 1e-13 * norm,
                    "n={n} {vals:?} {reference:?}"
                );
                // A v = λ v
                for i in 0..n {
                    let av: f64 = (0..n).map(|j| m[(i, j)] * vecs[j][k]).sum();
                    assert!((av - vals[k] * vecs[i][k]).abs() <= 1e-12 * norm);
                }
            }
        }
    }
}

#[test]
fn eigen_extreme_scales() {
    for s in [1e-300, 1e300] {
        let a = [
            [2.0 * s, s, 0.0, 0.0, 0.0],
            [s, 2.0 * s, 0.0, 0.0, 0.0],
            [0.0; 5],
            [0.0; 5],
            [0.0; 5],
        ];
        let (vals, _) = sym_eigen(2, &a);
        assert!((vals[0] / s - 1.0).abs() < 1e-14);
        assert!((vals[1] / s - 3.0).abs() < 1e-14);
    }
}

#[test]
fn pinv_matches_inverse_and_handles_rank_deficiency() {
    let m = DMatrix::from_row_slice(3, 3, &[4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0]);
    let inv = m.clone().try_inverse().unwrap();
    let (p, rank) = psd_pinv(3, &to_small(&m));
    assert_eq!(rank, 3);
    for i in 0..3 {
        for j in 0..3 {
            assert!((p[i][j] - inv[(i, j)]).abs() < 1e-14);
        }
    }
    // Rank one: v vᵀ with v = (1, 2, 0); pinv = v vᵀ / |v|⁴.
    let v = [1.0, 2.0, 0.0];
    let mut a = [[0.0; MAX]; MAX];
    for i in 0..3 {
        for j in 0..3 {
            a[i][j] = v[i] * v[j];
        }
    }
    let (p, rank) = psd_pinv(3, &a);
    assert_eq!(rank, 1);
    let mul = |x: &Small, y: &Small| {
        let mut o = [[0.0; MAX]; MAX];
        for i in 0..3 {
            for j in 0..3 {
                o[i][j] = (0..3).map(|k| x[i][k] * y[k][j]).sum();
            }
        }
        o
    };
    let aga = mul(&mul(&a, &p), &a);
    let gag = mul(&mul(&p, &a), &p);
    for i in 0..3 {
        for j in 0..3 {
            assert!((aga[i][j] - a[i][j]).abs() < 1e-13, "AGA != A");
            assert!((gag[i][j] - p[i][j]).abs() < 1e-13, "GAG != G");
            assert_eq!(p[i][j], p[j][i]);
        }
    }
    let (p, rank) = psd_pinv(2, &[[0.0; MAX]; MAX]);
    assert_eq!(rank, 0);
    assert_eq!(p, [[0.0; MAX]; MAX]);
}

/// The pivoted Cholesky determinant agrees with the product of eigenvalues on PSD
/// matrices of every size, full rank or not.
#[test]
fn psd_det_matches_the_eigenvalues() {
    let mut lcg = uniform(12345);
    let mut next = || lcg() - 0.5;
    for k in 1..=5 {
        for rank in 1..=k {
            let g: Vec<Vec<f64>> = (0..k).map(|_| (0..rank).map(|_| next()).collect()).collect();
            let mut m = [[0.0; MAX]; MAX];
            for i in 0..k {
                for j in 0..k {
                    m[i][j] = (0..rank).map(|l| g[i][l] * g[j][l]).sum();
                }
            }
            let (vals, _) = sym_eigen(k, &m);
            let want: f64 = vals[..k].iter().map(|v| v.max(0.0)).product();
            let got = psd_det(k, &mut m.clone());
            let scale = (0..k).map(|i| m[i][i]).product::<f64>().max(1e-300);
            assert!(
                (got - want).abs() <= 1e-10 * scale,
                "k {k} rank {rank}: {got} vs {want}"
            );
        }
    }
}

// ---- Cov

#[test]
fn packed_storage_is_symmetric_and_one_to_one() {
    fn check<const N: usize>() {
        let mut c = Cov::<N>::zeros();
        let mut v = 1.0;
        for i in 0..N {
            for j in i..N {
                c.set(j, i, v);
                v += 1.0;
            }
        }
        // Each of the N(N+1)/2 slots holds its own value, seen from both sides.
        let mut seen: Vec<f64> = c.packed().to_vec();
        seen.sort_by(f64::total_cmp);
        assert_eq!(seen, (1..=N * (N + 1) / 2).map(|k| k as f64).collect::<Vec<_>>());
        for i in 0..N {
            for j in 0..N {
                assert_eq!(c.get(i, j), c.get(j, i));
            }
        }
    }
    check::<2>();
    check::<3>();
    check::<4>();
    check::<5>();
}

#[test]
fn gaussian_matches_fact() {
    let c = Cov::<2>::gaussian([0.5, f64::INFINITY]).unwrap();
    assert!((c.get(0, 0) - 1.0 / (FOUR_PI_SQ * 0.25)).abs() < 1e-15);
    assert_eq!(c.get(1, 1), 0.0);
    assert!(Cov::<2>::gaussian([0.0, 1.0]).is_err());
    assert!(Cov::<2>::gaussian([f64::NAN, 1.0]).is_err());
    assert!(Cov::<2>::gaussian([1e-200, 1.0]).is_err());
    let p = SMatrix::<f64, 2, 2>::new(0.25, 0.0, 0.0, 4.0);
    let c2 = Cov::<2>::from_primal_covariance(&p).unwrap();
    let expected = Cov::<2>::gaussian([0.5, 2.0]).unwrap();
    assert!(approx::relative_eq!(c2, expected, max_relative = 1e-14));
}

#[test]
fn dirac_is_relative_to_scene() {
    let a = Cov::<4>::dirac(1.0, DIRAC_RELATIVE_SIZE).unwrap();
    let b = Cov::<4>::dirac(1000.0, DIRAC_RELATIVE_SIZE).unwrap();
    assert!((a.get(0, 0) / b.get(0, 0) - 1e6).abs() < 1e-6);
    assert_eq!(a.get(2, 2), 0.0);
    assert!(Cov::<4>::dirac(0.0, 1e-6).is_err());
    assert!(Cov::<4>::dirac(f64::NAN, 1e-6).is_err());
}

#[test]
fn from_matrix_validates() {
    let ok = SMatrix::<f64, 2, 2>::new(2.0, 1.0, 1.0, 2.0);
    assert!(Cov::from_matrix(&ok).is_ok());
    let asym = SMatrix::<f64, 2, 2>::new(2.0, 1.0, 0.5, 2.0);
    assert!(matches!(
        Cov::from_matrix(&asym),
        Err(CovError::NotSymmetric { .. })
    ));
    let neg = SMatrix::<f64, 2, 2>::new(1.0, 2.0, 2.0, 1.0);
    assert!(matches!(Cov::from_matrix(&neg), Err(CovError::NotPsd { .. })));
    let nan = SMatrix::<f64, 2, 2>::new(1.0, f64::NAN, f64::NAN, 1.0);
    assert!(matches!(Cov::from_matrix(&nan), Err(CovError::NonFinite { .. })));
}

#[test]
fn serde_roundtrip_via_rows() {
    let c = Cov::<3>::gaussian([0.1, 0.2, 0.3]).unwrap();
    let m = c.to_matrix();
    let back = Cov::<3>::from_matrix(&m).unwrap();
    assert_eq!(c, back);
}

#[test]
fn validity_of_degenerate() {
    let z = Cov::<5>::zeros().validity();
    assert!(z.is_valid());
    assert_eq!(z.condition, 1.0);
    let mut c = Cov::<2>::zeros();
    c.set(0, 0, 1e300);
    let v = c.validity();
    assert!(v.is_valid());
    assert!(v.condition.is_infinite());
    c.set(0, 0, f64::INFINITY);
    assert!(!c.validity().is_valid());
}

/// `Turn::towards` is the turn by the direction's angle, whatever its length (down to
/// components whose squares underflow, and up to f64's largest): the same angle as `atan2` to 4ε, a
/// cosine and sine within 2ε of `Turn::new`'s; a zero or non-finite direction has none.
#[test]
fn a_turn_towards_a_direction() {
    for k in 0..=200 {
        let angle = -3.0 + 6.0 * f64::from(k) / 200.0;
        let t = Turn::new(arg!("test", angle)).unwrap();
        for len in [1e-300, 1e-160, 1e-150, 1e-3, 1.0, 7.5, 1e150, 1e200, 1e308] {
            let d = Turn::towards(t.cos() * len, t.sin() * len).unwrap();
            assert!((d.angle() - angle).abs() <= 4.0 * f64::EPSILON, "{angle} {len}");
            assert!((d.cos() - t.cos()).abs() <= 2.0 * f64::EPSILON, "{angle} {len}");
            assert!((d.sin() - t.sin()).abs() <= 2.0 * f64::EPSILON, "{angle} {len}");
        }
    }
    for (x, y) in [(0.0, 0.0), (f64::NAN, 1.0), (f64::INFINITY, 0.0), (-0.0, 0.0)] {
        assert_eq!(Turn::towards(x, y), None, "{x} {y}");
    }
    // A turn is zero exactly where its angle is ±0.
    let turns = |angle: f64| Turn::new(arg!("test", angle)).unwrap();
    for (t, zero) in [
        (Turn::ZERO, true),
        (turns(0.0), true),
        (turns(-0.0), true),
        (turns(1e-300), false),
        (turns(std::f64::consts::TAU), false),
        (Turn::towards(2.0, 0.0).unwrap(), true),
        (Turn::towards(2.0, -0.0).unwrap(), true),
        (Turn::towards(-1.0, 0.0).unwrap(), false),
        (Turn::towards(1.0, 1e-300).unwrap(), false),
    ] {
        assert_eq!(t.is_zero(), zero, "{t:?}");
        assert_eq!(t.is_zero(), t.angle() == 0.0, "{t:?}");
    }
}
