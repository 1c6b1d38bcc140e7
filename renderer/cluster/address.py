"""`--address auto|HOST:PORT` checked in Python before Ray is asked to connect.

Why: `ray.init(address=HOST:PORT)` has no timeout. Where nobody answers (a refused port, a
name that does not resolve) it retries for minutes (over 200 s measured, ~41 s per attempt)
and prints C++ log lines on the way. A socket resolves and connects in milliseconds, so
the user's mistake is one line at once; only an address where something answers reaches
Ray (renderer/cluster/ray_executor.py then bounds Ray's own attempts).
"""

from __future__ import annotations

import socket

from renderer.errors import UserError

CONNECT_TIMEOUT_S = 3.0     # a black-holed host (packets dropped) fails after this
AUTO = "auto"               # Ray's own word: the cluster `ray start` left on this machine


def check_address(address: str, timeout: float = CONNECT_TIMEOUT_S) -> None:
    """Nothing if `address` is "auto" or a HOST:PORT where a TCP connection is accepted,
    else a UserError (key --address): malformed, host unknown, or nobody answering.
    "auto" is left to Ray, which says at once when no cluster runs here."""
    if address == AUTO:
        return
    host, port = split_address(address)
    try:
        socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)
    except (socket.gaierror, UnicodeError) as exc:
        reason = getattr(exc, "strerror", None) or type(exc).__name__
        raise UserError(f"cannot resolve the host {host!r} of {address} ({reason})",
                        key="--address") from None
    try:
        socket.create_connection((host, port), timeout=timeout).close()
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__     # socket.timeout has no strerror
        raise UserError(f"no Ray head answers at {address} ({reason})", key="--address") from None


def split_address(address: str) -> tuple[str, int]:
    """(host, port) of "HOST:PORT" ("[::1]:6379" for an IPv6 host), or a UserError."""
    host, sep, port = address.rpartition(":")
    if host.startswith("[") and host.endswith("]"):
        host = host[1:-1]
    if not sep or not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise UserError(f"{address!r} is not auto or HOST:PORT (a port from 1 to 65535)",
                        key="--address")
    return host, int(port)
