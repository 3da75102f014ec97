// Validates glTF/GLB files with the Khronos glTF-Validator (npm `gltf-validator`).
// Usage: node viewer/test/validate.mjs FILE.glb...   Exit status 1 if any file has an error.
// Also importable: `validateFile(path)` returns the validator's report.
import { readFile } from 'node:fs/promises';
import { pathToFileURL } from 'node:url';
import validator from 'gltf-validator';

export async function validateFile(path) {
  const bytes = new Uint8Array(await readFile(path));
  return validator.validateBytes(bytes, {
    uri: path,
    maxIssues: 100,
    externalResourceFunction: () => Promise.reject(new Error('external resources are not used')),
  });
}

if (import.meta.url === pathToFileURL(process.argv[1]).href) {
  let failed = 0;
  for (const f of process.argv.slice(2)) {
    const r = await validateFile(f);
    const { numErrors, numWarnings, numInfos, numHints } = r.issues;
    console.log(`${f}: ${numErrors} errors, ${numWarnings} warnings, ${numInfos} infos, ${numHints} hints`);
    for (const m of r.issues.messages) {
      if (m.severity <= 1) console.log(`  [${m.severity === 0 ? 'error' : 'warning'}] ${m.code} ${m.pointer ?? ''}: ${m.message}`);
    }
    if (numErrors > 0) failed += 1;
  }
  process.exit(failed ? 1 : 0);
}
