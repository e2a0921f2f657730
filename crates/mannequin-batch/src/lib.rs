//! Many people, each an independent array task of the CLI that exists, on the engines clusters
//! already run (a Slurm job array, a Kubernetes Indexed Job) or on this machine: a manifest
//! checked whole ([`manifest`]), a run folder ([`planner`]), one person's resumable steps
//! ([`task`]), the array run here ([`local`]), and what the tasks left ([`report`]). No
//! scheduler of its own.

mod csv;
mod kubernetes;
pub mod local;
mod manifest;
mod person;
pub mod plan;
pub mod planner;
pub mod report;
mod resources;
mod slurm;
mod state;
mod step;
pub mod task;

pub use plan::Engine;
pub use planner::PlanRequest;
