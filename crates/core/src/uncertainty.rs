//! What a set-up's calibrated constants are uncertain by and the shot-to-shot scatter of the
//! outputs its calibration shots show ([`Uncertainty`], docs/physics.md §10.6): plain validated
//! numbers (1-sigma, normal, correlated as stated, else independent), which `shpb-input` reads
//! from a set-up's
//! `[uncertainty]` table and the study layer carries into a run's 90 % bands.

/// One uncertain constant of the set-up: the set-up key it is written under, its value and its
/// standard deviation in the key's own SI unit.
#[derive(Debug, Clone, PartialEq)]
pub struct UncertainInput {
    /// The dotted set-up key (`gun.k_m2_per_s2_per_pa`).
    pub key: String,
    /// The key's value in the set-up, SI.
    pub value: f64,
    /// 1-sigma, in the key's SI unit (> 0).
    pub sd: f64,
    /// The 1-sigma as written, relative to the value, when the set-up gave it so.
    pub relative_sd: Option<f64>,
}

/// The outputs whose shot-to-shot scatter a calibration may state, with the run summary key each
/// is added to and whether the scatter is relative to the value (else absolute, in the output's
/// SI unit).
pub const SCATTER_OUTPUTS: [(&str, &str, bool); 4] = [
    ("incident_peak_stress", "incident_peak_stress", true),
    ("incident_energy", "incident_energy", true),
    ("reflected_delay_s", "reflected_delay", false),
    ("transmitted_delay_s", "transmitted_delay", false),
];

/// The shot-to-shot scatter of one output beyond the model (1-sigma).
#[derive(Debug, Clone, PartialEq)]
pub struct OutputScatter {
    /// The run summary key it applies to (`incident_peak_stress`, `reflected_delay`).
    pub output: String,
    /// 1-sigma: a fraction of the value when `relative`, else in the output's SI unit (> 0).
    pub sd: f64,
    /// Whether `sd` is relative to the value.
    pub relative: bool,
}

impl OutputScatter {
    /// The absolute 1-sigma at output value `value`.
    pub fn sd_at(&self, value: f64) -> f64 {
        if self.relative {
            self.sd * value.abs()
        } else {
            self.sd
        }
    }
}

/// The correlation coefficient of two uncertain constants that one fit gave together
/// (`[uncertainty.correlation]`; docs/physics.md §10.6).
#[derive(Debug, Clone, PartialEq)]
pub struct Correlation {
    /// The one constant's set-up key.
    pub a: String,
    /// The other's.
    pub b: String,
    /// Pearson's r, in [−1, 1].
    pub r: f64,
}

/// The correlation of keys `a` and `b` among `correlations`: 1 for a key with itself, the stated
/// r of a listed pair (either order), else 0 (independent).
pub fn correlation_of(correlations: &[Correlation], a: &str, b: &str) -> f64 {
    if a == b {
        return 1.0;
    }
    correlations
        .iter()
        .find(|c| (c.a == a && c.b == b) || (c.a == b && c.b == a))
        .map_or(0.0, |c| c.r)
}

/// The correlation matrix (row-major) of `keys` under `correlations` ([`correlation_of`]).
pub fn correlation_matrix(correlations: &[Correlation], keys: &[&str]) -> Vec<f64> {
    keys.iter()
        .flat_map(|a| keys.iter().map(move |b| correlation_of(correlations, a, b)))
        .collect()
}

/// Whether the symmetric matrix `m` (row-major, n × n) is positive semi-definite: its smallest
/// eigenvalue is not below −1e-6 times the largest magnitude (a correlation matrix must be; the
/// margin takes correlations written to six decimals).
pub fn is_positive_semidefinite(m: &[f64], n: usize) -> bool {
    if n == 0 {
        return true;
    }
    let a = nalgebra::DMatrix::from_row_slice(n, n, m);
    let e = a.symmetric_eigenvalues();
    let scale = e.iter().fold(0.0f64, |s, x| s.max(x.abs())).max(1e-300);
    e.iter().all(|x| *x >= -1e-6 * scale)
}

/// A set-up's `[uncertainty]`: what the calibration was fitted on, the uncertain constants, their
/// correlations and the outputs' shot-to-shot scatter.
#[derive(Debug, Clone, PartialEq)]
pub struct Uncertainty {
    /// What the constants were fitted on (free text).
    pub fitted_on: String,
    /// Number of calibration shots (≥ 1).
    pub shots: u32,
    /// The uncertain constants, in the order written.
    pub inputs: Vec<UncertainInput>,
    /// The correlations of pairs of `inputs` (a pair not listed is independent).
    pub correlations: Vec<Correlation>,
    /// The outputs' shot-to-shot scatter, in the order written.
    pub scatter: Vec<OutputScatter>,
}

impl Uncertainty {
    /// The scatter stated for run summary key `output`, if any.
    pub fn scatter_of(&self, output: &str) -> Option<&OutputScatter> {
        self.scatter.iter().find(|s| s.output == output)
    }

    /// The correlation of constants `a` and `b`: 1 for a key with itself, the stated r of a
    /// listed pair (either order), else 0 (independent).
    pub fn correlation(&self, a: &str, b: &str) -> f64 {
        correlation_of(&self.correlations, a, b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_correlation_matrix_is_checked_for_positive_semidefiniteness() {
        // r = 0.9 between 1-2 and 2-3 forces r13 ≥ 2·0.81 − 1 = 0.62: −0.5 is impossible.
        assert!(is_positive_semidefinite(
            &[1.0, 0.9, 0.7, 0.9, 1.0, 0.9, 0.7, 0.9, 1.0],
            3
        ));
        assert!(!is_positive_semidefinite(
            &[1.0, 0.9, -0.5, 0.9, 1.0, 0.9, -0.5, 0.9, 1.0],
            3
        ));
        assert!(is_positive_semidefinite(&[1.0, 1.0, 1.0, 1.0], 2));
    }

    #[test]
    fn scatter_is_relative_or_absolute() {
        let rel = OutputScatter {
            output: "incident_peak_stress".into(),
            sd: 0.02,
            relative: true,
        };
        assert!((rel.sd_at(-100.0) - 2.0).abs() < 1e-12);
        let abs = OutputScatter {
            output: "reflected_delay".into(),
            sd: 2e-6,
            relative: false,
        };
        assert_eq!(abs.sd_at(5.0), 2e-6);
        let u = Uncertainty {
            fitted_on: "x".into(),
            shots: 1,
            inputs: vec![],
            correlations: vec![Correlation {
                a: "k".into(),
                b: "p".into(),
                r: 0.9,
            }],
            scatter: vec![rel.clone(), abs],
        };
        assert_eq!(u.correlation("p", "k"), 0.9);
        assert_eq!(u.correlation("k", "k"), 1.0);
        assert_eq!(u.correlation("k", "d"), 0.0);
        assert_eq!(u.scatter_of("incident_peak_stress"), Some(&rel));
        assert_eq!(u.scatter_of("incident_energy"), None);
    }
}
