//! The material presets are defined once ([`modal_bake::fem::MaterialPreset::ALL`]); the
//! artist guide's table (docs/artist-guide.md § 5), which names each value's source, must
//! list exactly those presets with exactly those E (GPa), ν and ρ (kg/m³).
//!
//! `cargo test --release --workspace --test material_table`

use modal_bake::fem::MaterialPreset;

#[test]
fn the_guide_table_lists_every_preset_with_its_values() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/artist-guide.md");
    let guide = std::fs::read_to_string(path).expect("docs/artist-guide.md");
    let mut seen = Vec::new();
    for line in guide.lines().filter(|l| l.starts_with("| `")) {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        // "", name, grade, E, ν, ρ, range, source, ""
        let name = cells[1].trim_matches('`');
        let Some(p) = MaterialPreset::find(name) else {
            continue; // another table's row (options, controls)
        };
        if p.name != name || cells.len() < 8 {
            continue;
        }
        let num = |i: usize| -> f64 {
            cells[i]
                .parse()
                .unwrap_or_else(|_| panic!("{name}: cell {i} `{}` is not a number", cells[i]))
        };
        let (e, nu, rho) = (num(3) * 1e9, num(4), num(5));
        assert!(
            (e - p.youngs).abs() <= 1e-9 * p.youngs,
            "{name}: guide E {e} Pa, preset {} Pa",
            p.youngs
        );
        assert_eq!(nu, p.poisson, "{name}: guide ν vs preset");
        assert_eq!(rho, p.density, "{name}: guide ρ vs preset");
        seen.push(p.name);
    }
    let all: Vec<&str> = MaterialPreset::ALL.iter().map(|p| p.name).collect();
    assert_eq!(
        seen, all,
        "the guide's table must list every preset once, in order"
    );
}
