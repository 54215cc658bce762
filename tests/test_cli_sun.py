import pandas as pd
import pytest

from hybridtrack.cli import main


def test_sun_prints_a_table_and_summary(capsys):
    import pvlib

    assert main(["sun", "--site", "nanjing", "--date", "2013-12-22", "--freq", "1h"]) == 0
    out = capsys.readouterr().out
    # the highest of the hourly stamps by pvlib's SPA itself (Nanjing 31.453° N 118.4629° E, 20 m,
    # docs/physics.md §1): 35.099° at 12:00, short of the day's 35.11° at solar noon a few minutes later
    hours = pd.date_range("2013-12-22", periods=24, freq="1h", tz="Asia/Shanghai")
    spa = pvlib.solarposition.spa_python(hours, 31.453, 118.4629, altitude=20.0, delta_t=67.0)["elevation"]
    assert f"highest {spa.max():.3f}° at {spa.idxmax():%H:%M:%S}" in out
    assert "2013-12-22 12:00:00" in out and "fastest target rate" in out


def test_sun_writes_csv_and_plot(tmp_path):
    csv, png = tmp_path / "sun.csv", tmp_path / "sun.png"
    assert main(["sun", "--site", "lanzhou", "--date", "2021-06-21", "--model", "plc", "--collector", "heliostat",
                 "--csv", str(csv), "--plot", str(png), "--freq", "30min"]) == 0
    table = pd.read_csv(csv, index_col="time")
    assert {"altitude", "normal_elevation", "jack_3"} <= set(table.columns)
    assert len(table) == 15 * 2 + 1 and png.stat().st_size > 10_000  # 05:00-20:00 (the defaults) every 30 min


def test_sun_at_coordinates_with_fresnel_geometry(capsys):
    args = ["sun", "--lat", "-33.9", "--lon", "18.4", "--tz", "Africa/Johannesburg", "--date", "2024-12-21",
            "--collector", "fresnel", "--row-distance", "-5", "--receiver-height", "8"]
    assert main(args) == 0
    assert "end_loss" in capsys.readouterr().out


@pytest.mark.parametrize("args, message", [
    (["--site", "mars", "--date", "2013-06-21"], "unknown site 'mars'"),
    (["--date", "2013-02-30"], "date '2013-02-30' does not exist"),
    (["--lat", "95", "--lon", "0", "--tz", "UTC", "--date", "2013-06-21"], "--lat 95.0 is outside"),
    (["--lat", "30", "--date", "2013-06-21"], "--lat, --lon and --tz go together"),
    (["--date", "2013-06-21", "--freq", "fast"], "step 'fast' is not a duration"),
    (["--date", "2013-06-21", "--start", "25:00"], "clock time '25:00' is not HH:MM"),
])
def test_sun_bad_input_is_one_line_and_status_2(capsys, args, message):
    assert main(["sun", *args]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err and err.startswith("hybridtrack: error: ")


def test_every_command_has_help(capsys):
    from hybridtrack.cli import _COMMANDS

    for name in _COMMANDS:
        with pytest.raises(SystemExit) as stop:
            main([name, "--help"])
        assert stop.value.code == 0
        assert "usage: hybridtrack" in capsys.readouterr().out


def test_a_closed_pipe_is_not_an_error(tmp_path):
    import subprocess
    import sys

    script = "import sys; from hybridtrack.cli import main; sys.exit(main(sys.argv[1:]))"
    run = subprocess.run(f'"{sys.executable}" -c "{script}" sun --date 2013-06-21 --freq 1min | head -n 2',
                         shell=True, capture_output=True, text=True)
    assert run.stdout.count("\n") == 2 and "error" not in run.stderr


def test_one_step_with_the_sun_up_has_no_rate_and_no_warning(capsys):
    """05:00 and 05:50 are before sunrise at Lanzhou on 21 June, 06:40 after: one step with the sun
    up gives no rate; 'nan °/min' and numpy's All-NaN RuntimeWarning had been printed."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert main(["sun", "--site", "lanzhou", "--date", "2021-06-21", "--start", "05:00", "--end", "06:40",
                     "--freq", "50min"]) == 0
    captured = capsys.readouterr()
    assert "sun up in range 06:40-06:40" in captured.out
    assert "  fastest target rate: needs two steps with the sun up\n" in captured.out
    assert "nan" not in captured.out and captured.err == ""


@pytest.mark.parametrize("geometric", [False, True])
def test_the_sun_commands_targets_are_on_the_apparent_sun_unless_asked_for_the_geometric(tmp_path, geometric):
    """Targets on the sun as it appears (where the light comes from, where the simulated world's sun
    is and the controller aims), or with --geometric on the geometric sun: pvlib's SPA either way."""
    import numpy as np
    import pvlib

    from hybridtrack.collectors import trough_angle

    out = tmp_path / "sun.csv"
    assert main(["sun", "--site", "lanzhou", "--date", "2021-06-21", "--start", "06:00", "--end", "09:00", "--freq",
                 "10min", "--csv", str(out), *(["--geometric"] if geometric else [])]) == 0
    table = pd.read_csv(out, index_col="time")
    times = pd.DatetimeIndex(pd.to_datetime(table.index)).tz_convert("Asia/Shanghai")
    from hybridtrack import sites

    site = sites.get("lanzhou")
    spa = pvlib.solarposition.spa_python(times, site.latitude, site.longitude, altitude=site.altitude, delta_t=67.0,
                                         pressure=pvlib.atmosphere.alt2pres(site.altitude), temperature=12.0)
    aimed = spa["elevation" if geometric else "apparent_elevation"].to_numpy()
    expected = trough_angle(aimed, spa["azimuth"].to_numpy(), 0.0)
    up = np.isfinite(expected)
    np.testing.assert_allclose(table["angle"].to_numpy()[up], expected[up], atol=1e-5)  # the CSV's six places
