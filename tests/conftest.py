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


@pytest.fixture
def warned():
    """``warned(run, category)``: the messages of the warnings of `category` that ``run()`` gives."""
    import warnings

    def messages(run, category) -> list[str]:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            run()
        return [str(w.message) for w in caught if issubclass(w.category, category)]

    return messages


@pytest.fixture
def engine_choices(monkeypatch):
    """A list of the engine each run asks `uses_kernel` about (its config's ``engine``), with the
    kernel neither compiled nor cached as far as ``auto`` can tell and `COMPILE_PAYS_AT` left for
    the test to set."""
    import hybridtrack.kernel as kernel
    import hybridtrack.simulation as simulation

    engines = []
    real = simulation.uses_kernel
    monkeypatch.setattr(simulation, "uses_kernel", lambda config, scans=0: engines.append(config.engine)
                        or real(config, scans))
    monkeypatch.setattr(kernel, "compiled", lambda: False)
    monkeypatch.setattr(kernel, "cached", lambda: False)
    return engines


#: Tests that run the compiled controller kernel: every test of these modules, and any test
#: parametrised with ``engine="compiled"`` or named here.
_KERNEL_MODULES = ("test_kernel.py",)
_KERNEL_TESTS = ("test_the_carried_clock_watch_runs_the_same_on_both_engines",
                 "test_the_engine_is_chosen_on_the_fields_scans_not_each_collectors",
                 "test_a_sweeps_runs_choose_the_engine_on_the_sweeps_steps")


def pytest_collection_modifyitems(config, items):
    """Put the tests that run the compiled kernel on one worker (pytest-xdist's ``loadgroup``):
    on a fresh clone the first of them compiles it (about two minutes); on one worker that is
    done once, while the other workers run the rest, instead of once on every worker."""
    for item in items:
        params = getattr(getattr(item, "callspec", None), "params", {})
        if (item.path.name in _KERNEL_MODULES or params.get("engine") == "compiled"
                or getattr(item, "originalname", item.name) in _KERNEL_TESTS):
            item.add_marker(pytest.mark.xdist_group("kernel"))
