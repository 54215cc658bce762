"""The mount fit's derivatives: the chain rule through the mount's rotation against central
differences of the whole mount geometry (the independent reference: turn the mount, recompute
every target)."""

import numpy as np
import pytest

from hybridtrack.collectors import Collector
from hybridtrack.control.mountfit import jacobian, parameter_names
from hybridtrack.control.plan import MountEstimate
from hybridtrack.sun import solar_position
from hybridtrack.times import local_range


@pytest.mark.parametrize("collector", [Collector("trough-ns"), Collector("trough-ew"), Collector("fresnel"),
                                       Collector("heliostat"), Collector("heliostat", aim=(30.0, -80.0, 40.0))])
def test_the_targets_derivatives_match_central_differences_of_the_turned_mount(collector):
    sun = solar_position(local_range("2021-06-21", "Asia/Shanghai", freq="10min"), "lanzhou")
    sun = sun[sun["altitude"] > 2.0]
    altitude, azimuth = sun["altitude"].to_numpy(), sun["azimuth"].to_numpy()
    names = parameter_names(collector)
    h = 1e-3
    expected = np.zeros((len(altitude), len(names) - 2, len(names)))
    for k, name in enumerate(names):
        up, down = (MountEstimate.from_parameters(names, [sign * h if n == name else 0.0 for n in names])
                    .targets(altitude, azimuth, collector) for sign in (1.0, -1.0))
        difference = up - down
        if not collector.single_axis:  # the azimuth axis turns through north
            difference[:, 0] = (difference[:, 0] + 180.0) % 360.0 - 180.0
        expected[:, :, k] = difference / (2.0 * h)
    got = jacobian(altitude, azimuth, collector)
    assert np.abs(expected[:, :, :2]).max() > 0.1  # the pedestal terms do move the targets
    np.testing.assert_allclose(got, expected, rtol=1e-5, atol=1e-6)  # the differences err by O(h²)
