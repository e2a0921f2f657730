//! NumPy `.npz` archives: a zip file whose entries are `<key>.npy` arrays.

use std::collections::BTreeMap;
use std::io::{Cursor, Read, Write};
use std::path::{Path, PathBuf};

use crate::atomic::write_atomic;
use crate::error::{IoError, NpyError};
use crate::limits::{MAX_ARCHIVE_ELEMENTS, MAX_ARRAY_ELEMENTS};
use crate::npy::{self, NpyArray, NpyData, parse_npy, write_npy};

/// All arrays of one `.npz` file (or of a pickled dict, see `pickle_arrays.rs`), decoded
/// eagerly, with the file name kept for errors.
#[derive(Debug, Clone)]
pub struct Npz {
    pub path: PathBuf,
    arrays: BTreeMap<String, NpyArray>,
    /// Keys of a pickled dict whose values are not arrays, and what each is instead, so that
    /// asking for one says why rather than that it is missing.
    not_arrays: BTreeMap<String, String>,
}

impl Npz {
    /// Reads and decodes every array in the archive.
    pub fn read(path: impl AsRef<Path>) -> Result<Self, IoError> {
        Self::read_within(path, MAX_ARCHIVE_ELEMENTS)
    }

    /// [`Npz::read`] for a reader that knows how large its file can be: an archive whose arrays
    /// declare more than `max_elements` in all is refused by their headers, before inflating.
    pub fn read_within(path: impl AsRef<Path>, max_elements: usize) -> Result<Self, IoError> {
        let path = path.as_ref().to_path_buf();
        let bytes = std::fs::read(&path).map_err(|source| IoError::Io { path: path.clone(), source })?;
        Self::decode(path, &bytes, max_elements.min(MAX_ARCHIVE_ELEMENTS))
    }

    /// Decodes an archive held in memory; `path` is used only in error messages.
    pub fn from_bytes(path: PathBuf, bytes: &[u8]) -> Result<Self, IoError> {
        Self::decode(path, bytes, MAX_ARCHIVE_ELEMENTS)
    }

    fn decode(path: PathBuf, bytes: &[u8], max_elements: usize) -> Result<Self, IoError> {
        let archive_err = |reason: String| IoError::Archive { path: path.clone(), reason };
        let mut zip = zip::ZipArchive::new(Cursor::new(bytes)).map_err(|e| archive_err(e.to_string()))?;
        let mut arrays = BTreeMap::new();
        let mut elements = 0usize;
        for i in 0..zip.len() {
            let entry = zip.by_index(i).map_err(|e| archive_err(e.to_string()))?;
            let name = entry.name().to_string();
            let key = name.strip_suffix(".npy").unwrap_or(&name).to_string();
            let array = read_member(entry, bytes.len(), &mut elements, max_elements)
                .and_then(|member| Ok(parse_npy(&member)?))
                .map_err(|e| match e {
                    MemberError::Inflate(e) => archive_err(format!("member '{name}': {e}")),
                    MemberError::Npy(e) => {
                        IoError::Field { path: path.clone(), key: key.clone(), reason: e.to_string() }
                    }
                })?;
            arrays.insert(key, array);
        }
        Ok(Self { path, arrays, not_arrays: BTreeMap::new() })
    }

    /// Arrays decoded from another container; `not_arrays` says what each other key holds.
    pub(crate) fn from_parts(
        path: PathBuf,
        arrays: BTreeMap<String, NpyArray>,
        not_arrays: BTreeMap<String, String>,
    ) -> Self {
        Self { path, arrays, not_arrays }
    }

    pub fn keys(&self) -> impl Iterator<Item = &str> {
        self.arrays.keys().map(String::as_str)
    }

    pub fn contains(&self, key: &str) -> bool {
        self.arrays.contains_key(key)
    }

    pub fn get(&self, key: &str) -> Option<&NpyArray> {
        self.arrays.get(key)
    }

    /// The array under `key`, or an error that says what the key holds instead or lists the
    /// keys that are there.
    pub fn require(&self, key: &str) -> Result<&NpyArray, IoError> {
        if let Some(what) = self.not_arrays.get(key) {
            return Err(self.field_error(key, what.clone()));
        }
        self.arrays.get(key).ok_or_else(|| IoError::MissingKey {
            path: self.path.clone(),
            key: key.to_string(),
            present: self.keys().collect::<Vec<_>>().join(", "),
        })
    }

