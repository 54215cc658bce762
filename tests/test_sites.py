import pytest

from hybridtrack import HybridtrackError, sites


def test_builtin_sites_carry_the_published_coordinates():
    lanzhou, nanjing = sites.get("lanzhou"), sites.get("Nanjing")
    assert (lanzhou.latitude, lanzhou.longitude, lanzhou.tz) == (36.1055556, 103.726389, "Asia/Shanghai")
    assert (nanjing.latitude, nanjing.longitude) == (31.453, 118.4629)
    assert sites.get("kunming").latitude == pytest.approx(25 + 1 / 60)
    assert sites.get("delingha").longitude == pytest.approx(97.803267)


def test_unknown_site_lists_the_known_names():
    with pytest.raises(HybridtrackError, match="unknown site 'mars'; known sites: delingha, kunming, lanzhou, nanjing"):
        sites.get("mars")


@pytest.mark.parametrize(
    "latitude, longitude, tz, message",
    [(91.0, 0.0, "UTC", "latitude 91.0 is outside"), (0.0, 200.0, "UTC", "longitude 200.0 is outside"),
     (10.0, 10.0, "Mars/Olympus", "unknown time zone 'Mars/Olympus'")],
)
def test_custom_sites_are_validated(latitude, longitude, tz, message):
    with pytest.raises(HybridtrackError, match=message):
        sites.custom(latitude, longitude, tz)


def test_custom_site_is_a_frozen_value():
    site = sites.custom(-33.9, 18.4, "Africa/Johannesburg", 10)
    assert sites.get(site) is site
    with pytest.raises(AttributeError):
        site.latitude = 0.0
