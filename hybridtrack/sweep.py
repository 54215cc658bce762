"""Parameter sweeps on Dask: a grid of runs, one tidy table, the trade-off it asked about.

A sweep file (TOML) names a base run and a grid::

    [base]                      # every run starts from this
    site = "lanzhou"
    collector = "fresnel"
    strategy = "hybrid"
    start = 2021-06-19
    days = 3
    weather = "mixed"

    [grid]                      # every combination of these is one run
    "drive.deadband" = [0.1, 0.2, 0.4]
    seed = [0, 1, 2]

    [plot]                      # the trade-off to draw (default: moves against rms)
    x = "moves"
    y = "rms"

Run keys are ``site``, ``collector``, ``strategy``, ``start``, ``days``, ``weather``, ``freq``,
``seed`` (seeds the synthetic sky and the sensor noise) and ``gusts_per_day``; a dotted key is a
field of the run config in its TOML layout (``drive.deadband``, ``controller.sun_model``,
``imperfections.encoder_offset``), or of the collector (``collector.row_distance``). A base
``[base.config]`` table is a whole run config. Keys and their places are checked before the sweep
starts, and so are the base values the grid leaves alone (every run would fail on them), by the
code the runs check them with: each run key alone, then the collector, the synthetic weather (its
dates, one weather a day, its span against the memory budget) and the config as a whole when the
grid sets none of their keys. A bad grid value is checked by its run, so it fails that run only;
the run's error names the grid's key and value (``grid.drive.deadband = -1: ...``).

Every run is independent and seeded, and the table is sorted by run number, so it is the same
whatever the number of workers. A run that fails is kept, with its error, and the sweep goes on.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import itertools
import numbers
import signal
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from . import params
from .cluster import WorkersGone, check_where, close, cores, dask_client, finished, holding_interrupts
from .errors import HybridtrackError, blamed
from .outputs import claim, output_folder, removing_empty_folders, together, write

__all__ = ["Sweep", "SweepInterrupted", "run_sweep", "run_one", "save_sweep", "pareto_front", "plot_tradeoff", "RUN_KEYS", "METRICS",
           "MAXIMISED"]

#: Keys of a run besides its config, with their defaults.
RUN_KEYS = {"site": "lanzhou", "collector": "trough-ns", "strategy": "hybrid", "start": "2021-06-21", "days": 1,
            "weather": "mixed", "freq": "1min", "seed": 0, "gusts_per_day": 0.0}
#: The config key a run's ``strategy`` sets: refused beside it, which would replace it in every run.
STRATEGY_KEY = "controller.strategy"
#: The metrics of every run's row (from its summary), in the table's order.
METRICS = ("rms", "p95", "max", "mean", "within_0_5_deg", "energy_capture", "moves", "travel_deg", "mode_switches",
           "stow_events", "faults", "steps")
#: Metrics that count things (whole numbers; empty where a run failed).
COUNTS = ("moves", "mode_switches", "stow_events", "faults", "steps")
#: The most runs one sweep may hold (each is a task on the scheduler and a row of the table).
MAX_RUNS = 100_000
#: The most values of a text grid key the plot names in a legend; more go on a colour bar.
LEGEND_MOST = 12
#: Metrics where more is better (the others: less is better).
MAXIMISED = ("energy_capture", "within_0_5_deg")


@dataclass(frozen=True)
class Sweep:
    """A parsed sweep: the base run, the grid (key -> values, in file order), the plot axes."""

    base: dict
    grid: dict
    x: str = "moves"
    y: str = "rms"
    source: str = dataclasses.field(default="sweep", compare=False)  # where it was read, not what it runs

    def __post_init__(self) -> None:
        """A sweep built directly is checked as a file's is (`from_dict`), and its values made what
        its file holds: built so, a numpy seed had ended in a TypeError writing ``sweep.toml``, a
        misspelt key had run (every row failed), and x = y had been written and then refused."""
        if not isinstance(self.source, str):
            raise HybridtrackError(f"sweep: source must be text, got {self.source!r:.60}")
        for name in ("base", "grid"):
            _table_of_text_keys(getattr(self, name), self.source, f"[{name}]")
        for axis in ("x", "y"):
            if not isinstance(getattr(self, axis), str):
                raise HybridtrackError(f"{self.source}: plot.{axis}: must be a metric's name, "
                                       f"got {getattr(self, axis)!r:.60}")
        base, grid, x, y = _checked(self.to_dict(), self.source)
        for name, value in (("base", base), ("grid", grid), ("x", x), ("y", y)):
            object.__setattr__(self, name, value)

    @classmethod
    def from_toml(cls, path) -> Sweep:
        from .io import read_toml

        return cls.from_dict(read_toml(path, "sweep", if_empty="a sweep file needs a [grid] table at least"), source=str(path))

    @classmethod
    def from_dict(cls, data: dict, *, source: str = "sweep") -> Sweep:
        """A sweep from its TOML layout (``base``, ``grid``, ``plot`` tables), checked."""
        return cls(*_checked(data, source), source)

    def to_dict(self) -> dict:
        """The sweep in its TOML layout; `from_dict` reads it back equal."""
        base = {k: v for k, v in self.base.items() if k != "config"}
        if self.base.get("config"):
            base["config"] = self.base["config"]
        return {"base": base, "grid": dict(self.grid), "plot": {"x": self.x, "y": self.y}}

    def to_toml(self, path) -> Path:
        """Write the sweep as TOML; `from_toml` reads it back equal."""
        from .io import write_toml

        return write_toml(self.to_dict(), path)

    def runs(self) -> list[dict]:
        """Every run of the grid, in order: the grid's values vary fastest from the last key."""
        keys = list(self.grid)
        return [{"run": i, **dict(zip(keys, values))}
                for i, values in enumerate(itertools.product(*(self.grid[k] for k in keys)))]