    /// The text under `key`, stored by [`NpyArray::text`].
    pub fn text(&self, key: &str) -> Result<&str, IoError> {
        let a = self.require(key)?;
        match &a.data {
            NpyData::Str(v) if v.len() == 1 => Ok(&v[0]),
            _ => Err(self.field_error(
                key,
                format!("expected one string, found dtype {} shape {:?}", a.dtype_name(), a.shape),
            )),
        }
    }

    /// An error about `key` in this file.
    pub fn field_error(&self, key: &str, reason: impl Into<String>) -> IoError {
        IoError::Field { path: self.path.clone(), key: key.to_string(), reason: reason.into() }
    }

    /// The array under `key` as f64, checking its shape against `expected`
    /// (`None` entries match any size).
    pub fn f64_with_shape(
        &self,
        key: &str,
        expected: &[Option<usize>],
    ) -> Result<(Vec<usize>, Vec<f64>), IoError> {
        let a = self.require(key)?;
        check_shape(self, key, &a.shape, expected)?;
        let v = a.to_f64().ok_or_else(|| {
            self.field_error(key, format!("expected numbers, found dtype {}", a.dtype_name()))
        })?;
        Ok((a.shape.clone(), v))
    }

    /// [`Npz::f64_with_shape`], refusing a NaN or infinity by its index: a reader hands on
    /// only numbers that mean something.
    pub fn finite_f64_with_shape(
        &self,
        key: &str,
        expected: &[Option<usize>],
    ) -> Result<(Vec<usize>, Vec<f64>), IoError> {
        let (shape, v) = self.f64_with_shape(key, expected)?;
        match v.iter().position(|x| !x.is_finite()) {
            Some(i) => {
                Err(self
                    .field_error(key, format!("element {i} is {}: expected a finite number", number(v[i]))))
            }
            None => Ok((shape, v)),
        }
    }

    /// The array under `key` as finite f64 in `range`, refusing the first value outside it.
    pub fn f64_in_range(
        &self,
        key: &str,
        expected: &[Option<usize>],
        range: std::ops::RangeInclusive<f64>,
    ) -> Result<(Vec<usize>, Vec<f64>), IoError> {
        let (shape, v) = self.finite_f64_with_shape(key, expected)?;
        match v.iter().position(|x| !range.contains(x)) {
            Some(i) => Err(self.field_error(
                key,
                format!(
                    "element {i} is {}: expected {}–{}",
                    number(v[i]),
                    number(*range.start()),
                    number(*range.end())
                ),
            )),
            None => Ok((shape, v)),
        }
    }
}

/// A number as a message shows it: whole numbers plainly, the very large or small with an
/// exponent (`1e300`, not 301 digits).
fn number(x: f64) -> String {
    let a = x.abs();
    if a >= 1e15 || (a > 0.0 && a < 1e-4) { format!("{x:e}") } else { format!("{x}") }
}

/// Why a member could not be read: its compressed bytes, or its array's header.
enum MemberError {
    Inflate(std::io::Error),
    Npy(NpyError),
}

impl From<std::io::Error> for MemberError {
    fn from(e: std::io::Error) -> Self {
        Self::Inflate(e)
    }
}

impl From<NpyError> for MemberError {
    fn from(e: NpyError) -> Self {
        Self::Npy(e)
    }
}

/// Inflates one member no further than its `.npy` header declares (header plus shape × dtype
/// bytes), so a zip bomb costs only what its header admits to: the header is read first, then
/// at most the declared length and one byte more, which is refused. The header's shape is held
/// to [`MAX_ARRAY_ELEMENTS`], and `elements` (the archive's running total) to `max_elements`,
/// before anything is inflated: a few kilobytes of deflated zeros may
/// honestly hold gigabytes. Nothing is reserved by the archive's own size fields, and never more
/// than the archive's length (all a stored member needs).
fn read_member(
    mut entry: impl Read,
    archive_len: usize,
    elements: &mut usize,
    max_elements: usize,
) -> Result<Vec<u8>, MemberError> {
    let mut buf = Vec::new();
    (&mut entry).take(npy::PREFIX_LEN as u64).read_to_end(&mut buf)?;
    let header_end = npy::header_end(&buf)?;
    (&mut entry).take(header_end.saturating_sub(buf.len()) as u64).read_to_end(&mut buf)?;
    let (declared, shape) = npy::declared(&buf)?;
    // An element counts as at least 8 bytes' worth: one text element may declare 800 MB.
    let data_bytes = declared.saturating_sub(header_end);
    let count =
        shape.iter().try_fold(1usize, |a, &d| a.checked_mul(d)).unwrap_or(usize::MAX).max(data_bytes / 8);
    if count > MAX_ARRAY_ELEMENTS {
        return Err(MemberError::Npy(NpyError::Format(format!(
            "shape {shape:?} ({data_bytes} bytes) holds {count} elements' worth, expected at most {MAX_ARRAY_ELEMENTS} (of 8 bytes)"
        ))));
    }
    *elements += count;
    if *elements > max_elements {
        return Err(MemberError::Npy(NpyError::Format(format!(
            "shape {shape:?} brings the archive to {} elements, expected at most {max_elements} in all",
            *elements
        ))));
    }
    buf.reserve(declared.min(archive_len).saturating_sub(buf.len()));
    (&mut entry).take((declared.saturating_sub(buf.len()) as u64).saturating_add(1)).read_to_end(&mut buf)?;
    if buf.len() > declared {
        return Err(MemberError::Inflate(std::io::Error::other(format!(
            "inflates past the {declared} bytes that its .npy header's shape and dtype declare"
        ))));
    }
    Ok(buf)
}

