// The vertex element of a binary little-endian PLY file, as one Float32Array per property: what
// a 3DGS file in the INRIA layout holds, plus any extra properties (Mannequin's skinning).
const TYPES = {
  char: ["getInt8", 1], int8: ["getInt8", 1], uchar: ["getUint8", 1], uint8: ["getUint8", 1],
  short: ["getInt16", 2], int16: ["getInt16", 2], ushort: ["getUint16", 2], uint16: ["getUint16", 2],
  int: ["getInt32", 4], int32: ["getInt32", 4], uint: ["getUint32", 4], uint32: ["getUint32", 4],
  float: ["getFloat32", 4], float32: ["getFloat32", 4], double: ["getFloat64", 8], float64: ["getFloat64", 8],
};

export function readPly(bytes, name) {
  const head = new TextDecoder().decode(bytes.subarray(0, Math.min(bytes.length, 65536)));
  const end = head.indexOf("end_header\n");
  if (!head.startsWith("ply\n") || end < 0) throw new Error(`${name}: not a PLY file`);
  if (!head.includes("format binary_little_endian 1.0")) {
    throw new Error(`${name}: expected a binary_little_endian PLY, as 3DGS tools write`);
  }
  const properties = [];
  let count = 0;
  let section = null;
  for (const line of head.slice(0, end).split("\n")) {
    const words = line.trim().split(/\s+/);
    if (words[0] === "element") {
      if (section === "vertex") break;
      if (words[1] !== "vertex") throw new Error(`${name}: element '${words[1]}' before the vertices`);
      section = "vertex";
      count = Number(words[2]);
    } else if (words[0] === "property" && section === "vertex") {
      if (!(words[1] in TYPES)) throw new Error(`${name}: vertex property '${words.at(-1)}' is not a scalar`);
      properties.push({ name: words[2], type: TYPES[words[1]] });
    }
  }
  const stride = properties.reduce((s, p) => s + p.type[1], 0);
  const body = bytes.byteOffset + end + "end_header\n".length;
  if (bytes.length - (end + 11) < count * stride) throw new Error(`${name}: ${count} vertices but the file is truncated`);
  const view = new DataView(bytes.buffer, body, count * stride);
  const columns = {};
  let offset = 0;
  for (const p of properties) {
    const column = new Float32Array(count);
    const [getter, size] = p.type;
    for (let i = 0, at = offset; i < count; i++, at += stride) column[i] = view[getter](at, true);
    columns[p.name] = column;
    offset += size;
  }
  return { count, columns };
}
