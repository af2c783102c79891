"""What every ``softgym`` parser shares: the help format, the global flags, subcommands."""

from __future__ import annotations

import argparse
from importlib.metadata import PackageNotFoundError, version
from typing import Any

__all__ = ["HelpFormatter", "installed_version", "subcommands"]


class HelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """``--help`` shows every default as ``(default: X)``; options without one say theirs in words."""

    def _get_help_string(self, action: argparse.Action) -> str:
        if action.default is None or isinstance(action, argparse._StoreTrueAction):
            return action.help or ""
        return super()._get_help_string(action)


def installed_version() -> str:
    """The version pyproject.toml gives the installed distribution."""
    try:
        return version("softgym")
    except PackageNotFoundError:  # pragma: no cover - run from a bare source tree
        return "unknown (not installed)"


def global_flags(p: argparse.ArgumentParser, default: Any) -> None:
    """``-v`` and ``-q``, on the main parser (``default``: their defaults) and on every
    subcommand (``argparse.SUPPRESS``: typed after the subcommand, they still count).
    """
    p.add_argument("-v", "--verbose", action="count",
                   default=0 if default is None else default,
                   help="log lines (-v: each generation and Dask's; -vv: debug)")  # fmt: skip
    p.add_argument("-q", "--quiet", action="store_true",
                   default=False if default is None else default,
                   help="no progress bar (study: no line per finished run)")  # fmt: skip


def subcommands(parser: argparse.ArgumentParser, dest: str, default: str | None = None,
                default_help: str = "run (the default)") -> Any:  # fmt: skip
    """A subparsers action whose parsers show their defaults and take the global flags;
    with ``default``, the subcommand is optional and ``default`` (e.g. ``"run"``) is one.
    """
    sub = parser.add_subparsers(dest=dest, required=default is None)
    add = sub.add_parser

    def add_parser(name: str, **kw: Any) -> argparse.ArgumentParser:
        p = add(name, formatter_class=HelpFormatter, allow_abbrev=False, **kw)
        global_flags(p, argparse.SUPPRESS)
        return p

    sub.add_parser = add_parser
    if default is not None:
        sub.add_parser(default, help=default_help).set_defaults(**{dest: default})
    return sub
