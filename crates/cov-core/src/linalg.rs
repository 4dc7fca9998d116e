//! Small symmetric matrices (size 1 to 5): the eigen-solver and pseudo-inverse that the
//! kernels use. Tested against nalgebra.
//!
//! Everything here works on a full `[[f64; 5]; 5]` array of which the leading `n × n`
//! block is used, so that the kernels never allocate.

/// Largest matrix size handled here (the 5D layout).
pub const MAX: usize = 5;

/// A full `n × n` symmetric block stored in a fixed array (only `[..n][..n]` is used).
pub type Small = [[f64; MAX]; MAX];

/// Rank tolerance of the generalised inverse [`psd_pinv`] (dimensionless).
///
/// After scaling a PSD matrix to unit diagonal (so the tolerance does not depend on the
/// units of the axes), a pivot of its `LDLᵀ` factorisation at or below `PINV_RCOND` ends
/// the factorisation: the remaining directions count as zero (correlation `1 − 1e-12`
/// is treated as exact). `1e-12` is about 4500 ulps: above the rounding noise of a 5×5
/// factorisation, below any correlation that carries information.
pub const PINV_RCOND: f64 = 1e-12;

/// Eigen-decomposition of the symmetric `n × n` block of `a` by cyclic Jacobi rotations.
///
/// Returns the eigenvalues (ascending) and the eigenvectors as the columns of the second
/// array. The matrix is scaled by its largest entry first, so entries anywhere in
/// `1e-300 … 1e300` neither overflow nor underflow. Non-finite input gives non-finite
/// eigenvalues (callers check finiteness first).
pub fn sym_eigen(n: usize, a: &Small) -> ([f64; MAX], Small) {
    let mut vals = [0.0; MAX];
    let mut vecs = [[0.0; MAX]; MAX];
    for (i, row) in vecs.iter_mut().enumerate().take(n) {
        row[i] = 1.0;
    }
    let mut scale = 0.0f64;
    for row in a.iter().take(n) {
        for v in row.iter().take(n) {
            scale = scale.max(v.abs());
        }
    }
    if scale == 0.0 || !scale.is_finite() {
        for (i, v) in vals.iter_mut().enumerate().take(n) {
            *v = if scale == 0.0 { 0.0 } else { a[i][i] };
        }
        return (vals, vecs);
    }
    let mut b = [[0.0; MAX]; MAX];
    for i in 0..n {
        for j in 0..n {
            // Symmetrise while scaling: the solver relies on exact symmetry.
            b[i][j] = 0.5 * (a[i][j] + a[j][i]) / scale;
        }
    }
    for sweep in 0..100 {
        let mut off = 0.0;
        for i in 0..n {
            for j in (i + 1)..n {
                off += b[i][j].abs();
            }
        }
        if off == 0.0 {
            break;
        }
        for p in 0..n {
            for q in (p + 1)..n {
                let bpq = b[p][q];
                if bpq == 0.0 {
                    continue;
                }
                // Negligible against both diagonal entries: drop it (after a few sweeps, as
                // in the classical cyclic Jacobi method).
                let g = 100.0 * bpq.abs();
                if sweep > 3 && b[p][p].abs() + g == b[p][p].abs() && b[q][q].abs() + g == b[q][q].abs() {
                    b[p][q] = 0.0;
                    b[q][p] = 0.0;
                    continue;
                }
                let h = b[q][q] - b[p][p];
                let t = if h.abs() + g == h.abs() {
                    bpq / h
                } else {
                    let theta = 0.5 * h / bpq;
                    let t = 1.0 / (theta.abs() + (1.0 + theta * theta).sqrt());
                    if theta < 0.0 { -t } else { t }
                };
                let c = 1.0 / (1.0 + t * t).sqrt();
                let s = t * c;
                let tau = s / (1.0 + c);
                let hh = t * bpq;
                b[p][p] -= hh;
                b[q][q] += hh;
                b[p][q] = 0.0;
                b[q][p] = 0.0;
                for r in 0..n {
                    if r != p && r != q {
                        let g = b[r][p];
                        let h = b[r][q];
                        b[r][p] = g - s * (h + g * tau);
                        b[p][r] = b[r][p];
                        b[r][q] = h + s * (g - h * tau);
                        b[q][r] = b[r][q];
                    }
                }
                for row in vecs.iter_mut().take(n) {
                    let g = row[p];
                    let h = row[q];
                    row[p] = g - s * (h + g * tau);
                    row[q] = h + s * (g - h * tau);
                }
            }
        }
    }
    // Sort ascending (selection sort, n ≤ 5), moving eigenvector columns along.
    for i in 0..n {
        vals[i] = b[i][i] * scale;
    }
    for i in 0..n {
        let mut m = i;
        for j in (i + 1)..n {
            if vals[j] < vals[m] {
                m = j;
            }
        }
        if m != i {
            vals.swap(i, m);
            for row in vecs.iter_mut().take(n) {
                row.swap(i, m);
            }
        }
    }
    (vals, vecs)
}

