//! Unit mistakes named: an object's size, mass, lowest frequency and material compared with
//! what real objects have, so that a millimetre asset read as metres (a 300 m bunny) or a
//! modulus in GPa typed as Pa is named — in every refusal it causes and as a warning before the
//! factorization and in `modal-bake info`.
//!
//! Frequencies scale as √(E/ρ)/L, so a wrong length unit leaves f·L/c unchanged: it shows in
//! the absolute size, mass and frequency, which is what these checks test.

use dcr_runtime::format::MaterialSi;

/// Bounding-box diagonals of plausible objects (m): a 5 mm bead … a 100 m bridge.
pub const PLAUSIBLE_EXTENT_M: [f64; 2] = [0.005, 100.0];

/// Plausible object masses (kg): 0.1 g … 1000 t.
pub const PLAUSIBLE_MASS_KG: [f64; 2] = [1e-4, 1e6];

/// Plausible lowest elastic frequencies (Hz) of the objects a scene holds: a 2 Hz swaying
/// lamp post … a 50 kHz bead (a 100 m tower can sway below 1 Hz: the warning is a hint).
pub const PLAUSIBLE_LOWEST_HZ: [f64; 2] = [2.0, 5e4];

/// Plausible bar wave speeds √(E/ρ) of solids (m/s): soft silicone rubber ~ 15 (E 0.25 MPa,
/// ρ 1100 kg/m³) … diamond ~ 18,000. A modulus typed in MPa or GPa lands below (steel 5 and
/// 0.005 m/s, oak 3.8 m/s, ABS 1.5 m/s), a density in g/cm³ above (steel 1.6e5 m/s).
pub const PLAUSIBLE_WAVE_SPEED: [f64; 2] = [10.0, 2e4];

/// What the size of an object `extent_m` across (bounding-box diagonal, m) says about its
/// length unit, when it is implausible: the likely unit and the fix. `None` for a plausible
/// size.
///
/// ```
/// use modal_bake::bake::unit_hint;
/// let h = unit_hint(300.0).unwrap();
/// assert!(h.contains("millimetres") && h.contains("--units mm"), "{h}");
/// assert!(unit_hint(0.3).is_none());
/// ```
pub fn unit_hint(extent_m: f64) -> Option<String> {
    let [lo, hi] = PLAUSIBLE_EXTENT_M;
    if !extent_m.is_finite() || (lo..=hi).contains(&extent_m) {
        return None;
    }
    if extent_m > hi {
        let (unit, flag, factor) = if extent_m / 1000.0 >= lo {
            ("millimetres", "mm", 1000.0)
        } else {
            ("micrometres or worse", "mm", 1000.0)
        };
        let cm = if extent_m / 100.0 <= hi && extent_m / 100.0 >= lo {
            format!(
                "; if in centimetres, --units cm ({:.3} m)",
                extent_m / 100.0
            )
        } else {
            String::new()
        };
        Some(format!(
            "the object is {extent_m:.4} m across (bounding-box diagonal), larger than any object the \
             defaults suit ({lo} … {hi} m): its file is probably in {unit}; rerun with --units {flag} \
             ({:.4} m across{cm}) and keep every length option (--fixed-below, --fixed-box, --size) in \
             metres, or give those options in the file's units",
            extent_m / factor
        ))
    } else {
        Some(format!(
            "the object is only {:.4} mm across (bounding-box diagonal), smaller than any object the \
             defaults suit ({} … {hi} m): if its file is in metres, do not pass --units mm/cm; if \
             the length options were meant in millimetres, divide them by 1000",
            extent_m * 1e3,
            lo
        ))
    }
}

