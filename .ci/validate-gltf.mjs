// Runs the Khronos glTF validator (the npm package `gltf-validator`) on
// each file given: prints its counts and every message, and exits 1 if
// any file has an error (severity 0) or a warning (1), or the validator
// cannot read it. Infos and hints are printed only.
//
// usage: node .ci/validate-gltf.mjs VALIDATOR_DIR FILE...
//   VALIDATOR_DIR: where `npm install --prefix` put the package.
import { readFileSync } from "node:fs";
import { createRequire } from "node:module";
import { join, resolve } from "node:path";

const [dir, ...files] = process.argv.slice(2);
if (!dir || files.length === 0) {
  console.error("usage: node .ci/validate-gltf.mjs VALIDATOR_DIR FILE...");
  process.exit(2);
}
const require = createRequire(join(resolve(dir), "package.json"));
const validator = require("gltf-validator");
const severities = ["error", "warning", "info", "hint"];

let failed = false;
for (const file of files) {
  try {
    const report = await validator.validateBytes(new Uint8Array(readFileSync(file)), {
      uri: file,
      maxIssues: 0,
    });
    const { numErrors, numWarnings, numInfos, numHints, messages } = report.issues;
    console.log(
      `${file}: ${numErrors} errors, ${numWarnings} warnings, ${numInfos} infos, ${numHints} hints ` +
        `(gltf-validator ${report.validatorVersion})`,
    );
    for (const m of messages) {
      console.log(`  ${severities[m.severity]} ${m.code} at ${m.pointer ?? m.offset ?? ""}: ${m.message}`);
    }
    failed ||= numErrors > 0 || numWarnings > 0;
  } catch (e) {
    console.log(`${file}: the validator could not read it: ${e}`);
    failed = true;
  }
}
process.exit(failed ? 1 : 0);
