// A viewer for the 3D Tiles 1.1 tilesets that `cga generate ... -o
// out/tileset.json` writes (docs/tiles.md), on 3d-tiles-renderer and
// three.js: `tiles.html?tileset=URL` loads the tileset, frames it, and
// clicking a building shows its lot (the tile's EXT_mesh_features feature
// id and the row of its EXT_structural_metadata property table).
//
// URL parameters:
//   tileset=URL       the tileset.json (default: tileset.json beside the page)
//   errorTarget=PX    screen-space error to refine to (default 6; 0 loads
//                     every leaf in view)
//   shadows=0         no shadow map (faster in a software renderer)
//
// What tests (and curious users) can read: `window.tilesState`.

import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { TilesRenderer } from '3d-tiles-renderer/three';
import { GLTFExtensionsPlugin, ReorientationPlugin } from '3d-tiles-renderer/three/plugins';

const $ = (id) => document.getElementById(id);
const BACKGROUND = 0xdde3ea;
const GROUND = 0xc9cbc4;

const params = new URLSearchParams(location.search);
const tilesetUrl = new URL(params.get('tileset') || 'tileset.json', location.href).href;
const errorTarget = Number(params.get('errorTarget') ?? 6);
const shadows = params.get('shadows') !== '0';

const state = {
  tileset: tilesetUrl,
  errorTarget,
  ready: false, // the root tileset is loaded and the camera framed
  loading: false, // tiles are queued, downloading or parsing
  georeferenced: false, // the root has a transform to ECEF
  rootTransform: null, // column-major 4x4, as in tileset.json
  contents: [], // the URL of every tile content in tileset.json
  requested: [], // URLs of the tile contents requested so far
  loaded: [], // ... loaded (parsed into meshes) so far
  failed: [], // ... that failed
  errors: [], // messages of every error seen on the page
  triangles: 0, // in the tiles drawn in the last frame
  tilesDrawn: 0, // tiles with content drawn in the last frame
  frames: 0,
  picked: null, // the lot last clicked: {index, name, attributes, reports, tile, featureId, instanced, point, local}
};
window.tilesState = state;

const requested = new Set();
const loaded = new Set();
const failed = new Set();
function error(message) {
  state.errors.push(String(message));
  const m = $('message');
  m.textContent = state.errors[0];
  m.hidden = false;
}
window.addEventListener('error', (e) => error(e.message));
window.addEventListener('unhandledrejection', (e) => error(e.reason?.message || e.reason));

// ---------------------------------------------------------------- viewport

const canvas = $('canvas');
// The drawing buffer is kept so that tests can read the pixels drawn.
const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
renderer.shadowMap.enabled = shadows;
renderer.shadowMap.type = THREE.PCFShadowMap;
const scene = new THREE.Scene();
scene.background = new THREE.Color(BACKGROUND);
const camera = new THREE.PerspectiveCamera(40, 1, 1, 10000);
const controls = new OrbitControls(camera, canvas);
controls.enableDamping = false;

// Sky and ground light, and a sun from the south-west, high enough that
// streets are not all in shadow; placed once the city's frame is known.
const hemisphere = new THREE.HemisphereLight(0xffffff, 0x8d8a80, 1.5);
const sun = new THREE.DirectionalLight(0xffffff, 2.0);
sun.castShadow = shadows;
sun.shadow.mapSize.set(4096, 4096);
// Without a bias, walls shadow themselves in stripes (shadow acne).
sun.shadow.bias = -0.0005;
sun.shadow.normalBias = 0.05;
scene.add(hemisphere, sun, sun.target);
const ground = new THREE.Mesh(
  new THREE.CircleGeometry(1, 96),
  new THREE.MeshStandardMaterial({ color: GROUND, roughness: 1 }),
);
ground.receiveShadow = true;
ground.visible = false;
scene.add(ground);

// ---------------------------------------------------------------- tiles

