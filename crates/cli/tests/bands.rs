//! Issue 41 item 4: the 90 % bands of `shpb run` from a set-up's `[uncertainty]` (and its gun's
//! `velocity_scatter`), docs/physics.md §10.6. Every input of bars/authors.toml acts through the
//! striker velocity: the linear gun v² = k (p − p_loss) and the scatter v·f make v's relative
//! shares, over ± 1 sd, (√(1 + s_k) − √(1 − s_k))/2, (√(1 + s_p/(p − p_loss)) −
//! √(1 − s_p/(p − p_loss)))/2 and s_v: a value y ∝ v^η (η measured by two runs at the scene's
//! `striker_velocity_m_s` ± 1 %, not through the set-up) must get the band
//! 1.645 η √(Σ shares²) y, to the curvature of y over the inputs' range (below 0.2 % of the
//! half-width here).

mod common;
use common::{repo, repo_path, shpb, stderr, stdout};
use std::path::Path;

/// One pound per square inch, Pa.
const PSI_PA: f64 = shpb::units::PSI_PA;

/// The banded values.
use shpb::band::BANDED;

fn json(out: &std::process::Output) -> serde_json::Value {
    assert_eq!(out.status.code(), Some(0), "{}", stderr(out));
    serde_json::from_str(&stdout(out)).unwrap_or_else(|e| panic!("{e}: {}", stdout(out)))
}

/// A scene of the SS440c pair on set-up `bars` at `psi`, shaper on or off, at `fast`.
fn scene(dir: &Path, bars: &str, psi: f64, shaper: bool) -> String {
    let path = dir.join(format!("s-{psi}-{shaper}.toml"));
    std::fs::write(
        &path,
        format!(
            "kind = \"shpb\"\nbars = \"{bars}\"\npressure = \"{psi}psi\"\nfidelity = \"fast\"\n\
             [specimen]\npair = \"ss440c\"\n[shaper]\nenabled = {shaper}\n"
        ),
    )
    .unwrap();
    path.display().to_string()
}

/// A copy of bars/authors.toml in `dir` (with its gauge file) whose `[uncertainty]` is `table`
/// and whose gun scatter is `velocity_scatter`.
fn set_up(dir: &Path, name: &str, table: &str, velocity_scatter: f64) -> String {
    let text = std::fs::read_to_string(repo().join("bars/authors.toml")).unwrap();
    let head = &text[..text.find("\n# What the calibrated constants").unwrap() + 1];
    let head = head.replace(
        "velocity_scatter = 0.0145",
        &format!("velocity_scatter = {velocity_scatter}"),
    );
    std::fs::copy(
        repo().join("bars/gauges-authors.toml"),
        dir.join("gauges-authors.toml"),
    )
    .unwrap();
    let path = dir.join(name);
    std::fs::write(&path, format!("{head}{table}")).unwrap();
    path.display().to_string()
}

fn value(j: &serde_json::Value, key: &str) -> f64 {
    j["summary"][key]["value"].as_f64().unwrap()
}

fn band(j: &serde_json::Value, key: &str) -> [f64; 2] {
    let b = j["summary"][key]["band_90"]
        .as_array()
        .unwrap_or_else(|| panic!("{key}: {}", j["summary"][key]));
    [b[0].as_f64().unwrap(), b[1].as_f64().unwrap()]
}

/// Half-width of a band relative to its value.
fn relative_half_width(j: &serde_json::Value, key: &str) -> f64 {
    let [lo, hi] = band(j, key);
    0.5 * (hi - lo) / value(j, key)
}

