"""The general Mamdani engine: scikit-fuzzy parity on random systems, hand-computed cases, fallback."""

import numpy as np
import pytest

from hybridtrack import HybridtrackError
from hybridtrack.fuzzy import FuzzyWeatherClassifier
from hybridtrack.fuzzy.config import Methods, Term, Variable
from hybridtrack.fuzzy.engine import CompiledSystem, evaluate, evaluate_skfuzzy
from hybridtrack.fuzzy.membership import SHAPES, from_matlab, membership
from hybridtrack.fuzzy.system import MamdaniSystem, SystemRule


def random_term(rng, name, lo, hi):
    """A valid term of a random type somewhere on [lo, hi]."""
    shape = rng.choice(sorted(SHAPES))
    w = hi - lo
    c = rng.uniform(lo, hi)
    s = rng.uniform(0.05, 0.3) * w
    points = np.sort(rng.uniform(lo - 0.1 * w, hi + 0.1 * w, 4))
    points[-1] += 0.01 * w  # never zero width
    params = {
        "trimf": points[:3] if points[2] > points[0] else points[[0, 1, 3]],
        "trapmf": points,
        "gaussmf": (c, s),
        "gauss2mf": (c - s, s, c + s, 0.5 * s),
        "gbellmf": (s, rng.uniform(1, 4), c),
        "sigmf": (c, rng.choice([-1, 1]) * rng.uniform(2, 10) / w),
        "dsigmf": (c - s, 8 / w, c + s, 8 / w),
        "psigmf": (c - s, 8 / w, c + s, -8 / w),
        "pimf": points,
        "smf": points[[0, 3]],
        "zmf": points[[0, 3]],
    }[shape]
    return Term(name, shape, tuple(float(p) for p in params))


def random_variable(rng, name, terms):
    lo = float(rng.uniform(-5, 5))
    hi = lo + float(rng.uniform(1, 20))
    return Variable(name, (lo, hi), tuple(random_term(rng, f"{name}{k}", lo, hi) for k in range(terms)))


def random_system(seed, *, methods=None, outputs=1, resolution=(201, 401)):
    rng = np.random.default_rng(seed)
    inputs = tuple(random_variable(rng, f"in{i}", int(rng.integers(2, 5))) for i in range(int(rng.integers(1, 4))))
    outs = tuple(random_variable(rng, f"out{o}", int(rng.integers(2, 5))) for o in range(outputs))
    rules = []
    for _ in range(int(rng.integers(2, 9))):
        ante = [int(rng.integers(1, len(v.terms) + 1)) * int(rng.choice([1, 1, 1, -1])) if rng.random() < 0.75 else 0
                for v in inputs]
        if not any(ante):
            ante[0] = 1
        cons = tuple(int(rng.integers(1, len(v.terms) + 1)) for v in outs)
        rules.append(SystemRule(tuple(ante), cons, float(rng.choice([1.0, rng.uniform(0.2, 1.0)])),
                                str(rng.choice(["and", "or"]))))
    if methods is None:
        methods = Methods(and_method=str(rng.choice(["min", "prod"])), or_method=str(rng.choice(["max", "probor"])))
    return MamdaniSystem(inputs, outs, tuple(rules), methods, resolution, name=f"random{seed}")


def readings(system, n, seed):
    rng = np.random.default_rng(seed)
    return np.stack([rng.uniform(*v.universe, n) for v in system.inputs], axis=1)


@pytest.mark.parametrize("shape", sorted(SHAPES))
def test_membership_formulas_are_scikit_fuzzys(shape):
    import skfuzzy as fuzz

    rng = np.random.default_rng(len(shape))
    for _ in range(5):
        term = random_term(rng, "t", 0.0, 10.0)
        while term.shape != shape:
            term = random_term(rng, "t", 0.0, 10.0)
        x = np.linspace(-2, 12, 1401)
        p = term.params
        if shape in ("trimf", "trapmf"):
            reference = getattr(fuzz, shape)(x, list(p))
        else:
            reference = getattr(fuzz, shape)(x, *p)
        if shape == "dsigmf":  # MATLAB's |f1 - f2|; scikit-fuzzy's f1 - f2 agrees where f1 dominates
            reference = np.abs(reference)
        np.testing.assert_allclose(membership(shape, p, x), reference, atol=1e-12)


