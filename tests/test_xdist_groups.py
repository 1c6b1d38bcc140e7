"""The xdist groups CI relies on (.ci/run: --dist loadgroup): one xdist worker runs a group's
tests, so that a group's cached work is done once (the local Ray, tests/conftest.py; each twin
frame of tests/test_pathtrace.py and tests/test_radiosity_method.py). pytest-xdist marks a
grouped test by adding "@GROUP" to its id as the worker collects it; pytest 9.2 keeps the id
where that no longer takes (pytest-dev/pytest-xdist#1386), and the groups were spread over the
workers with nothing failing, the full run minutes longer (pyproject.toml pins pytest below
9.2). This test fails when a grouped test's id lacks its group under loadgroup."""

import pytest


@pytest.mark.xdist_group("xdist_group_check")
def test_a_grouped_test_carries_its_group_under_loadgroup(request):
    if not getattr(request.config.option, "loadgroup", False):
        pytest.skip("not an xdist worker under --dist loadgroup: nothing to group")
    assert request.node.nodeid.endswith("@xdist_group_check"), request.node.nodeid
