"""The API says when a frame made for one site is run at another
(`hybridtrack.simulation.AnotherSiteWarning`): Lanzhou's weather run at Nanjing had run without a
word, its sun, light and wind Lanzhou's."""

import warnings

import pytest

from hybridtrack import simulate, simulate_field, sites
from hybridtrack.fields import FresnelField
from hybridtrack.simulation import AnotherSiteWarning
from hybridtrack.sky import synthetic


@pytest.fixture(scope="module")
def lanzhou_day():
    return synthetic("lanzhou", "2021-06-21", weather="sunny", seed=1, freq="5min")


def _warned(run) -> list[str]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        run()
    return [str(w.message) for w in caught if issubclass(w.category, AnotherSiteWarning)]


def test_a_frame_run_at_another_site_is_named(lanzhou_day):
    expected = ("the weather frame was made for lanzhou (its attrs['site']) and runs at nanjing: its sun, light and "
                "wind are lanzhou's; make or read the weather for nanjing")
    assert _warned(lambda: simulate(lanzhou_day, "nanjing")) == [expected]
    field = FresnelField(row_distances=[-2.0, 2.0])
    assert _warned(lambda: simulate_field(lanzhou_day, "nanjing", field, keep_log=False, progress=False)) == [expected]


@pytest.mark.parametrize("site", ["lanzhou", "LANZHOU", sites.Site("our plant", 36.1, 103.75, 1520.0, "Asia/Shanghai")])
def test_the_frames_own_site_is_not_named(lanzhou_day, site):
    """Its own name in any case, or a site of another name within 0.1° of it (the same place)."""
    assert _warned(lambda: simulate(lanzhou_day, site)) == []


def test_a_frame_without_a_site_is_not_named(lanzhou_day):
    bare = lanzhou_day.copy()
    bare.attrs = {}
    assert _warned(lambda: simulate(bare, "nanjing")) == []
