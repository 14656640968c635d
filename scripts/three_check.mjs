#!/usr/bin/env node
// three_check.mjs — plays an exported wind clip in three.js (npm `three`, pinned by
// scripts/setup.sh into .tools/node), as a web page would, without a browser.
//
//   node scripts/three_check.mjs FILE.glb --times T1,T2,... [--every N]
//
// (A .glb: Node has no ProgressEvent, which GLTFLoader needs to fetch a .gltf's data URI;
// and no image decoder: the images are taken out before parsing.)
//
// GLTFLoader parses the file (EXT_meshopt_compression through three's MeshoptDecoder); for
// each time, AnimationMixer.setTime(t) poses the skeleton
// of the file's first animation, and SkinnedMesh.getVertexPosition (three's own skinning:
// bone matrices, inverse bind matrices, JOINTS_0/WEIGHTS_0) gives the skinned positions
// of every N-th vertex (default 1) of each skinned mesh, in world space (glTF's Y up,
// metres). Prints one line "THREE_CHECK {json}":
//   {"meshes": [{"name", "vertices", "positions": [x, y, z, ...] of the sampled vertices}...]
//      (every mesh's geometry as three decoded it, in mesh space),
//    "skinned_meshes": [{"name", "vertices", "bones", "attributes" (three's names, sorted),
//                        "rest": [x, y, z, ...],
//                        "skin": [j0, j1, j2, j3, w0, w1, w2, w3, ...]}...]  (the sampled
//                        vertices' POSITION and JOINTS_0/WEIGHTS_0 as three read them),
//    "clips": [{"name", "duration", "tracks"}...],
//    "frames": [{"t", "meshes": [[x, y, z, x, y, z, ...] per skinned mesh]}...]}
// Exits 1 when the file cannot be parsed, 2 on a usage problem.
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const threeDir = path.join(here, '..', '.tools', 'node', 'node_modules', 'three');

let THREE, GLTFLoader, MeshoptDecoder;
try {
  THREE = await import(pathToFileURL(path.join(threeDir, 'build', 'three.module.js')).href);
  ({ GLTFLoader } = await import(pathToFileURL(path.join(threeDir, 'examples', 'jsm', 'loaders', 'GLTFLoader.js')).href));
  ({ MeshoptDecoder } = await import(pathToFileURL(path.join(threeDir, 'examples', 'jsm', 'libs', 'meshopt_decoder.module.js')).href));
} catch (error) {
  console.error(`three_check: error: three.js is not installed at ${threeDir} (run scripts/setup.sh): ${error.message}`);
  process.exit(2);
}

const args = process.argv.slice(2);
const file = args.find((a, i) => !a.startsWith('--') && (i === 0 || !args[i - 1].startsWith('--')));
const flag = (name, fallback) => {
  const i = args.indexOf(name);
  return i >= 0 && i + 1 < args.length ? args[i + 1] : fallback;
};
const times = flag('--times', '0').split(',').map(Number);
const every = Math.max(1, parseInt(flag('--every', '1'), 10));
if (!file || times.some((t) => !Number.isFinite(t))) {
  console.error('usage: node scripts/three_check.mjs FILE.glb --times T1,T2,... [--every N]');
  process.exit(2);
}

// Node cannot decode images (no createImageBitmap, no DOM): the textures are taken out of
// the GLB's JSON first; geometry, skins and animations are untouched.
function withoutTextures(bytes) {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  if (view.getUint32(0, true) !== 0x46546c67) return bytes;  // not a GLB: as it is
  const jsonLength = view.getUint32(12, true);
  const json = JSON.parse(new TextDecoder().decode(bytes.subarray(20, 20 + jsonLength)));
  if (!json.images) return bytes;
  delete json.images;
  delete json.textures;
  delete json.samplers;
  for (const m of json.materials ?? []) {
    delete m.normalTexture;
    delete m.occlusionTexture;
    delete m.emissiveTexture;
    if (m.pbrMetallicRoughness) {
      delete m.pbrMetallicRoughness.baseColorTexture;
      delete m.pbrMetallicRoughness.metallicRoughnessTexture;
    }
  }
  let text = new TextEncoder().encode(JSON.stringify(json));
  const padded = new Uint8Array(Math.ceil(text.length / 4) * 4).fill(0x20);
  padded.set(text);
  text = padded;
  const rest = bytes.subarray(20 + jsonLength);
  const out = new Uint8Array(20 + text.length + rest.length);
  const outView = new DataView(out.buffer);
  out.set(bytes.subarray(0, 12));
  outView.setUint32(8, out.length, true);
  outView.setUint32(12, text.length, true);
  outView.setUint32(16, 0x4e4f534a, true);
  out.set(text, 20);
  out.set(rest, 20 + text.length);
  return out;
}

const bytes = withoutTextures(new Uint8Array(await readFile(file)));
const buffer = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
let gltf;
try {
  // EXT_meshopt_compression decodes with three's own WebAssembly decoder, as a page would.
  const loader = new GLTFLoader().setMeshoptDecoder(MeshoptDecoder);
  gltf = await new Promise((resolve, reject) => loader.parse(buffer, '', resolve, reject));
} catch (error) {
  console.error(`${file}: error: GLTFLoader: ${error.message ?? error}`);
  process.exit(1);
}

const scene = gltf.scene;
const skinned = [];
scene.traverse((o) => { if (o.isSkinnedMesh) skinned.push(o); });
const mixer = new THREE.AnimationMixer(scene);
if (gltf.animations.length > 0) mixer.clipAction(gltf.animations[0]).play();

const plain = [];
scene.traverse((o) => { if (o.isMesh) plain.push(o); });
const report = {
  meshes: plain.map((m) => {
    const position = m.geometry.attributes.position;
    const positions = [];
    for (let i = 0; i < position.count; i += every) positions.push(position.getX(i), position.getY(i), position.getZ(i));
    return { name: m.name, vertices: position.count, indices: m.geometry.index ? m.geometry.index.count : 0, positions };
  }),
  skinned_meshes: skinned.map((m) => {
    const { position, skinIndex, skinWeight } = m.geometry.attributes;
    const rest = [], skin = [];
    for (let i = 0; i < position.count; i += every) {
      rest.push(position.getX(i), position.getY(i), position.getZ(i));
      for (let k = 0; k < 4; ++k) skin.push(skinIndex.getComponent(i, k));
      for (let k = 0; k < 4; ++k) skin.push(skinWeight.getComponent(i, k));
    }
    return { name: m.name, vertices: position.count, bones: m.skeleton.bones.length,
             attributes: Object.keys(m.geometry.attributes).sort(), rest, skin };
  }),
  clips: gltf.animations.map((c) => ({ name: c.name, duration: c.duration, tracks: c.tracks.length })),
  frames: [],
};
const v = new THREE.Vector3();
for (const t of times) {
  mixer.setTime(t);
  scene.updateMatrixWorld(true);
  const meshes = skinned.map((m) => {
    const out = [];
    for (let i = 0; i < m.geometry.attributes.position.count; i += every) {
      m.getVertexPosition(i, v);
      v.applyMatrix4(m.matrixWorld);
      out.push(v.x, v.y, v.z);
    }
    return out;
  });
  report.frames.push({ t, meshes });
}
console.log('THREE_CHECK ' + JSON.stringify(report));
