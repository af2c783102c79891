"""The ``softgym`` parser and entry point: global flags, one help format, one error line."""

from __future__ import annotations

import argparse
import logging
import sys

from softgym.exceptions import SoftGymError
from softgym.io import check_path_depth
from softgym_cli.commands import add_tool_parsers, kernel_line
from softgym_cli.flags import (
    HelpFormatter,
    global_flags,
    installed_version,
    plain,
    subcommands,
    with_checkout_hint,
)
from softgym_cli.runs import add_evolve_parser, add_poet_parser, add_qd_parser, explicit_flags
from softgym_cli.study import add_study_parser

__all__ = ["main"]


class _VersionAction(argparse.Action):
    """``--version``: the installed version and the kernel build in use (imported only then)."""

    def __init__(self, option_strings: list[str], dest: str = argparse.SUPPRESS,
                 default: str = argparse.SUPPRESS, help: str | None = None) -> None:  # fmt: skip
        super().__init__(option_strings, dest=dest, default=default, nargs=0, help=help)

    def __call__(self, parser, namespace, values, option_string=None):  # noqa: D102
        print(f"softgym {installed_version()}")
        try:
            print(kernel_line())
        except SoftGymError as exc:  # e.g. a SOFTGYM_KERNEL this machine cannot run
            print(f"kernel: {' '.join(str(exc).split())}")
        parser.exit()


def _parser() -> tuple[argparse.ArgumentParser, argparse.ArgumentParser]:
    """The ``softgym`` parser and its ``evolve`` subparser."""
    import softgym_cli

    parser = argparse.ArgumentParser(
        prog="softgym", description=plain(softgym_cli.__doc__.split("\n")[0]),
        formatter_class=HelpFormatter,
    )  # fmt: skip
    parser.add_argument("--version", action=_VersionAction,
                        help="the installed version, the kernel build in use and OpenMP "
                        "(softgym info: every detail)")  # fmt: skip
    global_flags(parser, None)
    parser.add_argument(
        "--debug", action="store_true", help="show the traceback of an error (before the command)"
    )
    sub = subcommands(parser, "command")
    add_tool_parsers(sub)
    evolve = add_evolve_parser(sub)
    add_study_parser(sub)
    add_qd_parser(sub)
    add_poet_parser(sub)
    return parser, evolve


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``softgym`` command.

    A :class:`~softgym.exceptions.SoftGymError` or :class:`OSError` from a
    subcommand prints one line, ``softgym <command>: <message>``, to stderr and
    returns 2; ``softgym --debug <command> ...`` raises it instead (traceback).
    """
    parser, evolve_parser = _parser()
    argv = sys.argv[1:] if argv is None else list(argv)
    args = parser.parse_args(argv)
    if args.command == "evolve":
        args.explicit = explicit_flags(evolve_parser, argv)
    level = (logging.WARNING, logging.INFO, logging.DEBUG)[min(args.verbose, 2)]
    logging.basicConfig(level=level, format="%(message)s")
    for name in ("softgym", "evolvers"):
        logging.getLogger(name).setLevel(level)
    try:
        for dest in ("out", "compare_out", "report_out", "export_out"):  # every path written
            if isinstance(getattr(args, dest, None), str):
                check_path_depth(getattr(args, dest), "--out")
        return int(args.func(args))
    except (SoftGymError, OSError) as exc:  # bad input or a file problem: one line, exit 2
        if args.debug:
            raise
        message = with_checkout_hint(" ".join(str(exc).split()) or type(exc).__name__)
        print(f"softgym {args.command}: {message}", file=sys.stderr)
        return 2
