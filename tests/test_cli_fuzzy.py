import json

import numpy as np
import pandas as pd
import pytest

from hybridtrack.cli import main
from hybridtrack.fuzzy import FuzzyConfig


def published_score_by_skfuzzy(intensity_ma, variation_ma):
    """The published classifier written out afresh in scikit-fuzzy's control API (not through
    hybridtrack's own translation): Gaussian inputs on 0-10 (σ 1.5 and 2.5, the documented
    choice of hybridtrack.fuzzy.config), triangular outputs on 0-30, the four published rules,
    the published linear maps 30-300 mA and 0-180 mA onto 0-10, and the same sampling (1001 and
    3001 points) so that scikit-fuzzy's discrete centroid is the same integral."""
    import skfuzzy as fuzz
    from skfuzzy import control as ctrl

    i = ctrl.Antecedent(np.linspace(0, 10, 1001), "intensity")
    v = ctrl.Antecedent(np.linspace(0, 10, 1001), "variation")
    w = ctrl.Consequent(np.linspace(0, 30, 3001), "weather")
    for name, mean in (("weak", 0.0), ("medium", 5.0), ("strong", 10.0)):
        i[name] = fuzz.gaussmf(i.universe, mean, 1.5)
    v["small"], v["large"] = fuzz.gaussmf(v.universe, 0.0, 2.5), fuzz.gaussmf(v.universe, 10.0, 2.5)
    for name, abc in (("overcast", [0, 5, 10]), ("cloudy", [10, 15, 20]), ("sunny", [20, 25, 30])):
        w[name] = fuzz.trimf(w.universe, abc)
    rules = [ctrl.Rule(i["strong"] & v["small"], w["sunny"]), ctrl.Rule(i["strong"] & v["large"], w["cloudy"]),
             ctrl.Rule(i["medium"] & v["large"], w["cloudy"]), ctrl.Rule(i["weak"] & v["small"], w["overcast"])]
    sim = ctrl.ControlSystemSimulation(ctrl.ControlSystem(rules))
    sim.input["intensity"] = (intensity_ma - 30.0) / 270.0 * 10.0
    sim.input["variation"] = variation_ma / 180.0 * 10.0
    sim.compute()
    return float(sim.output["weather"])


def test_classify_one_reading_prints_score_label_and_rules(capsys):
    """The published cloudy reading (200.1 mA, 84.6 mA); the score is scikit-fuzzy's, the firing by hand."""
    assert main(["classify", "--intensity", "200.1", "--variation", "84.6"]) == 0
    out = capsys.readouterr().out
    score = published_score_by_skfuzzy(200.1, 84.6)
    assert 10.0 <= score < 20.0  # the published label, cloudy, by the reference alone
    assert out.startswith(f"score {score:.3f} -> cloudy")
    # by hand: intensity (200.1 - 30)/27 = 6.3, variation 84.6/18 = 4.7;
    # medium(6.3) = exp(-1.3²/4.5) = 0.687, large(4.7) = exp(-5.3²/12.5) = 0.1057; rule 3 fires min = 0.106
    firing = min(np.exp(-(6.3 - 5.0) ** 2 / 4.5), np.exp(-(4.7 - 10.0) ** 2 / 12.5))
    assert f"{firing:.3f}" == "0.106"
    assert f"rule 3: intensity is medium AND variation is large -> cloudy  fires {firing:.3f}" in out


