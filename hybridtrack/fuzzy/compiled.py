"""The compiled Mamdani engine (numba): the same discretised system as `engine`, per reading.

Firing strengths come from the sampled input terms on their uniform grids. For the common
system (min implication, max aggregation, centroid, at most `MAX_SUBSET_UNITS` output
terms in use) the output needs no curve at all. Its value at sample ``j`` is
``f_j = max_u min(s_u, V_uj)`` (unit levels ``s``, sampled terms ``V``). Sort the levels
downwards, ``s_(1) >= s_(2) >= ...``, and let ``T_k`` be the units of the ``k`` highest
levels. Then ``f_j = sum_k [min(s_(k), M_kj) - min(s_(k+1), M_kj)]`` with
``M_kj = max_{u in T_k} V_uj``. Any weighted sum of the ``f_j``, such as the trapezoid area
and moment, is therefore a sum of differences of ``G_T(s) = sum_j w_j min(s, M_Tj)``, a
piecewise-linear function of ``s`` tabulated once per unit subset ``T`` (prefix sums over
its sorted breakpoints). The cut points, found by bisection on each term's monotone runs,
only change the few cells they fall in; those cells are integrated exactly and the
trapezoid they replace is taken off. Every other system runs a dense per-reading loop over
the cells with the same cut points. Both are exact to rounding against `engine`.

numba is a runtime dependency. Where it is missing the package falls back to the numpy
engine with one warning.
"""

from __future__ import annotations

import threading
import types

import numpy as np

from ..errors import HybridtrackError

__all__ = ["kernel_for", "available", "MAX_SUBSET_UNITS"]

#: Largest number of output units tabulated by subsets (2**units - 1 tables).
MAX_SUBSET_UNITS = 8

_STATE: dict = {}
_SETUP_LOCK = threading.Lock()
#: Held while a parallel kernel runs: numba's parallel kernels may not be launched from two threads
#: at once on every threading layer (its ``workqueue`` layer aborts the process), and one launch uses
#: every core already.
_PARALLEL_LOCK = threading.Lock()
_TOLERANCE = 1e-12  # as engine.MAXIMUM_TOLERANCE
_CHUNKS = 64
#: Readings below which the kernels run on one thread: starting threads costs more.
PARALLEL_FROM = 20_000
_STEPS = 1024  # even level steps indexing the sorted tables, so that a look-up searches a short stretch


def available() -> bool:
    """Whether numba imports here (warns once when it does not). The first call compiles the
    kernels' helpers into this module's namespace; threads that make it at once (a field's) take
    turns, as compiling a function twice fails."""
    if "numba" in _STATE:
        return _STATE["numba"]
    with _SETUP_LOCK:
        return _set_up()


def _set_up() -> bool:
    if "numba" not in _STATE:
        try:
            import numba
        except ImportError:
            _STATE["numba"] = False
            from ..kernel.jit import warn_missing

            warn_missing()
        else:
            if not _STATE.get("compiled"):
                # kernels call helpers through module globals: compile helpers first, then kernels
                namespace = globals()
                namespace["_prange"] = numba.prange
                for name in _HELPERS:
                    namespace[name] = numba.njit(cache=True, inline="always", error_model="numpy")(namespace[name])
                for name in _PARALLEL:
                    function = namespace[name]
                    serial = types.FunctionType(function.__code__, namespace, f"{name}_serial")
                    serial.__qualname__ = f"{name}_serial"
                    namespace[f"{name}_serial"] = numba.njit(cache=True, error_model="numpy")(serial)
                    namespace[name] = numba.njit(cache=True, parallel=True, error_model="numpy")(function)
                _STATE["compiled"] = True
            _STATE["numba"] = True
    return _STATE["numba"]


def kernel_for(system, *, required: bool = False):
    """The compiled kernel of a `CompiledSystem`, or None (numpy) where numba is missing."""
    if not available():
        if required:
            raise HybridtrackError("the numba engine needs numba, which is not installed (pip install numba)")
        return None
    kernel = getattr(system, "_kernel", None)
    if kernel is None:
        kernel = _Kernel(system)
        system._kernel = kernel
    return kernel


