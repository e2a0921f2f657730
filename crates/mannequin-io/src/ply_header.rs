//! The header of a Polygon File Format (`.ply`) file: its encoding, and its elements with their
//! properties and scalar types. Meshes and Gaussian splats both use PLY, and each reader wants
//! different properties, so this reads only the header and leaves the body to the reader (see
//! [`crate::ply_body`]).

/// A PLY property type, under either its classic name (`uchar`) or its sized one (`uint8`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    pub fn parse(name: &str) -> Option<Self> {
        Some(match name {
            "char" | "int8" => Self::I8,
            "uchar" | "uint8" => Self::U8,
            "short" | "int16" => Self::I16,
            "ushort" | "uint16" => Self::U16,
            "int" | "int32" => Self::I32,
            "uint" | "uint32" => Self::U32,
            "float" | "float32" => Self::F32,
            "double" | "float64" => Self::F64,
            _ => return None,
        })
    }

    /// Bytes one value takes in a binary body.
    pub fn size(self) -> usize {
        match self {
            Self::I8 | Self::U8 => 1,
            Self::I16 | Self::U16 => 2,
            Self::I32 | Self::U32 | Self::F32 => 4,
            Self::F64 => 8,
        }
    }

    /// Decodes one binary value from the front of `bytes`; `None` when fewer than
    /// [`Scalar::size`] bytes are left. Every PLY type fits an `f64` exactly.
    pub fn decode(self, bytes: &[u8], big_endian: bool) -> Option<f64> {
        macro_rules! num {
            ($t:ty) => {{
                let a = bytes.get(..size_of::<$t>())?.try_into().ok()?;
                (if big_endian { <$t>::from_be_bytes(a) } else { <$t>::from_le_bytes(a) }) as f64
            }};
        }
        Some(match self {
            Self::I8 => num!(i8),
            Self::U8 => num!(u8),
            Self::I16 => num!(i16),
            Self::U16 => num!(u16),
            Self::I32 => num!(i32),
            Self::U32 => num!(u32),
            Self::F32 => num!(f32),
            Self::F64 => num!(f64),
        })
    }
}

/// How the body is encoded.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    Ascii,
    Binary { big_endian: bool },
}

#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Property {
    Scalar {
        name: String,
        ty: Scalar,
    },
    /// A length of type `count`, then that many values of type `item` (e.g. a face's corners).
    List {
        name: String,
        count: Scalar,
        item: Scalar,
    },
}

impl Property {
    pub fn name(&self) -> &str {
        match self {
            Self::Scalar { name, .. } | Self::List { name, .. } => name,
        }
    }
}

/// `count` records, each holding `properties` in order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Element {
    pub name: String,
    /// As the file declares it: untrusted, so readers must not allocate by it unchecked.
    pub count: usize,
    pub properties: Vec<Property>,
}

#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PlyHeader {
    pub format: Format,
    pub elements: Vec<Element>,
    /// Bytes up to and including the `end_header` line break: where the body starts.
    pub byte_len: usize,
}

/// What is wrong with a header, saying what was expected; readers add the file name.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PlyHeaderError {
    #[error("not a PLY file: expected the magic line 'ply' first")]
    NotPly,
    #[error("no 'end_header' line: not a PLY file, or a truncated one")]
    NoEndHeader,
    #[error("header line {line} is not text")]
    NotText { line: usize },
    #[error("unknown format '{format}': expected ascii, binary_little_endian or binary_big_endian")]
    UnknownFormat { format: String },
    #[error("element '{element}' has a bad count '{count}': expected a whole number")]
    BadCount { element: String, count: String },
    #[error("property '{property}' comes before any element")]
    PropertyBeforeElement { property: String },
    #[error(
        "property '{property}': unknown type '{ty}': expected char, uchar, short, ushort, int, uint, \
         float or double (or int8 ... float64)"
    )]
    UnknownType { property: String, ty: String },
    #[error("cannot parse header line '{line}': expected format, element, property or comment")]
    BadLine { line: String },
    #[error("no 'format' line in the header")]
    NoFormat,
}

