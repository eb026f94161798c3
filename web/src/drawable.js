// One `draw` object of a GLB (its plans, or the iteration-counting `instrumented` ones) made
// ready in a WebGL2 context: its arrays read, its plans decoded and added to an Executor of
// their own; a plan the page cannot draw is reported and left out.

import { Executor, Unsupported } from './executor.js';
import { readArrays } from './glb.js';
import { HOOKS } from './hooks/index.js';
import { decodePlans } from './plans.js';

/** {executor, plans}: the plans ``draw`` holds that the executor can draw. */
export async function makeDrawable(gl, glb, draw, name, programs, report) {
  const plans = decodePlans(draw, await readArrays(gl, glb, draw));
  const executor = new Executor(gl, draw, name, HOOKS, programs);
  const drawn = [];
  try {
    for (const plan of plans) {
      try {
        executor.add(plan);
        drawn.push(plan);
      } catch (e) {
        if (!(e instanceof Unsupported)) throw e;
        report(`${name}: ${e.message}`);
      }
    }
  } catch (e) {
    executor.dispose(); // what it made so far (a shader that does not compile)
    throw e;
  }
  return { executor, plans: drawn };
}