# -- kernels (plain Python, compiled by numba when it imports) -------------------------------------


def _firing(x, lo, scale, last, samples, nterms, ante, weights, is_or, and_prod, or_probor, firing):
    n_read, n_in = x.shape
    chunk = (n_read + _CHUNKS - 1) // _CHUNKS
    for c in _prange(_CHUNKS):
        mu = np.empty((n_in, samples.shape[2]))
        for n in range(c * chunk, min(n_read, (c + 1) * chunk)):
            _fire(x, n, lo, scale, last, samples, nterms, ante, weights, is_or, and_prod, or_probor, mu, firing, n)


def _fire(x, n, lo, scale, last, samples, nterms, ante, weights, is_or, and_prod, or_probor, mu, firing, row):
    """Every rule's firing for reading n of x into firing[row]; samples are (inputs, points, terms)."""
    n_in = x.shape[1]
    for i in range(n_in):
        v = x[n, i]
        if v != v:
            for r in range(ante.shape[0]):
                firing[row, r] = np.nan
            return
        pos = (v - lo[i]) * scale[i]
        if pos <= 0.0:
            j, t = 0, 0.0
        elif pos >= last[i]:
            j, t = last[i] - 1, 1.0
        else:
            j = int(pos)
            t = pos - j
        for k in range(nterms[i]):
            a = samples[i, j, k]
            mu[i, k] = a + t * (samples[i, j + 1, k] - a)
    for r in range(ante.shape[0]):
        value = -1.0
        for i in range(n_in):
            k = ante[r, i]
            if k == 0:
                continue
            m = mu[i, k - 1] if k > 0 else 1.0 - mu[i, -k - 1]
            if value < 0.0:
                value = m
            elif is_or[r]:
                value = max(value, m) if not or_probor else value + m - value * m
            else:
                value = min(value, m) if not and_prod else value * m
        firing[row, r] = value * weights[r]


def _levels(firing, n, rule_unit, n_units, aggregate_max, s):
    """Unit levels of reading n into s; False if the reading is NaN."""
    for u in range(n_units):
        s[u] = 0.0
    for r in range(rule_unit.shape[0]):
        u = rule_unit[r]
        if u < 0:
            continue
        f = firing[n, r]
        if f != f:
            return False
        if aggregate_max:
            s[u] = max(s[u], f)
        else:
            s[u] = f
    return True


def _table(s, block, table, offsets, steps):
    """G_T(s) for area and moment of the unit subset `block`; table rows are (breakpoint, P_a, Q_a, P_m, Q_m)."""
    q = min(int(s * (steps.shape[1] - 1)), steps.shape[1] - 2)  # s lies between level steps q and q + 1
    a, b = steps[block, q], steps[block, q + 1]  # first breakpoint >= s is in [a, b]
    while a < b:
        mid = (a + b) // 2
        if table[mid, 0] < s:
            a = mid + 1
        else:
            b = mid
    return table[a, 1] + s * table[a, 2], table[a, 3] + s * table[a, 4]


def _crossing(curves, u, a, b, rising, s, steps, r):
    """Cell j in [a, b) of a monotone run r of curve u where it crosses level s, or -1."""
    q = min(int(s * (steps.shape[1] - 1)), steps.shape[1] - 2)
    if rising:  # first point at or above s
        if not (curves[a, u] < s and curves[b, u] >= s):
            return -1
        lo, hi = steps[r, q], steps[r, q + 1]
        while lo < hi:
            mid = (lo + hi) // 2
            if curves[mid, u] >= s:
                hi = mid
            else:
                lo = mid + 1
    else:  # first point below s
        if not (curves[a, u] >= s and curves[b, u] < s):
            return -1
        lo, hi = steps[r, q + 1], steps[r, q]
        while lo < hi:
            mid = (lo + hi) // 2
            if curves[mid, u] < s:
                hi = mid
            else:
                lo = mid + 1
    return lo - 1


