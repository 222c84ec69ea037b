// Starting `cga serve` and Debian's Chromium for the browser tests.
//
// CGA_BIN: the `cga` binary (default: ../target/debug/cga, as
// `cargo build -p cga-cli` leaves it). CHROMIUM: the browser (default
// /usr/bin/chromium; Playwright's own browser download is not used).

import { spawn } from 'node:child_process';
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve, dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const here = dirname(fileURLToPath(import.meta.url));
export const repo = resolve(here, '..', '..');

export function cgaBinary() {
  return process.env.CGA_BIN || join(repo, 'target', 'debug', 'cga');
}

/// Starts `cga serve ARGS --port 0` and resolves with its URL and process.
export function startServer(args) {
  return new Promise((resolveStart, reject) => {
    const child = spawn(cgaBinary(), ['serve', ...args, '--port', '0'], {
      env: { ...process.env, CGA_WEB_DIR: process.env.CGA_WEB_DIR || join(repo, 'web', 'dist') },
      stdio: ['ignore', 'pipe', 'pipe'],
    });
    let out = '';
    let err = '';
    const timer = setTimeout(() => reject(new Error(`cga serve did not start:\n${out}\n${err}`)), 60000);
    child.stdout.on('data', (d) => {
      out += d;
      const m = out.match(/preview at (http:\/\/\S+)/);
      if (m) {
        clearTimeout(timer);
        resolveStart({ url: m[1], child, stderr: () => err });
      }
    });
    child.stderr.on('data', (d) => { err += d; });
    child.on('exit', (code) => {
      clearTimeout(timer);
      reject(new Error(`cga serve exited with ${code}:\n${out}\n${err}`));
    });
  });
}

/// How Chromium is started here: without the sandbox and the background
/// connections this machine's closed network refuses, WebGL in software.
export const chromiumArgs = [
  '--no-sandbox',
  '--disable-gpu',
  '--disable-quic',
  '--no-first-run',
  '--disable-background-networking',
  '--disable-component-update',
  '--disable-sync',
  // WebGL without a GPU: Chromium's software renderer.
  '--enable-unsafe-swiftshader',
  '--use-angle=swiftshader',
];

/// Debian's Chromium, headless, with a fresh profile and without the
/// background connections this machine's closed network refuses.
export async function launchBrowser() {
  const profile = mkdtempSync(join(tmpdir(), 'cga-preview-profile-'));
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    headless: true,
    viewport: { width: 1280, height: 800 },
    args: chromiumArgs,
  });
  return {
    context,
    async close() {
      await context.close();
      rmSync(profile, { recursive: true, force: true });
    },
  };
}

/// `cga serve ARGS` and a page of it in Debian's Chromium, once the page
/// has drawn its first model. On failure nothing is left running.
export async function openPreview(args) {
  const server = await startServer(args);
  let browser;
  try {
    browser = await launchBrowser();
    const page = await browser.context.newPage();
    page.on('pageerror', (e) => console.error('page error:', e));
    await page.goto(server.url);
    await page.waitForFunction(() => window.cgaPreview.modelVersion > 0, null, { timeout: 30000 });
    return { server, browser, page };
  } catch (e) {
    await browser?.close();
    server.child.kill();
    throw e;
  }
}
