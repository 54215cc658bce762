"""A user's rule-table test: expected classifier behaviour kept as data in a CSV file."""

from pathlib import Path

import pytest

from hybridtrack.testing import rule_table_cases

HERE = Path(__file__).parent


@pytest.mark.parametrize("case", rule_table_cases(HERE / "commissioning.csv"))
def test_commissioning_readings(case):
    case.check()  # the published classifier; pass case.check(my_classifier) to test another
