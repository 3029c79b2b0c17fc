// Runs Khronos's glTF-Validator (npm `gltf-validator`) on each file named on the command line and
// prints one JSON line per file: {"file", "errors", "warnings", "messages": [first errors]}.
// Exit status 0 whatever it finds: the Rust test (tests/gltf_variants.rs) judges the report.
import { readFile } from 'node:fs/promises';
import { createRequire } from 'node:module';

const require = createRequire(import.meta.url);
const validator = require('gltf-validator');

for (const file of process.argv.slice(2)) {
  const bytes = new Uint8Array(await readFile(file));
  const report = await validator.validateBytes(bytes, { maxIssues: 100 });
  const errors = report.issues.messages.filter((m) => m.severity === 0);
  console.log(JSON.stringify({
    file,
    errors: report.issues.numErrors,
    warnings: report.issues.numWarnings,
    messages: errors.slice(0, 10).map((m) => `${m.code} at ${m.pointer}: ${m.message}`),
    warningMessages: report.issues.messages.filter((m) => m.severity === 1).slice(0, 10).map((m) => `${m.code} at ${m.pointer}: ${m.message}`),
  }));
}
