// Runs the JavaScript view hooks for tests/viewer/test_hooks_js.py: one JSON request a line
// on stdin, one JSON answer a line on stdout; arrays travel as {dtype, shape, b64} (the
// bytes little-endian, base64).
//   {"load": {"doc": <to_json document>, "arrays": {key: array}}}  -> {"plans": N}
//   {"call": {"plan": i, "camera": {...}, "light": {...}}}         -> {"update": {...}}
//   {"names": true}                                                -> {"names": [HOOKS' keys]}
// An error answers {"error": "..."} and the process goes on.

import { createInterface } from "node:readline";
import { ndarray, typedArrayOf } from "../../web/src/hooks/ndarray.js";
import { decodePlans } from "../../web/src/plans.js";
import { HOOKS, viewUpdate } from "../../web/src/hooks/index.js";

function fromWire(a) {
  const bytes = Buffer.from(a.b64, "base64");
  const Type = typedArrayOf(a.dtype);
  const copy = new Uint8Array(bytes); // aligned
  return ndarray(a.dtype, a.shape, new Type(copy.buffer, 0, copy.length / Type.BYTES_PER_ELEMENT));
}

function toWire(value) {
  if (ArrayBuffer.isView(value)) throw new Error("a bare typed array: give {dtype, shape, data}");
  if (Array.isArray(value)) return value.map(toWire);
  if (value === null || typeof value !== "object") return value;
  if (value.dtype && value.data && ArrayBuffer.isView(value.data)) {
    const d = value.data;
    return { dtype: value.dtype, shape: value.shape,
      b64: Buffer.from(d.buffer, d.byteOffset, d.byteLength).toString("base64") };
  }
  return Object.fromEntries(Object.entries(value).map(([k, v]) => [k, toWire(v)]));
}

let plans = [];
const lines = createInterface({ input: process.stdin, crlfDelay: Infinity });
for await (const line of lines) {
  if (!line.trim()) continue;
  let answer;
  try {
    const request = JSON.parse(line);
    if (request.names) {
      answer = { names: Object.keys(HOOKS) };
    } else if (request.load) {
      const arrays = Object.fromEntries(Object.entries(request.load.arrays).map(
        ([k, a]) => [k, fromWire(a)]));
      plans = decodePlans(request.load.doc, arrays);
      answer = { plans: plans.length };
    } else {
      const { plan, camera, light } = request.call;
      answer = { update: toWire(viewUpdate(plans[plan], camera, light)) };
    }
  } catch (error) {
    answer = { error: String(error && error.stack || error) };
  }
  process.stdout.write(`${JSON.stringify(answer)}\n`);
}
