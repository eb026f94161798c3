"""Declared options on the command line: one flag per name, checked by its owner."""

from __future__ import annotations

import argparse

from ..core.params import describe_default


def add_flag(parser, *args, within=None, dash_value: bool = False, **kwargs):
    """``add_argument`` (to ``within``, a group of ``parser``, if given); with ``dash_value``
    the flag's value may start with '-' (see `_Parser`)."""
    action = (within or parser).add_argument(*args, **kwargs)
    if dash_value:
        parser.dash_values.update(s for s in action.option_strings if s.startswith("--"))
    return action


OPTION_PREFIX = "opt_"  # argparse dest of a declared option (kept apart from the command's own)


def add_options(p: argparse.ArgumentParser, owners: list[tuple[str, tuple]], title: str):
    """One flag per declared option name, whoever declares it; defaults stay the owners'.

    The flag's value is checked later by the declaration of whatever the input turns out to
    be, so two techniques may both declare ``method`` with different choices.
    """
    by_name: dict[str, list] = {}
    for owner, options in owners:
        for opt in options:
            by_name.setdefault(opt.name, []).append((owner, opt))
    group = p.add_argument_group(title)
    for name, decls in by_name.items():
        first = decls[0][1]
        flag = "--" + first.flag
        if all(opt.kind == "bool" for _, opt in decls):
            group.add_argument(flag, dest=OPTION_PREFIX + name, default=None,
                               action=argparse.BooleanOptionalAction, help=_option_help(decls))
            continue
        choices = dict.fromkeys(str(c) for _, opt in decls for c in (opt.choices or ()))
        metavar = "|".join(choices) if choices else (
            ",".join(["X"] * (first.count or 2)) if first.kind == "floats" else first.kind.upper())
        add_flag(p, flag, within=group, dest=OPTION_PREFIX + name, default=None,
                  metavar=metavar, help=_option_help(decls),
                  dash_value=any(_takes_dash(opt) for _, opt in decls))


def _takes_dash(opt) -> bool:
    """Whether a value of ``opt`` may start with '-': a number, or a choice such as '-y'."""
    if opt.choices:
        return any(str(choice).startswith("-") for choice in opt.choices)
    return opt.kind in ("int", "float", "floats")


def _option_help(decls: list) -> str:
    """One help text for an option that several owners declare: owners sharing a text or a
    default are listed together."""
    texts: dict[str, list[str]] = {}
    defaults: dict[str, list[str]] = {}
    for owner, opt in decls:
        for table, key in ((texts, opt.help), (defaults, describe_default(opt))):
            owners = table.setdefault(key, [])
            if owner not in owners:
                owners.append(owner)
    single = len(texts) == 1
    parts = [text if single else f"{', '.join(owners)}: {text}" for text, owners in texts.items()]
    owners_all = ", ".join(dict.fromkeys(o for o, _ in decls))
    if len(defaults) == 1:
        tail = f"default {next(iter(defaults))}"
    else:
        tail = "default " + ", ".join(f"{d} ({', '.join(o)})" for d, o in defaults.items())
    return (f"[{owners_all}] " if single else "") + "; ".join(parts).replace("%", "%%") + \
        f"; {tail}"


def given_options(args) -> dict:
    """The declared options the user gave (the rest keep their declared defaults)."""
    return {key[len(OPTION_PREFIX):]: value for key, value in vars(args).items()
            if key.startswith(OPTION_PREFIX) and value is not None}