def _checked(data: dict, source: str) -> tuple[dict, dict, str, str]:
    """A sweep in its TOML layout (`Sweep.to_dict`), checked: its base (with its ``config``), its
    grid and its plot's axes, each value as its file holds it (`_written`)."""
    _table_of_text_keys(data, source, "the sweep")
    unknown = [key for key in data if key not in ("base", "grid", "plot")]
    if unknown:
        raise HybridtrackError(f"{source}: {unknown[0]}: unknown table; a sweep has [base], [grid] and [plot]")
    base = dict(_table_of_text_keys(data.get("base", {}), source, "[base]"))
    config = _table_of_text_keys(base.pop("config", {}), source, "[base.config]")
    base = {k: _written(v, f"base.{k}", source) for k, v in _dotted(base, source, "base").items()}
    config = _written(config, "base.config", source)
    grid = {k: _written(v, f"grid.{k}", source)
            for k, v in _dotted(_table_of_text_keys(data.get("grid", {}), source, "[grid]"), source, "grid").items()}
    plot = _table_of_text_keys(data.get("plot", {}), source, "[plot]")
    for key in base:
        _check_key(key, source, "base")
    _refuse_given_twice(base, config, source)
    _check_base(base, config, grid, source)
    _check_grid(grid, source, given="grid" in data)
    _canonical_names(base, grid)
    x, y = _plot_axes(plot, source)
    return {**base, "config": config}, dict(grid), x, y


def _check_grid(grid: dict, source: str, *, given: bool) -> None:
    """Refuse a grid that is empty (or not `given`), a key no run reads, a value that is no
    non-empty list, a value given twice, or more runs than `MAX_RUNS`."""
    if not grid:
        raise HybridtrackError(f"{source}: [grid] {'is empty' if given else 'is missing'}; give at least one key with "
                               "a list of values")
    for key, values in grid.items():
        _check_key(key, source, "grid")
        if not isinstance(values, list) or not values:
            raise HybridtrackError(f"{source}: grid.{key}: must be a non-empty list of values, got {values!r}")
        _refuse_repeats(key, values, source)
    count = int(np.prod([len(v) for v in grid.values()], dtype=float))
    if count > MAX_RUNS:
        raise HybridtrackError(f"{source}: the grid makes {count:,} runs; at most {MAX_RUNS:,} in one sweep")


def _canonical_names(base: dict, grid: dict) -> None:
    """The base's and the grid's weathers and sites, in place, by the names the runs give them
    (after the grid's repeats are judged, by the names as given)."""
    for key, canonical in (("weather", _canonical_weather), ("site", _canonical_site)):
        if key in grid:
            grid[key] = [canonical(value) for value in grid[key]]
        if key in base:
            base[key] = canonical(base[key])


def _plot_axes(plot: dict, source: str) -> tuple[str, str]:
    """The plot's two metrics (``moves`` and ``rms`` by default), refused unless metrics, and two."""
    for axis in ("x", "y"):
        if axis in plot and plot[axis] not in METRICS:
            raise HybridtrackError(f"{source}: plot.{axis}: {plot[axis]!r} is not a metric; "
                                   f"choose from {', '.join(METRICS)}")
    unknown = sorted(set(plot) - {"x", "y"})
    if unknown:
        raise HybridtrackError(f"{source}: plot.{unknown[0]}: unknown key; known: x, y")
    x, y = plot.get("x", "moves"), plot.get("y", "rms")
    if x == y:  # one metric against itself: a diagonal, its "front" one point
        unsaid = "".join(f" ({axis} by default)" for axis in ("x", "y") if axis not in plot)
        raise HybridtrackError(f"{source}: plot.x and plot.y are both {x!r}{unsaid}; a trade-off needs two metrics")
    return x, y


def _table_of_text_keys(table, source: str, name: str) -> dict:
    """`table`, refused unless a table (a dict) whose keys are text, as TOML makes them."""
    if not isinstance(table, dict):
        raise HybridtrackError(f"{source}: {name} must be a table, got {table!r:.80}")
    for key in table:
        if not isinstance(key, str):
            raise HybridtrackError(f"{source}: {name}: key {key!r} is not text; keys are names such as drive.deadband")
    return table


def _dotted(table: dict, source: str, name: str) -> dict:
    """`table` with each sub-table's keys as dotted keys, in order: TOML reads ``drive.deadband =
    [...]`` unquoted, and ``[grid.drive]``, as a table ``drive`` holding ``deadband``, the key a
    sweep writes ``"drive.deadband"``. No value of a sweep key is a table (a grid's are lists)."""
    flat: dict = {}

    def add(prefix: str, node: dict) -> None:
        for key, value in _table_of_text_keys(node, source, f"[{name}{'.' if prefix else ''}{prefix[:-1]}]").items():
            dotted = prefix + key
            if isinstance(value, dict):
                add(dotted + ".", value)
            elif dotted in flat:
                raise HybridtrackError(f"{source}: {name}.{dotted}: given twice, as \"{dotted}\" and as a table "
                                       f"({dotted.rpartition('.')[0]}); give it once")
            else:
                flat[dotted] = value

    add("", table)
    return flat


