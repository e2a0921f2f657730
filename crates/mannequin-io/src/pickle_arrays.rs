//! The arrays of a pickled dict, in the shapes SMPL-family `.pkl` model files hold them: NumPy
//! arrays (`numpy.core.multiarray._reconstruct` with its state tuple, or protocol 5's
//! `_frombuffer`), SciPy sparse matrices (CSC or CSR, made dense), and chumpy `Ch` objects (their
//! array is `state['x']`). Entries that are not arrays (strings, nested dicts) are kept only as a
//! note of what they are, which [`Npz::require`] reports if asked for one.

use std::collections::BTreeMap;
use std::path::PathBuf;

use crate::error::IoError;
use crate::npy::{NpyArray, NpyData, from_raw};
use crate::npz::Npz;
use crate::pickle::{Pickle, Value, ValueId};

/// Most elements the arrays of one file may hold in all. The input's length alone does not bound
/// them: sparse matrices are made dense, and one array may be referenced under many keys. SMPL-X
/// holds about 3·10⁷.
const MAX_ELEMENTS: usize = 1 << 28;

/// How deep arrays may nest inside wrappers (a chumpy `Ch` holds an array).
const MAX_DEPTH: usize = 4;

impl Npz {
    /// Reads the arrays of a pickled dict held in memory; `path` is used only in error messages.
    pub fn from_pickle(path: PathBuf, bytes: &[u8]) -> Result<Self, IoError> {
        let pickle = Pickle::parse(bytes).map_err(|e| IoError::Pickle {
            path: path.clone(),
            reason: format!("not a readable pickle: {e}"),
        })?;
        let Value::Dict(entries) = pickle.get(pickle.root()) else {
            let found = describe(&pickle, pickle.root());
            return Err(IoError::Pickle {
                path,
                reason: format!("expected a pickled dict of arrays, found {found}"),
            });
        };
        let mut reader = Reader { pickle: &pickle, elements: 0 };
        let (mut arrays, mut not_arrays) = (BTreeMap::new(), BTreeMap::new());
        for &(key, value) in entries {
            let Some(key) = text(&pickle, key) else { continue };
            match reader.array(value, 0) {
                Ok(a) => {
                    arrays.insert(key, a);
                }
                Err(Problem::NotArray(what)) => {
                    not_arrays.insert(key, format!("holds {what}, not an array"));
                }
                Err(Problem::Bad(reason)) => return Err(IoError::Field { path, key, reason }),
            }
        }
        Ok(Self::from_parts(path, arrays, not_arrays))
    }
}

/// Why a value did not give an array: it is something else (fine unless that key is needed),
/// or it claims to be an array and is broken (always an error).
enum Problem {
    NotArray(String),
    Bad(String),
}

fn bad<T>(reason: impl Into<String>) -> Result<T, Problem> {
    Err(Problem::Bad(reason.into()))
}

/// A string value's text; Python 2 strings are bytes, read as Latin-1 (as `encoding='latin1'`).
fn text(p: &Pickle, id: ValueId) -> Option<String> {
    match p.get(id) {
        Value::Str(s) => Some(s.clone()),
        Value::Bytes(b) => Some(b.iter().map(|&c| c as char).collect()),
        _ => None,
    }
}

/// What a value is, for messages.
fn describe(p: &Pickle, id: ValueId) -> String {
    match p.get(id) {
        Value::None => "None".into(),
        Value::Bool(_) => "a bool".into(),
        Value::Int(_) => "an int".into(),
        Value::Float(_) => "a float".into(),
        Value::Bytes(_) | Value::Str(_) => "a string".into(),
        Value::Tuple(_) => "a tuple".into(),
        Value::List(_) => "a list".into(),
        Value::Dict(_) => "a dict".into(),
        Value::Global { module, name } => format!("the name {module}.{name}"),
        Value::Object { class, .. } => match p.get(*class) {
            Value::Global { module, name } => format!("a {module}.{name} object"),
            _ => "an object".into(),
        },
    }
}

