// Loads a .glb with three.js's GLTFLoader in Node (no browser) and reports what a web viewer would
// play: skinned meshes, bone counts, animation clips, and the posed mesh's bounding box at the
// first and last key; then each morph-animated mesh (a cloth cache) and its box at the last key. Exits 1 if there is neither an animated skinned mesh nor a morph mesh, 2 if three.js is missing.
//
// Install three.js once:  npm install --prefix "$HOME/.cache/three-check" three
// Usage:                  node tools/gltf_three_check.mjs FILE.glb
// THREE_DIR overrides the package folder (default: $HOME/.cache/three-check/node_modules/three).
import { readFileSync } from "node:fs";
import { homedir } from "node:os";
import { join } from "node:path";
import { pathToFileURL } from "node:url";

const file = process.argv[2];
if (!file) {
  console.error("usage: node tools/gltf_three_check.mjs FILE.glb");
  process.exit(2);
}
const dir = process.env.THREE_DIR || join(homedir(), ".cache/three-check/node_modules/three");
let THREE, GLTFLoader;
try {
  THREE = await import(pathToFileURL(join(dir, "build/three.module.js")).href);
  ({ GLTFLoader } = await import(pathToFileURL(join(dir, "examples/jsm/loaders/GLTFLoader.js")).href));
} catch (e) {
  console.error(`cannot load three.js from ${dir}: ${e.message}`);
  process.exit(2);
}

const bytes = readFileSync(file);
const data = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
const gltf = await new Promise((resolve, reject) => new GLTFLoader().parse(data, "", resolve, reject));

const skinned = [];
gltf.scene.traverse((o) => o.isSkinnedMesh && skinned.push(o));
console.log(`${file}: three.js r${THREE.REVISION}: ${skinned.length} skinned mesh(es), ` +
  `${gltf.animations.length} animation(s)`);
for (const m of skinned) {
  console.log(`  skinned mesh '${m.name}': ${m.geometry.attributes.position.count} vertices, ` +
    `${m.skeleton.bones.length} bones, attributes ${Object.keys(m.geometry.attributes).join(" ")}`);
}
for (const clip of gltf.animations) {
  console.log(`  clip '${clip.name}': duration ${clip.duration.toFixed(4)} s, ${clip.tracks.length} tracks`);
}

/// The world-space bounding box of the posed (skinned or morphed) vertices at time t of the first clip.
function posedBox(mesh, t) {
  const mixer = new THREE.AnimationMixer(gltf.scene);
  // Play once and hold the last pose: a looping clip at t = duration wraps back to its first key.
  const action = mixer.clipAction(gltf.animations[0]);
  action.setLoop(THREE.LoopOnce, 1);
  action.clampWhenFinished = true;
  action.play();
  mixer.setTime(t);
  gltf.scene.updateMatrixWorld(true);
  if (mesh.isSkinnedMesh) mesh.skeleton.update();
  const box = new THREE.Box3();
  const v = new THREE.Vector3();
  for (let i = 0; i < mesh.geometry.attributes.position.count; i++) {
    mesh.getVertexPosition(i, v);
    box.expandByPoint(v.applyMatrix4(mesh.matrixWorld));
  }
  mixer.stopAllAction();
  const f = (p) => p.toArray().map((x) => x.toFixed(4)).join(", ");
  return `min (${f(box.min)}) max (${f(box.max)})`;
}
if (skinned.length && gltf.animations.length) {
  const d = gltf.animations[0].duration;
  for (const t of [0, d / 3, d]) {
    console.log(`  posed box at t=${t.toFixed(4)}: ${posedBox(skinned[0], t)}`);
  }
}
// Vertex caches (cloth) beside the body: unskinned meshes played by morph targets.
const morphs = [];
gltf.scene.traverse((o) => o.isMesh && !o.isSkinnedMesh && o.morphTargetInfluences && morphs.push(o));
for (const m of morphs) {
  const targets = m.geometry.morphAttributes.position.length;
  const names = Object.keys(m.morphTargetDictionary || {});
  const named = names.length ? ` (${names.join(", ")})` : "";
  console.log(`  morph mesh '${m.name}': ${m.geometry.attributes.position.count} vertices, ${targets} targets${named}`);
  if (gltf.animations.length) {
    const t = gltf.animations[0].duration;
    console.log(`  ${m.name} box at t=${t.toFixed(4)}: ${posedBox(m, t)}`);
  }
}
process.exit((skinned.length && gltf.animations.length) || morphs.length ? 0 : 1);
