//! The 24 SMPL joint indices, named, so poses and garments say which joint they mean.

pub const PELVIS: usize = 0;
pub const L_HIP: usize = 1;
pub const R_HIP: usize = 2;
pub const SPINE1: usize = 3;
pub const L_KNEE: usize = 4;
pub const R_KNEE: usize = 5;
pub const SPINE2: usize = 6;
pub const L_ANKLE: usize = 7;
pub const R_ANKLE: usize = 8;
pub const SPINE3: usize = 9;
pub const L_FOOT: usize = 10;
pub const R_FOOT: usize = 11;
pub const NECK: usize = 12;
pub const L_COLLAR: usize = 13;
pub const R_COLLAR: usize = 14;
pub const HEAD: usize = 15;
pub const L_SHOULDER: usize = 16;
pub const R_SHOULDER: usize = 17;
pub const L_ELBOW: usize = 18;
pub const R_ELBOW: usize = 19;
pub const L_WRIST: usize = 20;
pub const R_WRIST: usize = 21;
pub const L_HAND: usize = 22;
pub const R_HAND: usize = 23;