def _written(value, where: str, source: str):
    """`value` as its sweep file holds it: numpy's numbers as the Python numbers they are (a grid
    of ``list(np.arange(3))``), tuples as lists; refused if TOML cannot hold it. Each ran every
    run, then failed with a TypeError writing ``sweep.toml``, after the table."""
    import datetime as dt

    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, (list, tuple)):
        return [_written(v, where, source) for v in value]
    if isinstance(value, dict):
        return {k: _written(v, f"{where}.{k}", source) for k, v in value.items()}
    if isinstance(value, (bool, int, float, str, dt.date, dt.time)):
        return value
    shown = " ".join(repr(value).split())  # one line: a Series' repr runs over several
    raise HybridtrackError(f"{source}: {where}: {shown:.60} cannot be written in a sweep file; a sweep holds text, "
                           "numbers, true or false, dates and times, lists and tables (as TOML)")


def _alike(value):
    """What two grid values that make the same run have alike: equal numbers (1 and 1.0) but not a
    true beside a 1 (a seed of true is refused by its run, 1 is not), lists by their items."""
    if isinstance(value, bool):
        return bool, value
    if isinstance(value, (list, tuple)):
        return list, tuple(_alike(v) for v in value)
    if isinstance(value, dict):
        return dict, tuple((k, _alike(v)) for k, v in value.items())
    return None, value


def _refuse_repeats(key: str, values: list, source: str) -> None:
    """Refuse a grid value given twice, or two that its runs read alike (`_run_reading`): every
    combination with it would run twice, two rows alike in all but their number, and a mean over
    them counted double."""
    seen: dict = {}
    check = _key_checks().get(key)
    for number, value in enumerate(values, 1):
        try:
            first = seen.setdefault(_run_reading(key, value, check), number)
        except TypeError:  # unhashable in a way TOML does not make: judged by its run
            continue
        if first != number and _alike(values[first - 1]) == _alike(value):
            raise HybridtrackError(f"{source}: grid.{key}: {_shown(value)} is given twice (values {first} and "
                                   f"{number}); each value makes its runs once")
        if first != number:
            raise HybridtrackError(f"{source}: grid.{key}: {_shown(value)} is {_shown(values[first - 1])} again "
                                   f"(values {first} and {number}): their runs are the same; each value makes its "
                                   "runs once")


def _run_reading(key: str, value, check):
    """What a run makes of a grid value of `key`, to tell repeats by: a run key's value as its
    `check` (`_key_checks`) reads it (a date and its text, '60min' and '1h', 'Lanzhou' and
    'lanzhou', 'sunny' and ['sunny'] had each made the same runs twice); any other value, or one
    its run refuses (which fails each of its runs on its own), by `_alike`."""
    try:
        read = check(value) if check is not None else None
    except HybridtrackError:
        read = None
    if read is None:
        return _alike(value)
    if key == "freq":  # the step, not its text
        from .times import parse_freq

        read = parse_freq(read)
    return key, tuple(read) if isinstance(read, list) else read


def _known_keys() -> list[str]:
    """Every key a sweep takes: run keys, ``collector.FIELD`` and dotted config fields."""
    from .collectors import Collector
    from .simulation import SimulationConfig

    keys = [*RUN_KEYS, *(f"collector.{f.name}" for f in dataclasses.fields(Collector) if f.name != "kind")]

    def fields(node, prefix: str) -> None:
        for f in dataclasses.fields(node):
            value = getattr(node, f.name)
            if dataclasses.is_dataclass(value):
                fields(value, f"{prefix}{f.name}.")
            elif prefix + f.name != STRATEGY_KEY:
                keys.append(prefix + f.name)

    fields(SimulationConfig(), "")
    return keys


def _check_key(key: str, source: str, table: str) -> None:
    """A run key, a collector field or a config field that exists; its value is checked by the run."""
    from .collectors import Collector
    from .simulation import SimulationConfig

    if key in RUN_KEYS:
        return
    if key == STRATEGY_KEY:  # the run key would replace it in every run, without a word
        raise HybridtrackError(f"{source}: {table}.{key}: a run's strategy is the run key strategy; "
                               f"write strategy = ... in [{table}]")
    head, _, rest = key.partition(".")
    if head == "collector" and rest in {f.name for f in dataclasses.fields(Collector)} - {"kind"}:
        return
    node = SimulationConfig()
    for part in key.split("."):
        if not dataclasses.is_dataclass(node) or part not in {f.name for f in dataclasses.fields(node)}:
            import difflib

            near = difflib.get_close_matches(key, _known_keys(), n=1)
            hint = f"did you mean {near[0]}? " if near else ""
            raise HybridtrackError(f"{source}: {table}.{key}: unknown key; {hint}use {', '.join(RUN_KEYS)}, "
                                   "collector.FIELD or a dotted config key such as drive.deadband")
        node = getattr(node, part)
    if dataclasses.is_dataclass(node):
        raise HybridtrackError(f"{source}: {table}.{key}: is a whole table; name one of its fields")


def _refuse_given_twice(base: dict, config: dict, source: str) -> None:
    """Refuse a config value the base gives twice, dotted (``drive.deadband``) and in
    ``[base.config]``, and a ``[base.config]`` seed or strategy, which each run's ``seed`` and
    ``strategy`` replace: one of the two would be dropped without a word."""
    if "seed" in config:
        raise HybridtrackError(f"{source}: [base.config] seed: each run's seed is the run key seed; set it in [base] "
                               "or [grid]")
    if isinstance(config.get("controller"), dict) and "strategy" in config["controller"]:
        raise HybridtrackError(f"{source}: [base.config.controller] strategy: each run's strategy is the run key "
                               "strategy; set it in [base] or [grid]")
    for key in base:
        if key in RUN_KEYS or key.startswith("collector."):
            continue
        if _config_value(config, key) is not None:
            raise HybridtrackError(f"{source}: base.{key} and [base.config] both set {key}; give it once")


