// The page `mannequin view` serves: the layers listed in /scene.json (skinned glTF meshes with
// their animation, cloth caches as morph targets, Gaussian splats, splats skinned to a glTF
// skeleton) on one timeline. Query parameters, for reproducible screenshots:
//   camera=<camera JSON, as `splat render --camera` reads it>  fixes the view and canvas size
//   t=<seconds>  starts paused at that time;  bg=<CSS colour>;  ui=0 hides the panel.
// window.mannequin exposes ready, frames (drawn so far), fps, duration, setTime(t),
// setBackground(colour), motions() and chooseMotion(i) to tests and benchmarks.
import * as THREE from "three";
import { OrbitControls } from "three/addons/controls/OrbitControls.js";
import { GLTFLoader } from "three/addons/loaders/GLTFLoader.js";
import { GaussianSplats } from "./gaussian_splats.js";
import { cameraFromOpenCv } from "./opencv_camera.js";
import { readPly } from "./ply.js";

const params = new URLSearchParams(location.search);
const $ = (id) => document.getElementById(id);
const status = { ready: false, frames: 0, duration: 0, time: 0, layers: [] };
window.mannequin = status;

function fail(message) {
  $("error").textContent += `${message}\n`;
  console.error(message);
}

const manifest = await (await fetch("/scene.json")).json();
const canvas = $("view");
// Multisampling costs splats half their frame rate on software WebGL and does not improve them.
const antialias = !manifest.layers.some((l) => l.kind === "splats");
const renderer = new THREE.WebGLRenderer({ canvas, antialias, preserveDrawingBuffer: true });
renderer.setPixelRatio(1);
const scene = new THREE.Scene();
scene.add(new THREE.HemisphereLight(0xffffff, 0x505060, 2.0));
const sun = new THREE.DirectionalLight(0xffffff, 1.5);
sun.position.set(-1, 2, 3);
scene.add(sun);

const background = params.get("bg") ?? "#20242a";
scene.background = new THREE.Color(background);
document.body.style.setProperty("--background", background);
if (params.get("ui") === "0") document.body.classList.add("bare");

// The view: a fixed OpenCV camera from the query, else a perspective camera orbiting the scene.
let camera;
let controls = null;
const fixed = params.get("camera");
if (fixed) {
  const c = cameraFromOpenCv(JSON.parse(fixed));
  camera = c.camera;
  renderer.setSize(c.width, c.height, true);
} else {
  camera = new THREE.PerspectiveCamera(35, 1, 0.01, 100);
  camera.position.set(0, 0.2, 4);
  controls = new OrbitControls(camera, canvas);
  controls.enablePan = true;
  const resize = () => {
    renderer.setSize(window.innerWidth, window.innerHeight, true);
    camera.aspect = window.innerWidth / window.innerHeight;
    camera.updateProjectionMatrix();
  };
  window.addEventListener("resize", resize);
  resize();
}

// Cloth caches come as one morph target per frame; three.js's shaders loop over every target of
// a mesh for every vertex, which a long clip makes slow, so past this many targets the page
// blends the (at most two) weighted frames itself.
const MAX_SHADER_MORPHS = 8;
const morphCaches = [];

/// Takes `mesh`'s morph targets out of its shaders: its positions become the base plus the
/// weighted targets, recomputed when the timeline moves.
function playOnCpu(mesh) {
  const geometry = mesh.geometry;
  const targets = geometry.morphAttributes.position.map((a) => a.array);
  const relative = geometry.morphTargetsRelative;
  const base = geometry.attributes.position.array.slice();
  geometry.morphAttributes = {};
  // The loader's bounds span every frame (the whole path walked); frame the base instead.
  geometry.computeBoundingBox();
  geometry.computeBoundingSphere();
  const influences = mesh.morphTargetInfluences;
  const position = geometry.attributes.position;
  position.setUsage(THREE.DynamicDrawUsage);
  return {
    update() {
      const out = position.array;
      let total = 0;
      out.set(base);
      influences.forEach((w, k) => {
        if (w === 0) return;
        total += w;
        const target = targets[k];
        for (let i = 0; i < out.length; i++) out[i] += w * (relative ? target[i] : target[i] - base[i]);
      });
      position.needsUpdate = true;
      geometry.computeVertexNormals();
      return total;
    },
  };
}

