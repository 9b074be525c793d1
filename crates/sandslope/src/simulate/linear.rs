//! Dense linear algebra for the velocity solve of docs/model.md §17: the Newton step on the
//! body's two or three rates.

/// Solves the first `dofs` rows and columns of `a x = b` (Gaussian elimination with partial
/// pivoting; `dofs` is 2 or 3), the rest of `x` zero.
pub(crate) fn solve_dofs(a: &[[f64; 3]; 3], b: &[f64; 3], dofs: usize) -> [f64; 3] {
    let mut m = [[0.0; 4]; 3];
    for i in 0..dofs {
        m[i][..dofs].copy_from_slice(&a[i][..dofs]);
        m[i][3] = b[i];
    }
    for col in 0..dofs {
        let p = (col..dofs).max_by(|&x, &y| m[x][col].abs().total_cmp(&m[y][col].abs())).unwrap_or(col);
        m.swap(col, p);
        let piv = m[col][col];
        if piv == 0.0 || !piv.is_finite() {
            return [0.0; 3];
        }
        let pivot_row = m[col];
        for row in m.iter_mut().take(dofs).skip(col + 1) {
            let f = row[col] / piv;
            for (x, p) in row.iter_mut().zip(pivot_row).skip(col) {
                *x -= f * p;
            }
        }
    }
    let mut x = [0.0; 3];
    for i in (0..dofs).rev() {
        let s: f64 = (i + 1..dofs).map(|k| m[i][k] * x[k]).sum();
        x[i] = (m[i][3] - s) / m[i][i];
    }
    x
}
