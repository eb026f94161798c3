// Every view hook a draw plan may name, by its Python name ("module:function"): the
// browser calls HOOKS[plan.per_view.function](plan, camera, light, plan.per_view.data).
// README.md gives the forms of the arguments and of the update.

import { boxView, cloudView } from "./billboard_box_view.js";
import { displacementSlicesView } from "./displacement_slices_view.js";
import { instancedView } from "./instanced_view.js";
import { proxyView } from "./relief_proxy_view.js";
import { visibilityHook } from "./shellvolume_visibility_hook.js";
import { rayCastView } from "./slicing_ray_cast_view.js";
import { slicesView } from "./slicing_slices_view.js";

export const HOOKS = {
  "reliefkit.techniques.relief.render:proxy_view": proxyView,
  "reliefkit.techniques.billboard.box_render:box_view": boxView,
  "reliefkit.techniques.billboard.box_render:cloud_view": cloudView,
  "reliefkit.techniques.slicing.render:ray_cast_view": rayCastView,
  "reliefkit.techniques.slicing.render:slices_view": slicesView,
  "reliefkit.techniques.slicing.displacement_render:slices_view": displacementSlicesView,
  "reliefkit.techniques.shellvolume.render:visibility_hook": visibilityHook,
  "reliefkit.render.instancing:instanced_view": instancedView,
};

/** The update of `plan` seen from `camera`: its hook's answer, or {} when it has none. */
export function viewUpdate(plan, camera, light) {
  if (!plan.per_view) return {};
  const fn = HOOKS[plan.per_view.function];
  if (!fn) throw new Error(`no JavaScript port of the view hook ${plan.per_view.function}`);
  return fn(plan, camera, light, plan.per_view.data);
}