// The timeline: one clock for every layer's animation.
// The orbiting camera follows the first skeleton's root, so a walk stays in view.
let followed = null;
const followedAt = new THREE.Vector3();
const followedNow = new THREE.Vector3();
const mixers = [];
const layerMixers = new Map();
const skinnedSplats = [];
const splatLayers = [];
let playing = !params.has("t");
let time = Number(params.get("t") ?? 0);
let speed = 1;
$("play").textContent = playing ? "Pause" : "Play";
$("play").onclick = () => {
  playing = !playing;
  $("play").textContent = playing ? "Pause" : "Play";
};
$("speed").onchange = (e) => {
  speed = Number(e.target.value);
};
$("timeline").oninput = (e) => {
  playing = false;
  $("play").textContent = "Play";
  setTime(Number(e.target.value) * status.duration);
};

function setTime(t) {
  time = status.duration > 0 ? ((t % status.duration) + status.duration) % status.duration : 0;
  status.time = time;
  for (const mixer of mixers) mixer.setTime(time);
  for (const cache of morphCaches) cache.update();
  scene.updateMatrixWorld(true);
  for (const s of skinnedSplats) s.update();
  $("timeline").value = status.duration > 0 ? time / status.duration : 0;
  $("clock").textContent = `${time.toFixed(2)} s`;
}
status.setTime = setTime;
status.setBackground = (colour) => {
  scene.background = new THREE.Color(colour);
};

function addToggle(name, object) {
  const label = document.createElement("label");
  const box = document.createElement("input");
  box.type = "checkbox";
  box.checked = object.visible;
  box.onchange = () => {
    object.visible = box.checked;
  };
  label.append(box, ` ${name}`);
  $("layers").append(label);
  status.layers.push(name);
}

async function loadGltf(layer) {
  const gltf = await new GLTFLoader().loadAsync(layer.url);
  const root = gltf.scene;
  scene.add(root);
  root.traverse((o) => {
    if (o.isMesh) {
      o.frustumCulled = false;
      o.visible = layer.visible !== false;
      addToggle(o.name || layer.name, o);
      if ((o.geometry.morphAttributes.position?.length ?? 0) > MAX_SHADER_MORPHS) morphCaches.push(playOnCpu(o));
    }
  });
  const skinned = [];
  root.traverse((o) => o.isSkinnedMesh && skinned.push(o));
  followed ??= skinned[0]?.skeleton.bones[0] ?? null;
  if (skinned.length > 0) {
    const helper = new THREE.SkeletonHelper(root);
    helper.visible = false;
    scene.add(helper);
    addToggle(`${layer.name} skeleton`, helper);
  }
  if (gltf.animations.length > 0) {
    const mixer = new THREE.AnimationMixer(root);
    for (const clip of gltf.animations) mixer.clipAction(clip).play();
    mixers.push(mixer);
    layerMixers.set(layer.name, mixer);
    status.duration = Math.max(status.duration, ...gltf.animations.map((c) => c.duration));
  }
  return { root, skeleton: skinned[0]?.skeleton ?? null };
}

// Splats (a 3DGS .ply), skinned to a glTF layer's skeleton when the file carries skinning: each
// splat then moves by its weights' blend of S_k = bone_k.matrixWorld · boneInverse_k, the matrix
// three.js skins that layer's vertices with.
async function loadSplats(layer, skeletons) {
  const bytes = new Uint8Array(await (await fetch(layer.url)).arrayBuffer());
  const { count, columns } = readPly(bytes, layer.url);
  const splats = new GaussianSplats(count, columns, { dilation: layer.dilation ?? 0.3 });
  scene.add(splats);
  addToggle(layer.name, splats);
  splatLayers.push(splats);
  if (!layer.skeleton) return;
  const skeleton = skeletons.get(layer.skeleton);
  if (!skeleton) throw new Error(`${layer.url}: no skinned mesh in layer '${layer.skeleton}' to follow`);
  if (!splats.skin) throw new Error(`${layer.url}: no joint_0..3 / weight_0..3 properties to skin by`);
  const matrices = skeleton.bones.map(() => new THREE.Matrix4());
  splats.setBones(matrices);
  skinnedSplats.push({
    update() {
      skeleton.bones.forEach((bone, k) => matrices[k].multiplyMatrices(bone.matrixWorld, skeleton.boneInverses[k]));
      splats.bonesMoved();
    },
  });
}

