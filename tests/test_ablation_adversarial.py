"""An ablation's plan and command line against a user's slips: refused in one line before any run."""

import pytest

from hybridtrack.ablation import AblationPlan
from hybridtrack.cli import main
from hybridtrack.errors import HybridtrackError

#: One day, one policy: a plan that would run in seconds, were it run.
SMALL = ["ablate", "--sites", "lanzhou", "--seasons", "summer", "--collectors", "trough-ns", "--seeds", "1",
         "--policies", "hybrid"]


@pytest.mark.parametrize("field, values, named", [
    ("sites", ("lanzhou", "nanjing", "lanzhou"), "'lanzhou'"),
    ("sites", ("lanzhou", "Lanzhou"), "'lanzhou'"),  # the same site however written
    ("seasons", ("summer", "summer"), "'summer'"),
    ("weather", ("sunny", "sunny"), "'sunny'"),
    ("seeds", (1, 2, 1), "1"),
    ("collectors", ("fresnel", "fresnel"), "'fresnel'"),
    ("policies", ("hybrid", "sensor", "hybrid"), "'hybrid'"),
])
def test_a_plan_naming_a_value_twice_is_refused(field, values, named):
    # each day would be run twice and counted twice in the table's means
    with pytest.raises(HybridtrackError, match=f"ablate: {field} names {named} twice"):
        AblationPlan(**{field: values})


@pytest.mark.parametrize("field, value", [("sites", "lanzhou"), ("policies", "hybrid"), ("weather", "sunny"),
                                          ("seeds", 5)])
def test_a_plan_given_a_text_for_a_list_is_refused_as_such(field, value):
    # it had been read a letter at a time: "unknown site 'l'"
    with pytest.raises(HybridtrackError, match=f"ablate: {field} must be a list"):
        AblationPlan(**{field: value})


@pytest.mark.parametrize("seed", [1.5, -1, True, 2**64, "1"])
def test_a_plan_refuses_a_seed_that_is_no_seed(seed):
    # 1.5 and True had run as seed 1, -1 and 2**64 failed only once the days had begun
    with pytest.raises(HybridtrackError, match="ablate: seed must be a whole number"):
        AblationPlan(seeds=(seed,))


def test_a_site_written_in_capitals_takes_its_own_year():
    # ablation.SITE_YEARS: Nanjing's days are those of 2013; 'Nanjing' had taken 2021's
    days = AblationPlan(sites=("Nanjing",), seasons=("summer",), seeds=(1,), collectors=("trough-ns",)).days()
    assert [(day["site"], day["date"]) for day in days] == [("nanjing", "2013-06-21")]


def test_an_unknown_site_is_refused_when_the_plan_is_made():
    with pytest.raises(HybridtrackError, match="unknown site 'mars'"):
        AblationPlan(sites=("lanzhou", "mars"))


@pytest.mark.parametrize("flags, named", [(["--deadbands", "0.2"], "--deadbands goes with --tradeoff"),
                                          (["--periods", "5min"], "--periods goes with --tradeoff"),
                                          (["--periods", "5min", "--deadbands", "0.2"],
                                           "--deadbands and --periods go with --tradeoff")])
def test_tradeoff_flags_without_tradeoff_are_refused(flags, named, capsys):
    # they had been dropped without a word: every policy ran at the config's deadband and 1 min
    assert main([*SMALL, *flags]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and named in err


@pytest.mark.parametrize("tradeoff", [[], ["--tradeoff"]])
def test_an_empty_config_path_is_refused_not_read_as_the_defaults(tradeoff, capsys):
    # --config "$CONFIG" with the variable unset had run the defaults without a word
    assert main([*SMALL, *tradeoff, "--config", ""]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--config is empty: give a file to read" in err


def test_the_help_names_the_tradeoff_defaults(capsys):
    with pytest.raises(SystemExit):
        main(["ablate", "--help"])
    help_text = " ".join(capsys.readouterr().out.split())
    assert "(default 0.1,0.2,0.4,0.8)" in help_text and "(default 1min;" in help_text


def test_a_tradeoff_plan_takes_a_built_in_sites_days_whatever_its_names_case():
    """TradeoffPlan(sites=("Nanjing",)) had taken 2021's days; Nanjing's typical days are 2013's."""
    from hybridtrack.tradeoff import TradeoffPlan

    plan = TradeoffPlan(sites=("Nanjing",), seasons=("summer",))
    assert plan.sites == ("nanjing",) and {day["date"] for day in plan.days()} == {"2013-06-21"}


@pytest.mark.parametrize("flags, message", [
    (["--sites", "atlantis"], "--sites: unknown site 'atlantis'; known sites: "),
    (["--weather", "foggy"], "--weather: unknown weather 'foggy'; choose from sunny, cloudy, overcast, mixed"),
    (["--collectors", "tower"], "--collectors: unknown collector 'tower'; choose from "),
    (["--sites", "lanzhou", "Lanzhou"], "--sites: sites names 'lanzhou' twice"),
])
def test_an_ablate_flag_naming_nothing_known_is_refused_naming_the_flag(flags, message, capsys):
    """'unknown site 'atlantis'' and 'ablate: unknown weather 'foggy'' had named no flag."""
    from hybridtrack.cli import main

    assert main(["ablate", *flags]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"hybridtrack: error: {message}") and err.count("\n") == 1


@pytest.mark.parametrize("flags, message", [
    (["--periods", "0"], "--periods: period '0' is not a step such as '1min' or '10s'"),
    (["--periods", "1min,60s"], "--periods: period '60s' is given twice (as '1min' and '60s')"),
    (["--deadbands", "-1"], "--deadbands: drive: deadband (degrees) = -1.0 is outside [0, 10]"),
    (["--deadbands", "0.1,0.4,0.10"], "--deadbands: deadband 0.1 is given twice"),
])
def test_a_tradeoff_grid_flag_is_refused_naming_the_flag(flags, message, capsys):
    """'tradeoff: period '0' is not a step' and 'drive: deadband (degrees) = -1.0' had named no flag."""
    from hybridtrack.cli import main

    assert main(["ablate", "--tradeoff", *flags]) == 2
    assert capsys.readouterr().err == f"hybridtrack: error: {message}\n"
