//! The embedded default body: a SMPL-compatible model converted from the CC0 MakeHuman assets by
//! `tools/default_body/convert.py` (see `assets/NOTICE`). Shipping it means nothing needs a licence.

use std::path::Path;

use mannequin_io::Npz;

use crate::error::BodyError;
use crate::model::BodyModel;
use crate::smpl_npz::{load_model, parse_model};

static FULL: &[u8] = include_bytes!("../assets/default_body.npz");
static LOD1: &[u8] = include_bytes!("../assets/default_body_lod1.npz");

/// Names accepted by [`BodyModel::from_spec`] for the embedded levels.
pub const DEFAULT_SPECS: [&str; 2] = ["default", "default-lod1"];

fn embedded(name: &str, bytes: &[u8]) -> BodyModel {
    let npz = Npz::from_bytes(format!("<embedded {name}>").into(), bytes)
        .expect("the embedded default body is a valid npz");
    parse_model(&npz, None).expect("the embedded default body is a valid model")
}

impl BodyModel {
    /// The full-resolution default body.
    pub fn default_body() -> Self {
        embedded("default_body.npz", FULL)
    }

    /// The decimated default body (about 1k vertices), for fast tests and previews.
    pub fn default_body_lod1() -> Self {
        embedded("default_body_lod1.npz", LOD1)
    }

    /// `default`, `default-lod1`, or the path of a SMPL-family `.npz` or `.pkl` file.
    pub fn from_spec(spec: &str, num_betas: Option<usize>) -> Result<Self, BodyError> {
        let model = match spec {
            "default" => Self::default_body(),
            "default-lod1" => Self::default_body_lod1(),
            path => return load_model(Path::new(path), num_betas),
        };
        match num_betas {
            Some(n) => model.with_num_betas(n),
            None => Ok(model),
        }
    }
}
