"""Fuzzy system files: MATLAB .fis and IEC 61131-7 FCL in full, lossless round trips, conformance, CLI."""

from pathlib import Path

import numpy as np
import pytest

from hybridtrack import HybridtrackError
from hybridtrack.cli import main
from hybridtrack.fuzzy import FuzzyConfig, FuzzyWeatherClassifier
from hybridtrack.fuzzy.config import Methods, Rule
from hybridtrack.fuzzy.engine import CompiledSystem, evaluate, evaluate_skfuzzy
from hybridtrack.fuzzy.fcl import fcl_text, read_fcl
from hybridtrack.fuzzy.fis import fis_text, read_fis_system

from test_fuzzy_engine import random_system, readings

CONFORMANCE = Path(__file__).parent / "fuzzy_conformance"

FULL_FIS = """[System]
Name='everything'
Type='mamdani'
Version=2.0
NumInputs=3
NumOutputs=2
NumRules=4
AndMethod='prod'
OrMethod='probor'
ImpMethod='prod'
AggMethod='sum'
DefuzzMethod='bisector'

[Input1]
Name='a'
Range=[0 10]
NumMFs=4
MF1='t1':'trimf',[0 0 5]
MF2='t2':'gbellmf',[2 3 5]
MF3='t3':'sigmf',[2 7]
MF4='t4':'psigmf',[3 2 -3 8]

[Input2]
Name='b'
Range=[-1 1]
NumMFs=4
MF1='u1':'dsigmf',[10 -0.5 10 0.5]
MF2='u2':'pimf',[-1 -0.5 0 0.5]
MF3='u3':'smf',[0 1]
MF4='u4':'zmf',[-1 0]

[Input3]
Name='c'
Range=[0 1]
NumMFs=2
MF1='v1':'gauss2mf',[0.1 0.2 0.2 0.4]
MF2='v2':'trapmf',[0.3 0.6 0.8 1]

[Output1]
Name='y'
Range=[0 30]
NumMFs=3
MF1='low':'gaussmf',[4 5]
MF2='mid':'trimf',[10 15 20]
MF3='high':'trapmf',[18 24 30 30]

[Output2]
Name='z'
Range=[0 1]
NumMFs=2
MF1='no':'zmf',[0 0.6]
MF2='yes':'smf',[0.4 1]

[Rules]
1 -2 0, 1 2 (1) : 1
3 0 2, 2 0 (0.5) : 2
-4 4 1, 3 -1 (0.25) : 1
2 1 0, 0 2 (1) : 2
"""


@pytest.fixture
def full(tmp_path):
    path = tmp_path / "everything.fis"
    path.write_text(FULL_FIS)
    return read_fis_system(path)


def test_a_fis_with_every_option_is_read_in_full(full):
    assert full.methods == Methods("prod", "probor", "prod", "sum", "bisector")
    assert [len(v.terms) for v in full.inputs] == [4, 4, 2] and len(full.outputs) == 2
    assert full.inputs[0].terms[2].params == (7.0, 2.0)  # sigmf: MATLAB [slope centre] -> (centre, slope)
    assert full.inputs[2].terms[0].params == (0.2, 0.1, 0.4, 0.2)  # gauss2mf: (mean1, sigma1, mean2, sigma2)
    assert full.rules[0].antecedent == (1, -2, 0) and full.rules[0].consequent == (1, 2)
    assert full.rules[1].weight == 0.5 and full.rules[1].connection == "or"
    assert full.rules[2].consequent == (3, -1)  # a negated consequent
    assert fis_text(full) == FULL_FIS  # written back byte for byte


def test_fis_to_fcl_to_fis_is_lossless_with_the_same_outputs(full, tmp_path):
    fcl = tmp_path / "everything.fcl"
    fcl.write_text(fcl_text(full))
    back = read_fcl(fcl)
    assert back == full and fis_text(back) == FULL_FIS
    x = readings(full, 300, 1)
    np.testing.assert_array_equal(evaluate(CompiledSystem(back), x)[0], evaluate(CompiledSystem(full), x)[0])