/// The value under a text key of a dict value.
fn dict_get(p: &Pickle, dict: ValueId, key: &str) -> Option<ValueId> {
    match p.get(dict) {
        Value::Dict(entries) => {
            entries.iter().find(|&&(k, _)| text(p, k).as_deref() == Some(key)).map(|e| e.1)
        }
        _ => None,
    }
}

fn items(p: &Pickle, id: ValueId) -> Option<&[ValueId]> {
    match p.get(id) {
        Value::Tuple(v) | Value::List(v) => Some(v),
        _ => None,
    }
}

fn int(p: &Pickle, id: ValueId) -> Option<i64> {
    match p.get(id) {
        Value::Int(v) => Some(*v),
        Value::Bool(b) => Some(*b as i64),
        _ => None,
    }
}

/// A tuple of non-negative ints, as shapes are stored.
fn shape(p: &Pickle, id: ValueId) -> Result<Vec<usize>, Problem> {
    let dims =
        items(p, id).ok_or_else(|| Problem::Bad(format!("shape is {}, not a tuple", describe(p, id))))?;
    dims.iter()
        .map(|&d| match int(p, d).map(usize::try_from) {
            Some(Ok(n)) => Ok(n),
            _ => bad(format!("shape holds {}, not a size", describe(p, d))),
        })
        .collect()
}

struct Reader<'p> {
    pickle: &'p Pickle,
    /// Elements of the arrays read so far, against [`MAX_ELEMENTS`].
    elements: usize,
}

