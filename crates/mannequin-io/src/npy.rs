//! The NumPy `.npy` array format (versions 1–3): header parsing, dtype decoding, and writing.
//!
//! The format is documented in `numpy/lib/format.py`: a magic string, a version, a header length,
//! and a Python-literal dict `{'descr': ..., 'fortran_order': ..., 'shape': (...)}`, followed by
//! the raw array bytes.

use crate::error::NpyError;

const MAGIC: &[u8; 6] = b"\x93NUMPY";

/// The element values of an array, decoded to a native type per dtype kind.
#[derive(Debug, Clone, PartialEq)]
pub enum NpyData {
    F32(Vec<f32>),
    F64(Vec<f64>),
    I64(Vec<i64>),
    U64(Vec<u64>),
    /// `uint8`, kept narrow because masks and images are stored this way.
    U8(Vec<u8>),
    Bool(Vec<bool>),
    Str(Vec<String>),
}

/// An n-dimensional array in C (row-major) order.
#[derive(Debug, Clone, PartialEq)]
pub struct NpyArray {
    pub shape: Vec<usize>,
    pub data: NpyData,
}

impl NpyArray {
    pub fn f32(shape: Vec<usize>, data: Vec<f32>) -> Self {
        Self { shape, data: NpyData::F32(data) }
    }

    pub fn f64(shape: Vec<usize>, data: Vec<f64>) -> Self {
        Self { shape, data: NpyData::F64(data) }
    }

    pub fn i64(shape: Vec<usize>, data: Vec<i64>) -> Self {
        Self { shape, data: NpyData::I64(data) }
    }

    /// One string as a 0-d array (numpy reads it back with `str(a)`): JSON and other text
    /// stored beside the arrays it describes, so both are written in one atomic file.
    pub fn text(s: &str) -> Self {
        Self { shape: vec![], data: NpyData::Str(vec![s.to_string()]) }
    }

    pub fn len(&self) -> usize {
        self.shape.iter().product()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Numeric values as f64 (booleans as 0/1). Strings are not numbers.
    pub fn to_f64(&self) -> Option<Vec<f64>> {
        Some(match &self.data {
            NpyData::F32(v) => v.iter().map(|&x| x as f64).collect(),
            NpyData::F64(v) => v.clone(),
            NpyData::I64(v) => v.iter().map(|&x| x as f64).collect(),
            NpyData::U64(v) => v.iter().map(|&x| x as f64).collect(),
            NpyData::U8(v) => v.iter().map(|&x| x as f64).collect(),
            NpyData::Bool(v) => v.iter().map(|&x| x as u8 as f64).collect(),
            NpyData::Str(_) => return None,
        })
    }

    /// Numeric values as f32.
    pub fn to_f32(&self) -> Option<Vec<f32>> {
        match &self.data {
            NpyData::F32(v) => Some(v.clone()),
            _ => self.to_f64().map(|v| v.into_iter().map(|x| x as f32).collect()),
        }
    }

    /// Integer values; floats are accepted only when they are whole numbers.
    pub fn to_i64(&self) -> Option<Vec<i64>> {
        match &self.data {
            NpyData::I64(v) => Some(v.clone()),
            NpyData::U64(v) => v.iter().map(|&x| i64::try_from(x).ok()).collect(),
            NpyData::U8(v) => Some(v.iter().map(|&x| x as i64).collect()),
            NpyData::Bool(v) => Some(v.iter().map(|&x| x as i64).collect()),
            NpyData::Str(_) => None,
            _ => self
                .to_f64()?
                .into_iter()
                .map(|x| (x.fract() == 0.0 && x.abs() < 9.0e15).then_some(x as i64))
                .collect(),
        }
    }

    /// A human-readable dtype name for error messages.
    pub fn dtype_name(&self) -> &'static str {
        match self.data {
            NpyData::F32(_) => "float32",
            NpyData::F64(_) => "float64",
            NpyData::I64(_) => "int",
            NpyData::U64(_) => "uint",
            NpyData::U8(_) => "uint8",
            NpyData::Bool(_) => "bool",
            NpyData::Str(_) => "str",
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    Float,
    Int,
    UInt,
    Bool,
    Unicode,
    Bytes,
}

struct Descr {
    kind: Kind,
    /// Bytes per element (four per character for `U`).
    size: usize,
    big_endian: bool,
}

fn parse_descr(descr: &str) -> Result<Descr, NpyError> {
    let bad = || NpyError::Format(format!("unsupported dtype '{descr}'"));
    let mut chars = descr.chars();
    let order = chars.next().ok_or_else(bad)?;
    let (big_endian, rest) = match order {
        '<' | '|' | '=' => (false, &descr[1..]),
        '>' => (true, &descr[1..]),
        _ => (false, descr),
    };
    let kind = match rest.chars().next().ok_or_else(bad)? {
        'f' => Kind::Float,
        'i' => Kind::Int,
        'u' => Kind::UInt,
        'b' => Kind::Bool,
        'U' => Kind::Unicode,
        'S' | 'a' => Kind::Bytes,
        'O' => {
            return Err(NpyError::Format(
                "object arrays (dtype 'O') hold pickled Python objects; save plain numeric arrays".into(),
            ));
        }
        _ => return Err(bad()),
    };
    let width: usize = rest[1..].parse().map_err(|_| bad())?;
    let valid = match kind {
        Kind::Float => matches!(width, 4 | 8),
        Kind::Int | Kind::UInt => matches!(width, 1 | 2 | 4 | 8),
        Kind::Bool => width == 1,
        // A zero-width element would let any element count fit in no bytes at all.
        Kind::Unicode | Kind::Bytes if width == 0 => {
            return Err(NpyError::Format(format!(
                "dtype '{descr}' has zero-width strings: expected a width of at least 1"
            )));
        }
        Kind::Unicode | Kind::Bytes => true,
    };
    let size = if kind == Kind::Unicode { width.checked_mul(4) } else { Some(width) };
    match size {
        Some(size) if valid => Ok(Descr { kind, size, big_endian }),
        _ => Err(bad()),
    }
}

/// Extracts the value text after `'key':` in the header dict.
fn header_field<'a>(header: &'a str, key: &str) -> Result<&'a str, NpyError> {
    let pat = format!("'{key}'");
    let start = header.find(&pat).ok_or_else(|| NpyError::Format(format!("header lacks '{key}'")))?;
    let after = header[start + pat.len()..].trim_start();
    let after = after
        .strip_prefix(':')
        .ok_or_else(|| NpyError::Format(format!("header field '{key}' has no value")))?;
    Ok(after.trim_start())
}

