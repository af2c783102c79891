"""What every ``softgym`` parser shares: the help format, the global flags, subcommands."""

from __future__ import annotations

import argparse
import re
from importlib.metadata import PackageNotFoundError, version
from typing import Any

__all__ = [
    "HelpFormatter",
    "extra_hint",
    "installed_version",
    "options_after",
    "plain",
    "subcommands",
]

#: ``-v`` / ``-q`` help of each command (what they do there); others get :data:`_QUIET_TOOL`.
GLOBAL_HELP: dict[str | None, tuple[str, str]] = {
    None: ("log lines (-v: info, e.g. each generation and Dask's; -vv: debug); also after "
           "the subcommand",
           "no progress bars, no line per study run; also after the subcommand"),
    "evolve": ("log lines (-v: each generation, and Dask's with --dask; -vv: debug)",
               "no progress bar"),
    "qd": ("log lines (-v: each generation, and Dask's with --dask; -vv: debug)",
           "no progress bar"),
    "poet": ("log lines (-v: each iteration, and Dask's with --dask; -vv: debug)",
             "no progress bar"),
    "study": ("log lines (-v: each run's generations, and Dask's with --workers/--dask; "
              "-vv: debug)",
              "no line per started and finished run (the summary is still printed)"),
}  # fmt: skip
_QUIET_TOOL = ("log lines (-v: info; -vv: debug)",
               "accepted for symmetry: this command draws no progress bar")  # fmt: skip


def plain(text: str) -> str:
    """``text`` without reStructuredText markup (``literal``, :role:`target`), for ``--help``."""
    text = re.sub(r":[a-z]+(?::[a-z]+)?:`~?([^`]+)`", r"\1", text)
    return text.replace("``", "")


def extra_hint(extra: str) -> str:
    """How to install a pip extra, from PyPI and in a checkout (the README's way)."""
    return f'pip install "softgym[{extra}]", or pip install -e ".[{extra}]" in a checkout'


def with_checkout_hint(message: str) -> str:
    """A message's ``pip install "softgym[X]"`` with the checkout form beside it."""
    return re.sub(r'pip install "softgym\[([a-z]+)\]"(?!, or)', lambda m: extra_hint(m[1]),
                  message)  # fmt: skip


class HelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """``--help`` shows every default as ``(default: X)``; options without one say theirs in words."""

    def _get_help_string(self, action: argparse.Action) -> str:
        shown = getattr(action, "shown_default", action.default)
        if (
            shown is None
            or shown is argparse.SUPPRESS
            or isinstance(action, argparse._StoreTrueAction)
        ):
            return action.help or ""
        if shown is not action.default:  # an option repeated after a subcommand (options_after)
            return f"{action.help or ''} (default: {shown})"
        return super()._get_help_string(action)


def installed_version() -> str:
    """The version pyproject.toml gives the installed distribution."""
    try:
        return version("softgym")
    except PackageNotFoundError:  # pragma: no cover - run from a bare source tree
        return "unknown (not installed)"


def global_flags(p: argparse.ArgumentParser, default: Any, command: str | None = None) -> None:
    """``-v`` and ``-q``, on the main parser (``default``: their defaults) and on every
    subcommand (``argparse.SUPPRESS``: typed after the subcommand, they still count), each
    with what it does in ``command``.
    """
    verbose_help, quiet_help = GLOBAL_HELP.get(command, _QUIET_TOOL)
    p.add_argument("-v", "--verbose", action="count",
                   default=0 if default is None else default, help=verbose_help)  # fmt: skip
    p.add_argument("-q", "--quiet", action="store_true",
                   default=False if default is None else default, help=quiet_help)  # fmt: skip


def options_after(parser: argparse.ArgumentParser, sub: argparse.ArgumentParser,
                  add: Any) -> None:  # fmt: skip
    """Add the options ``add(p)`` puts on ``parser`` to its subcommand ``sub`` too, so that
    ``softgym qd run --generations 1`` reads as ``softgym qd --generations 1 run``.

    On ``sub`` every option defaults to :data:`argparse.SUPPRESS` (a value typed before the
    subcommand stays; ``--help`` still shows the real default).
    """
    before = len(sub._actions)
    add(sub)
    for action in sub._actions[before:]:
        action.shown_default = action.default
        action.default = argparse.SUPPRESS


def subcommands(parser: argparse.ArgumentParser, dest: str, default: str | None = None,
                default_help: str = "run (the default)", command: str | None = None) -> Any:  # fmt: skip
    """A subparsers action whose parsers show their defaults and take the global flags;
    with ``default``, the subcommand is optional and ``default`` (e.g. ``"run"``) is one.
    ``command``: the parent command (whose ``-v`` / ``-q`` help the default one shares).
    """
    sub = parser.add_subparsers(dest=dest, required=default is None)
    add = sub.add_parser

    def add_parser(name: str, **kw: Any) -> argparse.ArgumentParser:
        p = add(name, formatter_class=HelpFormatter, allow_abbrev=False, **kw)
        global_flags(p, argparse.SUPPRESS, command if name == default else name)
        return p

    sub.add_parser = add_parser
    if default is not None:
        sub.add_parser(default, help=default_help, description=default_help).set_defaults(
            **{dest: default}
        )
    return sub