@pytest.mark.parametrize("seed", range(8))
def test_random_systems_round_trip_through_both_formats(seed, tmp_path):
    rng = np.random.default_rng(seed)
    methods = Methods(*(str(rng.choice(c)) for c in (("min", "prod"), ("max", "probor"), ("min", "prod"),
                                                     ("max", "sum", "probor"),
                                                     ("centroid", "bisector", "mom", "som", "lom"))))
    system = random_system(seed + 200, methods=methods, outputs=int(rng.integers(1, 3)))
    (tmp_path / "a.fis").write_text(fis_text(system))
    from_fis = read_fis_system(tmp_path / "a.fis", resolution=system.resolution)
    (tmp_path / "b.fcl").write_text(fcl_text(from_fis))
    from_fcl = read_fcl(tmp_path / "b.fcl", resolution=system.resolution)
    assert from_fis == system and from_fcl == system
    assert fis_text(from_fcl) == fis_text(system)


@pytest.mark.parametrize("edit, message", [
    (("Type='mamdani'", "Type='sugeno'"), ":3: only Mamdani systems"),
    (("Version=2.0", "TypeReductionMethod='karnikmendel'"), ":4: TypeReductionMethod: type-2"),
    (("MF2='t2':'gbellmf',[2 3 5]", "MF2='t2':'gbellmf',[2 3 5],[1 3 5]"), ":19: type-2 membership"),
    (("MF3='t3':'sigmf',[2 7]", "MF3='t3':'linsmf',[2 7]"), ":20: membership type 'linsmf' is not supported"),
    (("1 -2 0, 1 2 (1) : 1", "1.2 -2 0, 1 2 (1) : 1"), ":55: fractional term indices"),
    (("1 -2 0, 1 2 (1) : 1", "1 -2, 1 2 (1) : 1"), ":55: a rule needs 3 input and 2 output indices"),
    (("1 -2 0, 1 2 (1) : 1", "1 -5 0, 1 2 (1) : 1"), ":55: b has no term 5"),
    (("NumRules=4", "NumRules=5"), ":7: NumRules=5 but \\[Rules\\] has 4 rules"),
    (("NumMFs=2\nMF1='v1'", "NumMFs=3\nMF1='v1'"), ":35: \\[Input3\\] declares 3 MFs but has no MF3="),
    (("AggMethod='sum'", "AggMethod='myagg'"), ":11: AggMethod 'myagg' is not supported"),
    (("MF1='t1':'trimf',[0 0 5]", "MF1='t1':'trimf',[5 0 0]"), ":18: trimf parameters must be in order"),
    (("Range=[0 10]", "Range=[10 0]"), ":16: Range needs two numbers, low < high"),
])
def test_bad_fis_files_are_refused_with_the_line(tmp_path, edit, message):
    path = tmp_path / "bad.fis"
    assert edit[0] in FULL_FIS
    path.write_text(FULL_FIS.replace(*edit, 1))
    with pytest.raises(HybridtrackError, match=message):
        read_fis_system(path)


TIPPER_FCL = (CONFORMANCE / "jfuzzylogic_tipper.fcl").read_text()


@pytest.mark.parametrize("old, new, message", [
    ("METHOD : COG;", "METHOD : COGS;", ":29: METHOD : COGS"),
    ("METHOD : COG;", "METHOD : MEAN;", ":29: METHOD : MEAN is not supported"),
    ("IF service IS excellent AND food", "IF service IS excellent AND service IS poor OR food",
     ":39: a rule mixing AND and OR"),
    ("IF service IS good THEN", "IF (service IS good) THEN", ":38: parentheses"),
    ("THEN tip IS average", "THEN tip IS middling", ":38: tip has no term 'middling'"),
    ("TERM cheap := (0, 0) (5, 1) (10, 0);", "TERM cheap := 5;", ":26: cannot read term '5'"),
    ("TERM cheap := (0, 0) (5, 1) (10, 0);", "TERM cheap := (0, 0) (5, 1) (7, 0.5) (10, 0);", ":26: point lists must"),
    ("ACT : MIN;", "ACT : MIN", ":35: cannot read 'ACT : MIN ACCU : MAX'"),
    ("FUZZIFY food", "FUZZIFY drink", ":20: FUZZIFY drink: not declared in VAR_INPUT"),
    ("AND : MIN;", "AND : BDIF;", ":34: AND : BDIF is not supported"),
    ("TERM delicious := (7, 0) (9, 1);", "TERM delicious := cosine(2, 8);", ":22: membership type 'cosine'"),
])
def test_bad_fcl_files_are_refused_with_the_line(tmp_path, old, new, message):
    path = tmp_path / "bad.fcl"
    assert old in TIPPER_FCL
    path.write_text(TIPPER_FCL.replace(old, new, 1))
    with pytest.raises(HybridtrackError, match=message):
        read_fcl(path)


