//! A body model named the way a user names one (`default`, `default-lod1` or a model file), with
//! an error that says which one failed to load.

use crate::error::BodyError;
use crate::model::BodyModel;

/// A body model that could not be loaded, with the name it was asked for.
#[derive(Debug, thiserror::Error)]
#[error("loading body model '{spec}'")]
pub struct LoadBodyError {
    pub spec: String,
    #[source]
    pub source: BodyError,
}

/// The body model `spec` names ([`BodyModel::from_spec`]), at its own number of shape components.
pub fn load_body(spec: &str) -> Result<BodyModel, LoadBodyError> {
    BodyModel::from_spec(spec, None).map_err(|source| LoadBodyError { spec: spec.to_string(), source })
}