def _cubic(s, u, levels, coefficients, offsets, buckets, bucket_scale):
    """Area and moment of unit u's own cells (tabulated piecewise cubic in its level s)."""
    b = offsets[u + 1] - 1  # levels[offsets[u]..b]; intervals offsets[u]..b-1
    level = min(s, levels[b])
    lo = buckets[u, min(int(level * bucket_scale[u]), buckets.shape[1] - 1)]  # an interval at or below
    while lo > offsets[u] and levels[lo] > level:  # rounding in the bucket index
        lo -= 1
    while lo < b - 1 and levels[lo + 1] <= level:
        lo += 1
    t = (level - levels[lo]) / (levels[lo + 1] - levels[lo])
    i = lo - u  # coefficient rows: one fewer per unit than levels; area then moment
    c = coefficients
    return (c[i, 0] + t * (c[i, 1] + t * (c[i, 2] + t * c[i, 3])),
            c[i, 4] + t * (c[i, 5] + t * (c[i, 6] + t * c[i, 7])))


def _value(curves, s, n_units, j, frac, imp_min, agg):
    """Aggregated implied sets at fraction `frac` of cell j (agg 0 max, 1 sum, 2 probor)."""
    total = 0.0
    for u in range(n_units):
        a = curves[j, u]
        v = a + frac * (curves[j + 1, u] - a)
        v = min(s[u], v) if imp_min else s[u] * v
        if agg == 0:
            total = max(total, v)
        elif agg == 1:
            total += v
        else:
            total = total + v - total * v
    return total


def _cell_points(y, curves, s, n_units, j, imp_min, pts):
    """Edges and cut points of cell j, sorted, into pts; returns their count."""
    y1, y2 = y[j], y[j + 1]
    count = 1
    pts[0] = y1
    if imp_min:
        for u in range(n_units):
            v1, v2 = curves[j, u], curves[j + 1, u]
            if (v1 >= s[u]) != (v2 >= s[u]):
                c = y1 + (s[u] - v1) * (y2 - y1) / (v2 - v1)
                if y1 < c < y2:
                    k = count
                    while k > 1 and pts[k - 1] > c:
                        pts[k] = pts[k - 1]
                        k -= 1
                    pts[k] = c
                    count += 1
    pts[count] = y2
    return count + 1


def _cell_integral(y, curves, s, n_units, j, imp_min, agg, pts):
    count = _cell_points(y, curves, s, n_units, j, imp_min, pts)
    y1, width = y[j], y[j + 1] - y[j]
    area = moment = 0.0
    p = _value(curves, s, n_units, j, 0.0, imp_min, agg)
    for k in range(1, count):
        a, b = pts[k - 1], pts[k]
        q = _value(curves, s, n_units, j, (b - y1) / width, imp_min, agg)
        area += 0.5 * (b - a) * (p + q)
        moment += (b - a) * (p * (2 * a + b) + q * (a + 2 * b)) / 6.0
        p = q
    return area, moment


def _subset_centroid(firing, rule_unit, n_units, y, curves, levels, coefficients, level_offsets, buckets,
                     bucket_scale, shared, table, offsets, steps, run_unit, run_a, run_b, run_rising, run_steps, out):
    n_read = firing.shape[0]
    chunk = (n_read + _CHUNKS - 1) // _CHUNKS
    for c in _prange(_CHUNKS):
        s = np.empty(n_units)
        order = np.empty(n_units, np.int64)
        cells = np.empty(run_unit.shape[0] + 1, np.int64)
        pts = np.empty(n_units + 2)
        for n in range(c * chunk, min(n_read, (c + 1) * chunk)):
            out[n] = _subset_one(firing, n, rule_unit, n_units, y, curves, levels, coefficients, level_offsets,
                                 buckets, bucket_scale, shared, table, offsets, steps, run_unit, run_a, run_b,
                                 run_rising, run_steps, s, order, cells, pts)


