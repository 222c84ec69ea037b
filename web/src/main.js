// The page of `cga serve`: a 3D view of the model the server generates, an
// attribute panel built from the rule file's annotations, and panels for
// problems, prints, reports and statistics. The server pushes a `state`
// event after every change (server-sent events); the model comes as plain
// arrays in a frame per lot (`/api/model.bin`, see
// crates/cga-serve/src/encode.rs), and while a new model is made its lots
// come as each is made (`/api/live.bin`): the page fetches and builds them
// while the server derives the next.

import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';

const $ = (id) => document.getElementById(id);
const BACKGROUND = 0xdde3ea;

// What tests (and curious users) can read: `window.cgaPreview`.
const page = {
  stateVersion: 0,
  modelVersion: 0, // of the model drawn
  drawnAt: 0,
  drawnFrom: null, // 'live' or 'whole', see showModel
  bounds: null, // {min: [x,y,z], max: [x,y,z]} of the model drawn
  problems: [],
  stale: false,
  values: {},
  picked: null,
};
window.cgaPreview = page;

// ---------------------------------------------------------------- viewport

const canvas = $('canvas');
// The drawing buffer is kept so that tests can read the pixels drawn.
const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
renderer.shadowMap.enabled = true;
renderer.shadowMap.type = THREE.PCFSoftShadowMap;
// The shadow map depends on the model and the sun, not on the camera: it
// is drawn again only when they change (see `render`), not on every orbit.
renderer.shadowMap.autoUpdate = false;
let shadowsStale = true;
let shadowTimer = 0;
const scene = new THREE.Scene();
scene.background = new THREE.Color(BACKGROUND);
const camera = new THREE.PerspectiveCamera(45, 1, 0.1, 100000);
camera.position.set(40, 35, 40);
const controls = new OrbitControls(camera, canvas);
controls.enableDamping = false;

