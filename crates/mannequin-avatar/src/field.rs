//! A neural field over fixed canonical points: multi-resolution hash encoding followed by an MLP
//! with two hidden ReLU layers (Tavatar's E_s, iHuman's displacement and colour encoders).
//! The points never move, so their grid lookups are computed once.

use burn::tensor::{DType, Device, Tensor};
use mannequin_io::rng::SplitMix64;

use crate::config::AvatarConfig;
use crate::error::AvatarError;
use crate::hash_grid::{Aabb, DeviceLookup, HashGridLookup, encode, init_table};
use crate::mlp::Mlp;
use crate::params::Param;

/// Margin around the points' bounding box, so offsets near the extremes stay inside the grid.
const BOX_MARGIN: f32 = 0.05;

#[derive(Clone, Debug)]
pub struct Field {
    lookup: DeviceLookup,
    table: usize,
    mlp: Mlp,
}

impl Field {
    /// Appends the table `{name}/table` and the MLP `{name}/mlp/*` to `params`.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        name: &str,
        config: &AvatarConfig,
        points: &[[f32; 3]],
        outputs: usize,
        lr: f64,
        rng: &mut SplitMix64,
        device: &Device,
        params: &mut Vec<Param>,
    ) -> Result<Self, AvatarError> {
        let grid = config.hash_grid();
        let grid_error =
            |e: crate::hash_grid::HashGridError| AvatarError::Invalid(format!("{name} field: {e}"));
        let aabb = Aabb::enclosing(points, BOX_MARGIN).map_err(grid_error)?;
        let lookup = HashGridLookup::new(&grid, &aabb, points).map_err(grid_error)?;
        let lookup = lookup.to_device(device, DType::F32).map_err(grid_error)?;
        params.push(Param::new(&format!("{name}/table"), init_table(&grid, rng.next_u64(), device), lr));
        let table = params.len() - 1;
        let widths = [grid.output_dim(), config.hidden, config.hidden, outputs];
        let mlp = Mlp::new(&format!("{name}/mlp"), &widths, lr, rng, device, params);
        Ok(Self { lookup, table, mlp })
    }

    /// The field at its points, [N, outputs].
    pub fn forward(&self, params: &[Param]) -> Result<Tensor<2>, AvatarError> {
        let features = encode(&self.lookup, params[self.table].value.clone())?;
        Ok(self.mlp.forward(params, features))
    }
}
