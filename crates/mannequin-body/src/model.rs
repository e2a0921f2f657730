//! The body-model data: a linear blend-skinned template with shape and pose-corrective bases, in
//! the SMPL formulation (thesis §SMPL: T(β, θ) = T̄ + B_S(β) + B_P(θ), J(β) = 𝒥 T(β)).
//! SMPL, SMPL-H, SMPL-X and the embedded default body are all this one type; they differ only in
//! joint count and bases.

use std::collections::BTreeMap;

use mannequin_io::NpyArray;
use mannequin_mesh::{TriMesh, UvLayout};

use crate::error::BodyError;

/// Which member of the SMPL family a model file is, told by its joint count.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelFamily {
    /// 24 joints.
    Smpl,
    /// 52 joints: SMPL body plus 2 × 15 finger joints.
    SmplH,
    /// 55 joints: SMPL-H plus jaw and eyes.
    SmplX,
    /// Any other kinematic tree.
    Other(usize),
}

impl ModelFamily {
    pub fn from_joint_count(n: usize) -> Self {
        match n {
            24 => Self::Smpl,
            52 => Self::SmplH,
            55 => Self::SmplX,
            n => Self::Other(n),
        }
    }

    pub fn name(&self) -> String {
        match self {
            Self::Smpl => "SMPL".into(),
            Self::SmplH => "SMPL-H".into(),
            Self::SmplX => "SMPL-X".into(),
            Self::Other(n) => format!("custom ({n} joints)"),
        }
    }
}

/// A sparse row-major matrix (CSR), used for the joint regressor, which is mostly zeros.
#[derive(Debug, Clone, PartialEq)]
pub struct SparseRows {
    pub offsets: Vec<usize>,
    pub columns: Vec<u32>,
    pub values: Vec<f32>,
}

impl SparseRows {
    /// Keeps the non-zero entries of a dense row-major `rows × cols` matrix.
    pub fn from_dense(dense: &[f32], rows: usize, cols: usize) -> Self {
        let mut offsets = vec![0];
        let (mut columns, mut values) = (Vec::new(), Vec::new());
        for r in 0..rows {
            for (c, &v) in dense[r * cols..(r + 1) * cols].iter().enumerate() {
                if v != 0.0 {
                    columns.push(c as u32);
                    values.push(v);
                }
            }
            offsets.push(columns.len());
        }
        Self { offsets, columns, values }
    }

    pub fn rows(&self) -> usize {
        self.offsets.len() - 1
    }

    /// The (column, value) pairs of row `r`.
    pub fn row(&self, r: usize) -> impl Iterator<Item = (usize, f32)> + '_ {
        let span = self.offsets[r]..self.offsets[r + 1];
        self.columns[span.clone()].iter().map(|&c| c as usize).zip(self.values[span].iter().copied())
    }

    /// Row-major dense copy.
    pub fn to_dense(&self, cols: usize) -> Vec<f32> {
        let mut out = vec![0.0; self.rows() * cols];
        for r in 0..self.rows() {
            for (c, v) in self.row(r) {
                out[r * cols + c] = v;
            }
        }
        out
    }
}

/// Everything needed to build a [`BodyModel`]; validated by [`BodyModel::new`].
#[derive(Debug, Clone, Default)]
pub struct BodyModelParts {
    pub name: String,
    pub gender: String,
    pub v_template: Vec<[f32; 3]>,
    pub faces: Vec<[u32; 3]>,
    pub uv: Option<UvLayout>,
    /// Shape basis, component-major: `shapedirs[k * 3V + 3v + c]`.
    pub shapedirs: Vec<f32>,
    pub num_betas: usize,
    /// Trailing shape components that are facial expressions (SMPL-X), after the betas.
    pub num_expression: usize,
    /// Pose-corrective basis, feature-major: `posedirs[p * 3V + 3v + c]`, with 9 (J − 1) features
    /// (or none).
    pub posedirs: Vec<f32>,
    /// Joint regressor, J × V, row-major dense.
    pub j_regressor: Vec<f32>,
    pub parents: Vec<Option<usize>>,
    /// Skinning weights, V × J, row-major.
    pub weights: Vec<f32>,
    pub joint_names: Vec<String>,
    pub shape_names: Vec<String>,
    /// Arrays of the model file that the forward pass does not use (SMPL-X landmarks, hand PCA).
    pub extras: BTreeMap<String, NpyArray>,
}