scene.add(new THREE.HemisphereLight(0xffffff, 0x8d8a80, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 1.8);
sun.position.set(60, 100, 40);
sun.castShadow = true;
sun.shadow.mapSize.set(2048, 2048);
// Without a bias, walls shadow themselves in stripes (shadow acne).
sun.shadow.bias = -0.0005;
sun.shadow.normalBias = 0.05;
scene.add(sun, sun.target);

const grids = new THREE.Group();
scene.add(grids);
const lotsGroup = new THREE.Group();
const modelGroup = new THREE.Group();
scene.add(lotsGroup, modelGroup);

function resize() {
  const w = canvas.clientWidth;
  const h = canvas.clientHeight;
  if (canvas.width !== Math.floor(w * renderer.getPixelRatio()) || canvas.height !== Math.floor(h * renderer.getPixelRatio())) {
    renderer.setSize(w, h, false);
    camera.aspect = w / Math.max(h, 1);
    camera.updateProjectionMatrix();
  }
}

// Draws the scene. `newModel`: the model changed; the frame
// showing it is drawn with the shadows as they were (a pass over every
// triangle less, which without a GPU is a large part of a frame), and
// the shadows follow once the models stop coming (a slider being moved,
// edits saved one after another) for SHADOW_DELAY_MS.
const SHADOW_DELAY_MS = 400;
// A new model is on its way (values sent, a file saved): the shadows
// wait for it, so that their pass does not take the cores generating it.
function holdShadows() {
  clearTimeout(shadowTimer);
}
// Shadows that were held follow after the delay.
function releaseShadows() {
  if (!shadowsStale) return;
  clearTimeout(shadowTimer);
  shadowTimer = setTimeout(() => render(), SHADOW_DELAY_MS);
}
function render({ newModel = false } = {}) {
  resize();
  if (newModel) {
    shadowsStale = true;
    releaseShadows();
  } else if (shadowsStale) {
    placeSun();
    renderer.shadowMap.needsUpdate = true;
    shadowsStale = false;
  }
  renderer.render(scene, camera);
}
controls.addEventListener('change', () => render());
window.addEventListener('resize', () => render());

// A grid of 1 m cells and one of 10 m cells under the model, sized to it.
function makeGrids(box) {
  grids.clear();
  const size = box.isEmpty() ? new THREE.Vector3(40, 0, 40) : box.getSize(new THREE.Vector3());
  const centre = box.isEmpty() ? new THREE.Vector3() : box.getCenter(new THREE.Vector3());
  const extent = Math.ceil((Math.max(size.x, size.z) * 1.6 + 20) / 10) * 10;
  const fine = new THREE.GridHelper(extent, extent, 0xc4cad2, 0xc4cad2);
  const coarse = new THREE.GridHelper(extent, extent / 10, 0x98a0aa, 0x98a0aa);
  for (const g of [fine, coarse]) {
    g.position.set(Math.round(centre.x / 10) * 10, -0.02, Math.round(centre.z / 10) * 10);
    grids.add(g);
  }
  const shadow = new THREE.Mesh(new THREE.PlaneGeometry(extent, extent), new THREE.ShadowMaterial({ opacity: 0.18 }));
  shadow.rotation.x = -Math.PI / 2;
  shadow.position.copy(fine.position).setY(-0.03);
  shadow.receiveShadow = true;
  grids.add(shadow);
  // The sun's direction never changes, only the box its shadows cover:
  // moved with the next shadow map, which the old one must still fit.
  sunFrame = { centre, r: Math.max(size.x, size.y, size.z, 10) };
}

let sunFrame = null;
function placeSun() {
  if (!sunFrame) return;
  const { centre, r } = sunFrame;
  sun.position.set(centre.x + r, centre.y + 2 * r, centre.z + 0.7 * r);
  sun.target.position.copy(centre);
  const cam = sun.shadow.camera;
  cam.left = cam.bottom = -1.5 * r;
  cam.right = cam.top = 1.5 * r;
  cam.near = 0.1;
  cam.far = 6 * r;
  cam.updateProjectionMatrix();
  sunFrame = null;
}

function fit() {
  const box = groupBox(modelGroup);
  if (box.isEmpty()) box.copy(groupBox(lotsGroup));
  if (box.isEmpty()) return;
  const centre = box.getCenter(new THREE.Vector3());
  const radius = box.getBoundingSphere(new THREE.Sphere()).radius;
  const distance = radius / Math.sin(THREE.MathUtils.degToRad(camera.fov / 2)) * 1.1;
  const direction = new THREE.Vector3(1, 0.8, 1.2).normalize();
  camera.position.copy(centre).addScaledVector(direction, distance);
  controls.target.copy(centre);
  controls.update();
  render();
}
$('fit').addEventListener('click', fit);

// ------------------------------------------------------------------ models

// Reads a model's frames from a response as they come (see the server's
// encode.rs): "CGAF", then frames of a header length, a data length, the
// arrays and the JSON header. Calls `onFrame(header, data)` for each, `data`
// an ArrayBuffer of the frame's arrays alone (their offsets count from its
// start, and typed arrays over it are aligned); returns the end frame's
// header. What `onFrame` throws stops the reading.
const MAGIC = 'CGAF';
const textDecoder = new TextDecoder();
async function readFrames(response, onFrame) {
  const reader = response.body.getReader();
  const chunks = []; // received, not yet taken
  let head = 0; // bytes of chunks[0] taken
  let have = 0; // bytes received, not yet taken
  const need = async (n) => {
    while (have < n) {
      const { done, value } = await reader.read();
      if (done) throw new Error('the model was cut short');
      chunks.push(value);
      have += value.length;
    }
  };
  // The next n bytes, in a buffer of their own.
  const take = (n) => {
    const out = new Uint8Array(n);
    let at = 0;
    while (at < n) {
      const c = chunks[0];
      const k = Math.min(n - at, c.length - head);
      out.set(c.subarray(head, head + k), at);
      at += k;
      head += k;
      if (head === c.length) {
        chunks.shift();
        head = 0;
      }
    }
    have -= n;
    return out;
  };
  try {
    await need(4);
    if (textDecoder.decode(take(4)) !== MAGIC) throw new Error('not a model');
    for (;;) {
      await need(8);
      const lengths = new DataView(take(8).buffer);
      const headerLength = lengths.getUint32(0, true);
      const dataLength = lengths.getUint32(4, true);
      await need(dataLength + headerLength);
      const data = take(dataLength).buffer;
      const header = JSON.parse(textDecoder.decode(take(headerLength)));
      onFrame(header, data);
      if (header.end) return header.end;
    }
  } finally {
    reader.cancel().catch(() => {});
  }
}

// A mesh's triangle indices: sent as they are, or (`fans`) as the number
// of corners of each face, whose triangles are the fan (b, b + i, b + i + 1)
// over the face's own run of vertices starting at b: a byte a face on the
// wire instead of 6 or 12 bytes a triangle, made into indices here.
function indices(buffer, m) {
  if (m.fans === null || m.fans === undefined) {
    const Indices = m.index_bytes === 2 ? Uint16Array : Uint32Array;
    return new Indices(buffer, m.indices, m.triangles * 3);
  }
  const corners = new Uint8Array(buffer, m.indices, m.fans);
  const out = new (m.vertices <= 65536 ? Uint16Array : Uint32Array)(m.triangles * 3);
  let at = 0;
  let base = 0;
  for (let f = 0; f < corners.length; f++) {
    const n = corners[f];
    for (let i = 1; i < n - 1; i++) {
      out[at] = base;
      out[at + 1] = base + i;
      out[at + 2] = base + i + 1;
      at += 3;
    }
    base += n;
  }
  return out;
}

// A mesh's normals, a vertex's three bytes each: sent so, or
// (`face_normals`, meshes of flat fans) one per face, given here to the
// face's vertices (3 bytes a quad on the wire instead of 12).
function normals(buffer, m) {
  if (!m.face_normals) return new Int8Array(buffer, m.normals, m.vertices * 3);
  const corners = new Uint8Array(buffer, m.indices, m.fans);
  const faces = new Int8Array(buffer, m.normals, m.fans * 3);
  const out = new Int8Array(m.vertices * 3);
  let at = 0;
  for (let f = 0; f < corners.length; f++) {
    const x = faces[3 * f];
    const y = faces[3 * f + 1];
    const z = faces[3 * f + 2];
    for (let k = corners[f]; k > 0; k--) {
      out[at] = x;
      out[at + 1] = y;
      out[at + 2] = z;
      at += 3;
    }
  }
  return out;
}

// Colour maps by URL, loaded once; a texture that changes on disk is
// seen after a reload of the page.
const textures = new Map();
const textureLoader = new THREE.TextureLoader();
// Per-mesh copies of a colour map made before its image arrived: told
// when it does.
const waitingCopies = new Map();
function texture(url) {
  if (!textures.has(url)) {
    waitingCopies.set(url, []);
    const t = textureLoader.load(url, () => {
      // The map keeps its image on the GPU while meshes come and go
      // (their copies share it).
      renderer.initTexture(t);
      for (const copy of waitingCopies.get(url)) copy.version = t.version;
      waitingCopies.delete(url);
      render();
    });
    t.colorSpace = THREE.SRGBColorSpace;
    t.wrapS = t.wrapT = THREE.RepeatWrapping;
    t.anisotropy = 4;
    textures.set(url, t);
  }
  return textures.get(url);
}

// A colour map for texture coordinates sent as 16-bit steps across their
// box (see the server's encode.rs): a texture sharing the map's image (on
// the GPU too) whose offset and repeat move the steps back into the box.
// Not `clone()`: a copy marks the image for another upload.
const sharedSettings = ['wrapS', 'wrapT', 'magFilter', 'minFilter', 'anisotropy', 'format', 'internalFormat', 'type', 'generateMipmaps', 'premultiplyAlpha', 'flipY', 'unpackAlignment', 'colorSpace'];
function steppedTexture(url, min, extent) {
  const map = texture(url);
  const copy = new THREE.Texture();
  for (const k of sharedSettings) copy[k] = map[k];
  copy.source = map.source;
  copy.version = map.version;
  copy.offset.set(min[0], min[1]);
  copy.repeat.set(extent[0], extent[1]);
  copy.userData.copy = true;
  waitingCopies.get(url)?.push(copy);
  return copy;
}

function srgb(c) {
  return new THREE.Color().setRGB(c[0], c[1], c[2], THREE.SRGBColorSpace);
}

// A group's box from the bounds its model came with.
function groupBox(group) {
  const b = group.userData.bounds;
  return b ? new THREE.Box3(new THREE.Vector3().fromArray(b.min), new THREE.Vector3().fromArray(b.max)) : new THREE.Box3();
}

// Frees the meshes' geometry and materials. Textures are shared between
// models (see `texture`): only the per-mesh copies go.
function disposeMeshes(meshes) {
  for (const child of meshes) {
    child.geometry.dispose();
    if (child.material.map?.userData.copy) child.material.map.dispose();
    child.material.dispose();
  }
}

// The meshes of one lot's frame (`lot` its header, `buffer` its arrays).
function lotMeshes(lot, buffer, { lots = false } = {}) {
  const out = [];
  for (const m of lot.meshes) {
    const geometry = new THREE.BufferGeometry();
    // Positions come as 16-bit steps across the mesh's box (see the
    // server's encode.rs): read as normalised, scaled by the box's
    // largest side and moved to its corner.
    geometry.setAttribute('position', new THREE.BufferAttribute(new Uint16Array(buffer, m.positions, m.vertices * 3), 3, true));
    // Bytes scaled by 127, read as normalised.
    geometry.setAttribute('normal', new THREE.BufferAttribute(normals(buffer, m), 3, true));
    let map = null;
    if (m.uvs !== null) {
      // 16-bit steps across the box are read as normalised, and the
      // map's offset and repeat put them back; else 32-bit floats.
      const steps = m.uv_bytes === 2;
      const Coords = steps ? Uint16Array : Float32Array;
      geometry.setAttribute('uv', new THREE.BufferAttribute(new Coords(buffer, m.uvs, m.vertices * 2), 2, steps));
      if (!lots && m.texture) map = steps ? steppedTexture(m.texture, m.uv_min, m.uv_extent) : texture(m.texture);
    }
    // Every quantised position lies in the unit cube: bounds known
    // without a pass over the vertices (three.js would make one for
    // culling and picking).
    geometry.boundingBox = new THREE.Box3(new THREE.Vector3(0, 0, 0), new THREE.Vector3(1, 1, 1));
    geometry.boundingSphere = new THREE.Sphere(new THREE.Vector3(0.5, 0.5, 0.5), Math.sqrt(3) / 2);
    geometry.setIndex(new THREE.BufferAttribute(indices(buffer, m), 1));
    const material = new THREE.MeshStandardMaterial({
      color: lots ? 0xa8a89e : srgb(m.color),
      map,
      roughness: 0.85,
      metalness: 0,
      transparent: m.opacity < 1,
      opacity: m.opacity,
      side: m.double_sided || lots ? THREE.DoubleSide : THREE.FrontSide,
      // Lots lie where the buildings stand: drawn behind them.
      polygonOffset: lots,
      polygonOffsetFactor: lots ? 2 : 0,
      polygonOffsetUnits: lots ? 2 : 0,
    });
    const mesh = new THREE.Mesh(geometry, material);
    mesh.position.fromArray(m.min);
    mesh.scale.setScalar(m.extent);
    mesh.castShadow = !lots;
    mesh.receiveShadow = true;
    mesh.userData = { lot: lot.index, lotName: lot.name, mesh: m.mesh, material: m.material };
    out.push(mesh);
  }
  return out;
}

// Puts `meshes` in `group` in place of what it held.
function replaceMeshes(group, meshes, bounds) {
  disposeMeshes(group.children);
  group.clear();
  if (meshes.length) group.add(...meshes);
  group.userData.bounds = bounds;
}

let lotsLoading = null;
let fitted = false;

// The lots' outlines, fetched once (again after a failure).
function loadLots() {
  lotsLoading ??= (async () => {
    const response = await fetch('api/lots.bin');
    if (!response.ok) throw new Error(`lots.bin: ${response.status}`);
    const meshes = [];
    const end = await readFrames(response, (header, data) => {
      if (header.lot) meshes.push(...lotMeshes(header.lot, data, { lots: true }));
    });
    replaceMeshes(lotsGroup, meshes, end.bounds);
  })().catch((e) => {
    lotsLoading = null;
    throw e;
  });
  return lotsLoading;
}

// The model being fetched: `{ controller, live }` (`live`: the number of
// the request whose model comes as it is made, else null and `version`:
// the model's number). A newer load aborts it.
let loading = null;
let lastState = null;

function beginLoad(fields) {
  loading?.controller.abort();
  loading = { controller: new AbortController(), live: null, version: 0, ...fields };
  return loading;
}

// Fetches a model's frames and builds each lot's meshes as it comes;
// resolves with the end frame's header, the meshes and the time spent
// building them, or null when the load was replaced or failed.
async function fetchModel(url, load) {
  const meshes = [];
  let buildMs = 0;
  try {
    const response = await fetch(url, { signal: load.controller.signal });
    if (!response.ok) return null;
    const end = await readFrames(response, (header, data) => {
      if (loading !== load) throw new Error('replaced');
      if (!header.lot) return;
      const t = performance.now();
      meshes.push(...lotMeshes(header.lot, data));
      buildMs += performance.now() - t;
    });
    if (loading === load && end.complete) return { end, meshes, buildMs };
  } catch {
    // Aborted, replaced or cut short: the model shown stays.
  }
  disposeMeshes(meshes);
  return null;
}

// Shows a model fetched by `fetchModel` (started at `t`) as model `version`.
// Resolves with whether it was shown (not when an older model than the
// one shown, or when the lots could not be loaded).
async function showModel(got, version, t, from) {
  const fetched = performance.now();
  try {
    await loadLots();
  } catch {
    disposeMeshes(got.meshes);
    return false;
  }
  if (version < page.modelVersion) {
    disposeMeshes(got.meshes);
    return false;
  }
  const swap = performance.now();
  replaceMeshes(modelGroup, got.meshes, got.end.bounds);
  const built = performance.now();
  const box = groupBox(modelGroup);
  const both = box.clone().union(groupBox(lotsGroup));
  makeGrids(both);
  if (!fitted) {
    fitted = true;
    fit();
  }
  render({ newModel: true });
  const rendered = performance.now();
  // Drawn is when the browser has shown the frame, not when the commands
  // were issued.
  await new Promise((r) => requestAnimationFrame(() => r()));
  // A newer model may have been drawn meanwhile: the version only grows.
  if (version < page.modelVersion) return true;
  page.modelVersion = version;
  // 'live': the lots came as they were made; 'whole': the last good model.
  page.drawnFrom = from;
  page.drawnAt = performance.now();
  page.drawMs = page.drawnAt - t;
  // Where the time went (the benchmark reads these): fetching (with the
  // lots' meshes built as they came, `build` of it), putting the meshes
  // in place, issuing the draw, until the frame was shown.
  page.drawParts = { fetch: fetched - t, build: got.buildMs + (built - swap), render: rendered - built, frame: page.drawnAt - rendered, sent: page.sentAt, state: page.stateAt, loadStart: t };
  // The exact bounds the server computed (the positions drawn are within
  // a step of 16 bits of the mesh's box).
  page.bounds = modelGroup.userData.bounds ?? null;
  $('stat-draw').textContent = `${page.drawMs.toFixed(1)} ms`;
  return true;
}

// The last good model, number `version`, all at once. (A load stays
// `loading` until its model is shown: a state naming it meanwhile does
// not load it again.)
async function loadModel(version) {
  const load = beginLoad({ version });
  const t = performance.now();
  const got = await fetchModel(`api/model.bin?v=${version}`, load);
  if (loading !== load) return;
  // The model sent is the newest, which may be newer than asked for.
  const shown = got ? await showModel(got, got.end.model_version ?? version, t, 'whole') : false;
  if (!shown) releaseShadows();
  if (loading === load) {
    loading = null;
    // Only after a success: a model that cannot be fetched now is asked
    // for again by the next state.
    if (shown) catchUp();
  }
}

// A newer model than the one shown that the states named while another
// was shown (a page's own values, then another page's): loaded now.
function catchUp() {
  if (!loading && lastState && lastState.model_version > page.modelVersion) loadModel(lastState.model_version);
}

// The model being made for request `n`, its lots fetched and built as
// each is made; when it is abandoned (a newer request, rules with errors,
// a failure), the model the latest state names is shown.
async function loadLive(n) {
  if (loading && loading.live !== null && loading.live >= n) return;
  const load = beginLoad({ live: n });
  const t = performance.now();
  const got = await fetchModel(`api/live.bin?n=${n}`, load);
  if (loading !== load) return;
  if (got) {
    const shown = await showModel(got, got.end.model_version, t, 'live');
    if (loading === load) {
      loading = null;
      if (shown) catchUp();
    }
    return;
  }
  loading = null;
  if (lastState && lastState.model_version > page.modelVersion) loadModel(lastState.model_version);
  else releaseShadows();
}

// The model as drawn: its triangles and their total area in square metres
// (tests compare it with the command's output).
page.modelTriangles = () => {
  let triangles = 0;
  let area = 0;
  const a = new THREE.Vector3();
  const b = new THREE.Vector3();
  const c = new THREE.Vector3();
  for (const mesh of modelGroup.children) {
    const position = mesh.geometry.getAttribute('position');
    const index = mesh.geometry.index;
    let sum = 0;
    for (let t = 0; t < index.count; t += 3) {
      a.fromBufferAttribute(position, index.getX(t));
      b.fromBufferAttribute(position, index.getX(t + 1));
      c.fromBufferAttribute(position, index.getX(t + 2));
      sum += b.sub(a).cross(c.sub(a)).length() / 2;
    }
    // Positions are steps across the mesh's box, scaled by its side.
    area += sum * mesh.scale.x * mesh.scale.x;
    triangles += index.count / 3;
  }
  return { triangles, area };
};

// The model's pixels: the share of the model's screen box that changes
// when the model is hidden (tests read it).
page.modelPixels = () => {
  const box = groupBox(modelGroup);
  if (box.isEmpty()) return { box: null, changed: 0, total: 0 };
  const corners = [];
  for (const x of [box.min.x, box.max.x]) for (const y of [box.min.y, box.max.y]) for (const z of [box.min.z, box.max.z]) {
    corners.push(new THREE.Vector3(x, y, z).project(camera));
  }
  const w = renderer.domElement.width;
  const h = renderer.domElement.height;
  const xs = corners.map((c) => Math.round((c.x + 1) / 2 * w));
  const ys = corners.map((c) => Math.round((1 - c.y) / 2 * h));
  const x0 = Math.max(0, Math.min(...xs)); const x1 = Math.min(w, Math.max(...xs));
  const y0 = Math.max(0, Math.min(...ys)); const y1 = Math.min(h, Math.max(...ys));
  const read = () => {
    render();
    const c = document.createElement('canvas');
    c.width = w; c.height = h;
    const g = c.getContext('2d');
    g.drawImage(renderer.domElement, 0, 0);
    return g.getImageData(x0, y0, Math.max(1, x1 - x0), Math.max(1, y1 - y0)).data;
  };
  const withModel = read();
  modelGroup.visible = false;
  const without = read();
  modelGroup.visible = true;
  render();
  let changed = 0;
  for (let i = 0; i < withModel.length; i += 4) {
    const d = Math.abs(withModel[i] - without[i]) + Math.abs(withModel[i + 1] - without[i + 1]) + Math.abs(withModel[i + 2] - without[i + 2]);
    if (d > 24) changed++;
  }
  return { box: [x0, y0, x1, y1], changed, total: withModel.length / 4 };
};

// ------------------------------------------------------------- attributes

let attributeSignature = '';
const values = {}; // name -> value set on the page
let seed = 0;
let sendTimer = null;

function sendParams() {
  // One request per frame at most; the server cancels what it obsoletes.
  if (sendTimer) return;
  sendTimer = requestAnimationFrame(async () => {
    sendTimer = null;
    page.sentAt = performance.now();
    holdShadows();
    setStatus('generating…', 'busy');
    await fetch('api/params', {
      method: 'POST',
      headers: { 'content-type': 'application/json' },
      body: JSON.stringify({ seed, attrs: values }),
    });
  });
}

$('seed').addEventListener('input', (e) => {
  const n = Math.max(0, Math.floor(Number(e.target.value) || 0));
  seed = n;
  sendParams();
});

function sortAttributes(attributes) {
  const groupOrder = new Map();
  for (const a of attributes) {
    const g = a.group ? a.group.name : '';
    const o = a.group && a.group.order !== null ? a.group.order : Infinity;
    if (!groupOrder.has(g) || o < groupOrder.get(g)) groupOrder.set(g, o);
  }
  const firstLine = new Map();
  for (const a of attributes) {
    const g = a.group ? a.group.name : '';
    firstLine.set(g, Math.min(firstLine.get(g) ?? Infinity, a.line ?? Infinity));
  }
  const key = (a) => {
    const g = a.group ? a.group.name : '';
    return [g === '' ? -Infinity : groupOrder.get(g), firstLine.get(g), g, a.order ?? Infinity, a.line ?? Infinity, a.name];
  };
  return [...attributes].sort((a, b) => {
    const ka = key(a); const kb = key(b);
    for (let i = 0; i < ka.length; i++) {
      if (ka[i] < kb[i]) return -1;
      if (ka[i] > kb[i]) return 1;
    }
    return 0;
  });
}

function text(v) {
  return typeof v === 'number' ? String(Math.round(v * 1000) / 1000) : String(v);
}

function control(a, value) {
  const set = (v) => { values[a.name] = v; sendParams(); };
  if (a.enum) {
    const select = document.createElement('select');
    for (const option of a.enum) {
      const o = document.createElement('option');
      o.value = JSON.stringify(option);
      o.textContent = text(option);
      select.append(o);
    }
    select.value = JSON.stringify(value);
    select.addEventListener('change', () => set(JSON.parse(select.value)));
    return select;
  }
  if (a.type === 'bool') {
    const box = document.createElement('input');
    box.type = 'checkbox';
    box.checked = value === true;
    box.addEventListener('change', () => set(box.checked));
    return box;
  }
  if (a.type === 'float' && a.range) {
    const wrap = document.createElement('span');
    wrap.className = 'with-value';
    const slider = document.createElement('input');
    slider.type = 'range';
    slider.min = a.range.min;
    slider.max = a.range.max;
    // Without a step: whole numbers where the range and default are
    // (counts such as floors), else 200 steps over the range.
    const whole = [a.range.min, a.range.max, a.default].every(Number.isInteger);
    slider.step = a.range.step ?? (whole ? 1 : ((a.range.max - a.range.min) / 200 || 'any'));
    slider.value = value;
    const out = document.createElement('output');
    out.textContent = text(value);
    slider.addEventListener('input', () => {
      out.textContent = text(Number(slider.value));
      set(Number(slider.value));
    });
    wrap.append(slider, out);
    return wrap;
  }
  if (a.type === 'float') {
    const input = document.createElement('input');
    input.type = 'number';
    input.step = 'any';
    input.value = value;
    input.addEventListener('change', () => { if (input.value !== '') set(Number(input.value)); });
    return input;
  }
  if (a.type === 'str' && a.color) {
    const input = document.createElement('input');
    input.type = 'color';
    input.value = /^#[0-9a-fA-F]{6}$/.test(value) ? value : '#000000';
    input.addEventListener('input', () => set(input.value));
    return input;
  }
  if (a.type === 'str' && a.files) {
    const select = document.createElement('select');
    const options = a.files.includes(value) ? a.files : [value, ...a.files];
    for (const f of options) {
      const o = document.createElement('option');
      o.value = f; o.textContent = f;
      select.append(o);
    }
    select.value = value;
    select.addEventListener('change', () => set(select.value));
    return select;
  }
  const input = document.createElement('input');
  input.type = 'text';
  input.value = Array.isArray(value) ? JSON.stringify(value) : value ?? '';
  input.readOnly = a.type !== 'str';
  input.addEventListener('change', () => set(input.value));
  return input;
}

function renderAttributes(state) {
  const signature = JSON.stringify(state.attributes.map((a) => [a.name, a.type, a.range, a.enum, a.color, a.group, a.order, a.hidden, a.description, a.files, a.default]));
  if (signature === attributeSignature) return;
  attributeSignature = signature;
  const form = $('attributes');
  form.replaceChildren();
  let group = null;
  for (const a of sortAttributes(state.attributes)) {
    if (a.hidden) continue;
    const g = a.group ? a.group.name : '';
    if (g !== group) {
      group = g;
      if (g) {
        const h = document.createElement('h3');
        h.textContent = g;
        form.append(h);
      }
    }
    const label = document.createElement('label');
    label.className = 'attr';
    label.dataset.attr = a.name;
    if (a.description) label.title = a.description;
    const name = document.createElement('span');
    name.className = 'name';
    name.textContent = a.name;
    const value = a.name in state.values ? state.values[a.name] : a.default;
    label.append(name, control(a, value));
    form.append(label);
  }
}

// ------------------------------------------------------------------ panels

function setStatus(message, kind = '') {
  const s = $('status');
  s.textContent = message;
  s.className = `status ${kind}`;
}

function renderProblems(problems) {
  const list = $('problems');
  list.replaceChildren();
  for (const p of problems) {
    const li = document.createElement('li');
    li.className = `problem ${p.severity}`;
    const where = document.createElement('div');
    where.className = 'where';
    where.textContent = p.file ? `${p.file}:${p.line}:${p.column}` : (p.lot ?? '');
    const message = document.createElement('div');
    message.textContent = `${p.severity}: ${p.message}${p.lot && p.file ? ` (lot ${p.lot})` : ''}`;
    li.append(where, message);
    if (p.line_text) {
      const pre = document.createElement('pre');
      pre.textContent = p.line_text;
      li.append(pre);
    }
    list.append(li);
  }
  $('problem-count').textContent = String(problems.length);
}

function row(table, cells) {
  const tr = document.createElement('tr');
  for (const [c, numeric] of cells) {
    const td = document.createElement('td');
    td.textContent = c;
    if (numeric) td.className = 'n';
    tr.append(td);
  }
  table.append(tr);
}

function renderStats(state) {
  const t = $('stats');
  t.replaceChildren();
  const s = state.stats;
  const n = (x) => Number(x).toLocaleString('en');
  row(t, [['lots'], [`${n(s.lots)}${s.failed ? ` (${s.failed} stopped)` : ''}`, true]]);
  row(t, [['shapes'], [n(s.shapes), true]]);
  row(t, [['leaves'], [n(s.leaves), true]]);
  row(t, [['faces'], [n(s.faces), true]]);
  row(t, [['triangles'], [n(s.triangles), true]]);
  row(t, [['load'], [`${s.load_ms.toFixed(1)} ms`, true]]);
  row(t, [['generate'], [`${s.generate_ms.toFixed(1)} ms`, true]]);
  row(t, [['encode'], [`${s.encode_ms.toFixed(1)} ms`, true]]);
  const tr = document.createElement('tr');
  tr.innerHTML = '<td>draw</td><td class="n" id="stat-draw"></td>';
  t.append(tr);
  if (page.drawMs !== undefined) $('stat-draw').textContent = `${page.drawMs.toFixed(1)} ms`;
}

function renderOutputs(state) {
  const multi = state.lots.length > 1;
  $('prints').textContent = state.prints.map((p) => (multi ? `[${p.lot}] ${p.text}` : p.text)).join('\n');
  $('print-count').textContent = String(state.prints.length);
  const t = $('reports');
  t.replaceChildren();
  for (const r of state.reports) row(t, multi ? [[r.lot], [r.key], [text(r.value), true]] : [[r.key], [text(r.value), true]]);
  $('report-count').textContent = String(state.reports.length);
}

function onState(state) {
  page.stateAt = performance.now();
  page.stateVersion = state.version;
  page.problems = state.problems;
  page.stale = state.stale;
  page.values = state.values;
  page.stats = state.stats;
  $('rules-name').textContent = state.rules;
  document.title = `${state.rules} · cga serve`;
  seed = state.seed;
  if (document.activeElement !== $('seed')) $('seed').value = String(state.seed);
  Object.assign(values, state.values);
  renderAttributes(state);
  renderProblems(state.problems);
  renderStats(state);
  renderOutputs(state);
  $('stale').hidden = !state.stale;
  const errors = state.problems.filter((p) => p.severity === 'error').length;
  if (errors) setStatus(`${errors} error${errors > 1 ? 's' : ''}`, 'error');
  else setStatus('up to date');
  lastState = state;
  // A model on its way (being made, or this one) is awaited.
  const awaited = loading && (loading.live !== null || loading.version === state.model_version);
  if (state.model_version > page.modelVersion && !awaited) loadModel(state.model_version);
  else if (!loading) releaseShadows();
}

// ------------------------------------------------------------- provenance

const raycaster = new THREE.Raycaster();
let down = null;
canvas.addEventListener('pointerdown', (e) => { down = [e.clientX, e.clientY]; });
canvas.addEventListener('pointerup', async (e) => {
  if (!down || Math.hypot(e.clientX - down[0], e.clientY - down[1]) > 4) return;
  const r = canvas.getBoundingClientRect();
  const pointer = new THREE.Vector2((e.clientX - r.left) / r.width * 2 - 1, -((e.clientY - r.top) / r.height) * 2 + 1);
  raycaster.setFromCamera(pointer, camera);
  const hit = raycaster.intersectObjects(modelGroup.children, false)[0];
  const box = $('picked');
  if (!hit) { box.hidden = true; page.picked = null; return; }
  const { lot, mesh } = hit.object.userData;
  const response = await fetch(`api/provenance?lot=${lot}&mesh=${mesh}&tri=${hit.faceIndex}`);
  if (!response.ok) { box.hidden = true; return; }
  const p = await response.json();
  page.picked = p;
  box.replaceChildren();
  const head = document.createElement('div');
  head.textContent = `${p.rule ?? '(no rule)'} → ${p.shape}${p.file ? ` at ${p.file}:${p.line}:${p.column}` : ''} · lot ${p.lot}`;
  box.append(head);
  if (p.line_text) {
    const pre = document.createElement('pre');
    pre.textContent = p.line_text;
    box.append(pre);
  }
  box.hidden = false;
});

// ------------------------------------------------------------------ events

function connect() {
  const events = new EventSource('api/events');
  events.addEventListener('state', (e) => onState(JSON.parse(e.data)));
  events.addEventListener('generating', (e) => {
    holdShadows();
    setStatus('generating…', 'busy');
    // Pages in the background leave the connection to the one in view
    // (a browser opens six to a server); they load the model the state
    // names.
    if (document.visibilityState === 'visible') loadLive(Number(e.data));
  });
  events.onerror = () => setStatus('disconnected: is cga serve running?', 'error');
  events.onopen = () => {
    setStatus('connected');
    // A server started again counts its models from 1: the model its
    // first state names is loaded whatever this page showed.
    page.modelVersion = 0;
  };
}

render();
connect();
