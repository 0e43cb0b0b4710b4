// Validate glTF/GLB files with the Khronos glTF validator (npm package gltf-validator) and print one JSON
// object: file -> the validator's report (issues listed in full, no timestamp).
//   node tests/gltf_validate.js VALIDATOR_DIR FILE...
// VALIDATOR_DIR: where `npm install --prefix VALIDATOR_DIR gltf-validator` put its node_modules.
"use strict";
const fs = require("fs");
const path = require("path");
const validator = require(path.join(path.resolve(process.argv[2]), "node_modules", "gltf-validator"));

async function main() {
  const reports = {};
  for (const file of process.argv.slice(3)) {
    const bytes = new Uint8Array(fs.readFileSync(file));
    reports[file] = await validator.validateBytes(bytes, { uri: path.basename(file), maxIssues: 0, writeTimestamp: false });
  }
  process.stdout.write(JSON.stringify(reports) + "\n");
}

main().catch(e => { process.stderr.write(String(e) + "\n"); process.exit(1); });