/// A validated SMPL-family body model.
#[derive(Debug, Clone)]
pub struct BodyModel {
    pub name: String,
    pub family: ModelFamily,
    pub gender: String,
    pub v_template: Vec<[f32; 3]>,
    pub faces: Vec<[u32; 3]>,
    pub uv: Option<UvLayout>,
    shapedirs: Vec<f32>,
    num_betas: usize,
    num_expression: usize,
    posedirs: Vec<f32>,
    j_regressor: SparseRows,
    parents: Vec<Option<usize>>,
    weights: Vec<f32>,
    skin: SparseRows,
    pub joint_names: Vec<String>,
    pub shape_names: Vec<String>,
    pub extras: BTreeMap<String, NpyArray>,
}

/// Weight rows must sum to one within this tolerance: LBS is only affine-invariant then.
const WEIGHT_SUM_TOLERANCE: f32 = 1e-3;

fn bad(name: &str, field: &str, reason: String) -> BodyError {
    BodyError::field(name, field, reason)
}

impl BodyModel {
    /// Checks sizes, indices, finiteness, the kinematic order and the weight sums.
    pub fn new(p: BodyModelParts) -> Result<Self, BodyError> {
        let n = &p.name;
        let v = p.v_template.len();
        let j = p.parents.len();
        if v == 0 {
            return Err(bad(n, "v_template", "expected at least one vertex".into()));
        }
        if j == 0 {
            return Err(bad(n, "kintree_table", "expected at least one joint".into()));
        }
        let mesh = TriMesh::new(p.v_template.clone(), p.faces.clone());
        mesh.validate().map_err(|e| bad(n, "f", e.to_string()))?;
        for (k, parent) in p.parents.iter().enumerate() {
            match parent {
                None if k != 0 => {
                    return Err(bad(
                        n,
                        "kintree_table",
                        format!("joint {k} has no parent; only joint 0 may be the root"),
                    ));
                }
                Some(_) if k == 0 => {
                    return Err(bad(n, "kintree_table", "joint 0 must be the root".into()));
                }
                Some(q) if *q >= k => {
                    return Err(bad(
                        n,
                        "kintree_table",
                        format!("joint {k} has parent {q}; parents must come first"),
                    ));
                }
                _ => {}
            }
        }
        let shape_len = p.num_betas + p.num_expression;
        if p.shapedirs.len() != shape_len * 3 * v {
            return Err(bad(
                n,
                "shapedirs",
                format!("expected {shape_len} components of {v}×3, found {} values", p.shapedirs.len()),
            ));
        }
        let pose_features = 9 * (j - 1);
        if !p.posedirs.is_empty() && p.posedirs.len() != pose_features * 3 * v {
            return Err(bad(
                n,
                "posedirs",
                format!(
                    "expected ({v}, 3, {pose_features}) or an empty basis, found {} values",
                    p.posedirs.len()
                ),
            ));
        }
        if p.j_regressor.len() != j * v {
            return Err(bad(
                n,
                "J_regressor",
                format!("expected shape ({j}, {v}), found {} values", p.j_regressor.len()),
            ));
        }
        if p.weights.len() != v * j {
            return Err(bad(
                n,
                "weights",
                format!("expected shape ({v}, {j}), found {} values", p.weights.len()),
            ));
        }
        for (field, values) in [
            ("shapedirs", &p.shapedirs),
            ("posedirs", &p.posedirs),
            ("J_regressor", &p.j_regressor),
            ("weights", &p.weights),
        ] {
            if let Some(i) = values.iter().position(|x| !x.is_finite()) {
                return Err(bad(n, field, format!("value {i} is not finite")));
            }
        }
        for (vi, row) in p.weights.chunks_exact(j).enumerate() {
            let sum: f32 = row.iter().sum();
            if (sum - 1.0).abs() > WEIGHT_SUM_TOLERANCE {
                return Err(bad(n, "weights", format!("row of vertex {vi} sums to {sum}, expected 1")));
            }
        }
        let joint_names = if p.joint_names.len() == j {
            p.joint_names
        } else {
            (0..j).map(|k| format!("joint_{k}")).collect()
        };
        let shape_names = if p.shape_names.len() == shape_len {
            p.shape_names
        } else {
            (0..shape_len).map(|k| format!("beta_{k}")).collect()
        };
        Ok(Self {
            family: ModelFamily::from_joint_count(j),
            j_regressor: SparseRows::from_dense(&p.j_regressor, j, v),
            skin: SparseRows::from_dense(&p.weights, v, j),
            name: p.name,
            gender: p.gender,
            v_template: p.v_template,
            faces: p.faces,
            uv: p.uv,
            shapedirs: p.shapedirs,
            num_betas: p.num_betas,
            num_expression: p.num_expression,
            posedirs: p.posedirs,
            parents: p.parents,
            weights: p.weights,
            joint_names,
            shape_names,
            extras: p.extras,
        })
    }