const tiles = new TilesRenderer(tilesetUrl);
tiles.registerPlugin(new GLTFExtensionsPlugin({ metadata: true, rtc: true }));
// A georeferenced tileset (root transform to ECEF) is brought back to the
// origin, its up to three.js' +y; a local one (z up) is turned y up and
// centred.
tiles.registerPlugin(new ReorientationPlugin({ recenter: true, up: '+z' }));
tiles.errorTarget = errorTarget;
tiles.setCamera(camera);
tiles.setResolutionFromRenderer(camera, renderer);
scene.add(tiles.group);

// Which tile a loaded scene is (for picking).
const tileOf = new WeakMap();

// The picked lot is drawn highlighted: the tiles' materials compare each
// vertex's feature id (EXT_mesh_features' attribute) with the picked one,
// which is set on the materials of the picked tile only (feature ids are
// rows of each tile's own property table).
const NONE = -1;
// Instanced assets (EXT_mesh_gpu_instancing) carry their lot's feature id
// per instance (EXT_instance_features), which three.js' GLTFLoader keeps
// as this instanced attribute; 3d-tiles-renderer does not read that
// extension, so the page does.
const INSTANCE_FEATURE = '_FEATURE_ID_0';
// `attribute`: the feature id's attribute (per vertex, or per instance for
// instanced assets).
function highlightable(material, attribute) {
  material.userData.highlight = { value: NONE };
  material.onBeforeCompile = (shader) => {
    shader.uniforms.highlightFeature = material.userData.highlight;
    shader.vertexShader = shader.vertexShader
      .replace('void main() {', `attribute float ${attribute};\nvarying float vFeature;\nvoid main() {\n\tvFeature = ${attribute};`);
    shader.fragmentShader = shader.fragmentShader
      .replace('void main() {', 'uniform float highlightFeature;\nvarying float vFeature;\nvoid main() {')
      .replace('#include <color_fragment>', '#include <color_fragment>\n\tif (abs(vFeature - highlightFeature) < 0.5) diffuseColor.rgb = mix(diffuseColor.rgb, vec3(1.0, 0.55, 0.1), 0.65);');
  };
  material.customProgramCacheKey = () => `cga-feature-highlight-${attribute}`;
  material.needsUpdate = true;
}
let highlighted = []; // materials with a highlight set
function highlight(scene, featureId) {
  for (const m of highlighted) m.userData.highlight.value = NONE;
  highlighted = [];
  if (!scene) return;
  scene.traverse((o) => {
    if (!o.isMesh) return;
    for (const m of Array.isArray(o.material) ? o.material : [o.material]) {
      if (m.userData.highlight) {
        m.userData.highlight.value = featureId;
        highlighted.push(m);
      }
    }
  });
  requestRender();
}

tiles.addEventListener('tile-download-start', (e) => {
  requested.add(e.url);
  state.requested = [...requested];
});
tiles.addEventListener('load-model', (e) => {
  loaded.add(e.url);
  state.loaded = [...loaded];
  tileOf.set(e.scene, e.tile);
  e.scene.traverse((o) => {
    if (o.isMesh) {
      o.castShadow = shadows;
      o.receiveShadow = shadows;
      if (o.userData.meshFeatures && o.geometry.getAttribute('_feature_id_0')) {
        for (const m of Array.isArray(o.material) ? o.material : [o.material]) highlightable(m, '_feature_id_0');
      } else if (o.isInstancedMesh && o.geometry.getAttribute(INSTANCE_FEATURE)) {
        // Its own material: a shared one may also draw meshes without
        // instances, whose feature ids are another attribute.
        o.material = o.material.clone();
        highlightable(o.material, INSTANCE_FEATURE);
      }
    }
  });
  counts();
  requestRender();
});
tiles.addEventListener('load-error', (e) => {
  if (e.url) failed.add(e.url);
  state.failed = [...failed];
  // The root tileset itself (no tile): say how to name another one.
  const hint = e.tile ? '' : ' (open this page as tiles.html?tileset=URL of a tileset.json)';
  error(`${e.url || tilesetUrl}: ${e.error?.message || e.error}${hint}`);
  counts();
});
tiles.addEventListener('tiles-load-start', () => { state.loading = true; setStatus(); });
tiles.addEventListener('tiles-load-end', () => { state.loading = false; setStatus(); requestRender(); });
tiles.addEventListener('needs-update', () => requestRender());
tiles.addEventListener('needs-render', () => requestRender());