def _fused_subset(x, lo, scale, last, samples, nterms, ante, weights, is_or, and_prod, or_probor, rule_unit, n_units,
                  y, curves, levels, coefficients, level_offsets, buckets, bucket_scale, shared, table, offsets, steps,
                  run_unit, run_a, run_b, run_rising, run_steps, out):
    """Firing and output in one pass per reading, for callers that do not keep the firing."""
    n_read, n_in = x.shape
    chunk = (n_read + _CHUNKS - 1) // _CHUNKS
    for c in _prange(_CHUNKS):
        mu = np.empty((n_in, samples.shape[2]))
        firing = np.empty((1, ante.shape[0]))
        s = np.empty(n_units)
        order = np.empty(n_units, np.int64)
        cells = np.empty(run_unit.shape[0] + 1, np.int64)
        pts = np.empty(n_units + 2)
        for n in range(c * chunk, min(n_read, (c + 1) * chunk)):
            _fire(x, n, lo, scale, last, samples, nterms, ante, weights, is_or, and_prod, or_probor, mu, firing, 0)
            out[n] = _subset_one(firing, 0, rule_unit, n_units, y, curves, levels, coefficients, level_offsets,
                                 buckets, bucket_scale, shared, table, offsets, steps, run_unit, run_a, run_b,
                                 run_rising, run_steps, s, order, cells, pts)


def _subset_one(firing, n, rule_unit, n_units, y, curves, levels, coefficients, level_offsets, buckets, bucket_scale,
                shared, table, offsets, steps, run_unit, run_a, run_b, run_rising, run_steps, s, order, cells, pts):
    """The centroid of reading n (min implication, max aggregation) from the tables."""
    if not _levels(firing, n, rule_unit, n_units, True, s):
        return np.nan
    area = moment = 0.0
    for u in range(n_units):  # cells where one unit alone is non-zero
        if s[u] > 0.0:
            a, m = _cubic(s[u], u, levels, coefficients, level_offsets, buckets, bucket_scale)
            area += a
            moment += m
    if shared:
        a, m = _shared_part(s, n_units, order, y, curves, table, offsets, steps, run_unit, run_a, run_b,
                            run_rising, run_steps, cells, pts)
        area += a
        moment += m
    return moment / area if area > 0.0 else np.nan


def _shared_part(s, n_units, order, y, curves, table, offsets, steps, run_unit, run_a, run_b,
                 run_rising, run_steps, cells, pts):
    """Area and moment over the cells where output units overlap (subset tables, cut cells exact)."""
    for u in range(n_units):  # insertion sort, highest level first
        k = u
        while k > 0 and s[order[k - 1]] < s[u]:
            order[k] = order[k - 1]
            k -= 1
        order[k] = u
    area = moment = 0.0
    block = 0
    for k in range(n_units):
        hi = s[order[k]]
        if hi <= 0.0:
            break
        lo = s[order[k + 1]] if k + 1 < n_units else 0.0
        block |= 1 << order[k]
        if hi > lo:
            a1, m1 = _table(hi, block - 1, table, offsets, steps)
            a0, m0 = _table(lo, block - 1, table, offsets, steps)
            area += a1 - a0
            moment += m1 - m0
    n_cells = 0
    for r in range(run_unit.shape[0]):  # runs cover the shared cells only
        u = run_unit[r]
        if s[u] > 0.0:
            j = _crossing(curves, u, run_a[r], run_b[r], run_rising[r], s[u], run_steps, r)
            if j >= 0:
                k = n_cells
                while k > 0 and cells[k - 1] > j:
                    cells[k] = cells[k - 1]
                    k -= 1
                cells[k] = j
                n_cells += 1
    for k in range(n_cells):
        j = cells[k]
        if k > 0 and cells[k - 1] == j:
            continue
        a, m = _cell_integral(y, curves, s, n_units, j, True, 0, pts)
        p = _value(curves, s, n_units, j, 0.0, True, 0)
        q = _value(curves, s, n_units, j, 1.0, True, 0)
        y1, y2 = y[j], y[j + 1]
        area += a - 0.5 * (y2 - y1) * (p + q)
        moment += m - (y2 - y1) * (p * (2 * y1 + y2) + q * (y1 + 2 * y2)) / 6.0
    return area, moment


