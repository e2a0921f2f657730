//! XPBD cloth (thesis §3.3): a garment mesh's vertices as particles, held by stretch and dihedral
//! bending constraints, kept off itself and off an animated body.
