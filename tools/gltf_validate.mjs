// Validates a glTF 2.0 file (.glb or .gltf) with the Khronos glTF-Validator and prints its report.
// Exits 1 when the report has errors, 2 when the validator cannot be loaded or run.
//
// Install the validator once:  npm install --prefix "$HOME/.cache/gltf-validator" gltf-validator
// Usage:                       node tools/gltf_validate.mjs FILE.glb
// GLTF_VALIDATOR_DIR overrides the package folder
// (default: $HOME/.cache/gltf-validator/node_modules/gltf-validator).
import { createRequire } from "node:module";
import { readFileSync } from "node:fs";
import { homedir } from "node:os";
import { join } from "node:path";

const file = process.argv[2];
if (!file) {
  console.error("usage: node tools/gltf_validate.mjs FILE.glb");
  process.exit(2);
}
const dir = process.env.GLTF_VALIDATOR_DIR || join(homedir(), ".cache/gltf-validator/node_modules/gltf-validator");
let validator;
try {
  validator = createRequire(import.meta.url)(dir);
} catch (e) {
  console.error(`cannot load gltf-validator from ${dir}: ${e.message}`);
  process.exit(2);
}
try {
  const report = await validator.validateBytes(new Uint8Array(readFileSync(file)), {
    uri: file,
    maxIssues: 0,
    writeTimestamp: false,
  });
  const { numErrors, numWarnings, numInfos, numHints, messages } = report.issues;
  const severity = ["error", "warning", "info", "hint"];
  console.log(`${file}: gltf-validator ${validator.version()}: ` +
    `${numErrors} errors, ${numWarnings} warnings, ${numInfos} infos, ${numHints} hints`);
  for (const m of messages) {
    console.log(`  ${severity[m.severity]} ${m.code} at ${m.pointer ?? m.offset ?? "-"}: ${m.message}`);
  }
  const info = report.info ?? {};
  console.log(`  info: ${JSON.stringify({ generator: info.generator, animationCount: info.animationCount,
    hasSkins: info.hasSkins, totalVertexCount: info.totalVertexCount, totalTriangleCount: info.totalTriangleCount,
    maxInfluences: info.maxInfluences })}`);
  process.exit(numErrors > 0 ? 1 : 0);
} catch (e) {
  console.error(`${file}: gltf-validator failed: ${e}`);
  process.exit(2);
}