#[test]
fn the_authors_set_up_gives_every_value_its_band_of_the_stated_uncertainty() {
    let dir = tempfile::TempDir::new().unwrap();
    let bars = repo_path("bars/authors.toml");
    let psi = 12.5;
    let out = shpb(
        dir.path(),
        &[
            "--json",
            "run",
            &scene(dir.path(), &bars, psi, false),
            "-o",
            "run.h5",
        ],
    );
    let j = json(&out);
    // The shape: {value, unit, band_90} for the banded values, {value, unit} for the others.
    for key in BANDED {
        let item = j["summary"][key].as_object().unwrap();
        let mut keys: Vec<&str> = item.keys().map(String::as_str).collect();
        keys.sort();
        assert_eq!(keys, ["band_90", "unit", "value"], "{key}");
        let [lo, hi] = band(&j, key);
        let v = value(&j, key);
        assert!(lo <= v && v <= hi, "{key}: {v} outside [{lo}, {hi}]");
    }
    for key in ["pressure", "striker_velocity", "peak_contact_force"] {
        let keys: Vec<&String> = j["summary"][key].as_object().unwrap().keys().collect();
        assert_eq!(keys, ["unit", "value"], "{key}");
    }
    // Every input acts through v (see the module docs): bars/authors.toml states k ± 4.5 %,
    // p_loss ± 3.0 kPa, velocity_scatter 1.45 %.
    let p = psi * PSI_PA;
    let secant = |s: f64| ((1.0 + s).sqrt() - (1.0 - s).sqrt()) / 2.0;
    let shares = [secant(0.045), secant(3.0e3 / (p - 21.76e3)), 0.0145];
    let sigma_v = shares.iter().map(|s| s * s).sum::<f64>().sqrt();
    let v = value(&j, "striker_velocity");
    let at = |factor: f64| {
        let set = format!("striker_velocity_m_s={}", factor * v);
        let out = shpb(
            dir.path(),
            &[
                "--json",
                "run",
                &scene(dir.path(), &bars, psi, false),
                "--set",
                &set,
                "--no-bands",
            ],
        );
        json(&out)
    };
    let (up, down) = (at(1.01), at(0.99));
    for key in ["incident_peak_stress", "incident_energy"] {
        let eta = (value(&up, key) / value(&down, key)).ln() / (1.01f64 / 0.99).ln();
        let expected = 1.644_853_6 * eta * sigma_v;
        let got = relative_half_width(&j, key);
        assert!(
            (got / expected - 1.0).abs() < 2e-3,
            "{key}: ±{got:.5} of its value, expected ±{expected:.5} (η = {eta:.4})"
        );
    }
    // The run file stores the same bands under /summary/bands.
    let file = shpb_output::run_file::read_run_file(&dir.path().join("run.h5")).unwrap();
    for key in BANDED {
        let d = file
            .datasets
            .iter()
            .find(|d| d.path == format!("summary/bands/{key}"))
            .unwrap_or_else(|| panic!("no summary/bands/{key}"));
        // (serde_json reads floats to within an ulp, not exactly.)
        for (stored, printed) in d.data.iter().zip(band(&j, key)) {
            assert!(
                (stored - printed).abs() <= 1e-15 * printed.abs(),
                "{key}: {stored} {printed}"
            );
        }
    }
    // The text table shows `value [low, high]`.
    let out = shpb(dir.path(), &["run", &scene(dir.path(), &bars, psi, false)]);
    let line = stdout(&out)
        .lines()
        .find(|l| l.trim_start().starts_with("incident_peak_stress"))
        .unwrap()
        .to_string();
    let [lo, hi] = band(&j, "incident_peak_stress");
    assert!(line.contains(&format!("[{lo:.6e}, {hi:.6e}] Pa")), "{line}");
    // --no-bands: no band anywhere, and the values of the run unchanged.
    let out = shpb(
        dir.path(),
        &[
            "--json",
            "run",
            &scene(dir.path(), &bars, psi, false),
            "--no-bands",
        ],
    );
    let plain = json(&out);
    for (key, item) in plain["summary"].as_object().unwrap() {
        assert!(item.get("band_90").is_none(), "{key}");
        assert_eq!(item["value"], j["summary"][key]["value"], "{key}");
    }
}

#[test]
fn band_widths_follow_the_stated_sd() {
    let dir = tempfile::TempDir::new().unwrap();
    let table = |rel: f64| {
        format!(
            "[uncertainty]\nfitted_on = \"test\"\nshots = 3\n[uncertainty.relative_sd]\n\
             \"gun.k_m2_per_s2_per_pa\" = {rel}\n"
        )
    };
    // Only k, with the shaper: the incident peak's band is the first-order one, proportional to
    // the sd; central differences over ±1 sd keep it so to their second-order terms.
    let width = |name: &str, rel: f64| {
        let bars = set_up(dir.path(), name, &table(rel), 0.0);
        let out = shpb(
            dir.path(),
            &["--json", "run", &scene(dir.path(), &bars, 12.5, true)],
        );
        let j = json(&out);
        (
            relative_half_width(&j, "incident_peak_stress"),
            relative_half_width(&j, "reduced_peak_back_force"),
        )
    };
    let wide = width("wide.toml", 0.045);
    let narrow = width("narrow.toml", 0.0045);
    let tiny = width("tiny.toml", 1e-7);
    for (w, n, what) in [
        (wide.0, narrow.0, "incident peak"),
        (wide.1, narrow.1, "peak back force"),
    ] {
        assert!(w > 0.0 && n > 0.0, "{what}: {w} {n}");
        assert!(
            (w / n / 10.0 - 1.0).abs() < 0.05,
            "{what}: ten times the sd gives {:.3} times the band",
            w / n
        );
    }
    assert!(tiny.0 < 1e-5 && tiny.1 < 1e-5, "tiny sd, band {tiny:?}");
    // An sd of zero is no uncertainty: refused, naming the file and the key.
    let bars = set_up(dir.path(), "zero.toml", &table(0.0), 0.0);
    let out = shpb(
        dir.path(),
        &["run", &scene(dir.path(), &bars, 12.5, true), "-q"],
    );
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).contains(
            "zero.toml: `uncertainty.relative_sd.gun.k_m2_per_s2_per_pa`: 0 is out of range"
        ),
        "{}",
        stderr(&out)
    );
}

#[test]
fn a_set_up_without_uncertainty_gives_no_band() {
    let dir = tempfile::TempDir::new().unwrap();
    let bars = set_up(dir.path(), "plain.toml", "", 0.0);
    let out = shpb(
        dir.path(),
        &["--json", "run", &scene(dir.path(), &bars, 12.5, true)],
    );
    let j = json(&out);
    for (key, item) in j["summary"].as_object().unwrap() {
        assert!(item.get("band_90").is_none(), "{key}");
    }
}
