// A tileset in a real browser: `cga generate examples/building.cga --lot
// city.geojson -o out/tileset.json` (the rules with a report added) over a
// small city made here (150 lots
// in longitude/latitude, and the same city in local metres), served by a
// static server of our own, loaded by the viewer page (web/src/tiles.js:
// 3d-tiles-renderer and three.js) in Debian's Chromium driven by
// Playwright. Every tile must load without an error, the city must be
// drawn, and clicking a building must give its lot's index and attributes
// from the tile's feature ids and property table.
//
// SCREENSHOTS: a folder to save screenshots into (docs/images/tileset.png
// comes from `SCREENSHOTS=../docs/images npm test`).

import { test, before, after, describe } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { createServer } from 'node:http';
import { mkdtempSync, readFileSync, writeFileSync, rmSync, mkdirSync, statSync, unlinkSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, normalize, extname } from 'node:path';
import { repo, cgaBinary, launchBrowser, startServer } from './harness.mjs';

// ------------------------------------------------------------------ city

// A centre of 12 x 10 lots of 20 m x 24 m, 10 m apart, and a suburb of
// 6 x 5 to the north-east, around a point of Zurich: the quadtree splits
// the centre once more (64 lots a leaf at most), so there are massing
// tiles at two levels and leaves at two. The floors vary (2 to 8), one
// tower has 18, and each lot has an owner (a property that is no rule
// attribute) and a wall colour (one that is).
const DISTRICTS = [
  { cols: 12, rows: 10, at: [0, 0] },
  { cols: 6, rows: 5, at: [560, 560] },
];
const LOT = [20, 24];
const PITCH = [30, 34];
const TOWER = 77; // in the centre
const SUBURB = 149; // the last lot
const ORIGIN = { lon: 8.5417, lat: 47.3769 };
const LOCAL_ORIGIN = [1000, 2000]; // metres, for the local city
const COLOURS = ['#d8cfc4', '#c9b8a6', '#e6dfd2', '#b7a99a', '#d3c2b0'];

const floorsOf = (i) => (i === TOWER ? 18 : 2 + ((i * 5) % 7));
// examples/building.cga: a 4.5 m ground floor and floors of 3.2 m.
const heightOf = (i) => 4.5 + floorsOf(i) * 3.2;

// Degrees per metre near the origin (the test only needs them to lay the
// lots out; expectations use the lots' own coordinates).
const DEG_LAT = 1 / 111132;
const DEG_LON = 1 / (111320 * Math.cos((ORIGIN.lat * Math.PI) / 180));

/// The lots as [x0, y0, x1, y1] in metres east and north of about the
/// city's middle.
function lotBoxes() {
  const boxes = [];
  for (const { cols, rows, at } of DISTRICTS) {
    for (let i = 0; i < cols * rows; i++) {
      const x0 = at[0] + (i % cols) * PITCH[0] - 365;
      const y0 = at[1] + Math.floor(i / cols) * PITCH[1] - 360;
      boxes.push([x0, y0, x0 + LOT[0], y0 + LOT[1]]);
    }
  }
  return boxes;
}

/// A GeoJSON FeatureCollection of the lots, `place` turning metres east
/// and north into the file's coordinates.
function cityGeojson(place) {
  return {
    type: 'FeatureCollection',
    features: lotBoxes().map(([x0, y0, x1, y1], i) => ({
      type: 'Feature',
      id: `B${String(i).padStart(3, '0')}`,
      properties: { floors: floorsOf(i), wallColor: COLOURS[i % COLOURS.length], owner: `owner ${i}` },
      geometry: {
        type: 'Polygon',
        // Counter-clockwise, as RFC 7946 has exterior rings.
        coordinates: [[[x0, y0], [x1, y0], [x1, y1], [x0, y1], [x0, y0]].map(([x, y]) => place(x, y))],
      },
    })),
  };
}
const geographic = (x, y) => [ORIGIN.lon + x * DEG_LON, ORIGIN.lat + y * DEG_LAT];
const local = (x, y) => [LOCAL_ORIGIN[0] + x, LOCAL_ORIGIN[1] + y];

/// ECEF (WGS84) of a longitude, latitude (degrees) and height (metres).
function ecef(lon, lat, h) {
  const a = 6378137;
  const f = 1 / 298.257223563;
  const e2 = f * (2 - f);
  const [l, p] = [(lon * Math.PI) / 180, (lat * Math.PI) / 180];
  const n = a / Math.sqrt(1 - e2 * Math.sin(p) ** 2);
  return [(n + h) * Math.cos(p) * Math.cos(l), (n + h) * Math.cos(p) * Math.sin(l), (n * (1 - e2) + h) * Math.sin(p)];
}

