//! The Nelder–Mead simplex minimiser of the calibration (derivative-free: every objective value
//! is a set of bar simulations).

/// Nelder–Mead simplex minimisation (Nelder & Mead, Comput. J. 7, 308 (1965); coefficients
/// reflection 1, expansion 2, contraction ½, shrink ½). Returns the best point, its value and the
/// evaluations used. Stops after `max_evals` or when the simplex's values agree to `ftol`.
pub fn nelder_mead(
    f: &mut dyn FnMut(&[f64]) -> f64,
    x0: &[f64],
    step: &[f64],
    max_evals: usize,
    ftol: f64,
) -> (Vec<f64>, f64, usize) {
    let n = x0.len();
    let mut pts: Vec<Vec<f64>> = vec![x0.to_vec()];
    for i in 0..n {
        let mut p = x0.to_vec();
        p[i] += step[i];
        pts.push(p);
    }
    let mut vals: Vec<f64> = pts.iter().map(|p| f(p)).collect();
    let mut evals = n + 1;
    let along = |c: &[f64], w: &[f64], t: f64| -> Vec<f64> {
        c.iter().zip(w).map(|(ci, wi)| ci + t * (wi - ci)).collect()
    };
    while evals < max_evals {
        let mut order: Vec<usize> = (0..=n).collect();
        order.sort_by(|&i, &j| vals[i].total_cmp(&vals[j]));
        pts = order.iter().map(|&i| pts[i].clone()).collect();
        vals = order.iter().map(|&i| vals[i]).collect();
        if (vals[n] - vals[0]).abs() <= ftol * (1.0 + vals[0].abs()) {
            break;
        }
        let centroid: Vec<f64> = (0..n)
            .map(|d| pts[..n].iter().map(|p| p[d]).sum::<f64>() / n as f64)
            .collect();
        let xr = along(&centroid, &pts[n], -1.0);
        let fr = f(&xr);
        evals += 1;
        if fr < vals[0] {
            let xe = along(&centroid, &pts[n], -2.0);
            let fe = f(&xe);
            evals += 1;
            if fe < fr {
                (pts[n], vals[n]) = (xe, fe);
            } else {
                (pts[n], vals[n]) = (xr, fr);
            }
        } else if fr < vals[n - 1] {
            (pts[n], vals[n]) = (xr, fr);
        } else {
            // Outside contraction if the reflection improved on the worst, inside otherwise.
            let (xc, fc) = if fr < vals[n] {
                let x = along(&centroid, &pts[n], -0.5);
                let v = f(&x);
                (x, v)
            } else {
                let x = along(&centroid, &pts[n], 0.5);
                let v = f(&x);
                (x, v)
            };
            evals += 1;
            if fc < vals[n].min(fr) {
                (pts[n], vals[n]) = (xc, fc);
            } else {
                for i in 1..=n {
                    pts[i] = along(&pts[0], &pts[i], 0.5);
                    vals[i] = f(&pts[i]);
                }
                evals += n;
            }
        }
    }
    let best = (0..=n)
        .min_by(|&i, &j| vals[i].total_cmp(&vals[j]))
        .unwrap_or(0);
    (pts[best].clone(), vals[best], evals)
}

#[cfg(test)]
mod tests {
    use super::nelder_mead;

    /// Rosenbrock's function, minimum 0 at (1, 1) at the bottom of a curved valley.
    fn rosenbrock(x: &[f64]) -> f64 {
        (1.0 - x[0]).powi(2) + 100.0 * (x[1] - x[0] * x[0]).powi(2)
    }

    #[test]
    fn minimises_the_rosenbrock_function() {
        let mut calls = 0;
        let mut f = |x: &[f64]| {
            calls += 1;
            rosenbrock(x)
        };
        let (x, fx, evals) = nelder_mead(&mut f, &[-1.2, 1.0], &[0.5, 0.5], 5000, 1e-14);
        assert!(fx < 1e-8, "f = {fx} at {x:?}");
        assert!(
            (x[0] - 1.0).abs() < 1e-3 && (x[1] - 1.0).abs() < 1e-3,
            "{x:?}"
        );
        assert!(evals < 5000, "stopped by ftol, not by the budget: {evals}");
        assert_eq!(evals, calls, "every evaluation is counted");
    }

    #[test]
    fn stops_at_the_evaluation_budget() {
        let mut f = |x: &[f64]| rosenbrock(x);
        let (_, _, evals) = nelder_mead(&mut f, &[-1.2, 1.0], &[0.5, 0.5], 20, 0.0);
        // The budget is checked before each iteration, which uses at most n + 2 evaluations
        // (reflection, contraction, then a shrink of n points).
        assert!((20..20 + 2 + 2).contains(&evals), "{evals}");
    }

    #[test]
    fn a_quadratic_bowl_in_three_dimensions() {
        let mut f =
            |x: &[f64]| (x[0] - 3.0).powi(2) + 2.0 * (x[1] + 1.0).powi(2) + 0.5 * x[2] * x[2];
        let (x, fx, _) = nelder_mead(&mut f, &[0.0, 0.0, 0.0], &[1.0, 1.0, 1.0], 2000, 1e-15);
        assert!(fx < 1e-10, "f = {fx}");
        for (xi, want) in x.iter().zip([3.0, -1.0, 0.0]) {
            assert!((xi - want).abs() < 1e-4, "{x:?}");
        }
    }
}
