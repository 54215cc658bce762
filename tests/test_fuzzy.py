"""The fuzzy weather classifier: published rows, engine parity, contracts, files and tuning."""


import numpy as np
import pandas as pd
import pytest

from hybridtrack import HybridtrackError
from hybridtrack.fuzzy import FuzzyConfig, FuzzyWeatherClassifier, Rule, Term, Variable, tune
from hybridtrack.fuzzy.config import PUBLISHED_RULES
from hybridtrack.testing import rule_peak_cases

PUBLISHED = [((246.0, 27.0), "sunny"), ((200.1, 84.6), "cloudy"), ((200.1, 93.6), "cloudy"),
             ((143.4, 45.0), "overcast")]


@pytest.fixture(scope="module")
def clf():
    return FuzzyWeatherClassifier()


def bounded_config(**changes):
    """Triangular/trapezoidal inputs with gaps (no rule fires there) and overlapping outputs."""
    inputs = (
        Variable("intensity", (0, 10), (Term("weak", "trimf", (0, 0, 4)), Term("medium", "trapmf", (3, 4.5, 5.5, 7)),
                                        Term("strong", "trimf", (6, 10, 10))), (30, 300), "mA"),
        Variable("variation", (0, 10), (Term("small", "trimf", (0, 0, 4)),
                                        Term("large", "gauss2mf", (7, 1.0, 10, 1.0))), (0, 180), "mA"),
    )
    output = Variable("weather", (0, 30), (Term("overcast", "gaussmf", (5, 3)), Term("cloudy", "trapmf", (8, 12, 18, 22)),
                                           Term("sunny", "trimf", (18, 25, 30))))
    return FuzzyConfig(inputs=inputs, output=output, resolution=(501, 601), name="bounded", **changes)


@pytest.mark.parametrize("engine", ["fast", "skfuzzy", "skfuzzy-scalar"])
def test_published_readings_from_every_engine(clf, engine):
    for (intensity, variation), weather in PUBLISHED:
        assert clf.classify(intensity, variation, engine=engine) == weather


def test_normalisation_is_the_published_linear_map(clf):
    x = clf.normalise(np.array([30.0, 165.0, 300.0, 400.0, 0.0]), np.array([0.0, 90.0, 180.0, 200.0, -5.0]))
    np.testing.assert_allclose(x, [[0, 0], [5, 5], [10, 10], [10, 10], [0, 0]])


def test_fast_engine_matches_scikit_fuzzy_on_10000_random_readings(clf):
    rng = np.random.default_rng(20261121)
    raw = rng.uniform([20.0, -10.0], [320.0, 190.0], size=(10_000, 2))  # a little outside the ranges too
    fast = clf.score(raw[:, 0], raw[:, 1])
    reference = clf.score(raw[:, 0], raw[:, 1], engine="skfuzzy")
    np.testing.assert_allclose(fast, reference, atol=1e-6, rtol=0)
    assert (clf.label(fast) == clf.label(reference)).all()
    assert not np.isnan(fast).any()  # Gaussian terms: some rule always fires


def test_parity_holds_with_overlapping_outputs_and_empty_cells():
    clf = FuzzyWeatherClassifier(bounded_config())
    assert len(clf._system.shared_cells) > 0  # the dense path is exercised
    rng = np.random.default_rng(7)
    raw = rng.uniform([30.0, 0.0], [300.0, 180.0], size=(3000, 2))
    fast = clf.score(raw[:, 0], raw[:, 1])
    reference = clf.score(raw[:, 0], raw[:, 1], engine="skfuzzy")
    assert np.isnan(fast).sum() > 100  # readings where no rule fires
    np.testing.assert_array_equal(np.isnan(fast), np.isnan(reference))
    np.testing.assert_allclose(fast, reference, atol=1e-6, rtol=0)
    scalar = clf.score(raw[:40, 0], raw[:40, 1], engine="skfuzzy-scalar")
    np.testing.assert_allclose(scalar, fast[:40], atol=1e-6)
    labels = clf.label(fast)
    assert (labels[np.isnan(fast)] == "unknown").all()


