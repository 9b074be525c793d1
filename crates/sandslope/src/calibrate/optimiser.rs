//! Levenberg-Marquardt on the unbounded coordinates of the unknowns, with some unknowns held
//! fixed and an optional penalty holding `ln k_s(20)/k_s(0)` at a target (for its profile).

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{storage::Owned, DMatrix, DVector, Dyn};

use super::problem::Problem;

/// A penalty term `(ln ratio - target) / tolerance` that holds `ln k_s(20)/k_s(0)` at `target`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct RatioPenalty {
    pub target: f64,
    pub tolerance: f64,
}

/// The least-squares problem handed to Levenberg-Marquardt: the unbounded coordinates `u` of the
/// unknowns not held fixed, plus the optional penalty.
struct LeastSquares<'a, 'b> {
    problem: &'a Problem<'b>,
    /// Values of every unknown; the free ones are overwritten from `u`.
    base: Vec<f64>,
    free: Vec<usize>,
    u: DVector<f64>,
    penalty: Option<RatioPenalty>,
}

impl LeastSquares<'_, '_> {
    fn values_at(&self, u: &DVector<f64>) -> Vec<f64> {
        let mut x = self.base.clone();
        for (k, &i) in self.free.iter().enumerate() {
            x[i] = self.problem.unknowns[i].value_at_unbounded(u[k]);
        }
        x
    }

    fn residuals_at(&self, u: &DVector<f64>) -> DVector<f64> {
        let x = self.values_at(u);
        let mut r = self.problem.residuals(&x);
        if let Some(RatioPenalty { target, tolerance }) = self.penalty {
            let ln_ratio = self.problem.ratio(&x).ln();
            r.push(if ln_ratio.is_finite() { (ln_ratio - target) / tolerance } else { 1e3 });
        }
        while r.len() < self.free.len() {
            r.push(0.0);
        }
        DVector::from_vec(r)
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for LeastSquares<'_, '_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, u: &DVector<f64>) {
        self.u.copy_from(u);
    }
    fn params(&self) -> DVector<f64> {
        self.u.clone()
    }
    fn residuals(&self) -> Option<DVector<f64>> {
        Some(self.residuals_at(&self.u))
    }
    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let base = self.residuals_at(&self.u);
        let mut j = DMatrix::zeros(base.len(), self.free.len());
        for c in 0..self.free.len() {
            let h = self.problem.jacobian_step() * self.u[c].abs().max(1.0);
            let (mut up, mut down) = (self.u.clone(), self.u.clone());
            up[c] += h;
            down[c] -= h;
            let col = (self.residuals_at(&up) - self.residuals_at(&down)) / (2.0 * h);
            j.set_column(c, &col);
        }
        Some(j)
    }
}

/// Minimises over the unknowns not in `fixed`, from the values `start`; returns the values at
/// the minimum and their objective (without the penalty).
pub(crate) fn minimise(
    problem: &Problem,
    start: &[f64],
    fixed: &[usize],
    penalty: Option<RatioPenalty>,
) -> (Vec<f64>, f64) {
    let free: Vec<usize> = (0..problem.unknowns.len()).filter(|i| !fixed.contains(i)).collect();
    if free.is_empty() {
        return (start.to_vec(), problem.objective(start));
    }
    let u = DVector::from_iterator(
        free.len(),
        free.iter().map(|&i| problem.unknowns[i].unbounded_coordinate(start[i])),
    );
    let fit = LeastSquares { problem, base: start.to_vec(), free, u, penalty };
    let lm = if problem.simulator.is_some() {
        // Each evaluation walks the robot at every observed slope; the walks' own integration
        // error (docs/simulate.md) is far above 1e-6 relative, so a tighter tolerance buys
        // evaluations, not accuracy.
        LevenbergMarquardt::new().with_patience(30).with_xtol(1e-6).with_ftol(1e-6)
    } else {
        LevenbergMarquardt::new().with_patience(100).with_xtol(1e-12)
    };
    let (fit, _) = lm.minimize(fit);
    let x = fit.values_at(&fit.u);
    let s = problem.objective(&x);
    // Keep the start when the optimiser wandered off to something worse.
    let s0 = problem.objective(start);
    if penalty.is_none() && s0 < s {
        (start.to_vec(), s0)
    } else {
        (x, s)
    }
}