/// Warnings (one line each, no `warning:` prefix) for an object `extent_m` across (when
/// given) of mass `mass_kg` (NaN: not checked) and `material`, with its lowest elastic
/// frequency when known: implausible size ([`unit_hint`]), mass, frequency or wave speed.
/// Empty when everything is plausible.
///
/// ```
/// use modal_bake::bake::{plausibility_warnings, MaterialSi};
/// let oak = MaterialSi { youngs: 12.3e9, poisson: 0.37, density: 750.0 };
/// assert!(plausibility_warnings(Some(0.3), 5.0, &oak, Some(800.0)).is_empty());
/// let w = plausibility_warnings(Some(300.0), 5e9, &oak, Some(1.44));
/// assert_eq!(w.len(), 3, "{w:?}");
/// ```
pub fn plausibility_warnings(
    extent_m: Option<f64>,
    mass_kg: f64,
    material: &MaterialSi,
    lowest_hz: Option<f64>,
) -> Vec<String> {
    let mut out = Vec::new();
    if let Some(h) = extent_m.and_then(unit_hint) {
        out.push(h);
    }
    let [mlo, mhi] = PLAUSIBLE_MASS_KG;
    if mass_kg.is_finite() && !(mlo..=mhi).contains(&mass_kg) {
        out.push(format!(
            "the object weighs {mass_kg:.4e} kg (ρ {} kg/m³ × its volume), outside {mlo:e} … {mhi:e} kg: \
             a length unit 10× off changes the mass 1000×; check --units and --density",
            material.density
        ));
    }
    if let Some(f) = lowest_hz {
        let [flo, fhi] = PLAUSIBLE_LOWEST_HZ;
        if f.is_finite() && f > 0.0 && !(flo..=fhi).contains(&f) {
            out.push(format!(
                "the lowest elastic mode is at {f:.4} Hz, outside the {flo} … {fhi:e} Hz of scene objects: frequencies scale as √(E/ρ)/length, so check the length unit \
                 (--units) and E and ρ (E {:e} Pa, ρ {} kg/m³)",
                material.youngs, material.density
            ));
        }
    }
    let c = (material.youngs / material.density).sqrt();
    let [clo, chi] = PLAUSIBLE_WAVE_SPEED;
    if c.is_finite() && !(clo..=chi).contains(&c) {
        out.push(format!(
            "the material's wave speed √(E/ρ) = {c:.4e} m/s is outside the {clo} … {chi:e} m/s of solids \
             (E {:e} Pa, ρ {} kg/m³): E is in Pa (1 GPa = 1e9), ρ in kg/m³ (1 g/cm³ = 1000)",
            material.youngs, material.density
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    // A millimetre bunny read as metres (0.3 m → 300 m) is named as millimetres with the
    // metre size it would have; a metre asset read as millimetres (0.3 m → 0.3 mm) as too
    // small; plausible sizes give nothing.
    #[test]
    fn unit_hints_name_the_likely_unit() {
        let h = unit_hint(300.0).unwrap();
        assert!(h.contains("millimetres") && h.contains("0.3000 m"), "{h}");
        let h = unit_hint(3e-4).unwrap();
        assert!(h.contains("0.3000 mm") && h.contains("--units"), "{h}");
        for ok in [0.005, 0.3, 10.0, 100.0] {
            assert!(unit_hint(ok).is_none(), "{ok}");
        }
        let steel = MaterialSi {
            youngs: 2e11,
            poisson: 0.3,
            density: 7850.0,
        };
        // E typed in GPa as Pa: 200 Pa → c = 0.16 m/s.
        let gpa_as_pa = MaterialSi {
            youngs: 200.0,
            ..steel
        };
        let w = plausibility_warnings(Some(0.3), 10.0, &gpa_as_pa, None);
        assert!(w.len() == 1 && w[0].contains("wave speed"), "{w:?}");
        // E typed in MPa: 2e5 Pa → c = 5 m/s; ρ in g/cm³: 7.85 → 1.6e5 m/s.
        for wrong in [
            MaterialSi {
                youngs: 2e5,
                ..steel
            },
            MaterialSi {
                density: 7.85,
                ..steel
            },
        ] {
            let w = plausibility_warnings(Some(0.3), 10.0, &wrong, None);
            assert!(w.len() == 1 && w[0].contains("wave speed"), "{w:?}");
        }
        // Rubber (E 1 MPa, ρ 1100 kg/m³: 30 m/s) and soft silicone (0.25 MPa: 15 m/s) are solids.
        for youngs in [1e6, 2.5e5] {
            let rubber = MaterialSi {
                youngs,
                poisson: 0.49,
                density: 1100.0,
            };
            assert!(plausibility_warnings(Some(0.3), 1.0, &rubber, None).is_empty());
        }
        assert!(plausibility_warnings(Some(0.3), 10.0, &steel, Some(2000.0)).is_empty());
    }
}