def _config_value(config: dict, key: str):
    """The value a dotted `key` (``drive.deadband``) names in a ``[base.config]`` table, or None."""
    node = config
    for part in key.split("."):
        node = node.get(part) if isinstance(node, dict) else None
    return node


def _check_base(base: dict, config: dict, grid: dict, source: str) -> None:
    """Refuse, before a cluster starts, a base value every run would fail on, checked as the runs
    check it: each run key the grid does not set, then the collector and the weather when the grid
    sets none of their keys, and the config without the dotted keys the grid sets. A value checked
    with a key the grid sets is left to the runs (a grid value fails its own run only)."""
    _refuse_set_by_both(base, config, grid, source)
    fixed = {key: value for key, value in base.items() if key not in grid}
    for key in RUN_KEYS.keys() & fixed.keys():
        _refuse_in_base([key], source, functools.partial(_key_checks()[key], fixed[key]))
    spec = {**RUN_KEYS, **fixed}
    for keys, make in ((_collector_keys(spec), _collector), (WEATHER_KEYS, _weather_arguments)):
        if not grid.keys() & set(keys):
            _refuse_in_base([key for key in fixed if key in keys], source, functools.partial(make, spec))
    dotted = {k: v for k, v in fixed.items() if "." in k and not k.startswith("collector.")}
    _config_from(config, dotted, f"{source}: base")  # the base config must stand on its own


def _refuse_set_by_both(base: dict, config: dict, grid: dict, source: str) -> None:
    """Refuse a key the base sets that the grid sets too (``seed = 7`` beside ``seed = [0, 1]``, a
    dotted ``drive.deadband`` or ``[base.config.drive] deadband`` beside a grid deadband): every run
    takes the grid's value, and the base's had been dropped without a word."""
    for key in grid:
        in_config = "." in key and _config_value(config, key) is not None
        where = f"base.{key}" if key in base else "[base.config]" if in_config else None
        if where is not None:
            raise HybridtrackError(f"{source}: {where} and grid.{key} both set {key}, and every run takes the grid's "
                                   "value; give it once (in [grid] to vary it)")


def _refuse_in_base(keys: list, source: str, check) -> None:
    """Call `check`; its refusal names the sweep and the base `keys` it came from."""
    try:
        check()
    except HybridtrackError as exc:
        raise HybridtrackError(f"{source}: {', '.join(f'base.{key}' for key in keys) or 'base'}: {exc}") from None


def _whole_days(days) -> int:
    if isinstance(days, bool) or not isinstance(days, int) or not 1 <= days <= 3660:
        raise HybridtrackError(f"days must be a whole number from 1 to 3660, got {days!r}")
    return days


def _strategy(name) -> str:
    from .control import STRATEGIES

    if name not in STRATEGIES:
        raise HybridtrackError(f"unknown strategy {name!r}; choose from {', '.join(STRATEGIES)}")
    return name


def _weather_names(value) -> list[str]:
    """The weather's names as the runs read them (`hybridtrack.sky.weather_name`: ``Sunny`` is
    ``sunny``): one for every day, or one per day (a list, or text with commas)."""
    from .sky import WEATHERS, weather_name

    names = value if isinstance(value, list) else str(value).split(",")
    if not names:
        raise HybridtrackError("weather is an empty list; give a weather, or one per day")
    for name in names:
        if weather_name(name) not in WEATHERS:
            raise HybridtrackError(f"unknown weather {name!r}; choose from {', '.join(WEATHERS)} or a per-day list")
    return [weather_name(name) for name in names]


def _canonical_weather(value):
    """A base or grid value of ``weather`` with its names as the runs read them (`_weather_names`),
    in its own shape (text, or a list), so that the table, the plot and ``sweep.toml`` name the
    weather the runs made: ``Sunny`` had been refused where ``Lanzhou`` was a site. A value the
    runs refuse is kept as written, for them to refuse by its name."""
    try:
        names = _weather_names(value)
    except HybridtrackError:
        return value
    return names if isinstance(value, list) else ",".join(names)


def _canonical_site(value):
    """A base or grid value of ``site`` by the name the runs give it (``Lanzhou`` is ``lanzhou``),
    so that the table and its plot name one site one way, as the ablation's table does; a value
    the runs refuse is kept as written, for them to refuse by its name."""
    from . import sites

    try:
        return sites.get(value).name if isinstance(value, str) else value
    except HybridtrackError:
        return value


def _step(freq) -> str:
    """The step as the text `hybridtrack.sky.synthetic` takes, such as ``"1min"``, refused beyond
    the longest a run takes (`hybridtrack.simulation.LONGEST_STEP`): a base ``freq = "2h"`` (or
    ``"1D"``, one step a day) had been taken, to fail every run once the cluster was up."""
    from .simulation import run_step

    if not isinstance(freq, str):
        raise HybridtrackError(f"freq must be a step such as '1min' or '10s', got {freq!r}")
    run_step(freq)
    return freq


def _first_day(start):
    """The first day of a run: a date (a date and time is refused, as a time of day would be lost)."""
    from .times import parse_date

    return parse_date(_plain(start))


def _key_checks() -> dict:
    """Each run key's check on its own, as its run converts it."""
    from . import sites
    from .collectors import Collector

    return {"site": sites.get, "collector": Collector, "strategy": _strategy, "start": _first_day,
            "days": _whole_days, "weather": _weather_names, "freq": _step, "seed": params.seed,
            "gusts_per_day": _gusts}


def _gusts(value) -> float:
    return params.number(value, "gusts_per_day", 0, 200)


#: The run keys a run's synthetic weather is made from (`_weather_arguments`).
WEATHER_KEYS = ("site", "start", "days", "weather", "freq", "gusts_per_day")


