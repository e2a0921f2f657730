//! What a person's pixel can show, before the garments are named: skin, hair, shoes, and the
//! garment worn on the upper and on the lower body (one dress is both, decided later).

/// The classes a pixel of the person is labelled with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Class {
    Skin,
    Hair,
    Shoes,
    Upper,
    Lower,
}

/// How many classes there are.
pub const CLASSES: usize = 5;

impl Class {
    pub const ALL: [Class; CLASSES] = [Class::Skin, Class::Hair, Class::Shoes, Class::Upper, Class::Lower];

    pub fn index(self) -> usize {
        self as usize
    }

    pub fn name(self) -> &'static str {
        match self {
            Class::Skin => "skin",
            Class::Hair => "hair",
            Class::Shoes => "shoes",
            Class::Upper => "upper",
            Class::Lower => "lower",
        }
    }
}

/// A score per class.
pub type Scores = [f32; CLASSES];
