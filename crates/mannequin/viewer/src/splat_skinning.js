// Reads the skinning Mannequin writes beside a 3DGS .ply's splats (docs/viewer.md): the float
// vertex properties joint_0..3 (joint indices) and weight_0..3, in a binary little-endian file.
const SIZES = { char: 1, uchar: 1, int8: 1, uint8: 1, short: 2, ushort: 2, int16: 2, uint16: 2,
  int: 4, uint: 4, int32: 4, uint32: 4, float: 4, float32: 4, double: 8, float64: 8 };

export function readSkinning(bytes, name) {
  const head = new TextDecoder().decode(bytes.subarray(0, Math.min(bytes.length, 65536)));
  const end = head.indexOf("end_header\n");
  if (!head.startsWith("ply\n") || end < 0) throw new Error(`${name}: not a PLY file`);
  if (!head.includes("format binary_little_endian 1.0")) {
    throw new Error(`${name}: skinned splats must be binary_little_endian`);
  }
  let count = 0;
  let inVertex = false;
  let stride = 0;
  const offsets = new Map();
  for (const line of head.slice(0, end).split("\n")) {
    const words = line.trim().split(/\s+/);
    if (words[0] === "element") {
      if (inVertex) break;
      inVertex = words[1] === "vertex";
      count = Number(words[2]);
    } else if (words[0] === "property" && inVertex) {
      if (!(words[1] in SIZES)) throw new Error(`${name}: vertex property '${words[2]}' has type ${words[1]}`);
      offsets.set(words[2], { at: stride, type: words[1] });
      stride += SIZES[words[1]];
    }
  }
  const names = [0, 1, 2, 3].flatMap((k) => [`joint_${k}`, `weight_${k}`]);
  for (const n of names) {
    if (offsets.get(n)?.type !== "float") throw new Error(`${name}: no float vertex property '${n}'`);
  }
  const view = new DataView(bytes.buffer, bytes.byteOffset + end + "end_header\n".length);
  if (view.byteLength < count * stride) throw new Error(`${name}: ${count} splats but the file is truncated`);
  const joints = new Uint16Array(4 * count);
  const weights = new Float32Array(4 * count);
  for (let i = 0; i < count; i++) {
    for (let k = 0; k < 4; k++) {
      joints[4 * i + k] = view.getFloat32(i * stride + offsets.get(`joint_${k}`).at, true);
      weights[4 * i + k] = view.getFloat32(i * stride + offsets.get(`weight_${k}`).at, true);
    }
  }
  return { count, joints, weights };
}