def _weather_arguments(spec: dict) -> tuple:
    """The arguments of a run's synthetic weather (`_frame` but its seed), checked as the run uses
    them, its span's size against the memory budget included, without making the weather."""
    import datetime as dt

    from . import sites
    from .sky import check_weather
    from .times import local_range

    site, first, days = sites.get(spec["site"]), _first_day(spec["start"]), _whole_days(spec["days"])
    names, freq = _weather_names(spec["weather"]), _step(spec["freq"])
    check_weather(names if len(names) > 1 else names[0], days)
    last = (first + dt.timedelta(days=days - 1)).isoformat()
    local_range(first, site.tz, end_date=last, freq=freq)  # refuses a span past 2261 or over the memory budget
    return site, first.isoformat(), days, ",".join(names), freq, _gusts(spec["gusts_per_day"])


def _collector_keys(spec: dict) -> list[str]:
    return ["collector", *(key for key in spec if key.startswith("collector."))]


def _collector(spec: dict):
    """A run's collector: its kind and the geometry its ``collector.FIELD`` keys give."""
    from .collectors import Collector

    geometry = {k.partition(".")[2]: (tuple(v) if isinstance(v, list) else v)
                for k, v in spec.items() if k.startswith("collector.")}
    return Collector(spec["collector"], **geometry)


def _config_from(base: dict, dotted: dict, source: str):
    """The run config: the base table with the dotted values set in it."""
    import copy

    from .simulation import SimulationConfig

    data = copy.deepcopy(base)
    for key, value in dotted.items():
        *path, last = key.split(".")
        node = data
        for part in path:
            node = node.setdefault(part, {})
        node[last] = value
    return SimulationConfig.from_dict(data, source=source)


@functools.lru_cache(maxsize=8)
def _frame(site, start: str, days: int, weather: str, freq: str, gusts_per_day: float, seed: int) -> pd.DataFrame:
    """The synthetic weather of a run, from `_weather_arguments`; runs that differ only in their
    config share it (per worker)."""
    import datetime as dt

    from .sky import synthetic

    first = dt.date.fromisoformat(start)
    sky = weather.split(",") if "," in weather else weather
    return synthetic(site, first, first + dt.timedelta(days=days - 1), weather=sky, freq=freq, seed=seed,
                     gusts_per_day=gusts_per_day)


def _plain(value):
    """A table cell: dates and lists as text (`_text`), everything else as it is."""
    return _text(value) if isinstance(value, (list, tuple)) or hasattr(value, "isoformat") else value


def _text(value) -> str:
    """A grid value as text, as its TOML wrote it: ``true`` (not Python's ``True``), a list's
    items joined by commas, a table's as ``{key = value, ...}``, a date in ISO form."""
    if isinstance(value, (bool, np.bool_)):
        return "true" if value else "false"
    if isinstance(value, (list, tuple)):
        return ",".join(_text(v) for v in value)
    if isinstance(value, dict):
        return "{" + ", ".join(f"{key} = {_text(v)}" for key, v in value.items()) + "}"
    if hasattr(value, "isoformat"):
        return value.isoformat()
    return str(value)


def run_one(base: dict, grid_values: dict, source: str = "sweep", sweep_steps: int = 0) -> dict:
    """One run of a sweep: its row of the table. Never raises: a failure is the row's ``error``,
    which names the grid's key and value (``grid.drive.deadband = -1: ...``) when the value the
    run refused came from the grid. The config's ``engine = "auto"`` is decided on the sweep's
    steps in all (`sweep_steps`; `hybridtrack.kernel.decided`), not on the run's own."""
    spec = _spec(base, grid_values)
    row = _row(spec)
    try:
        setup = _setup(spec, base, source)
    except HybridtrackError as exc:  # a value refused before the run: the grid's, or not
        return _failed(row, exc, _from_grid(base, grid_values, source, str(exc)))
    except Exception as exc:  # noqa: BLE001 - a failed run is a row, not the end of the sweep
        return _failed(row, exc)
    try:
        from .kernel import decided

        seed, config, weather, collector = setup
        config = decided(config, sweep_steps)
        row.update(_metrics(spec["strategy"], seed, config, weather, collector), error=None)
    except Exception as exc:  # noqa: BLE001
        return _failed(row, exc)
    return row


def _setup(spec: dict, base: dict, source: str) -> tuple:
    """The seed, config, weather arguments and collector of a run given `spec` (`_spec`), each
    checked as the run uses it, and its strategy checked."""
    _strategy(spec["strategy"])
    seed = params.seed(spec["seed"])  # 1.5 or true is refused, not truncated to another run's seed
    dotted = {k: v for k, v in spec.items() if "." in k and not k.startswith("collector.")}
    config = dataclasses.replace(_config_from(base.get("config", {}), dotted, source), seed=seed)
    return seed, config, _weather_arguments(spec), _collector(spec)


def _metrics(strategy: str, seed: int, config, weather: tuple, collector) -> dict:
    """The metrics of a run of `strategy` set up by `_setup`."""
    from .simulation import one_thread, simulate

    frame = _frame(*weather, seed)
    with one_thread():  # the sweep spreads its runs over the cores itself
        summary = simulate(frame, weather[0], collector=collector, strategy=strategy, config=config).summary
    error = summary["tracking_error_deg"]
    return {m: error[m] if m in error else summary[m] for m in METRICS}


def _from_grid(base: dict, grid_values: dict, source: str, error: str) -> dict:
    """The grid's values of a run that `error`, its refusal by `_setup`, came from (`blamed`)."""
    given = {key: value for key, value in grid_values.items() if key != "run"}
    keys = blamed(lambda values: _setup(_spec(base, values), base, source), given, error)
    return {key: given[key] for key in keys}


