"""Typed options: baker parameters and render options declared once, as dataclass fields.

A technique writes

    @dataclass(frozen=True)
    class ReliefRender:
        method: str = param("robust", "ray/heightfield intersection", choices=METHODS)
        linear_steps: int = param(16, "binary: fixed pre-steps", lo=1, hi=4096)

and gets validation (`make`), the CLI's flags, defaults and help (`Option`), and one place
where each default lives.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from functools import cache

from ..errors import UsageError
from .transforms import MAX_COORDINATE

KINDS = ("bool", "int", "float", "str", "floats")

#: The render option an animated representation declares: its time, period 1
#: (``reliefkit render --animate N`` draws times 0, 1/N, ...).
ANIMATION_TIME = "time"


def param(default, help: str, *, choices: tuple | None = None, lo: float | None = None,
          hi: float | None = None, kind: str | None = None, count: int | None = None):
    """A dataclass field carrying what an `Option` needs.

    ``kind`` is inferred from the default (give it when the default is None); ``"floats"``
    is a comma-separated list of ``count`` numbers (``--box 2,0.5,2``). ``lo``/``hi`` bound
    numbers (inclusive), every entry of a ``floats``.
    """
    if kind is None:
        kind = {bool: "bool", int: "int", float: "float", str: "str"}.get(type(default))
    if kind not in KINDS:
        raise TypeError(f"param({default!r}): give kind= (one of {', '.join(KINDS)})")
    meta = {"help": help, "choices": tuple(choices) if choices else None, "lo": lo, "hi": hi,
            "kind": kind, "count": count}
    if isinstance(default, list | dict | set):
        raise TypeError("param defaults must be immutable (use a tuple)")
    return dataclasses.field(default=default, metadata={"reliefkit": meta})


@dataclass(frozen=True)
class Option:
    """One declared option: name, default, help, and how to parse and check a value."""

    name: str
    default: object
    help: str
    kind: str
    choices: tuple | None = None
    lo: float | None = None
    hi: float | None = None
    count: int | None = None

    @property
    def flag(self) -> str:
        return self.name.replace("_", "-")

    def check(self, value, owner: str):
        """The value converted to this option's kind, or UsageError saying what is allowed."""
        where = f"{owner}: {self.flag}"
        if value is None:
            if self.default is None:
                return None
            raise UsageError(f"{where} needs a value")
        try:
            value = _convert(self.kind, value, self.count)
        except (TypeError, ValueError):
            shape = f"{self.count} comma-separated numbers" if self.kind == "floats" else \
                _KIND_NAMES.get(self.kind, f"a {self.kind}")
            raise UsageError(f"{where} must be {shape}, got {value!r}") from None
        if self.choices and value not in self.choices:
            raise UsageError(f"{where} must be one of {', '.join(map(str, self.choices))}, "
                             f"got {value!r}")
        for v in (value if self.kind == "floats" else (value,)):
            if self.kind in ("int", "float", "floats") and not (
                    (self.lo is None or v >= self.lo) and (self.hi is None or v <= self.hi)):
                raise UsageError(f"{where} must be within [{_num(self.lo, '-inf')}, "
                                 f"{_num(self.hi, 'inf')}], got {v!r}")
        return value


def _num(x, unbounded: str) -> str:
    return unbounded if x is None else f"{x:g}"


_KIND_NAMES = {"int": "an integer", "float": "a number", "bool": "true or false",
               "str": "a string"}


def _convert(kind: str, value, count: int | None):
    if kind == "bool":
        if isinstance(value, bool):
            return value
        raise TypeError
    if kind == "int":
        if isinstance(value, bool) or (isinstance(value, float) and not value.is_integer()):
            raise TypeError
        return int(value)
    if kind == "float":
        if isinstance(value, bool):
            raise TypeError
        out = float(value)
        if out != out or out in (float("inf"), float("-inf")):
            raise ValueError
        return out
    if kind == "str":
        if not isinstance(value, str):
            raise TypeError
        return value
    items = value.split(",") if isinstance(value, str) else list(value)
    out = tuple(float(x) for x in items)
    if (count is not None and len(out) != count) or any(v != v for v in out):
        raise ValueError
    return out


@cache
def options_of(cls: type) -> tuple[Option, ...]:
    """The `Option`s of a params dataclass, in field order; every field must use `param`."""
    if not dataclasses.is_dataclass(cls):
        raise TypeError(f"{cls!r} is not a dataclass of options")
    out = []
    for f in dataclasses.fields(cls):
        meta = f.metadata.get("reliefkit")
        if meta is None:
            raise TypeError(f"{cls.__qualname__}.{f.name} is not declared with param()")
        out.append(Option(f.name, f.default, meta["help"], meta["kind"], meta["choices"],
                          meta["lo"], meta["hi"], meta["count"]))
    return tuple(out)


def make(cls: type, values: dict, owner: str, *, strict: bool = True):
    """An instance of the params dataclass ``cls`` from ``values``, every value checked.

    With ``strict`` a key that is no field of ``cls`` is an error naming the known ones.
    """
    options = {opt.name: opt for opt in options_of(cls)}
    unknown = sorted(set(values) - set(options))
    if strict and unknown:
        raise UsageError(f"{owner}: unknown option(s) {', '.join(unknown)} (it has: "
                         f"{', '.join(options) or 'none'})")
    kwargs = {name: options[name].check(v, owner) for name, v in values.items() if name in options}
    return cls(**kwargs)


def describe_default(opt: Option) -> str:
    if opt.default is None:
        return "none"
    if opt.kind == "floats":
        return ",".join(f"{x:g}" for x in opt.default)
    return str(opt.default)


def applicable(given: dict, options, what: str) -> dict:
    """``given`` restricted to ``options`` and checked by their declarations; a flag that
    does not apply, or a bad value, is a UsageError naming the flag as the user typed it."""
    by_name = {opt.name: opt for opt in options}
    wrong = [k for k in given if k not in by_name]
    if wrong:
        flags = ", ".join("--" + k.replace("_", "-") for k in wrong)
        has = ", ".join("--" + opt.flag for opt in options) or "none"
        raise UsageError(f"{flags} does not apply to {what} (its options: {has})")
    return {name: checked(by_name[name], value, what) for name, value in given.items()}


def checked(opt, value, what: str):
    """``opt.check`` with the message saying ``--flag`` (the declaration says ``flag``)."""
    try:
        checked = opt.check(value, what)
    except UsageError as exc:
        message, bare = str(exc), f"{what}: {opt.flag} "
        if message.startswith(bare):
            message = f"--{opt.flag} {message[len(bare):]} ({what})"
        raise UsageError(message) from None
    if opt.kind in ("float", "floats") and checked is not None:
        for v in (checked if opt.kind == "floats" else (checked,)):
            if not (math.isfinite(v) and abs(v) <= MAX_COORDINATE):
                raise UsageError(f"--{opt.flag} needs finite numbers of magnitude at most "
                                 f"{MAX_COORDINATE:g}, got {value!r} ({what})")
    return checked