// The reorientation plugin listens for the root tileset first (it was
// registered before this listener), so the group is placed by now.
tiles.addEventListener('load-root-tileset', (e) => {
  const root = e.tileset.root;
  state.rootTransform = root.transform || null;
  state.georeferenced = !!root.transform && new THREE.Vector3(root.transform[12], root.transform[13], root.transform[14]).length() > 1e6;
  const contents = [];
  const walk = (tile) => {
    const uri = tile.content?.uri || tile.content?.url;
    if (uri) contents.push(new URL(uri, e.url).href);
    (tile.children || []).forEach(walk);
  };
  walk(root);
  state.contents = contents;
  placeLights();
  $('tileset-name').textContent = decodeURIComponent(new URL(e.url).pathname.split('/').pop());
  fit();
  state.ready = true;
  counts();
});

// ---------------------------------------------------------------- framing

// The tileset's frame in the world: east, north and up (unit vectors),
// and the box of `points` (of the tileset's frame, after the root
// transform) or else of the root's bounding volume.
function frame(points = null) {
  tiles.group.updateMatrixWorld(true);
  const local = new THREE.Matrix4();
  if (state.rootTransform) local.fromArray(state.rootTransform);
  const toWorld = tiles.group.matrixWorld;
  const axis = (k) => new THREE.Vector3().setFromMatrixColumn(local, k).transformDirection(toWorld);
  const box = new THREE.Box3();
  if (points) {
    for (const p of points) box.expandByPoint(new THREE.Vector3(...p).applyMatrix4(toWorld));
  } else {
    const obb = new THREE.Box3();
    const obbMatrix = new THREE.Matrix4();
    if (tiles.getOrientedBoundingBox(obb, obbMatrix)) {
      const m = obbMatrix.clone().premultiply(toWorld);
      for (const x of [obb.min.x, obb.max.x]) for (const y of [obb.min.y, obb.max.y]) for (const z of [obb.min.z, obb.max.z]) {
        box.expandByPoint(new THREE.Vector3(x, y, z).applyMatrix4(m));
      }
    }
  }
  return { east: axis(0), north: axis(1), up: axis(2), box };
}

// The ground and the sun, for the whole tileset.
function placeLights() {
  const { east, north, up, box } = frame();
  if (box.isEmpty()) return;
  const sphere = box.getBoundingSphere(new THREE.Sphere());
  const r = Math.max(sphere.radius, 1);
  // The ground: a disc under the city, at its lowest point.
  const bottom = Math.min(...[box.min, box.max].map((p) => p.dot(up)));
  ground.scale.setScalar(r * 30);
  ground.position.copy(sphere.center).addScaledVector(up, bottom - sphere.center.dot(up) - 0.05);
  ground.quaternion.setFromUnitVectors(new THREE.Vector3(0, 0, 1), up);
  ground.visible = true;

  // The sun from the south-west, 50 degrees high; its shadow camera
  // around the city.
  const toSun = east.clone().multiplyScalar(-0.45).addScaledVector(north, -0.55).normalize()
    .multiplyScalar(Math.cos(THREE.MathUtils.degToRad(50))).addScaledVector(up, Math.sin(THREE.MathUtils.degToRad(50)));
  sun.target.position.copy(sphere.center);
  sun.position.copy(sphere.center).addScaledVector(toSun, r * 3);
  const s = sun.shadow.camera;
  s.left = -r; s.right = r; s.top = r; s.bottom = -r;
  s.near = r * 0.5; s.far = r * 6;
  s.updateProjectionMatrix();
  sun.shadow.normalBias = r / 2000;
}