def test_matlab_parameter_orders():
    assert from_matlab("gaussmf", [1.5, 5]) == (5.0, 1.5)
    assert from_matlab("sigmf", [2, 4]) == (4.0, 2.0)  # MATLAB [slope centre] -> (centre, slope)
    assert from_matlab("dsigmf", [5, 2, 5, 7]) == (2.0, 5.0, 7.0, 5.0)
    assert from_matlab("gbellmf", [2, 4, 6]) == (2.0, 4.0, 6.0)


@pytest.mark.parametrize("defuzz", ["centroid", "bisector", "mom", "som", "lom"])
@pytest.mark.parametrize("seed", range(6))
def test_random_systems_match_scikit_fuzzy(seed, defuzz):
    """Random inputs, terms of every type, negation, don't-care, weights, AND/OR (min/prod, max/probor)."""
    system = random_system(100 * seed + len(defuzz))
    system = MamdaniSystem(system.inputs, system.outputs, system.rules,
                           Methods(system.methods.and_method, system.methods.or_method, defuzzification=defuzz),
                           system.resolution, system.name)
    x = readings(system, 150, seed)
    reference = evaluate_skfuzzy(system, x)
    if defuzz in ("mom", "som", "lom"):
        # where no rule fires scikit-fuzzy's centroid refuses, but its mom/som/lom return a point of the
        # empty set (the whole universe is "at its maximum" 0); the empty set has no value here either way
        empty = np.isnan(evaluate_skfuzzy(MamdaniSystem(system.inputs, system.outputs, system.rules, Methods(
            system.methods.and_method, system.methods.or_method), system.resolution), x))
        reference[empty] = np.nan
    compiled = CompiledSystem(system)
    for engine in ("numpy", "numba"):
        ours = evaluate(compiled, x, engine=engine)[0][:, 0]
        np.testing.assert_array_equal(np.isnan(ours), np.isnan(reference))
        # centroid and bisector are exact; mom/som/lom pick sampled points by float equality in
        # scikit-fuzzy, whose value at a cut point is its clip level only to rounding: one step
        step = np.diff(system.outputs[0].universe)[0] / (system.resolution[1] - 1)
        tolerance = 1e-9 if defuzz in ("centroid", "bisector") else step
        np.testing.assert_allclose(ours, reference, atol=tolerance, rtol=0, err_msg=engine)


@pytest.mark.parametrize("methods", [Methods(implication="prod"), Methods(aggregation="sum"),
                                     Methods(aggregation="probor"), Methods(implication="prod", aggregation="probor"),
                                     Methods(implication="prod", aggregation="sum", defuzzification="bisector"),
                                     Methods(aggregation="probor", defuzzification="mom"),
                                     Methods(implication="prod", defuzzification="lom")],
                         ids=lambda m: "-".join(m.to_dict().values()))
def test_compiled_and_numpy_engines_agree_beyond_scikit_fuzzy(methods):
    """Options scikit-fuzzy lacks: the two implementations (tables and dense) against each other."""
    for seed in range(4):
        system = random_system(seed + 50, methods=methods, outputs=2)
        x = readings(system, 200, seed)
        compiled = CompiledSystem(system)
        a = evaluate(compiled, x, engine="numpy")[0]
        b = evaluate(compiled, x, engine="numba")[0]
        np.testing.assert_array_equal(np.isnan(a), np.isnan(b))
        np.testing.assert_allclose(a, b, atol=1e-9, rtol=0)


def one_input_system(output_terms, rules, methods, input_terms=None, resolution=(101, 3001)):
    terms = input_terms or (Term("low", "trimf", (0, 0, 10)), Term("high", "trimf", (0, 10, 10)))
    return MamdaniSystem((Variable("x", (0, 10), terms),), (Variable("y", (0, 30), output_terms),), rules, methods,
                         resolution)


