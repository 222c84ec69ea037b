// The preview in a real browser: Debian's Chromium driven by Playwright
// against `cga serve` on a copy of examples/building.cga.
//
// SCREENSHOTS: a folder to save screenshots into (the README's come from
// `SCREENSHOTS=../docs/images npm test`).

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, readFileSync, writeFileSync, rmSync, mkdirSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { repo, openPreview, cgaBinary } from './harness.mjs';
import { spawnSync } from 'node:child_process';

const original = readFileSync(join(repo, 'examples', 'building.cga'), 'utf8');
let dir;
let rules;
let server;
let browser;
let page;

async function screenshot(name) {
  const folder = process.env.SCREENSHOTS;
  if (!folder) return;
  mkdirSync(folder, { recursive: true });
  // The shadows follow a new model after 400 ms (main.js).
  await page.waitForTimeout(600);
  await page.screenshot({ path: join(folder, name) });
}

const preview = () => page.evaluate(() => ({
  modelVersion: window.cgaPreview.modelVersion,
  stateVersion: window.cgaPreview.stateVersion,
  bounds: window.cgaPreview.bounds,
  stale: window.cgaPreview.stale,
  problems: window.cgaPreview.problems,
}));
const height = async () => (await preview()).bounds.max[1];
const modelPixels = () => page.evaluate(() => window.cgaPreview.modelPixels());

before(async () => {
  dir = mkdtempSync(join(tmpdir(), 'cga-preview-'));
  rules = join(dir, 'building.cga');
  writeFileSync(rules, original);
  ({ server, browser, page } = await openPreview([rules]));
});

after(async () => {
  await browser?.close();
  server?.child.kill();
  if (dir) rmSync(dir, { recursive: true, force: true });
});

test('the page shows the model', async () => {
  const p = await preview();
  // examples/building.cga on rect:20,30: 4.5 m ground floor, 6 floors of 3.2 m.
  assert.ok(Math.abs(p.bounds.max[1] - (4.5 + 6 * 3.2)) < 0.5, `height ${p.bounds.max[1]}`);
  assert.ok(Math.abs(p.bounds.min[0]) < 0.6 && Math.abs(p.bounds.max[0] - 20) < 0.6, JSON.stringify(p.bounds));
  const pixels = await modelPixels();
  // The building covers much of its screen box (not a blank canvas).
  assert.ok(pixels.total > 1000, JSON.stringify(pixels));
  assert.ok(pixels.changed / pixels.total > 0.3, JSON.stringify(pixels));
  // Attribute panel: a slider for each @Range attribute, text for strings.
  assert.equal(await page.locator('label[data-attr=floors] input[type=range]').count(), 1);
  assert.equal(await page.locator('label[data-attr=floorHeight] input[type=range]').count(), 1);
  assert.equal(await page.locator('label[data-attr=wallColor] input[type=text]').count(), 1);
  assert.match(await page.locator('#stats').innerText(), /shapes\s+4,225/);
});

test('the page draws the triangles the command generates', async () => {
  // The same rule and lot through `cga generate`, as OBJ: its faces'
  // area against the area of the triangles the page made from the bytes
  // it fetched (faces sent as fans, see encode.rs).
  const obj = join(dir, 'building.obj');
  const run = spawnSync(cgaBinary(), ['generate', rules, '-o', obj], { encoding: 'utf8' });
  assert.equal(run.status, 0, run.stderr);
  const v = [];
  let area = 0;
  let triangles = 0;
  for (const line of readFileSync(obj, 'utf8').split('\n')) {
    const w = line.trim().split(/\s+/);
    if (w[0] === 'v') v.push(w.slice(1, 4).map(Number));
    if (w[0] !== 'f') continue;
    const p = w.slice(1).map((c) => v[Number(c.split('/')[0]) - 1]);
    // The vector area of a planar polygon, concave or not.
    const s = [0, 0, 0];
    for (let i = 0; i < p.length; i++) {
      const [a, b] = [p[i], p[(i + 1) % p.length]];
      s[0] += a[1] * b[2] - a[2] * b[1];
      s[1] += a[2] * b[0] - a[0] * b[2];
      s[2] += a[0] * b[1] - a[1] * b[0];
    }
    area += Math.hypot(...s) / 2;
    triangles += p.length - 2;
  }
  const drawn = await page.evaluate(() => window.cgaPreview.modelTriangles());
  assert.equal(drawn.triangles, triangles);
  // Positions are 16-bit steps across each mesh's box: sub-millimetre.
  assert.ok(Math.abs(drawn.area - area) < 1e-4 * area, `${drawn.area} against ${area}`);
});

