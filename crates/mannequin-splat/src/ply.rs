//! 3D Gaussian splats in the INRIA `.ply` layout, which 3DGS writes and splat viewers read:
//! one `vertex` element with `x y z`, `nx ny nz` (unused), `f_dc_0..2`, `f_rest_*`
//! (channel-major: all red coefficients of bases 1.., then green, then blue), `opacity` as a
//! logit, `scale_0..2` as natural logs, and `rot_0..3` as a `(w, x, y, z)` quaternion.
//! Binary (either endianness) and ASCII files are read; binary little-endian is written.

use std::io::Write;
use std::path::{Path, PathBuf};

use mannequin_io::ply_header::{Element, Property};
use mannequin_io::{PlyHeader, PlyValues};

use crate::gaussians::{Colors, Gaussians, Rotations};
use crate::{SplatError, sh};

/// Gaussians as stored in a splat file, with activations applied (opacity in `[0, 1]`, scales
/// as standard deviations) and SH coefficients as `[N, (degree+1)², 3]`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SplatScene {
    pub means: Vec<f32>,
    /// `(w, x, y, z)`, as stored (not necessarily unit).
    pub quaternions: Vec<f32>,
    pub scales: Vec<f32>,
    pub opacities: Vec<f32>,
    pub sh_degree: usize,
    pub sh: Vec<f32>,
}

/// Where each INRIA field sits in a vertex record.
struct Layout {
    index: std::collections::HashMap<String, usize>,
}

impl Layout {
    fn find(&self, name: &str, err: &dyn Fn(String) -> SplatError) -> Result<usize, SplatError> {
        self.index.get(name).copied().ok_or_else(|| err(format!("vertex element has no property '{name}'")))
    }
}

fn sigmoid(x: f64) -> f64 {
    1.0 / (1.0 + (-x).exp())
}

impl SplatScene {
    /// Number of Gaussians.
    pub fn len(&self) -> usize {
        self.opacities.len()
    }

    pub fn is_empty(&self) -> bool {
        self.opacities.is_empty()
    }

