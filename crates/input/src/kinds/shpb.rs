//! `kind = "shpb"`: the whole virtual test, a pulse scene ([`super::pulse`]) with two spheres
//! between the bars, gauges and the lab's reduction.

use super::pulse::{
    self, BARS, CELL_SIZE, DISPERSION, END_TIME, GAUGE_LENGTH, INCIDENT_RECORD, LOADING, PRESSURE,
    SHAPER, SMOOTH, STRIKER_VELOCITY,
};
use super::{Key, LAW, Parsed, REGION2, SceneKind, UNLOADING};
use crate::error::{Result, Validator};
use shpb_core::fidelity::Fidelity;
use std::path::Path;

/// The registry entry.
pub(super) const KIND: SceneKind = SceneKind {
    name: "shpb",
    help: "the whole virtual test: gun, striker, shaper, bars, spheres or a cylinder, gauges and the lab's reduction",
    keys: &[
        SPECIMEN,
        LAW,
        REGION2,
        UNLOADING,
        BARS,
        PRESSURE,
        STRIKER_VELOCITY,
        INCIDENT_RECORD,
        SHAPER,
        CELL_SIZE,
        DISPERSION,
        END_TIME,
        GAUGE_LENGTH,
        SMOOTH,
        LOADING,
    ],
    example: "kind = \"shpb\"\nbars = \"authors\"\npressure = \"10psi\"\nspecimen = { pair = \"ss440c\" }\n",
    example_dir: None,
    parse,
};

/// `[specimen]` of a full test: spheres (as a chain scene's) or a cylinder (docs/physics.md §6.9).
const SPECIMEN: Key = Key {
    key: "specimen",
    unit: "",
    default: "required",
    meaning: "the spheres in a line, sphere 1 first: count = N (2 to 100000) with material (built-in or .toml) and diameter_m, or one [[specimen.sphere]] table per sphere (material, diameter_m or radius_m, optional mass_kg), or a pair as in the other scenes (pair = \"ss440c\", or sphere1/sphere2), each contact seated touching (default), across gap_m (m, to 1 mm) or pressed by preload_n (N, to 10 kN), yield_stress_pa (Pa), jc_c and jc_reference_rate_per_s (1/s) replacing every sphere's material constants (σy, C, ε̇0 of paper Eq. 2); or an elastic cylinder: shape = \"cylinder\" with length_m and diameter_m (m, each at most 0.1) and material (built-in name, material .toml, or a table of density_kg_m3, youngs_modulus_pa, poisson_ratio), its flow by [specimen.johnson_cook] (a_pa, b_pa, n, c, …; a table without a_pa, b_pa and n is merged over the material's)",
};

fn parse(
    text: &str,
    file: &str,
    base_dir: &Path,
    fidelity: Fidelity,
    v: &Validator,
) -> Result<Parsed> {
    pulse::parse_bars(text, file, base_dir, fidelity, v, true)
}

#[cfg(test)]
mod tests {
    use super::*;
    use shpb_core::apparatus::IncidentEnd;
    use shpb_core::scene::SceneParams;

    #[test]
    fn registry_entry() {
        // `incident_end` is accepted (a pulse scene's key) but a test's incident bar always ends
        // at the specimen.
        super::super::check_kind(&KIND, &["incident_end"]);
        pulse::check_bar_key_docs();
    }

    #[test]
    fn example_values() {
        let (specimen, p) = super::super::parse_example(&KIND, Fidelity::Fast);
        let SceneParams::Pulse { options, .. } = p else {
            panic!("not a bar scene: {p:?}")
        };
        assert_eq!(options.end, IncidentEnd::Specimen);
        let specimen = specimen.expect("a specimen");
        let spheres = specimen.spheres().expect("spheres");
        assert_eq!(spheres.chain.len(), 2);
        assert_eq!(spheres.law, shpb_core::contact::LawSpec::default());
        assert_eq!(options.cell_size_m, 4e-3);
        assert_eq!(
            options.snapshot_interval_s,
            Some(Fidelity::Fast.bar_knobs().snapshot_interval_s)
        );
    }