def _spec(base: dict, grid_values: dict) -> dict:
    """Everything a run is given: the defaults, the base run, its grid values."""
    return {**RUN_KEYS, **{k: v for k, v in base.items() if k != "config"}, **grid_values}


def _row(spec: dict) -> dict:
    """The table cells naming a run: its number, its run keys, then any other key it was given."""
    row = {key: _plain(spec[key]) for key in ("run", *RUN_KEYS) if key in spec}
    row.update({key: _plain(value) for key, value in spec.items() if key not in row})
    return row


def _failed(row: dict, exc: BaseException, grid: dict | None = None) -> dict:
    """`row` of a failed run: no metrics, and the error, after the `grid` values it came from."""
    named = "".join(f"grid.{key} = {_shown(value)}, " for key, value in (grid or {}).items())
    named = f"{named[:-2]}: " if named else ""
    return {**row, **{m: None for m in METRICS}, "error": f"{type(exc).__name__}: {named}{exc}"}


def _shown(value) -> str:
    """A grid value as an error shows it: a date as written in the sweep, anything else as Python writes it."""
    return value.isoformat() if hasattr(value, "isoformat") else repr(value)


def run_sweep(sweep: Sweep, *, scheduler: str | None = None, workers: int | None = None,
              progress: bool = True, started=None) -> pd.DataFrame:
    """Run every run of `sweep` on Dask and return the table, one row per run, sorted by run.

    Parameters
    ----------
    sweep : Sweep
    scheduler : str, optional
        Address of a running Dask scheduler (``tcp://host:8786``); by default a local cluster.
    workers : int, optional
        Worker processes of the local cluster, one thread each; the machine's cores by default.
        Never more than the sweep has runs, nor (by default) than can hold the sweep's longest
        run each at once in the memory budget (`hybridtrack.budget`); more than that, asked for,
        is refused.
    progress : bool
        A progress bar over runs on stderr.
    started : callable, optional
        Called with no argument once the cluster is up or the scheduler reached (and has a worker),
        before the first run is sent: a refusal of where the runs go comes before whatever it says.
    """
    import dask

    from .progress import bar as progress_bar

    if not isinstance(sweep, Sweep):
        raise HybridtrackError(f"run_sweep: sweep must be a Sweep (Sweep.from_toml, Sweep.from_dict), got {sweep!r:.80}")
    if started is not None and not callable(started):
        raise HybridtrackError(f"run_sweep: started must be a callable or None, got {started!r:.60}")
    runs = sweep.runs()
    check_where(scheduler, workers)
    if scheduler is None:  # a local cluster starts no worker without a run to do (64 for 2 runs had)
        workers = _workers_that_fit(sweep, runs, min(cores() if workers is None else workers, len(runs)),
                                    chosen=workers is not None)
    client, cluster = dask_client(scheduler, workers, what="sweeps")
    rows = []
    stop = None
    try:
        if started is not None:
            started()
        # one map, not a submit a run: 100,000 submits took 45 s before the bar appeared
        steps = _all_steps(sweep, runs)
        if progress:
            _say_if_compiling(sweep, runs, steps)
        # a big grid's graph is large (11 MB at 100,000 runs): Dask's advice about it had printed a
        # five-line UserWarning beside the progress bar, which a sweep's user can do nothing about
        with dask.config.set({"distributed.admin.large-graph-warning-threshold": "1 TiB"}):
            futures = dict(zip(client.map(run_one, [sweep.base] * len(runs), runs, [sweep.source] * len(runs),
                                          [steps] * len(runs), pure=False), runs))
        with progress_bar(len(futures), unit="run", disable=not progress) as bar:
            try:
                for future, row, error in finished(client, futures):
                    run = futures.pop(future)  # an error here is the worker's death (killed, out of memory)
                    rows.append(row if error is None else _failed(_row(_spec(sweep.base, run)), error))
                    bar.update()
            except WorkersGone as gone:  # the runs left are recorded as failed, with why
                rows.extend(_failed(_row(_spec(sweep.base, run)), gone) for run in futures.values())
    except KeyboardInterrupt as exc:
        stop = exc
    finally:
        # a Ctrl-C pressed again while the cluster closes is held: raised there, it lost the runs
        with holding_interrupts() as held:
            close(client, cluster)
    if held and stop is None:  # one that came after the last run: the runs are all there, kept as finished
        try:
            signal.raise_signal(held[0])  # as this process meets it (Ctrl-C, or the command line's SIGTERM)
        except KeyboardInterrupt as exc:
            stop = exc
    if stop is not None:
        raise SweepInterrupted(_table(rows) if rows else None, len(runs), stop) from None
    return _table(rows)


def _say_if_compiling(sweep: Sweep, runs: list[dict], steps: int) -> None:
    """Say so on stderr where the runs will compile the kernel first: each worker compiles it
    before its first run, and the bar stands at 0 for minutes (judged on the first run's config;
    one that cannot be set up says nothing here and fails as its own row)."""
    from .kernel import COMPILING, compiles_first

    try:
        config = _setup(_spec(sweep.base, runs[0]), sweep.base, sweep.source)[1]
        if compiles_first(config, steps):
            print(COMPILING, file=sys.stderr)
    except HybridtrackError:
        pass


