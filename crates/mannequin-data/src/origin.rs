//! Where a dataset's poses came from, recorded in `origin.json`: a synthetic subject's are the
//! truth, `capture`'s are estimates from the images. Training refines estimated poses and
//! evaluation fits estimated test poses (issue 36); poses that are the truth are used as they are.

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::DataError;
use crate::layout;

/// How a dataset's poses and cameras were obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PoseOrigin {
    /// Ground truth: the poses rendered the images (`mannequin synth`).
    Truth,
    /// Estimated from the images themselves (`mannequin capture`).
    Estimated,
}

/// The contents of `origin.json`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Origin {
    pub poses: PoseOrigin,
    /// The program that wrote the dataset, for people.
    pub by: String,
}

impl Origin {
    /// Reads `root/origin.json`; `None` where a dataset has none (PeopleSnapshot and other
    /// datasets prepared elsewhere).
    pub fn read(root: &Path) -> Result<Option<Self>, DataError> {
        let path = root.join(layout::ORIGIN);
        if !path.exists() {
            return Ok(None);
        }
        let text = std::fs::read_to_string(&path).map_err(|e| DataError::os(&path, e))?;
        serde_json::from_str(&text).map(Some).map_err(|e| {
            DataError::file(
                &path,
                format!("{e}: expected {{\"poses\": \"truth\" or \"estimated\", \"by\": \"...\"}}"),
            )
        })
    }

    pub fn write(&self, root: &Path) -> Result<(), DataError> {
        let path = root.join(layout::ORIGIN);
        let text = serde_json::to_string_pretty(self).expect("an origin serialises");
        mannequin_io::write_atomic(&path, text.as_bytes()).map_err(|e| DataError::os(&path, e))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_origin_reads_back_and_a_wrong_one_names_the_file() {
        let dir = std::env::temp_dir().join(format!("mq-origin-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        assert_eq!(Origin::read(&dir).unwrap(), None);
        let origin = Origin { poses: PoseOrigin::Estimated, by: "mannequin capture".into() };
        origin.write(&dir).unwrap();
        assert_eq!(Origin::read(&dir).unwrap(), Some(origin));
        std::fs::write(dir.join(layout::ORIGIN), r#"{"poses": "guessed", "by": "x"}"#).unwrap();
        let e = Origin::read(&dir).unwrap_err().to_string();
        assert!(e.contains("origin.json") && e.contains("guessed") && e.contains("estimated"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