def run(system, *x):
    return evaluate(CompiledSystem(system), np.array([x], float).T, engine="numba")[0][:, 0], \
        evaluate(CompiledSystem(system), np.array([x], float).T, engine="numpy")[0][:, 0]


RIGHT_TRIANGLE = (Term("t", "trimf", (0, 0, 30)),)
TWO_TRIANGLES = (Term("a", "trimf", (0, 10, 20)), Term("b", "trimf", (10, 20, 30)))


@pytest.mark.parametrize("defuzz, expected", [
    ("centroid", 10.0),  # scaling does not move a triangle's centroid: (0 + 0 + 30) / 3
    ("bisector", 30 * (1 - 1 / np.sqrt(2))),  # half the area of s (1 - y/30) lies left of this
    ("mom", 0.0), ("som", 0.0), ("lom", 0.0),  # the scaled triangle peaks at its corner
])
def test_product_implication_by_hand(defuzz, expected):
    system = one_input_system(RIGHT_TRIANGLE, (SystemRule((2,), (1,)),),
                              Methods(implication="prod", defuzzification=defuzz))
    for value in run(system, 5.0):  # "high" is 0.5 at x = 5
        np.testing.assert_allclose(value, expected, atol=1e-9)


def test_min_implication_clip_by_hand():
    # triangle 0-10-20 clipped at 0.5: a trapezoid (0,0) (5,.5) (15,.5) (20,0), symmetric about 10,
    # so its centroid and bisector are 10; its plateau runs 5 to 15 (som 5, mom 10, lom 15)
    system = one_input_system((Term("a", "trimf", (0, 10, 20)),), (SystemRule((2,), (1,)),), Methods())
    for value in run(system, 5.0):
        np.testing.assert_allclose(value, 10.0, atol=1e-9)
    for method, value in (("mom", 10.0), ("som", 5.0), ("lom", 15.0), ("bisector", 10.0)):
        system = one_input_system((Term("a", "trimf", (0, 10, 20)),), (SystemRule((2,), (1,)),),
                                  Methods(defuzzification=method))
        for got in run(system, 5.0):
            np.testing.assert_allclose(got, value, atol=1e-9, err_msg=method)


def test_sum_aggregation_by_hand():
    # rules fire 1 and 0.5 (weight) with product implication: t_a + 0.5 t_b, areas 10 and 5 at 10 and 20
    rules = (SystemRule((2,), (1,)), SystemRule((2,), (2,), weight=0.5))
    system = one_input_system(TWO_TRIANGLES, rules, Methods(implication="prod", aggregation="sum"))
    for value in run(system, 10.0):
        np.testing.assert_allclose(value, (10 * 10 + 5 * 20) / 15, atol=1e-9)
    # max aggregation differs: where both overlap (10-20) the larger one only
    system = one_input_system(TWO_TRIANGLES, rules, Methods(implication="prod", aggregation="max"))
    assert abs(run(system, 10.0)[0][0] - (10 * 10 + 5 * 20) / 15) > 0.1


def test_probor_aggregation_by_hand():
    # t_a + 0.5 t_b - 0.5 t_a t_b: on 10..20 the product integrates to 10/6 (moment 15 x that)
    rules = (SystemRule((2,), (1,)), SystemRule((2,), (2,), weight=0.5))
    system = one_input_system(TWO_TRIANGLES, rules, Methods(implication="prod", aggregation="probor"))
    area = 10 + 5 - 0.5 * 10 / 6
    moment = 100 + 0.5 * 200 - 0.5 * 15 * 10 / 6
    for value in run(system, 10.0):  # piecewise-linear between 3001 samples: O(h^2) from the curve
        np.testing.assert_allclose(value, moment / area, atol=1e-5)


