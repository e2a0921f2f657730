// 3D Gaussian splats drawn the way Mannequin's own renderer draws them (3DGS: EWA projection of
// each covariance, a low-pass dilation in pixels², back-to-front "over" compositing), optionally
// skinned to a skeleton. The per-splat work (skinning, projection, colour from spherical
// harmonics, a depth sort) runs in JavaScript when the pose or the view changes, and the GPU
// only draws one triangle per splat with a trivial shader: on software WebGL that is what makes
// a 40k-splat avatar animate (Spark, which regenerates, reads back and sorts every splat for each
// pose, drew 1.4 frames per second on SwiftShader and 7 on llvmpipe; docs/viewer.md).
import * as THREE from "three";

const SH_C0 = 0.28209479177387814;
const SH_C1 = 0.4886025119029199;
const SH_C2 = [1.0925484305920792, -1.0925484305920792, 0.31539156525252005, -1.0925484305920792, 0.5462742152960396];
/// The quad reaches this many standard deviations; 3DGS cuts its footprint at 3σ too.
const EXTENT = 3;
/// Floats per corner of a drawn splat: NDC centre, footprint axes, colour and opacity.
const STRIDE = 11;

const VERTEX = /* glsl */ `
  attribute vec3 center;   // NDC
  attribute vec4 axes;     // the footprint's half-axes at EXTENT σ, in pixels (x right, y down)
  attribute vec4 colour;   // linear RGB and opacity
  uniform vec2 viewport;
  varying vec2 corner;
  varying vec4 vColour;
  void main() {
    vec2 offset = position.x * axes.xy + position.y * axes.zw;
    gl_Position = vec4(center.xy + vec2(2.0, -2.0) * offset / viewport, center.z, 1.0);
    corner = position.xy;
    vColour = colour;
  }`;

const FRAGMENT = /* glsl */ `
  varying vec2 corner;
  varying vec4 vColour;
  void main() {
    float alpha = min(0.99, vColour.a * exp(-0.5 * ${(EXTENT * EXTENT).toFixed(1)} * dot(corner, corner)));
    if (alpha < 1.0 / 255.0) discard;
    gl_FragColor = vec4(vColour.rgb * alpha, alpha);
  }`;

