//! Reading image files as PNG or JPEG, told apart by their first bytes rather than their
//! extension (captures renamed by hand, or exported by tools that pick their own suffix, still
//! read). Values are `byte / 255` (`/ 65535` for 16-bit PNG), with no gamma conversion.

use std::io::{BufReader, Cursor};
use std::path::Path;

use zune_jpeg::JpegDecoder;
use zune_jpeg::zune_core::bytestream::ZCursor;
use zune_jpeg::zune_core::colorspace::ColorSpace;
use zune_jpeg::zune_core::options::DecoderOptions;

use mannequin_io::limits::check_image_size;

use crate::error::DataError;
use crate::image::Image;

const PNG_SIGNATURE: &[u8] = b"\x89PNG\r\n\x1a\n";
/// Start-of-image marker followed by the first marker's lead byte.
const JPEG_SIGNATURE: &[u8] = &[0xFF, 0xD8, 0xFF];

/// The encodings an image file may hold.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageFormat {
    Png,
    Jpeg,
}

impl ImageFormat {
    /// The format the bytes start with, if any.
    pub fn sniff(bytes: &[u8]) -> Option<Self> {
        if bytes.starts_with(PNG_SIGNATURE) {
            Some(Self::Png)
        } else if bytes.starts_with(JPEG_SIGNATURE) {
            Some(Self::Jpeg)
        } else {
            None
        }
    }
}

/// What a file that is neither format starts with, for the error message.
fn describe_start(bytes: &[u8]) -> String {
    if bytes.is_empty() {
        return "an empty file".into();
    }
    let head: Vec<String> = bytes.iter().take(8).map(|b| format!("{b:02x}")).collect();
    format!("bytes {}", head.join(" "))
}

/// Refuses an image whose header claims no pixels, or more than
/// [`mannequin_io::limits::check_image_size`] allows, before its pixels are allocated: a
/// 74-byte PNG may claim 65535×65535.
pub(crate) fn check_size(path: &Path, width: usize, height: usize) -> Result<(), DataError> {
    if width == 0 || height == 0 {
        return Err(DataError::file(path, format!("image size {width}×{height} is empty")));
    }
    check_image_size(width, height).map_err(|e| DataError::file(path, e))
}

impl Image {
    /// Decodes a PNG or a JPEG, whichever the bytes hold; `path` names the file in errors.
    pub fn decode(path: &Path, bytes: &[u8]) -> Result<Self, DataError> {
        match ImageFormat::sniff(bytes) {
            Some(ImageFormat::Png) => Self::decode_png(path, bytes),
            Some(ImageFormat::Jpeg) => Self::decode_jpeg(path, bytes),
            None => Err(DataError::file(
                path,
                format!("expected a PNG or JPEG image, found {}", describe_start(bytes)),
            )),
        }
    }

    /// The width and height a PNG or JPEG file's header gives, checked against the limits,
    /// without decoding its pixels: for checking that a clip's frames agree before any work.
    pub fn read_size(path: &Path) -> Result<(usize, usize), DataError> {
        let bytes = std::fs::read(path).map_err(|e| DataError::os(path, e))?;
        let (w, h) = match ImageFormat::sniff(&bytes) {
            Some(ImageFormat::Png) => {
                let reader = png::Decoder::new(Cursor::new(&bytes))
                    .read_info()
                    .map_err(|e| DataError::file(path, format!("not a readable PNG: {e}")))?;
                (reader.info().width as usize, reader.info().height as usize)
            }
            Some(ImageFormat::Jpeg) => {
                let mut decoder = JpegDecoder::new(ZCursor::new(&bytes));
                decoder
                    .decode_headers()
                    .map_err(|e| DataError::file(path, format!("not a readable JPEG: {e}")))?;
                decoder
                    .dimensions()
                    .ok_or_else(|| DataError::file(path, "not a readable JPEG: no frame header"))?
            }
            None => return Self::decode(path, &bytes).map(|i| (i.width, i.height)),
        };
        check_size(path, w, h)?;
        Ok((w, h))
    }

    /// Reads a PNG or JPEG file (see [`Image::decode`]).
    pub fn read(path: &Path) -> Result<Self, DataError> {
        let bytes = std::fs::read(path).map_err(|e| DataError::os(path, e))?;
        Self::decode(path, &bytes)
    }

