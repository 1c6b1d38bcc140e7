"""A virtual X display (Xvfb) for running the window viewer where there is no screen: the
tests, the viewer benchmark, CI. Users with no screen can equally type `xvfb-run -a renderer
view ...`.

    with virtual_display() as display:     # ":99", say; DISPLAY is not changed
        subprocess.run([...], env={**os.environ, "DISPLAY": display})
"""

from __future__ import annotations

import contextlib
import os
import shutil
import subprocess
import tempfile

from renderer.errors import ContextError


@contextlib.contextmanager
def virtual_display(width: int = 1280, height: int = 1024, timeout: float = 20.0):
    """Start Xvfb on a free display number (Xvfb picks it: -displayfd), yield ":N", stop it."""
    if shutil.which("Xvfb") is None:
        raise ContextError("Xvfb is not installed: install the Debian package xvfb")
    read_end, write_end = os.pipe()
    log = tempfile.TemporaryFile()           # a file, not a pipe: nobody reads it while it runs
    # -noreset: by default Xvfb resets when its last client disconnects, and a window opened
    # during the reset fails to connect (a test that follows another one failed so).
    process = subprocess.Popen(
        ["Xvfb", "-displayfd", str(write_end), "-screen", "0", f"{width}x{height}x24",
         "-nolisten", "tcp", "-noreset", "+extension", "GLX"],
        pass_fds=(write_end,), stdout=subprocess.DEVNULL, stderr=log)
    os.close(write_end)
    try:
        with os.fdopen(read_end) as announced:
            # Xvfb writes the display number once it accepts connections; EOF means it died.
            number = _read_line(announced, timeout)
        if not number:
            process.kill()
            process.wait()
            log.seek(0)
            message = log.read().decode(errors="replace").strip().splitlines()
            raise ContextError(f"Xvfb did not start: {message[-1] if message else 'no reason given'}")
        yield f":{number}"
    finally:
        process.terminate()
        try:
            process.wait(5)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()
        log.close()


def _read_line(stream, timeout: float) -> str:
    import select
    ready, _, _ = select.select([stream], [], [], timeout)
    return stream.readline().strip() if ready else ""