async function load() {
  $("title").textContent = manifest.title;
  document.title = `${manifest.title} · Mannequin`;
  const skeletons = new Map();
  for (const layer of manifest.layers.filter((l) => l.kind === "glb")) {
    const { skeleton } = await loadGltf(layer);
    if (skeleton) skeletons.set(layer.name, skeleton);
  }
  for (const layer of manifest.layers.filter((l) => l.kind === "splats")) await loadSplats(layer, skeletons);
  if (manifest.compare) showCompare(manifest.compare);
  if (manifest.motions) offerMotions(manifest.motions);
  setTime(time);
  if (controls) frameScene();
  followed?.getWorldPosition(followedAt);
  const parts = manifest.layers.map((l) => `${l.name} (${l.kind})`).join(", ");
  $("status").textContent = `${parts}\n${status.duration.toFixed(2)} s of motion`;
}

// Points the orbiting camera at everything loaded, from the front (+z), whole body in view.
function frameScene() {
  const box = new THREE.Box3().setFromObject(scene);
  if (box.isEmpty()) return;
  const centre = box.getCenter(new THREE.Vector3());
  const size = box.getSize(new THREE.Vector3()).length();
  controls.target.copy(centre);
  camera.position.set(centre.x, centre.y, centre.z + 1.6 * size);
  controls.update();
}

// The motions an avatar can play: each a glTF of its mesh with one animation, whose clip
// replaces the one its layer plays.
function offerMotions({ layer, choices }) {
  const select = $("motion");
  for (const { name, url } of choices) select.append(new Option(name, url));
  select.hidden = false;
  select.onchange = async () => {
    const mixer = layerMixers.get(layer);
    const [clip] = (await new GLTFLoader().loadAsync(select.value)).animations;
    mixer.stopAllAction();
    mixer.clipAction(clip).play();
    status.duration = clip.duration;
    setTime(0);
  };
}
status.motions = () => [...$("motion").options].map((o) => o.text);
status.chooseMotion = (index) => {
  $("motion").selectedIndex = index;
  return $("motion").onchange();
};

// A test view beside its ground truth, for an avatar folder with its dataset.
function showCompare(compare) {
  const box = $("compare");
  for (const [label, url] of [["render", compare.render], ["ground truth", compare.truth]]) {
    const img = document.createElement("img");
    img.src = url;
    img.alt = label;
    img.title = label;
    box.append(img);
  }
  box.classList.add("shown");
}

// Files dropped on the page: a .glb (its animation joins the timeline) or a 3DGS .ply.
document.addEventListener("dragover", (e) => e.preventDefault());
document.addEventListener("drop", async (e) => {
  e.preventDefault();
  for (const file of e.dataTransfer.files) {
    const url = URL.createObjectURL(file);
    const name = file.name;
    try {
      if (name.toLowerCase().endsWith(".glb")) await loadGltf({ name, url, kind: "glb" });
      else if (name.toLowerCase().endsWith(".ply")) await loadSplats({ name, url, kind: "splats" }, new Map());
      else fail(`${name}: expected a .glb or a 3DGS .ply`);
      setTime(time);
    } catch (err) {
      fail(`${name}: ${err.message}`);
    }
  }
});

let last = performance.now();
let fpsFrames = 0;
let fpsStart = last;
function frame(now) {
  const dt = Math.min((now - last) / 1000, 0.1);
  last = now;
  if (playing && status.duration > 0) setTime(time + dt * speed);
  if (controls && followed) {
    followed.getWorldPosition(followedNow);
    const step = followedNow.clone().sub(followedAt);
    camera.position.add(step);
    controls.target.add(step);
    followedAt.copy(followedNow);
  }
  controls?.update();
  const size = renderer.getDrawingBufferSize(new THREE.Vector2());
  const start = performance.now();
  for (const splats of splatLayers) if (splats.visible) splats.update(camera, size.x, size.y);
  status.splatUpdateMs = performance.now() - start;
  status.splatsDrawn = splatLayers.map((s) => (s.visible ? s.drawn : 0));
  renderer.render(scene, camera);
  status.frames += 1;
  fpsFrames += 1;
  if (now - fpsStart > 1000) {
    status.fps = (1000 * fpsFrames) / (now - fpsStart);
    $("fps").textContent = `${status.fps.toFixed(1)} frames/s`;
    fpsFrames = 0;
    fpsStart = now;
  }
  requestAnimationFrame(frame);
}

load()
  .then(() => {
    status.ready = true;
    document.body.dataset.ready = "1";
    requestAnimationFrame(frame);
  })
  .catch((err) => fail(`loading the scene: ${err.message}`));
