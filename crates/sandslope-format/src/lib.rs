//! Number formatting for the text of every front end, in one place: the terminal's tables
//! (`sandslope fit`, `phase`, `risk`, `infer`, which docs/inference.md quotes) write a strength
//! as [`e_notation`] (`2.237e6`), the report's prose (report_text.rs, HTML and Markdown) as
//! [`powers_of_ten`] (`2.24 × 10⁶`). JSON and CSV carry full precision and use neither. The
//! regimes and their causes in words are [`Outcome`] and [`Explain`].

mod words;
pub use words::{Explain, Outcome};

/// `x` in Rust's scientific notation with 3 digits after the point: `2.237e6`, `-4.536e4`,
/// `4.000e-4`; 4 significant digits, so the terminal's table columns line up. The terminal's
/// number format for strengths and their intervals.
pub fn e_notation(x: f64) -> String {
    format!("{x:.3e}")
}

/// `x` as `m.mm × 10ⁿ` with `decimals` digits after the point (superscript exponent), or
/// plainly with `decimals + 1` significant digits when `0.01 <= |x| < 10⁴`; 0, infinities and
/// NaN as Rust writes them. The report's number format.
pub fn powers_of_ten(x: f64, decimals: usize) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let a = x.abs();
    if (0.01..1e4).contains(&a) {
        let digits = (decimals as i32 + 1 - a.log10().floor() as i32 - 1).max(0) as usize;
        return format!("{x:.digits$}");
    }
    let text = format!("{x:.decimals$e}");
    let (m, e) = text.split_once('e').unwrap_or((&text, "0"));
    const SUP: [char; 10] = ['⁰', '¹', '²', '³', '⁴', '⁵', '⁶', '⁷', '⁸', '⁹'];
    let exp: String = e
        .chars()
        .map(|c| match c {
            '-' => '⁻',
            d => d.to_digit(10).map_or(d, |d| SUP[d as usize]),
        })
        .collect();
    format!("{m} × 10{exp}")
}

/// A probability as text: two decimals from 0.01 up (`0.20`), below it a mantissa of two
/// significant digits and a power of ten (`3.0 × 10⁻³`), and `< 10⁻³⁰⁰` for 0 (below what the
/// tail computation resolves).
pub fn probability(p: f64) -> String {
    if p <= 0.0 {
        "< 10⁻³⁰⁰".into()
    } else if p >= 0.01 {
        format!("{p:.2}")
    } else {
        powers_of_ten(p, 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The terminal's format, worked by hand: 2,237,000 is 2.237 x 10^6; -45,359 rounds to
    /// -4.536 x 10^4; 1e4 keeps its three zeros; 0.0004 is 4 x 10^-4; 0 is 0 x 10^0 (the
    /// table lines of docs/inference.md, `7.000e5   2.237e6`).
    #[test]
    fn e_notation_keeps_four_significant_digits() {
        assert_eq!(e_notation(2_237_000.0), "2.237e6");
        assert_eq!(e_notation(700_000.0), "7.000e5");
        assert_eq!(e_notation(-45_359.0), "-4.536e4");
        assert_eq!(e_notation(1e4), "1.000e4");
        assert_eq!(e_notation(4e-4), "4.000e-4");
        assert_eq!(e_notation(0.0), "0.000e0");
    }

    /// The report's format, worked by hand: plain from 0.01 to 10^4 with `decimals + 1`
    /// significant digits (0.5 to two: 0.50; 123.456 to three: 123; 0.01 to two: 0.010), else
    /// a mantissa with `decimals` digits and a superscript power (1.234e6 to 1.23 × 10⁶;
    /// 12,345, past 10^4, to 1.23 × 10⁴; -0.000025 to -2.5 × 10⁻⁵).
    #[test]
    fn powers_of_ten_writes_plain_or_a_power() {
        assert_eq!(powers_of_ten(1.234e6, 2), "1.23 × 10⁶");
        assert_eq!(powers_of_ten(12_345.0, 2), "1.23 × 10⁴");
        assert_eq!(powers_of_ten(4e-4, 1), "4.0 × 10⁻⁴");
        assert_eq!(powers_of_ten(-2.5e-5, 1), "-2.5 × 10⁻⁵");
        assert_eq!(powers_of_ten(0.5, 1), "0.50");
        assert_eq!(powers_of_ten(0.01, 1), "0.010");
        assert_eq!(powers_of_ten(123.456, 2), "123");
        assert_eq!(powers_of_ten(9_999.0, 1), "9999");
        assert_eq!(powers_of_ten(0.0, 2), "0");
        assert_eq!(powers_of_ten(f64::NAN, 2), "NaN");
    }

    /// Probabilities worked by hand: 0.2 to two decimals is 0.20; 0.003 is 3.0 x 10^-3; 0.01,
    /// the boundary, stays plain (0.01); 0 is below what a float's tail holds.
    #[test]
    fn probability_is_plain_from_a_hundredth_else_a_power() {
        assert_eq!(probability(0.2), "0.20");
        assert_eq!(probability(0.01), "0.01");
        assert_eq!(probability(0.003), "3.0 × 10⁻³");
        assert_eq!(probability(0.0), "< 10⁻³⁰⁰");
    }
}