/// A symmetric reflexive generalised inverse `G` of a symmetric positive semi-definite
/// `n × n` block `M` (`M G M = M`, `G M G = G`): the inverse when `M` is non-singular.
/// Returns `G` and the numerical rank.
///
/// Method: `M` is scaled to unit diagonal (`M = D C D`, `D = diag(√M_ii)`), which makes
/// the rank decision independent of the units of the axes; `C` is factored by an
/// `LDLᵀ` decomposition with diagonal pivoting (rank revealing for PSD matrices), stopping
/// when the largest remaining pivot is at most [`PINV_RCOND`] (the scaled diagonal is 1).
/// With `r` pivots taken, `G = D⁻¹ Pᵀ [C₁₁⁻¹ 0; 0 0] P D⁻¹`, `C₁₁` the pivoted leading
/// `r × r` block. Rows with a zero (or negative) diagonal are zero rows.
///
/// For a singular `M` this is not the Moore–Penrose inverse; it is what the Schur
/// complement `Σ_kk − Σ_kr G Σ_rk` and the lobe product need, whose results are the same
/// for every generalised inverse when the off-diagonal block lies in the range of `M`
/// (always true for a PSD Σ). Unlike an eigen-decomposition, the triangular factors keep
/// small off-diagonal entries to relative accuracy, which matters once `D` is undone.
pub fn psd_pinv(n: usize, m: &Small) -> (Small, usize) {
    let mut d = [0.0; MAX];
    for i in 0..n {
        d[i] = if m[i][i] > 0.0 { m[i][i].sqrt() } else { 0.0 };
    }
    // Only rows with a positive diagonal take part.
    let mut act = [0usize; MAX];
    let mut na = 0;
    for i in 0..n {
        if d[i] > 0.0 {
            act[na] = i;
            na += 1;
        }
    }
    let mut a = [[0.0; MAX]; MAX];
    for x in 0..na {
        for y in 0..na {
            let (i, j) = (act[x], act[y]);
            a[x][y] = if x == y { 1.0 } else { (m[i][j] / d[i]) / d[j] };
        }
    }
    // LDLᵀ with diagonal pivoting: after step k, a[k..][k..] holds the Schur complement.
    let mut perm = [0usize; MAX];
    for (x, p) in perm.iter_mut().enumerate() {
        *p = x;
    }
    let mut l = [[0.0; MAX]; MAX];
    let mut piv = [0.0; MAX];
    let mut rank = 0;
    for k in 0..na {
        let mut p = k;
        for x in (k + 1)..na {
            if a[x][x] > a[p][p] {
                p = x;
            }
        }
        if a[p][p].is_nan() || a[p][p] <= PINV_RCOND {
            break;
        }
        if p != k {
            a.swap(p, k);
            for row in a.iter_mut() {
                row.swap(p, k);
            }
            l.swap(p, k);
            perm.swap(p, k);
        }
        piv[k] = a[k][k];
        l[k][k] = 1.0;
        for x in (k + 1)..na {
            l[x][k] = a[x][k] / piv[k];
        }
        for x in (k + 1)..na {
            for y in (k + 1)..na {
                a[x][y] -= l[x][k] * l[y][k] * piv[k];
            }
        }
        rank += 1;
    }
    // C₁₁⁻¹ = L₁⁻ᵀ D₁⁻¹ L₁⁻¹ with L₁ unit lower triangular (r × r).
    let r = rank;
    let mut li = [[0.0; MAX]; MAX];
    for col in 0..r {
        li[col][col] = 1.0;
        for x in (col + 1)..r {
            let s: f64 = (col..x).map(|y| l[x][y] * li[y][col]).sum();
            li[x][col] = -s;
        }
    }
    let mut ginv = [[0.0; MAX]; MAX];
    for x in 0..r {
        for y in 0..r {
            let s: f64 = (x.max(y)..r).map(|z| li[z][x] * li[z][y] / piv[z]).sum();
            ginv[x][y] = s;
        }
    }
    let mut out = [[0.0; MAX]; MAX];
    for x in 0..r {
        for y in 0..r {
            let (i, j) = (act[perm[x]], act[perm[y]]);
            out[i][j] = (ginv[x][y] / d[i]) / d[j];
        }
    }
    (out, rank)
}

/// The determinant of the PSD matrix `m` (its first `k` rows and columns; overwritten),
/// by Cholesky with symmetric pivoting: the largest remaining diagonal first, and 0 as
/// soon as no positive pivot is left (rank deficient). Cheaper than eigenvalues, and as accurate for PSD input.
pub fn psd_det(k: usize, m: &mut Small) -> f64 {
    let mut det = 1.0;
    let mut order = [0, 1, 2, 3, 4];
    for s in 0..k {
        // Pivot: the largest remaining diagonal.
        let p = (s..k)
            .max_by(|&a, &b| m[order[a]][order[a]].total_cmp(&m[order[b]][order[b]]))
            .unwrap_or(s);
        order.swap(s, p);
        let d = m[order[s]][order[s]];
        if d.is_nan() || d <= 0.0 {
            return 0.0;
        }
        det *= d;
        // Schur complement on the remaining rows.
        let r = order[s];
        for &i in &order[s + 1..k] {
            let f = m[i][r] / d;
            for &j in &order[s + 1..k] {
                m[i][j] -= f * m[r][j];
            }
        }
    }
    det
}