/// The centre of lot `i`'s outline in the file's coordinates.
function lotCentre(geojson, i) {
  const ring = geojson.features[i].geometry.coordinates[0].slice(0, 4);
  return [0, 1].map((k) => ring.reduce((s, p) => s + p[k], 0) / 4);
}

// ------------------------------------------------------------------ tileset

/// Tile contents in a tileset.json (URIs relative to it).
function contents(tile, out = []) {
  if (tile.content?.uri) out.push(tile.content.uri);
  (tile.children || []).forEach((c) => contents(c, out));
  return out;
}

/// Triangles a GLB draws (indexed triangle lists, as the engine writes):
/// each node's mesh, times its instances (EXT_mesh_gpu_instancing).
function glbTriangles(path) {
  const bytes = readFileSync(path);
  const len = bytes.readUInt32LE(12);
  const json = JSON.parse(bytes.subarray(20, 20 + len).toString('utf8'));
  let triangles = 0;
  for (const node of json.nodes || []) {
    if (node.mesh === undefined) continue;
    let mesh = 0;
    for (const p of json.meshes[node.mesh].primitives) {
      assert.ok(p.mode === undefined || p.mode === 4, 'triangle lists');
      mesh += json.accessors[p.indices].count / 3;
    }
    const instancing = node.extensions?.EXT_mesh_gpu_instancing;
    triangles += mesh * (instancing ? json.accessors[instancing.attributes.TRANSLATION].count : 1);
  }
  return triangles;
}

/// Leaves: tiles without children (REPLACE refinement draws these alone
/// once everything is loaded).
function leaves(tile, out = []) {
  if (!tile.children?.length) {
    if (tile.content?.uri) out.push(tile.content.uri);
  } else tile.children.forEach((c) => leaves(c, out));
  return out;
}

/// examples/building.cga, with each lot reporting its footprint's area
/// (a report for the property table's `report_` columns).
function writeRules(dir) {
  const original = readFileSync(join(repo, 'examples', 'building.cga'), 'utf8');
  const rules = original.replace('Lot -->\n', 'Lot -->\n\treport("footprint", geometry.area)\n');
  assert.notEqual(rules, original);
  const path = join(dir, 'building.cga');
  writeFileSync(path, rules);
  return path;
}

function generate(dir, name, geojson, extra = []) {
  const lots = join(dir, `${name}.geojson`);
  writeFileSync(lots, JSON.stringify(geojson));
  const out = join(dir, name, 'tileset.json');
  const run = spawnSync(
    cgaBinary(),
    ['generate', writeRules(dir), '--lot', lots, ...extra, '-o', out],
    { encoding: 'utf8' },
  );
  assert.equal(run.status, 0, `cga generate failed:\n${run.stdout}\n${run.stderr}`);
  return JSON.parse(readFileSync(out, 'utf8'));
}

// ------------------------------------------------------------------ server

const TYPES = {
  '.html': 'text/html', '.js': 'text/javascript', '.css': 'text/css', '.map': 'application/json',
  '.json': 'application/json', '.glb': 'model/gltf-binary',
};

/// A static server: `/viewer/...` is web/dist, `/data/...` the folder of
/// the tilesets. Every request and its status is kept.
function serve(data) {
  const roots = { viewer: join(repo, 'web', 'dist'), data };
  const log = [];
  const server = createServer((req, res) => {
    const path = decodeURIComponent(new URL(req.url, 'http://x').pathname);
    const [, top, ...rest] = path.split('/');
    const root = roots[top];
    const file = root && normalize(join(root, ...rest));
    let status = 404;
    if (file && file.startsWith(root) && statSync(file, { throwIfNoEntry: false })?.isFile()) {
      status = 200;
      res.writeHead(200, { 'content-type': TYPES[extname(file)] || 'application/octet-stream' });
      res.end(readFileSync(file));
    } else {
      res.writeHead(404).end();
    }
    log.push({ path, status });
  });
  return new Promise((resolve) => {
    server.listen(0, '127.0.0.1', () => resolve({ server, log, url: `http://127.0.0.1:${server.address().port}` }));
  });
}

// ------------------------------------------------------------------ tests

let dir;
let http;
let browser;

