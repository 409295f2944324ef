//! The exact Pochhammer–Chree first mode (`shpb_core::dispersion`) against a published table of
//! c/c0 against d/Λ: `tests/data/bancroft_table.csv` (its header says where the digits come from:
//! Bancroft's 1941 table as two SHPB tools transcribe it, ν = 0.25, 0.30, 0.35, five digits).
//!
//! Acceptance of issue 19: within 0.1 % for ν = 0.29 and 0.31. The table has no such columns, so
//! those two are compared with the table interpolated in ν (quadratic through its three columns);
//! the interpolation's own error is measured on the solver (interpolating its ν = 0.25/0.30/0.35
//! values to 0.29/0.31 against solving there) and must be far below the tolerance for the
//! comparison to mean anything.

use shpb_core::dispersion::velocity_ratio_at_radius_over_wavelength;

/// (d/Λ, [c/c0 at ν = 0.25, 0.30, 0.35]) rows of the table.
fn table() -> Vec<(f64, [f64; 3])> {
    include_str!("data/bancroft_table.csv")
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("d_over") && !l.trim().is_empty())
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.trim().parse().unwrap()).collect();
            (v[0], [v[1], v[2], v[3]])
        })
        .collect()
}

const NU: [f64; 3] = [0.25, 0.30, 0.35];

/// Quadratic Lagrange interpolation through (NU[k], y[k]) at ν.
fn in_nu(y: [f64; 3], nu: f64) -> f64 {
    (0..3)
        .map(|k| {
            let w: f64 = (0..3)
                .filter(|&j| j != k)
                .map(|j| (nu - NU[j]) / (NU[k] - NU[j]))
                .product();
            w * y[k]
        })
        .sum()
}

/// The solver at d/Λ (a/Λ = d/(2Λ)).
fn exact(nu: f64, d_over_lambda: f64) -> f64 {
    velocity_ratio_at_radius_over_wavelength(nu, 0.5 * d_over_lambda)
}

#[test]
fn the_tabulated_columns_are_matched_within_a_tenth_of_a_percent() {
    let mut worst = 0.0f64;
    for (d, row) in table() {
        for (k, &nu) in NU.iter().enumerate() {
            let e = (exact(nu, d) / row[k] - 1.0).abs();
            worst = worst.max(e);
            assert!(
                e < 1e-3,
                "ν = {nu}, d/Λ = {d}: {} vs {}",
                exact(nu, d),
                row[k]
            );
        }
    }
    eprintln!("largest |relative difference| over 26 rows × 3 columns: {worst:.2e}");
}

#[test]
fn nu_0_29_and_0_31_match_the_table_interpolated_in_nu_within_a_tenth_of_a_percent() {
    for nu in [0.29, 0.31] {
        let (mut worst, mut interpolation) = (0.0f64, 0.0f64);
        for (d, row) in table() {
            let solved = exact(nu, d);
            let tabled = in_nu(row, nu);
            let own = in_nu(NU.map(|n| exact(n, d)), nu);
            interpolation = interpolation.max((own / solved - 1.0).abs());
            let e = (solved / tabled - 1.0).abs();
            worst = worst.max(e);
            assert!(e < 1e-3, "ν = {nu}, d/Λ = {d}: {solved} vs {tabled}");
        }
        eprintln!(
            "ν = {nu}: largest |relative difference| {worst:.2e}; interpolation in ν alone {interpolation:.2e}"
        );
        // The interpolation must not be what makes the comparison pass or fail.
        assert!(interpolation < 1e-4, "{interpolation}");
    }
}
