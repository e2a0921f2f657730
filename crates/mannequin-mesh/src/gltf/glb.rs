//! The GLB container: a 12-byte header, then a JSON chunk and a binary chunk, each padded to a
//! multiple of 4 bytes (JSON with spaces, binary with zeros) as the glTF 2.0 spec requires.

const MAGIC: &[u8; 4] = b"glTF";
const JSON_CHUNK: &[u8; 4] = b"JSON";
const BIN_CHUNK: &[u8; 4] = b"BIN\0";

pub(crate) fn glb(json: &[u8], bin: &[u8]) -> Vec<u8> {
    let padded = |n: usize| n.next_multiple_of(4);
    let total = 12 + 8 + padded(json.len()) + 8 + padded(bin.len());
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(MAGIC);
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    for (kind, data, pad) in [(JSON_CHUNK, json, b' '), (BIN_CHUNK, bin, 0u8)] {
        out.extend_from_slice(&(padded(data.len()) as u32).to_le_bytes());
        out.extend_from_slice(kind);
        out.extend_from_slice(data);
        out.resize(out.len() + padded(data.len()) - data.len(), pad);
    }
    out
}
