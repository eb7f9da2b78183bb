// Validates a .glb/.gltf with the Khronos glTF-Validator (npm gltf-validator, installed by
// scripts/fetch_gltf_validator) and prints its issue counts and messages; exit 0 when the
// report has no errors, 1 otherwise, 2 on a usage or read failure.
// Usage: NODE_PATH=DIR/node_modules node validate.js FILE
const fs = require('fs');
const validator = require('gltf-validator');
const file = process.argv[2];
if (!file) {
  console.error('usage: validate.js FILE.glb');
  process.exit(2);
}
const bytes = new Uint8Array(fs.readFileSync(file));
validator.validateBytes(bytes, {maxIssues: 100})
    .then((report) => {
      const i = report.issues;
      console.log(`gltf-validator ${report.validatorVersion}: ${file}: ${i.numErrors} errors, ` +
                  `${i.numWarnings} warnings, ${i.numInfos} infos, ${i.numHints} hints`);
      for (const m of i.messages) {
        if (m.severity <= 1) console.log(`  [${m.severity}] ${m.code} ${m.pointer || ''}: ${m.message}`);
      }
      process.exit(i.numErrors === 0 ? 0 : 1);
    })
    .catch((e) => {
      console.error(`gltf-validator: ${file}: ${e}`);
      process.exit(2);
    });