test('clicking the building names the rule and source line', async () => {
  const pixels = await modelPixels();
  const [x0, y0, x1, y1] = pixels.box;
  const canvas = await page.locator('#canvas').boundingBox();
  const ratio = await page.evaluate(() => Math.min(window.devicePixelRatio, 2));
  await page.mouse.click(canvas.x + (x0 + x1) / 2 / ratio, canvas.y + (y0 + y1) / 2 / ratio);
  await page.waitForFunction(() => window.cgaPreview.picked !== null, null, { timeout: 10000 });
  const picked = await page.evaluate(() => window.cgaPreview.picked);
  assert.equal(picked.file, 'building.cga');
  assert.ok(picked.line > 0 && picked.line_text.startsWith(picked.rule.split('.').pop()), JSON.stringify(picked));
  assert.match(await page.locator('#picked').innerText(), new RegExp(`building\\.cga:${picked.line}:1`));
});

test('moving a @Range slider changes the model', async () => {
  const before = await preview();
  await page.evaluate(() => {
    const slider = document.querySelector('label[data-attr=floors] input[type=range]');
    slider.value = '12';
    slider.dispatchEvent(new Event('input', { bubbles: true }));
  });
  await page.waitForFunction((v) => window.cgaPreview.modelVersion > v, before.modelVersion, { timeout: 30000 });
  const h = await height();
  assert.ok(Math.abs(h - (before.bounds.max[1] + 6 * 3.2)) < 0.01, `height ${before.bounds.max[1]} -> ${h}`);
  assert.equal(await page.locator('label[data-attr=floors] output').innerText(), '12');
  // Its lots came as they were made (api/live.bin), not fetched after.
  assert.equal(await page.evaluate(() => window.cgaPreview.drawnFrom), 'live');
  await screenshot('preview.png');
});

test('a syntax error is shown with file:line:col and the last model stays', async () => {
  const before = await preview();
  writeFileSync(rules, original.replace('\textrude(height)\n', '\textrude(height\n'));
  await page.waitForFunction(
    () => window.cgaPreview.problems.some((p) => p.severity === 'error'),
    null,
    { timeout: 30000 },
  );
  const problems = page.locator('#problems .problem.error');
  assert.equal(await problems.count(), 1);
  const text = await problems.first().innerText();
  assert.match(text, /building\.cga:25:2/);
  assert.match(text, /expected `\)`/);
  assert.match(text, /Mass/); // the source line
  const after = await preview();
  assert.equal(after.modelVersion, before.modelVersion);
  assert.equal(after.stale, true);
  assert.ok(await page.locator('#stale').isVisible());
  // The attribute panel keeps the last good file's controls.
  assert.equal(await page.locator('label[data-attr=floors] input[type=range]').count(), 1);
  assert.equal(await height(), before.bounds.max[1]);
  const pixels = await modelPixels();
  assert.ok(pixels.changed / pixels.total > 0.3, JSON.stringify(pixels));
  await screenshot('preview-problems.png');
});

test('fixing the error brings the new model', async () => {
  const before = await preview();
  // Fixed, and with a taller ground floor (4.5 m -> 8 m).
  writeFileSync(rules, original.replace('attr groundFloorHeight = 4.5', 'attr groundFloorHeight = 8'));
  await page.waitForFunction((v) => window.cgaPreview.modelVersion > v, before.modelVersion, { timeout: 30000 });
  const after = await preview();
  assert.equal(after.stale, false);
  assert.equal(after.problems.filter((p) => p.severity === 'error').length, 0);
  assert.equal(await page.locator('#problems .problem.error').count(), 0);
  assert.ok(await page.locator('#stale').isHidden());
  // The slider's 12 floors are kept: 8 + 12 x 3.2.
  assert.ok(Math.abs(after.bounds.max[1] - (8 + 12 * 3.2)) < 0.5, `height ${after.bounds.max[1]}`);
  assert.equal(await page.evaluate(() => window.cgaPreview.drawnFrom), 'live');
});
