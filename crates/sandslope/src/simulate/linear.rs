//! Dense linear algebra for the velocity solve of docs/model.md §17: the Newton step on the
//! body's two or three rates.
//!
//! Gaussian elimination with partial pivoting, written out for two and three unknowns. The
//! loop over rows and columns it replaces was 11% of a 10 degree walk's time (`perf`,
//! 2026-12-02: the pivot search's iterator, the augmented matrix's copies and row swaps); the
//! written-out solve does the same floating-point operations in the same order, so the walks
//! are the same to the bit (a test checks it against the loop).

/// Solves the first `dofs` rows and columns of `a x = b` (Gaussian elimination with partial
/// pivoting; `dofs` is 2 or 3), the rest of `x` zero; all zero where a pivot is zero or not
/// finite.
#[inline]
pub(crate) fn solve_dofs(a: &[[f64; 3]; 3], b: &[f64; 3], dofs: usize) -> [f64; 3] {
    if dofs == 2 {
        solve2(a, b)
    } else {
        solve3(a, b)
    }
}

/// Whether `p` can be a pivot.
#[inline(always)]
fn usable(p: f64) -> bool {
    p != 0.0 && p.is_finite()
}

/// Whether row `y`'s entry displaces row `x`'s as the pivot: the larger magnitude, the later
/// row on a tie (`Iterator::max_by`'s rule, which the loop used).
#[inline(always)]
fn displaces(x: f64, y: f64) -> bool {
    x.abs().total_cmp(&y.abs()) != std::cmp::Ordering::Greater
}

/// The 2 x 2 case.
#[inline(always)]
fn solve2(a: &[[f64; 3]; 3], b: &[f64; 3]) -> [f64; 3] {
    let (mut r0, mut r1) = ([a[0][0], a[0][1], b[0]], [a[1][0], a[1][1], b[1]]);
    if displaces(r0[0], r1[0]) {
        std::mem::swap(&mut r0, &mut r1);
    }
    if !usable(r0[0]) {
        return [0.0; 3];
    }
    let f = r1[0] / r0[0];
    let (m11, m12) = (r1[1] - f * r0[1], r1[2] - f * r0[2]);
    if !usable(m11) {
        return [0.0; 3];
    }
    // `+ 0.0` is the loop's empty sum subtracted (`- (-0.0)`), to the bit.
    let x1 = (m12 + 0.0) / m11;
    let x0 = (r0[2] - r0[1] * x1) / r0[0];
    [x0, x1, 0.0]
}

/// The 3 x 3 case.
#[inline(always)]
fn solve3(a: &[[f64; 3]; 3], b: &[f64; 3]) -> [f64; 3] {
    let mut m = [
        [a[0][0], a[0][1], a[0][2], b[0]],
        [a[1][0], a[1][1], a[1][2], b[1]],
        [a[2][0], a[2][1], a[2][2], b[2]],
    ];
    // Column 0.
    let mut p = 0;
    for r in 1..3 {
        if displaces(m[p][0], m[r][0]) {
            p = r;
        }
    }
    m.swap(0, p);
    if !usable(m[0][0]) {
        return [0.0; 3];
    }
    let top = m[0];
    for row in &mut m[1..] {
        let f = row[0] / top[0];
        for c in 1..4 {
            row[c] -= f * top[c];
        }
    }
    // Column 1.
    if displaces(m[1][1], m[2][1]) {
        m.swap(1, 2);
    }
    if !usable(m[1][1]) {
        return [0.0; 3];
    }
    let f = m[2][1] / m[1][1];
    m[2][2] -= f * m[1][2];
    m[2][3] -= f * m[1][3];
    if !usable(m[2][2]) {
        return [0.0; 3];
    }
    let x2 = (m[2][3] + 0.0) / m[2][2];
    let x1 = (m[1][3] - m[1][2] * x2) / m[1][1];
    let x0 = (m[0][3] - (m[0][1] * x1 + m[0][2] * x2)) / m[0][0];
    [x0, x1, x2]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The elimination as a loop over rows and columns, as it was written before the solve was
    /// written out (the reference the written-out solve must match to the bit).
    fn solve_loop(a: &[[f64; 3]; 3], b: &[f64; 3], dofs: usize) -> [f64; 3] {
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

    /// A small deterministic generator (xorshift), so the test needs no dependency.
    fn draws(seed: u64) -> impl FnMut() -> f64 {
        let mut s = seed;
        move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        }
    }

    /// The written-out solve is the loop to the bit: random systems at scales from 1e-8 to
    /// 1e8, ties in the pivot column, zeros (signed), singular and non-finite matrices.
    #[test]
    fn the_written_out_solve_is_the_loop_to_the_bit() {
        let mut next = draws(0x5eed);
        let mut cases: Vec<([[f64; 3]; 3], [f64; 3])> = Vec::new();
        for k in 0..20_000 {
            let scale = 10f64.powi(k % 17 - 8);
            let mut a = [[0.0; 3]; 3];
            a.iter_mut().flatten().for_each(|x| *x = scale * next());
            let b = [next(), next(), next()];
            cases.push((a, b));
        }
        let specials = [0.0, -0.0, 1.0, -1.0, f64::NAN, f64::INFINITY];
        for &s in &specials {
            for &t in &specials {
                cases.push(([[s, 1.0, 2.0], [t, s, 1.0], [-s, t, 3.0]], [1.0, -0.0, 0.0]));
                cases.push(([[1.0, s, 0.5], [-1.0, t, 2.0], [1.0, 2.0, s]], [0.0, 1.0, -2.0]));
            }
        }
        // A tie in the pivot column picks the later row.
        cases.push(([[2.0, 1.0, 0.0], [-2.0, 3.0, 1.0], [2.0, 0.0, 5.0]], [1.0, 2.0, 3.0]));
        for (a, b) in &cases {
            for dofs in [2, 3] {
                let (got, want) = (solve_dofs(a, b, dofs), solve_loop(a, b, dofs));
                assert_eq!(got.map(f64::to_bits), want.map(f64::to_bits), "{a:?} {b:?} {dofs}");
            }
        }
    }

    /// A system solved by hand: `[[2, 1], [1, 3]] x = [3, 5]` gives x = (0.8, 1.4); the 3 x 3
    /// `[[0, 1, 0], [2, 0, 0], [0, 0, 4]] x = [1, 2, 8]` needs a pivot swap and gives (1, 1, 2).
    #[test]
    fn systems_solved_by_hand() {
        let x = solve_dofs(&[[2.0, 1.0, 9.0], [1.0, 3.0, 9.0], [9.0; 3]], &[3.0, 5.0, 9.0], 2);
        assert!((x[0] - 0.8).abs() < 1e-15 && (x[1] - 1.4).abs() < 1e-15 && x[2] == 0.0);
        let x = solve_dofs(&[[0.0, 1.0, 0.0], [2.0, 0.0, 0.0], [0.0, 0.0, 4.0]], &[1.0, 2.0, 8.0], 3);
        assert_eq!(x, [1.0, 1.0, 2.0]);
        assert_eq!(solve_dofs(&[[0.0; 3]; 3], &[1.0; 3], 3), [0.0; 3]);
    }
}
