//! `shpb sweep`: the Cartesian product, deterministic shards whose union is the whole sweep,
//! summaries identical to single runs, parallel runs identical to serial ones, and clear errors
//! for bad `--set` specifications.

use shpb::scene::Params;
use shpb::sweep::{overrides, parse_axis, parse_shard, product, run_points, shard, summarise};
use std::path::PathBuf;

fn scene() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/shpb-ss440c-10psi.toml")
}

fn axes() -> Vec<shpb::sweep::Axis> {
    // `fast` keeps the test quick; the summary's physics is the same at every preset (tests/fidelity.rs).
    [
        "fidelity=fast",
        "pressure=8psi:16psi:3",
        "shaper.thickness=0.35mm,0.5mm",
    ]
    .iter()
    .map(|s| parse_axis(s).unwrap())
    .collect()
}

#[test]
fn set_specifications_parse_with_units_and_aliases() {
    let a = parse_axis("striker.pressure=5psi:20psi:16").unwrap();
    assert_eq!(a.key, "pressure");
    assert_eq!(a.labels.len(), 16);
    assert_eq!(
        (a.labels[0].as_str(), a.labels[15].as_str()),
        ("5psi", "20psi")
    );
    let t = parse_axis("shaper.thickness=0.5mm,1mm,1.5mm").unwrap();
    assert_eq!(t.key, "shaper.thickness_m");
    assert_eq!(t.values[1], toml::Value::Float(1e-3));
    for bad in [
        "pressure",
        "=1,2",
        "pressure=5psi:20bar:3",
        "pressure=1:2:x",
        "shaper.thickness_m=1furlong",
        "pressure=1,,2",
        "pressure=1:2:1",
    ] {
        let e = parse_axis(bad).unwrap_err().to_string();
        assert!(e.contains("--set"), "{bad}: {e}");
    }
    assert!(
        parse_shard("0/2").is_err() && parse_shard("3/2").is_err() && parse_shard("a").is_err()
    );
    assert_eq!(parse_shard("2/4").unwrap(), (2, 4));
}

#[test]
fn shards_partition_the_product_and_parallel_runs_match_single_runs() {
    let axes = axes();
    let all = product(&axes);
    assert_eq!(all.len(), 6);
    let whole = run_points(&scene(), &axes, &all, 2, || {}).unwrap();
    // Each run equals the same scene run on its own, bit for bit.
    for (p, row) in all.iter().zip(&whole) {
        let out = Params::from_file_overridden(&scene(), &overrides(&axes, p))
            .unwrap()
            .run()
            .unwrap();
        assert_eq!(summarise(p.index, row.inputs.clone(), &out), *row);
    }
    // Two shards, run serially, together are the whole sweep.
    let mut merged = Vec::new();
    for k in 1..=2 {
        let part = shard(all.clone(), k, 2);
        merged.extend(run_points(&scene(), &axes, &part, 1, || {}).unwrap());
    }
    merged.sort_by_key(|r| r.index);
    assert_eq!(merged, whole);
    // Peak force grows with pressure at each shaper thickness.
    for j in 0..2 {
        assert!(whole[j].peak_force_n < whole[2 + j].peak_force_n);
        assert!(whole[2 + j].peak_force_n < whole[4 + j].peak_force_n);
    }
}