impl Reader<'_> {
    /// Counts `n` more elements against the budget, before they are allocated.
    fn spend(&mut self, n: usize) -> Result<(), Problem> {
        match self.elements.checked_add(n).filter(|&t| t <= MAX_ELEMENTS) {
            Some(t) => {
                self.elements = t;
                Ok(())
            }
            None => bad(format!("the file's arrays would hold over {MAX_ELEMENTS} elements in all")),
        }
    }

    /// The `module.name` an object was made with, seeing through protocol 0–1's
    /// `copy_reg._reconstructor(cls, base, state)`.
    fn class(&self, class: ValueId, args: ValueId) -> Option<(&str, &str)> {
        let p = self.pickle;
        match p.get(class) {
            Value::Global { module, name }
                if (module == "copy_reg" || module == "copyreg") && name == "_reconstructor" =>
            {
                match p.get(*items(p, args)?.first()?) {
                    Value::Global { module, name } => Some((module, name)),
                    _ => None,
                }
            }
            Value::Global { module, name } => Some((module, name)),
            _ => None,
        }
    }

    fn array(&mut self, id: ValueId, depth: usize) -> Result<NpyArray, Problem> {
        let p = self.pickle;
        if depth > MAX_DEPTH {
            return bad(format!("arrays nested more than {MAX_DEPTH} deep"));
        }
        let &Value::Object { class, args, state } = p.get(id) else {
            return Err(Problem::NotArray(describe(p, id)));
        };
        let Some((module, name)) = self.class(class, args) else {
            return Err(Problem::NotArray(describe(p, id)));
        };
        let state = || state.ok_or_else(|| Problem::Bad(format!("a {module}.{name} without its state")));
        match (module, name) {
            (m, "_reconstruct") if m.starts_with("numpy") => self.ndarray(state()?),
            (m, "_frombuffer") if m.starts_with("numpy") => self.frombuffer(args),
            (m, n) if m.starts_with("scipy.sparse") && (n.starts_with("csc_") || n.starts_with("csr_")) => {
                self.sparse(state()?, n.starts_with("csc_"), depth)
            }
            ("chumpy.ch", "Ch") => {
                let x = dict_get(p, state()?, "x")
                    .ok_or_else(|| Problem::Bad("a chumpy Ch without 'x'".into()))?;
                self.array(x, depth + 1)
            }
            _ => Err(Problem::NotArray(describe(p, id))),
        }
    }

    /// The dtype string (`'<f8'`) of a pickled `numpy.dtype(code, ...)` with its BUILD state.
    fn dtype(&self, id: ValueId) -> Result<String, Problem> {
        let p = self.pickle;
        let &Value::Object { args, state, .. } = p.get(id) else {
            return bad(format!("dtype is {}", describe(p, id)));
        };
        let code = items(p, args).and_then(|a| a.first()).and_then(|&c| text(p, c));
        let Some(code) = code else { return bad("dtype without a type code") };
        let state = state.and_then(|s| items(p, s));
        if state.is_some_and(|s| s.get(3).is_some_and(|&names| p.get(names) != &Value::None)) {
            return bad(format!("structured dtype '{code}' is not supported"));
        }
        let order = state.and_then(|s| s.get(1)).and_then(|&o| text(p, o)).unwrap_or_else(|| "|".into());
        // A dtype's code gives unicode sizes in bytes (4 per character); '.npy' descrs count characters.
        let code = match code.strip_prefix('U').map(str::parse::<usize>) {
            Some(Ok(bytes)) => format!("U{}", bytes / 4),
            _ => code,
        };
        Ok(format!("{order}{code}"))
    }

    /// Raw element bytes: `bytes`, a Python 2 `str`, or protocol 0's `_codecs.encode(text, 'latin1')`.
    fn raw(&self, id: ValueId) -> Result<Vec<u8>, Problem> {
        let p = self.pickle;
        match p.get(id) {
            Value::Bytes(b) => Ok(b.clone()),
            Value::Str(s) => s
                .chars()
                .map(|c| u8::try_from(c as u32))
                .collect::<Result<_, _>>()
                .or_else(|_| bad("array data is text with characters beyond Latin-1")),
            &Value::Object { class, args, .. } if self.class(class, args) == Some(("_codecs", "encode")) => {
                match items(p, args).and_then(|a| a.first()) {
                    Some(&text) => self.raw(text),
                    None => bad("_codecs.encode without its text"),
                }
            }
            _ => bad(format!("array data is {}, not bytes (object arrays are not read)", describe(p, id))),
        }
    }

    fn decode(
        &mut self,
        descr: &str,
        fortran: bool,
        shape: Vec<usize>,
        raw: &[u8],
    ) -> Result<NpyArray, Problem> {
        let a = from_raw(descr, fortran, shape, raw).map_err(|e| Problem::Bad(e.to_string()))?;
        self.spend(a.len())?;
        Ok(a)
    }

    /// `ndarray.__setstate__((version, shape, dtype, is_fortran, data))`; older NumPy omits the
    /// version.
    fn ndarray(&mut self, state: ValueId) -> Result<NpyArray, Problem> {
        let p = self.pickle;
        let parts = match items(p, state) {
            Some(s) if s.len() == 5 => &s[1..],
            Some(s) if s.len() == 4 => s,
            _ => return bad(format!("ndarray state is {}, not a 4- or 5-tuple", describe(p, state))),
        };
        let shape = shape(p, parts[0])?;
        let descr = self.dtype(parts[1])?;
        // Object arrays hold Python objects (SMPL-X's name tables), not numbers: not read.
        if descr.trim_start_matches(['<', '>', '|', '=']).starts_with('O') {
            return Err(Problem::NotArray("a NumPy object array".into()));
        }
        let fortran = int(p, parts[2]).is_some_and(|f| f != 0);
        let raw = self.raw(parts[3])?;
        self.decode(&descr, fortran, shape, &raw)
    }

    /// Protocol 5's in-band `numpy.core.numeric._frombuffer(buffer, dtype, shape, order)`.
    fn frombuffer(&mut self, args: ValueId) -> Result<NpyArray, Problem> {
        let p = self.pickle;
        let Some(&[buffer, dtype, dims, order]) = items(p, args) else {
            return bad("_frombuffer needs (buffer, dtype, shape, order)");
        };
        let (descr, shape, raw) = (self.dtype(dtype)?, shape(p, dims)?, self.raw(buffer)?);
        self.decode(&descr, text(p, order).as_deref() == Some("F"), shape, &raw)
    }

    /// A SciPy CSC (`csc = true`) or CSR matrix from its state dict (`data`, `indices`,
    /// `indptr`, `_shape`), made dense in C order; repeated entries add up, as `toarray()` does.
    fn sparse(&mut self, state: ValueId, csc: bool, depth: usize) -> Result<NpyArray, Problem> {
        let p = self.pickle;
        let field = |key: &str| {
            dict_get(p, state, key).ok_or_else(|| Problem::Bad(format!("sparse matrix without '{key}'")))
        };
        let dims = dict_get(p, state, "_shape").or_else(|| dict_get(p, state, "shape"));
        let Some(dims) = dims else { return bad("sparse matrix without '_shape'") };
        let &[rows, cols] = shape(p, dims)?.as_slice() else {
            return bad("sparse matrix shape is not (rows, cols)");
        };
        let data = self.array(field("data")?, depth + 1)?;
        let indices = self.array(field("indices")?, depth + 1)?.to_i64();
        let indptr = self.array(field("indptr")?, depth + 1)?.to_i64();
        let (Some(values), Some(indices), Some(indptr)) = (data.to_f64(), indices, indptr) else {
            return bad("sparse matrix with non-numeric data or non-integer indices");
        };
        let (major, minor) = if csc { (cols, rows) } else { (rows, cols) };
        let nnz = values.len();
        let ptr_ok = major.checked_add(1) == Some(indptr.len())
            && indptr.first() == Some(&0)
            && indptr.windows(2).all(|w| w[0] <= w[1])
            && indptr.last().is_some_and(|&e| e as usize <= nnz.min(indices.len()));
        if !ptr_ok {
            return bad(format!(
                "sparse matrix ({rows}, {cols}) has an indptr of {} entries that does not index its {nnz} values",
                indptr.len()
            ));
        }
        let size =
            rows.checked_mul(cols).ok_or_else(|| Problem::Bad("sparse matrix shape overflows".into()))?;
        self.spend(size)?;
        let mut dense = vec![0.0f64; size];
        for m in 0..major {
            for k in indptr[m] as usize..indptr[m + 1] as usize {
                let n = match usize::try_from(indices[k]) {
                    Ok(n) if n < minor => n,
                    _ => return bad(format!("sparse index {} is outside 0..{minor}", indices[k])),
                };
                let (r, c) = if csc { (n, m) } else { (m, n) };
                dense[r * cols + c] += values[k];
            }
        }
        Ok(NpyArray { shape: vec![rows, cols], data: NpyData::F64(dense) })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pickle opcodes for the few shapes under test, written as Python 2's protocol 2 would.
    fn s(text: &str) -> Vec<u8> {
        [&[b'U', text.len() as u8][..], text.as_bytes()].concat()
    }

    fn global(module: &str, name: &str) -> Vec<u8> {
        format!("c{module}\n{name}\n").into_bytes()
    }

    fn ints(values: &[u8]) -> Vec<u8> {
        let mut out = vec![b'('];
        values.iter().for_each(|&v| out.extend([b'K', v]));
        out.push(b't');
        out
    }

    /// `numpy.core.multiarray._reconstruct(ndarray, (0,), 'b')` built with `(1, shape, dtype,
    /// False, raw)`.
    fn ndarray(code: &str, shape: &[u8], raw: &[u8]) -> Vec<u8> {
        let mut out = global("numpy.core.multiarray", "_reconstruct");
        out.extend(global("numpy", "ndarray"));
        out.extend([b'K', 0, 0x85].iter().chain(&s("b")).chain(&[0x87, b'R', b'(', b'K', 1]));
        out.extend(ints(shape));
        out.extend(global("numpy", "dtype"));
        out.extend(s(code).iter().chain(&[0x89, 0x88, 0x87, b'R']));
        out.extend(
            [b'(', b'K', 3].iter().chain(&s("<")).chain(b"NNNJ\xff\xff\xff\xffJ\xff\xff\xff\xffK\x00tb"),
        );
        out.push(0x89);
        out.extend([b'T'].iter().chain(&(raw.len() as u32).to_le_bytes()).chain(raw));
        out.extend(b"tb");
        out
    }

    /// A CSC matrix `(2, 2)` from its three arrays, by NEWOBJ and BUILD as Python pickles it.
    fn csc(data: &[f64], indices: &[i64], indptr: &[i64]) -> Vec<u8> {
        let le = |v: &[i64]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<_>>();
        let f = data.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<_>>();
        let mut out = global("scipy.sparse.csc", "csc_matrix");
        out.extend(b")\x81}(");
        out.extend(s("data").into_iter().chain(ndarray("f8", &[data.len() as u8], &f)));
        out.extend(s("indices").into_iter().chain(ndarray("i8", &[indices.len() as u8], &le(indices))));
        out.extend(s("indptr").into_iter().chain(ndarray("i8", &[indptr.len() as u8], &le(indptr))));
        out.extend(s("_shape").into_iter().chain(ints(&[2, 2])));
        out.extend(b"ub");
        out
    }

    fn dict(entries: &[(&str, Vec<u8>)]) -> Vec<u8> {
        let mut out = b"\x80\x02}(".to_vec();
        for (k, v) in entries {
            out.extend(s(k).into_iter().chain(v.iter().copied()));
        }
        out.extend(b"u.");
        out
    }

    fn read(bytes: &[u8]) -> Result<Npz, IoError> {
        Npz::from_pickle("m.pkl".into(), bytes)
    }

    #[test]
    fn arrays_sparse_matrices_and_other_values() {
        let raw: Vec<u8> = [1.5f64, -2.0, 0.25, 4.0].iter().flat_map(|x| x.to_le_bytes()).collect();
        let npz = read(&dict(&[
            ("a", ndarray("f8", &[2, 2], &raw)),
            ("m", csc(&[1.0, 2.0, 3.0], &[1, 0, 1], &[0, 1, 3])),
            ("kind", s("lbs")),
            ("names", ndarray("O8", &[0], &[])),
        ]))
        .unwrap();
        let a = npz.require("a").unwrap();
        assert_eq!((a.shape.clone(), a.to_f64().unwrap()), (vec![2, 2], vec![1.5, -2.0, 0.25, 4.0]));
        // Column 0 holds row 1; column 1 holds rows 0 and 1.
        assert_eq!(npz.require("m").unwrap().to_f64().unwrap(), vec![0.0, 2.0, 1.0, 3.0]);
        let msg = npz.require("kind").unwrap_err().to_string();
        assert!(msg.contains("m.pkl") && msg.contains("'kind'") && msg.contains("a string"), "{msg}");
        let msg = npz.require("names").unwrap_err().to_string();
        assert!(msg.contains("'names'") && msg.contains("object array"), "{msg}");
        assert_eq!(npz.keys().collect::<Vec<_>>(), vec!["a", "m"]);
    }

    #[test]
    fn broken_arrays_name_the_key_and_the_problem() {
        let short = read(&dict(&[("a", ndarray("f8", &[3], &[0; 16]))])).unwrap_err().to_string();
        assert!(
            short.contains("m.pkl") && short.contains("'a'") && short.contains("truncated data"),
            "{short}"
        );
        let outside = csc(&[1.0], &[5], &[0, 1, 1]);
        let msg = read(&dict(&[("J_regressor", outside)])).unwrap_err().to_string();
        assert!(msg.contains("'J_regressor'") && msg.contains("sparse index 5 is outside 0..2"), "{msg}");
        let bad_ptr = csc(&[1.0], &[0], &[0, 2, 1]);
        let msg = read(&dict(&[("J_regressor", bad_ptr)])).unwrap_err().to_string();
        assert!(msg.contains("indptr"), "{msg}");
        let msg = read(b"\x80\x02]q\x00.").unwrap_err().to_string();
        assert!(
            msg.contains("m.pkl") && msg.contains("expected a pickled dict of arrays, found a list"),
            "{msg}"
        );
    }
}
