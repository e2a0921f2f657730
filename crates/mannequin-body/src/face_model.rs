//! The default body's face model (thesis §2.3, Eq. 2.18, without a licence): a PCA shape basis
//! over the CC0 MakeHuman face targets and the 52 ARKit-named expression units of the CC0 Face
//! Units pack, both on the default body's own head, converted by `tools/default_body/face.py`
//! (see `assets/NOTICE`). A fitted face is the default body's head moved by
//! Σ αₖ Sₖ + Σ eⱼ Eⱼ, so it stays part of the body and animates with it.

use mannequin_io::Npz;

use crate::BodyModel;
use crate::error::BodyError;

static FACE: &[u8] = include_bytes!("../assets/default_face.npz");

/// Shape and expression offsets of the default body's head vertices.
#[derive(Debug, Clone)]
pub struct FaceModel {
    /// The head's vertices, as indices into the default body.
    pub vertices: Vec<usize>,
    /// [K, V, 3]: metres per unit coefficient (the coefficients are unit normal).
    pub shape_basis: Vec<f32>,
    /// The share of the sampled faces' variance each component explains, largest first.
    pub shape_variance: Vec<f32>,
    /// [52, V, 3]: metres at weight 1.
    pub expression_basis: Vec<f32>,
    pub expression_names: Vec<String>,
}

impl FaceModel {
    /// The embedded face model of the default body.
    pub fn default_face() -> Self {
        let npz = Npz::from_bytes("<embedded default_face.npz>".into(), FACE)
            .expect("the embedded face model is a valid npz");
        Self::parse(&npz).expect("the embedded face model is a valid face model")
    }

    fn parse(npz: &Npz) -> Result<Self, BodyError> {
        let wrong = |field: &str, what: &str| BodyError::Io(npz.field_error(field, what));
        let vertices: Vec<usize> = npz
            .require("vertices")?
            .to_i64()
            .ok_or_else(|| wrong("vertices", "integer vertex indices"))?
            .into_iter()
            .map(|v| usize::try_from(v).map_err(|_| wrong("vertices", "non-negative indices")))
            .collect::<Result<_, _>>()?;
        let v = vertices.len();
        let (shape, shape_basis) = npz.f64_with_shape("shape_basis", &[None, Some(v), Some(3)])?;
        let (_, variance) = npz.f64_with_shape("shape_variance", &[Some(shape[0])])?;
        let (_, expression_basis) = npz.f64_with_shape("expression_basis", &[None, Some(v), Some(3)])?;
        let names = match &npz.require("expression_names")?.data {
            mannequin_io::NpyData::Str(names) => names.clone(),
            _ => return Err(wrong("expression_names", "the expression units' names as strings")),
        };
        if names.len() * v * 3 != expression_basis.len() {
            return Err(wrong("expression_names", "one name per expression unit"));
        }
        let f32s = |x: Vec<f64>| x.into_iter().map(|v| v as f32).collect();
        Ok(Self {
            vertices,
            shape_basis: f32s(shape_basis),
            shape_variance: f32s(variance),
            expression_basis: f32s(expression_basis),
            expression_names: names,
        })
    }

    pub fn num_shape(&self) -> usize {
        self.shape_variance.len()
    }

    pub fn num_expressions(&self) -> usize {
        self.expression_names.len()
    }

    /// The body's triangles whose corners are all head vertices, in head-vertex indices (the
    /// order of `vertices`): the head as a mesh of its own.
    pub fn head_faces(&self, body: &BodyModel) -> Vec<[u32; 3]> {
        let mut slot = vec![None; body.num_vertices()];
        self.vertices.iter().enumerate().for_each(|(i, &v)| slot[v] = Some(i as u32));
        let at = |v: u32| slot.get(v as usize).copied().flatten();
        body.faces.iter().filter_map(|f| Some([at(f[0])?, at(f[1])?, at(f[2])?])).collect()
    }

    /// The expression unit called `name` (ARKit's names: `jawOpen`, `eyeBlinkLeft`, ...).
    pub fn expression(&self, name: &str) -> Option<usize> {
        self.expression_names.iter().position(|n| n == name)
    }

