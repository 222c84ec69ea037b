// The attribute panel built from annotations, on two lots, in Chromium.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, writeFileSync, rmSync, mkdirSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { openPreview } from './harness.mjs';

const RULES = `
@Group("Roof", 2) @Order(1) @Enum("flat", "tall")
attr roof = "flat"
@Group("Massing", 1) @Order(2) @Range(min=2, max=30) @Description("Height of the walls in metres")
attr height = 10
@Group("Massing", 1) @Order(1) @Color
attr wall = "#aa3300"
@File("obj")
attr asset = "assets/a.obj"
@Hidden
attr internal = 3
attr lit = true
attr label = "x"

@StartRule
Lot --> extrude(height) print("lot " + label) report("height", height) Mass
Mass --> comp(f) { top : Top | side : color(wall) Wall. }
Top --> case roof == "tall" : extrude(5) Roof. else : Roof.
`;

let dir;
let server;
let browser;
let page;

before(async () => {
  dir = mkdtempSync(join(tmpdir(), 'cga-preview-controls-'));
  mkdirSync(join(dir, 'assets'));
  writeFileSync(join(dir, 'assets', 'a.obj'), 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n');
  writeFileSync(join(dir, 'assets', 'b.obj'), 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n');
  writeFileSync(join(dir, 'rules.cga'), RULES);
  ({ server, browser, page } = await openPreview([join(dir, 'rules.cga'), '--lot', 'rect:10,10', '--lot', 'rect:20,10']));
});

after(async () => {
  await browser?.close();
  server?.child.kill();
  if (dir) rmSync(dir, { recursive: true, force: true });
});

test('each annotation gives its control, grouped and ordered', async () => {
  const labels = await page.locator('#attributes > *').evaluateAll((nodes) =>
    nodes.map((n) => (n.tagName === 'H3' ? `# ${n.textContent}` : n.dataset.attr)));
  // Ungrouped first (file order), then groups by their order, each by @Order.
  assert.deepEqual(labels, ['asset', 'lit', 'label', '# Massing', 'wall', 'height', '# Roof', 'roof']);
  const options = await page.locator('label[data-attr=roof] select option').allInnerTexts();
  assert.deepEqual(options, ['flat', 'tall']);
  assert.equal(await page.locator('label[data-attr=wall] input[type=color]').inputValue(), '#aa3300');
  assert.equal(await page.locator('label[data-attr=lit] input[type=checkbox]').isChecked(), true);
  assert.equal(await page.locator('label[data-attr=label] input[type=text]').inputValue(), 'x');
  const files = await page.locator('label[data-attr=asset] select option').allInnerTexts();
  assert.deepEqual(files, ['assets/a.obj', 'assets/b.obj']);
  assert.equal(await page.locator('label[data-attr=internal]').count(), 0);
  assert.equal(await page.locator('label[data-attr=height]').getAttribute('title'), 'Height of the walls in metres');
});

test('two lots: prints and reports per lot', async () => {
  const state = await page.evaluate(() => window.cgaPreview.stats);
  assert.equal(state.lots, 2);
  assert.equal(await page.locator('#prints').innerText(), '[rect 10x10] lot x\n[rect 20x10] lot x');
  assert.equal(await page.locator('#reports tr').count(), 2);
  const bounds = await page.evaluate(() => window.cgaPreview.bounds);
  assert.equal(bounds.max[1], 10);
});

test('a drop-down and a text field regenerate', async () => {
  let v = await page.evaluate(() => window.cgaPreview.modelVersion);
  await page.locator('label[data-attr=roof] select').selectOption({ label: 'tall' });
  await page.waitForFunction((old) => window.cgaPreview.modelVersion > old, v, { timeout: 30000 });
  assert.equal((await page.evaluate(() => window.cgaPreview.bounds)).max[1], 15);
  v = await page.evaluate(() => window.cgaPreview.modelVersion);
  await page.locator('label[data-attr=label] input').fill('y');
  await page.locator('label[data-attr=label] input').press('Enter');
  await page.waitForFunction((old) => window.cgaPreview.modelVersion > old, v, { timeout: 30000 });
  assert.equal(await page.locator('#prints').innerText(), '[rect 10x10] lot y\n[rect 20x10] lot y');
});