fn parse_header(header: &str) -> Result<(&str, bool, Vec<usize>), NpyError> {
    let descr_txt = header_field(header, "descr")?;
    let quote = descr_txt
        .chars()
        .next()
        .filter(|c| *c == '\'' || *c == '"')
        .ok_or_else(|| NpyError::Format("structured dtypes are not supported".into()))?;
    let end = descr_txt[1..].find(quote).ok_or_else(|| NpyError::Format("unterminated 'descr'".into()))?;
    let descr = &descr_txt[1..1 + end];

    let fortran = header_field(header, "fortran_order")?.starts_with("True");

    let shape_txt = header_field(header, "shape")?;
    let shape_txt =
        shape_txt.strip_prefix('(').ok_or_else(|| NpyError::Format("'shape' is not a tuple".into()))?;
    let close = shape_txt.find(')').ok_or_else(|| NpyError::Format("unterminated 'shape'".into()))?;
    let shape = shape_txt[..close]
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| {
            s.trim_end_matches('L')
                .parse::<usize>()
                .map_err(|_| NpyError::Format(format!("bad dimension '{s}' in 'shape'")))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok((descr, fortran, shape))
}

fn read_word(bytes: &[u8], big_endian: bool) -> u64 {
    let mut v = 0u64;
    if big_endian {
        for &b in bytes {
            v = (v << 8) | b as u64;
        }
    } else {
        for &b in bytes.iter().rev() {
            v = (v << 8) | b as u64;
        }
    }
    v
}

fn decode(descr: &Descr, raw: &[u8], count: usize) -> Result<NpyData, NpyError> {
    let s = descr.size;
    let words = raw.chunks_exact(s).take(count);
    let be = descr.big_endian;
    Ok(match descr.kind {
        Kind::Float if s == 4 => {
            NpyData::F32(words.map(|w| f32::from_bits(read_word(w, be) as u32)).collect())
        }
        Kind::Float => NpyData::F64(words.map(|w| f64::from_bits(read_word(w, be))).collect()),
        Kind::Int => NpyData::I64(
            words
                .map(|w| {
                    let shift = 64 - 8 * s as u32;
                    ((read_word(w, be) << shift) as i64) >> shift
                })
                .collect(),
        ),
        Kind::UInt if s == 1 => NpyData::U8(words.map(|w| w[0]).collect()),
        Kind::UInt => NpyData::U64(words.map(|w| read_word(w, be)).collect()),
        Kind::Bool => NpyData::Bool(words.map(|w| w[0] != 0).collect()),
        Kind::Bytes => NpyData::Str(
            words
                .map(|w| {
                    let end = w.iter().position(|&b| b == 0).unwrap_or(w.len());
                    String::from_utf8_lossy(&w[..end]).into_owned()
                })
                .collect(),
        ),
        // 'U<n>' stores n UCS-4 code points per element.
        Kind::Unicode => NpyData::Str(
            words
                .map(|w| {
                    w.chunks_exact(4)
                        .map(|c| read_word(c, be) as u32)
                        .take_while(|&c| c != 0)
                        .map(|c| char::from_u32(c).unwrap_or('\u{fffd}'))
                        .collect()
                })
                .collect(),
        ),
    })
}

/// Reorders a Fortran-order (column-major) buffer into C order.
fn fortran_to_c<T: Clone>(data: &[T], shape: &[usize]) -> Vec<T> {
    let n: usize = shape.iter().product();
    if shape.len() < 2 {
        return data.to_vec();
    }
    let mut out = Vec::with_capacity(n);
    let mut idx = vec![0usize; shape.len()];
    for _ in 0..n {
        // Column-major offset of the C-order multi-index.
        let mut off = 0;
        let mut stride = 1;
        for (d, &i) in idx.iter().enumerate() {
            off += i * stride;
            stride *= shape[d];
        }
        out.push(data[off].clone());
        for d in (0..shape.len()).rev() {
            idx[d] += 1;
            if idx[d] < shape[d] {
                break;
            }
            idx[d] = 0;
        }
    }
    out
}

/// Bytes before the header text: magic, version and header length (two bytes of length in
/// version 1, four after). [`header_end`] needs no more.
pub const PREFIX_LEN: usize = 12;

/// Longest header accepted, as numpy's own reader (`max_header_size`): the length field is
/// untrusted, and an archive reader must not inflate gigabytes of "header" to learn that.
const MAX_HEADER_LEN: usize = 10_000;

/// Where the header ends and the data starts, read from the file's first [`PREFIX_LEN`] bytes.
pub fn header_end(bytes: &[u8]) -> Result<usize, NpyError> {
    header_span(bytes).map(|span| span.end)
}

/// Where the header text lies.
fn header_span(bytes: &[u8]) -> Result<std::ops::Range<usize>, NpyError> {
    if bytes.len() < 10 || &bytes[..6] != MAGIC {
        return Err(NpyError::Format("not an .npy array (bad magic)".into()));
    }
    let (header_len, header_start) = match bytes[6] {
        1 => (u16::from_le_bytes([bytes[8], bytes[9]]) as usize, 10),
        2 | 3 => match bytes.get(8..12) {
            Some(&[a, b, c, d]) => (u32::from_le_bytes([a, b, c, d]) as usize, 12),
            _ => return Err(NpyError::Format("truncated header".into())),
        },
        v => return Err(NpyError::Format(format!("unsupported .npy version {v}"))),
    };
    if header_len > MAX_HEADER_LEN {
        return Err(NpyError::Format(format!(
            "header of {header_len} bytes: expected at most {MAX_HEADER_LEN}, as numpy reads"
        )));
    }
    Ok(header_start..header_start + header_len)
}

/// What the header says: the element type, the layout, and where the data lies.
struct Header {
    descr: Descr,
    fortran: bool,
    shape: Vec<usize>,
    data_start: usize,
    data_len: usize,
}

/// Elements in `shape` and the bytes they take, or an error where either overflows.
fn extent(descr: &Descr, shape: &[usize]) -> Result<(usize, usize), NpyError> {
    let overflow = || NpyError::Format(format!("shape {shape:?} overflows"));
    let count = shape.iter().try_fold(1usize, |a, &d| a.checked_mul(d)).ok_or_else(overflow)?;
    Ok((count, count.checked_mul(descr.size).ok_or_else(overflow)?))
}

fn read_header(bytes: &[u8]) -> Result<Header, NpyError> {
    let span = header_span(bytes)?;
    let data_start = span.end;
    let header = bytes.get(span).ok_or_else(|| NpyError::Format("truncated header".into()))?;
    let header = std::str::from_utf8(header).map_err(|_| NpyError::Format("header is not text".into()))?;
    let (descr, fortran, shape) = parse_header(header)?;
    let descr = parse_descr(descr)?;
    let (_, data_len) = extent(&descr, &shape)?;
    data_start.checked_add(data_len).ok_or_else(|| NpyError::Format(format!("shape {shape:?} overflows")))?;
    Ok(Header { descr, fortran, shape, data_start, data_len })
}

/// Bytes the whole file takes, header and data, and the array's shape, by its header; `bytes`
/// must hold the header ([`header_end`]). An archive reader refuses a member that inflates past
/// this length, and checks the shape before inflating any of it.
pub fn declared(bytes: &[u8]) -> Result<(usize, Vec<usize>), NpyError> {
    read_header(bytes).map(|h| (h.data_start + h.data_len, h.shape))
}

/// Parses one `.npy` file held in memory.
pub fn parse_npy(bytes: &[u8]) -> Result<NpyArray, NpyError> {
    let Header { descr, fortran, shape, data_start, .. } = read_header(bytes)?;
    decode_array(&descr, fortran, shape, &bytes[data_start.min(bytes.len())..])
}

/// Decodes an array from its dtype string (`'<f8'`, `'|u1'`, …), memory order, shape and raw
/// element bytes, as `.npy` files and pickled NumPy arrays both store them.
pub fn from_raw(descr: &str, fortran: bool, shape: Vec<usize>, raw: &[u8]) -> Result<NpyArray, NpyError> {
    decode_array(&parse_descr(descr)?, fortran, shape, raw)
}

/// The array of `shape` in `raw`, which must hold every element, reordered to C order.
fn decode_array(descr: &Descr, fortran: bool, shape: Vec<usize>, raw: &[u8]) -> Result<NpyArray, NpyError> {
    let (count, data_len) = extent(descr, &shape)?;
    if raw.len() < data_len {
        return Err(NpyError::Format(format!(
            "truncated data: shape {shape:?} needs {data_len} bytes, found {}",
            raw.len()
        )));
    }
    let mut data = decode(descr, raw, count)?;
    if fortran {
        data = match data {
            NpyData::F32(v) => NpyData::F32(fortran_to_c(&v, &shape)),
            NpyData::F64(v) => NpyData::F64(fortran_to_c(&v, &shape)),
            NpyData::I64(v) => NpyData::I64(fortran_to_c(&v, &shape)),
            NpyData::U64(v) => NpyData::U64(fortran_to_c(&v, &shape)),
            NpyData::U8(v) => NpyData::U8(fortran_to_c(&v, &shape)),
            NpyData::Bool(v) => NpyData::Bool(fortran_to_c(&v, &shape)),
            NpyData::Str(v) => NpyData::Str(fortran_to_c(&v, &shape)),
        };
    }
    Ok(NpyArray { shape, data })
}

/// Serialises an array as a version-1 `.npy` file (little-endian, C order).
pub fn write_npy(array: &NpyArray) -> Vec<u8> {
    let (descr, payload): (String, Vec<u8>) = match &array.data {
        NpyData::F32(v) => ("<f4".into(), v.iter().flat_map(|x| x.to_le_bytes()).collect()),
        NpyData::F64(v) => ("<f8".into(), v.iter().flat_map(|x| x.to_le_bytes()).collect()),
        NpyData::I64(v) => ("<i8".into(), v.iter().flat_map(|x| x.to_le_bytes()).collect()),
        NpyData::U64(v) => ("<u8".into(), v.iter().flat_map(|x| x.to_le_bytes()).collect()),
        NpyData::U8(v) => ("|u1".into(), v.clone()),
        NpyData::Bool(v) => ("|b1".into(), v.iter().map(|&b| b as u8).collect()),
        NpyData::Str(v) => {
            let width = v.iter().map(|s| s.chars().count()).max().unwrap_or(0).max(1);
            let mut bytes = Vec::with_capacity(v.len() * width * 4);
            for s in v {
                let mut n = 0;
                for c in s.chars() {
                    bytes.extend_from_slice(&(c as u32).to_le_bytes());
                    n += 1;
                }
                bytes.resize(bytes.len() + 4 * (width - n), 0);
            }
            (format!("<U{width}"), bytes)
        }
    };
    let shape = match array.shape.len() {
        1 => format!("({},)", array.shape[0]),
        _ => format!("({})", array.shape.iter().map(|d| d.to_string()).collect::<Vec<_>>().join(", ")),
    };
    let mut header = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
    // Pad so that the data starts on a 64-byte boundary, ending the header with '\n'.
    let total = 10 + header.len() + 1;
    header.push_str(&" ".repeat((64 - total % 64) % 64));
    header.push('\n');
    let mut out = Vec::with_capacity(10 + header.len() + payload.len());
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&[1, 0]);
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    out.extend_from_slice(&payload);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Bytes that `numpy.save` writes for `np.array([[1, 2, 3], [4, 5, 6]], dtype='<f8')`.
    fn numpy_f8_2x3() -> Vec<u8> {
        let mut header = "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 3), }".to_string();
        while !(10 + header.len() + 1).is_multiple_of(64) {
            header.push(' ');
        }
        header.push('\n');
        let mut b = b"\x93NUMPY\x01\x00".to_vec();
        b.extend_from_slice(&(header.len() as u16).to_le_bytes());
        b.extend_from_slice(header.as_bytes());
        for x in [1.0f64, 2.0, 3.0, 4.0, 5.0, 6.0] {
            b.extend_from_slice(&x.to_le_bytes());
        }
        b
    }

    #[test]
    fn reads_numpy_layout() {
        let a = parse_npy(&numpy_f8_2x3()).unwrap();
        assert_eq!(a.shape, vec![2, 3]);
        assert_eq!(a.data, NpyData::F64(vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]));
    }

    #[test]
    fn fortran_order_is_transposed_to_c() {
        let mut b = numpy_f8_2x3();
        let pos = b.windows(5).position(|w| w == b"False").unwrap();
        b[pos..pos + 5].copy_from_slice(b"True ");
        let a = parse_npy(&b).unwrap();
        // Column-major [1..6] with shape (2,3) is [[1,3,5],[2,4,6]].
        assert_eq!(a.data, NpyData::F64(vec![1.0, 3.0, 5.0, 2.0, 4.0, 6.0]));
    }

    #[test]
    fn round_trips_every_kind() {
        for a in [
            NpyArray::f32(vec![3], vec![1.5, -2.0, 3.25]),
            NpyArray::f64(vec![1, 2], vec![1e-300, 7.0]),
            NpyArray::i64(vec![2, 2], vec![-1, 2, -3, 4]),
            NpyArray { shape: vec![2], data: NpyData::Str(vec!["male".into(), "f".into()]) },
            NpyArray { shape: vec![], data: NpyData::F64(vec![120.0]) },
            NpyArray { shape: vec![2, 2], data: NpyData::U8(vec![0, 1, 1, 255]) },
        ] {
            assert_eq!(parse_npy(&write_npy(&a)).unwrap(), a);
        }
    }

    #[test]
    fn truncated_data_is_an_error() {
        let b = numpy_f8_2x3();
        let err = parse_npy(&b[..b.len() - 3]).unwrap_err();
        assert!(err.to_string().contains("truncated"), "{err}");
    }

    /// A version-1 file with this header dict and data.
    fn npy_with(header: &str, data: &[u8]) -> Vec<u8> {
        let mut b = b"\x93NUMPY\x01\x00".to_vec();
        b.extend_from_slice(&(header.len() as u16).to_le_bytes());
        b.extend_from_slice(header.as_bytes());
        b.extend_from_slice(data);
        b
    }

    /// Zero-width strings would let any element count fit in no data at all.
    #[test]
    fn zero_width_strings_are_an_error() {
        for descr in ["<U0", "|S0"] {
            let b = npy_with(
                &format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': (99999999999,), }}"),
                &[],
            );
            let err = parse_npy(&b).unwrap_err().to_string();
            assert!(err.contains(descr) && err.contains("width of at least 1"), "{err}");
        }
        // A width whose four bytes per character overflow is no dtype either.
        let b = npy_with("{'descr': '<U4611686018427387904', 'fortran_order': False, 'shape': (1,), }", &[]);
        assert!(parse_npy(&b).unwrap_err().to_string().contains("unsupported dtype"));
    }

    #[test]
    fn declared_is_header_plus_data_and_long_headers_are_refused() {
        let b = numpy_f8_2x3();
        assert_eq!(declared(&b).unwrap(), (b.len(), vec![2, 3]));
        assert_eq!(header_end(&b[..PREFIX_LEN]).unwrap(), b.len() - 48);
        let mut long = b"\x93NUMPY\x02\x00".to_vec();
        long.extend_from_slice(&u32::MAX.to_le_bytes());
        let err = header_end(&long).unwrap_err().to_string();
        assert!(err.contains("4294967295") && err.contains("at most 10000"), "{err}");
    }

    #[test]
    fn small_int_widths_sign_extend() {
        let d = parse_descr("<i2").unwrap();
        let NpyData::I64(v) = decode(&d, &[0xff, 0xff, 0x02, 0x00], 2).unwrap() else { panic!() };
        assert_eq!(v, vec![-1, 2]);
    }
}
