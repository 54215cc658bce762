"""Fixtures more than one test module uses."""

import pvlib
import pytest
from hypothesis import settings

# No property test is timed (the suite has no timed test): Hypothesis's default 200 ms deadline
# failed a property's first example on a cold call (the fuzzy engine built, a cache loaded) when
# its module ran alone on a busy machine.
settings.register_profile("untimed", deadline=None)
settings.load_profile("untimed")


@pytest.fixture
def spa_calls(monkeypatch):
    """A list that grows by one at every call of pvlib's SPA (which still answers)."""
    calls = []
    original = pvlib.solarposition.spa_python
    monkeypatch.setattr(pvlib.solarposition, "spa_python", lambda *a, **k: calls.append(1) or original(*a, **k))
    return calls


#: Tests that run the compiled controller kernel: every test of these modules, and any test
#: parametrised with ``engine="compiled"`` or named here.
_KERNEL_MODULES = ("test_kernel.py",)
_KERNEL_TESTS = ("test_the_carried_clock_watch_runs_the_same_on_both_engines",)


def pytest_collection_modifyitems(config, items):
    """Put the tests that run the compiled kernel on one worker (pytest-xdist's ``loadgroup``):
    on a fresh clone the first of them compiles it (about two minutes); on one worker that is
    done once, while the other workers run the rest, instead of once on every worker."""
    for item in items:
        params = getattr(getattr(item, "callspec", None), "params", {})
        if (item.path.name in _KERNEL_MODULES or params.get("engine") == "compiled"
                or getattr(item, "originalname", item.name) in _KERNEL_TESTS):
            item.add_marker(pytest.mark.xdist_group("kernel"))
