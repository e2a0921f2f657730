//! One shipped person model: an ONNX file embedded in the binary, optimised once by tract and
//! run on NHWC float inputs. Nothing is read from disk or downloaded at run time.

use std::io::Cursor;
use std::sync::Arc;

use tract_onnx::prelude::*;

use crate::error::FitError;

/// A loaded, optimised network with its output names.
pub struct Network {
    name: &'static str,
    plan: Arc<TypedRunnableModel>,
    input_shape: Vec<usize>,
    output_names: Vec<String>,
}

/// One output tensor, row-major.
#[derive(Debug, Clone)]
pub struct Output {
    pub shape: Vec<usize>,
    pub values: Vec<f32>,
}

impl Network {
    /// Parses and optimises an ONNX model whose single input has a fixed shape.
    pub fn load(name: &'static str, onnx: &[u8]) -> Result<Self, FitError> {
        let fail = |e: TractError| FitError::Model { model: name, reason: format!("{e:#}") };
        let model = tract_onnx::onnx().model_for_read(&mut Cursor::new(onnx)).map_err(fail)?;
        let output_names = model
            .output_outlets()
            .map_err(fail)?
            .iter()
            .map(|o| model.outlet_label(*o).unwrap_or(&model.node(o.node).name).to_string())
            .collect();
        let typed = model.into_optimized().map_err(fail)?;
        let input_fact = typed.input_fact(0).map_err(fail)?;
        let input_shape = input_fact
            .shape
            .as_concrete()
            .ok_or_else(|| FitError::Model { model: name, reason: "its input shape is not fixed".into() })?
            .to_vec();
        let plan = typed.into_runnable().map_err(fail)?;
        Ok(Self { name, plan, input_shape, output_names })
    }

    pub fn input_shape(&self) -> &[usize] {
        &self.input_shape
    }

    /// Runs the network on one input of `input_shape` values; the outputs in the model's order.
    pub fn run(&self, input: Vec<f32>) -> Result<Vec<Output>, FitError> {
        let fail = |e: TractError| FitError::Model { model: self.name, reason: format!("{e:#}") };
        let expected: usize = self.input_shape.iter().product();
        if input.len() != expected {
            return Err(FitError::Model {
                model: self.name,
                reason: format!(
                    "input of {} values, expected {expected} ({:?})",
                    input.len(),
                    self.input_shape
                ),
            });
        }
        let tensor = Tensor::from_shape(&self.input_shape, &input).map_err(fail)?;
        let outputs = self.plan.run(tvec!(tensor.into())).map_err(fail)?;
        outputs
            .iter()
            .map(|t| {
                let view = t.to_plain_array_view::<f32>().map_err(fail)?;
                Ok(Output { shape: view.shape().to_vec(), values: view.iter().copied().collect() })
            })
            .collect()
    }

    /// The index of the output called `name`.
    pub fn output_index(&self, name: &str) -> Result<usize, FitError> {
        self.output_names.iter().position(|n| n == name).ok_or_else(|| FitError::Model {
            model: self.name,
            reason: format!("no output named {name:?}; it has {:?}", self.output_names),
        })
    }
}

/// A network's logit as a probability.
pub(crate) fn sigmoid(x: f32) -> f32 {
    1.0 / (1.0 + (-x).exp())
}