    /// A view the renderer takes.
    pub fn gaussians(&self) -> Gaussians<'_, f32> {
        Gaussians {
            means: &self.means,
            rotations: Rotations::Quaternions(&self.quaternions),
            scales: &self.scales,
            opacities: &self.opacities,
            colors: Colors::Sh { degree: self.sh_degree, coeffs: &self.sh },
        }
    }

    /// Reads a `.ply` file.
    pub fn read_ply(path: impl AsRef<Path>) -> Result<Self, SplatError> {
        let path = path.as_ref();
        let bytes =
            std::fs::read(path).map_err(|source| SplatError::Io { path: path.to_path_buf(), source })?;
        Self::from_ply_bytes(path, &bytes)
    }

    /// Parses `.ply` bytes; `path` only labels errors.
    pub fn from_ply_bytes(path: &Path, bytes: &[u8]) -> Result<Self, SplatError> {
        let err = |reason: String| SplatError::Ply { path: PathBuf::from(path), reason };
        let header = PlyHeader::parse(bytes).map_err(|e| err(e.to_string()))?;
        let mut body = PlyValues::new(bytes, &header);
        for el in &header.elements {
            if el.name == "vertex" {
                return Self::read_vertices(el, &mut body, &err);
            }
            skip_element(el, &mut body, &err)?;
        }
        Err(err("no 'vertex' element".into()))
    }

    fn read_vertices(
        el: &Element,
        body: &mut PlyValues,
        err: &dyn Fn(String) -> SplatError,
    ) -> Result<Self, SplatError> {
        let mut types = Vec::with_capacity(el.properties.len());
        let mut index = std::collections::HashMap::new();
        for (k, p) in el.properties.iter().enumerate() {
            match p {
                Property::Scalar { name, ty } => {
                    types.push(*ty);
                    index.insert(name.clone(), k);
                }
                Property::List { name, .. } => {
                    return Err(err(format!(
                        "vertex property '{name}' is a list; splat files have scalars only"
                    )));
                }
            }
        }
        let layout = Layout { index };
        body.check_count(el).map_err(|e| err(format!("element 'vertex': {e}")))?;
        let n_rest = (0..).take_while(|j| layout.index.contains_key(&format!("f_rest_{j}"))).count();
        let degree =
            (0..=sh::MAX_DEGREE).find(|&d| 3 * (sh::basis_len(d) - 1) == n_rest).ok_or_else(|| {
                err(format!("{n_rest} 'f_rest_*' properties; expected 0, 9, 24 or 45 (SH degree 0 to 3)"))
            })?;
        let field = |name: &str| layout.find(name, err);
        let pos = [field("x")?, field("y")?, field("z")?];
        let dc = [field("f_dc_0")?, field("f_dc_1")?, field("f_dc_2")?];
        let rest: Vec<usize> = (0..n_rest).map(|j| layout.index[&format!("f_rest_{j}")]).collect();
        let opacity = field("opacity")?;
        let scale = [field("scale_0")?, field("scale_1")?, field("scale_2")?];
        let rot = [field("rot_0")?, field("rot_1")?, field("rot_2")?, field("rot_3")?];
        let k = sh::basis_len(degree);
        let n = el.count;
        let mut s = SplatScene {
            means: Vec::with_capacity(3 * n),
            quaternions: Vec::with_capacity(4 * n),
            scales: Vec::with_capacity(3 * n),
            opacities: Vec::with_capacity(n),
            sh_degree: degree,
            sh: Vec::with_capacity(3 * k * n),
        };
        let mut rec = vec![0.0f64; types.len()];
        let mut coeffs = vec![0.0f32; 3 * k];
        for v in 0..n {
            for (slot, (&ty, p)) in rec.iter_mut().zip(types.iter().zip(&el.properties)) {
                *slot = body.next(ty).map_err(|_| {
                    err(format!(
                        "vertex {v} of {n}: property '{}' is missing or not a number (truncated file?)",
                        p.name()
                    ))
                })?;
            }
            s.means.extend(pos.map(|i| rec[i] as f32));
            s.quaternions.extend(rot.map(|i| rec[i] as f32));
            s.scales.extend(scale.map(|i| rec[i].exp() as f32));
            s.opacities.push(sigmoid(rec[opacity]) as f32);
            for c in 0..3 {
                coeffs[c] = rec[dc[c]] as f32;
                for b in 1..k {
                    // f_rest is channel-major: index c·(K−1) + (b−1).
                    coeffs[3 * b + c] = rec[rest[c * (k - 1) + b - 1]] as f32;
                }
            }
            s.sh.extend_from_slice(&coeffs);
        }
        Ok(s)
    }

    /// Writes the scene as a binary little-endian INRIA `.ply`, atomically.
    pub fn write_ply(&self, path: impl AsRef<Path>) -> Result<(), SplatError> {
        self.write_ply_with(path, &[])
    }

    /// [`Self::write_ply`] with `extra` per-splat float properties (name, one value per splat)
    /// after the INRIA ones, such as the skinning of animated splats; viewers skip what they do
    /// not know.
    pub fn write_ply_with(&self, path: impl AsRef<Path>, extra: &[(&str, &[f32])]) -> Result<(), SplatError> {
        let path = path.as_ref();
        self.check_ply(extra)
            .map_err(|e| SplatError::Ply { path: path.to_path_buf(), reason: e.to_string() })?;
        mannequin_io::write_atomic_with(path, |w| self.encode_ply(w, extra))
            .map_err(|source| SplatError::Io { path: path.to_path_buf(), source })
    }

    /// The bytes [`Self::write_ply_with`] writes, for a server that sends them instead.
    pub fn ply_bytes(&self, extra: &[(&str, &[f32])]) -> Result<Vec<u8>, SplatError> {
        self.check_ply(extra)?;
        let mut bytes = Vec::new();
        self.encode_ply(&mut bytes, extra)
            .map_err(|source| SplatError::Io { path: "<memory>".into(), source })?;
        Ok(bytes)
    }

    fn check_ply(&self, extra: &[(&str, &[f32])]) -> Result<(), SplatError> {
        let n = self.len();
        let k = sh::basis_len(self.sh_degree);
        let expect = |field: &'static str, len: usize, per: usize| {
            if len == n * per {
                Ok(())
            } else {
                Err(SplatError::Shape { field, expected: n * per, found: len })
            }
        };
        expect("means", self.means.len(), 3)?;
        expect("quaternions", self.quaternions.len(), 4)?;
        expect("scales", self.scales.len(), 3)?;
        expect("SH coefficients", self.sh.len(), 3 * k)?;
        for (_, values) in extra {
            expect("extra property", values.len(), 1)?;
        }
        // A file must hold numbers: a NaN is refused here rather than handed to a viewer.
        self.gaussians().validate_values()?;
        let mut fields = vec![
            ("mean", &self.means[..], 3),
            ("rotation", &self.quaternions[..], 4),
            ("scale", &self.scales[..], 3),
            ("opacity", &self.opacities[..], 1),
            ("SH coefficient", &self.sh[..], 3 * k),
        ];
        fields.extend(extra.iter().map(|(_, values)| ("extra property", *values, 1)));
        for (field, values, per) in fields {
            if let Some(i) = values.iter().position(|v| !v.is_finite()) {
                let value = f64::from(values[i]);
                return Err(SplatError::Domain {
                    field,
                    index: i / per,
                    value,
                    expected: "expected a finite number",
                });
            }
        }
        Ok(())
    }

    fn encode_ply(&self, w: &mut dyn Write, extra: &[(&str, &[f32])]) -> std::io::Result<()> {
        let n = self.len();
        let k = sh::basis_len(self.sh_degree);
        let mut header = format!("ply\nformat binary_little_endian 1.0\nelement vertex {n}\n");
        let mut names: Vec<String> =
            ["x", "y", "z", "nx", "ny", "nz", "f_dc_0", "f_dc_1", "f_dc_2"].map(String::from).to_vec();
        names.extend((0..3 * (k - 1)).map(|j| format!("f_rest_{j}")));
        names.extend(
            ["opacity", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"]
                .map(String::from),
        );
        names.extend(extra.iter().map(|(name, _)| name.to_string()));
        for name in &names {
            header.push_str(&format!("property float {name}\n"));
        }
        header.push_str("end_header\n");
        let mut record = Vec::with_capacity(names.len());
        w.write_all(header.as_bytes())?;
        for i in 0..n {
            record.clear();
            record.extend_from_slice(&self.means[3 * i..3 * i + 3]);
            record.extend([0.0; 3]);
            let c = &self.sh[3 * k * i..3 * k * (i + 1)];
            record.extend_from_slice(&c[..3]);
            for ch in 0..3 {
                record.extend((1..k).map(|b| c[3 * b + ch]));
            }
            // Keep the logit finite for opacities of exactly 0 or 1.
            let o = (self.opacities[i] as f64).clamp(1e-7, 1.0 - 1e-7);
            record.push((o / (1.0 - o)).ln() as f32);
            record.extend(self.scales[3 * i..3 * i + 3].iter().map(|s| s.ln()));
            record.extend_from_slice(&self.quaternions[4 * i..4 * i + 4]);
            record.extend(extra.iter().map(|(_, values)| values[i]));
            for v in &record {
                w.write_all(&v.to_le_bytes())?;
            }
        }
        Ok(())
    }
}

