// Textured models in a real browser: texture coordinates come to the
// page as 16-bit steps across their box (crates/cga-serve/src/encode.rs)
// and the page must put them back where the rules placed them.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, writeFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { deflateSync } from 'node:zlib';
import { openPreview } from './harness.mjs';

/// CRC-32 of PNG chunks.
function crc32(bytes) {
  let c = ~0;
  for (const b of bytes) {
    c ^= b;
    for (let k = 0; k < 8; k++) c = (c >>> 1) ^ (0xedb88320 & -(c & 1));
  }
  return ~c >>> 0;
}

/// A PNG of `width` x `height` RGB pixels, `colour(x, y)` each.
function png(width, height, colour) {
  const chunk = (type, data) => {
    const body = Buffer.concat([Buffer.from(type, 'ascii'), data]);
    const out = Buffer.alloc(12 + data.length);
    out.writeUInt32BE(data.length, 0);
    body.copy(out, 4);
    out.writeUInt32BE(crc32(body), 8 + data.length);
    return out;
  };
  const header = Buffer.alloc(13);
  header.writeUInt32BE(width, 0);
  header.writeUInt32BE(height, 4);
  header[8] = 8; // bits per channel
  header[9] = 2; // RGB
  const rows = Buffer.alloc(height * (1 + 3 * width));
  for (let y = 0; y < height; y++) {
    for (let x = 0; x < width; x++) {
      const at = y * (1 + 3 * width) + 1 + 3 * x;
      colour(x, y).forEach((v, i) => { rows[at + i] = v; });
    }
  }
  return Buffer.concat([
    Buffer.from([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]),
    chunk('IHDR', header),
    chunk('IDAT', deflateSync(rows)),
    chunk('IEND', Buffer.alloc(0)),
  ]);
}

let dir;
let server;
let browser;
let page;

before(async () => {
  dir = mkdtempSync(join(tmpdir(), 'cga-textures-'));
  // Left half red, right half blue.
  writeFileSync(join(dir, 'halves.png'), png(64, 64, (x) => (x < 32 ? [255, 0, 0] : [0, 0, 255])));
  // The lot's texture coordinates span u from 0.55 to 0.95: only the
  // blue half shows. Coordinates drawn as sent, without their box
  // (0 to 1), would show both halves.
  writeFileSync(join(dir, 'lot.cga'), [
    'Lot --> setupProjection(0, scope.xz, scope.sx, scope.sz)',
    '        projectUV(0) scaleUV(0, 0.4, 1) translateUV(0, 0.55, 0)',
    '        color("#ffffff") texture("halves.png") Top.',
    '',
  ].join('\n'));
  ({ server, browser, page } = await openPreview([join(dir, 'lot.cga'), '--lot', 'rect:30,30']));
});

after(async () => {
  await browser?.close();
  server?.child.kill();
  if (dir) rmSync(dir, { recursive: true, force: true });
});

/// Pixels of the canvas that are clearly red and clearly blue.
const hues = () => page.evaluate(() => {
  const canvas = document.querySelector('canvas');
  const c = document.createElement('canvas');
  c.width = canvas.width;
  c.height = canvas.height;
  const g = c.getContext('2d');
  g.drawImage(canvas, 0, 0);
  const d = g.getImageData(0, 0, c.width, c.height).data;
  let red = 0;
  let blue = 0;
  for (let i = 0; i < d.length; i += 4) {
    if (d[i] > 60 && d[i] > 3 * d[i + 1] && d[i] > 3 * d[i + 2]) red++;
    if (d[i + 2] > 60 && d[i + 2] > 3 * d[i] && d[i + 2] > 3 * d[i + 1]) blue++;
  }
  return { red, blue };
});

test('texture coordinates sent as steps land where the rules put them', async () => {
  // The texture's image arrives after the model: wait for its colour.
  let seen = { red: 0, blue: 0 };
  for (let i = 0; i < 50 && seen.blue < 5000; i++) {
    await page.waitForTimeout(200);
    seen = await hues();
  }
  assert.ok(seen.blue >= 5000, `blue pixels: ${JSON.stringify(seen)}`);
  assert.ok(seen.red < seen.blue / 100, `red pixels: ${JSON.stringify(seen)}`);
});
