//! A validated garment ready to simulate: its vertices as particles with masses, and its stretch
//! and bending constraints, coloured for parallel projection.

use glam::Vec3;
use mannequin_mesh::TriMesh;

use crate::bending::BendingConstraints;
use crate::error::ClothError;
use crate::garment_check::check_garment;
use crate::material::Material;
use crate::stretch::StretchConstraints;
use crate::topology::topology;

#[derive(Debug, Clone, PartialEq)]
pub struct Cloth {
    pub(crate) rest: Vec<[f32; 3]>,
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
    /// vertices, and vertices no triangle uses, get inverse mass 0: they never move.
    pub fn new(mesh: &TriMesh, material: &Material, pins: &[u32]) -> Result<Cloth, ClothError> {
        material.validate()?;
        check_garment(mesh, pins)?;
        let topology = topology(&mesh.faces)?;
        let rest = mesh.positions.clone();
        let mut mass = vec![0.0f32; rest.len()];
        for &tri in &mesh.faces {
            let [a, b, c] = tri.map(|i| Vec3::from(rest[i as usize]));
            let third = (b - a).cross(c - a).length() / 6.0 * material.density;
            for i in tri {
                mass[i as usize] += third;
            }
        }
        let mut inverse_mass: Vec<f32> = mass.iter().map(|&m| if m > 0.0 { 1.0 / m } else { 0.0 }).collect();
        for &p in pins {
            inverse_mass[p as usize] = 0.0;
        }
        Ok(Cloth {
            stretch: StretchConstraints::new(&rest, &topology.edges, material.stretch_compliance),
            bending: BendingConstraints::new(&rest, &topology.hinges, material.bend_compliance),
            faces: mesh.faces.clone(),
            inverse_mass,
            rest,
            material: *material,
        })
    }

    pub fn particle_count(&self) -> usize {
        self.rest.len()
    }

    /// The positions the garment was built from: its rest shape.
    pub fn rest_positions(&self) -> &[[f32; 3]] {
        &self.rest
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