def test_and_or_negation_and_weights_by_hand():
    terms = (Term("low", "trimf", (0, 0, 10)), Term("high", "trimf", (0, 10, 10)))
    two = (Variable("x", (0, 10), terms), Variable("z", (0, 10), terms))
    out = (Variable("y", (0, 30), (Term("a", "trimf", (0, 10, 20)),)),)
    x = np.array([[2.0, 7.0]])  # low(x) .8, high(x) .2; low(z) .3, high(z) .7
    cases = [(SystemRule((1, 2), (1,)), Methods(), 0.7), (SystemRule((1, 2), (1,)), Methods(and_method="prod"), 0.56),
             (SystemRule((2, 1), (1,), connection="or"), Methods(), 0.3),
             (SystemRule((2, 1), (1,), connection="or"), Methods(or_method="probor"), 0.2 + 0.3 - 0.06),
             (SystemRule((-1, 0), (1,), weight=0.5), Methods(), 0.5 * 0.2)]
    for rule, methods, expected in cases:
        compiled = CompiledSystem(MamdaniSystem(two, out, (rule,), methods, (101, 301)))
        for engine in ("numba", "numpy"):
            np.testing.assert_allclose(evaluate(compiled, x, engine=engine)[1], [[expected]], atol=1e-12)


def test_nan_readings_and_empty_sets_are_nan_and_defaults_fill_empty_sets():
    terms = (Term("low", "trimf", (0, 0, 4)), Term("high", "trimf", (6, 10, 10)))
    out = Variable("y", (0, 30), (Term("a", "trimf", (0, 10, 20)),))
    system = MamdaniSystem((Variable("x", (0, 10), terms),), (out,), (SystemRule((1,), (1,)),), Methods(), (101, 301))
    x = np.array([[1.0], [5.0], [np.nan]])
    for engine in ("numba", "numpy"):
        values = evaluate(CompiledSystem(system), x, engine=engine)[0][:, 0]
        assert values[0] == pytest.approx(10.0) and np.isnan(values[1]) and np.isnan(values[2])
    with_default = MamdaniSystem(system.inputs, system.outputs, system.rules, system.methods, system.resolution,
                                 defaults=(7.5,))
    values = evaluate(CompiledSystem(with_default), x)[0][:, 0]
    assert values[1] == 7.5 and np.isnan(values[2])  # a missing reading stays missing


def test_without_numba_the_numpy_engine_runs_with_one_warning(monkeypatch):
    import sys

    from hybridtrack.fuzzy import compiled
    from hybridtrack.kernel import jit

    monkeypatch.setattr(compiled, "_STATE", {"compiled": compiled._STATE.get("compiled")})
    monkeypatch.setattr(jit, "_WARNED", [])  # the process's one warning not yet given
    monkeypatch.setitem(sys.modules, "numba", None)  # what a missing package looks like to import
    clf = FuzzyWeatherClassifier()
    with pytest.warns(RuntimeWarning, match="numba is not installed") as record:
        assert clf.classify(246.0, 27.0) == "sunny"
        assert clf.classify(143.4, 45.0) == "overcast"
    assert len(record) == 1
    with pytest.raises(HybridtrackError, match="needs numba"):
        clf.score(246.0, 27.0, engine="numba")
    monkeypatch.undo()
    assert compiled.available()


def test_classifier_engines_agree_on_the_published_system():
    clf = FuzzyWeatherClassifier()
    raw = np.random.default_rng(11).uniform([20.0, -10.0], [320.0, 190.0], size=(5000, 2))
    numba_scores = clf.score(raw[:, 0], raw[:, 1], engine="numba")
    numpy_scores = clf.score(raw[:, 0], raw[:, 1], engine="numpy")
    np.testing.assert_allclose(numba_scores, numpy_scores, atol=1e-9, rtol=0)


@pytest.mark.parametrize("x", [np.zeros((3, 2)), np.zeros(3), [["a"]]])
def test_readings_of_the_wrong_shape_are_refused(x):
    system = CompiledSystem(random_system(3))
    with pytest.raises(HybridtrackError, match="readings must be"):
        evaluate(system, x if np.shape(x) != (3, 2) or len(system.system.inputs) != 2 else np.zeros((3, 5)))