/// Splats from a PLY's columns (readPly): means, covariances from scale and rotation, opacity,
/// SH colour (degree ≤ 2 used), and skinning where joint_0..3 / weight_0..3 are present.
export class GaussianSplats extends THREE.Mesh {
  constructor(count, columns, { dilation = 0.3 } = {}) {
    // A plain triangle list, each splat's record repeated at its three corners: SwiftShader
    // draws the same splats as instances thirty times slower.
    const geometry = new THREE.BufferGeometry();
    // One triangle around the unit circle (the footprint at EXTENT σ) rather than a quad: a
    // software rasteriser's cost is per triangle more than per pixel, and this halves them.
    const h = Math.sqrt(3);
    const corners = new Float32Array(9 * count);
    for (let i = 0; i < count; i++) corners.set([0, 2, 0, -h, -1, 0, h, -1, 0], 9 * i);
    geometry.setAttribute("position", new THREE.BufferAttribute(corners, 3));
    // One interleaved record per corner of each drawn splat: centre (3), axes (4), colour (4).
    const records = new THREE.InterleavedBuffer(new Float32Array(3 * count * STRIDE), STRIDE).setUsage(THREE.DynamicDrawUsage);
    geometry.setAttribute("center", new THREE.InterleavedBufferAttribute(records, 3, 0));
    geometry.setAttribute("axes", new THREE.InterleavedBufferAttribute(records, 4, 3));
    geometry.setAttribute("colour", new THREE.InterleavedBufferAttribute(records, 4, 7));
    geometry.setDrawRange(0, 0);
    const material = new THREE.ShaderMaterial({
      vertexShader: VERTEX,
      fragmentShader: FRAGMENT,
      uniforms: { viewport: { value: new THREE.Vector2(1, 1) } },
      transparent: true,
      depthWrite: false,
      // The footprint's axes are in pixels with y down, which can mirror the quad.
      side: THREE.DoubleSide,
      blending: THREE.CustomBlending,
      blendSrc: THREE.OneFactor,
      blendDst: THREE.OneMinusSrcAlphaFactor,
      blendSrcAlpha: THREE.OneFactor,
      blendDstAlpha: THREE.OneMinusSrcAlphaFactor,
    });
    super(geometry, material);
    this.frustumCulled = false;
    this.splatCount = count;
    this.dilation = dilation;
    this.means = interleave(count, columns, ["x", "y", "z"]);
    // Bounds are the means', not the drawing triangle's, for framing and culling.
    geometry.boundingBox = new THREE.Box3().setFromArray(this.means);
    geometry.boundingSphere = geometry.boundingBox.getBoundingSphere(new THREE.Sphere());
    this.covariances = covariances(count, columns);
    this.opacities = columns.opacity.map((o) => 1 / (1 + Math.exp(-o)));
    this.sh = harmonics(count, columns);
    this.skin = columns.joint_0 ? { joints: interleave(count, columns, ["joint_0", "joint_1", "joint_2", "joint_3"]),
      weights: interleave(count, columns, ["weight_0", "weight_1", "weight_2", "weight_3"]) } : null;
    this.posedMeans = new Float32Array(3 * count);
    this.posedCov = new Float32Array(6 * count);
    this.depth = new Float32Array(count);
    this.visibleIndex = new Uint32Array(count);
    this.order = new Uint32Array(count);
    this.unsorted = { centre: new Float32Array(3 * count), axes: new Float32Array(4 * count), colour: new Float32Array(4 * count) };
    this.drawn = 0;
    this.blend = new Float64Array(12);
    this.camCov = new Float64Array(6);
    this.basis = new Float64Array(9);
    this.bones = null;
    this.key = "";
  }

  /// Skinning matrices (THREE.Matrix4 per joint, bind → posed) the splats follow, or null.
  setBones(bones) {
    this.bones = bones;
    this.key = "";
  }

  /// Recomputes what is drawn for `camera` on a `width`×`height` canvas when the pose or the
  /// view changed since the last call.
  update(camera, width, height) {
    const key = `${camera.matrixWorld.elements.join()}|${camera.projectionMatrix.elements.join()}|${width}x${height}|${this.poseVersion ?? 0}`;
    if (key === this.key) return;
    this.key = key;
    this.pose();
    this.project(camera, width, height);
  }

  /// Marks the bones as moved.
  bonesMoved() {
    this.poseVersion = (this.poseVersion ?? 0) + 1;
  }

  pose() {
    const { splatCount: count, means, covariances: cov, posedMeans: m, posedCov: c } = this;
    if (!this.skin || !this.bones) {
      m.set(means);
      c.set(cov);
      return;
    }
    const { joints, weights } = this.skin;
    const bones = this.bones.map((b) => b.elements);
    const a = this.blend;
    for (let i = 0; i < count; i++) {
      a.fill(0);
      for (let k = 0; k < 4; k++) {
        const w = weights[4 * i + k];
        if (w === 0) continue;
        const e = bones[joints[4 * i + k]];
        // Column-major 4×4 → the rows of the 3×4 [A | t].
        a[0] += w * e[0]; a[1] += w * e[4]; a[2] += w * e[8]; a[3] += w * e[12];
        a[4] += w * e[1]; a[5] += w * e[5]; a[6] += w * e[9]; a[7] += w * e[13];
        a[8] += w * e[2]; a[9] += w * e[6]; a[10] += w * e[10]; a[11] += w * e[14];
      }
      const x = means[3 * i];
      const y = means[3 * i + 1];
      const z = means[3 * i + 2];
      m[3 * i] = a[0] * x + a[1] * y + a[2] * z + a[3];
      m[3 * i + 1] = a[4] * x + a[5] * y + a[6] * z + a[7];
      m[3 * i + 2] = a[8] * x + a[9] * y + a[10] * z + a[11];
      transformCovariance(cov, 6 * i, a, 4, c, 6 * i);
    }
  }

