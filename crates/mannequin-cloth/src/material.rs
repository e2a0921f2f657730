//! Named fabrics. Units: density kg/m²; stretch compliance m/N (the XPBD α of an edge's length
//! constraint, the inverse of its spring stiffness; for a triangle mesh an edge's stiffness is about
//! the fabric's tensile stiffness in N/m, whatever the edge length); bending compliance 1/(N·m) (the
//! inverse of the bending rigidity B, scaled per hinge by its shape, see [`crate::bending`]);
//! friction a Coulomb coefficient against the body; damping 1/s (velocity decays as e^(−damping·t)).
//!
//! Bending rigidities come from KES-type measurements, quoted in gf·cm²/cm, where
//! 1 gf·cm²/cm ≈ 9.8e-5 N·m. Damping stands in for air drag: linearised drag at 1 m/s,
//! ½·ρ_air·C_d ≈ 0.7 N·s/m³, divided by the areal density and halved, since air resists only
//! the motion across the sheet.
//!
//! A material is named once, where it is read (a command-line flag, a run record), and travels as
//! this type from there.

use std::str::FromStr;

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::error::ClothError;

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    pub name: &'static str,
    pub density: f32,
    pub stretch_compliance: f32,
    pub bend_compliance: f32,
    pub friction: f32,
    pub damping: f32,
    pub strain_limit: f32,
}

pub const MATERIAL_NAMES: [&str; 5] = ["cotton", "denim", "silk", "jersey", "leather"];

/// Every named fabric, in the order of [`MATERIAL_NAMES`].
static MATERIALS: [Material; 5] = [COTTON, DENIM, SILK, JERSEY, LEATHER];

/// Cotton shirting: ~150 g/m²; woven, tensile stiffness ~2000 N/m; bending ~0.05 gf·cm²/cm
/// (5e-6 N·m); cotton on skin μ ≈ 0.5.
const COTTON: Material = Material {
    name: "cotton",
    density: 0.15,
    stretch_compliance: 5e-4,
    bend_compliance: 2e5,
    friction: 0.5,
    damping: 2.4,
    strain_limit: 0.05,
};

/// Denim: ~400 g/m² (12 oz/yd²); stiff twill, ~5000 N/m; bending ~0.5 gf·cm²/cm (5e-5 N·m);
/// μ ≈ 0.6.
const DENIM: Material = Material {
    name: "denim",
    density: 0.4,
    stretch_compliance: 2e-4,
    bend_compliance: 2e4,
    friction: 0.6,
    damping: 0.9,
    strain_limit: 0.03,
};

/// Silk charmeuse: ~80 g/m²; ~1000 N/m; bending ~0.01 gf·cm²/cm (1e-6 N·m); slippery, μ ≈ 0.25.
const SILK: Material = Material {
    name: "silk",
    density: 0.08,
    stretch_compliance: 1e-3,
    bend_compliance: 1e6,
    friction: 0.25,
    damping: 4.5,
    strain_limit: 0.05,
};

/// Cotton jersey (a knit): ~180 g/m²; knits stretch easily, ~100 N/m; bending ~0.02 gf·cm²/cm
/// (2e-6 N·m); μ ≈ 0.5.
const JERSEY: Material = Material {
    name: "jersey",
    density: 0.18,
    stretch_compliance: 1e-2,
    bend_compliance: 5e5,
    friction: 0.5,
    damping: 2.0,
    strain_limit: 0.25,
};

/// Garment leather, ~1 mm: ~800 g/m²; E ≈ 20 MPa gives ~2e4 N/m; a plate's B = E·t³/12 with
/// E ≈ 6 MPa for soft lamb leather gives ~5e-4 N·m; μ ≈ 0.4.
const LEATHER: Material = Material {
    name: "leather",
    density: 0.8,
    stretch_compliance: 5e-5,
    bend_compliance: 2e3,
    friction: 0.4,
    damping: 0.45,
    strain_limit: 0.08,
};

impl Material {
    pub const COTTON: Material = COTTON;
    pub const DENIM: Material = DENIM;
    pub const SILK: Material = SILK;
    pub const JERSEY: Material = JERSEY;
    pub const LEATHER: Material = LEATHER;

    /// The fabric called `name` (one of [`MATERIAL_NAMES`]).
    pub fn named(name: &str) -> Result<Material, ClothError> {
        MATERIALS.into_iter().find(|m| m.name == name).ok_or_else(|| ClothError::UnknownMaterial {
            name: name.to_string(),
            known: MATERIAL_NAMES.join(", "),
        })
    }

    /// Refuses negative or non-finite parameters, and a zero density (a particle needs mass).
    pub fn validate(&self) -> Result<(), ClothError> {
        let fields = [
            ("density", self.density),
            ("stretch_compliance", self.stretch_compliance),
            ("bend_compliance", self.bend_compliance),
            ("friction", self.friction),
            ("damping", self.damping),
            ("strain_limit", self.strain_limit),
        ];
        for (field, value) in fields {
            if !(value.is_finite() && value >= 0.0) {
                return Err(ClothError::invalid(
                    format!("material.{field}"),
                    format!("{value} is not a finite non-negative number"),
                ));
            }
        }
        if self.density == 0.0 {
            return Err(ClothError::invalid("material.density", "must be positive"));
        }
        Ok(())
    }
}

impl Default for Material {
    fn default() -> Self {
        COTTON
    }
}

impl FromStr for Material {
    type Err = ClothError;

    fn from_str(name: &str) -> Result<Self, ClothError> {
        Material::named(name)
    }
}

impl std::fmt::Display for Material {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name)
    }
}

/// `--material <name>`: one of the named fabrics, refused by clap listing them.
impl clap::ValueEnum for Material {
    fn value_variants<'a>() -> &'a [Self] {
        &MATERIALS
    }

    fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
        Some(clap::builder::PossibleValue::new(self.name))
    }
}

/// A material is stored by its name.
impl Serialize for Material {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.name)
    }
}

impl<'de> Deserialize<'de> for Material {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let name = String::deserialize(deserializer)?;
        Material::named(&name).map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_name_is_a_valid_material() {
        for name in MATERIAL_NAMES {
            let m = Material::named(name).unwrap();
            assert_eq!(m.name, name);
            m.validate().unwrap();
        }
    }

    #[test]
    fn a_material_is_parsed_and_stored_by_its_name() {
        let denim: Material = "denim".parse().unwrap();
        assert_eq!(denim, Material::named("denim").unwrap());
        assert_eq!(serde_json::to_string(&denim).unwrap(), "\"denim\"");
        assert_eq!(serde_json::from_str::<Material>("\"denim\"").unwrap(), denim);
        assert!(serde_json::from_str::<Material>("\"tweed\"").unwrap_err().to_string().contains("tweed"));
    }

    #[test]
    fn unknown_names_list_the_known_ones() {
        let e = Material::named("tweed").unwrap_err().to_string();
        assert!(e.contains("tweed") && e.contains("cotton, denim, silk, jersey, leather"), "{e}");
    }
}
