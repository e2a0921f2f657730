//! Per-split SMPL parameters, `poses/anim_nerf_{split}.npz`: `betas (1,10)`, `global_orient (N,3)`,
//! `body_pose (N,69)`, `transl (N,3)` (float32), as Anim-NeRF and InstantAvatar store them.

use std::path::Path;

use mannequin_io::limits::{MAX_BETA, MAX_DISTANCE};
use mannequin_io::{NpyArray, Npz, NpzWriter};

use crate::error::DataError;

/// Body-pose parameters per joint after the root: 23 joints × 3.
pub const BODY_POSE_LEN: usize = 69;

#[derive(Debug, Clone, PartialEq)]
pub struct Poses {
    pub betas: Vec<f32>,
    pub global_orient: Vec<[f32; 3]>,
    /// N × 69, row-major.
    pub body_pose: Vec<f32>,
    pub transl: Vec<[f32; 3]>,
}

fn triples(v: Vec<f64>) -> Vec<[f32; 3]> {
    v.chunks_exact(3).map(|c| [c[0] as f32, c[1] as f32, c[2] as f32]).collect()
}

impl Poses {
    pub fn len(&self) -> usize {
        self.transl.len()
    }

    pub fn is_empty(&self) -> bool {
        self.transl.is_empty()
    }

    /// SMPL's 72-vector of frame `i`: global orientation first, then the body pose.
    pub fn pose72(&self, i: usize) -> Vec<f32> {
        let mut p = self.global_orient[i].to_vec();
        p.extend_from_slice(&self.body_pose[i * BODY_POSE_LEN..(i + 1) * BODY_POSE_LEN]);
        p
    }

    /// Frames `frames` of `self`, in that order.
    pub fn select(&self, frames: &[usize]) -> Self {
        Self {
            betas: self.betas.clone(),
            global_orient: frames.iter().map(|&f| self.global_orient[f]).collect(),
            body_pose: frames
                .iter()
                .flat_map(|&f| self.body_pose[f * BODY_POSE_LEN..(f + 1) * BODY_POSE_LEN].iter().copied())
                .collect(),
            transl: frames.iter().map(|&f| self.transl[f]).collect(),
        }
    }

    /// `other`'s frames after `self`'s (the shape stays `self`'s): splits joined back into a clip.
    pub fn append(&mut self, other: &Self) {
        self.global_orient.extend_from_slice(&other.global_orient);
        self.body_pose.extend_from_slice(&other.body_pose);
        self.transl.extend_from_slice(&other.transl);
    }

    /// Reads the arrays, also accepting `thetas (N,72)` in place of `global_orient` + `body_pose`.
    pub fn read(path: &Path) -> Result<Self, DataError> {
        let npz = Npz::read(path)?;
        let (_, transl) = npz.f64_in_range("transl", &[None, Some(3)], -MAX_DISTANCE..=MAX_DISTANCE)?;
        let n = transl.len() / 3;
        let betas = match npz.require("betas")?.shape.len() {
            1 => npz.f64_in_range("betas", &[None], -MAX_BETA..=MAX_BETA)?.1,
            _ => npz.f64_in_range("betas", &[Some(1), None], -MAX_BETA..=MAX_BETA)?.1,
        };
        let (global_orient, body_pose) = if npz.contains("thetas") {
            let (_, t) = npz.finite_f64_with_shape("thetas", &[Some(n), Some(72)])?;
            let go = t.chunks_exact(72).flat_map(|r| r[..3].to_vec()).collect();
            let bp = t.chunks_exact(72).flat_map(|r| r[3..].to_vec()).collect();
            (go, bp)
        } else {
            (
                npz.finite_f64_with_shape("global_orient", &[Some(n), Some(3)])?.1,
                npz.finite_f64_with_shape("body_pose", &[Some(n), Some(BODY_POSE_LEN)])?.1,
            )
        };
        Ok(Self {
            betas: betas.into_iter().map(|b| b as f32).collect(),
            global_orient: triples(global_orient),
            body_pose: body_pose.into_iter().map(|b| b as f32).collect(),
            transl: triples(transl),
        })
    }

    pub fn write(&self, path: &Path) -> Result<(), DataError> {
        let n = self.len();
        if self.global_orient.len() != n || self.body_pose.len() != n * BODY_POSE_LEN {
            return Err(DataError::file(
                path,
                format!(
                    "inconsistent poses: {n} translations, {} orientations, {} body-pose values",
                    self.global_orient.len(),
                    self.body_pose.len()
                ),
            ));
        }
        let flat = |v: &[[f32; 3]]| v.iter().flatten().copied().collect::<Vec<f32>>();
        let mut w = NpzWriter::new();
        w.add("betas", NpyArray::f32(vec![1, self.betas.len()], self.betas.clone()));
        w.add("global_orient", NpyArray::f32(vec![n, 3], flat(&self.global_orient)));
        w.add("body_pose", NpyArray::f32(vec![n, BODY_POSE_LEN], self.body_pose.clone()));
        w.add("transl", NpyArray::f32(vec![n, 3], flat(&self.transl)));
        Ok(w.write(path)?)
    }
}
