"""Tuning that cannot mislead: physical constraints, held-out accuracy, the labelled range."""

import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from hybridtrack.cli import main
from hybridtrack.fuzzy import FuzzyConfig, FuzzyWeatherClassifier
from hybridtrack.fuzzy.tuning import OutsideLabelsWarning, _folds, constraint_violations, read_samples, tune

LABELS = Path(__file__).parent.parent / "examples" / "tuning" / "labels.csv"
TUNED = Path(__file__).parent.parent / "examples" / "tuning" / "tuned.toml"


def test_the_published_system_keeps_the_physical_constraints():
    assert constraint_violations(FuzzyConfig()) == (0.0, [])


def test_a_strong_term_that_peaks_short_of_full_light_bounds_the_sunny_region():
    # by hand at full light, no variation: strong(10) = exp(-9/0.5) ~ 1.5e-8 fires the sunny rule,
    # medium(10) = exp(-25/4.5) = 0.0039 and large(0) = exp(-100/12.5) = 3.4e-4 fire the cloudy one
    broken = FuzzyConfig().with_params("intensity", "strong", (7.0, 0.5))
    assert FuzzyWeatherClassifier(broken).classify(300.0, 0.0) == "cloudy"
    amount, reasons = constraint_violations(broken)
    assert amount > 0 and any("bounded on the high-intensity side" in r for r in reasons)


def test_the_rebuilt_labelled_set_spans_three_skies():
    samples = pd.read_csv(LABELS)
    assert 60 <= len(samples) <= 80
    assert samples["weather"].value_counts().to_dict() == {"cloudy": 24, "overcast": 24, "sunny": 24}


def test_the_shipped_tuned_config_calls_clear_noon_sunny_and_darkness_overcast():
    tuned = FuzzyConfig.from_toml(TUNED)
    samples = pd.read_csv(LABELS)
    assert tuned.labelled_range == ((samples["intensity"].min(), samples["intensity"].max()),
                                    (samples["variation"].min(), samples["variation"].max()))
    clf = FuzzyWeatherClassifier(tuned)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # (290, 5) lies inside the labels: no warning
        assert clf.classify(290.0, 5.0) == "sunny"
    with pytest.warns(OutsideLabelsWarning, match="outside the range"):
        assert clf.classify(30.0, 0.0) == "overcast"  # the dark current lies below every label
    assert constraint_violations(tuned)[1] == []


def test_tuning_the_labelled_set_keeps_physics_and_reports_held_out_accuracy():
    tuned, report = tune(None, LABELS, folds=3, maxiter=25, popsize=6, restarts=2)
    clf = FuzzyWeatherClassifier(tuned)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", OutsideLabelsWarning)
        assert clf.classify(290.0, 5.0) == "sunny" and clf.classify(30.0, 0.0) == "overcast"
    assert report.constraints_after == [] and report.accuracy_after > report.accuracy_before
    assert report.folds == 3 and len(report.accuracy_cv_folds) == 3
    # pooled over every held-out reading: with 72 labels, 24 of each sky, in 3 stratified folds of
    # 24, that is the mean of the folds' accuracies, each a whole number of 24ths
    folds = np.array(report.accuracy_cv_folds)
    np.testing.assert_allclose(folds * 24, np.round(folds * 24), atol=1e-9)
    assert report.accuracy_cv == pytest.approx(folds.mean(), abs=1e-12)
    # three balanced skies: guessing scores 1/3; a fit that generalises at all scores well above it
    assert 0.6 < report.accuracy_cv <= 1.0
    assert "cross-validated" in str(report)


def test_folds_are_stratified_by_label():
    samples = read_samples(LABELS)
    fold = _folds(samples, 5, seed=0)
    for label in ("sunny", "cloudy", "overcast"):
        counts = np.bincount(fold[samples["weather"].to_numpy() == label], minlength=5)
        assert counts.max() - counts.min() <= 1


def test_the_labelled_range_round_trips_through_toml(tmp_path):
    config = FuzzyConfig().replace(labelled_range=((40.0, 340.0), (2.0, 250.0)))
    assert FuzzyConfig.from_toml(config.to_toml(tmp_path / "c.toml")) == config
    assert "[labelled_range]" in (tmp_path / "c.toml").read_text()


def test_classify_warns_on_one_line_outside_the_labelled_range(capsys):
    assert main(["classify", "--intensity", "30", "--variation", "0", "--config", str(TUNED)]) == 0
    err = capsys.readouterr().err
    assert err.startswith("hybridtrack: warning: 1 of 1 readings lie outside") and err.count("\n") == 1


def test_progress_counts_every_fit():
    calls = []
    tune(None, LABELS, method="local", maxiter=3, restarts=0, folds=3, seeds=2, progress=calls.append)
    assert calls == [1] * (1 + 3 + 1)
