"""Shared fixtures: one headless GL context of each kind for the whole test session, and a
virtual X display for the window viewer."""

import pytest

from renderer.gpu.context import make_context

CONTEXT_KINDS = ("egl", "osmesa")


@pytest.fixture(scope="session")
def gl_contexts():
    """{"egl": ctx, "osmesa": ctx}. Both must start: CI installs both (install.sh)."""
    contexts = {kind: make_context(kind) for kind in CONTEXT_KINDS}
    yield contexts
    for ctx in contexts.values():
        ctx.release()


@pytest.fixture(scope="session")
def x_display():
    """A virtual X display (Xvfb) for the window viewer's tests, ":N". It must start: CI
    installs xvfb (install.sh)."""
    from renderer.viewer.virtual_display import virtual_display
    with virtual_display() as display:
        yield display


@pytest.fixture
def on_x_display(x_display, monkeypatch):
    """DISPLAY set to the virtual display for this test (glfw reads it when it starts)."""
    monkeypatch.setenv("DISPLAY", x_display)
    monkeypatch.delenv("WAYLAND_DISPLAY", raising=False)
    return x_display