def test_no_rule_firing_gives_nan_and_unknown_from_both_engines():
    clf = FuzzyWeatherClassifier(bounded_config())
    # intensity 1 is only "weak", variation 6 is past "small" (ends at 4): no rule can fire
    reading = (30 + 27 * 1.0, 18 * 6.0)
    for engine in ("fast", "skfuzzy", "skfuzzy-scalar"):
        assert np.isnan(clf.score(*reading, engine=engine))
        assert clf.classify(*reading, engine=engine) == "unknown"


def test_nan_inputs_are_unknown_without_raising(clf):
    labels = clf.classify(np.array([np.nan, 246.0, 200.0]), np.array([10.0, 27.0, np.nan]))
    assert list(labels) == ["unknown", "sunny", "unknown"]
    assert clf.classify(np.nan, 3.0, engine="skfuzzy") == "unknown"


def test_shapes_follow_the_inputs(clf):
    assert isinstance(clf.score(246.0, 27.0), float)
    assert isinstance(clf.classify(246.0, 27.0), str)
    index = pd.date_range("2021-06-21 12:00", periods=3, freq="1min", tz="Asia/Shanghai")
    series = clf.score(pd.Series([246.0, 200.1, 143.4], index=index), pd.Series([27.0, 84.6, 45.0], index=index))
    assert series.index.equals(index) and series.name == "sky_score"
    labels = clf.label(series)
    assert list(labels) == ["sunny", "cloudy", "overcast"] and labels.index.equals(index)
    grid = clf.score(np.full((2, 3), 246.0), 27.0)
    assert grid.shape == (2, 3)


def test_raw_false_takes_normalised_inputs(clf):
    assert clf.score(8.0, 1.5, raw=False) == pytest.approx(clf.score(246.0, 27.0))


def test_band_edges_are_half_open(clf):
    assert list(clf.label(np.array([0.0, 9.999, 10.0, 19.999, 20.0, 30.0]))) == [
        "overcast", "overcast", "cloudy", "cloudy", "sunny", "sunny"]


def test_label_codes_index_the_band_names_with_unknown_for_nan(clf):
    codes, names = clf.label_codes(np.array([np.nan, 0.0, 10.0, 20.0]))
    assert names == ("overcast", "cloudy", "sunny", "unknown")
    assert codes.tolist() == [3, 0, 1, 2]


def test_explain_shows_memberships_and_firings(clf):
    explanation = clf.explain(200.1, 84.6)
    assert explanation.weather == "cloudy"
    assert explanation.memberships["intensity"]["medium"] == pytest.approx(np.exp(-(6.3 - 5) ** 2 / 4.5), abs=1e-4)
    firing = {rule["then"] + str(rule["rule"]): rule["firing"] for rule in explanation.rules}
    assert firing["cloudy3"] > 2 * firing["sunny1"]  # cloudy wins by its own rule, not by a tie
    data = explanation.to_dict()
    assert set(data) >= {"score", "weather", "rules"} and len(data["rules"]) == 4
    assert "fires" in str(explanation)


@pytest.mark.parametrize("case", rule_peak_cases(FuzzyConfig.default()))
def test_each_rules_term_peaks_give_its_label(case):
    case.check()


@pytest.mark.parametrize("case", rule_peak_cases(FuzzyConfig.complete()))
def test_each_complete_rules_term_peaks_give_its_label(case):
    case.check(FuzzyWeatherClassifier(FuzzyConfig.complete()))


# --- config validation and files ----------------------------------------------------------------


@pytest.mark.parametrize("make, message", [
    (lambda: FuzzyConfig(rules=()), "the rule table is empty"),
    (lambda: FuzzyConfig(rules=(Rule({"intensity": "blinding", "variation": "small"}, "sunny"),)),
     "rules\\[1\\]: unknown term 'blinding' for intensity"),
    (lambda: FuzzyConfig(rules=(Rule({"brightness": "strong"}, "sunny"),)), "unknown input 'brightness'"),
    (lambda: FuzzyConfig(rules=(Rule({"intensity": "strong"}, "stormy"),)), "unknown output term 'stormy'"),
    (lambda: FuzzyConfig().with_params("intensity", "weak", (0.0, -1.0)), "sigma must be positive"),
    (lambda: FuzzyConfig().with_params("weather", "cloudy", (20.0, 15.0, 10.0)), "must be in order"),
    (lambda: FuzzyConfig().with_params("intensity", "weak", (0.0, 1.0, 2.0)), "takes 2 parameters"),
    (lambda: FuzzyConfig(bands=(("overcast", 0, 10), ("cloudy", 12, 20), ("sunny", 20, 30))), "must meet"),
    (lambda: FuzzyConfig(bands=(("overcast", 0, 10), ("cloudy", 10, 20))), "must cover"),
    (lambda: FuzzyConfig(rules=PUBLISHED_RULES + PUBLISHED_RULES[:1]), "same conditions"),
    (lambda: FuzzyConfig().with_params("intensity", "medium", (0.0, 1.5)), "'weak' and 'medium' overlap completely"),
])
def test_invalid_configs_are_refused(make, message):
    with pytest.raises(HybridtrackError, match=message):
        make()