fn shape_text(expected: &[Option<usize>]) -> String {
    let dims: Vec<String> = expected.iter().map(|d| d.map_or("*".into(), |n| n.to_string())).collect();
    format!("({})", dims.join(", "))
}

fn check_shape(npz: &Npz, key: &str, shape: &[usize], expected: &[Option<usize>]) -> Result<(), IoError> {
    let ok =
        shape.len() == expected.len() && shape.iter().zip(expected).all(|(s, e)| e.is_none_or(|e| e == *s));
    if ok {
        Ok(())
    } else {
        Err(npz.field_error(key, format!("expected shape {}, found {:?}", shape_text(expected), shape)))
    }
}

/// Collects arrays and writes them as one `.npz` archive, atomically.
#[derive(Debug, Default)]
pub struct NpzWriter {
    arrays: Vec<(String, NpyArray)>,
    stored: bool,
}

impl NpzWriter {
    pub fn new() -> Self {
        Self::default()
    }

    /// Entries stored without compression (as `numpy.savez`): for large float arrays written
    /// often, such as training checkpoints, deflate costs seconds and saves little.
    pub fn uncompressed() -> Self {
        Self { stored: true, ..Self::default() }
    }

    pub fn add(&mut self, key: &str, array: NpyArray) -> &mut Self {
        self.arrays.push((key.to_string(), array));
        self
    }