def _dense(firing, rule_unit, n_units, aggregate_max, y, curves, imp_min, agg, method, out):
    """Any implication, aggregation and defuzzification (method 0 centroid, 1 bisector, 2 mom, 3 som, 4 lom)."""
    n_read = firing.shape[0]
    n_cells = y.shape[0] - 1
    chunk = (n_read + _CHUNKS - 1) // _CHUNKS
    for c in _prange(_CHUNKS):
        s = np.empty(n_units)
        pts = np.empty(n_units + 2)
        for n in range(c * chunk, min(n_read, (c + 1) * chunk)):
            if not _levels(firing, n, rule_unit, n_units, aggregate_max, s):
                out[n] = np.nan
                continue
            area = moment = 0.0
            for j in range(n_cells):
                a, m = _cell_integral(y, curves, s, n_units, j, imp_min, agg, pts)
                area += a
                moment += m
            if not area > 0.0:
                out[n] = np.nan
            elif method == 0:
                out[n] = moment / area
            elif method == 1:
                out[n] = _dense_bisector(y, curves, s, n_units, imp_min, agg, pts, 0.5 * area)
            else:
                out[n] = _dense_maximum(y, curves, s, n_units, imp_min, agg, pts, method)


def _dense_bisector(y, curves, s, n_units, imp_min, agg, pts, half):
    done = 0.0
    for j in range(y.shape[0] - 1):
        count = _cell_points(y, curves, s, n_units, j, imp_min, pts)
        y1, width = y[j], y[j + 1] - y[j]
        p = _value(curves, s, n_units, j, 0.0, imp_min, agg)
        for k in range(1, count):
            a, b = pts[k - 1], pts[k]
            q = _value(curves, s, n_units, j, (b - y1) / width, imp_min, agg)
            piece = 0.5 * (b - a) * (p + q)
            if done + piece >= half and piece > 0.0:
                rest = half - done
                slope = (q - p) / (b - a)
                return a + 2.0 * rest / (p + np.sqrt(max(p * p + 2.0 * slope * rest, 0.0))) if rest > 0.0 else a
            done += piece
            p = q
    return y[y.shape[0] - 1]


def _dense_maximum(y, curves, s, n_units, imp_min, agg, pts, method):
    top = 0.0
    n_cells = y.shape[0] - 1
    for j in range(n_cells):
        count = _cell_points(y, curves, s, n_units, j, imp_min, pts)
        for k in range(count):
            top = max(top, _value(curves, s, n_units, j, (pts[k] - y[j]) / (y[j + 1] - y[j]), imp_min, agg))
    floor = top * (1.0 - _TOLERANCE)
    total, number, first, final, previous = 0.0, 0, np.inf, -np.inf, -np.inf
    for j in range(n_cells):
        count = _cell_points(y, curves, s, n_units, j, imp_min, pts)
        upto = count if j == n_cells - 1 else count - 1  # a cell's end is the next cell's start
        for k in range(upto):
            x = pts[k]
            if x <= previous:
                continue
            previous = x
            if _value(curves, s, n_units, j, (x - y[j]) / (y[j + 1] - y[j]), imp_min, agg) >= floor:
                total += x
                number += 1
                first = min(first, x)
                final = max(final, x)
    if method == 2:
        return total / number
    return first if method == 3 else final


def _prange(n):  # replaced by numba.prange inside compiled kernels
    return range(n)


_HELPERS = ("_fire", "_subset_one", "_levels", "_table", "_crossing", "_cubic", "_shared_part", "_value",
            "_cell_points", "_cell_integral", "_dense_bisector", "_dense_maximum")
_PARALLEL = ("_firing", "_subset_centroid", "_fused_subset", "_dense")