@pytest.mark.parametrize("config", [FuzzyConfig.default(), FuzzyConfig.complete(), bounded_config()],
                         ids=["published", "complete", "bounded"])
def test_toml_and_fis_round_trip(tmp_path, config):
    assert FuzzyConfig.from_toml(config.to_toml(tmp_path / "c.toml")) == config
    back = FuzzyConfig.from_fis(config.to_fis(tmp_path / "c.fis"), resolution=config.resolution)
    assert back.inputs == config.inputs and back.output == config.output and back.rules == config.rules


def test_shipped_complete_config_is_the_six_rule_table():
    shipped = FuzzyConfig.from_toml("data/fuzzy-complete.toml")
    assert shipped == FuzzyConfig.complete() and len(shipped.rules) == 6


MATLAB_FIS = """% exported from MATLAB R2021a
[System]
Name='weather'
Type='mamdani'
Version=2.0
NumInputs=2
NumOutputs=1
NumRules=4
AndMethod='min'
OrMethod='max'
ImpMethod='min'
AggMethod='max'
DefuzzMethod='centroid'

[Input1]
Name='light'
Range=[0 10]
NumMFs=3
MF1='weak':'gaussmf',[1.5 0]
MF2='medium':'gaussmf',[1.5 5]
MF3='strong':'gaussmf',[1.5 10]

[Input2]
Name='change'
Range=[0 10]
NumMFs=2
MF1='small':'gaussmf',[2.5 0]
MF2='large':'gauss2mf',[2.5 10 1 12]

[Output1]
Name='weather'
Range=[0 30]
NumMFs=3
MF1='overcast':'trimf',[0 5 10]
MF2='cloudy':'trimf',[10 15 20]
MF3='sunny':'trapmf',[20 24 26 30]

[Rules]
3 1, 3 (1) : 1
3 2, 2 (1) : 1
2 2, 2 (1) : 1
1 0, 1 (1) : 1
"""


def test_reads_a_matlab_fis_with_sigma_first_and_dont_care(tmp_path):
    path = tmp_path / "weather.fis"
    path.write_text(MATLAB_FIS)
    config = FuzzyConfig.from_fis(path)
    assert config.input_names == ("light", "change")
    assert config.variable("light").term("medium").params == (5.0, 1.5)  # mean first here
    assert config.variable("change").term("large").params == (10.0, 2.5, 12.0, 1.0)
    assert config.rules[3].conditions == {"light": "weak"}  # index 0: input does not matter
    assert [b[1:] for b in config.bands] == [(0.0, 10.0), (10.0, 20.0), (20.0, 30.0)]
    assert FuzzyWeatherClassifier(config).classify(246.0, 27.0) == "sunny"


@pytest.mark.parametrize("edit, message", [
    (("Type='mamdani'", "Type='sugeno'"), ":4: only Mamdani"),
    (("DefuzzMethod='centroid'", "DefuzzMethod='wtaver'"), ":13: DefuzzMethod 'wtaver' belongs to Sugeno"),
    (("'gaussmf',[1.5 5]", "'linsmf',[1 5]"), ":20: membership type 'linsmf' is not supported"),
    (("3 1, 3 (1) : 1", "3 1, 3 (1) : 3"), ":39: the connection must be 1 \\(AND\\) or 2 \\(OR\\)"),
    (("3 2, 2 (1) : 1", "3 2, 2 (1.5) : 1"), ":40: the rule weight must be one number between 0 and 1"),
    (("2 2, 2 (1) : 1", "2 7, 2 (1) : 1"), ":41: change has no term 7"),
    (("MF1='small':'gaussmf',[2.5 0]", "MF1='small':'gaussmf',[-2.5 0]"), "sigma must be positive"),
])
def test_bad_fis_files_name_the_line(tmp_path, edit, message):
    path = tmp_path / "bad.fis"
    path.write_text(MATLAB_FIS.replace(*edit))
    with pytest.raises(HybridtrackError, match=message):
        FuzzyConfig.from_fis(path)


