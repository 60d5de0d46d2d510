// Validates glTF files with the Khronos glTF validator. Exit 0: no errors and no warnings;
// 1: issues (listed); 77: the validator is not installed (ctest reports "skipped").
const fs = require('fs');
let validator;
try {
  validator = require('gltf-validator');
} catch (e) {
  console.log('skipped: gltf-validator not installed (npm ci --prefix tests/gltf)');
  process.exit(77);
}
(async () => {
  let failed = false;
  for (const file of process.argv.slice(2)) {
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)));
    const { numErrors, numWarnings } = report.issues;
    console.log(`${file}: ${numErrors} errors, ${numWarnings} warnings`);
    for (const m of report.issues.messages) console.log(`  ${m.code} ${m.pointer || ''}: ${m.message}`);
    if (numErrors || numWarnings) failed = true;
  }
  process.exit(failed ? 1 : 0);
})();
