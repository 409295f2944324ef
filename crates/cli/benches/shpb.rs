//! Criterion benches: a full SS440c SHPB test (gun → shaper → bars → spheres → gauges →
//! reduction) at each fidelity preset, the bar pulse alone, the force-driven Fig. 4 DEM, the
//! reduction of one real gauge record, and one contact-law evaluation.
//! Run with `cargo bench`; report ratios, not absolute times (DEVELOPERS.md).

use criterion::{Criterion, criterion_group, criterion_main};
use shpb::apparatus::Apparatus;
use shpb::contact::LawKind;
use shpb::fidelity::Fidelity;
use shpb::gauges::reduce_record_file;
use shpb::material::Material;
use shpb::prelude::*;
use shpb::reduce::ReductionOptions;
use shpb::scene::Params;
use shpb::specimen::SpherePair;
use std::hint::black_box;
use std::path::Path;

fn scene(path: &str) -> Params {
    Params::from_file(&Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join(path))
        .expect("shipped scene")
}

fn benches(c: &mut Criterion) {
    let root = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."));
    // Every preset: `reference` (exact first mode on delay lines at 1 mm) costs ≈ 3× `standard`.
    for f in Fidelity::ALL {
        let test = Params::from_file_with(&root.join("scenes/shpb-ss440c-10psi.toml"), Some(f))
            .expect("shipped scene");
        c.bench_function(
            &format!("full SHPB test, SS440c 10 psi ({})", f.name()),
            |b| b.iter(|| black_box(test.run().unwrap())),
        );
    }
    let app = Apparatus::from_file(&root.join("bars/authors.toml")).expect("shipped set-up");
    let record = root.join("validation/gauge-records/data/2013-05-22_sample2_ss440c.csv");
    c.bench_function(
        "reduction of a real record (sample 2, dispersion corrected)",
        |b| {
            b.iter(|| {
                black_box(reduce_record_file(&record, &app, &ReductionOptions::default()).unwrap())
            })
        },
    );
    let pulse = scene("scenes/pulse-10psi.toml");
    c.bench_function("pulse only, 10 psi", |b| {
        b.iter(|| black_box(pulse.run().unwrap()))
    });
    let fd = scene("scenes/force-driven-ss440c-10psi.toml");
    c.bench_function("force-driven Fig. 4 DEM, SS440c 10 psi", |b| {
        b.iter(|| black_box(fd.run().unwrap()))
    });
    let law = LawKind::BurgoyneDaraio
        .build(SpherePair::paper(Material::builtin("ss440c").unwrap()).contact_properties());
    c.bench_function("contact law evaluation (rate-dependent, loading)", |b| {
        let mut d = 0.0;
        b.iter(|| {
            d = if d > 2e-4 { 1e-6 } else { d + 1e-7 };
            black_box(law.trial(black_box(d), 5.0))
        })
    });
}

criterion_group! {
    name = shpb_benches;
    config = Criterion::default().sample_size(20);
    targets = benches
}
criterion_main!(shpb_benches);