/// Skips the records of an element that is not `vertex`.
fn skip_element(
    el: &Element,
    body: &mut PlyValues,
    err: &dyn Fn(String) -> SplatError,
) -> Result<(), SplatError> {
    let short = || err(format!("element '{}' is truncated", el.name));
    body.check_count(el).map_err(|e| err(format!("element '{}': {e}", el.name)))?;
    for _ in 0..el.count {
        for p in &el.properties {
            match p {
                Property::Scalar { ty, .. } => {
                    body.next(*ty).map_err(|_| short())?;
                }
                Property::List { count, item, .. } => {
                    let len = body.next(*count).map_err(|_| short())?;
                    if !(len >= 0.0 && len <= body.remaining() as f64) {
                        return Err(short());
                    }
                    for _ in 0..len as usize {
                        body.next(*item).map_err(|_| short())?;
                    }
                }
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scene(degree: usize) -> SplatScene {
        let k = sh::basis_len(degree);
        let n = 3;
        SplatScene {
            means: (0..3 * n).map(|i| i as f32 * 0.1 - 0.3).collect(),
            quaternions: (0..4 * n).map(|i| (i % 5) as f32 * 0.2 + 0.1).collect(),
            scales: (0..3 * n).map(|i| 0.01 + i as f32 * 0.003).collect(),
            opacities: vec![0.1, 0.5, 0.97],
            sh_degree: degree,
            sh: (0..3 * k * n).map(|i| (i as f32 * 0.37).sin()).collect(),
        }
    }

    fn close(a: &SplatScene, b: &SplatScene) {
        assert_eq!(a.sh_degree, b.sh_degree);
        for (x, y) in [(&a.means, &b.means), (&a.quaternions, &b.quaternions), (&a.sh, &b.sh)] {
            assert_eq!(x, y);
        }
        for (x, y) in a.scales.iter().zip(&b.scales).chain(a.opacities.iter().zip(&b.opacities)) {
            assert!((x - y).abs() <= 1e-6 * (1.0 + x.abs()), "{x} vs {y}");
        }
    }

    #[test]
    fn binary_round_trip_for_every_sh_degree() {
        let dir = std::env::temp_dir().join(format!("mq-splat-ply-{}", std::process::id()));
        for degree in 0..=3 {
            let s = scene(degree);
            let path = dir.join(format!("d{degree}.ply"));
            s.write_ply(&path).unwrap();
            close(&SplatScene::read_ply(&path).unwrap(), &s);
        }
        std::fs::remove_dir_all(dir).unwrap();
    }

    /// An ASCII file written by hand in the INRIA layout, with an extra element before the
    /// vertices and properties in another order, decodes to the documented activations.
    #[test]
    fn ascii_with_other_elements_and_property_order() {
        let text = "ply\nformat ascii 1.0\ncomment made by hand\nelement camera 1\nproperty list uchar float k\n\
                    element vertex 1\nproperty float opacity\nproperty double x\nproperty float y\nproperty float z\n\
                    property float f_dc_0\nproperty float f_dc_1\nproperty float f_dc_2\n\
                    property float scale_0\nproperty float scale_1\nproperty float scale_2\n\
                    property float rot_0\nproperty float rot_1\nproperty float rot_2\nproperty float rot_3\nend_header\n\
                    3 1 2 3\n0 1.5 -2 3 0.1 0.2 0.3 -1 0 1 1 0 0 0\n";
        let s = SplatScene::from_ply_bytes(Path::new("hand.ply"), text.as_bytes()).unwrap();
        assert_eq!(s.means, vec![1.5, -2.0, 3.0]);
        assert_eq!(s.opacities, vec![0.5]);
        assert_eq!(s.sh, vec![0.1, 0.2, 0.3]);
        assert!((s.scales[0] - (-1.0f32).exp()).abs() < 1e-7 && s.scales[1] == 1.0);
        assert_eq!(s.quaternions, vec![1.0, 0.0, 0.0, 0.0]);
    }

    #[test]
    fn malformed_files_name_the_file_and_the_problem() {
        let p = Path::new("bad.ply");
        let msg = |b: &[u8]| SplatScene::from_ply_bytes(p, b).unwrap_err().to_string();
        assert!(msg(b"hello").contains("bad.ply"));
        assert!(msg(b"hello").contains("'ply'"));
        assert!(msg(b"ply\nformat ascii 1.0\nelement vertex 1\n").contains("end_header"));
        let header = "ply\nformat binary_little_endian 1.0\nelement vertex 2\nproperty float x\nproperty float y\n\
                      property float z\nend_header\n";
        assert!(msg(header.as_bytes()).contains("at most 0"));
        let mut one = header.replace("vertex 2", "vertex 1").into_bytes();
        one.extend([0u8; 12]);
        assert!(msg(&one).contains("'f_dc_0'"), "{}", msg(&one));
        let typo = "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty flot x\nend_header\n";
        assert!(msg(typo.as_bytes()).contains("unknown type 'flot'"));
        let names = "x y z f_dc_0 f_dc_1 f_dc_2 opacity scale_0 scale_1 scale_2 rot_0 rot_1 rot_2 rot_3";
        let props: String = names.split(' ').map(|n| format!("property float {n}\n")).collect();
        let ascii = format!(
            "ply\nformat ascii 1.0\nelement vertex 1\n{props}end_header\n1 oops 3 0 0 0 0 0 0 0 1 0 0 0\n"
        );
        assert!(msg(ascii.as_bytes()).contains("vertex 0 of 1: property 'y'"), "{}", msg(ascii.as_bytes()));
        // A truncated binary body names the property where the data ran out.
        let s = scene(1);
        let dir = std::env::temp_dir().join(format!("mq-splat-trunc-{}", std::process::id()));
        let path = dir.join("t.ply");
        s.write_ply(&path).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let cut = &bytes[..bytes.len() - 10];
        let m = msg(cut);
        assert!(m.contains("at most 2") || m.contains("vertex 2 of 3"), "{m}");
        std::fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn non_finite_or_out_of_domain_values_are_not_written() {
        let dir = std::env::temp_dir().join(format!("mq-splat-nan-{}", std::process::id()));
        let path = dir.join("nan.ply");
        type Spoil = fn(&mut SplatScene);
        let spoil: [(&str, Spoil); 5] = [
            ("mean of Gaussian 1 is NaN", |s| s.means[4] = f32::NAN),
            ("rotation of Gaussian 2 is inf", |s| s.quaternions[8] = f32::INFINITY),
            ("SH coefficient of Gaussian 0 is -inf", |s| s.sh[1] = f32::NEG_INFINITY),
            ("opacity of Gaussian 1 is NaN", |s| s.opacities[1] = f32::NAN),
            ("scale of Gaussian 0 is 0", |s| s.scales[0] = 0.0),
        ];
        for (expected, f) in spoil {
            let mut s = scene(1);
            f(&mut s);
            let e = s.write_ply(&path).unwrap_err().to_string();
            assert!(e.starts_with(&format!("{}: {expected}", path.display())), "{e}");
            assert!(!path.exists());
            let e = s.ply_bytes(&[("joint_0", &[0.0, f32::NAN, 0.0])]).unwrap_err().to_string();
            assert!(e.starts_with(expected), "{e}");
        }
        let e = scene(0).ply_bytes(&[("joint_0", &[0.0, f32::NAN, 0.0])]).unwrap_err().to_string();
        assert_eq!(e, "extra property of Gaussian 1 is NaN: expected a finite number");
        let _ = std::fs::remove_dir_all(dir);
    }

    /// An element of no properties before the vertices cannot declare more records than the
    /// file has bytes: a huge count is refused rather than skipped one empty record at a time.
    #[test]
    fn huge_counts_of_empty_elements_are_refused() {
        let text = b"ply\nformat binary_little_endian 1.0\nelement junk 18446744073709551615\n\
                     element vertex 0\nproperty float x\nend_header\n";
        let err = SplatScene::from_ply_bytes(Path::new("e.ply"), text).unwrap_err().to_string();
        assert!(err.starts_with("e.ply: element 'junk': ") && err.contains("at most 0"), "{err}");
    }
}