# --- conformance ------------------------------------------------------------------------------


@pytest.mark.parametrize("service, food, published", [(2, 1, 7.0169), (4, 5, 14.4585), (7, 8, 20.3414)])
def test_matlab_tipper_gives_matlabs_published_tips(service, food, published):
    system = read_fis_system(CONFORMANCE / "tipper.fis")
    tip = evaluate(CompiledSystem(system), np.array([[service, food]]))[0][0, 0]
    assert tip == pytest.approx(published, abs=0.01)  # MATLAB's 101-point discrete centroid (README)


def test_matlab_tipper_matches_scikit_fuzzy_built_the_same_way():
    system = read_fis_system(CONFORMANCE / "tipper.fis")
    x = readings(system, 400, 3)
    x[0] = (5.0, 5.0)
    ours = evaluate(CompiledSystem(system), x)[0][:, 0]
    np.testing.assert_allclose(ours, evaluate_skfuzzy(system, x), atol=1e-9, rtol=0)
    assert ours[0] == pytest.approx(15.0, abs=1e-9)


def test_tipper_loads_as_a_classifier_config_with_its_or_rules():
    config = FuzzyConfig.from_fis(CONFORMANCE / "tipper.fis", raw_ranges=((0, 10), (0, 10)))
    assert config.rules[0] == Rule({"service": "poor", "food": "rancid"}, "cheap", connection="or")
    clf = FuzzyWeatherClassifier(config)
    assert clf.score(2, 1, engine="skfuzzy") == pytest.approx(clf.score(2, 1), abs=1e-9)
    assert [b[0] for b in config.bands] == ["cheap", "average", "generous"]


def test_fcl_tipper_matches_scikit_fuzzy_and_applies_its_default(tmp_path):
    system = read_fcl(CONFORMANCE / "jfuzzylogic_tipper.fcl")
    assert system.inputs[0].universe == (0.0, 9.0)  # spanned by the terms' points
    assert system.inputs[0].terms[0].params == (0.0, 0.0, 0.0, 4.0)  # the open shoulder (0,1) (4,0)
    assert system.rules[2].connection == "and" and system.defaults == (0.0,)
    x = readings(system, 300, 4)
    ours = evaluate(CompiledSystem(system), x)[0][:, 0]
    reference = evaluate_skfuzzy(system, x)
    fired = ~np.isnan(reference)
    np.testing.assert_allclose(ours[fired], reference[fired], atol=1e-9, rtol=0)
    assert (ours[~fired] == 0.0).all()  # DEFAULT := 0 where no rule fires
    (tmp_path / "again.fcl").write_text(fcl_text(system))
    assert read_fcl(tmp_path / "again.fcl") == system
    with pytest.raises(HybridtrackError, match="no place for a DEFAULT"):
        fis_text(system)


def test_classifier_configs_keep_methods_weights_and_negation_in_toml(tmp_path):
    config = FuzzyConfig(rules=(Rule({"intensity": "strong", "variation": "small"}, "sunny", 0.8, "or"),
                                Rule({"intensity": "weak", "variation": "large"}, "overcast", negated=["variation"])),
                         methods=Methods(and_method="prod", defuzzification="bisector"))
    assert FuzzyConfig.from_toml(config.to_toml(tmp_path / "c.toml")) == config
    assert FuzzyConfig.from_fis(config.to_fis(tmp_path / "c.fis")).rules == config.rules
    assert FuzzyConfig.from_fcl(config.to_fcl(tmp_path / "c.fcl")).system() == config.system()
    assert "variation is not large" in config.rules[1].describe(config.input_names)


# --- command line -----------------------------------------------------------------------------


