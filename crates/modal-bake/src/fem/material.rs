//! Isotropic linear-elastic material.

/// An isotropic, homogeneous linear-elastic material (SI units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Young's modulus E (Pa).
    pub youngs: f64,
    /// Poisson's ratio ν (dimensionless), −1 < ν < 0.5.
    pub poisson: f64,
    /// Mass density ρ (kg/m³).
    pub density: f64,
}

/// Why a [`Material`] was rejected.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MaterialError {
    /// Young's modulus must be finite and within [`Material::YOUNGS_RANGE`] (Pa).
    #[error("Young's modulus {0:e} Pa is outside the supported 1 … 1e14 Pa (foams ~1e5, polymers ~1e9, steel 2e11)")]
    Youngs(f64),
    /// Poisson's ratio must be finite with −1 < ν < 0.5.
    #[error("Poisson's ratio must satisfy -1 < nu < 0.5, got {0}")]
    Poisson(f64),
    /// Density must be finite and within [`Material::DENSITY_RANGE`] (kg/m³).
    #[error("density {0:e} kg/m³ is outside the supported 0.01 … 1e6 kg/m³ (aerogel ~2, wood ~700, steel 7850)")]
    Density(f64),
}

impl Material {
    /// A validated material: Young's modulus `youngs` (Pa), Poisson's ratio `poisson`, density
    /// `density` (kg/m³).
    ///
    /// # Errors
    /// [`MaterialError`] when a parameter is non-finite or out of its physical range.
    ///
    /// ```
    /// use modal_bake::fem::Material;
    /// let steel = Material::new(200e9, 0.3, 7850.0).unwrap();
    /// assert!(Material::new(1e9, 0.5, 1000.0).is_err());
    /// # let _ = steel;
    /// ```
    pub fn new(youngs: f64, poisson: f64, density: f64) -> Result<Self, MaterialError> {
        let m = Material {
            youngs,
            poisson,
            density,
        };
        m.validate()?;
        Ok(m)
    }

    /// Supported Young's modulus (Pa): softer than any foam to stiffer than diamond; outside,
    /// stiffness and eigenvalues leave the range the eigensolver's tolerances are set for.
    pub const YOUNGS_RANGE: [f64; 2] = [1.0, 1e14];

    /// Supported density (kg/m³): lighter than aerogel to denser than any element.
    pub const DENSITY_RANGE: [f64; 2] = [1e-2, 1e6];

    /// Checks E within [`Material::YOUNGS_RANGE`], −1 < ν < 0.5, ρ within
    /// [`Material::DENSITY_RANGE`], all finite.
    ///
    /// # Errors
    /// The first offending parameter as a [`MaterialError`].
    pub fn validate(&self) -> Result<(), MaterialError> {
        let within = |x: f64, [lo, hi]: [f64; 2]| x >= lo && x <= hi;
        if !within(self.youngs, Self::YOUNGS_RANGE) {
            return Err(MaterialError::Youngs(self.youngs));
        }
        if !(self.poisson.is_finite() && self.poisson > -1.0 && self.poisson < 0.5) {
            return Err(MaterialError::Poisson(self.poisson));
        }
        if !within(self.density, Self::DENSITY_RANGE) {
            return Err(MaterialError::Density(self.density));
        }
        Ok(())
    }

    /// Lamé parameters `(λ, μ)` in Pa: λ = Eν/((1+ν)(1−2ν)), μ = E/(2(1+ν)).
    pub fn lame(&self) -> (f64, f64) {
        let (e, nu) = (self.youngs, self.poisson);
        (
            e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
            e / (2.0 * (1.0 + nu)),
        )
    }

    /// Squared bar wave speed E/ρ (m²/s²): sets the frequency scale of the material.
    pub fn bar_speed_squared(&self) -> f64 {
        self.youngs / self.density
    }
}