    /// Decodes an 8- or 16-bit PNG of any colour type; alpha is dropped, grey is replicated.
    /// JPEG data is refused by name, for files that must be lossless (normal maps).
    pub fn decode_png(path: &Path, bytes: &[u8]) -> Result<Self, DataError> {
        if ImageFormat::sniff(bytes) == Some(ImageFormat::Jpeg) {
            return Err(DataError::file(
                path,
                "expected a PNG, found JPEG data (this file must be lossless)",
            ));
        }
        let err = |e: png::DecodingError| DataError::file(path, format!("not a readable PNG: {e}"));
        let mut decoder = png::Decoder::new(BufReader::new(Cursor::new(bytes)));
        decoder.set_transformations(png::Transformations::EXPAND);
        let mut reader = decoder.read_info().map_err(err)?;
        check_size(path, reader.info().width as usize, reader.info().height as usize)?;
        let size = reader
            .output_buffer_size()
            .ok_or_else(|| DataError::file(path, "PNG dimensions are too large"))?;
        let mut buf = vec![0u8; size];
        let info = reader.next_frame(&mut buf).map_err(err)?;
        let (w, h) = (info.width as usize, info.height as usize);
        let channels = info.color_type.samples();
        let sixteen = info.bit_depth == png::BitDepth::Sixteen;
        let sample = |i: usize| -> f32 {
            if sixteen {
                u16::from_be_bytes([buf[2 * i], buf[2 * i + 1]]) as f32 / 65535.0
            } else {
                buf[i] as f32 / 255.0
            }
        };
        let pixels = (0..w * h)
            .map(|p| {
                let base = p * channels;
                if channels >= 3 {
                    [sample(base), sample(base + 1), sample(base + 2)]
                } else {
                    [sample(base); 3]
                }
            })
            .collect();
        Ok(Self { width: w, height: h, pixels })
    }

    /// Reads a PNG file (see [`Image::decode_png`]).
    pub fn read_png(path: &Path) -> Result<Self, DataError> {
        let bytes = std::fs::read(path).map_err(|e| DataError::os(path, e))?;
        Self::decode_png(path, &bytes)
    }

    /// Decodes a baseline or progressive JPEG, grey or colour, to 8-bit RGB.
    fn decode_jpeg(path: &Path, bytes: &[u8]) -> Result<Self, DataError> {
        let err =
            |e: zune_jpeg::errors::DecodeErrors| DataError::file(path, format!("not a readable JPEG: {e}"));
        // Strict: a truncated or corrupt file is an error, not grey blocks to train on.
        let options =
            DecoderOptions::default().jpeg_set_out_colorspace(ColorSpace::RGB).set_strict_mode(true);
        let mut decoder = JpegDecoder::new_with_options(ZCursor::new(bytes), options);
        decoder.decode_headers().map_err(err)?;
        let (w, h) = decoder
            .dimensions()
            .ok_or_else(|| DataError::file(path, "not a readable JPEG: no frame header"))?;
        check_size(path, w, h)?;
        let rgb = decoder.decode().map_err(err)?;
        let pixels = rgb.chunks_exact(3).map(|p| [p[0], p[1], p[2]].map(|b| b as f32 / 255.0)).collect();
        Ok(Self { width: w, height: h, pixels })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn garbage_names_the_file_and_both_formats() {
        let err = Image::decode(Path::new("images/image_0003.jpg"), b"GIF89a..").unwrap_err().to_string();
        assert!(err.contains("images/image_0003.jpg") && err.contains("PNG or JPEG"), "{err}");
        assert!(err.contains("47 49 46 38"), "{err}");
        let err = Image::decode_png(Path::new("images/image_0003.png"), b"nope").unwrap_err().to_string();
        assert!(err.contains("images/image_0003.png"), "{err}");
    }

    #[test]
    fn a_truncated_jpeg_is_an_error_naming_the_file() {
        let err =
            Image::decode(Path::new("x.jpg"), &[0xFF, 0xD8, 0xFF, 0xE0, 0, 16]).unwrap_err().to_string();
        assert!(err.contains("x.jpg") && err.contains("JPEG"), "{err}");
    }
}
