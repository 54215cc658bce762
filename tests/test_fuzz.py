"""Fuzzing the file reader and the config loaders: only the project's own clear errors may come out.

The suite runs a bounded number of examples per target. For a longer run:

    HYBRIDTRACK_FUZZ_EXAMPLES=20000 python -m pytest tests/test_fuzz.py -q
"""

import os
import string
import tempfile
from pathlib import Path

import pandas as pd
import tomli_w
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from hybridtrack import HybridtrackError
from hybridtrack.fuzzy import FuzzyConfig
from hybridtrack.io import read_weather
from hybridtrack.simulation import SimulationConfig

EXAMPLES = int(os.environ.get("HYBRIDTRACK_FUZZ_EXAMPLES", "120"))
FUZZ = settings(max_examples=EXAMPLES, deadline=None, derandomize=EXAMPLES <= 120,
                suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


def survives(call, payload: bytes, suffix: str):
    """Write `payload` to a file and call `call(path)`; anything but our own error fails."""
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / f"fuzz{suffix}"
        path.write_bytes(payload)
        try:
            return call(path)
        except HybridtrackError as error:
            assert str(error) and "\n" not in str(error)
            return None


HEADERS = ["time", "Timestamp", "GHI", "Global [kW/m2]", "Direct Normal", "dni", "DHI", "Diffuse", "wind", "Wind speed [km/h]",
           "temp_air", "Temperature [K]", "photocurrent", "sky", "x", "", "time", "GHI"]
CELLS = st.one_of(
    st.sampled_from(["", "nan", "-", "NA", "0", "-0.5", "1e3", "1,5", "900.5", "abc", "2021-06-21 12:00",
                     "2021-06-21T12:00:00+08:00", "2021-03-14 02:30", "21.06.2021 12:00", "12:00", "9" * 30, "sunny"]),
    st.integers(-10_000, 10_000).map(str), st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.text(string.printable, max_size=12))


@st.composite
def csv_files(draw):
    sep = draw(st.sampled_from([",", ";", "\t", "|", " "]))
    width = draw(st.integers(1, 6))
    header = draw(st.lists(st.sampled_from(HEADERS), min_size=width, max_size=width))
    rows = draw(st.lists(st.lists(CELLS, min_size=width, max_size=width), max_size=30))
    if draw(st.booleans()):  # a time column that parses
        start = pd.Timestamp("2021-06-21 10:00")
        header[0] = "time"
        for k, row in enumerate(rows):
            row[0] = str(start + pd.Timedelta(minutes=draw(st.integers(-5, 5)) + k))
    lines = [sep.join(header)] + [sep.join(row) for row in rows]
    preamble = draw(st.lists(st.text(string.printable, max_size=30), max_size=3))
    return ("\n".join(preamble + lines)).encode("utf-8")


@FUZZ
@given(st.binary(max_size=400))
def test_read_weather_survives_random_bytes(payload):
    survives(lambda p: read_weather(p, tz="UTC"), payload, ".csv")


@FUZZ
@given(csv_files(), st.sampled_from([None, "UTC", "Asia/Shanghai", "America/Denver"]), st.booleans(),
       st.sampled_from([None, "1min", "5min"]))
# what the fuzzer found, kept: a header naming a column twice, a number read as a UTC offset
# of -24 h, and numbers read as dates in year 0
@example(b"time,time,GHI\n,,", None, False, None)
@example(b"time,GHI\n-2360,", None, False, None)
@example(b"time;Timestamp;GHI\n-0.5;;\n1,5;;", "UTC", False, None)
def test_read_weather_survives_csv_shaped_files(payload, tz, strict, freq):
    frame = survives(lambda p: read_weather(p, tz=tz, strict=strict, freq=freq, site="lanzhou"), payload, ".csv")
    if frame is not None:
        assert frame.index.tz is not None and frame.index.is_monotonic_increasing and not frame.index.has_duplicates
        assert "validation" in frame.attrs


@FUZZ
@given(st.binary(max_size=300), st.sampled_from(["epw", "tmy3", "midc", "srml", "bsrn", "surfrad"]))
def test_pvlib_formats_survive_random_bytes(payload, fmt):
    survives(lambda p: read_weather(p, format=fmt, tz="UTC"), payload, f".{fmt}")


SCALARS = st.one_of(st.integers(-10, 10_000), st.floats(allow_nan=False, allow_infinity=False, width=32),
                    st.booleans(), st.text(max_size=8), st.sampled_from(["gaussmf", "trimf", "trapmf", "gauss2mf",
                                                                         "sunny", "weak", "strong", "small", "5min"]))
VALUES = st.recursive(SCALARS, lambda inner: st.one_of(st.lists(inner, max_size=5),
                                                       st.dictionaries(st.sampled_from(
                                                           ["shape", "params", "terms", "raw_range", "universe",
                                                            "unit", "weak", "medium", "strong", "small", "large"]),
                                                           inner, max_size=4)), max_leaves=12)
FUZZY_KEYS = ["name", "resolution", "inputs", "output", "bands", "rules", "intensity", "variation", "weather",
              "input", "terms", "bogus"]
RUN_KEYS = ["controller", "imperfections", "sensor", "drive", "seed", "strategy", "dwell", "deadband", "limits",
            "clock_error", "window", "bogus"]


def toml_documents(keys):
    return st.dictionaries(st.sampled_from(keys), VALUES, max_size=5)


def render(document) -> bytes:
    try:
        return tomli_w.dumps(document).encode("utf-8")
    except (TypeError, ValueError):  # not representable as TOML: fuzz the text instead
        return repr(document).encode("utf-8")


@FUZZ
@given(st.one_of(toml_documents(FUZZY_KEYS).map(render), st.binary(max_size=200)))
def test_fuzzy_config_loader_survives(payload):
    survives(FuzzyConfig.from_toml, payload, ".toml")


@FUZZ
@given(st.one_of(toml_documents(RUN_KEYS).map(render), st.binary(max_size=200)))
def test_run_config_loader_survives(payload):
    survives(SimulationConfig.from_toml, payload, ".toml")


FIS = FuzzyConfig().to_fis(Path(tempfile.mkdtemp()) / "published.fis").read_text()


@FUZZ
@given(st.lists(st.tuples(st.integers(0, len(FIS) - 1), st.text(string.printable, max_size=6)), max_size=6))
def test_fis_reader_survives_mutations(edits):
    text = FIS
    for at, insert in edits:
        text = text[:at] + insert + text[at + len(insert):]
    survives(FuzzyConfig.from_fis, text.encode("utf-8"), ".fis")
