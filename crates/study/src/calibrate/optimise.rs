//! The calibrations' derivative-free minimiser: argmin's Nelder–Mead simplex (Nelder & Mead,
//! Comput. J. 7, 308 (1965); reflection 1, expansion 2, contraction ½, shrink ½) on a plain
//! closure, with an evaluation budget. Every objective value of a shaper fit is a set of bar
//! simulations, so no gradient is available.

use argmin::core::{CostFunction, Executor};
use argmin::solver::neldermead::NelderMead;
use std::cell::RefCell;

/// An objective: the value at a point.
type Objective<'f> = &'f mut dyn FnMut(&[f64]) -> f64;

/// The closure as argmin's cost function, counting evaluations and keeping the best point;
/// past the budget it stops the run (an error argmin returns, caught by [`nelder_mead`]).
struct Budgeted<'f, 's> {
    f: RefCell<Objective<'f>>,
    /// Evaluations, best value, best point.
    state: &'s RefCell<(usize, f64, Vec<f64>)>,
    budget: usize,
}

impl CostFunction for Budgeted<'_, '_> {
    type Param = Vec<f64>;
    type Output = f64;

    fn cost(&self, x: &Vec<f64>) -> Result<f64, argmin::core::Error> {
        if self.state.borrow().0 >= self.budget {
            return Err(argmin::core::Error::msg("evaluation budget spent"));
        }
        let v = (self.f.borrow_mut())(x);
        let mut s = self.state.borrow_mut();
        s.0 += 1;
        if v < s.1 || s.2.is_empty() {
            (s.1, s.2) = (v, x.clone());
        }
        Ok(v)
    }
}

/// Minimises `f` from `x0` with argmin's Nelder–Mead on the simplex x0, x0 + step_i e_i; stops
/// when the standard deviation of the simplex's values falls below `sd_tolerance` or after
/// `max_evals` evaluations. Returns the best point any evaluation saw, its value and the
/// evaluations used.
pub fn nelder_mead(
    f: &mut dyn FnMut(&[f64]) -> f64,
    x0: &[f64],
    step: &[f64],
    max_evals: usize,
    sd_tolerance: f64,
) -> (Vec<f64>, f64, usize) {
    let mut simplex = vec![x0.to_vec()];
    for (i, s) in step.iter().enumerate() {
        let mut p = x0.to_vec();
        p[i] += s;
        simplex.push(p);
    }
    let state = RefCell::new((0, f64::INFINITY, Vec::new()));
    let problem = Budgeted {
        f: RefCell::new(f),
        state: &state,
        budget: max_evals.max(x0.len() + 1),
    };
    let solver = NelderMead::new(simplex)
        .with_sd_tolerance(sd_tolerance.max(0.0))
        .expect("a tolerance of at least 0");
    // Each iteration evaluates at least once, so the budget also bounds the iterations. A run
    // stopped by the budget ends in argmin's error; the best point any evaluation saw is kept
    // here either way (Nelder–Mead's best vertex is one of them).
    let _stopped_or_converged = Executor::new(problem, solver)
        .configure(|s| s.max_iters(max_evals as u64))
        .run();
    let (evals, best, x) = state.into_inner();
    let x = if x.is_empty() { x0.to_vec() } else { x };
    (x, best, evals)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_rosenbrock_valley_is_followed_to_its_minimum() {
        let mut f = |x: &[f64]| (1.0 - x[0]).powi(2) + 100.0 * (x[1] - x[0] * x[0]).powi(2);
        let (x, v, n) = nelder_mead(&mut f, &[-1.2, 1.0], &[0.1, 0.1], 2000, 1e-12);
        assert!(
            (x[0] - 1.0).abs() < 1e-3 && (x[1] - 1.0).abs() < 2e-3,
            "{x:?}"
        );
        assert!(v < 1e-6 && n <= 2000);
    }

    #[test]
    fn the_budget_stops_the_search_and_keeps_its_best_point() {
        let mut calls = 0;
        let mut f = |x: &[f64]| {
            calls += 1;
            (x[0] - 3.0).powi(2)
        };
        let (x, v, n) = nelder_mead(&mut f, &[0.0], &[1.0], 10, 0.0);
        assert_eq!(n, 10);
        assert!(v < 9.0 && (v - (x[0] - 3.0).powi(2)).abs() < 1e-12);
        assert_eq!(calls, 10);
    }
}
