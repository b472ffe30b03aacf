// Validate a .glb with the Khronos glTF validator; print one JSON report on stdout.
// Usage: node web/validate_gltf.mjs FILE.glb   (exit 0 when it ran; the counts tell the verdict)
import fs from 'node:fs';
import path from 'node:path';
import validator from 'gltf-validator';

const file = process.argv[2];
const data = new Uint8Array(fs.readFileSync(file));
const report = await validator.validateBytes(data, {
  uri: path.basename(file),
  maxIssues: 0,
  externalResourceFunction: () => Promise.reject(new Error('a GLB from glassbench has no external resources')),
});
const issues = report.issues;
console.log(JSON.stringify({
  validatorVersion: report.validatorVersion,
  errors: issues.numErrors, warnings: issues.numWarnings, infos: issues.numInfos, hints: issues.numHints,
  messages: issues.messages.filter((m) => m.severity <= 1),
  info: report.info,
}));
