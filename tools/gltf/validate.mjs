// Print the Khronos glTF validator's JSON report for one .glb or .gltf file.
// Usage: node tools/gltf/validate.mjs FILE   (after `npm ci` in the repository root)
// Exit status: 0 with the report on stdout; 2 with one `error: ...` line when FILE cannot be read.
import { readFile } from "node:fs/promises";
import path from "node:path";
import validator from "gltf-validator";

const file = process.argv[2];
if (!file || process.argv.length > 3) {
  console.error("error: usage: node tools/gltf/validate.mjs FILE");
  process.exit(2);
}
let bytes;
try {
  bytes = new Uint8Array(await readFile(file));
} catch (err) {
  console.error(`error: ${file}: ${err.code === "ENOENT" ? "no such file" : err.message}`);
  process.exit(2);
}
// a .gltf's buffers and images are resolved beside it; a GLB of reliefkit's has none
const folder = path.dirname(path.resolve(file));
const report = await validator.validateBytes(bytes, {
  uri: path.basename(file),
  maxIssues: 0, // report them all
  externalResourceFunction: async (uri) =>
    new Uint8Array(await readFile(path.resolve(folder, decodeURIComponent(uri)))),
});
process.stdout.write(JSON.stringify(report, null, 2) + "\n");
