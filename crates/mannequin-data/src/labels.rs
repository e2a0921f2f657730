//! Label maps: per pixel, which part of the person it shows (background, skin, hair, each
//! garment), as an 8-bit greyscale PNG whose value is the label's index; the dataset's legend
//! names the indices. NGD's garment masks (its Eq. 13) are the pixels of one label.

use std::path::Path;

use crate::error::DataError;

#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LabelMap {
    pub width: usize,
    pub height: usize,
    /// Row-major label indices.
    pub labels: Vec<u8>,
}

impl LabelMap {
    pub fn encode_png(&self) -> Vec<u8> {
        let mut out = Vec::new();
        let mut enc = png::Encoder::new(&mut out, self.width as u32, self.height as u32);
        enc.set_color(png::ColorType::Grayscale);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_compression(png::Compression::Fast);
        // Encoding into memory with a header matching the data cannot fail.
        let mut writer = enc.write_header().expect("in-memory PNG header");
        writer.write_image_data(&self.labels).expect("in-memory PNG data");
        writer.finish().expect("in-memory PNG finish");
        out
    }

    pub fn write_png(&self, path: &Path) -> Result<(), DataError> {
        mannequin_io::write_atomic(path, &self.encode_png()).map_err(|e| DataError::os(path, e))
    }

    pub fn read_png(path: &Path) -> Result<Self, DataError> {
        let bytes = std::fs::read(path).map_err(|e| DataError::os(path, e))?;
        let err = |e: png::DecodingError| DataError::file(path, format!("not a readable PNG: {e}"));
        let mut reader = png::Decoder::new(std::io::Cursor::new(bytes)).read_info().map_err(err)?;
        let info = reader.info();
        if info.color_type != png::ColorType::Grayscale || info.bit_depth != png::BitDepth::Eight {
            return Err(DataError::file(
                path,
                format!("a label map is 8-bit greyscale, this is {:?} {:?}", info.color_type, info.bit_depth),
            ));
        }
        let (width, height) = (info.width as usize, info.height as usize);
        crate::image_decode::check_size(path, width, height)?;
        let size = reader
            .output_buffer_size()
            .ok_or_else(|| DataError::file(path, "PNG dimensions are too large"))?;
        let mut labels = vec![0u8; size];
        reader.next_frame(&mut labels).map_err(err)?;
        labels.truncate(width * height);
        Ok(Self { width, height, labels })
    }

    /// Reads a label map whose legend names `legend` labels, refusing a pixel whose index is past
    /// it: a label nothing names is a broken file, not a part of the person.
    pub fn read_png_with_legend(path: &Path, legend: usize) -> Result<Self, DataError> {
        let map = Self::read_png(path)?;
        if let Some(i) = map.labels.iter().position(|&l| usize::from(l) >= legend) {
            return Err(DataError::file(
                path,
                format!(
                    "pixel {i} has label {}: expected an index into the legend's {legend} labels",
                    map.labels[i]
                ),
            ));
        }
        Ok(map)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_label_map_reads_back_as_written_and_a_colour_png_is_refused() {
        let dir = std::env::temp_dir().join(format!("mannequin-labels-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("label_0000.png");
        let map = LabelMap { width: 3, height: 2, labels: vec![0, 1, 2, 3, 4, 255] };
        map.write_png(&path).unwrap();
        assert_eq!(LabelMap::read_png(&path).unwrap(), map);
        let e = LabelMap::read_png_with_legend(&path, 5).unwrap_err().to_string();
        assert!(e.contains("label_0000.png") && e.contains("pixel 5 has label 255"), "{e}");
        assert_eq!(LabelMap::read_png_with_legend(&path, 256).unwrap(), map);
        let colour = crate::image::Image { width: 1, height: 1, pixels: vec![[0.5; 3]] };
        colour.write_png(&path).unwrap();
        let e = LabelMap::read_png(&path).unwrap_err().to_string();
        assert!(e.contains("label_0000.png") && e.contains("8-bit greyscale"), "{e}");
        std::fs::remove_dir_all(dir).unwrap();
    }
}