def test_cli_converts_fis_to_fcl_to_toml_and_back(tmp_path, capsys):
    source = CONFORMANCE / "tipper.fis"
    assert main(["fuzzy", "convert", str(source), str(tmp_path / "t.fcl")]) == 0
    assert main(["fuzzy", "convert", str(tmp_path / "t.fcl"), str(tmp_path / "t.toml")]) == 0
    assert main(["fuzzy", "convert", str(tmp_path / "t.toml"), str(tmp_path / "t.fis")]) == 0
    assert "(2 inputs, 1 output, 3 rules)" in capsys.readouterr().out
    assert read_fis_system(tmp_path / "t.fis") == read_fis_system(source)


def test_cli_evaluates_a_system_file(capsys):
    assert main(["fuzzy", "eval", str(CONFORMANCE / "tipper.fis"), "service=5", "food=5"]) == 0
    assert capsys.readouterr().out.strip() == "tip = 15"


@pytest.mark.parametrize("raw, normalised", [
    (("intensity=165", "variation=90"), ("intensity=5", "variation=5")),  # 10 (165 - 30) / 270, 10 (90 - 0) / 180
    (("intensity=246", "variation=27"), ("intensity=8", "variation=1.5")),  # 10 * 216 / 270, 10 * 27 / 180
    (("intensity=400", "variation=0"), ("intensity=10", "variation=0")),  # above 300 mA: clipped to the top
])
def test_cli_evaluates_a_classifier_toml_at_raw_readings_through_its_raw_range(tmp_path, capsys, raw, normalised):
    # the raw mA had been taken as universe values and clipped: intensity=246 variation=27 gave
    # weather = 15.0067 (cloudy) where the classifier from the same file gives 24.906 (sunny)
    config = FuzzyConfig()  # raw_range 30-300 mA and 0-180 mA onto universes 0-10
    toml, fis = config.to_toml(tmp_path / "c.toml"), config.to_fis(tmp_path / "c.fis")  # a .fis has no raw range
    assert main(["fuzzy", "eval", str(fis), *normalised]) == 0
    reference = capsys.readouterr().out
    assert main(["fuzzy", "eval", str(toml), *raw]) == 0
    printed = capsys.readouterr().out
    assert printed == reference
    intensity, variation = (float(value.split("=")[1]) for value in raw)
    classifier = FuzzyWeatherClassifier(FuzzyConfig.from_toml(toml))
    assert printed == f"weather = {classifier.score(intensity, variation):.6g}\n"


@pytest.mark.parametrize("args, message", [
    (["convert", "tipper.fis", "out.xml"], "unknown fuzzy system format '.xml'"),
    (["convert", "missing.fis", "out.fcl"], "missing.fis"),
    (["eval", "tipper.fis", "service=2"], "no value for input 'food'"),
    (["eval", "tipper.fis", "service=2", "food=x"], "input values must be numbers"),
    (["eval", "tipper.fis", "service=2", "food=1", "drink=3"], "unknown input 'drink'"),
    # a NaN input printed 'tip = nan' and an infinite one was clipped, status 0
    (["eval", "tipper.fis", "service=nan", "food=1"], "input 'service' must be a finite number, got nan"),
    (["eval", "tipper.fis", "service=2", "food=inf"], "input 'food' must be a finite number, got inf"),
])
def test_cli_mistakes_are_one_line(args, message, capsys, monkeypatch):
    monkeypatch.chdir(CONFORMANCE)
    assert main(["fuzzy", *args]) == 2
    err = capsys.readouterr().err
    assert err.startswith("hybridtrack: error:") and message in err and err.count("\n") == 1


@pytest.mark.parametrize("text, message", [
    ("[methods]\nimplication = 'lukasiewicz'\n", "methods.implication: unknown method 'lukasiewicz'"),
    ("[methods]\naggregation = 3\n", "methods.aggregation: must be a string"),
    ("[methods]\nhedges = 'very'\n", "unknown key 'hedges'"),
    ("[[rules]]\nintensity = 'strong'\nweather = 'sunny'\nweight = 2\n",
     "rules\\[1\\]: weight must be between 0 and 1"),
    ("[[rules]]\nintensity = 'strong'\nweather = 'sunny'\nconnection = 'xor'\n", "connection must be 'and' or 'or'"),
    ("[[rules]]\nintensity = 'not blinding'\nweather = 'sunny'\n", "unknown term 'blinding' for intensity"),
])
def test_bad_methods_and_rule_options_in_toml_name_the_key(tmp_path, text, message):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(HybridtrackError, match=message):
        FuzzyConfig.from_toml(path)