@pytest.mark.parametrize("text, message", [
    ("name = 3\n", "name must be a string"),
    ("colour = 'blue'\n", "unknown key 'colour'"),
    ("[inputs.intensity]\nraw_range = [300, 30]\nterms.weak = {shape='gaussmf', params=[0, 1]}\n"
     "[inputs.variation]\nraw_range = [0, 180]\nterms.small = {shape='gaussmf', params=[0, 1]}\n",
     "raw_range must be two finite numbers \\[low, high\\]"),
    ("[[rules]]\nintensity = 'strong'\nvariation = 'small'\n", "rules\\[1\\]: says nothing of the output"),
    ("[[rules]]\nintensity = 'strong'\nweather = 3\n", "rules\\[1\\].weather: must be a term name"),
    ("[resolution]\ninput = 'fine'\n", "resolution.input: must be a whole number"),
    ("[bands]\nsunny = [20, 'x']\n", "bands.sunny: must be a number"),
    ("name = \n", "not valid TOML"),
])
def test_bad_toml_configs_name_the_key(tmp_path, text, message):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(HybridtrackError, match=message):
        FuzzyConfig.from_toml(path)


# --- tuning ---------------------------------------------------------------------------------


def target_table(n=25, seed=3):
    true = (FuzzyConfig().with_params("intensity", "medium", (4.0, 2.0))
            .with_params("intensity", "strong", (9.0, 1.2)).with_params("variation", "large", (8.0, 2.0)))
    raw = np.random.default_rng(seed).uniform([30, 0], [300, 180], size=(n, 2))
    clf = FuzzyWeatherClassifier(true)
    scores = clf.score(raw[:, 0], raw[:, 1])
    return pd.DataFrame({"intensity": raw[:, 0], "variation": raw[:, 1], "score": scores,
                         "weather": clf.label(scores)})


def test_one_seed_of_tuning_fits_a_table_of_target_scores_well():
    """One seed of the default search: at least three times closer than the published set, its
    terms in order (a local optimum near RMSE 0.31 is where seed 0 stops on an AVX-512 machine;
    the close fit from three seeds is `test_tuning_fits_a_table_of_target_scores_closely`, slow)."""
    table = target_table()[["intensity", "variation", "score"]]
    tuned, report = tune(None, table)
    assert report.rmse_before > 1.0 and report.rmse_after < report.rmse_before / 3
    centres = [t.centre for t in tuned.variable("intensity").terms]
    assert centres == sorted(centres)


@pytest.mark.slow  # 85 s: three seeds of the default search
def test_tuning_fits_a_table_of_target_scores_closely():
    """A close fit from three seeds of the default search, the best kept. One seed's 60
    generations of 8 can stop in a local optimum near RMSE 0.31: seeds 0 and 1 did on an AVX-512
    machine (2026-11-29, where numpy's exponentials round otherwise and the search takes another
    path; 120 generations from seed 0 too), where seed 2 reached 0.04 and seed 0 had passed
    elsewhere; the tuner had returned the first seed's fit whatever the others found."""
    table = target_table()[["intensity", "variation", "score"]]
    tuned, report = tune(None, table, seeds=3)
    assert report.seed in (0, 1, 2) and set(report.seeds) == {0, 1, 2}
    assert report.rmse_before > 1.0
    assert report.rmse_after < 0.25 and report.rmse_after < report.rmse_before / 5
    clf = FuzzyWeatherClassifier(tuned)
    np.testing.assert_allclose(clf.score(table.intensity, table.variation), table.score, atol=1.0)
    centres = [t.centre for t in tuned.variable("intensity").terms]
    assert centres == sorted(centres)  # terms stay ordered
    assert tuned.name == "published-tuned"


def test_tuning_to_labels_reaches_full_accuracy_and_is_reproducible():
    table = target_table(40, seed=5)[["intensity", "variation", "weather"]]
    # the hidden truth dips 0.56 score units as intensity rises, which tuning may not copy, so the
    # local search alone gets stuck at 95 %; the population search finds a sound fit of every label
    first, report = tune(None, table, maxiter=30, popsize=6)
    assert report.accuracy_after == 1.0 and report.accuracy_before < 1.0
    second, _ = tune(None, table, maxiter=30, popsize=6)
    assert first == second


