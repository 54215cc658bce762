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


@pytest.mark.parametrize("arguments, message", [
    (("north", 103.7, "Asia/Shanghai"), "latitude must be a number, got 'north'"),  # float() raised ValueError
    ((None, 103.7, "UTC"), "latitude must be a number, got None"),                   # ... TypeError
    (([36.1], 103.7, "UTC"), r"latitude must be a number, got \[36.1\]"),
    ((1j, 103.7, "UTC"), "latitude must be a number, got 1j"),
    ((10**400, 103.7, "UTC"), r"latitude 10000000000000000000… \(401 characters\) is outside"),  # OverflowError
    ((True, 103.7, "UTC"), "latitude must be a number, got True"),  # had been latitude 1.0
    ((36.1, 103.7, "UTC", "x"), "altitude must be a number, got 'x'"),
    ((36.1, 103.7, "UTC", 0.0, None), "a site's name must be a non-empty text, got None"),
])
def test_custom_sites_refuse_what_is_no_coordinate_by_its_name(arguments, message):
    with pytest.raises(HybridtrackError, match=message):
        sites.custom(*arguments)


def test_a_site_keeps_numpy_numbers_and_zone_objects_as_plain_values():
    """A ZoneInfo was kept as the object: runs worked, and saving a field's netCDF failed at the
    end with xarray's TypeError. numpy's scalars are numbers (they had been refused)."""
    import datetime
    import zoneinfo

    import numpy as np

    site = sites.custom(np.float32(36.0), np.int64(100), zoneinfo.ZoneInfo("Asia/Shanghai"), altitude=np.float64(1.5))
    assert site == sites.Site("custom", 36.0, 100.0, 1.5, "Asia/Shanghai")
    assert all(type(value) is float for value in (site.latitude, site.longitude, site.altitude))
    assert sites.custom(1.0, 2.0, datetime.timezone.utc).tz == "UTC"
