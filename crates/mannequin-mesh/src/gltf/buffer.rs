//! The binary chunk and the bufferView/accessor entries that describe it. Every view starts on a
//! 4-byte boundary, which glTF requires for vertex attributes and float data.

use serde_json::{Value, json};

pub(crate) const ARRAY_BUFFER: u32 = 34962;
pub(crate) const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const FLOAT: u32 = 5126;

/// The component types of integer accessors.
#[derive(Clone, Copy)]
pub(crate) enum Int {
    U8 = 5121,
    U16 = 5123,
    U32 = 5125,
}

#[derive(Default)]
pub(crate) struct Buffer {
    pub bytes: Vec<u8>,
    pub views: Vec<Value>,
    pub accessors: Vec<Value>,
    /// The first float accessor holding a non-finite value and that value's element: values
    /// computed from checked inputs (normals, key times) can still overflow, and a file must not
    /// carry them.
    pub non_finite: Option<(usize, usize)>,
}

impl Buffer {
    /// Appends one view holding `data`; returns its index.
    fn view(&mut self, data: &[u8], target: Option<u32>) -> usize {
        while !self.bytes.len().is_multiple_of(4) {
            self.bytes.push(0);
        }
        let mut view = json!({ "buffer": 0, "byteOffset": self.bytes.len(), "byteLength": data.len() });
        if let Some(t) = target {
            view["target"] = json!(t);
        }
        self.bytes.extend_from_slice(data);
        self.views.push(view);
        self.views.len() - 1
    }

    fn accessor(&mut self, accessor: Value) -> usize {
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    /// A float accessor of `N`-component elements ("SCALAR", "VEC2", ...), with min/max when
    /// `bounds` (required for POSITION and animation input).
    pub fn floats<const N: usize>(&mut self, data: &[[f32; N]], bounds: bool, target: Option<u32>) -> usize {
        let bytes: Vec<u8> = data.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
        if self.non_finite.is_none()
            && let Some(e) = data.iter().position(|x| x.iter().any(|c| !c.is_finite()))
        {
            self.non_finite = Some((self.accessors.len(), e));
        }
        let view = self.view(&bytes, target);
        let mut accessor = json!({ "bufferView": view, "componentType": FLOAT, "count": data.len(), "type": element_type(N) });
        if bounds {
            let fold = |init: f32, pick: fn(f32, f32) -> f32| {
                data.iter().fold([init; N], |acc, x| std::array::from_fn(|d| pick(acc[d], x[d])))
            };
            accessor["min"] = json!(fold(f32::INFINITY, f32::min).as_slice());
            accessor["max"] = json!(fold(f32::NEG_INFINITY, f32::max).as_slice());
        }
        self.accessor(accessor)
    }

    /// An unsigned-integer accessor of `N`-component elements stored as `kind` (values must fit).
    pub fn ints<const N: usize>(&mut self, data: &[[u32; N]], kind: Int, target: Option<u32>) -> usize {
        let values = data.iter().flatten().copied();
        let bytes: Vec<u8> = match kind {
            Int::U8 => values.map(|x| x as u8).collect(),
            Int::U16 => values.flat_map(|x| (x as u16).to_le_bytes()).collect(),
            Int::U32 => values.flat_map(u32::to_le_bytes).collect(),
        };
        let view = self.view(&bytes, target);
        self.accessor(json!({ "bufferView": view, "componentType": kind as u32, "count": data.len(), "type": element_type(N) }))
    }
}

fn element_type(n: usize) -> &'static str {
    match n {
        1 => "SCALAR",
        2 => "VEC2",
        3 => "VEC3",
        4 => "VEC4",
        16 => "MAT4",
        _ => unreachable!("glTF has no {n}-component element type used here"),
    }
}
