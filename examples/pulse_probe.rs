//! Prints the simulated gauge strains of one pulse run as CSV (exploration aid for calibration):
//! `cargo run --release --example pulse_probe -- V D H DX GAUGE_LENGTH`.
use shpb::apparatus::{Apparatus, IncidentEnd, PulseOptions};
use shpb::bar::Dispersion;
use shpb::solver::pulse::simulate_chain;

fn main() {
    let a = Apparatus::from_file(std::path::Path::new("bars/authors.toml")).expect("set-up file");
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .map(|s| s.parse().expect("number"))
        .collect();
    let (v, d, h, dx, gl) = (args[0], args[1], args[2], args[3], args[4]);
    let mut s = a.shaper.expect("set-up has a shaper");
    s.diameter_m = d;
    s.thickness_m = h;
    let setup = a.pulse_chain(&PulseOptions {
        striker_velocity_m_s: v,
        shaper: Some(s),
        end: IncidentEnd::Transmission,
        cell_size_m: dx,
        dispersion: Dispersion::None,
        end_time_s: 500e-6,
        gauge_length_m: gl,
    });
    let r = simulate_chain(&setup).expect("run");
    for (i, t) in r.time_s.iter().enumerate() {
        println!("{t:e},{:e},{:e}", r.strain[0][i], r.strain[1][i]);
    }
}
