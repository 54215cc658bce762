"""The rule-table plugin and helper, run the way a user runs them."""

import subprocess
import sys
from pathlib import Path

import pytest

from hybridtrack import HybridtrackError
from hybridtrack.fuzzy import FuzzyWeatherClassifier
from hybridtrack.testing import RuleCaseFailure, load_cases, rule_table_cases

ROOT = Path(__file__).resolve().parents[1]


def run_pytest(folder, *args):
    return subprocess.run([sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-v", *args, str(folder)],
                          capture_output=True, text=True, cwd=folder)


def test_the_example_rule_tables_pass_and_have_readable_ids():
    result = run_pytest(ROOT / "examples" / "rule_tables")
    assert result.returncode == 0, result.stdout + result.stderr
    assert "test_site.rules.csv::line4-280mA-10mA-sunny PASSED" in result.stdout
    assert "test_commissioning_readings[line4-143.4mA-45mA-overcast] PASSED" in result.stdout
    assert "8 passed" in result.stdout


def test_a_failing_row_shows_memberships_and_firings(tmp_path):
    (tmp_path / "test_wrong.rules.csv").write_text("intensity,variation,weather\n246.0,27.0,overcast\n")
    result = run_pytest(tmp_path)
    assert result.returncode == 1
    out = result.stdout
    assert "expected overcast, got sunny for intensity 246 mA, variation 27 mA" in out
    # by hand: 246 mA is (246 - 30)/27 = 8.0 on the universe; weak exp(-64/4.5) = 7e-7, medium
    # exp(-9/4.5) = 0.1353, strong exp(-4/4.5) = 0.4111; 27 mA is 1.5, small exp(-2.25/12.5) = 0.835
    assert "intensity: weak 0.000, medium 0.135, strong 0.411" in out
    assert "rule 1: intensity is strong AND variation is small -> sunny  fires 0.411" in out


def test_a_broken_rule_table_is_a_collection_error_that_says_where(tmp_path):
    (tmp_path / "test_broken.rules.csv").write_text("intensity,variation,weather\nbright,27.0,sunny\n")
    result = run_pytest(tmp_path)
    assert result.returncode != 0
    assert "test_broken.rules.csv:2: column 'intensity': 'bright' is not a number" in result.stdout


def test_toml_cases_read_config_and_scores():
    cases = load_cases(ROOT / "tests" / "test_complete.rules.toml")
    assert cases[0].config_path.endswith("data/fuzzy-complete.toml")
    assert [c.weather for c in cases] == ["sunny", "cloudy", "cloudy", "cloudy", "overcast"]
    assert cases[3].score == 15.0 and cases[3].tolerance == 0.01


def test_check_raises_a_rule_case_failure_with_the_explanation():
    case = rule_table_cases(ROOT / "examples" / "rule_tables" / "commissioning.csv")[0].values[0]
    case.check()
    wrong = type(case)(case.intensity, case.variation, "cloudy", score=20.0, tolerance=0.1)
    # the score the message gives is scikit-fuzzy's for the published sunny reading (246 mA, 27 mA)
    score = FuzzyWeatherClassifier().score(246.0, 27.0, engine="skfuzzy")
    assert (case.intensity, case.variation) == (246.0, 27.0)
    expected = rf"expected cloudy, got sunny; expected score 20 ± 0.1, got {score:.4f}"
    with pytest.raises(RuleCaseFailure, match=expected):
        wrong.check()


def test_missing_rule_table_is_a_clear_error(tmp_path):
    with pytest.raises(HybridtrackError, match="no such file"):
        load_cases(tmp_path / "nope.csv")


def test_a_failure_cites_the_file_line_and_the_config(tmp_path):
    table = tmp_path / "test_lines.rules.csv"
    table.write_text("# two comment lines\n# config: ../cfg.toml\nintensity,variation,weather\n"
                     "246.0,27.0,sunny\n246.0,27.0,overcast\n")
    (tmp_path.parent / "cfg.toml").write_text('name = "mine"\n')
    result = run_pytest(tmp_path)
    assert result.returncode == 1
    assert "test_lines.rules.csv:5: expected overcast, got sunny" in result.stdout
    assert f"config: {(tmp_path.parent / 'cfg.toml').resolve()}" in result.stdout
    assert "test_lines.rules.csv::line5-246mA-27mA-overcast FAILED" in result.stdout


@pytest.mark.parametrize("row, message", [
    ("246.0,27.0,sunnny", "t.csv:3: unknown weather label 'sunnny'; the config's labels are overcast, cloudy, sunny"),
    ("350.0,27.0,sunny", "t.csv:3: intensity 350 mA is outside the config's range 30-300 mA"),
    ("246.0,-1,sunny", "t.csv:3: variation -1 mA is outside the config's range 0-180 mA"),
    ("246.0,inf,sunny", "t.csv:3: column 'variation': inf is not a finite number"),
])
def test_bad_rows_are_errors_naming_file_and_line(tmp_path, row, message):
    table = tmp_path / "t.csv"
    table.write_text(f"intensity,variation,weather\n100,5,overcast\n{row}\n")
    with pytest.raises(HybridtrackError, match=message.replace("(", r"\(").replace(")", r"\)")):
        load_cases(table)


def test_toml_cases_carry_their_table_line():
    cases = load_cases(ROOT / "tests" / "test_complete.rules.toml")
    text = (ROOT / "tests" / "test_complete.rules.toml").read_text().splitlines()
    assert all(text[case.line - 1].startswith("[[case]]") for case in cases)


def test_a_toml_case_naming_a_column_twice_is_refused(tmp_path):
    # names are read lowered: 'Weather' and 'weather' would be two keys pandas keeps side by side
    table = tmp_path / "cases.toml"
    table.write_text('[[case]]\nintensity = 250\nvariation = 10\nweather = "sunny"\nWeather = "cloudy"\n')
    with pytest.raises(HybridtrackError, match="case 1: column 'weather' appears more than once"):
        load_cases(table)
