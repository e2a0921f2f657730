//! Table initialisation as in instant-ngp: every entry uniform in [-10⁻⁴, 10⁻⁴], so the encoding
//! starts near zero and the MLP behind it starts from a near-constant input.

use burn::tensor::{DType, Device, Tensor, TensorData};
use mannequin_io::rng::SplitMix64;

use super::HashGridConfig;

/// Half-width of instant-ngp's uniform initialisation.
pub const INIT_SCALE: f64 = 1e-4;

/// A `[L·T, F]` f32 table drawn from SplitMix64 seeded with `seed`, in row-major order: the same
/// seed gives the same bits on every machine.
pub fn init_table(config: &HashGridConfig, seed: u64, device: &Device) -> Tensor<2> {
    let shape = [config.table_rows(), config.features_per_level];
    let mut rng = SplitMix64::new(seed);
    let values: Vec<f32> =
        (0..shape[0] * shape[1]).map(|_| rng.range(-INIT_SCALE, INIT_SCALE) as f32).collect();
    Tensor::from_data(TensorData::new(values, shape), (device, DType::F32))
}