// Frames the whole tileset (or `points` of its frame) from the
// south-east, above.
function fit(points = null) {
  const { east, north, up, box } = frame(points);
  if (box.isEmpty()) return;
  const sphere = box.getBoundingSphere(new THREE.Sphere());
  const r = Math.max(sphere.radius, 1);
  const view = east.clone().multiplyScalar(0.55).addScaledVector(north, -0.8).addScaledVector(up, 0.75).normalize();
  // From the distance at which the bounding sphere fits, come closer
  // until the box's corners fill the view (a sphere around a flat city
  // leaves most of the screen empty).
  resize();
  const corners = [];
  for (const x of [box.min.x, box.max.x]) for (const y of [box.min.y, box.max.y]) for (const z of [box.min.z, box.max.z]) {
    corners.push(new THREE.Vector3(x, y, z));
  }
  let distance = r / Math.sin(THREE.MathUtils.degToRad(camera.fov / 2));
  const whole = frame().box.getBoundingSphere(new THREE.Sphere());
  camera.near = Math.max(distance / 1000, 0.1);
  camera.far = distance + whole.radius * 40;
  camera.updateProjectionMatrix();
  controls.target.copy(sphere.center);
  for (let k = 0; k < 8; k++) {
    camera.position.copy(sphere.center).addScaledVector(view, distance);
    camera.lookAt(sphere.center);
    camera.updateMatrixWorld();
    const extent = Math.max(...corners.map((c) => {
      const p = c.clone().project(camera);
      return Math.max(Math.abs(p.x), Math.abs(p.y));
    }));
    distance *= 1 + (extent / 0.92 - 1) * 0.7;
  }
  controls.update();
  // The ground fades into the sky far behind the city.
  const far = distance + whole.radius;
  scene.fog = new THREE.Fog(BACKGROUND, far * 1.5, far * 8);
  requestRender();
}
$('fit').addEventListener('click', () => fit());

// ---------------------------------------------------------------- drawing

function resize() {
  const w = canvas.clientWidth;
  const h = canvas.clientHeight;
  if (canvas.width !== Math.floor(w * renderer.getPixelRatio()) || canvas.height !== Math.floor(h * renderer.getPixelRatio())) {
    renderer.setSize(w, h, false);
    camera.aspect = w / Math.max(h, 1);
    camera.updateProjectionMatrix();
  }
}

function render() {
  resize();
  camera.updateMatrixWorld();
  tiles.setResolutionFromRenderer(camera, renderer);
  tiles.update();
  renderer.render(scene, camera);
  state.frames++;
  let triangles = 0;
  let drawn = 0;
  for (const tile of tiles.visibleTiles) {
    const s = tile.engineData?.scene;
    if (!s) continue;
    drawn++;
    s.traverse((o) => {
      if (o.isMesh && o.visible) {
        const g = o.geometry;
        triangles += ((g.index ? g.index.count : g.attributes.position.count) / 3) * (o.isInstancedMesh ? o.count : 1);
      }
    });
  }
  state.triangles = triangles;
  state.tilesDrawn = drawn;
}

// Frames are drawn when something changed (a tile loaded, the camera
// moved), not continuously: a software renderer has the CPU to itself.
let scheduled = false;
function requestRender() {
  if (scheduled) return;
  scheduled = true;
  requestAnimationFrame(() => {
    scheduled = false;
    render();
  });
}
controls.addEventListener('change', requestRender);
window.addEventListener('resize', requestRender);

function setStatus() {
  const s = $('status');
  if (failed.size) {
    s.textContent = `${failed.size} failed`;
    s.className = 'status error';
  } else if (state.loading || !state.ready) {
    s.textContent = 'loading…';
    s.className = 'status busy';
  } else {
    s.textContent = 'loaded';
    s.className = 'status';
  }
}
function counts() {
  $('counts').textContent = `${loaded.size} of ${state.contents.length} tiles loaded`;
  setStatus();
}

// ---------------------------------------------------------------- picking

const raycaster = new THREE.Raycaster();

