// Runs the Khronos glTF-Validator on each file given; prints one JSON line per file with its counts
// of errors, warnings, infos and the first messages. Exit code 1 if any file has an error.
// Usage: node scripts/validate_gltf.mjs FILE.glb...   (gltf-validator from scripts/node/)
import { createRequire } from "node:module";
import { readFileSync } from "node:fs";
import { dirname, join } from "node:path";
import { fileURLToPath } from "node:url";

const require = createRequire(join(dirname(fileURLToPath(import.meta.url)), "node", "package.json"));
const validator = require("gltf-validator");

let failed = false;
for (const file of process.argv.slice(2)) {
  const report = await validator.validateBytes(new Uint8Array(readFileSync(file)), {
    uri: file,
    maxIssues: 100,
    externalResourceFunction: () => Promise.reject(new Error("external resources are not used")),
  });
  const issues = report.issues;
  const first = issues.messages.slice(0, 5).map((m) => `${m.code} ${m.pointer ?? ""}: ${m.message}`);
  console.log(JSON.stringify({ file, errors: issues.numErrors, warnings: issues.numWarnings,
    infos: issues.numInfos, messages: first }));
  if (issues.numErrors > 0) failed = true;
}
process.exit(failed ? 1 : 0);