@pytest.mark.parametrize("table, message", [
    (pd.DataFrame({"intensity": [1.0], "variation": [2.0]}), "needs a 'weather' or a 'score'"),
    (pd.DataFrame({"intensity": [1.0], "weather": ["sunny"]}), "missing column 'variation'"),
    (pd.DataFrame({"intensity": ["bright"], "variation": [2.0], "weather": ["sunny"]}),
     "row 2, column 'intensity': 'bright' is not a number"),
    (pd.DataFrame({"intensity": [100.0], "variation": [2.0], "weather": ["stormy"]}), "unknown weather label 'stormy'"),
])
def test_bad_tuning_tables_are_refused(table, message):
    with pytest.raises(HybridtrackError, match=message):
        tune(None, table, method="local")


@pytest.mark.parametrize("options, message", [
    ({"seeds": "3"}, r"seeds must be a whole number within \[1, 20\], got '3'"),  # TypeError: '<=' not supported
    ({"seeds": 2.0}, r"seeds must be a whole number within \[1, 20\], got 2.0"),  # TypeError in range()
    ({"folds": 2.5}, r"folds must be 0 \(none\) or between 2 .* got 2.5"),  # TypeError in range()
    ({"maxiter": 0}, r"maxiter must be a whole number within \[1, 100,000\], got 0"),  # a fit of no iterations
    ({"popsize": -1}, r"popsize must be a whole number within \[1, 1,000\], got -1"),  # had been accepted
    ({"restarts": float("nan")}, r"restarts must be a whole number within \[0, 1,000\], got nan"),
    ({"seed": -1}, r"seed must be a whole number within \[0, 4,294,967,276\], got -1"),  # numpy's ValueError
    ({"seed": 2**40}, r"seed must be a whole number within \[0, 4,294,967,276\]"),  # scipy's: below 2\*\*32
])
def test_tunings_counts_and_seed_are_refused_in_one_message(options, message):
    table = target_table(12)[["intensity", "variation", "weather"]]
    with pytest.raises(HybridtrackError, match=message):
        tune(None, table, method="local", **options)


def test_an_unlabelled_sample_is_named_by_the_files_own_row(tmp_path):
    from hybridtrack.fuzzy.tuning import read_samples

    path = tmp_path / "labels.csv"
    path.write_text("# labelled by hand\nintensity,variation,weather\n246,27,sunny\n\n200,80,\n")
    with pytest.raises(HybridtrackError, match=r"labels.csv: row 5, column 'weather': empty"):
        read_samples(path)


@pytest.mark.parametrize("intensity, variation, message", [
    ("246", 27.0, "intensity must be numbers"),  # text had been read as 246 mA: sunny
    (np.inf, 27.0, "intensity must be finite"),  # inf mA had been the brightest sun: sunny
    (True, 3.0, "intensity must be numbers"),  # True had been 1 mA: overcast
    (pd.Series([246.0], index=[1]), pd.Series([27.0], index=[2]), "Series on different indexes"),
])
def test_the_classifier_refuses_readings_that_are_no_readings(intensity, variation, message):
    with pytest.raises(HybridtrackError, match=message):
        FuzzyWeatherClassifier().classify(intensity, variation)


def test_the_classifier_reads_pythons_and_numpys_numbers_and_none_as_no_reading():
    clf = FuzzyWeatherClassifier()
    assert clf.classify(np.float32(246.0), np.int64(27)) == clf.classify(246, 27) == "sunny"  # the published case
    assert list(clf.classify([246.0, None], [27.0, 3.0])) == ["sunny", "unknown"]


def test_a_negative_reading_from_the_api_is_clipped_as_a_run_survives_it():
    """A recorded photocurrent below zero (a logger's offset) reaches the classifier from a run's
    log: the API clips it onto the range, as the controller's sky watch does, so a run does not
    fail at its end; the command line refuses a negative reading typed or in a file."""
    clf = FuzzyWeatherClassifier()
    assert clf.score(-500.0, 20.0) == clf.score(0.0, 20.0)
    assert clf.classify(-1.0, 0.0, raw=False) == clf.classify(0.0, 0.0, raw=False)
