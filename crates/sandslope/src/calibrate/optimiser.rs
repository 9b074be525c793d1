//! Levenberg-Marquardt on the unbounded coordinates of the unknowns, with some unknowns held
//! fixed and an optional penalty holding `ln k_s(20)/k_s(0)` at a target (for its profile).

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{storage::Owned, DMatrix, DVector, Dyn};

use super::model::Walked;
use super::problem::Problem;

/// What holds `ln k_s(20)/k_s(0)` at `target` (for its profile): the unknown `tied`, when
/// given, is not searched but solved from the others so that the ratio is exactly the target
/// ([`Problem::tied_value`]); a penalty term `(ln ratio - target) / tolerance` holds it where
/// no tie is given or the tie would leave its bounds.
#[derive(Debug, Clone, Copy)]
pub(crate) struct RatioPenalty {
    pub target: f64,
    pub tolerance: f64,
    pub tied: Option<usize>,
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
        if let Some(RatioPenalty { target, tied: Some(t), .. }) = self.penalty {
            if let Some(v) = self.problem.tied_value(&x, t, target) {
                x[t] = v;
            }
        }
        x
    }

    fn residuals_at(&self, u: &DVector<f64>) -> DVector<f64> {
        self.residuals_of(&self.values_at(u), None)
    }

    /// The residuals at the values `x`, with the simulator's walks given or walked.
    fn residuals_of(&self, x: &[f64], walks: Option<&[Walked]>) -> DVector<f64> {
        let mut r = self.problem.residuals_with(x, walks);
        if let Some(RatioPenalty { target, tolerance, .. }) = self.penalty {
            let ln_ratio = self.problem.ratio(x).ln();
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
        if let Some(j) = self.chain_rule_jacobian() {
            return Some(j);
        }
        let base = self.residuals_at(&self.u);
        let mut j = DMatrix::zeros(base.len(), self.free.len());
        for c in 0..self.free.len() {
            let (up, down, h) = self.column_points(c);
            let col = (self.residuals_at(&up) - self.residuals_at(&down)) / (2.0 * h);
            j.set_column(c, &col);
        }
        Some(j)
    }
}

/// One Jacobian column's central difference: its half distance `h` in the unbounded
/// coordinate, and at each of its two points the values and every walk's change in `ln k_s`.
type Column = (f64, Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>);

impl LeastSquares<'_, '_> {
    /// The two points of column `c`'s central difference and their half distance.
    fn column_points(&self, c: usize) -> (DVector<f64>, DVector<f64>, f64) {
        let h = self.problem.jacobian_step() * self.u[c].abs().max(1.0);
        let (mut up, mut down) = (self.u.clone(), self.u.clone());
        up[c] += h;
        down[c] -= h;
        (up, down, h)
    }

