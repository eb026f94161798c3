"""Multi-pass kinds of the executor: plans drawn by several passes instead of one draw
(`render.plan.MultiPass`); each module is one kind, listed in `render.executor.MULTIPASS`."""
