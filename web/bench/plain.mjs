// Debian's Chromium driven for the benchmarks without Playwright: over the
// DevTools protocol on a pipe (`--remote-debugging-pipe`), with nothing but
// the page's target and `Runtime.evaluate`. Playwright turns on the
// protocol's network domain (for its request events), which makes
// Chromium's fetches slower: the 10-lot street's 21.5 MB took about 56 ms
// median under Playwright against 32 ms in the same browser driven
// without it (docs/performance.md). The benchmarks measure what a user's
// browser does; the tests keep Playwright.
//
// `launchPlain()` resolves with `{ context: { newPage() }, close() }`, a
// page having the few methods the benchmarks use, as Playwright's do:
// `goto`, `evaluate(fn, arg)`, `waitForFunction(fn, arg, { timeout })`,
// `waitForTimeout`, `on('pageerror' | 'console', f)`.

import { spawn } from 'node:child_process';
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { chromiumArgs } from '../tests/harness.mjs';

export async function launchPlain() {
  const profile = mkdtempSync(join(tmpdir(), 'cga-bench-profile-'));
  const child = spawn(process.env.CHROMIUM || '/usr/bin/chromium', [
    '--headless',
    '--remote-debugging-pipe',
    `--user-data-dir=${profile}`,
    '--window-size=1280,800',
    ...chromiumArgs,
    'about:blank',
  ], { stdio: ['ignore', 'ignore', 'ignore', 'pipe', 'pipe'] });
  const toBrowser = child.stdio[3];
  const fromBrowser = child.stdio[4];
  let id = 0;
  const pending = new Map();
  const listeners = { pageerror: [], console: [] };
  let received = '';
  fromBrowser.on('data', (d) => {
    received += d;
    for (let end = received.indexOf('\0'); end >= 0; end = received.indexOf('\0')) {
      const message = JSON.parse(received.slice(0, end));
      received = received.slice(end + 1);
      if (message.id !== undefined && pending.has(message.id)) {
        const { resolve, reject } = pending.get(message.id);
        pending.delete(message.id);
        if (message.error) reject(new Error(message.error.message));
        else resolve(message.result);
      } else if (message.method === 'Runtime.exceptionThrown') {
        for (const f of listeners.pageerror) f(message.params.exceptionDetails.exception?.description ?? message.params.exceptionDetails.text);
      } else if (message.method === 'Runtime.consoleAPICalled') {
        const text = message.params.args.map((a) => a.value ?? a.description ?? '').join(' ');
        for (const f of listeners.console) f({ text: () => text });
      }
    }
  });
  const send = (method, params = {}, sessionId = undefined) => new Promise((resolve, reject) => {
    const message = { id: ++id, method, params, ...(sessionId ? { sessionId } : {}) };
    pending.set(message.id, { resolve, reject });
    toBrowser.write(`${JSON.stringify(message)}\0`);
  });

  async function newPage() {
    const { targetId } = await send('Target.createTarget', { url: 'about:blank' });
    const { sessionId } = await send('Target.attachToTarget', { targetId, flatten: true });
    await send('Runtime.enable', {}, sessionId);
    await send('Page.enable', {}, sessionId);
    const evaluate = async (fn, arg) => {
      const r = await send('Runtime.evaluate', {
        expression: `(${fn})(${arg === undefined ? '' : JSON.stringify(arg)})`,
        awaitPromise: true,
        returnByValue: true,
      }, sessionId);
      if (r.exceptionDetails) throw new Error(r.exceptionDetails.exception?.description ?? r.exceptionDetails.text);
      return r.result.value;
    };
    const page = {
      on(event, f) { listeners[event]?.push(f); },
      async goto(url) { await send('Page.navigate', { url }, sessionId); },
      evaluate,
      // Polled in the page (every 2 ms), as one evaluation.
      async waitForFunction(fn, arg, { timeout = 30000 } = {}) {
        const end = Date.now() + timeout;
        for (;;) {
          try {
            return await evaluate(`async (a) => {
              const f = ${fn};
              const end = performance.now() + ${timeout};
              while (!f(a)) {
                if (performance.now() > end) throw new Error('timed out');
                await new Promise((r) => setTimeout(r, 2));
              }
              return true;
            }`, arg);
          } catch (e) {
            // The page may be navigating or not have its script yet.
            if (Date.now() > end) throw e;
            await new Promise((r) => setTimeout(r, 50));
          }
        }
      },
      waitForTimeout: (ms) => new Promise((r) => setTimeout(r, ms)),
    };
    return page;
  }

  return {
    context: { newPage },
    async close() {
      child.kill();
      await new Promise((r) => child.once('exit', r));
      rmSync(profile, { recursive: true, force: true });
    },
  };
}
