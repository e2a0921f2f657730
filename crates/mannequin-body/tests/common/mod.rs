//! Test scaffolding shared by the body tests.

pub mod random_model;
