//! The op on Flex: the host passes run in f64 on a copy of the vertices, whatever their dtype.

use burn::backend::Flex;
use burn::backend::flex::FlexTensor;
use burn::backend::tensor::FloatTensor;
use burn::tensor::{DType, TensorData};

use super::{MeshLoss, MeshLossBackend};

/// The tensor's values as f64, and its dtype.
fn values(t: FlexTensor) -> (Vec<f64>, DType) {
    let dtype = t.dtype();
    let data = t.into_data();
    (data.convert::<f64>().try_into_vec::<f64>().expect("converted to f64"), dtype)
}

fn tensor(values: Vec<f64>, shape: Vec<usize>, dtype: DType) -> FlexTensor {
    FlexTensor::from_data(TensorData::new(values, shape).convert_dtype(dtype))
}

impl MeshLossBackend for Flex {
    fn mesh_loss_forward(vertices: FloatTensor<Self>, loss: MeshLoss) -> FloatTensor<Self> {
        let (v, dtype) = values(vertices);
        tensor(vec![loss.evaluate(&v, None)], vec![1], dtype)
    }

    fn mesh_loss_backward(
        vertices: FloatTensor<Self>,
        grad: FloatTensor<Self>,
        loss: MeshLoss,
    ) -> FloatTensor<Self> {
        let (v, dtype) = values(vertices);
        let (upstream, _) = values(grad);
        let mut d = vec![0.0; v.len()];
        loss.evaluate(&v, Some(&mut d));
        d.iter_mut().for_each(|x| *x *= upstream[0]);
        tensor(d, vec![v.len() / 3, 3], dtype)
    }
}