before(async () => {
  dir = mkdtempSync(join(tmpdir(), 'cga-tiles-'));
  http = await serve(dir);
  browser = await launchBrowser();
});

after(async () => {
  await browser?.close();
  http?.server.close();
  if (dir) rmSync(dir, { recursive: true, force: true });
});

/// Opens the viewer on a tileset with every leaf wanted and waits until
/// nothing more is loading. Returns the page, the console's errors and the
/// page's state.
async function view(name, url = `${http.url}/viewer/tiles.html?tileset=/data/${name}/tileset.json&errorTarget=0`) {
  const page = await browser.context.newPage();
  const consoleErrors = [];
  page.on('console', (m) => { if (m.type() === 'error') consoleErrors.push(`${m.text()} (${m.location().url})`); });
  page.on('pageerror', (e) => consoleErrors.push(`page error: ${e.message}`));
  await page.goto(url);
  const settled = () => page.waitForFunction(
    () => {
      const s = window.tilesState;
      return s.ready && !s.loading && s.frames > 2 && s.loaded.length + s.failed.length >= s.requested.length
        && s.requested.length > 0;
    },
    null,
    { timeout: 120000, polling: 250 },
  );
  // Twice, half a second apart: a frame after the last load could still
  // ask for more.
  await settled();
  await page.waitForTimeout(500);
  await settled();
  // A frame after the last load, to draw it.
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  return { page, consoleErrors, state: await page.evaluate(() => ({ ...window.tilesState })) };
}

/// Clicks the roof of lot `i` (`roof`: that point in the tileset's frame)
/// and returns what the page picked.
async function clickRoof(page, roof) {
  const at = await page.evaluate((p) => window.tilesState.project(p), roof);
  assert.ok(at.inView, `the roof is in view: ${JSON.stringify(at)}`);
  const canvas = await page.locator('#canvas').boundingBox();
  await page.mouse.click(canvas.x + at.x, canvas.y + at.y);
  await page.waitForFunction(() => window.tilesState.picked !== null, null, { timeout: 10000 });
  return page.evaluate(() => window.tilesState.picked);
}

function checkLoaded(tileset, name, state, consoleErrors) {
  const base = `${http.url}/data/${name}/`;
  const expected = contents(tileset.root).map((u) => new URL(u, base).href).sort();
  assert.deepEqual([...state.contents].sort(), expected, 'the page saw every content of tileset.json');
  assert.deepEqual([...state.requested].sort(), expected, 'every tile was requested');
  assert.deepEqual([...state.loaded].sort(), expected, 'every tile was loaded');
  assert.deepEqual(state.failed, []);
  assert.deepEqual(state.errors, []);
  assert.deepEqual(consoleErrors, []);
  // The server agrees: each tile fetched once with 200, nothing missing.
  const served = http.log.filter((r) => r.path.startsWith(`/data/${name}/`));
  assert.deepEqual(served.filter((r) => r.status !== 200), []);
  for (const url of expected) {
    assert.ok(served.some((r) => `${http.url}${r.path}` === url), `served ${url}`);
  }
  // Everything loaded and refined: the leaves are drawn, and only they
  // (REPLACE), with exactly the triangles their GLBs hold.
  const leafUris = leaves(tileset.root);
  const triangles = leafUris.reduce((s, u) => s + glbTriangles(join(dir, name, u)), 0);
  assert.equal(state.tilesDrawn, leafUris.length);
  assert.equal(state.triangles, triangles);
}

/// The corners of the box around district `d` (its lots, from the ground
/// to 30 m), in the tileset's frame: `toFrame([x, y], h)` places a point of
/// the GeoJSON at a height.
function districtBox(geojson, d, toFrame) {
  const first = DISTRICTS.slice(0, d).reduce((n, k) => n + k.cols * k.rows, 0);
  const count = DISTRICTS[d].cols * DISTRICTS[d].rows;
  const points = geojson.features.slice(first, first + count).flatMap((f) => f.geometry.coordinates[0]);
  const [xs, ys] = [0, 1].map((k) => [Math.min, Math.max].map((m) => m(...points.map((p) => p[k]))));
  const corners = [];
  for (const x of xs) for (const y of ys) for (const h of [0, 30]) corners.push(toFrame([x, y], h));
  return corners;
}

