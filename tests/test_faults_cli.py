"""``hybridtrack faults`` against a user's slips: one line, status 2, and a hint where one is near."""

import pytest

from hybridtrack.cli import main
from hybridtrack.errors import HybridtrackError
from hybridtrack.faults import run_scenario


@pytest.mark.parametrize("typed, meant", [("sensor-stuk", "sensor-stuck"), ("WIND-GUST", "wind-gust"),
                                          ("encoder-glitch-brust", "encoder-glitch-burst")])
def test_a_misspelt_scenario_is_refused_with_the_nearest_name(typed, meant, capsys):
    assert main(["faults", "run", typed]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"unknown fault scenario {typed!r}; did you mean {meant!r}?" in err


def test_a_scenario_near_no_name_is_refused_with_the_list_command_only():
    with pytest.raises(HybridtrackError) as caught:
        run_scenario("zzzz")
    assert str(caught.value) == "unknown fault scenario 'zzzz'; `hybridtrack faults list` shows them"


@pytest.mark.parametrize("extra, named", [(["wind-gust"], "a scenario's name ('wind-gust') goes"),
                                          (["--site", "nanjing"], "--site goes"),
                                          (["--markdown"], "--markdown goes"),
                                          (["--site", "nanjing", "--markdown"], "--site and --markdown go")])
def test_list_refuses_what_only_run_takes(extra, named, capsys):
    # list had printed the plain list, dropping them without a word (--markdown gave no Markdown)
    assert main(["faults", "list", *extra]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"{named} with faults run, not faults list" in err


def test_the_list_sets_every_description_apart_from_its_name_in_one_column(capsys):
    from hybridtrack.faults import SCENARIOS

    assert main(["faults", "list"]) == 0
    lines = capsys.readouterr().out.splitlines()
    starts = {line.index(scenario.description) for line, scenario in zip(lines, SCENARIOS.values())}
    assert len(starts) == 1 and all(line.startswith(name + "  ") for line, name in zip(lines, SCENARIOS))
