//! Round trip of the whole virtual experiment: reduce the simulated gauge records the way the lab
//! does (dispersion off: the simulated bars are non-dispersive) and recover the simulation's true
//! contact history, which no lab can measure.

use shpb::prelude::*;
use shpb::reduce::{ReductionInput, ReductionOptions, ReductionSetup, reduce};
use shpb::scene::{Params, SceneParams};
use std::path::PathBuf;

#[test]
fn reduction_of_simulated_records_recovers_the_true_contact() {
    for m in ["ss440c", "ss302", "al2017"] {
        let path = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
            .join(format!("validation/fig4-virtual-shpb/{m}-12p5psi.toml"));
        let params = Params::from_file(&path).unwrap();
        let SceneParams::Pulse { apparatus, .. } = &params.params else {
            unreachable!()
        };
        let out = params.run().unwrap();
        let input = ReductionInput::from_noise_free_gauges(&out).unwrap();
        let options = ReductionOptions {
            dispersion: shpb::reduce::DispersionCorrection::None,
            specimen_radii_m: params
                .sphere_pair()
                .map(|(p, _)| (p.sphere1.radius_m, p.sphere2.radius_m)),
            ..Default::default()
        };
        let r = reduce(
            &input,
            &ReductionSetup::from_apparatus(apparatus).unwrap(),
            &options,
        )
        .unwrap();
        let c = out.contact.as_ref().unwrap();
        let k = c.peak_index();
        let (f_true, d_true) = (c.force_n[k], c.displacement_m[k]);
        let f_err = (r.peak_back_force_n - f_true).abs() / f_true;
        let d_err = (r.displacement_at_peak_force_m - d_true).abs() / d_true;
        eprintln!(
            "{m}: peak force true {f_true:.1} N, reduced {:.1} N ({:+.2} %); δ at peak true {d_true:.4e} m, reduced {:.4e} m ({:+.2} %); equilibrium at peak {:.3}",
            r.peak_back_force_n,
            100.0 * (r.peak_back_force_n / f_true - 1.0),
            r.displacement_at_peak_force_m,
            100.0 * (r.displacement_at_peak_force_m / d_true - 1.0),
            r.equilibrium_ratio_at_peak
        );
        assert!(f_err < 0.02, "{m}: peak force error {f_err}");
        assert!(d_err < 0.02, "{m}: displacement at peak error {d_err}");
    }
}
