// A three.js camera from a Mannequin camera file (OpenCV: x right, y down, z forward; K in
// pixels, pixel centres at +0.5; `extrinsic` world→camera), so a page view matches a render by
// the project's own renderer pixel for pixel.
import * as THREE from "three";

export function cameraFromOpenCv(json) {
  const { width, height, K, extrinsic } = json;
  const near = json.near ?? 0.01;
  const far = Math.min(json.far ?? 100, 1000);
  const camera = new THREE.PerspectiveCamera();
  // Camera→world: the inverse extrinsic, then OpenCV's y and z axes flipped into three.js's.
  const e = new THREE.Matrix4().set(...extrinsic.flat());
  const flip = new THREE.Matrix4().makeScale(1, -1, -1);
  camera.matrixAutoUpdate = false;
  camera.matrix.copy(e.invert().multiply(flip));
  camera.matrix.decompose(camera.position, camera.quaternion, camera.scale);
  camera.updateMatrixWorld(true);
  // Clip coordinates: x_ndc = (2fx/w)·X/(−Z) + 2cx/w − 1, y_ndc = (2fy/h)·Y/(−Z) + 1 − 2cy/h.
  const [fx, cx, fy, cy] = [K[0][0], K[0][2], K[1][1], K[1][2]];
  camera.projectionMatrix.set(
    (2 * fx) / width, 0, 1 - (2 * cx) / width, 0,
    0, (2 * fy) / height, (2 * cy) / height - 1, 0,
    0, 0, -(far + near) / (far - near), (-2 * far * near) / (far - near),
    0, 0, -1, 0,
  );
  camera.projectionMatrixInverse.copy(camera.projectionMatrix).invert();
  return { camera, width, height };
}