impl PlyHeader {
    /// Reads the header at the start of `bytes`, which may hold the whole file.
    pub fn parse(bytes: &[u8]) -> Result<Self, PlyHeaderError> {
        if !bytes.starts_with(b"ply") {
            return Err(PlyHeaderError::NotPly);
        }
        let mut format = None;
        let mut elements: Vec<Element> = Vec::new();
        let mut at = 0;
        for number in 1.. {
            // Every header line, `end_header` included, ends with a line break (\n or \r\n).
            let len = bytes[at..].iter().position(|&b| b == b'\n').ok_or(PlyHeaderError::NoEndHeader)?;
            let line = std::str::from_utf8(&bytes[at..at + len])
                .map_err(|_| PlyHeaderError::NotText { line: number })?
                .trim();
            at += len + 1;
            let words: Vec<&str> = line.split_whitespace().collect();
            match words.as_slice() {
                ["ply"] if number == 1 => {}
                _ if number == 1 => return Err(PlyHeaderError::NotPly),
                ["end_header"] => break,
                [] | ["comment", ..] | ["obj_info", ..] => {}
                ["format", f, _version] => {
                    format = Some(match *f {
                        "ascii" => Format::Ascii,
                        "binary_little_endian" => Format::Binary { big_endian: false },
                        "binary_big_endian" => Format::Binary { big_endian: true },
                        other => return Err(PlyHeaderError::UnknownFormat { format: other.into() }),
                    })
                }
                ["element", name, count] => elements.push(Element {
                    name: name.to_string(),
                    count: count.parse().map_err(|_| PlyHeaderError::BadCount {
                        element: name.to_string(),
                        count: count.to_string(),
                    })?,
                    properties: Vec::new(),
                }),
                ["property", "list", count, item, name] => {
                    let count = scalar(count, name)?;
                    let item = scalar(item, name)?;
                    last(&mut elements, name)?.properties.push(Property::List {
                        name: name.to_string(),
                        count,
                        item,
                    });
                }
                ["property", ty, name] => {
                    let ty = scalar(ty, name)?;
                    last(&mut elements, name)?
                        .properties
                        .push(Property::Scalar { name: name.to_string(), ty });
                }
                _ => return Err(PlyHeaderError::BadLine { line: line.to_string() }),
            }
        }
        Ok(Self { format: format.ok_or(PlyHeaderError::NoFormat)?, elements, byte_len: at })
    }
}

fn scalar(ty: &str, property: &str) -> Result<Scalar, PlyHeaderError> {
    Scalar::parse(ty)
        .ok_or_else(|| PlyHeaderError::UnknownType { property: property.to_string(), ty: ty.to_string() })
}

/// The element a `property` line belongs to: the last one declared.
fn last<'a>(elements: &'a mut [Element], property: &str) -> Result<&'a mut Element, PlyHeaderError> {
    elements
        .last_mut()
        .ok_or_else(|| PlyHeaderError::PropertyBeforeElement { property: property.to_string() })
}

#[cfg(test)]
mod tests {
    use super::*;

    const MESH: &str = "ply\nformat ascii 1.0\ncomment hand made\nelement vertex 4\nproperty double x\n\
                        property float32 y\nproperty uchar red\nelement face 2\n\
                        property list uchar int vertex_indices\nend_header\n0 0 0 255\n";

    #[test]
    fn ascii_header_lists_elements_properties_and_where_the_body_starts() {
        let h = PlyHeader::parse(MESH.as_bytes()).unwrap();
        assert_eq!(h.format, Format::Ascii);
        assert_eq!(h.byte_len, MESH.find("0 0 0 255").unwrap());
        let scalar = |name: &str, ty| Property::Scalar { name: name.into(), ty };
        assert_eq!(
            h.elements,
            vec![
                Element {
                    name: "vertex".into(),
                    count: 4,
                    properties: vec![
                        scalar("x", Scalar::F64),
                        scalar("y", Scalar::F32),
                        scalar("red", Scalar::U8)
                    ],
                },
                Element {
                    name: "face".into(),
                    count: 2,
                    properties: vec![Property::List {
                        name: "vertex_indices".into(),
                        count: Scalar::U8,
                        item: Scalar::I32,
                    }],
                },
            ]
        );
        assert_eq!(h.elements[1].properties[0].name(), "vertex_indices");
    }

    /// Binary headers, with either endianness and Windows line breaks, end right after the
    /// `end_header` line break even when the body bytes that follow look like text.
    #[test]
    fn binary_header_ends_at_its_line_break() {
        for (f, big_endian) in [("binary_little_endian", false), ("binary_big_endian", true)] {
            let head =
                format!("ply\r\nformat {f} 1.0\r\nelement vertex 1\r\nproperty float x\r\nend_header\r\n");
            let mut bytes = head.clone().into_bytes();
            bytes.extend(b"\nend_header\n\x00\xff");
            let h = PlyHeader::parse(&bytes).unwrap();
            assert_eq!(h.format, Format::Binary { big_endian });
            assert_eq!(h.byte_len, head.len());
            assert_eq!(h.elements[0].count, 1);
        }
    }

