"""`renderer scenes`: the built-in scenes, one line each with what it shows."""

from __future__ import annotations


def add_parser(sub) -> None:
    """`scenes`' parser: no options."""
    sub.add_parser("scenes", help="list the built-in scenes")


def run(args) -> int:
    """NAME<tab>DESCRIPTION per built-in scene on stdout."""
    from renderer.core.builtin import builtin_scenes, describe
    for name in builtin_scenes():
        print(f"{name}\t{describe(name)}")
    return 0