/// The city is drawn: over the screen box of each district, many pixels
/// change when the tiles are hidden (not a blank canvas, nor the ground).
async function checkPixels(page, geojson, toFrame) {
  for (let d = 0; d < DISTRICTS.length; d++) {
    const box = districtBox(geojson, d, toFrame);
    const pixels = await page.evaluate((b) => window.tilesState.cityPixels(b), box);
    assert.ok(pixels.total > 10000, `district ${d}: ${JSON.stringify(pixels)}`);
    assert.ok(pixels.changed / pixels.total > 0.25, `district ${d}: ${JSON.stringify(pixels)}`);
  }
}

async function screenshot(page, file) {
  const folder = process.env.SCREENSHOTS;
  if (!folder) return;
  mkdirSync(folder, { recursive: true });
  await page.screenshot({ path: join(folder, file) });
}

describe('a tileset of lots in longitude/latitude', () => {
  let geojson;
  let tileset;
  let page;
  let loadedState;
  let consoleErrors;

  before(async () => {
    geojson = cityGeojson(geographic);
    tileset = generate(dir, 'geo', geojson);
    ({ page, state: loadedState, consoleErrors } = await view('geo'));
  });
  after(() => page?.close());

  test('every tile loads, without an error', () => {
    // The root's and the centre's massing, the centre's 4 leaves and the
    // suburb's leaf.
    assert.equal(contents(tileset.root).length, 7, JSON.stringify(contents(tileset.root)));
    assert.ok(tileset.root.transform, 'a root transform to ECEF');
    assert.equal(loadedState.georeferenced, true);
    checkLoaded(tileset, 'geo', loadedState, consoleErrors);
  });

  const onGlobe = ([lon, lat], h) => ecef(lon, lat, h);

  test('the city is drawn', () => checkPixels(page, geojson, onGlobe));

  test('clicking a building shows its lot', async () => {
    // A lot in the suburb: a leaf one level below the root.
    const [lon2, lat2] = lotCentre(geojson, SUBURB);
    const other = await clickRoof(page, ecef(lon2, lat2, heightOf(SUBURB)));
    assert.equal(other.index, SUBURB, JSON.stringify(other));
    assert.equal(other.name, `B${SUBURB}`);
    assert.equal(other.attributes.floors, String(floorsOf(SUBURB)));
    assert.equal(other.attributes.owner, `owner ${SUBURB}`);
    assert.match(other.tile, /\/tiles\/1_\d+_\d+\.glb$/);

    // The tower in the centre (a leaf two levels down), seen closer.
    await page.evaluate((b) => window.tilesState.fit(b), districtBox(geojson, 0, onGlobe));
    const [lon, lat] = lotCentre(geojson, TOWER);
    const roof = ecef(lon, lat, heightOf(TOWER));
    const colour = () => page.evaluate((p) => {
      const at = window.tilesState.project(p);
      return window.tilesState.pixelAt(at.x, at.y);
    }, roof);
    const grey = await colour();
    const picked = await clickRoof(page, roof);
    // The picked lot is highlighted in orange: its grey roof turns warm.
    const warm = await colour();
    assert.ok(Math.abs(grey[0] - grey[2]) < 30, `roof before: ${grey}`);
    assert.ok(warm[0] - warm[2] > 60, `roof after: ${warm}`);
    assert.equal(picked.index, TOWER, JSON.stringify(picked));
    assert.equal(picked.name, 'B077');
    assert.equal(picked.attributes.floors, '18');
    assert.equal(picked.attributes.owner, 'owner 77');
    assert.equal(picked.attributes.wallColor, COLOURS[TOWER % COLOURS.length]);
    // 20 m x 24 m, laid out in degrees with a spherical approximation.
    assert.ok(Math.abs(picked.reports.footprint - LOT[0] * LOT[1]) < 2, JSON.stringify(picked.reports));
    assert.match(picked.tile, /\/tiles\/2_\d+_\d+\.glb$/);
    // The hit is on that roof, where the globe has it.
    const miss = Math.hypot(...picked.point.map((v, k) => v - roof[k]));
    assert.ok(miss < 1.5, `hit ${miss.toFixed(2)} m from the roof's centre`);
    const panel = await page.locator('#picked').innerText();
    assert.match(panel, /lot\s+77 · B077/);
    assert.match(panel, /owner\s+owner 77/);
    assert.match(panel, /footprint\s+4\d\d/);
    // Nothing failed on the way (the closer view needed no tile it had not).
    assert.deepEqual(await page.evaluate(() => window.tilesState.errors), []);
    await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
    await screenshot(page, 'tileset.png');
  });
});

