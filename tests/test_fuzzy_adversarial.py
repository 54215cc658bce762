"""Fuzzy configs a user or a converted file could make: every one that is made round-trips
through TOML; the ones a TOML rule table would read as another are refused, naming the key."""

import dataclasses

import pytest
import tomli_w

from hybridtrack.errors import HybridtrackError
from hybridtrack.fuzzy import FuzzyConfig
from hybridtrack.fuzzy.config import Rule

DEFAULT = FuzzyConfig.default()


def _renamed_input(name: str) -> FuzzyConfig:
    """The published system with its intensity input called `name` (in its rules too)."""
    intensity, variation = DEFAULT.inputs
    rules = tuple(Rule({name if k == "intensity" else k: t for k, t in r.conditions.items()}, r.then)
                  for r in DEFAULT.rules)
    return DEFAULT.replace(inputs=(dataclasses.replace(intensity, name=name), variation), rules=rules)


def _renamed_term(name: str, *, negated: bool = False) -> FuzzyConfig:
    """The published system with the intensity term 'weak' called `name` (in its rules too)."""
    intensity, variation = DEFAULT.inputs
    terms = tuple(dataclasses.replace(t, name=name) if t.name == "weak" else t for t in intensity.terms)
    rules = tuple(Rule({k: name if t == "weak" else t for k, t in r.conditions.items()}, r.then,
                       negated=("intensity",) if negated and r.conditions["intensity"] == "weak" else ())
                  for r in DEFAULT.rules)
    return DEFAULT.replace(inputs=(dataclasses.replace(intensity, terms=terms), variation), rules=rules)


@pytest.mark.parametrize("name", ["weight", "connection"])
def test_an_input_named_like_a_rule_key_is_refused(name):
    # to_toml wrote it; from_toml read the rule's 'weight = "strong"' as its weight and refused its own file
    with pytest.raises(HybridtrackError, match=f"inputs.{name}: a variable cannot be named '{name}'"):
        _renamed_input(name)


@pytest.mark.parametrize("name", ["weight", "connection"])
def test_an_output_named_like_a_rule_key_is_refused(name):
    with pytest.raises(HybridtrackError, match=f"output.{name}: a variable cannot be named '{name}'"):
        DEFAULT.replace(output=dataclasses.replace(DEFAULT.output, name=name))


@pytest.mark.parametrize("name, negated", [("not weak", False), ("Not weak", False), (" weak", True)])
def test_an_input_term_a_rule_would_read_as_another_is_refused(name, negated):
    # 'not weak' was read back as the negation of a term 'weak'; ' weak' negated lost its blank
    with pytest.raises(HybridtrackError, match="would read as another in a rule"):
        _renamed_term(name, negated=negated)


@pytest.mark.parametrize("config", [
    _renamed_input("name"),  # a key of the file's top level, not of a rule
    _renamed_term("nothing"),  # begins with 'not', but not with 'not '
    _renamed_term("très faible ☁", negated=True),
    DEFAULT.replace(name="晴天 \"quoted\" \\ back\nslash", output=dataclasses.replace(DEFAULT.output, name="out put")),
    DEFAULT.replace(bands=(("阴", 0.0, 10.0), ("", 10.0, 20.0), ("a.b", 20.0, 30.0))),
    DEFAULT.replace(rules=tuple(dataclasses.replace(r, weight=0.1 + 0.2, connection="or") for r in DEFAULT.rules)),
    DEFAULT.replace(labelled_range=((-0.0, 300.0), (0.0, 180.0))),
], ids=["input-name", "term-nothing", "unicode-negated-term", "unicode-names", "odd-bands", "weights-or", "labelled"])
def test_a_config_made_round_trips_through_toml(config, tmp_path):
    assert FuzzyConfig.from_toml(config.to_toml(tmp_path / "fuzzy.toml")) == config


@pytest.mark.parametrize("values, named", [(["intensity=-5", "variation=50"], "input 'intensity' -5 is no reading"),
                                           (["intensity=200", "variation=-0.1"], "input 'variation' -0.1 is no reading"),
                                           (["intensity=1e308", "variation=5"], "input 'intensity' 1e+308 is no reading")])