  project(camera, width, height) {
    const { splatCount: count, posedMeans: m, posedCov: c, depth, visibleIndex, unsorted, sh, opacities } = this;
    const v = camera.matrixWorldInverse.elements;
    const p = camera.projectionMatrix.elements;
    const fx = (p[0] * width) / 2;
    const fy = (p[5] * height) / 2;
    // World → camera in OpenCV axes (x right, y down, z forward): the rows of diag(1, −1, −1)·V.
    const w = new Float64Array([v[0], v[4], v[8], -v[1], -v[5], -v[9], -v[2], -v[6], -v[10]]);
    const eye = new THREE.Vector3().setFromMatrixPosition(camera.matrixWorld);
    const camCov = this.camCov;
    const basis = this.basis;
    let visible = 0;
    for (let i = 0; i < count; i++) {
      const x = m[3 * i];
      const y = m[3 * i + 1];
      const z = m[3 * i + 2];
      // three.js camera space (y up, looking down −z); OpenCV's is (cx, −cy, −cz).
      const cx = v[0] * x + v[4] * y + v[8] * z + v[12];
      const cy = v[1] * x + v[5] * y + v[9] * z + v[13];
      const cz = v[2] * x + v[6] * y + v[10] * z + v[14];
      const tx = cx;
      const ty = -cy;
      const tz = -cz;
      if (tz < 0.01) continue;
      const cw = p[3] * cx + p[7] * cy + p[11] * cz + p[15];
      const ndcX = (p[0] * cx + p[4] * cy + p[8] * cz + p[12]) / cw;
      const ndcY = (p[1] * cx + p[5] * cy + p[9] * cz + p[13]) / cw;
      if (Math.abs(ndcX) > 1.3 || Math.abs(ndcY) > 1.3) continue;
      const ndcZ = (p[2] * cx + p[6] * cy + p[10] * cz + p[14]) / cw;
      transformCovariance(c, 6 * i, w, 3, camCov, 0);
      // EWA: J Σ Jᵀ with J = [[fx/z, 0, −fx x/z²], [0, fy/z, −fy y/z²]], plus the dilation.
      const j00 = fx / tz;
      const j02 = (-fx * tx) / (tz * tz);
      const j11 = fy / tz;
      const j12 = (-fy * ty) / (tz * tz);
      const s00 = camCov[0];
      const s01 = camCov[1];
      const s02 = camCov[2];
      const s11 = camCov[3];
      const s12 = camCov[4];
      const s22 = camCov[5];
      const a = j00 * j00 * s00 + 2 * j00 * j02 * s02 + j02 * j02 * s22 + this.dilation;
      const b = j00 * j11 * s01 + j00 * j12 * s02 + j02 * j11 * s12 + j02 * j12 * s22;
      const d = j11 * j11 * s11 + 2 * j11 * j12 * s12 + j12 * j12 * s22 + this.dilation;
      // Eigen-axes of [[a, b], [b, d]], scaled to EXTENT standard deviations.
      const mid = 0.5 * (a + d);
      const r = Math.sqrt(Math.max(0, 0.25 * (a - d) * (a - d) + b * b));
      const l1 = mid + r;
      const l2 = Math.max(mid - r, 1e-6);
      let ex = 1;
      let ey = 0;
      if (Math.abs(b) > 1e-12) {
        const n = Math.hypot(b, l1 - a);
        ex = b / n;
        ey = (l1 - a) / n;
      } else if (d > a) {
        ex = 0;
        ey = 1;
      }
      const r1 = EXTENT * Math.sqrt(l1);
      const r2 = EXTENT * Math.sqrt(l2);
      unsorted.centre[3 * i] = ndcX;
      unsorted.centre[3 * i + 1] = ndcY;
      unsorted.centre[3 * i + 2] = ndcZ;
      unsorted.axes[4 * i] = r1 * ex;
      unsorted.axes[4 * i + 1] = r1 * ey;
      unsorted.axes[4 * i + 2] = -r2 * ey;
      unsorted.axes[4 * i + 3] = r2 * ex;
      // Colour toward the eye: 0.5 + SH (degree ≤ 2), as 3DGS.
      const dx = x - eye.x;
      const dy = y - eye.y;
      const dz = z - eye.z;
      const n = Math.hypot(dx, dy, dz) || 1;
      shBasis(dx / n, dy / n, dz / n, basis);
      for (let ch = 0; ch < 3; ch++) {
        let value = 0.5;
        const base = (i * 3 + ch) * sh.terms;
        for (let t = 0; t < sh.terms; t++) value += basis[t] * sh.coefficients[base + t];
        unsorted.colour[4 * i + ch] = value > 0 ? value : 0;
      }
      unsorted.colour[4 * i + 3] = opacities[i];
      depth[i] = tz;
      visibleIndex[visible++] = i;
    }
    const order = sortFarToNear(visibleIndex, visible, depth, this.order);
    const records = this.geometry.attributes.center.data;
    const out = records.array;
    for (let k = 0; k < visible; k++) {
      const i = order[k];
      for (let corner = 0; corner < 3; corner++) {
        const at = STRIDE * (3 * k + corner);
        for (let q = 0; q < 3; q++) out[at + q] = unsorted.centre[3 * i + q];
        for (let q = 0; q < 4; q++) out[at + 3 + q] = unsorted.axes[4 * i + q];
        for (let q = 0; q < 4; q++) out[at + 7 + q] = unsorted.colour[4 * i + q];
      }
    }
    records.addUpdateRange(0, 3 * STRIDE * visible);
    records.needsUpdate = true;
    this.geometry.setDrawRange(0, 3 * visible);
    this.drawn = visible;
    this.material.uniforms.viewport.value.set(width, height);
  }
}