    #[test]
    fn bad_headers_say_what_was_expected() {
        let err = |s: &str| PlyHeader::parse(s.as_bytes()).unwrap_err();
        assert_eq!(err("plx\n"), PlyHeaderError::NotPly);
        assert_eq!(err("plyfoo\nend_header\n"), PlyHeaderError::NotPly);
        assert_eq!(err("ply\nformat ascii 1.0\nelement vertex 1\n"), PlyHeaderError::NoEndHeader);
        assert_eq!(err("ply\nformat ascii 1.0\nend_header"), PlyHeaderError::NoEndHeader);
        let typo = err("ply\nformat ascii 1.0\nelement vertex 1\nproperty flot x\nend_header\n");
        assert_eq!(typo, PlyHeaderError::UnknownType { property: "x".into(), ty: "flot".into() });
        assert!(typo.to_string().contains("unknown type 'flot'"), "{typo}");
        let list =
            err("ply\nformat ascii 1.0\nelement face 1\nproperty list uchar integer idx\nend_header\n");
        assert_eq!(list, PlyHeaderError::UnknownType { property: "idx".into(), ty: "integer".into() });
        assert_eq!(
            err("ply\nformat text 1.0\nend_header\n"),
            PlyHeaderError::UnknownFormat { format: "text".into() }
        );
        assert_eq!(
            err("ply\nformat ascii 1.0\nelement vertex -1\nend_header\n"),
            PlyHeaderError::BadCount { element: "vertex".into(), count: "-1".into() }
        );
        assert_eq!(
            err("ply\nformat ascii 1.0\nproperty float x\nend_header\n"),
            PlyHeaderError::PropertyBeforeElement { property: "x".into() }
        );
        assert_eq!(
            err("ply\nformat ascii 1.0\nvertex 3\nend_header\n"),
            PlyHeaderError::BadLine { line: "vertex 3".into() }
        );
        assert_eq!(err("ply\nelement vertex 0\nend_header\n"), PlyHeaderError::NoFormat);
        assert_eq!(
            PlyHeader::parse(b"ply\ncomment \xff\nend_header\n"),
            Err(PlyHeaderError::NotText { line: 2 })
        );
    }

    /// Every cut of a valid header is an error (it has no `end_header` line yet), never a panic.
    #[test]
    fn truncated_headers_are_errors() {
        let header = &MESH.as_bytes()[..MESH.find("0 0 0").unwrap()];
        for cut in 0..header.len() {
            let err = PlyHeader::parse(&header[..cut]).unwrap_err();
            let want = if cut < 3 { PlyHeaderError::NotPly } else { PlyHeaderError::NoEndHeader };
            assert_eq!(err, want, "cut at {cut}");
        }
        assert!(PlyHeader::parse(header).is_ok());
    }

    /// Reference bytes come from the standard library's own encoders.
    #[test]
    fn scalars_decode_in_both_byte_orders() {
        let cases: [(Scalar, f64, Vec<u8>, Vec<u8>); 8] = [
            (Scalar::I8, -5.0, (-5i8).to_le_bytes().into(), (-5i8).to_be_bytes().into()),
            (Scalar::U8, 250.0, vec![250], vec![250]),
            (Scalar::I16, -300.0, (-300i16).to_le_bytes().into(), (-300i16).to_be_bytes().into()),
            (Scalar::U16, 65000.0, 65000u16.to_le_bytes().into(), 65000u16.to_be_bytes().into()),
            (Scalar::I32, -70000.0, (-70000i32).to_le_bytes().into(), (-70000i32).to_be_bytes().into()),
            (Scalar::U32, 4e9, 4_000_000_000u32.to_le_bytes().into(), 4_000_000_000u32.to_be_bytes().into()),
            (Scalar::F32, 0.25, 0.25f32.to_le_bytes().into(), 0.25f32.to_be_bytes().into()),
            (Scalar::F64, -1e300, (-1e300f64).to_le_bytes().into(), (-1e300f64).to_be_bytes().into()),
        ];
        for (ty, want, le, be) in cases {
            assert_eq!(ty.size(), le.len());
            assert_eq!(ty.decode(&le, false), Some(want), "{ty:?} little endian");
            assert_eq!(ty.decode(&be, true), Some(want), "{ty:?} big endian");
            assert_eq!(ty.decode(&le[..le.len() - 1], false), None, "{ty:?} short");
        }
        assert_eq!(Scalar::parse("uint8"), Some(Scalar::U8));
        assert_eq!(Scalar::parse("float64"), Some(Scalar::F64));
        assert_eq!(Scalar::parse("half"), None);
    }
}
