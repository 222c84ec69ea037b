// Edit-to-picture latency of `cga serve` (docs/performance.md): the time
// from saving the rule file, or moving a slider, to the new model drawn
// in the browser (Debian's Chromium, software WebGL), over 20 edits.
//
//   CGA_BIN=target/release/cga node bench/latency.mjs [LOT SPEC]...
//
// Runs on a copy of Candler (../shared/prt-oracle/rules/candler) with
// the lots given (default: its footprint); each edit changes the default
// of BuildingHeight (file: 62 to 76 m) or moves the BuildingHeight slider
// (43 to 100 m: later slider edits make larger models). DEBUG=1 prints
// each edit's timeline. The browser is driven without Playwright (see
// plain.mjs); PLAYWRIGHT=1 drives it with Playwright.

import { cpSync, mkdtempSync, readFileSync, writeFileSync, rmSync, existsSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { repo, startServer, launchBrowser } from '../tests/harness.mjs';
import { launchPlain } from './plain.mjs';

const oracle = resolve(repo, '..', 'shared', 'prt-oracle');
if (!existsSync(join(oracle, 'rules', 'candler'))) {
  console.log('skipped: ../shared/prt-oracle (Candler) is absent');
  process.exit(0);
}
const lots = process.argv.slice(2);
const specs = (lots.length ? lots : ['lots/candler_footprint.obj'])
  .map((l) => l.replace(/(^|:)lots\//, `$1${join(oracle, 'lots')}/`));
const edits = Number(process.env.EDITS || 20);

const dir = mkdtempSync(join(tmpdir(), 'cga-latency-'));
cpSync(join(oracle, 'rules', 'candler'), join(dir, 'candler'), { recursive: true });
const rules = join(dir, 'candler', 'rules', 'candler.cga');
const original = readFileSync(rules, 'utf8');
const server = await startServer([rules, ...specs.flatMap((s) => ['--lot', s])]);
// PLAYWRIGHT=1: under Playwright, as the tests drive the page.
const browser = process.env.PLAYWRIGHT ? await launchBrowser() : await launchPlain();
const median = (xs) => { const s = [...xs].sort((a, b) => a - b); return s[Math.floor(s.length / 2)]; };
const p90 = (xs) => { const s = [...xs].sort((a, b) => a - b); return s[Math.min(s.length - 1, Math.floor(s.length * 0.9))]; };

try {
  const page = await browser.context.newPage();
  page.on('pageerror', (e) => console.error('page error:', e));
  page.on('console', (m) => console.error('console:', m.text()));
  await page.goto(server.url);
  await page.waitForFunction(() => window.cgaPreview.modelVersion > 0, null, { timeout: 120000 });
  const version = () => page.evaluate(() => window.cgaPreview.modelVersion);
  const stats = () => page.evaluate(() => window.cgaPreview.stats);
  const first = await stats();

  // Saving the file: from the write to the frame shown.
  const fileTimes = [];
  const generateTimes = [];
  const encodeTimes = [];
  const drawTimes = [];
  for (let i = 1; i <= edits; i++) {
    const v = await version();
    const text = original.replace(/attr BuildingHeight\s*=\s*62/, `attr BuildingHeight = ${62 + (i % 2 ? 4 : 0) + i * 0.5}`);
    const t0 = Date.now();
    writeFileSync(rules, text);
    await page.waitForFunction((old) => window.cgaPreview.modelVersion > old, v, { timeout: 60000 });
    const drawn = await page.evaluate(() => performance.timeOrigin + window.cgaPreview.drawnAt);
    fileTimes.push(drawn - t0);
    generateTimes.push((await stats()).generate_ms);
    encodeTimes.push((await stats()).encode_ms);
    drawTimes.push(await page.evaluate(() => window.cgaPreview.drawMs));
    if (process.env.DEBUG) {
      console.error('file timeline', await page.evaluate((t) => {
        const p = window.cgaPreview.drawParts;
        const s = window.cgaPreview.stats;
        const at = (x) => performance.timeOrigin + x - t;
        return JSON.stringify({ state: at(p.state), load: at(p.loadStart), drawn: at(window.cgaPreview.drawnAt), load_ms: s.load_ms, generate: s.generate_ms, encode: s.encode_ms, fetch: p.fetch, build: p.build, render: p.render });
      }, t0));
    }
    await page.waitForTimeout(150);
  }

  // Moving the slider: from the input event to the frame shown.
  const sliderTimes = [];
  for (let i = 1; i <= edits; i++) {
    const v = await version();
    const t0 = await page.evaluate((value) => {
      const slider = document.querySelector('label[data-attr=BuildingHeight] input[type=range]');
      slider.value = String(value);
      const t = performance.now();
      slider.dispatchEvent(new Event('input', { bubbles: true }));
      return t;
    }, 40 + i * 3);
    if (process.env.DEBUG) console.error('slider', i, await page.evaluate(() => JSON.stringify([window.cgaPreview.modelVersion, window.cgaPreview.stateVersion, window.cgaPreview.values])));
    try {
      await page.waitForFunction((old) => window.cgaPreview.modelVersion > old, v, { timeout: 20000 });
    } catch (e) {
      console.error('stuck at slider', i, 'model version', v, await page.evaluate(async () => JSON.stringify({
        page: [window.cgaPreview.modelVersion, window.cgaPreview.stateVersion, window.cgaPreview.values],
        server: await (await fetch('api/state')).json().then((s) => [s.version, s.model_version, s.values]),
      })));
      throw e;
    }
    sliderTimes.push(await page.evaluate((t) => window.cgaPreview.drawnAt - t, t0));
    if (process.env.DEBUG) {
      console.error('timeline', await page.evaluate((t) => {
        const p = window.cgaPreview.drawParts;
        const s = window.cgaPreview.stats;
        return JSON.stringify({ sent: p.sent - t, state: p.state - t, load: p.loadStart - t, drawn: window.cgaPreview.drawnAt - t, generate: s.generate_ms, encode: s.encode_ms, fetch: p.fetch, build: p.build, render: p.render, frame: p.frame });
      }, t0));
    }
    await page.waitForTimeout(150);
  }
  const f = (x) => `${x.toFixed(0)} ms`;
  console.log(JSON.stringify({
    lots: first.lots, triangles: first.triangles, edits,
    file: { median: f(median(fileTimes)), p90: f(p90(fileTimes)) },
    slider: { median: f(median(sliderTimes)), p90: f(p90(sliderTimes)) },
    generate: { median: f(median(generateTimes)) },
    // Making the bytes the page fetches (server).
    encode: { median: f(median(encodeTimes)) },
    // Fetching the model, building the meshes, drawing, the frame shown
    // (DEBUG=1 prints each part).
    draw: { median: f(median(drawTimes)) },
  }, null, 1));
} finally {
  await browser.close();
  server.child.kill();
  rmSync(dir, { recursive: true, force: true });
}