    /// The archive bytes (deflate-compressed entries, as `numpy.savez_compressed` writes, unless
    /// [`NpzWriter::uncompressed`]).
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut zip = zip::ZipWriter::new(Cursor::new(Vec::new()));
        let method =
            if self.stored { zip::CompressionMethod::Stored } else { zip::CompressionMethod::Deflated };
        // ZIP64 only where an entry needs it (over 4 GiB stays an error otherwise).
        let opts = zip::write::SimpleFileOptions::default().compression_method(method).large_file(false);
        for (key, array) in &self.arrays {
            // Writing into memory cannot fail except on allocation failure.
            zip.start_file(format!("{key}.npy"), opts).expect("in-memory zip entry");
            zip.write_all(&write_npy(array)).expect("in-memory zip write");
        }
        zip.finish().expect("in-memory zip finish").into_inner()
    }

    /// Writes the archive atomically, refusing a NaN or an infinity in any float array: a file
    /// that holds one would be refused by every reader, so it is not written.
    pub fn write(&self, path: impl AsRef<Path>) -> Result<(), IoError> {
        let path = path.as_ref();
        for (key, array) in &self.arrays {
            let bad = match &array.data {
                NpyData::F32(v) => v.iter().position(|x| !x.is_finite()).map(|i| (i, f64::from(v[i]))),
                NpyData::F64(v) => v.iter().position(|x| !x.is_finite()).map(|i| (i, v[i])),
                _ => None,
            };
            if let Some((i, x)) = bad {
                return Err(IoError::Field {
                    path: path.to_path_buf(),
                    key: key.clone(),
                    reason: format!("element {i} is {x}: refusing to write a non-finite number"),
                });
            }
        }
        write_atomic(path, &self.to_bytes())
            .map_err(|source| IoError::Io { path: path.to_path_buf(), source })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> NpzWriter {
        let mut w = NpzWriter::new();
        w.add("a", NpyArray::f32(vec![2, 2], vec![1.0, 2.0, 3.0, 4.0]));
        w.add("b", NpyArray::i64(vec![3], vec![7, 8, 9]));
        w
    }

    #[test]
    fn round_trip() {
        let npz = Npz::from_bytes("mem.npz".into(), &sample().to_bytes()).unwrap();
        assert_eq!(npz.keys().collect::<Vec<_>>(), vec!["a", "b"]);
        assert_eq!(npz.require("b").unwrap().to_i64().unwrap(), vec![7, 8, 9]);
    }

    #[test]
    fn uncompressed_round_trip_holds_the_raw_bytes() {
        let mut w = NpzWriter::uncompressed();
        let values: Vec<f32> = (0..1000).map(|i| i as f32).collect();
        w.add("x", NpyArray::f32(vec![1000], values.clone()));
        let bytes = w.to_bytes();
        // Stored entries carry the 4,000 data bytes verbatim.
        assert!(bytes.len() > 4000);
        let npz = Npz::from_bytes("mem.npz".into(), &bytes).unwrap();
        assert_eq!(npz.require("x").unwrap().to_f32().unwrap(), values);
    }

    #[test]
    fn text_round_trips_and_a_number_is_not_text() {
        let mut w = sample();
        w.add("json", NpyArray::text("{\"é\": 1}"));
        let npz = Npz::from_bytes("mem.npz".into(), &w.to_bytes()).unwrap();
        assert_eq!(npz.text("json").unwrap(), "{\"é\": 1}");
        let msg = npz.text("b").unwrap_err().to_string();
        assert!(msg.contains("'b'") && msg.contains("expected one string"), "{msg}");
    }

    #[test]
    fn missing_key_names_file_and_key() {
        let npz = Npz::from_bytes("model.npz".into(), &sample().to_bytes()).unwrap();
        let msg = npz.require("weights").unwrap_err().to_string();
        assert!(msg.contains("model.npz") && msg.contains("'weights'") && msg.contains("a, b"), "{msg}");
    }

    #[test]
    fn wrong_shape_names_expected_shape() {
        let npz = Npz::from_bytes("m.npz".into(), &sample().to_bytes()).unwrap();
        let msg = npz.f64_with_shape("a", &[Some(3), None]).unwrap_err().to_string();
        assert!(msg.contains("'a'") && msg.contains("(3, *)") && msg.contains("[2, 2]"), "{msg}");
    }

    #[test]
    fn truncated_archive_is_an_error() {
        let bytes = sample().to_bytes();
        for cut in [0, 10, bytes.len() / 2, bytes.len() - 1] {
            let err = Npz::from_bytes("t.npz".into(), &bytes[..cut]).unwrap_err();
            assert!(err.to_string().starts_with("t.npz: "), "{err}");
        }
    }

    /// A zip bomb: a member whose header declares ten floats but whose data inflates to 8 MB is
    /// refused, naming the file and the member, after reading no more than the header admits.
    #[test]
    fn member_inflating_past_its_header_is_refused() {
        let mut npy = write_npy(&NpyArray::f32(vec![10], vec![0.0; 10]));
        npy.resize(npy.len() + (8 << 20), 0);
        let mut zip = zip::ZipWriter::new(Cursor::new(Vec::new()));
        zip.start_file("x.npy", zip::write::SimpleFileOptions::default()).unwrap();
        zip.write_all(&npy).unwrap();
        let bomb = zip.finish().unwrap().into_inner();
        assert!(bomb.len() < 100_000);
        let err = Npz::from_bytes("bomb.npz".into(), &bomb).unwrap_err().to_string();
        assert!(
            err.starts_with("bomb.npz: ") && err.contains("'x.npy'") && err.contains("inflates past"),
            "{err}"
        );
    }

    /// A zip member of `npy` bytes.
    fn zipped(members: &[(&str, Vec<u8>)]) -> Vec<u8> {
        let mut zip = zip::ZipWriter::new(Cursor::new(Vec::new()));
        for (name, bytes) in members {
            zip.start_file(*name, zip::write::SimpleFileOptions::default()).unwrap();
            zip.write_all(bytes).unwrap();
        }
        zip.finish().unwrap().into_inner()
    }

    /// The header of a `|u1` array of `n` elements, with no data after it.
    fn u8_header(n: usize) -> Vec<u8> {
        write_npy(&NpyArray { shape: vec![n], data: NpyData::U8(vec![]) })
    }

    /// A header claiming 200 million rows is refused by its shape, before any of it is inflated
    /// (issue 42: a 2.5 MB garment once took 9.4 GB this way), and so is an archive whose arrays
    /// add up past the archive limit.
    #[test]
    fn shapes_past_the_limits_are_refused_before_inflating() {
        let bytes = zipped(&[("positions.npy", u8_header(600_000_000))]);
        let err = Npz::from_bytes("g.garment".into(), &bytes).unwrap_err().to_string();
        assert!(
            err.contains("g.garment")
                && err.contains("'positions'")
                && err.contains(&MAX_ARRAY_ELEMENTS.to_string()),
            "{err}"
        );
        let big = write_npy(&NpyArray {
            shape: vec![MAX_ARRAY_ELEMENTS],
            data: NpyData::U8(vec![0; MAX_ARRAY_ELEMENTS]),
        });
        assert_eq!(MAX_ARCHIVE_ELEMENTS, 2 * MAX_ARRAY_ELEMENTS);
        let bytes = zipped(&[("a.npy", big.clone()), ("b.npy", big), ("c.npy", u8_header(1))]);
        let err = Npz::from_bytes("m.npz".into(), &bytes).unwrap_err().to_string();
        assert!(err.contains("'c'") && err.contains("in all"), "{err}");
        let wide = write_npy(&NpyArray { shape: vec![1], data: NpyData::Str(vec!["x".repeat(70_000_000)]) });
        let header_only = wide[..npy::header_end(&wide).unwrap()].to_vec();
        let err =
            Npz::from_bytes("t.npz".into(), &zipped(&[("run.npy", header_only)])).unwrap_err().to_string();
        assert!(err.contains("'run'") && err.contains("bytes"), "{err}");
        let ok = zipped(&[("a.npy", write_npy(&NpyArray::f32(vec![2], vec![1.0, 2.0])))]);
        assert!(Npz::from_bytes("m.npz".into(), &ok).is_ok());
    }

    /// A reader's own bound refuses a header within the global limits but past what its file can
    /// hold, before inflating; an archive within it reads.
    #[test]
    fn a_readers_bound_is_held_before_inflating() {
        let path = std::env::temp_dir().join(format!("mq-npz-within-{}.npz", std::process::id()));
        std::fs::write(
            &path,
            zipped(&[("a.npy", write_npy(&NpyArray::f32(vec![4], vec![0.0; 4]))), ("b.npy", u8_header(100))]),
        )
        .unwrap();
        let err = Npz::read_within(&path, 50).unwrap_err().to_string();
        assert!(err.contains("'b'") && err.contains("104 elements, expected at most 50 in all"), "{err}");
        assert!(Npz::read_within(&path, 4).unwrap_err().to_string().contains("'b'"));
        std::fs::write(&path, zipped(&[("a.npy", write_npy(&NpyArray::f32(vec![4], vec![0.0; 4])))]))
            .unwrap();
        assert!(Npz::read_within(&path, 4).is_ok());
        std::fs::remove_file(path).unwrap();
    }

    #[test]
    fn non_finite_and_out_of_range_values_are_named_by_index() {
        let mut w = NpzWriter::new();
        w.add("betas", NpyArray::f64(vec![3], vec![0.5, f64::NAN, 1.0]));
        w.add("transl", NpyArray::f64(vec![2], vec![0.5, 2e6]));
        let npz = Npz::from_bytes("p.npz".into(), &w.to_bytes()).unwrap();
        let e = npz.finite_f64_with_shape("betas", &[None]).unwrap_err().to_string();
        assert!(e.contains("p.npz") && e.contains("'betas'") && e.contains("element 1 is NaN"), "{e}");
        let e = npz.f64_in_range("transl", &[None], -1e3..=1e3).unwrap_err().to_string();
        assert!(
            e.contains("'transl'") && e.contains("element 1 is 2000000") && e.contains("-1000–1000"),
            "{e}"
        );
        assert!(npz.f64_in_range("transl", &[None], -1e7..=1e7).is_ok());
        let mut w = NpzWriter::new();
        w.add("fx", NpyArray::f64(vec![1], vec![1e300]));
        let npz = Npz::from_bytes("k.npz".into(), &w.to_bytes()).unwrap();
        let e = npz.f64_in_range("fx", &[None], 0.0..=f64::from(f32::MAX)).unwrap_err().to_string();
        assert!(e.contains("element 0 is 1e300: expected 0–3.4028234663852886e38"), "{e}");
    }

    #[test]
    fn a_non_finite_number_is_not_written() {
        let dir = std::env::temp_dir().join(format!("mq-npz-nan-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("out.npz");
        let mut w = NpzWriter::new();
        w.add("ok", NpyArray::f64(vec![1], vec![1.0]))
            .add("x", NpyArray::f32(vec![3], vec![0.0, 1.0, f32::NAN]));
        let e = w.write(&path).unwrap_err().to_string();
        assert!(e.contains("out.npz") && e.contains("'x'") && e.contains("element 2 is NaN"), "{e}");
        assert!(!path.exists());
        std::fs::remove_dir_all(dir).unwrap();
    }
}