describe('a tileset of lots in local metres, a few lots a content', () => {
  let geojson;
  let tileset;
  let page;
  let loadedState;
  let consoleErrors;

  before(async () => {
    geojson = cityGeojson(local);
    // Few triangles a content: each leaf's lots fill several contents
    // under a tile without content of its own.
    tileset = generate(dir, 'local', geojson, ['--crs', 'local', '--tile-triangles', '40000']);
    ({ page, state: loadedState, consoleErrors } = await view('local'));
  });
  after(() => page?.close());

  test('every tile loads, without an error', () => {
    const split = [];
    const walk = (t) => {
      if (!t.content && t.children?.length && t.children.every((c) => c.content && !c.children?.length)) split.push(t);
      (t.children || []).forEach(walk);
    };
    walk(tileset.root);
    assert.ok(split.length >= 2, `leaves split into several contents: ${split.length}`);
    assert.ok(contents(tileset.root).length > 7, JSON.stringify(contents(tileset.root)));
    assert.equal(loadedState.georeferenced, false);
    checkLoaded(tileset, 'local', loadedState, consoleErrors);
  });

  const flat = ([x, y], h) => [x, y, h];

  test('the city is drawn', () => checkPixels(page, geojson, flat));

  test('clicking a building shows its lot', async () => {
    const [x, y] = lotCentre(geojson, TOWER);
    // The tileset's frame: x east, y north, z up, in the file's metres.
    const roof = [x, y, heightOf(TOWER)];
    const picked = await clickRoof(page, roof);
    assert.equal(picked.index, TOWER, JSON.stringify(picked));
    assert.equal(picked.attributes.owner, 'owner 77');
    assert.ok(Math.abs(picked.reports.footprint - LOT[0] * LOT[1]) < 1e-6, JSON.stringify(picked.reports));
    const miss = Math.hypot(...picked.point.map((v, k) => v - roof[k]));
    assert.ok(miss < 1.5, `hit ${miss.toFixed(2)} m from the roof's centre`);
  });
});

describe('a coarse view draws the massing', () => {
  test('with a large error target only the root loads, and shows every building as its massing', async () => {
    const tileset = generate(dir, 'coarse', cityGeojson(local), ['--crs', 'local']);
    const { page, state, consoleErrors } = await view(
      'coarse',
      `${http.url}/viewer/tiles.html?tileset=/data/coarse/tileset.json&errorTarget=100000`,
    );
    try {
      const root = new URL(tileset.root.content.uri, `${http.url}/data/coarse/`).href;
      assert.deepEqual(state.requested, [root]);
      assert.deepEqual(state.loaded, [root]);
      assert.deepEqual(consoleErrors, []);
      assert.equal(state.tilesDrawn, 1);
      // A box per building: 12 triangles (four walls, top and bottom).
      const triangles = glbTriangles(join(dir, 'coarse', tileset.root.content.uri));
      assert.equal(triangles, 150 * 12);
      assert.equal(state.triangles, triangles);
      // Picking works on the massing too: the same lot, from the root's
      // table (which has the lots' index and name only, not yet their
      // attributes and reports: docs/tiles.md).
      const [x, y] = lotCentre(cityGeojson(local), TOWER);
      const picked = await clickRoof(page, [x, y, heightOf(TOWER)]);
      assert.equal(picked.index, TOWER, JSON.stringify(picked));
      assert.equal(picked.name, 'B077');
      assert.equal(picked.tile, root);
    } finally {
      await page.close();
    }
  });
});