class SweepInterrupted(KeyboardInterrupt):
    """Ctrl-C during `run_sweep`: a KeyboardInterrupt that keeps the runs finished before it.

    Attributes
    ----------
    table : pandas.DataFrame or None
        The finished runs, one row each as `run_sweep` returns them; None if none had finished.
    planned : int
        The runs the sweep had.
    stop : KeyboardInterrupt or None
        What stopped it (Ctrl-C, or the command line's SIGTERM, which is one).
    """

    def __init__(self, table: pd.DataFrame | None, planned: int, stop: KeyboardInterrupt | None = None) -> None:
        super().__init__(f"{0 if table is None else len(table)} of {planned} runs had finished")
        self.table, self.planned, self.stop = table, planned, stop


def _table(rows: list[dict]) -> pd.DataFrame:
    """The runs' rows as one typed table, sorted by run, that Parquet can hold."""
    table = pd.DataFrame(rows)
    for column in table.columns.difference([*METRICS, "error"]):
        given = [row.get(column) for row in rows]
        if _whole_beside_fraction(given):  # pandas' float64 column: 9007199254740993 had become ...992.0
            table[column] = pd.Series(given, dtype=object)
    table = table.sort_values("run", kind="stable").reset_index(drop=True)
    for metric in METRICS:
        table[metric] = pd.to_numeric(table[metric], errors="coerce").astype("Int64" if metric in COUNTS else float)
    table["error"] = table["error"].astype("string")
    for column in table.columns.difference([*METRICS, "error"]):
        values = table[column]
        if values.dtype == object and not all(isinstance(v, str) for v in values.dropna()):
            table[column] = _as_text(values)
    return table


def _whole_beside_fraction(values: list) -> bool:
    """Whether a key's values hold whole numbers beside floats (``[nan, 1]``, ``[1, 1.0]``), which one
    column of numbers would hold as floats, each whole number as the float nearest it: the table
    then names a run by a value it was not given (`_as_text` keeps each as given)."""
    kinds = {type(value) for value in values if isinstance(value, numbers.Real) and not isinstance(value, bool)}
    return any(issubclass(kind, numbers.Integral) for kind in kinds) and any(
        not issubclass(kind, numbers.Integral) for kind in kinds)


def _as_text(values: pd.Series) -> pd.Series:
    """A grid key's values as text, each as the sweep gave it.

    For the columns pandas cannot make one native column of, which Parquet cannot store: values of
    several types (``[0.1, "wide"]``), whole numbers beyond 64 bits (a seed of 1e20, which fails
    its run but must not lose the table), tables. Text keeps every digit, where a float would not;
    a boolean is written as TOML writes it (``true``, where Python's ``str`` gave ``True``; `_text`).
    """
    return values.map(lambda v: v if v is None else _text(v)).astype("string")


def pareto_front(table: pd.DataFrame, x: str, y: str) -> pd.DataFrame:
    """The runs no other run beats on both `x` and `y` (each minimised, or maximised if in `MAXIMISED`)."""
    _check_columns(table, [x, y], "pareto_front", numbers=True)
    ok = table.dropna(subset=[x, y])
    sx = -1.0 if x in MAXIMISED else 1.0
    sy = -1.0 if y in MAXIMISED else 1.0
    order = ok.assign(_x=sx * ok[x], _y=sy * ok[y]).sort_values(["_x", "_y"], kind="stable")
    best = np.inf
    keep = []
    for index, value in zip(order.index, order["_y"]):
        if value < best:
            keep.append(index)
            best = value
    return ok.loc[keep]


