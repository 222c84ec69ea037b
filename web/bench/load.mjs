// A bounded load test of `cga serve` on loopback (docs/performance.md):
// CLIENTS clients (default 50) each ask for ROUNDS regenerations (default
// 20: new attribute values, the model being made for them, then the state
// and the model), three times over; prints errors, time and the server's
// resident memory after each pass (it should stay flat).
//
//   CGA_BIN=target/release/cga node bench/load.mjs [RULES.cga [LOT SPEC]]

import { readFileSync } from 'node:fs';
import { join } from 'node:path';
import { repo, startServer } from '../tests/harness.mjs';

const [rules = join(repo, 'examples', 'building.cga'), lot] = process.argv.slice(2);
const clients = Number(process.env.CLIENTS || 50);
const rounds = Number(process.env.ROUNDS || 20);
const server = await startServer([rules, ...(lot ? ['--lot', lot] : [])]);
const rss = () => {
  const m = readFileSync(`/proc/${server.child.pid}/status`, 'utf8').match(/VmRSS:\s+(\d+) kB/);
  return Math.round(Number(m[1]) / 1024);
};
let errors = 0;
let requests = 0;
async function check(response) {
  requests++;
  if (!response.ok) errors++;
  return response.arrayBuffer();
}
async function client(c) {
  for (let r = 0; r < rounds; r++) {
    try {
      const answer = await check(await fetch(`${server.url}api/params`, {
        method: 'POST',
        headers: { 'content-type': 'application/json' },
        body: JSON.stringify({ seed: c, attrs: { floors: 1 + ((c + r) % 20) } }),
      }));
      // The model being made for this request (most are replaced by
      // another client's before they are done: abandoned).
      const { request } = JSON.parse(new TextDecoder().decode(answer));
      await check(await fetch(`${server.url}api/live.bin?n=${request}`));
      await check(await fetch(`${server.url}api/state`));
      await check(await fetch(`${server.url}api/model.bin`));
    } catch (e) {
      errors++;
    }
  }
}
try {
  const passes = [];
  const start = rss();
  for (let pass = 1; pass <= 3; pass++) {
    const t = performance.now();
    await Promise.all(Array.from({ length: clients }, (_, c) => client(c)));
    passes.push({ pass, seconds: ((performance.now() - t) / 1000).toFixed(1), rss_mib: rss() });
  }
  const alive = (await fetch(`${server.url}api/state`)).ok;
  console.log(JSON.stringify({ clients, rounds, requests, errors, rss_mib_at_start: start, passes, alive }, null, 1));
  if (errors || !alive) process.exitCode = 1;
} finally {
  server.child.kill();
}