    /// A cylinder of a named material takes its E, ν, ρ; one given as a table takes the table's;
    /// the fast fidelity's 4 mm cell is refined so the specimen has CYLINDER_MIN_CELLS cells
    /// (docs/physics.md §6.9), an explicit cell is kept when fine enough.
    #[test]
    fn a_cylinder_specimen_is_read_and_resolved() {
        use shpb_core::material::Material;
        use shpb_core::specimen::CYLINDER_MIN_CELLS;
        let v = Validator::new("c.toml");
        let head = "kind = \"shpb\"\nbars = \"authors\"\npressure = \"10psi\"\n";
        let named = format!(
            "{head}[specimen]\nshape = \"cylinder\"\nmaterial = \"al2017\"\nlength_m = 6e-3\ndiameter_m = 12e-3\n"
        );
        let (specimen, p) = parse(&named, "c.toml", Path::new("."), Fidelity::Fast, &v).unwrap();
        let SceneParams::Pulse {
            options, apparatus, ..
        } = p
        else {
            panic!("not a bar scene")
        };
        let c = specimen
            .as_ref()
            .and_then(|s| s.cylinder())
            .expect("a cylinder")
            .clone();
        let al = <Material as crate::material::MaterialFile>::builtin("al2017").unwrap();
        assert_eq!(
            (
                c.material.youngs_modulus_pa,
                c.material.poisson_ratio,
                c.material.density_kg_m3
            ),
            (al.youngs_modulus_pa, al.poisson_ratio, al.density_kg_m3)
        );
        assert_eq!((c.length_m, c.diameter_m), (6e-3, 12e-3));
        assert_eq!(options.end, IncidentEnd::Specimen);
        let c0 = apparatus.material.wave_speed_m_s();
        assert!(options.cell_size_m < Fidelity::Fast.bar_knobs().cell_size_m);
        assert_eq!(c.cells_at(options.cell_size_m / c0), CYLINDER_MIN_CELLS);
        let table = format!(
            "{head}cell_size_m = 5e-4\n[specimen]\nshape = \"cylinder\"\nlength_m = 5e-3\ndiameter_m = 5e-3\nmaterial = {{ density_kg_m3 = 7850.0, youngs_modulus_pa = 200e9, poisson_ratio = 0.3 }}\n"
        );
        let (specimen, p) = parse(&table, "c.toml", Path::new("."), Fidelity::Fast, &v).unwrap();
        let SceneParams::Pulse { options, .. } = p else {
            panic!("not a bar scene")
        };
        let c = specimen
            .as_ref()
            .and_then(|s| s.cylinder())
            .unwrap()
            .clone();
        assert_eq!(c.material.youngs_modulus_pa, 200e9);
        assert_eq!(options.cell_size_m, 5e-4);
    }

    /// `gap_m` and `preload_n` seat the spheres (docs/physics.md §6.11); zero or absent is
    /// touching, as before.
    #[test]
    fn the_seating_keys_are_read() {
        use shpb_core::specimen::Seating;
        let v = Validator::new("s.toml");
        let seating = |extra: &str| {
            let text = format!(
                "kind = \"shpb\"\nbars = \"authors\"\npressure = \"10psi\"\n[specimen]\npair = \"ss440c\"\n{extra}"
            );
            let (specimen, p) = parse(&text, "s.toml", Path::new("."), Fidelity::Fast, &v).unwrap();
            assert!(matches!(p, SceneParams::Pulse { .. }), "not a bar scene");
            specimen.unwrap().spheres().unwrap().seating
        };
        assert_eq!(seating(""), Seating::Touching);
        assert_eq!(seating("gap_m = 0.0\n"), Seating::Touching);
        assert_eq!(seating("gap_m = 2e-5\n"), Seating::Gap { gap_m: 2e-5 });
        assert_eq!(
            seating("preload_n = 50.0\n"),
            Seating::Preload { force_n: 50.0 }
        );
    }

    #[test]
    fn a_specimen_is_required() {
        let v = Validator::new("s.toml");
        let text = "kind = \"shpb\"\nbars = \"authors\"\npressure = \"10psi\"\n";
        let e = parse(text, "s.toml", Path::new("."), Fidelity::Standard, &v).unwrap_err();
        assert_eq!(
            e.to_string(),
            "s.toml: `specimen`: missing; allowed: a [specimen] table (pair = \"ss440c\", or sphere1/sphere2)"
        );
    }
}