    /// Moves the head's vertices of `positions` (the default body's, posed or not) by shape
    /// coefficients `alpha` and expression weights `expression` (either may be shorter than
    /// the model's; missing ones are zero).
    pub fn apply(
        &self,
        positions: &mut [[f32; 3]],
        alpha: &[f32],
        expression: &[f32],
    ) -> Result<(), BodyError> {
        if alpha.len() > self.num_shape() || expression.len() > self.num_expressions() {
            return Err(BodyError::input(
                "face",
                format!(
                    "{} shape and {} expression coefficients; the model has {} and {}",
                    alpha.len(),
                    expression.len(),
                    self.num_shape(),
                    self.num_expressions()
                ),
            ));
        }
        if let Some(&last) = self.vertices.last()
            && last >= positions.len()
        {
            return Err(BodyError::input(
                "face",
                format!("a mesh of {} vertices; the face model needs the default body's", positions.len()),
            ));
        }
        let v = self.vertices.len();
        let blocks = [(&self.shape_basis, alpha), (&self.expression_basis, expression)];
        for (basis, weights) in blocks {
            for (k, &w) in weights.iter().enumerate().filter(|(_, w)| **w != 0.0) {
                let block = &basis[k * v * 3..(k + 1) * v * 3];
                for (i, &vertex) in self.vertices.iter().enumerate() {
                    (0..3).for_each(|c| positions[vertex][c] += w * block[3 * i + c]);
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A head vertex at rest and how far a unit moves it.
    type Move = ([f32; 3], [f32; 3]);

    /// Where the vertices a unit moves most sit (those moved over half its largest move), and
    /// their mean move.
    fn main_move(model: &FaceModel, name: &str, rest: &[[f32; 3]]) -> Move {
        let mut moved = rest.to_vec();
        let mut weights = vec![0.0; model.num_expressions()];
        weights[model.expression(name).unwrap()] = 1.0;
        model.apply(&mut moved, &[], &weights).unwrap();
        let d: Vec<Move> = model
            .vertices
            .iter()
            .map(|&v| (rest[v], std::array::from_fn(|c| moved[v][c] - rest[v][c])))
            .collect();
        let most = d.iter().map(|(_, o)| o.iter().map(|x| x * x).sum::<f32>()).fold(0.0, f32::max);
        let main: Vec<_> =
            d.iter().filter(|(_, o)| o.iter().map(|x| x * x).sum::<f32>() > 0.25 * most).collect();
        let mean = |f: &dyn Fn(&Move) -> [f32; 3]| -> [f32; 3] {
            std::array::from_fn(|c| main.iter().map(|p| f(p)[c]).sum::<f32>() / main.len() as f32)
        };
        (mean(&|p| p.0), mean(&|p| p.1))
    }

    #[test]
    fn expression_units_move_what_their_names_say() {
        let face = FaceModel::default_face();
        let body = BodyModel::default_body();
        assert_eq!(face.num_expressions(), 52);
        let rest = &body.v_template;
        // Axes: Y up, facing +Z, the subject's left at +X.
        let (at, by) = main_move(&face, "jawOpen", rest);
        assert!(by[1] < -0.01 && at[1] < 0.40, "jawOpen moves the chin down: {by:?} at {at:?}");
        for (side, sign) in [("Left", 1.0), ("Right", -1.0)] {
            let (at, by) = main_move(&face, &format!("eyeBlink{side}"), rest);
            assert!(
                sign * at[0] > 0.02 && by[1] < -0.003,
                "eyeBlink{side} closes that side's lid: {by:?} at {at:?}"
            );
            let (at, by) = main_move(&face, &format!("mouthSmile{side}"), rest);
            assert!(
                sign * at[0] > 0.01 && by[1] > 0.003 && sign * by[0] > 0.0,
                "mouthSmile{side}: {by:?} at {at:?}"
            );
        }
    }

    #[test]
    fn the_shape_basis_is_ordered_and_keeps_99_percent() {
        let face = FaceModel::default_face();
        let v = &face.shape_variance;
        assert!(v.windows(2).all(|w| w[0] >= w[1]), "components by variance");
        let kept: f32 = v.iter().sum();
        assert!((0.99..0.995).contains(&kept), "the components keep {kept} of the variance");
        // Every head vertex sits on the head and neck: above the collar bones' joints.
        let body = BodyModel::default_body();
        let joints = crate::forward(&body, &[], &[0.0; 72], &[0.0; 3]).unwrap().joints;
        let collar = joints[3 * crate::smpl_joint::L_COLLAR + 1];
        assert!(face.vertices.iter().all(|&i| body.v_template[i][1] > collar));
        let mut too_long = body.v_template.clone();
        assert!(face.apply(&mut too_long, &vec![1.0; face.num_shape() + 1], &[]).is_err());
    }
}