/// The real SH basis of degree ≤ 2 along the unit direction (x, y, z), in 3DGS's order and signs.
function shBasis(x, y, z, out) {
  out[0] = SH_C0;
  out[1] = -SH_C1 * y;
  out[2] = SH_C1 * z;
  out[3] = -SH_C1 * x;
  out[4] = SH_C2[0] * x * y;
  out[5] = SH_C2[1] * y * z;
  out[6] = SH_C2[2] * (2 * z * z - x * x - y * y);
  out[7] = SH_C2[3] * x * z;
  out[8] = SH_C2[4] * (x * x - y * y);
}

function interleave(count, columns, names) {
  const out = new Float32Array(count * names.length);
  names.forEach((name, k) => {
    const column = columns[name];
    if (!column) throw new Error(`no vertex property '${name}'`);
    for (let i = 0; i < count; i++) out[names.length * i + k] = column[i];
  });
  return out;
}

/// Σ = R diag(exp(scale))² Rᵀ from scale_0..2 (log) and rot_0..3 (w, x, y, z), upper triangle.
function covariances(count, columns) {
  const out = new Float32Array(6 * count);
  const s = [columns.scale_0, columns.scale_1, columns.scale_2];
  const q = [columns.rot_0, columns.rot_1, columns.rot_2, columns.rot_3];
  if (s.some((c) => !c) || q.some((c) => !c)) throw new Error("not 3DGS splats: no scale_0..2 and rot_0..3");
  for (let i = 0; i < count; i++) {
    let [w, x, y, z] = q.map((c) => c[i]);
    const n = Math.hypot(w, x, y, z) || 1;
    [w, x, y, z] = [w / n, x / n, y / n, z / n];
    const r = [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
      2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
      2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)];
    const v = s.map((c) => Math.exp(2 * c[i]));
    const entry = (a, b) => r[3 * a] * r[3 * b] * v[0] + r[3 * a + 1] * r[3 * b + 1] * v[1] + r[3 * a + 2] * r[3 * b + 2] * v[2];
    out.set([entry(0, 0), entry(0, 1), entry(0, 2), entry(1, 1), entry(1, 2), entry(2, 2)], 6 * i);
  }
  return out;
}

