//! A validated garment ready to simulate: its vertices as particles with masses, and its stretch
//! and bending constraints, coloured for parallel projection.

use mannequin_mesh::{TriMesh, UvLayout};

use crate::bending::BendingConstraints;
use crate::error::ClothError;
use crate::garment_check::{check_pins, checked_constraint_graph};
use crate::material::Material;
use crate::rest_shape::RestShape;
use crate::stretch::StretchConstraints;

#[derive(Debug, Clone, PartialEq)]
pub struct Cloth {
    /// Where the simulation starts.
    pub(crate) start: Vec<[f32; 3]>,
    pub(crate) faces: Vec<[u32; 3]>,
    pub(crate) inverse_mass: Vec<f32>,
    pub(crate) stretch: StretchConstraints,
    pub(crate) bending: BendingConstraints,
    pub(crate) material: Material,
}

impl Cloth {
    /// The garment `mesh` (its positions are the rest shape and the start of the simulation) in
    /// `material`, with the vertices `pins` held in place.
    ///
    /// Each triangle gives a third of its mass (area × density) to each of its vertices. Pinned
    /// vertices get inverse mass 0: they never move.
    pub fn new(mesh: &TriMesh, material: &Material, pins: &[u32]) -> Result<Cloth, ClothError> {
        Self::resting(mesh, RestShape::of_mesh(mesh), material, pins)
    }

    /// The garment sewn from the flat `pattern` (per face of `mesh`, its corners on their panel,
    /// in metres) and placed as `mesh`: it starts there and pulls back to the pattern's shape.
    pub fn sewn(
        mesh: &TriMesh,
        pattern: &UvLayout,
        material: &Material,
        pins: &[u32],
    ) -> Result<Cloth, ClothError> {
        Self::resting(mesh, RestShape::of_pattern(mesh, pattern)?, material, pins)
    }

    fn resting(
        mesh: &TriMesh,
        rest: RestShape,
        material: &Material,
        pins: &[u32],
    ) -> Result<Cloth, ClothError> {
        material.validate()?;
        let graph = checked_constraint_graph(mesh)?;
        check_pins(pins, mesh.positions.len())?;
        let n = mesh.positions.len();
        let mass = rest.masses(&mesh.faces, n, material.density);
        let mut inverse_mass: Vec<f32> = mass.iter().map(|&m| if m > 0.0 { 1.0 / m } else { 0.0 }).collect();
        for &p in pins {
            inverse_mass[p as usize] = 0.0;
        }
        let lengths = rest.edge_lengths(&mesh.faces, &graph);
        let hinges = rest.hinges(&mesh.faces, &graph);
        Ok(Cloth {
            stretch: StretchConstraints::new(&graph.edges, &lengths, n, material.stretch_compliance),
            bending: BendingConstraints::new(&graph.hinges, &hinges, n, material.bend_compliance),
            faces: mesh.faces.clone(),
            inverse_mass,
            start: mesh.positions.clone(),
            material: *material,
        })
    }

    pub fn particle_count(&self) -> usize {
        self.start.len()
    }

    pub fn faces(&self) -> &[[u32; 3]] {
        &self.faces
    }

    /// Every edge once (the stretch constraints), in the solver's order.
    pub fn edges(&self) -> Vec<[u32; 2]> {
        self.stretch.edges.iter().map(|&(e, _)| e).collect()
    }

    /// Inverse masses in 1/kg: 0 for pinned vertices and for vertices no triangle uses.
    pub fn inverse_masses(&self) -> &[f32] {
        &self.inverse_mass
    }

    pub fn material(&self) -> &Material {
        &self.material
    }
}
