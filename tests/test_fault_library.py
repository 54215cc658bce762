"""The fault library: every scenario passes the shared safety check, and every detectable fault is detected."""

import pytest

from hybridtrack.cli import main
from hybridtrack.faults import SCENARIOS, run_scenario


@pytest.mark.parametrize("name", list(SCENARIOS))
def test_every_scenario_is_safe_and_detected_where_there_is_something_to_detect(name):
    outcome = run_scenario(name)
    assert outcome.safe, outcome.breaches
    if SCENARIOS[name].detected_by is not None:
        assert outcome.detected, f"{name}: no event matched {SCENARIOS[name].detected_by!r}"


def test_the_library_holds_at_least_35_scenarios_and_lists_them(capsys):
    assert len(SCENARIOS) >= 35
    assert main(["faults", "list"]) == 0
    assert len(capsys.readouterr().out.splitlines()) == len(SCENARIOS)


def test_running_a_scenario_prints_its_row_and_refuses_an_unknown_one(capsys):
    assert main(["faults", "run", "wind-gust"]) == 0
    out = capsys.readouterr().out
    assert "wind-gust" in out and "yes" in out
    assert main(["faults", "run", "no-such-fault"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "unknown fault scenario 'no-such-fault'" in err
