//! One garment being worn in a dressing: what the outputs call it, its template, the cloth it is
//! made of, and its transfer to the body.

use mannequin_cloth::Material;

use crate::garment::Garment;
use crate::transfer::Dressed;

/// One garment being worn: its name in the outputs, template, material and transfer to the body.
pub struct Worn<'a> {
    pub name: String,
    pub garment: &'a Garment,
    pub material: Material,
    pub dressed: Dressed<'a>,
}
