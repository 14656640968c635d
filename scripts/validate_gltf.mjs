#!/usr/bin/env node
// validate_gltf.mjs — runs the Khronos glTF validator on each file given.
//
//   node scripts/validate_gltf.mjs FILE.glb|FILE.gltf...
//
// Prints every issue as "FILE: SEVERITY CODE at POINTER: message". Exits 0 when no file
// has an error or a warning (infos and hints are printed but allowed), 1 when one has,
// 2 on a usage problem (no files, unreadable file, validator not installed: run
// scripts/setup.sh, which installs the pinned gltf-validator into .tools/node).
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const validatorDir = path.join(here, '..', '.tools', 'node', 'node_modules', 'gltf-validator');

let validator;
try {
  // The package is CommonJS; its exports arrive as the default export.
  const module = await import(pathToFileURL(path.join(validatorDir, 'index.js')).href);
  validator = module.default ?? module;
} catch (error) {
  console.error(`validate_gltf: error: the Khronos glTF validator is not installed at ${validatorDir} ` +
                `(run scripts/setup.sh): ${error.message}`);
  process.exit(2);
}

const files = process.argv.slice(2);
if (files.length === 0) {
  console.error('usage: node scripts/validate_gltf.mjs FILE.glb|FILE.gltf...');
  process.exit(2);
}

const severityName = ['error', 'warning', 'info', 'hint'];
let failed = 0;
for (const file of files) {
  let bytes;
  try {
    bytes = new Uint8Array(await readFile(file));
  } catch (error) {
    console.error(`${file}: error: cannot read: ${error.message}`);
    process.exit(2);
  }
  let report;
  try {
    report = await validator.validateBytes(bytes, {
      uri: path.basename(file),
      maxIssues: 0,  // report everything
      writeTimestamp: false,
      externalResourceFunction: (uri) =>
        readFile(path.resolve(path.dirname(file), decodeURIComponent(uri))).then((b) => new Uint8Array(b)),
    });
  } catch (error) {
    console.error(`${file}: error: the validator could not read it: ${error}`);
    ++failed;
    continue;
  }
  const issues = report.issues;
  for (const m of issues.messages) {
    console.log(`${file}: ${severityName[m.severity] ?? m.severity} ${m.code}` +
                `${m.pointer ? ' at ' + m.pointer : ''}${m.offset !== undefined ? ' at byte ' + m.offset : ''}: ${m.message}`);
  }
  const bad = issues.numErrors + issues.numWarnings;
  console.log(`${file}: ${issues.numErrors} errors, ${issues.numWarnings} warnings, ${issues.numInfos} infos, ` +
              `${issues.numHints} hints${bad ? ' — FAILED' : ' — ok'}`);
  if (bad) ++failed;
}
process.exit(failed ? 1 : 0);