    pub fn num_vertices(&self) -> usize {
        self.v_template.len()
    }

    pub fn num_joints(&self) -> usize {
        self.parents.len()
    }

    /// Shape coefficients the file holds for body shape (β).
    pub fn num_betas(&self) -> usize {
        self.num_betas
    }

    /// Expression coefficients (SMPL-X), stored after the betas in the shape vector.
    pub fn num_expression(&self) -> usize {
        self.num_expression
    }

    /// Length of the full shape vector: betas then expressions.
    pub fn num_shape_coeffs(&self) -> usize {
        self.num_betas + self.num_expression
    }

    /// Length of an axis-angle pose vector: 3 per joint.
    pub fn pose_len(&self) -> usize {
        3 * self.num_joints()
    }

    /// Number of pose-corrective features (0 when the model has none).
    pub fn num_pose_features(&self) -> usize {
        if self.posedirs.is_empty() { 0 } else { 9 * (self.num_joints() - 1) }
    }

    pub fn parents(&self) -> &[Option<usize>] {
        &self.parents
    }

    /// Shape basis, component-major (`[k][3V]`).
    pub fn shapedirs(&self) -> &[f32] {
        &self.shapedirs
    }

    /// Pose-corrective basis, feature-major (`[p][3V]`); empty when the model has none.
    pub fn posedirs(&self) -> &[f32] {
        &self.posedirs
    }

    pub fn j_regressor(&self) -> &SparseRows {
        &self.j_regressor
    }

    /// Dense skinning weights, V × J row-major.
    pub fn weights(&self) -> &[f32] {
        &self.weights
    }

    /// Skinning weights as sparse per-vertex rows (the non-zero joints of each vertex).
    pub fn skin(&self) -> &SparseRows {
        &self.skin
    }

    /// Keeps only the first `n` betas (expressions stay), for files that hold more than a user
    /// wants to fit.
    pub fn with_num_betas(mut self, n: usize) -> Result<Self, BodyError> {
        if n > self.num_betas {
            return Err(bad(
                &self.name,
                "shapedirs",
                format!("{n} betas requested but the model has {}", self.num_betas),
            ));
        }
        let len = 3 * self.num_vertices();
        self.shapedirs.drain(n * len..self.num_betas * len);
        self.shape_names.drain(n..self.num_betas);
        self.num_betas = n;
        Ok(self)
    }

    /// The rest template as a mesh (with UVs when the model has them).
    pub fn template_mesh(&self) -> TriMesh {
        let mut mesh = TriMesh::new(self.v_template.clone(), self.faces.clone());
        mesh.uv = self.uv.clone();
        mesh
    }
}
