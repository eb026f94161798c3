// Runs web/src/textures/bc.js for tests/viewer/test_bc_js.py: one JSON request a line on
// stdin, one JSON answer a line on stdout; bytes travel base64.
//   {"decode": {"encoding": {...}, "b64": "..."}}
//       -> {"dtype", "shape", "b64"} (little-endian)
//   {"glFormat": {"encoding": {...}, "extensions": [names], "texture": {...}}}
//       -> {"format": number | null, "decode": [scale, bias], "enabled": [names]}
// An error answers {"error": "..."} and the process goes on.

import { createInterface } from "node:readline";
import { decodeEncoded, glFormatOf, samplerDecode } from "../../web/src/textures/bc.js";

/** A WebGL2 context as far as glFormatOf sees it: getExtension of the named ones. */
function fakeGl(extensions) {
  const enabled = [];
  const getExtension = (name) => (extensions.includes(name) ? (enabled.push(name), {}) : null);
  return { enabled, getExtension };
}

const lines = createInterface({ input: process.stdin, crlfDelay: Infinity });
for await (const line of lines) {
  if (!line.trim()) continue;
  let answer;
  try {
    const request = JSON.parse(line);
    if (request.decode) {
      const { encoding, b64 } = request.decode;
      const stored = new Uint8Array(Buffer.from(b64, "base64"));
      const { dtype, shape, data } = decodeEncoded(encoding, stored);
      const bytes = Buffer.from(data.buffer, data.byteOffset, data.byteLength);
      answer = { dtype, shape, b64: bytes.toString("base64") };
    } else {
      const { encoding, extensions, texture } = request.glFormat;
      const gl = fakeGl(extensions);
      const format = glFormatOf(encoding, gl, texture);
      answer = { format, decode: samplerDecode(encoding, format), enabled: gl.enabled };
    }
  } catch (error) {
    answer = { error: String(error && error.stack || error) };
  }
  process.stdout.write(`${JSON.stringify(answer)}\n`);
}
