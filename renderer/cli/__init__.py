"""The command line: `renderer render | view | compare | shaders | report | batch | scenes |
extremes | colour` (also `python -m renderer`).

A user's mistake (bad scene, bad output name, no GL) is one line on stderr and exit status
2, with nothing written; an option argparse refuses is its reason on one line and the
command's usage on the next, also status 2; a write the system refuses (read-only, disk full,
I/O error: errors.SystemFault) is one line and status 1, with nothing written either; a bug
keeps its traceback. Ctrl-C is one line, "renderer: interrupted" (batch says how many items
are done), and status 130 (errors.INTERRUPTED), with nothing half-written; the viewer takes
it as Esc. `compare` exits 1 when the images fail the pipeline tolerance.

Every command writes its files through one transaction (renderer/core/imageio.py, `outputs`):
its output names are checked before any work, and its files are renamed into place together.

Each command is a module here with its parser (`add_parser`) and its checks and work (`run`);
what several share is in options.py. This module assembles the parser and runs a command.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sys

from renderer import __version__
from renderer.cli import batch, colour, compare, extremes, render, report, scenes, shaders, view
from renderer.cli.options import Parser
from renderer.errors import INTERRUPTED, UsageError, UserError, escaped

# The commands in the order `renderer --help` lists them.
COMMANDS = {"render": render, "view": view, "compare": compare, "shaders": shaders, "report": report,
            "batch": batch, "scenes": scenes, "extremes": extremes, "colour": colour}


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(prog="renderer", description="A GLSL renderer checked against a NumPy reference.")
    parser.add_argument("--version", action="version", version=f"renderer {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    for command in COMMANDS.values():
        command.add_parser(sub)
    for subparser in sub.choices.values():       # for the commands' own checks of their options
        subparser.set_defaults(parser=subparser)
    return parser


# Options that name a file or folder to write (or, --cache, to read and write): each goes
# through renderer.core.paths.checked_path before the command starts. Scene arguments and
# mesh files are checked where they are read (resolve_scene, load_scene, load_mesh).
PATH_OPTIONS = ("output", "depth", "alpha", "out", "screenshot", "stats", "cache")


def _check_paths(args) -> None:
    from renderer.core.paths import checked_path
    for name in PATH_OPTIONS:
        if getattr(args, name, None) is not None:
            setattr(args, name, checked_path(getattr(args, name)))


def main(argv=None) -> int:
    try:
        try:
            args = build_parser().parse_args(argv)
        except SystemExit as done:       # --help, --version: printed; their status
            return done.code
        _check_paths(args)
        from renderer.core.memory import limit_set
        max_memory = getattr(args, "max_memory", None)       # else the limit in force stays
        with limit_set(max_memory) if max_memory is not None else contextlib.nullcontext():
            return COMMANDS[args.command].run(args)
    except UsageError as error:
        print(f"{error.prog}: {escaped(error.reason)}", file=sys.stderr)
        print(error.usage, file=sys.stderr)
        return 2
    except UserError as error:           # 2: the user's mistake; 1: a SystemFault (errors.py)
        print(f"renderer: {error.line()}", file=sys.stderr)
        return error.status
    except BrokenPipeError:              # `renderer scenes | head`: the reader left, not an error
        sys.stdout = open(os.devnull, "w")
        return 0
    except KeyboardInterrupt:            # Ctrl-C: one line (batch says its own), no traceback
        print("renderer: interrupted", file=sys.stderr)
        return INTERRUPTED
