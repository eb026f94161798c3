// render/instancing.py:instanced_view: an instance-safe hook's update for every instance,
// its faces to cull left to the plan's own back-face culling.

import { HOOKS } from "./index.js";

export function instancedView(plan, camera, light, { hook, data }) {
  const fn = HOOKS[hook];
  if (!fn) throw new Error(`no JavaScript port of the view hook ${hook}`);
  const { cull, ...update } = fn(plan, camera, light, data);
  return update;
}