// The lot under a point of the canvas (CSS pixels from its corner), or
// null: the first mesh hit with feature ids gives the feature id at the
// hit, and its tile's property table that lot's row.
function pickAt(x, y) {
  const rect = canvas.getBoundingClientRect();
  const ndc = new THREE.Vector2((x / rect.width) * 2 - 1, -(y / rect.height) * 2 + 1);
  raycaster.setFromCamera(ndc, camera);
  const hits = raycaster.intersectObject(tiles.group, true);
  const instanced = (h) => h.object.isInstancedMesh && h.instanceId !== undefined && h.object.geometry.getAttribute(INSTANCE_FEATURE);
  const hit = hits.find((h) => h.object.userData.meshFeatures || instanced(h));
  if (!hit) {
    highlight(null);
    return null;
  }
  let tile = null;
  let tileScene = null;
  for (let o = hit.object; o && !tile; o = o.parent) {
    tile = tileOf.get(o) || null;
    if (tile) tileScene = o;
  }
  let featureId;
  let table;
  let metadata = hit.object.userData.structuralMetadata;
  if (hit.object.userData.meshFeatures) {
    const features = hit.object.userData.meshFeatures;
    [featureId] = features.getFeatures(hit.faceIndex, hit.barycoord);
    table = features.getFeatureInfo()[0].propertyTable;
  } else {
    featureId = hit.object.geometry.getAttribute(INSTANCE_FEATURE).getX(hit.instanceId);
    // The tile's one property table (the engine writes one a tile).
    metadata = metadata || tileScene?.userData.structuralMetadata;
    table = 0;
  }
  const picked = {
    tile: tile ? new URL(tile.content.uri, tilesetUrl).href : null,
    featureId,
    instanced: !hit.object.userData.meshFeatures, // an instanced asset
    index: null,
    name: null,
    attributes: {},
    reports: {},
    // The hit in the tileset's frame (after the root transform: ECEF for
    // a georeferenced tileset) and before the root transform (metres east,
    // north, up).
    point: null,
    local: null,
  };
  const inGroup = hit.point.clone().applyMatrix4(tiles.group.matrixWorld.clone().invert());
  picked.point = inGroup.toArray();
  picked.local = state.rootTransform
    ? inGroup.clone().applyMatrix4(new THREE.Matrix4().fromArray(state.rootTransform).invert()).toArray()
    : picked.point;
  if (metadata && featureId !== null && table !== null && table !== undefined) {
    const row = metadata.getPropertyTableData(table, featureId);
    const className = metadata.getPropertyTableInfo([table])[0].className;
    const properties = metadata.schema.classes[className].properties;
    // The writer's columns (docs/tiles.md): `index`, `name`, `attr_NAME`
    // and `report_KEY`, with NAME and KEY in the property's `name`.
    for (const [id, value] of Object.entries(row)) {
      const label = properties[id]?.name || id;
      if (id === 'index') picked.index = Number(value);
      else if (id === 'name') picked.name = value;
      else if (id.startsWith('report_')) picked.reports[label] = typeof value === 'bigint' ? Number(value) : value;
      else picked.attributes[label] = value;
    }
  }
  highlight(tileScene, featureId ?? NONE);
  return picked;
}

function showPicked(p) {
  const panel = $('picked');
  if (!p) {
    panel.hidden = true;
    return;
  }
  panel.replaceChildren();
  const title = document.createElement('div');
  title.innerHTML = '<strong>lot</strong> ';
  title.append(`${p.index ?? '?'}`, p.name !== null ? ` · ${p.name}` : '');
  const table = document.createElement('table');
  const rows = (values, kind) => {
    for (const [k, v] of Object.entries(values)) {
      const tr = table.insertRow();
      tr.dataset[kind] = k;
      tr.insertCell().textContent = k;
      tr.insertCell().textContent = typeof v === 'number' ? String(Math.round(v * 1000) / 1000) : v;
    }
  };
  rows(p.attributes, 'attr');
  if (Object.keys(p.reports).length) {
    const h = table.insertRow().insertCell();
    h.colSpan = 2;
    h.className = 'heading';
    h.textContent = 'reports';
  }
  rows(p.reports, 'report');
  const where = document.createElement('div');
  where.className = 'note';
  where.textContent = `feature ${p.featureId} of ${p.tile ? p.tile.split('/').pop() : 'a tile'}`;
  panel.append(title, table, where);
  panel.hidden = false;
}

