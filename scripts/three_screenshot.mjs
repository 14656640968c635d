#!/usr/bin/env node
// three_screenshot.mjs — a web page playing an exported wind clip in three.js, in Debian's
// headless Chromium (puppeteer-core from npm; software WebGL), photographed at given times:
//
//   node scripts/three_screenshot.mjs FILE.glb OUT.png --times 0,1,2 [--size 360x480]
//       [--chromium /usr/bin/chromium] [--puppeteer DIR]
//
// Serves three (from .tools/node, scripts/setup.sh) and FILE over a local HTTP server,
// loads a page that parses FILE with GLTFLoader (MeshoptDecoder set), frames the scene,
// lights it, plays its first animation with an AnimationMixer and renders one frame per
// time with AnimationMixer.setTime; the frames are tiled left to right into OUT.png (by
// the page itself, in a canvas). Prints "THREE_SCREENSHOT {json}" with each frame's mean
// pixel difference to the first (0 at the loop's end). Not part of the test suite: it
// needs chromium and puppeteer-core, which setup.sh does not install (docs/gltf.md).
import { readFile, writeFile } from 'node:fs/promises';
import http from 'node:http';
import path from 'node:path';
import { createRequire } from 'node:module';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const args = process.argv.slice(2);
const flag = (name, fallback) => {
  const i = args.indexOf(name);
  return i >= 0 && i + 1 < args.length ? args[i + 1] : fallback;
};
const [file, out] = args;
if (!file || !out) {
  console.error('usage: node scripts/three_screenshot.mjs FILE.glb OUT.png --times T1,T2,... [--size WxH]');
  process.exit(2);
}
const times = flag('--times', '0').split(',').map(Number);
const [width, height] = flag('--size', '360x480').split('x').map(Number);
const puppeteerDir = flag('--puppeteer', path.join(here, '..', '.tools', 'puppeteer'));
const require = createRequire(path.join(puppeteerDir, 'package.json'));
const puppeteer = require('puppeteer-core');
const threeDir = path.join(here, '..', '.tools', 'node', 'node_modules', 'three');

const page_html = `<!doctype html><html><body style="margin:0;background:#fff">
<script type="importmap">{"imports":{"three":"/three/build/three.module.js","three/addons/":"/three/examples/jsm/"}}</script>
<script type="module">
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { MeshoptDecoder } from 'three/addons/libs/meshopt_decoder.module.js';
const times = ${JSON.stringify(times)}, W = ${width}, H = ${height};
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setSize(W, H);
renderer.setClearColor(0xf4f1ea);
const scene = new THREE.Scene();
scene.add(new THREE.HemisphereLight(0xdde8ff, 0x806040, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 2.2);
sun.position.set(3, 6, 4);
scene.add(sun);
const gltf = await new GLTFLoader().setMeshoptDecoder(MeshoptDecoder).loadAsync('/model.glb');
// Show the first level of detail only (the others overlap it by design), and not the
// skeleton's LINES, which stay at rest (docs/gltf.md "Rig and wind clip").
gltf.scene.traverse((o) => { if (/_LOD[1-9]/.test(o.name) || o.isLineSegments) o.visible = false; });
scene.add(gltf.scene);
const box = new THREE.Box3().setFromObject(gltf.scene);
const size = box.getSize(new THREE.Vector3()), centre = box.getCenter(new THREE.Vector3());
const camera = new THREE.PerspectiveCamera(35, W / H, 0.1, 1000);
const distance = 0.62 * Math.max(size.y, size.x * H / W) / Math.tan(THREE.MathUtils.degToRad(17.5));
camera.position.set(centre.x + 0.35 * distance, centre.y + 0.1 * distance, centre.z + 0.94 * distance);
camera.lookAt(centre);
const mixer = new THREE.AnimationMixer(gltf.scene);
if (gltf.animations.length) mixer.clipAction(gltf.animations[0]).play();
const sheet = document.createElement('canvas');
sheet.width = W * times.length; sheet.height = H;
const ctx = sheet.getContext('2d');
const frames = [];
for (let i = 0; i < times.length; ++i) {
  mixer.setTime(times[i]);
  renderer.render(scene, camera);
  ctx.drawImage(renderer.domElement, i * W, 0);
  frames.push(ctx.getImageData(i * W, 0, W, H).data);
}
const diff = frames.map((f) => { let d = 0; for (let k = 0; k < f.length; k += 4) d += Math.abs(f[k] - frames[0][k]) + Math.abs(f[k + 1] - frames[0][k + 1]) + Math.abs(f[k + 2] - frames[0][k + 2]); return d / (W * H * 3); });
window.result = { png: sheet.toDataURL('image/png'), diff, clips: gltf.animations.map((c) => c.duration) };
</script></body></html>`;

const model = await readFile(file);
const server = http.createServer(async (req, res) => {
  try {
    const url = decodeURIComponent(new URL(req.url, 'http://x').pathname);
    if (url === '/') return res.writeHead(200, { 'content-type': 'text/html' }).end(page_html);
    if (url === '/model.glb') return res.writeHead(200, { 'content-type': 'model/gltf-binary' }).end(model);
    if (url.startsWith('/three/')) {
      const target = path.join(threeDir, path.normalize(url.slice(7)));
      if (!target.startsWith(threeDir)) return res.writeHead(403).end();
      const type = target.endsWith('.js') ? 'text/javascript' : target.endsWith('.wasm') ? 'application/wasm' : 'application/octet-stream';
      return res.writeHead(200, { 'content-type': type }).end(await readFile(target));
    }
    res.writeHead(404).end();
  } catch {
    res.writeHead(404).end();
  }
});
await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
const browser = await puppeteer.launch({
  executablePath: flag('--chromium', '/usr/bin/chromium'),
  headless: true,
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist'],
});
try {
  const page = await browser.newPage();
  page.on('pageerror', (e) => console.error('page error:', e.message));
  await page.goto(`http://127.0.0.1:${server.address().port}/`);
  await page.waitForFunction('window.result !== undefined', { timeout: 120000 });
  const result = await page.evaluate('window.result');
  await writeFile(out, Buffer.from(result.png.split(',')[1], 'base64'));
  console.log('THREE_SCREENSHOT ' + JSON.stringify({ out, times, diff_to_first: result.diff, clips: result.clips }));
} finally {
  await browser.close();
  server.close();
}