/// The SH coefficients per splat and channel, degree ≤ 2 (INRIA layout: f_dc_c, then f_rest
/// channel-major).
function harmonics(count, columns) {
  const rest = Object.keys(columns).filter((k) => k.startsWith("f_rest_")).length / 3;
  const terms = Math.min(9, 1 + rest);
  const coefficients = new Float32Array(count * 3 * terms);
  for (let i = 0; i < count; i++) {
    for (let ch = 0; ch < 3; ch++) {
      const base = (i * 3 + ch) * terms;
      coefficients[base] = columns[`f_dc_${ch}`][i];
      for (let b = 1; b < terms; b++) coefficients[base + b] = columns[`f_rest_${ch * rest + b - 1}`][i];
    }
  }
  return { terms, coefficients };
}

/// A Σ Aᵀ for a symmetric Σ (upper triangle at `from[at..at+6]`) and the 3×3 `a` whose rows
/// start every `stride` entries (3 for a 3×3, 4 for the left of a 3×4), into `to[out..out+6]`.
function transformCovariance(from, at, a, stride, to, out) {
  const s00 = from[at];
  const s01 = from[at + 1];
  const s02 = from[at + 2];
  const s11 = from[at + 3];
  const s12 = from[at + 4];
  const s22 = from[at + 5];
  const [r0, r1, r2] = [0, stride, 2 * stride];
  // M = A Σ, row by row; then (M Aᵀ)_ij = M_i · A_j.
  const m00 = a[r0] * s00 + a[r0 + 1] * s01 + a[r0 + 2] * s02;
  const m01 = a[r0] * s01 + a[r0 + 1] * s11 + a[r0 + 2] * s12;
  const m02 = a[r0] * s02 + a[r0 + 1] * s12 + a[r0 + 2] * s22;
  const m10 = a[r1] * s00 + a[r1 + 1] * s01 + a[r1 + 2] * s02;
  const m11 = a[r1] * s01 + a[r1 + 1] * s11 + a[r1 + 2] * s12;
  const m12 = a[r1] * s02 + a[r1 + 1] * s12 + a[r1 + 2] * s22;
  const m20 = a[r2] * s00 + a[r2 + 1] * s01 + a[r2 + 2] * s02;
  const m21 = a[r2] * s01 + a[r2 + 1] * s11 + a[r2 + 2] * s12;
  const m22 = a[r2] * s02 + a[r2 + 1] * s12 + a[r2 + 2] * s22;
  to[out] = m00 * a[r0] + m01 * a[r0 + 1] + m02 * a[r0 + 2];
  to[out + 1] = m00 * a[r1] + m01 * a[r1 + 1] + m02 * a[r1 + 2];
  to[out + 2] = m00 * a[r2] + m01 * a[r2 + 1] + m02 * a[r2 + 2];
  to[out + 3] = m10 * a[r1] + m11 * a[r1 + 1] + m12 * a[r1 + 2];
  to[out + 4] = m10 * a[r2] + m11 * a[r2 + 1] + m12 * a[r2 + 2];
  to[out + 5] = m20 * a[r2] + m21 * a[r2 + 1] + m22 * a[r2 + 2];
}

/// The first `n` of `index` ordered by decreasing `depth`: a counting sort on 16-bit keys.
function sortFarToNear(index, n, depth, out) {
  let [lo, hi] = [Infinity, -Infinity];
  for (let k = 0; k < n; k++) {
    const d = depth[index[k]];
    lo = Math.min(lo, d);
    hi = Math.max(hi, d);
  }
  const buckets = 65536;
  const scale = hi > lo ? (buckets - 1) / (hi - lo) : 0;
  const counts = new Uint32Array(buckets + 1);
  const keys = new Uint16Array(n);
  for (let k = 0; k < n; k++) {
    keys[k] = buckets - 1 - Math.floor((depth[index[k]] - lo) * scale);
    counts[keys[k] + 1]++;
  }
  for (let b = 0; b < buckets; b++) counts[b + 1] += counts[b];
  for (let k = 0; k < n; k++) out[counts[keys[k]]++] = index[k];
  return out;
}