class _Kernel:
    """A `CompiledSystem`'s arrays laid out for the kernels."""

    def __init__(self, system):
        spec = system.system
        n_in = spec.resolution[0]
        width = max(len(var.terms) for var in spec.inputs)
        # (inputs, points, terms): a reading's memberships of one input share a cache line
        self.samples = np.zeros((len(spec.inputs), n_in, width))
        for i, terms in enumerate(system.input_samples):
            self.samples[i, :, :len(terms)] = np.transpose(terms)
        self.nterms = np.array([len(var.terms) for var in spec.inputs], np.int64)
        self.lo = np.array([var.universe[0] for var in spec.inputs])
        self.scale = np.array([(n_in - 1) / (var.universe[1] - var.universe[0]) for var in spec.inputs])
        self.last = np.full(len(spec.inputs), n_in - 1, np.int64)
        self.ante = np.ascontiguousarray(system.antecedents, np.int64)
        self.weights = np.ascontiguousarray(system.weights, float)
        self.is_or = np.ascontiguousarray(system.is_or, np.bool_)
        self.and_prod = spec.methods.and_method == "prod"
        self.or_probor = spec.methods.or_method == "probor"
        methods = spec.methods
        self.method = ("centroid", "bisector", "mom", "som", "lom").index(methods.defuzzification)
        self.imp_min = methods.implication == "min"
        self.agg = ("max", "sum", "probor").index(methods.aggregation)
        self.outputs = []
        for stage, units in zip(system.stages, system.rule_units):
            curves = np.ascontiguousarray(stage.curves.T)  # (points, units): a cell's values share a cache line
            subset = (self.method == 0 and self.imp_min and self.agg == 0
                      and 0 < curves.shape[1] <= MAX_SUBSET_UNITS)
            self.outputs.append((np.ascontiguousarray(units, np.int64), stage.y, curves,
                                 _stage_tables(stage) if subset else None))

    def evaluate(self, x: np.ndarray, with_firing: bool = True) -> tuple[np.ndarray, np.ndarray | None]:
        """Every output (N, outputs) and every rule's firing (N, rules; None unless `with_firing`)."""
        if len(x) < PARALLEL_FROM:
            return self._evaluate(x, with_firing, "_serial")  # the serial twins are made in `available`
        with _PARALLEL_LOCK:
            return self._evaluate(x, with_firing, "")

    def _evaluate(self, x: np.ndarray, with_firing: bool, suffix: str) -> tuple[np.ndarray, np.ndarray | None]:
        kernels = globals()
        inputs = (self.lo, self.scale, self.last, self.samples, self.nterms, self.ante, self.weights, self.is_or,
                  self.and_prod, self.or_probor)
        out = np.empty((len(x), len(self.outputs)))
        if not with_firing and len(self.outputs) == 1 and self.outputs[0][3] is not None:
            units, y, curves, tables = self.outputs[0]
            kernels[f"_fused_subset{suffix}"](x, *inputs, units, curves.shape[1], y, curves, *tables, out[:, 0])
            return out, None
        firing = np.empty((len(x), len(self.weights)))
        kernels[f"_firing{suffix}"](x, *inputs, firing)
        for o, (units, y, curves, tables) in enumerate(self.outputs):
            value = np.empty(len(x))
            if tables is not None:
                kernels[f"_subset_centroid{suffix}"](firing, units, curves.shape[1], y, curves, *tables, value)
            else:
                kernels[f"_dense{suffix}"](firing, units, curves.shape[1], self.agg == 0, y, curves, self.imp_min,
                                           self.agg, self.method, value)
            out[:, o] = value
        return out, firing


def _stage_tables(stage) -> tuple:
    """Per-unit cubic tables, subset tables and monotone runs of an output stage, built once per stage."""
    tables = stage.__dict__.get("_kernel_tables")
    if tables is None:
        levels = np.concatenate([t.levels for t in stage.tables])
        coefficients = np.ascontiguousarray(np.concatenate([np.hstack([t.area, t.moment]) for t in stage.tables]))
        level_offsets = np.cumsum([0] + [len(t.levels) for t in stage.tables]).astype(np.int64)
        cells = np.zeros(len(stage.y) - 1, bool)
        cells[stage.shared_cells] = True
        curves = np.ascontiguousarray(stage.curves)
        buckets, bucket_scale = _buckets(stage.tables, level_offsets)
        tables = (levels, coefficients, level_offsets, buckets, bucket_scale, bool(cells.any()),
                  *_subset_tables(stage.y, curves, cells), *_runs(curves, cells))
        object.__setattr__(stage, "_kernel_tables", tables)
    return tables