    /// The Jacobian by the chain rule through each walk's leg k_s, when the walks depend on the
    /// free quantities only through it ([`Problem::walks_depend_only_on_k_s`]): every walk is
    /// differentiated once in `ln k_s` (two walks at `k_s e^(+-walk_ln_k_s_step)`, all slopes
    /// in one parallel batch), and each column is the same central difference as without it,
    /// with the walks continued linearly in `ln k_s` from the point's own walks instead of
    /// walked again. On the paper's evidence that is 10 walks a Jacobian where the columns'
    /// own walks were 26 (`plate_scale` moves all five slopes' k_s, each force-test value
    /// four). `None` when it does not apply or a walk is refused (then the columns walk).
    fn chain_rule_jacobian(&self) -> Option<DMatrix<f64>> {
        let problem = self.problem;
        let sim = problem.simulator.as_ref().filter(|_| problem.walks_depend_only_on_k_s())?;
        let c0 = problem.candidate(&self.values_at(&self.u));
        let robot = c0.robot.as_ref()?;
        let g0 = problem.grounds(&c0);
        let w0 = sim.walks(robot, &g0).ok()?;
        // Each column's two points and the change in every walk's ln k_s there (no walks).
        let d_ln_k_s = |x: &[f64]| -> Vec<f64> {
            let g = problem.grounds(&problem.candidate(x));
            g.iter().zip(&g0).map(|(g, g0)| (g.2 / g0.2).ln()).collect()
        };
        let columns: Vec<Column> = (0..self.free.len())
            .map(|c| {
                let (up, down, h) = self.column_points(c);
                let (xu, xd) = (self.values_at(&up), self.values_at(&down));
                let (lu, ld) = (d_ln_k_s(&xu), d_ln_k_s(&xd));
                (h, xu, lu, xd, ld)
            })
            .collect();
        // The slopes whose k_s some column moves, each walked at k_s e^(+-step).
        let moved: Vec<usize> = (0..g0.len())
            .filter(|&i| columns.iter().any(|(_, _, lu, _, ld)| lu[i] != 0.0 || ld[i] != 0.0))
            .collect();
        let step = problem.walk_ln_k_s_step;
        let grounds: Vec<(f64, f64, f64)> = moved
            .iter()
            .flat_map(|&i| {
                let (deg, k_n, k_s) = g0[i];
                [(deg, k_n, k_s * step.exp()), (deg, k_n, k_s * (-step).exp())]
            })
            .collect();
        let walked = sim.walks(robot, &grounds).ok()?;
        // d(speed)/d(ln k_s) and d(t1)/d(ln k_s) of every walk (zero where no column moves it).
        let mut slope = vec![(0.0, 0.0); g0.len()];
        for (pair, &i) in walked.chunks_exact(2).zip(&moved) {
            let (a, b) = (pair[0], pair[1]);
            slope[i] = ((a.speed - b.speed) / (2.0 * step), (a.t1 - b.t1) / (2.0 * step));
        }
        let continued = |dl: &[f64]| -> Vec<Walked> {
            w0.iter()
                .zip(&slope)
                .zip(dl)
                .map(|((w, d), l)| Walked { speed: w.speed + d.0 * l, t1: w.t1 + d.1 * l })
                .collect()
        };
        let rows = self.residuals_of(&self.values_at(&self.u), Some(&w0)).len();
        let mut j = DMatrix::zeros(rows, self.free.len());
        for (c, (h, xu, lu, xd, ld)) in columns.iter().enumerate() {
            let up = self.residuals_of(xu, Some(&continued(lu)));
            let down = self.residuals_of(xd, Some(&continued(ld)));
            j.set_column(c, &((up - down) / (2.0 * h)));
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
    let tied = penalty.and_then(|p| p.tied);
    let free: Vec<usize> =
        (0..problem.unknowns.len()).filter(|i| !fixed.contains(i) && Some(*i) != tied).collect();
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::calibrate::problem::build;
    use crate::calibrate::profile::tests::paper_setup;
    use crate::calibrate::SpeedModel;
    use crate::simulate::SimSettings;

    /// The chain rule's Jacobian is the walked columns' Jacobian: on the paper's evidence
    /// (`plate_scale`, the floor and both force-test values free; short walks, 1.5 s at 2 ms)
    /// at the fit's best point, every entry of the two central differences of the same
    /// residuals (one through each walk's own k_s at 0.2%, one through the columns' walks at
    /// their own steps, 0.16% to 0.4% in k_s) agrees to 20% of its column's largest entry (a
    /// fixed-step walk is not smooth in k_s below about 1%: the 24 degree speed's derivative
    /// is 15% apart between the two steps, the largest difference); the chain rule walks each
    /// of the five slopes twice (10 walks), the columns 26 times.
    #[test]
    fn the_chain_rules_jacobian_is_the_walked_columns_jacobian() {
        let setup = paper_setup();
        let settings = SimSettings::new(1.5).unwrap().with_dt(2e-3).unwrap();
        let x = [1.04, 0.05, 97_500.0, 40_900.0];
        let mut jacobians = Vec::new();
        for chain_rule in [true, false] {
            let mut problem = build(&setup, SpeedModel::Simulator { settings }, None).unwrap();
            problem.chain_rule = chain_rule;
            // The chain rule at the columns' own scale (0.2%), so the two differences agree.
            problem.walk_ln_k_s_step = 2e-3;
            let free: Vec<usize> = (0..x.len()).collect();
            let u = DVector::from_iterator(
                free.len(),
                free.iter().map(|&i| problem.unknowns[i].unbounded_coordinate(x[i])),
            );
            let ls = LeastSquares { problem: &problem, base: x.to_vec(), free, u, penalty: None };
            ls.residuals().unwrap(); // the point's own five walks
            let before = problem.simulator.as_ref().unwrap().walks_run();
            let j = ls.jacobian().unwrap();
            let walks = problem.simulator.as_ref().unwrap().walks_run() - before;
            assert_eq!(walks, if chain_rule { 10 } else { 26 });
            jacobians.push(j);
        }
        let (a, b) = (&jacobians[0], &jacobians[1]);
        assert_eq!(a.shape(), b.shape());
        for c in 0..a.ncols() {
            let scale = b.column(c).amax();
            for r in 0..a.nrows() {
                assert!(
                    (a[(r, c)] - b[(r, c)]).abs() <= 0.2 * scale,
                    "column {c} row {r}: {} (chain rule) vs {} (walked), column scale {scale}",
                    a[(r, c)],
                    b[(r, c)]
                );
            }
        }
    }
}