def test_classify_json(capsys):
    """The published sunny reading (246 mA, 27 mA) against scikit-fuzzy and a hand-computed firing."""
    assert main(["classify", "--intensity", "246", "--variation", "27", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["weather"] == "sunny"
    assert data["score"] == pytest.approx(published_score_by_skfuzzy(246.0, 27.0), abs=1e-6)
    # by hand: intensity (246 - 30)/27 = 8.0, variation 27/18 = 1.5;
    # strong(8) = exp(-2²/4.5) = 0.4111, small(1.5) = exp(-1.5²/12.5) = 0.835; rule 1 fires min = 0.4111
    assert data["rules"][0]["firing"] == pytest.approx(np.exp(-4.0 / 4.5), rel=1e-9)


def test_classify_a_file_with_named_columns(tmp_path, capsys):
    src, out = tmp_path / "log.csv", tmp_path / "out.csv"
    pd.DataFrame({"time": ["12:00", "12:01", "12:02", "12:03"], "I_mA": [246.0, 200.1, 143.4, None],
                  "dI_mA": [27.0, 84.6, 45.0, 3.0]}).to_csv(src, index=False)
    assert main(["classify", str(src), "--intensity-col", "I_mA", "--variation-col", "dI_mA", "--out", str(out)]) == 0
    table = pd.read_csv(out)
    assert list(table["sky"]) == ["sunny", "cloudy", "overcast", "unknown"]
    assert "overcast 1, cloudy 1, sunny 1, unknown 1" in capsys.readouterr().out


def test_classify_with_the_complete_config_and_a_fis(tmp_path, capsys):
    assert main(["classify", "--intensity", "143.4", "--variation", "45", "--config", "data/fuzzy-complete.toml"]) == 0
    assert "-> cloudy" in capsys.readouterr().out
    fis = FuzzyConfig().to_fis(tmp_path / "published.fis")
    assert main(["classify", "--intensity", "143.4", "--variation", "45", "--config", str(fis)]) == 0
    assert "-> overcast" in capsys.readouterr().out


def test_tune_writes_a_config_that_loads(tmp_path, capsys):
    labels = tmp_path / "labels.csv"
    pd.DataFrame({"intensity": [246.0, 200.1, 200.1, 143.4, 100.0], "variation": [27.0, 84.6, 93.6, 45.0, 150.0],
                  "weather": ["sunny", "cloudy", "cloudy", "overcast", "cloudy"]}).to_csv(labels, index=False)
    out, report = tmp_path / "tuned.toml", tmp_path / "report"
    assert main(["tune", str(labels), "--out", str(out), "--method", "local", "--folds", "0", "--seeds", "1",
                 "--report", str(report)]) == 0
    printed = capsys.readouterr().out
    assert "label accuracy" in printed and f"wrote {out}" in printed
    tuned = FuzzyConfig.from_toml(out)
    assert tuned.name == "published-tuned"
    for picture in ("surfaces.png", "confusion.png"):
        assert (report / picture).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    data = json.loads((report / "report.json").read_text())
    assert data["accuracy_after"] >= data["accuracy_before"] and data["accuracy_after"] == 1.0


def test_surface_writes_a_png(tmp_path):
    out = tmp_path / "surface.png"
    assert main(["surface", "--out", str(out), "--points", "41"]) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and out.stat().st_size > 20_000


@pytest.mark.parametrize("args, message", [
    (["classify", "--intensity", "100"], "give --intensity and --variation"),
    (["classify", "--intensity", "1", "--variation", "2", "--config", "missing.toml"], "missing.toml: no such config"),
    (["classify", "nofile.csv"], "nofile.csv: no such file"),
    (["tune", "nofile.csv", "--out", "x.toml"], "nofile.csv: no such file"),
    (["surface", "--points", "2"], "--points must be between 5 and 1001"),
])
def test_fuzzy_commands_bad_input_one_line_status_2(capsys, args, message):
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err


def test_classify_file_missing_column(tmp_path, capsys):
    src = tmp_path / "log.csv"
    src.write_text("a,b\n1,2\n")
    assert main(["classify", str(src)]) == 2
    assert "no column 'intensity'; columns are a, b" in capsys.readouterr().err


def test_an_absurd_reading_is_clipped_to_its_range_not_overflowed():
    """From Python a reading past the input's range is clipped onto it (a run survives a logger's
    spike); the command line refuses it (`test_a_reading_no_sensor_gives_is_refused_in_one_line`)."""
    import warnings

    from hybridtrack.fuzzy import FuzzyWeatherClassifier

    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no overflow
        assert FuzzyWeatherClassifier().explain(1e308, 0.0).weather == "sunny"  # the strongest light


def test_a_warning_that_is_not_a_tuning_one_is_shown_once(monkeypatch):
    import warnings

    from hybridtrack.cli.fuzzy import tuned_config_warnings

    shown = []
    monkeypatch.setattr(warnings, "showwarning", lambda message, *rest, **kw: shown.append(str(message)))
    with tuned_config_warnings():
        warnings.warn("a plain warning", RuntimeWarning)
    assert shown == ["a plain warning"]


@pytest.mark.parametrize("value", ["nan", "inf", "-inf"])
def test_classify_refuses_a_reading_that_is_not_a_finite_number(capsys, value):
    # classify printed 'unknown' for nan and 'sunny' for inf (clipped), status 0; rules refused both
    assert main(["classify", f"--intensity={value}", "--variation", "1"]) == 2
    err = capsys.readouterr().err
    assert err == f"hybridtrack: error: --intensity must be a finite number, got {float(value)}\n"
    assert main(["classify", "--intensity", "100", f"--variation={value}"]) == 2
    assert "--variation must be a finite number" in capsys.readouterr().err


def test_a_bad_cell_is_named_by_the_files_own_row_past_comments_and_blank_lines(tmp_path, capsys):
    # the row was counted among the data rows only: 'row 3' for the file's line 6
    src = tmp_path / "log.csv"
    src.write_text("# site notes\nintensity,variation\n\n246,27\n# a remark\n200,abc\n")
    assert main(["classify", str(src)]) == 2
    assert capsys.readouterr().err == f"hybridtrack: error: {src}: row 6, column 'variation': 'abc' is not a number\n"


def test_classify_refuses_an_infinite_cell_by_row_and_column(tmp_path, capsys):
    # an infinite photocurrent was clipped and classified 'sunny', status 0
    src = tmp_path / "log.csv"
    src.write_text("intensity,variation\n246,27\n200,inf\n")
    assert main(["classify", str(src), "--out", str(tmp_path / "out.csv")]) == 2
    err = capsys.readouterr().err
    assert err == f"hybridtrack: error: {src}: row 3, column 'variation': inf is not a finite number\n"
    assert not (tmp_path / "out.csv").exists()


def _tune_refused(tmp_path, capsys, text: str, *flags: str) -> tuple:
    """Run ``tune`` on a labels file of `text` (no folds and one seed unless `flags` say); check it
    exits 2 and writes nothing; return the labels path and its standard error."""
    labels = tmp_path / "labels.csv"
    labels.write_text(text)
    flags = flags or ("--folds", "0", "--seeds", "1")
    assert main(["tune", str(labels), "--out", str(tmp_path / "t.toml"), "--method", "local", *flags]) == 2
    assert not (tmp_path / "t.toml").exists()
    return labels, capsys.readouterr().err


@pytest.mark.parametrize("cells, row, column", [
    ("246,27,sunny\n,3,overcast\n", 3, "intensity"),  # was fitted as a wrongly labelled reading
    ("246,27,sunny\n60,inf,overcast\n", 3, "variation"),  # was 'labelled_range needs a finite ...'
    ("246,27,sunny\n60,3,\n", 3, "weather"),  # was 'samples: unknown weather label 'nan'', no file or row
])
def test_tune_refuses_a_reading_without_a_number_by_row_and_column(tmp_path, capsys, cells, row, column):
    labels, err = _tune_refused(tmp_path, capsys, "intensity,variation,weather\n" + cells)
    assert err.count("\n") == 1 and f"{labels}: row {row}, column {column!r}: " in err


def test_tune_refuses_an_empty_score_cell(tmp_path, capsys):
    # an empty score made every loss NaN and the fit was written anyway ('loss nan -> nan')
    labels, err = _tune_refused(tmp_path, capsys, "intensity,variation,score\n246,27,25\n60,3,\n150,100,15\n")
    assert f"{labels}: row 3, column 'score': empty" in err


@pytest.mark.parametrize("command", ["classify", "rules"])
@pytest.mark.parametrize("intensity, variation, message", [
    ("-500", "20", "--intensity -500 is no reading: a photocurrent in mA is never below zero"),
    ("100", "-20", "--variation -20 is no reading: a variation is a range, max - min, never below zero"),
    ("1e308", "20", "--intensity 1e+308 is no reading: over 100,000 mA, which no sun sensor gives (a unit mixed up?)"),
    ("100", "200000", "--variation 200000 is no reading: over 100,000 mA, which no sun sensor gives (a unit mixed up?)"),
])
def test_a_reading_no_sensor_gives_is_refused_in_one_line(capsys, command, intensity, variation, message):
    # 'classify --intensity -500 --variation -20' had printed 'score 5.007 -> overcast', status 0,
    # and --intensity 1e308 'score 24.993 -> sunny'
    assert main([command, f"--intensity={intensity}", f"--variation={variation}"]) == 2
    assert capsys.readouterr().err == f"hybridtrack: error: {message}\n"


@pytest.mark.parametrize("command", ["classify", "tune"])
@pytest.mark.parametrize("rows, refused", [
    # negative labels had been fitted, and negative cells classified
    ("60,-3,overcast\n", "row 3, column 'variation': -3 is no reading; a variation is a range, max - min, never "
                         "below zero"),
    # a label of 1e308 mA had been fitted as the brightest sun; the earliest bad row is named
    ("1e308,3,sunny\n-60,-3,overcast\n", "row 3, column 'intensity': 1e+308 is no reading; over 100,000 mA, which "
                                         "no sun sensor gives (a unit mixed up?)"),
])
def test_a_cell_no_sensor_gives_is_refused_by_row_and_column(tmp_path, capsys, command, rows, refused):
    src = tmp_path / "labels.csv"
    src.write_text("intensity,variation,weather\n246,27,sunny\n" + rows)
    extra = ["--out", str(tmp_path / "t.toml"), "--folds", "0", "--seeds", "1"] if command == "tune" else []
    assert main([command, str(src), *extra]) == 2
    assert capsys.readouterr().err == f"hybridtrack: error: {src}: {refused}\n"
    assert not (tmp_path / "t.toml").exists()


@pytest.mark.parametrize("flags, message", [
    (["--margin", "100"], "--margin (score units) = 100.0 is outside [0, 30]"),
    (["--folds", "9"], "--folds must be 0 (none) or between 2 and the number of samples (3), got 9"),
    (["--folds", "-1"], "--folds must be 0 (none) or between 2 and the number of samples (3), got -1"),
    (["--seeds", "0"], "--seeds must be a whole number within [1, 20], got 0"),
    (["--seeds", "50"], "--seeds must be a whole number within [1, 20], got 50"),
    (["--seed", "5000000000"], "--seed must be a whole number within [0, 4,294,967,276], got 5000000000"),
])
def test_tune_names_the_flag_at_fault_in_one_line(tmp_path, capsys, flags, message):
    # 'margin (score units) = 100.0 ...', 'folds must be ...', 'seeds must be ...': no flag named, and the
    # last two after a progress bar had been drawn on the same standard error
    _, err = _tune_refused(tmp_path, capsys, "intensity,variation,weather\n246,27,sunny\n200,85,cloudy\n60,3,overcast\n",
                           *flags)
    assert err == f"hybridtrack: error: {message}\n"


def test_tune_names_the_file_row_and_column_of_an_unknown_label(tmp_path, capsys):
    # 'samples: unknown weather label 'foggy'; ...': neither the file nor the row
    labels, err = _tune_refused(tmp_path, capsys,
                                "# field notes\nintensity,variation,weather\n246,27,sunny\n150,40,Foggy\n60,3,overcast\n")
    assert err == (f"hybridtrack: error: {labels}: row 4, column 'weather': unknown weather label "
                                       "'Foggy'; the bands are overcast, cloudy, sunny\n")