def _workers_that_fit(sweep: Sweep, runs: list[dict], workers: int, *, chosen: bool) -> int:
    """The local cluster's workers whose runs fit in memory together: each worker holds one run
    at a time, so `workers` of the sweep's longest run must fit the memory budget at once (each
    run alone is checked as it is read). Fewer than `workers` where the default does not fit;
    refused, naming the longest run, where the user `chosen` them."""
    from .budget import BYTES_PER_STEP, readable_size, memory_budget

    readable = _readable_steps(sweep, runs)
    if not readable:  # every run fails on its own days or step, as its row says
        return 1
    count, days, freq = max(readable)
    size, budget = count * BYTES_PER_STEP, memory_budget()
    fitting = max(1, min(workers, budget // max(size, 1)))
    if chosen and fitting < workers:
        raise HybridtrackError(f"{workers} workers would each hold a run of up to {days} days at {freq} "
                               f"(about {readable_size(size)}), {readable_size(size * workers)} together, over the "
                               f"{readable_size(budget)} the runs may use; {fitting} fit: use --workers {fitting} "
                               "(workers= from Python)")
    return fitting


def _steps(sweep: Sweep, run: dict) -> tuple[int, int, str]:
    """A run's steps, whole days and step (``freq``)."""
    from .times import parse_freq

    spec = _spec(sweep.base, run)
    days, freq = _whole_days(spec["days"]), _step(spec["freq"])
    return days * pd.Timedelta(days=1) // parse_freq(freq), days, freq


def _readable_steps(sweep: Sweep, runs: list[dict]) -> list[tuple[int, int, str]]:
    """`_steps` of every run whose days and step can be read; a run whose cannot (a grid's
    ``days = 0`` or ``freq = "2h"``) fails on its own, its row naming the grid's value, and the
    sweep goes on (it had ended the whole sweep before it started, naming neither file nor key)."""
    readable = []
    for run in runs:
        with contextlib.suppress(HybridtrackError):
            readable.append(_steps(sweep, run))
    return readable


def _all_steps(sweep: Sweep, runs: list[dict]) -> int:
    """The steps of every run the sweep can read (`_readable_steps`)."""
    return sum(steps for steps, _, _ in _readable_steps(sweep, runs))


def _check_columns(table, names: list, what: str, *, numbers: bool = False) -> None:
    """Refuse a `table` that is not a DataFrame with the columns `names` (of numbers, if `numbers`)."""
    if not isinstance(table, pd.DataFrame):
        raise HybridtrackError(f"{what}: the table must be a pandas DataFrame (run_sweep's), got {table!r:.80}")
    for name in names:
        if name not in table.columns:
            raise HybridtrackError(f"{what}: the table has no column {name!r}; its columns: "
                                   f"{', '.join(map(str, table.columns))}")
        if numbers and not pd.api.types.is_numeric_dtype(table[name]):
            raise HybridtrackError(f"{what}: column {name!r} holds {table[name].dtype}, not numbers; "
                                   f"choose a metric: {', '.join(METRICS)}")


def plot_tradeoff(table: pd.DataFrame, x: str = "moves", y: str = "rms", *, colour: str | None = None,
                  title: str = ""):
    """Every run as a point of `x` against `y`, coloured by a grid key, with the Pareto front drawn.

    When the runs have several seeds, the mean over seeds of each `colour` value is marked too:
    a seed changes the sky, so single runs scatter more than the setting moves them.

    Returns a `matplotlib.figure.Figure`.
    """
    from matplotlib.figure import Figure

    _check_columns(table, [x, y], "plot_tradeoff", numbers=True)
    _check_columns(table, [] if colour is None else [colour], "plot_tradeoff: colour")
    fig = Figure(figsize=(7.5, 5), layout="constrained")
    ax = fig.add_subplot()
    ok = table.dropna(subset=[x, y])
    if colour is not None and colour in ok and pd.api.types.is_numeric_dtype(ok[colour]):
        points = ax.scatter(ok[x], ok[y], c=ok[colour], cmap="viridis", s=36, edgecolors="0.3", linewidths=0.4)
        fig.colorbar(points, ax=ax, label=colour)
    elif colour is not None and colour in ok and ok[colour].nunique() > LEGEND_MOST:
        # a legend of 60 start dates ran off the figure: values in their order on a colour bar
        codes, values = pd.factorize(ok[colour], sort=True)
        points = ax.scatter(ok[x], ok[y], c=codes, cmap="viridis", s=36, edgecolors="0.3", linewidths=0.4)
        bar = fig.colorbar(points, ax=ax, label=f"{colour} ({len(values)} values)")
        bar.set_ticks([0, len(values) - 1], labels=[str(values[0]), str(values[-1])])
    elif colour is not None and colour in ok and not ok.empty:
        for value, group in ok.groupby(colour, sort=False):
            ax.scatter(group[x], group[y], s=36, label=f"{colour} = {value}", edgecolors="0.3", linewidths=0.4)
        ax.legend(loc="best", fontsize="small")
    else:
        ax.scatter(ok[x], ok[y], s=36, edgecolors="0.3", linewidths=0.4)
    if colour is not None and colour != "seed" and colour in ok and "seed" in ok and ok["seed"].nunique() > 1:
        means = ok.groupby(colour, sort=True)[[x, y]].mean()
        ax.plot(means[x], means[y], marker="X", color="black", ls=":", lw=0.8, markersize=8,
                label=f"mean over {ok['seed'].nunique()} seeds")
    front = pareto_front(ok, x, y)
    ax.plot(front[x], front[y], color="tab:red", lw=1.2, drawstyle="steps-post", label="Pareto front", zorder=0)
    ax.legend(loc="best", fontsize="small")  # after the front: its red line had gone unexplained
    ax.set_xlabel(x + (" (more is better)" if x in MAXIMISED else ""))
    ax.set_ylabel(y + (" (more is better)" if y in MAXIMISED else ""))
    failed = int(table["error"].notna().sum()) if "error" in table else 0
    ax.set_title(title + (f" ({failed} failed run{'s' if failed != 1 else ''} left out)" if failed else ""))
    return fig


def sweep_files(folder) -> dict[str, Path]:
    """The files `save_sweep` writes into `folder`, by role."""
    folder = output_folder(folder)
    return {"table": folder / "runs.parquet", "plot": folder / "tradeoff.png", "sweep": folder / "sweep.toml"}


def partial_file(folder) -> Path:
    """Where an interrupted sweep's finished runs go (`SweepInterrupted.table`)."""
    return Path(folder) / "runs.partial.parquet"


@removing_empty_folders()
def save_sweep(table: pd.DataFrame, sweep: Sweep, folder) -> dict[str, Path]:
    """Write ``runs.parquet``, ``tradeoff.png`` and ``sweep.toml`` (the sweep that made them).

    The table is written first and on its own: the finished runs are kept even if the plot
    cannot be drawn or written; the plot and the sweep go in together. If they cannot, an
    earlier sweep's plot and sweep file are removed rather than left beside this table (which
    they do not describe), and the error says where the runs are."""
    if not isinstance(sweep, Sweep):
        raise HybridtrackError(f"save_sweep: sweep must be a Sweep, got {type(sweep).__name__}")
    written = sweep_files(folder)
    claim(written.values())
    write(written["table"], lambda path: table.to_parquet(path, index=False))
    try:
        with together():
            sweep.to_toml(written["sweep"])
            colour = next(iter(sweep.grid))
            figure = plot_tradeoff(table, sweep.x, sweep.y, colour=colour, title=Path(sweep.source).stem)
            write(written["plot"], lambda path: figure.savefig(path, dpi=120))
    except BaseException as exc:  # a Ctrl-C amid a long plot too: no earlier sweep's files beside this table
        for stale in (written["sweep"], written["plot"]):
            stale.unlink(missing_ok=True)
        if isinstance(exc, HybridtrackError):
            raise HybridtrackError(f"{exc}; the runs are in {written['table']}") from None
        raise
    return written
