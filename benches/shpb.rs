//! Criterion benches: a full default SS440c SHPB test (gun → shaper → bars → spheres → gauges),
//! the bar pulse alone, the force-driven Fig. 4 DEM, and one contact-law evaluation.
//! Run with `cargo bench`; report ratios, not absolute times (DEVELOPERS.md).

use criterion::{Criterion, criterion_group, criterion_main};
use shpb::contact::{ContactHistory, LawKind};
use shpb::material::Material;
use shpb::scene::Params;
use shpb::specimen::SpherePair;
use std::hint::black_box;
use std::path::Path;

fn scene(path: &str) -> Params {
    Params::from_file(&Path::new(env!("CARGO_MANIFEST_DIR")).join(path)).expect("shipped scene")
}

fn benches(c: &mut Criterion) {
    let test = scene("scenes/shpb-ss440c-10psi.toml");
    c.bench_function("full SHPB test, SS440c 10 psi (default)", |b| {
        b.iter(|| black_box(test.run().unwrap()))
    });
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
            black_box(law.evaluate(&mut ContactHistory::default(), black_box(d), 5.0))
        })
    });
}

criterion_group! {
    name = shpb_benches;
    config = Criterion::default().sample_size(20);
    targets = benches
}
criterion_main!(shpb_benches);
