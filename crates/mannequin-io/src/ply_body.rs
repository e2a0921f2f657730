//! Sequential reading of a PLY body's values, in whichever encoding its header declares. The
//! reader decides what the values mean; this only turns bytes or words into numbers.

use crate::ply_header::{Element, Format, PlyHeader, Property, Scalar};

/// Why the next value could not be read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum PlyValueError {
    #[error("the file ends early")]
    End,
    #[error("not a number")]
    NotANumber,
    #[error("a count the {remaining} bytes left can hold (at most {most}), found {count}")]
    CountTooLarge { count: usize, most: usize, remaining: usize },
}

/// A cursor over the values that follow the header.
pub struct PlyValues<'a> {
    bytes: &'a [u8],
    at: usize,
    format: Format,
}

impl<'a> PlyValues<'a> {
    /// The body of `bytes`, the whole file that `header` was read from.
    pub fn new(bytes: &'a [u8], header: &PlyHeader) -> Self {
        Self { bytes, at: header.byte_len.min(bytes.len()), format: header.format }
    }

    pub fn format(&self) -> Format {
        self.format
    }

    /// Bytes not read yet: an upper bound on how many values can follow.
    pub fn remaining(&self) -> usize {
        self.bytes.len() - self.at
    }

    /// Refuses a record count that the bytes left cannot hold, so a reader can loop and allocate
    /// by it: a binary value takes its size, an ASCII one a digit and a separator (none after
    /// the file's last), and a record of no properties is counted as one byte.
    pub fn check_count(&self, element: &Element) -> Result<(), PlyValueError> {
        let value_len = |ty: Scalar| match self.format {
            Format::Ascii => 2,
            Format::Binary { .. } => ty.size(),
        };
        let record_len: usize = element
            .properties
            .iter()
            .map(|p| match p {
                Property::Scalar { ty, .. } => value_len(*ty),
                Property::List { count, .. } => value_len(*count),
            })
            .sum();
        let remaining = self.remaining();
        let room = remaining + usize::from(self.format == Format::Ascii && record_len > 0);
        let most = room / record_len.max(1);
        if element.count > most {
            return Err(PlyValueError::CountTooLarge { count: element.count, most, remaining });
        }
        Ok(())
    }

    /// The next value, read as type `ty` (ASCII bodies ignore the type and parse the next word).
    pub fn next(&mut self, ty: Scalar) -> Result<f64, PlyValueError> {
        let rest = &self.bytes[self.at..];
        match self.format {
            Format::Ascii => {
                let start = rest.iter().position(|c| !c.is_ascii_whitespace()).ok_or(PlyValueError::End)?;
                let len =
                    rest[start..].iter().position(|c| c.is_ascii_whitespace()).unwrap_or(rest.len() - start);
                self.at += start + len;
                let word = std::str::from_utf8(&rest[start..start + len]);
                word.ok().and_then(|w| w.parse().ok()).ok_or(PlyValueError::NotANumber)
            }
            Format::Binary { big_endian } => {
                let value = ty.decode(rest, big_endian).ok_or(PlyValueError::End)?;
                self.at += ty.size();
                Ok(value)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header(format: &str, body: &[u8]) -> Vec<u8> {
        let mut b = format!("ply\nformat {format} 1.0\nelement vertex 1\nproperty short x\nend_header\n")
            .into_bytes();
        b.extend_from_slice(body);
        b
    }

    #[test]
    fn ascii_words_parse_and_stop_at_the_end() {
        let bytes = header("ascii", b" 1.5\n-2e3\tabc 7");
        let h = PlyHeader::parse(&bytes).unwrap();
        let mut v = PlyValues::new(&bytes, &h);
        assert_eq!(v.next(Scalar::F32), Ok(1.5));
        assert_eq!(v.next(Scalar::U8), Ok(-2000.0));
        assert_eq!(v.next(Scalar::F32), Err(PlyValueError::NotANumber));
        assert_eq!(v.next(Scalar::F32), Ok(7.0));
        assert_eq!(v.remaining(), 0);
        assert_eq!(v.next(Scalar::F32), Err(PlyValueError::End));
    }

    #[test]
    fn binary_values_follow_the_declared_byte_order() {
        for (format, bytes) in
            [("binary_little_endian", [0x34, 0x12, 0xff]), ("binary_big_endian", [0x12, 0x34, 0xff])]
        {
            let file = header(format, &bytes);
            let h = PlyHeader::parse(&file).unwrap();
            let mut v = PlyValues::new(&file, &h);
            assert_eq!(v.next(Scalar::I16), Ok(0x1234 as f64), "{format}");
            assert_eq!(v.remaining(), 1);
            assert_eq!(v.next(Scalar::I16), Err(PlyValueError::End), "{format}: one byte left");
            assert_eq!(v.next(Scalar::U8), Ok(255.0), "{format}: a failed read consumes nothing");
        }
    }

    /// A count is checked against the bytes left before anyone loops by it; an element of no
    /// properties counts a byte a record, so its count is bounded too.
    #[test]
    fn counts_beyond_the_bytes_left_are_refused() {
        let ascii = b"ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n\
                      element junk 18446744073709551615\nend_header\n1 2\n3 4";
        let h = PlyHeader::parse(ascii).unwrap();
        let v = PlyValues::new(ascii, &h);
        assert_eq!(v.check_count(&h.elements[0]), Ok(()), "no separator after the last value");
        let err = v.check_count(&h.elements[1]).unwrap_err();
        assert_eq!(err, PlyValueError::CountTooLarge { count: usize::MAX, most: 7, remaining: 7 });
        assert!(err.to_string().contains("at most 7"), "{err}");
        let binary = header("binary_little_endian", &[0; 3]);
        let h = PlyHeader::parse(&binary).unwrap();
        let mut two = h.elements[0].clone();
        assert_eq!(PlyValues::new(&binary, &h).check_count(&two), Ok(()));
        two.count = 2;
        assert!(PlyValues::new(&binary, &h).check_count(&two).is_err(), "two shorts need 4 bytes");
    }
}
