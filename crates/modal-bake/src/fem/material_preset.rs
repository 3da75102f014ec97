//! Named material presets: typical room-temperature values of common object materials
//! for isotropic linear elasticity (`modal-bake bake --material NAME`).
//!
//! Each preset is one representative grade (its `grade` field says which), with the
//! spread of the material class in `youngs_range`: real objects vary by that much, so a
//! baked frequency (∝ √(E/ρ)) is typical, not exact. The sources of every value are in
//! `docs/artist-guide.md` (§ Material). Woods are orthotropic: the presets give the modulus
//! along the grain, so modes that bend across the grain come out too high.
//!
//! Not offered: rubbers and foams (ν → 0.5 and large strains; linear tetrahedra lock),
//! composites and plywood (layered, strongly anisotropic).

use super::Material;

/// A named material: E (Pa), ν, ρ (kg/m³) of one representative grade, and the range of E
/// over its material class.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaterialPreset {
    /// The name `--material` takes (lower case, ASCII).
    pub name: &'static str,
    /// The representative grade these values belong to.
    pub grade: &'static str,
    /// Young's modulus E (Pa).
    pub youngs: f64,
    /// Poisson's ratio ν.
    pub poisson: f64,
    /// Density ρ (kg/m³).
    pub density: f64,
    /// Typical range of E over the material class (Pa), `[low, high]`.
    pub youngs_range: [f64; 2],
}

impl MaterialPreset {
    /// Every preset, in the order `--help` lists them.
    pub const ALL: &'static [MaterialPreset] = &[
        MaterialPreset {
            name: "oak",
            grade: "white oak, along the grain, 12 % moisture",
            youngs: 12.3e9,
            poisson: 0.37,
            density: 750.0,
            youngs_range: [9.0e9, 14.0e9],
        },
        MaterialPreset {
            name: "pine",
            grade: "pine (eastern white to southern), along the grain, 12 % moisture",
            youngs: 9.0e9,
            poisson: 0.33,
            density: 500.0,
            youngs_range: [7.0e9, 13.7e9],
        },
        MaterialPreset {
            name: "steel",
            grade: "carbon steel (e.g. AISI 1020)",
            youngs: 200e9,
            poisson: 0.29,
            density: 7850.0,
            youngs_range: [190e9, 210e9],
        },
        MaterialPreset {
            name: "aluminium",
            grade: "aluminium alloy 6061-T6",
            youngs: 68.9e9,
            poisson: 0.33,
            density: 2700.0,
            youngs_range: [68e9, 72e9],
        },
        MaterialPreset {
            name: "brass",
            grade: "cartridge brass C26000",
            youngs: 110e9,
            poisson: 0.34,
            density: 8530.0,
            youngs_range: [97e9, 117e9],
        },
        MaterialPreset {
            name: "cast-iron",
            grade: "grey cast iron, class 30",
            youngs: 100e9,
            poisson: 0.28,
            density: 7200.0,
            youngs_range: [66e9, 138e9],
        },
        MaterialPreset {
            name: "glass",
            grade: "soda-lime glass",
            youngs: 70e9,
            poisson: 0.22,
            density: 2500.0,
            youngs_range: [68e9, 74e9],
        },
        MaterialPreset {
            name: "ceramic",
            grade: "porcelain (tableware, electrical)",
            youngs: 70e9,
            poisson: 0.22,
            density: 2400.0,
            youngs_range: [50e9, 100e9],
        },
        MaterialPreset {
            name: "concrete",
            grade: "normal-weight concrete, strength class C30/37",
            youngs: 33e9,
            poisson: 0.2,
            density: 2400.0,
            youngs_range: [27e9, 44e9],
        },
        MaterialPreset {
            name: "stone",
            grade: "granite",
            youngs: 50e9,
            poisson: 0.25,
            density: 2650.0,
            youngs_range: [30e9, 70e9],
        },
        MaterialPreset {
            name: "marble",
            grade: "marble (calcite)",
            youngs: 55e9,
            poisson: 0.25,
            density: 2700.0,
            youngs_range: [35e9, 80e9],
        },
        MaterialPreset {
            name: "abs",
            grade: "ABS, injection moulded",
            youngs: 2.3e9,
            poisson: 0.4,
            density: 1050.0,
            youngs_range: [2.0e9, 2.9e9],
        },
        MaterialPreset {
            name: "pla",
            grade: "PLA, injection moulded (3D prints are 10–40 % softer)",
            youngs: 3.5e9,
            poisson: 0.36,
            density: 1240.0,
            youngs_range: [2.3e9, 4.0e9],
        },
        MaterialPreset {
            name: "acrylic",
            grade: "PMMA (acrylic glass, Plexiglas)",
            youngs: 3.2e9,
            poisson: 0.37,
            density: 1190.0,
            youngs_range: [2.4e9, 3.4e9],
        },
    ];

    /// The preset called `name` (case-insensitive; `_` and ` ` read as `-`; `aluminum` and
    /// `castiron` are accepted spellings), or `None`.
    ///
    /// ```
    /// use modal_bake::fem::MaterialPreset;
    /// let steel = MaterialPreset::find("Steel").unwrap();
    /// assert_eq!(steel.youngs, 200e9);
    /// assert_eq!(MaterialPreset::find("aluminum").unwrap().name, "aluminium");
    /// assert!(MaterialPreset::find("unobtainium").is_none());
    /// ```
    pub fn find(name: &str) -> Option<&'static MaterialPreset> {
        let key: String = name
            .trim()
            .to_ascii_lowercase()
            .chars()
            .map(|c| if c == '_' || c == ' ' { '-' } else { c })
            .collect();
        let key = match key.as_str() {
            "aluminum" => "aluminium",
            "castiron" | "iron" => "cast-iron",
            "granite" => "stone",
            "porcelain" => "ceramic",
            "pmma" => "acrylic",
            k => k,
        };
        Self::ALL.iter().find(|p| p.name == key)
    }

    /// The preset names, comma-separated (for messages and `--help`).
    pub fn names() -> String {
        Self::ALL
            .iter()
            .map(|p| p.name)
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// The preset as a [`Material`].
    pub fn material(&self) -> Material {
        Material {
            youngs: self.youngs,
            poisson: self.poisson,
            density: self.density,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // Every preset is a valid material, its E lies within its stated range, and its names are
    // unique and round-trip through `find`.
    #[test]
    fn presets_are_valid_and_findable() {
        for p in MaterialPreset::ALL {
            p.material().validate().unwrap();
            assert!(
                p.youngs_range[0] <= p.youngs && p.youngs <= p.youngs_range[1],
                "{}",
                p.name
            );
            assert_eq!(MaterialPreset::find(p.name), Some(p));
            assert_eq!(MaterialPreset::find(&p.name.to_ascii_uppercase()), Some(p));
            let c = (p.youngs / p.density).sqrt();
            // Bar wave speeds of solids: ~1 km/s (polymers) … ~6 km/s (glass, aluminium).
            assert!((1000.0..7000.0).contains(&c), "{}: {c} m/s", p.name);
        }
        assert_eq!(MaterialPreset::find("cast_iron").unwrap().name, "cast-iron");
    }
}