def test_fuzzy_eval_of_a_classifier_refuses_a_reading_below_zero_as_classify_does(values, named, tmp_path, capsys):
    # -5 mA had been clipped onto the raw range and scored overcast; classify and rules refuse it
    from hybridtrack.cli import main

    source = DEFAULT.to_toml(tmp_path / "fuzzy.toml")
    assert main(["fuzzy", "eval", str(source), *values]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and named in err
    assert main(["classify", "--config", str(source), "--intensity", values[0][10:], "--variation", values[1][10:]]) == 2


#: The published checks of the classifier (docs/physics.md §4): readings (mA) and their labels.
PUBLISHED_CHECKS = ((246.0, 27.0, "sunny"), (200.1, 84.6, "cloudy"), (143.4, 45.0, "overcast"))


def test_a_config_whose_name_is_no_fcl_identifier_is_written_as_fcl_under_a_plain_name(tmp_path):
    # a tuned config is named 'published-tuned': writing it as FCL had failed, after the fit
    from hybridtrack.fuzzy import FuzzyWeatherClassifier

    path = DEFAULT.replace(name="published-tuned").to_fcl(tmp_path / "tuned.fcl")
    assert path.read_text().splitlines()[0] == "FUNCTION_BLOCK published_tuned"
    read = FuzzyWeatherClassifier(FuzzyConfig.from_fcl(path))
    assert [read.classify(i, v) for i, v, _ in PUBLISHED_CHECKS] == [label for _, _, label in PUBLISHED_CHECKS]


@pytest.mark.parametrize("name, block", [("9 lives", "_9_lives"), ("", "_"), ("晴 x", "__x")])
def test_an_fcl_block_name_starts_as_an_identifier_must(name, block, tmp_path):
    path = DEFAULT.replace(name=name).to_fcl(tmp_path / "x.fcl")
    assert path.read_text().splitlines()[0] == f"FUNCTION_BLOCK {block}"
    assert FuzzyConfig.from_fcl(path).name == block


def _labels(tmp_path):
    path = tmp_path / "labels.csv"
    path.write_text("intensity,variation,weather\n" + "".join(f"{i},{v},{w}\n" for i, v, w in PUBLISHED_CHECKS)
                    + "280,5,sunny\n60,10,overcast\n220,120,cloudy\n")
    return path


def test_tune_writes_fcl_as_fcl(tmp_path, capsys):
    # --out tuned.fcl had been written as TOML, which no reader then took
    from hybridtrack.cli import main

    out = tmp_path / "tuned.fcl"
    assert main(["tune", str(_labels(tmp_path)), "--out", str(out), "--method", "local", "--folds", "0",
                 "--seeds", "1"]) == 0
    assert out.read_text().startswith("FUNCTION_BLOCK ") and FuzzyConfig.from_fcl(out).input_names == (
        "intensity", "variation")
    assert "a .fcl file cannot keep the labelled range" in capsys.readouterr().out


@pytest.mark.parametrize("name", ["tuned.json", "tuned"])
def test_tune_refuses_an_out_of_no_fuzzy_format_before_the_fit(name, tmp_path, capsys):
    from hybridtrack.cli import main

    assert main(["tune", str(_labels(tmp_path)), "--out", str(tmp_path / name)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "unknown fuzzy system format" in err and not (tmp_path / name).exists()


def test_a_toml_file_read_as_fcl_is_refused_in_a_short_line(tmp_path):
    # the statement left unclosed had been quoted whole: the entire TOML file as one line
    path = tmp_path / "fake.fcl"
    path.write_text(tomli_w.dumps(DEFAULT.to_dict()))
    with pytest.raises(HybridtrackError, match="statement without a closing ';'") as caught:
        FuzzyConfig.from_fcl(path)
    assert len(str(caught.value)) < 200


@pytest.mark.parametrize("shape, params, x, expected", [
    # exp(-(x - m)² / 2σ²) by hand: 1 at the mean, 0 a finite distance from a mean of σ → 0, 1 for σ → ∞
    ("gaussmf", (5.0, 1e-300), [5.0, 5.1], [1.0, 0.0]),
    ("gaussmf", (5.0, 1e300), [0.0, 10.0], [1.0, 1.0]),
    ("gauss2mf", (4.0, 1e-300, 6.0, 1e300), [3.9, 5.0, 10.0], [0.0, 1.0, 1.0]),
    ("gaussmf", (5.0, 2.0), [5.0, 7.0], [1.0, 0.6065306597126334]),  # exp(-1/2)
])
def test_a_gaussian_of_any_valid_sigma_is_evaluated_without_overflow(shape, params, x, expected):
    # σ = 1e300 had raised OverflowError (σ² past float), σ = 1e-300 divided by zero: NaN at the mean
    import warnings

    import numpy as np

    from hybridtrack.fuzzy.membership import membership

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert np.allclose(membership(shape, params, np.array(x)), expected, rtol=1e-15, atol=0)


def test_a_config_of_inputs_written_variation_first_reads_them_by_name(tmp_path):
    # [inputs.variation] above [inputs.intensity] had fed the photocurrent to the variation's terms:
    # the published sunny check (246 mA, 27 mA) came out cloudy
    from hybridtrack.fuzzy import FuzzyWeatherClassifier

    data = DEFAULT.to_dict()
    data["inputs"] = {"variation": data["inputs"]["variation"], "intensity": data["inputs"]["intensity"]}
    data["labelled_range"] = {"variation": [0.0, 100.0], "intensity": [50.0, 250.0]}
    path = tmp_path / "fuzzy.toml"
    path.write_text(tomli_w.dumps(data))
    config = FuzzyConfig.from_toml(path)
    assert config.input_names == ("intensity", "variation")
    assert config.labelled_range == ((50.0, 250.0), (0.0, 100.0))
    assert FuzzyWeatherClassifier(config).classify(246.0, 27.0) == "sunny"


def test_a_config_of_inputs_given_variation_first_is_refused():
    with pytest.raises(HybridtrackError, match="inputs: intensity must come first, then variation"):
        DEFAULT.replace(inputs=DEFAULT.inputs[::-1])


@pytest.mark.parametrize("variable, term, params, named", [
    ("intensity", "weak", (100.0, 1.5), "inputs.intensity.terms.weak: gaussmf [100.0, 1.5] is 0 at every one of "
                                        "the 1,001 samples of the universe 0-10"),
    ("weather", "sunny", (40.0, 45.0, 50.0), "output.weather.terms.sunny: trimf [40.0, 45.0, 50.0] is 0 at every one "
                                              "of the 3,001 samples of the universe 0-30"),
    ("weather", "cloudy", (15.001, 15.002, 15.003), "output.weather.terms.cloudy"),  # between two samples
])
def test_a_term_that_overlaps_no_sample_of_its_universe_is_refused(variable, term, params, named):
    # a classifier of such terms had called every reading unknown without a word
    with pytest.raises(HybridtrackError) as caught:
        DEFAULT.with_params(variable, term, params)
    assert named in str(caught.value) and "no rule on it could fire" in str(caught.value)


def test_a_term_on_a_single_sample_of_its_universe_is_kept():
    # 15 is a sample of 0-30 at 3,001 samples (every 0.01)
    assert DEFAULT.with_params("weather", "cloudy", (14.999, 15.0, 15.001)).output.term("cloudy").params[1] == 15.0


@pytest.mark.parametrize("resolution", [(10**9, 3001), (1001, 10_002), (2, 3001)])
def test_a_resolution_past_the_limits_is_refused_before_any_sampling(resolution):
    # 10**9 samples had filled the memory until the system killed the command
    with pytest.raises(HybridtrackError, match="resolution needs two sample counts from 3 to 10,001"):
        DEFAULT.replace(resolution=resolution)


def test_a_run_config_given_as_a_fuzzy_config_is_named_so(tmp_path):
    # it had been refused for its first key ("unknown key 'controller'"), not for being the other kind
    from hybridtrack.simulation import SimulationConfig

    path = SimulationConfig().to_toml(tmp_path / "run.toml")
    with pytest.raises(HybridtrackError, match="run.toml: a run config .* not a fuzzy classifier config"):
        FuzzyConfig.from_toml(path)
