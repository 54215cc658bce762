"""The API says when a frame made for one site is run at another
(`hybridtrack.simulation.AnotherSiteWarning`): Lanzhou's weather run at Nanjing had run without a
word, its sun, light and wind Lanzhou's."""

import pytest

from hybridtrack import simulate, simulate_field, sites
from hybridtrack.fields import FresnelField
from hybridtrack.simulation import AnotherSiteWarning
from hybridtrack.sky import synthetic


@pytest.fixture(scope="module")
def lanzhou_day():
    return synthetic("lanzhou", "2021-06-21", weather="sunny", seed=1, freq="5min")


def test_a_frame_run_at_another_site_is_named(lanzhou_day, warned):
    expected = ("the weather frame was made for lanzhou (its attrs['site']) and runs at nanjing: its sun, light and "
                "wind are lanzhou's; make or read the weather for nanjing")
    assert warned(lambda: simulate(lanzhou_day, "nanjing"), AnotherSiteWarning) == [expected]
    field = FresnelField(row_distances=[-2.0, 2.0])
    run = lambda: simulate_field(lanzhou_day, "nanjing", field, keep_log=False, progress=False)  # noqa: E731
    assert warned(run, AnotherSiteWarning) == [expected]


@pytest.mark.parametrize("site", ["lanzhou", "LANZHOU", sites.Site("our plant", 36.1, 103.75, 1520.0, "Asia/Shanghai")])
def test_the_frames_own_site_is_not_named(lanzhou_day, site, warned):
    """Its own name in any case, or a site of another name within 0.1° of it (the same place)."""
    assert warned(lambda: simulate(lanzhou_day, site), AnotherSiteWarning) == []


def test_a_frame_without_a_site_is_not_named(lanzhou_day, warned):
    bare = lanzhou_day.copy()
    bare.attrs = {}
    assert warned(lambda: simulate(bare, "nanjing"), AnotherSiteWarning) == []