describe('a street of instanced assets', () => {
  test('its tiles load and each tree or lamp picked is of the lot it stands on', async () => {
    // tools/perf/street/street.cga: trees and lamps inserted with i() and
    // written once a tile (EXT_mesh_gpu_instancing), each placement with
    // its lot's feature id (EXT_instance_features).
    const boxes = [];
    for (let i = 0; i < 6; i++) {
      const [x0, y0] = [LOCAL_ORIGIN[0] + (i % 3) * 50, LOCAL_ORIGIN[1] + Math.floor(i / 3) * 50];
      boxes.push([x0, y0, x0 + 40, y0 + 40]);
    }
    const geojson = {
      type: 'FeatureCollection',
      features: boxes.map(([x0, y0, x1, y1], i) => ({
        type: 'Feature',
        id: `S${i}`,
        properties: { owner: `owner ${i}` },
        geometry: { type: 'Polygon', coordinates: [[[x0, y0], [x1, y0], [x1, y1], [x0, y1], [x0, y0]]] },
      })),
    };
    const lots = join(dir, 'street.geojson');
    writeFileSync(lots, JSON.stringify(geojson));
    const out = join(dir, 'street', 'tileset.json');
    const run = spawnSync(
      cgaBinary(),
      ['generate', join(repo, 'tools', 'perf', 'street', 'street.cga'), '--lot', lots, '--crs', 'local', '-o', out],
      { encoding: 'utf8' },
    );
    assert.equal(run.status, 0, `cga generate failed:\n${run.stdout}\n${run.stderr}`);
    const tileset = JSON.parse(readFileSync(out, 'utf8'));
    const { page, state, consoleErrors } = await view('street');
    try {
      checkLoaded(tileset, 'street', state, consoleErrors);
      // Pick over a grid of points of the canvas: every hit on an asset
      // names the lot it stands on. A tree is turned about its 4 m cell's
      // corner before it is centred, so a crown (up to 1.75 m wide of its
      // centre) reaches under 4.8 m beyond the lot; the lots are 10 m
      // apart, so the nearest lot is unambiguous.
      const picks = await page.evaluate(() => {
        const s = window.tilesState;
        const c = document.getElementById('canvas').getBoundingClientRect();
        const out = [];
        for (let y = 0.2; y <= 0.8; y += 0.04) for (let x = 0.2; x <= 0.8; x += 0.04) {
          const p = s.pickAt(c.width * x, c.height * y);
          if (p) out.push(p);
        }
        return out;
      });
      const instanced = picks.filter((p) => p.instanced);
      assert.ok(instanced.length >= 20, `${instanced.length} assets hit of ${picks.length}`);
      const away = ([x0, y0, x1, y1], [x, y]) => Math.hypot(Math.max(x0 - x, 0, x - x1), Math.max(y0 - y, 0, y - y1));
      for (const p of instanced) {
        const distances = boxes.map((b) => away(b, p.point));
        assert.ok(distances[p.index] < 4.8, `lot ${p.index} hit at ${p.point}`);
        assert.equal(distances.indexOf(Math.min(...distances)), p.index, `lot ${p.index} hit at ${p.point}`);
        assert.equal(p.name, `S${p.index}`);
        assert.equal(p.attributes.owner, `owner ${p.index}`);
      }
      assert.ok(new Set(instanced.map((p) => p.index)).size >= 4, 'assets of several lots');
    } finally {
      await page.close();
    }
  });
});

describe('a missing tile is reported', () => {
  test('the page lists it as failed, with an error, and says so', async () => {
    const tileset = generate(dir, 'broken', cityGeojson(local), ['--crs', 'local']);
    const gone = leaves(tileset.root)[0];
    unlinkSync(join(dir, 'broken', gone));
    const { page, state, consoleErrors } = await view('broken');
    try {
      const url = new URL(gone, `${http.url}/data/broken/`).href;
      assert.deepEqual(state.failed, [url]);
      assert.equal(state.loaded.length, contents(tileset.root).length - 1);
      assert.equal(state.errors.length, 1);
      assert.match(state.errors[0], /404/);
      assert.ok(consoleErrors.length > 0);
      assert.equal(await page.locator('#status').innerText(), '1 failed');
      assert.ok(await page.locator('#message').isVisible());
    } finally {
      await page.close();
    }
  });
});

describe('cga serve shows a tileset beside its rules', () => {
  let serve;
  let page;

  before(async () => {
    // `cga serve RULES` serves the viewer page and the files of the rules'
    // folder (`files/...`): a tileset written there can be opened at once.
    generate(dir, 'served', cityGeojson(geographic));
    serve = await startServer([writeRules(dir)]);
  });
  after(async () => {
    await page?.close();
    serve?.child.kill();
  });

  test('every tile loads from cga serve, without an error', async () => {
    const tileset = JSON.parse(readFileSync(join(dir, 'served', 'tileset.json'), 'utf8'));
    let state;
    let consoleErrors;
    ({ page, state, consoleErrors } = await view('served', `${serve.url}tiles.html?tileset=files/served/tileset.json&errorTarget=0`));
    const expected = contents(tileset.root).map((u) => new URL(u, `${serve.url}files/served/`).href).sort();
    assert.deepEqual([...state.loaded].sort(), expected);
    assert.deepEqual(state.failed, []);
    assert.deepEqual(state.errors, []);
    assert.deepEqual(consoleErrors, []);
    await checkPixels(page, cityGeojson(geographic), ([lon, lat], h) => ecef(lon, lat, h));
  });
});