def _buckets(tables, offsets, count: int = 4096) -> tuple[np.ndarray, np.ndarray]:
    """For each unit, the last level interval starting at or below each of `count` even level steps."""
    buckets = np.zeros((len(tables), count), np.int64)
    scale = np.zeros(len(tables))
    for u, table in enumerate(tables):
        top = table.levels[-1]
        scale[u] = count / top if top > 0 else 0.0
        steps = np.arange(count) * (top / count)
        buckets[u] = offsets[u] + np.clip(np.searchsorted(table.levels, steps, side="right") - 1, 0,
                                          len(table.levels) - 2)
    return buckets, scale


def _subset_tables(y: np.ndarray, curves: np.ndarray, cells: np.ndarray) -> tuple:
    """G_T(s) of every non-empty unit subset T for the trapezoid area and moment over `cells` (mask)."""
    dy = np.where(cells, np.diff(y), 0.0)
    w_area = np.zeros(len(y))
    w_area[:-1] += 0.5 * dy
    w_area[1:] += 0.5 * dy
    w_moment = np.zeros(len(y))
    w_moment[:-1] += dy * (2 * y[:-1] + y[1:]) / 6.0
    w_moment[1:] += dy * (y[:-1] + 2 * y[1:]) / 6.0
    blocks = [[] for _ in range(5)]
    offsets = [0]
    for mask in range(1, 2 ** len(curves) if cells.any() else 1):
        top = curves[[u for u in range(len(curves)) if mask >> u & 1]].max(axis=0)
        breakpoints, index = np.unique(top, return_inverse=True)
        per = [np.bincount(index, weights=w, minlength=len(breakpoints)) for w in (w_area * top, w_area,
                                                                                   w_moment * top, w_moment)]
        blocks[0].append(np.append(breakpoints, np.inf))
        for k, (weighted, plain) in enumerate(((per[0], per[1]), (per[2], per[3]))):
            blocks[1 + 2 * k].append(np.concatenate([[0.0], np.cumsum(weighted)]))
            blocks[2 + 2 * k].append(plain.sum() - np.concatenate([[0.0], np.cumsum(plain)]))
        offsets.append(offsets[-1] + len(breakpoints) + 1)
    levels = np.linspace(0.0, 1.0, _STEPS + 1)
    steps = np.array([offsets[k] + np.searchsorted(b[:-1], levels) for k, b in enumerate(blocks[0])], np.int64)
    columns = [np.concatenate(b) if b else np.zeros(1) for b in blocks]
    return (np.ascontiguousarray(np.stack(columns, axis=1)), np.array(offsets, np.int64),
            steps.reshape(-1, _STEPS + 1))


def _runs(curves: np.ndarray, cells: np.ndarray) -> tuple:
    """Monotone runs of each sampled curve within each stretch of `cells`: unit, first and last point, rising."""
    unit, first, last, rising = [], [], [], []
    edges = np.flatnonzero(np.diff(np.concatenate([[0], cells.astype(int), [0]])))
    for begin, end in zip(edges[::2], edges[1::2]):  # cells begin..end-1, points begin..end
        for u, values in enumerate(curves):
            start, direction = begin, 0
            for j, step in enumerate(np.sign(np.diff(values[begin:end + 1])), start=begin):
                if step == 0 or step == direction:
                    continue
                if direction:
                    unit.append(u), first.append(start), last.append(j), rising.append(direction > 0)
                    start = j
                direction = step
            unit.append(u), first.append(start), last.append(end), rising.append(direction >= 0)
    levels = np.linspace(0.0, 1.0, _STEPS + 1)
    steps = np.zeros((len(unit), _STEPS + 1), np.int64)
    for r, (u, a, b, up) in enumerate(zip(unit, first, last, rising)):
        values = curves[u, a:b + 1]
        if up:  # first point at or above each level
            steps[r] = a + np.searchsorted(values, levels, side="left")
        else:  # first point below each level
            steps[r] = b + 1 - np.searchsorted(values[::-1], levels, side="left")
    return (np.array(unit, np.int64), np.array(first, np.int64), np.array(last, np.int64),
            np.array(rising, np.bool_), steps)
