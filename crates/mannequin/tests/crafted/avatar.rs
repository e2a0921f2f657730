//! Crafted bad input for the avatar area (filled in by its owner).

use std::path::Path;

use super::{Case, Fixtures};

pub fn cases(_fx: \&Fixtures, _dir: \&Path) -> Vec<Case> {
    Vec::new()
}
