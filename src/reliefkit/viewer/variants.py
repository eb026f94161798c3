"""Each input's GLB made again with other render options, for the page's controls.

The plans are made in Python from the options (a cone map, a maximum mipmap, a multi-pass
kind), so switching ``--method`` in the page asks the server for ``input-K.glb?method=cone``:
the query's flags are checked as the command line's are (`core.params.applicable`, per the
declaring drawable), the GLB is exported in the request's thread, one export at a time per
input, and the last few are kept per input. No HTTP here: the server hands over the file
name and the query string.
"""

from __future__ import annotations

import re
import threading
from collections import OrderedDict
from urllib.parse import parse_qsl

from ..core.params import applicable
from ..errors import UsageError
from ..io.inputs import what_it_is
from ..render import render_options
from .site import Input, glb_of

#: GLBs kept per input (each can be MBs): the one it was opened with and a few switches
KEEP = 4
_GLB_NAME = re.compile(r"input-(\d+)\.glb")


def checked_options(item: Input, options: dict) -> dict:
    """``options`` parsed (booleans 'true'/'false', '' for none) and checked by ``item``'s
    declarations, as `reliefkit render`'s flags are."""
    declared = {opt.name: opt for opt in render_options(item.obj)}
    given = {}
    for key, value in options.items():
        name = key.replace("-", "_")
        opt = declared.get(name)
        if opt is not None and isinstance(value, str):
            value = _from_text(opt, value)
        given[name] = value
    return applicable(given, declared.values(), what_it_is(item.name, item.obj))


def _from_text(opt, text: str):
    if opt.kind == "bool" and text in ("true", "false"):
        return text == "true"
    if text == "" and opt.default is None:
        return None
    return text  # Option.check converts it, or says what it must be


class Variants:
    """The GLBs the server answers ``input-K.glb?FLAG=VALUE&...`` with (`answer`)."""

    def __init__(self, inputs: list[Input], keep: int = KEEP):
        self.inputs = inputs
        self.keep = keep
        self._locks = [threading.Lock() for _ in inputs]
        self._made = [OrderedDict({_key(i, i.options): i.glb}) if i.obj is not None
                      else OrderedDict() for i in inputs]

    def answer(self, name: str, query: str) -> bytes | None:
        """The GLB for file ``name`` and URL ``query``; None when ``name`` is no input's GLB;
        a UsageError for bad options."""
        match = _GLB_NAME.fullmatch(name)
        if match is None or int(match[1]) >= len(self.inputs):
            return None
        index = int(match[1])
        item = self.inputs[index]
        if item.obj is None:
            raise UsageError(f"{item.name}: its render options cannot be changed here")
        pairs = parse_qsl(query, keep_blank_values=True)
        twice = sorted({k for k, _ in pairs if sum(1 for j, _ in pairs if j == k) > 1})
        if twice:
            raise UsageError(f"--{', --'.join(twice)} given twice")
        options = checked_options(item, dict(pairs))
        key = _key(item, options)
        made = self._made[index]
        with self._locks[index]:
            if key not in made:
                made[key] = glb_of(item.obj, options)
                while len(made) > self.keep:
                    made.popitem(last=False)
            made.move_to_end(key)
            return made[key]


    def kept(self, index: int) -> int:
        """How many GLBs of input ``index`` are kept."""
        return len(self._made[index])


def _key(item: Input, options: dict) -> tuple:
    """``options`` with the declared defaults left out: the same plans, the same key."""
    defaults = {opt.name: opt.default for opt in render_options(item.obj)}
    return tuple(sorted((k, v) for k, v in options.items() if defaults.get(k) != v))