// A click (not the end of a drag) picks.
let down = null;
canvas.addEventListener('pointerdown', (e) => { down = [e.clientX, e.clientY]; });
canvas.addEventListener('pointerup', (e) => {
  if (!down || Math.hypot(e.clientX - down[0], e.clientY - down[1]) > 4) return;
  const rect = canvas.getBoundingClientRect();
  try {
    state.picked = pickAt(e.clientX - rect.left, e.clientY - rect.top);
    showPicked(state.picked);
  } catch (err) {
    error(`picking: ${err.message}`);
  }
});

// ---------------------------------------------------------------- for tests

// Where a point of the tileset's frame (after the root transform) is on
// the canvas, in CSS pixels from its corner, and whether it is in view.
state.project = (p) => {
  const v = new THREE.Vector3(...p).applyMatrix4(tiles.group.matrixWorld).project(camera);
  const rect = canvas.getBoundingClientRect();
  return { x: (v.x + 1) / 2 * rect.width, y: (1 - v.y) / 2 * rect.height, inView: Math.abs(v.x) <= 1 && Math.abs(v.y) <= 1 && v.z < 1 };
};

// Pixels of the city: those that change when the tiles are hidden, over
// the screen box of the root's bounding volume (or of `points` of the
// tileset's frame).
state.cityPixels = (points = null) => {
  const { box } = frame(points);
  if (box.isEmpty()) return { box: null, changed: 0, total: 0 };
  const w = renderer.domElement.width;
  const h = renderer.domElement.height;
  const xs = [];
  const ys = [];
  for (const x of [box.min.x, box.max.x]) for (const y of [box.min.y, box.max.y]) for (const z of [box.min.z, box.max.z]) {
    const c = new THREE.Vector3(x, y, z).project(camera);
    xs.push(Math.round((c.x + 1) / 2 * w));
    ys.push(Math.round((1 - c.y) / 2 * h));
  }
  const x0 = Math.max(0, Math.min(...xs)); const x1 = Math.min(w, Math.max(...xs));
  const y0 = Math.max(0, Math.min(...ys)); const y1 = Math.min(h, Math.max(...ys));
  const read = () => {
    renderer.render(scene, camera);
    const c = document.createElement('canvas');
    c.width = w; c.height = h;
    const g = c.getContext('2d');
    g.drawImage(renderer.domElement, 0, 0);
    return g.getImageData(x0, y0, Math.max(1, x1 - x0), Math.max(1, y1 - y0)).data;
  };
  const withCity = read();
  tiles.group.visible = false;
  const without = read();
  tiles.group.visible = true;
  renderer.render(scene, camera);
  let changed = 0;
  for (let i = 0; i < withCity.length; i += 4) {
    const d = Math.abs(withCity[i] - without[i]) + Math.abs(withCity[i + 1] - without[i + 1]) + Math.abs(withCity[i + 2] - without[i + 2]);
    if (d > 24) changed++;
  }
  return { box: [x0, y0, x1, y1], changed, total: withCity.length / 4 };
};
// The colour drawn at a point of the canvas (CSS pixels), [r, g, b].
state.pixelAt = (x, y) => {
  render();
  const ratio = renderer.getPixelRatio();
  const c = document.createElement('canvas');
  c.width = 1; c.height = 1;
  c.getContext('2d').drawImage(renderer.domElement, Math.floor(x * ratio), Math.floor(y * ratio), 1, 1, 0, 0, 1, 1);
  return [...c.getContext('2d').getImageData(0, 0, 1, 1).data.slice(0, 3)];
};
state.pickAt = pickAt;
state.fit = fit;

requestRender();
