//! The registry of scene kinds.

/// The scene kinds with a one-line description each (shown by `shpb --help`).
pub const SCENE_KINDS: &[(&str, &str)] = &[
    (
        "quasistatic",
        "F(δ) of the loading law up to max_displacement_m (paper Fig. 2)",
    ),
    (
        "constant-rate",
        "spheres pressed at constant approach speed with rate hardening (paper Fig. 3)",
    ),
    (
        "collision",
        "two free spheres with initial velocities: restitution, contact time, peak force, dissipation",
    ),
    (
        "force-driven",
        "paper Fig. 4 DEM: a CSV force history drives sphere 1, sphere 2 rests on a medium of impedance Z",
    ),
    (
        "pulse",
        "striker, shaper and bars without specimen: the gauge signals of the bar set-up",
    ),
    (
        "shpb",
        "the whole virtual test: gun, striker, shaper, bars, two spheres, gauges and the lab's reduction",
    ),
];


/// (name, one-line help) of every scene kind, in registry order: what `shpb --help`, `shpb list`,
/// the "unknown kind" error and the README table show.
pub fn names_and_help() -> Vec<(&'static str, &'static str)> {
    SCENE_KINDS.to_vec()
}
