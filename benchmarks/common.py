"""What every benchmark script takes on its command line: the image size, how many frames
to time, and the GL context."""

from __future__ import annotations

import argparse

from renderer.cli import parse_size


def arguments(doc: str, count: str, default_count: int) -> argparse.Namespace:
    """--size WxH (640x480), --COUNT N (default_count) and --context egl|osmesa (egl)."""
    parser = argparse.ArgumentParser(description=doc.splitlines()[0])
    parser.add_argument("--size", type=parse_size, default=(640, 480))
    parser.add_argument(f"--{count}", type=int, default=default_count)
    parser.add_argument("--context", choices=("egl", "osmesa"), default="egl")
    return parser.parse_args()
