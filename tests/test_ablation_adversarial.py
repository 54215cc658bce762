"""An ablation's plan and command line against a user's slips: refused in one line before any run."""

import pytest

from hybridtrack.ablation import AblationPlan
from hybridtrack.errors import HybridtrackError

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


@pytest.mark.parametrize("field, value", [("sites", "lanzhou"), ("policies", "hybrid"), ("weather", "sunny")])
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
