"""Shared fixtures: one headless GL context of each kind for the whole test session."""

import pytest

from renderer.context import make_context

CONTEXT_KINDS = ("egl", "osmesa")


@pytest.fixture(scope="session")
def gl_contexts():
    """{"egl": ctx, "osmesa": ctx}. Both must start: CI installs both (install.sh)."""
    contexts = {kind: make_context(kind) for kind in CONTEXT_KINDS}
    yield contexts
    for ctx in contexts.values():
        ctx.release()