@pytest.mark.parametrize("parallel_from", [10**9, 1], ids=["serial", "parallel"])
def test_every_compiled_path_matches_the_numpy_engine(parallel_from, monkeypatch):
    """The fused (no firing kept), two-pass, serial and multi-threaded kernels, on the shipped systems."""
    from pathlib import Path

    from hybridtrack.fuzzy import compiled
    from hybridtrack.fuzzy.fis import read_fis_system

    monkeypatch.setattr(compiled, "PARALLEL_FROM", parallel_from)
    here = Path(__file__).parent / "fuzzy_conformance"
    for system in (FuzzyWeatherClassifier().config.system(), read_fis_system(here / "mixed27.fis"),
                   read_fis_system(here / "tipper.fis")):
        x = readings(system, 3000, 9)
        x[:5] = np.nan
        compiled_system = CompiledSystem(system)
        reference = evaluate(compiled_system, x, engine="numpy")[0]
        fused = evaluate(compiled_system, x, engine="numba", with_firing=False)[0]
        two_pass, firing = evaluate(compiled_system, x, engine="numba")
        np.testing.assert_allclose(fused, reference, atol=1e-9, rtol=0)
        np.testing.assert_array_equal(fused, two_pass)
        np.testing.assert_allclose(firing, compiled_system.firing(x), atol=1e-12, rtol=0)


def test_threads_that_first_use_the_compiled_engine_at_once_take_turns():
    """A field's threads may make a process's first fuzzy call at the same moment: compiling the
    engine's helpers twice raised numba's "jit decorator was called on an already jitted function"
    in the thread that lost (a fresh process, as the engine is set up once per process)."""
    import subprocess
    import sys

    script = ("import threading\n"
              "from hybridtrack.fuzzy import compiled\n"
              "errors = []\n"
              "def go():\n"
              "    try:\n"
              "        compiled.available()\n"
              "    except Exception as exc:\n"
              "        errors.append(repr(exc))\n"
              "threads = [threading.Thread(target=go) for _ in range(4)]\n"
              "[t.start() for t in threads]\n"
              "[t.join() for t in threads]\n"
              "print(errors)\n")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0 and done.stdout.strip() == "[]", done.stdout + done.stderr


@pytest.mark.parametrize("shape", ["tri", "gauss", "flat top", "complement", "random"])
def test_term_tables_integrate_the_clipped_term_exactly(shape):
    """A term's table (area and first moment of min(s, term), piecewise cubic in s) against the
    clipped curve integrated directly: every cell split where the clip level cuts it, and each
    piece (linear, so its moment quadratic) integrated by Simpson's rule, exact for both."""
    from hybridtrack.fuzzy.engine import _TermTable

    rng = np.random.default_rng(7)
    y = np.linspace(0.0, 30.0, 301)
    curve = {"tri": np.clip(1 - abs(y - 12) / 5, 0, 1), "gauss": np.exp(-(y - 20) ** 2 / 8),
             "flat top": np.clip(np.minimum((y - 3) / 4, (25 - y) / 6), 0, 1),
             "complement": 1 - np.clip(1 - abs(y - 12) / 5, 0, 1),
             "random": np.interp(y, np.linspace(0, 30, 40), rng.random(40))}[shape]
    cells = np.flatnonzero(rng.random(300) < 0.7)  # a term's own cells need not be contiguous
    levels = np.concatenate([rng.random(40), [0.0, 0.5, 1.0]])
    area, moment = _TermTable.build(y, curve, cells, "min")(levels)
    for s, got_area, got_moment in zip(levels, area, moment):
        want = np.zeros(2)
        for c in cells:
            x = [y[c], y[c + 1]]
            if (curve[c] - s) * (curve[c + 1] - s) < 0:
                x.insert(1, y[c] + (s - curve[c]) * (y[c + 1] - y[c]) / (curve[c + 1] - curve[c]))
            for a, b in zip(x[:-1], x[1:]):
                v = np.minimum(s, np.interp([a, (a + b) / 2, b], [y[c], y[c + 1]], [curve[c], curve[c + 1]]))
                want += (b - a) / 6 * np.array([v[0] + 4 * v[1] + v[2], a * v[0] + 2 * (a + b) * v[1] + b * v[2]])
        np.testing.assert_allclose([got_area, got_moment], want, rtol=1e-11, atol=1e-12)
