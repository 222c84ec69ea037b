// Validates a glTF or GLB file with the Khronos glTF validator.
//
//     node tools/gltf-validator/validate.mjs FILE.glb|FILE.gltf
//
// Prints the validator's report as JSON on standard output. Exit status: 0 when
// the report has no errors, 1 when it has errors, 2 when the file cannot be
// read or the validator rejects it outright (not glTF/GLB at all).
// External resources (a .gltf's .bin, image files) are loaded relative to FILE.
// Install once: npm ci --prefix tools/gltf-validator
import { readFile } from "node:fs/promises";
import path from "node:path";
import * as validator from "gltf-validator";

const file = process.argv[2];
if (!file || process.argv.length > 3) {
  console.error("usage: node validate.mjs FILE.glb|FILE.gltf");
  process.exit(2);
}

let bytes;
try {
  bytes = new Uint8Array(await readFile(file));
} catch (e) {
  console.error(`cannot read ${file}: ${e.message}`);
  process.exit(2);
}

const dir = path.dirname(path.resolve(file));
let report;
try {
  report = await validator.validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 0, // unlimited
    writeTimestamp: false,
    externalResourceFunction: async (uri) =>
      new Uint8Array(await readFile(path.resolve(dir, decodeURIComponent(uri)))),
  });
} catch (e) {
  console.error(`validator rejected ${file}: ${e}`);
  process.exit(2);
}

console.log(JSON.stringify(report, null, 2));
process.exit(report.issues.numErrors > 0 ? 1 : 0);
