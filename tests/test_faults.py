"""Fault scenarios: each injected fault leads to a safe, logged outcome (docs/robustness.md)."""

import numpy as np
import pandas as pd
import pytest

from hybridtrack import HybridtrackError, simulate, sites
from hybridtrack.cli import main
from hybridtrack.control import ControllerConfig
from hybridtrack.drive import gray_decode, gray_encode
from hybridtrack.faults import safety_breaches
from hybridtrack.simulation import SimulationConfig
from hybridtrack.sky import synthetic
from hybridtrack.world import Imperfections


def check_safety(result):
    """What every run must keep true, whatever went wrong: the fault library's shared check."""
    assert not safety_breaches(result), safety_breaches(result)


def sunny_day(site="lanzhou", date="2021-06-21", seed=1):
    return synthetic(site, date, weather="sunny", seed=seed)


def between(frame, start, end):
    clock = frame.index.tz_convert(frame.index.tz)
    mask = (clock >= pd.Timestamp(f"{clock[0].date()} {start}", tz=frame.index.tz)) & \
           (clock < pd.Timestamp(f"{clock[0].date()} {end}", tz=frame.index.tz))
    return np.asarray(mask)


def tracked(result, mask=None):
    log = result.log
    keep = log["mode"].isin(["sensor", "astronomical"]) & (log["dni"] > 0) & log["target_true"].notna()
    if mask is not None:
        keep &= mask
    return log.loc[keep, "error"]


def test_sensor_dropout_in_full_sun_hands_over_to_the_model():
    frame = sunny_day()
    dropout = between(frame, "11:00", "13:00")
    result = simulate(frame, "lanzhou", faults={"sensor_dropout": dropout})
    check_safety(result)
    log = result.log
    assert (log.loc[dropout, "sensor_status"] == "invalid reading").all()
    lost = result.events[result.events["reason"] == "sensor lost (invalid reading)"]
    assert len(lost) == 1 and lost["time"].iloc[0] <= pd.Timestamp("2021-06-21 11:04", tz="Asia/Shanghai")
    assert tracked(result, dropout).abs().max() < 0.5  # the calibrated model carries on
    assert (log.loc[between(frame, "13:30", "16:00"), "mode"] == "sensor").mean() > 0.8  # and it comes back


@pytest.mark.parametrize("noise", [0.0, 0.001])  # stuck exactly, and stuck with a little electronic noise
def test_a_stuck_sensor_is_recognised_and_not_followed(noise):
    frame = sunny_day()
    window = between(frame, "11:00", "14:00")
    jitter = noise * np.random.default_rng(3).standard_normal(len(frame))
    stuck = np.where(window, 0.0 + jitter, np.nan)  # says "perfectly aligned", forever
    result = simulate(frame, "lanzhou", faults={"sensor": stuck})
    check_safety(result)
    statuses = result.log.loc[between(frame, "11:10", "14:00"), "sensor_status"]
    assert (statuses == "stuck").all()
    assert "sensor lost (stuck)" in result.events["reason"].tolist()
    # held from its last move until the fourth equal reading (11:03): the error it tracked with
    # before the fault, and the sun's travel over the three scans held
    before = tracked(result, between(frame, "10:00", "11:00")).abs().max()
    travel = result.log.loc[window, "target_true"].diff().abs().max() * (ControllerConfig().stuck_scans - 1)
    assert tracked(result, window).abs().max() <= before + travel
    handover = result.events.loc[result.events["reason"] == "sensor lost (stuck)", "time"].iloc[0]
    assert handover <= pd.Timestamp("2021-06-21 11:10", tz="Asia/Shanghai")  # ten readings, then at once
    assert (result.log.loc[between(frame, "11:10", "14:00"), "mode"] != "sensor").all()  # never returned to


def test_a_healthy_sensor_is_never_judged_stuck():
    for site, date in (("lanzhou", "2021-06-21"), ("nanjing", "2013-12-22")):
        result = simulate(synthetic(site, date, weather="sunny", seed=8), site)
        assert not (result.log["sensor_status"] == "stuck").any()


def test_a_drifting_sensor_bias_is_bounded_by_the_plausibility_check():
    frame = sunny_day("nanjing", "2013-06-21")
    hours = np.asarray((frame.index - frame.index[0]) / pd.Timedelta(hours=1))
    drift = np.clip((hours - 8.0) * 0.8, 0.0, None)  # 0.8° an hour from 08:00
    result = simulate(frame, "nanjing", faults={"sensor_drift": drift})
    check_safety(result)
    limit = result.config.controller.sensor_plausibility
    assert tracked(result).abs().max() < limit + 0.6
    assert "implausible" in set(result.log["sensor_status"].astype(str))
    assert result.events["reason"].str.contains("implausible").any()
    late = result.log.loc[between(frame, "15:00", "18:00")]
    assert (late["mode"] == "astronomical").all() and late["calibration"].abs().max() <= limit


def test_nan_and_negative_bursts_in_irradiance():
    frame = synthetic("lanzhou", "2021-06-21", weather="mixed", seed=2)
    dni = frame["dni"].to_numpy().copy()
    dni[between(frame, "10:00", "10:30")] = np.nan
    dni[between(frame, "14:00", "14:20")] = -40.0
    result = simulate(frame.assign(dni=dni), "lanzhou")
    check_safety(result)
    nan_stretch = result.log.loc[between(frame, "10:00", "10:30")]
    assert (nan_stretch["sky"] == "unknown").any() and not (nan_stretch["sensor_status"] == "ok").any()
    assert (result.log.loc[between(frame, "10:05", "10:30"), "mode"] == "astronomical").all()
    assert np.isfinite(result.summary["tracking_error_deg"]["rms"])


def test_a_step_in_the_controller_clock_is_seen_and_taken_out():
    frame = sunny_day()
    clock = np.where(between(frame, "12:00", "23:59"), 600.0, 0.0)  # ten minutes forward at noon
    steady = SimulationConfig(imperfections=Imperfections(clock_drift=0.0))  # the step alone
    result = simulate(frame, "lanzhou", strategy="astronomical", faults={"clock": clock}, config=steady)
    clean = simulate(frame, "lanzhou", strategy="astronomical", config=steady)
    check_safety(result)
    assert result.events["reason"].str.contains("clock stepped by \\+600 s").sum() == 1
    afternoon = between(frame, "12:00", "18:00")
    np.testing.assert_allclose(tracked(result, afternoon), tracked(clean, afternoon), atol=1e-9)


def test_gray_code_round_trips_and_one_flipped_bit_is_one_wild_count():
    counts = np.arange(4096)
    assert (gray_decode(gray_encode(counts)) == counts).all()
    steps = gray_encode(counts[1:]) ^ gray_encode(counts[:-1])
    assert all(bin(int(step)).count("1") == 1 for step in steps)  # neighbouring counts differ in one bit


def test_an_encoder_glitch_is_ignored():
    frame = sunny_day()
    glitch = np.zeros(len(frame))
    at = int(np.flatnonzero(between(frame, "12:00", "12:01"))[0])
    count = 1200  # a reading of about 105°; one bit of its Gray code flips on the wire
    wild = int(gray_decode(gray_encode(count) ^ (1 << 9)))
    glitch[at] = (wild - count) * 360.0 / 4096
    clean = simulate(frame, "lanzhou")
    result = simulate(frame, "lanzhou", faults={"encoder": glitch})
    check_safety(result)
    assert result.events["reason"].str.startswith("encoder glitch").sum() == 1
    assert result.summary["travel_deg"] == pytest.approx(clean.summary["travel_deg"], abs=1.0)
    np.testing.assert_allclose(result.log["angle"], clean.log["angle"], atol=0.5)


def test_a_frozen_encoder_halts_the_drive_until_the_next_morning():
    frame = synthetic("nanjing", "2013-06-21", "2013-06-22", weather="sunny", seed=3)
    frozen = np.asarray((frame.index >= pd.Timestamp("2013-06-21 12:00", tz="Asia/Shanghai"))
                        & (frame.index < pd.Timestamp("2013-06-21 21:00", tz="Asia/Shanghai")))
    result = simulate(frame, "nanjing", faults={"encoder_frozen": frozen})
    check_safety(result)
    events = result.events
    halt = events[events["to"] == "fault"]
    assert len(halt) == 1 and "encoder frozen" in halt["reason"].iloc[0]
    after = result.log.loc[halt["time"].iloc[0]:pd.Timestamp("2013-06-22 04:00", tz="Asia/Shanghai")]
    assert after["angle"].nunique() <= 2 and (after["mode"] == "fault").all()  # at most the scan that found it
    assert "a new day: probing the encoder again" in events["reason"].tolist()
    next_day = result.log.loc[pd.Timestamp("2013-06-22 10:00", tz="Asia/Shanghai"):
                              pd.Timestamp("2013-06-22 14:00", tz="Asia/Shanghai"), "mode"]
    assert (next_day == "sensor").mean() > 0.5
    assert result.summary["faults"] == 1


def test_a_storm_all_day_keeps_the_collector_stowed():
    frame = sunny_day().assign(wind_speed=25.0)
    result = simulate(frame, "lanzhou")
    check_safety(result)
    assert result.summary["stow_events"] == 1 and result.summary["energy_capture"] == 0.0
    assert result.summary["mode_share"]["sensor"] == 0.0 and result.summary["mode_share"]["astronomical"] == 0.0
    assert result.log["angle"].nunique() == 1


def test_a_day_with_no_direct_sun_at_all():
    frame = synthetic("nanjing", "2013-06-21", weather="overcast", seed=4).assign(dni=0.0)
    result = simulate(frame, "nanjing")
    check_safety(result)
    assert result.summary["energy_capture"] is None and result.summary["tracking_error_deg"]["rms"] is None
    assert result.summary["mode_share"]["sensor"] == 0.0
    assert set(result.log["sensor_status"].astype(str)) <= {"low light", "not read"}


@pytest.mark.parametrize("date, sun", [("2022-06-21", "never sets"), ("2022-12-21", "never rises")])
def test_a_site_where_the_sun_never_sets_or_never_rises(date, sun):
    tromso = sites.custom(69.65, 18.96, "Europe/Oslo", name="tromso")
    frame = synthetic(tromso, date, weather="sunny", seed=5)
    result = simulate(frame, tromso)
    check_safety(result)
    if sun == "never sets":
        assert result.log["target_true"].notna().all()
        awake = result.log["mode"].isin(["sensor", "astronomical"])
        assert awake.mean() > 0.95  # the day is set by the sun: the midnight sun is tracked round the clock
        assert result.summary["tracking_error_deg"]["p95"] < 0.5
        hours = SimulationConfig(controller=ControllerConfig(working_hours=("05:00", "20:00")))
        limited = simulate(frame, tromso, config=hours).log
        tracked = limited.index.hour[limited["mode"].isin(["sensor", "astronomical"]).to_numpy()]
        assert tracked.min() >= 5 and tracked.max() <= 20  # clock hours, when given, still limit it
    else:
        assert result.log["target_true"].isna().all() and result.summary["moves"] == 0
        assert result.summary["mode_share"]["stow_night"] == 1.0


def test_the_southern_hemisphere():
    alice = sites.custom(-23.70, 133.88, "Australia/Darwin", 545, name="alice-springs")
    frame = synthetic(alice, "2022-12-21", weather="mixed", seed=6)
    runs = {s: simulate(frame, alice, strategy=s) for s in ("hybrid", "astronomical")}
    for result in runs.values():
        check_safety(result)
    rms = {name: run.summary["tracking_error_deg"]["rms"] for name, run in runs.items()}
    assert rms["hybrid"] < rms["astronomical"]
    assert runs["hybrid"].summary["tracking_error_deg"]["p95"] < 0.5


def test_replaying_a_file_across_a_dst_change(tmp_path, capsys):
    denver = sites.custom(39.74, -104.99, "America/Denver", 1609, name="denver")
    frame = synthetic(denver, "2021-03-14", weather="sunny", seed=7)
    local = frame.index.tz_convert("America/Denver").tz_localize(None)
    path = tmp_path / "denver.csv"
    pd.DataFrame({"time": local.strftime("%Y-%m-%d %H:%M"), "ghi": frame["ghi"].round(1), "dni": frame["dni"].round(1),
                  "dhi": frame["dhi"].round(1), "wind_speed": frame["wind_speed"].round(2)}).to_csv(path, index=False)
    out = tmp_path / "out"
    assert main(["replay", str(path), "--lat", "39.74", "--lon", "-104.99", "--tz", "America/Denver",
                 "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "naive stamps localised to America/Denver" in printed
    import json

    summary = json.loads((out / "summary.json").read_text())
    assert summary["steps"] == len(frame) and summary["tracking_error_deg"]["p95"] < 0.5


def test_a_replay_interrupted_by_a_bad_stretch_reports_it_and_carries_on(tmp_path, capsys):
    frame = synthetic("nanjing", "2013-06-21", weather="mixed", seed=8)
    local = frame.index.strftime("%Y-%m-%dT%H:%M:%S+08:00")
    table = pd.DataFrame({"time": local, "ghi": frame["ghi"].round(1).astype(str),
                          "dni": frame["dni"].round(1).astype(str), "dhi": frame["dhi"].round(1).astype(str),
                          "wind_speed": frame["wind_speed"].round(2).astype(str)})
    bad = slice(700, 720)  # twenty minutes of a logger writing garbage around noon
    table.loc[table.index[bad], ["ghi", "dni", "dhi"]] = "ERR#"
    path = tmp_path / "record.csv"
    table.to_csv(path, index=False)
    out = tmp_path / "out"
    assert main(["replay", str(path), "--site", "nanjing", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "set to NaN (unreadable text): ghi count 20, lines 702, 703, 704, 705, 706" in printed
    import json

    summary = json.loads((out / "summary.json").read_text())
    assert summary["steps"] == len(frame) and summary["tracking_error_deg"]["p95"] < 0.5
    log = pd.read_parquet(out / "log.parquet") if (out / "log.parquet").exists() else pd.read_csv(out / "log.csv")
    assert log["mode"].iloc[bad].isin(["astronomical", "stow_night"]).all()  # no sensor, no sky: the model


def test_a_gust_while_the_encoder_is_judged_frozen_stows_by_a_timed_move_and_is_logged():
    frame = synthetic("nanjing", "2013-06-21", weather="sunny", seed=3)
    clock = frame.index.tz_convert("Asia/Shanghai")
    frozen = np.asarray((clock.hour >= 12) & (clock.hour < 18))
    wind = np.clip(frame["wind_speed"].to_numpy(), 0.0, 11.0)
    storm = np.asarray((clock.hour == 14) & (clock.minute < 20))
    wind[storm] = 29.0
    result = simulate(frame.assign(wind_speed=wind), "nanjing", faults={"encoder_frozen": frozen})
    check_safety(result)
    log, events = result.log, result.events
    first = int(np.flatnonzero(storm)[0])
    assert log["mode"].iloc[first - 1] == "fault" and log["mode"].iloc[first] == "stow_wind"  # the same scan
    reason = events.loc[events["to"] == "stow_wind", "reason"].iloc[0]
    assert "29.0 m/s" in reason and "timed stow move" in reason
    stowed = log["angle"].iloc[first + 3]
    assert abs(stowed - 90.0) < 3.0  # a timed move from the reckoned position: near stow, no encoder
    released = events[(events["from"] == "stow_wind") & (events["to"] == "fault")]
    assert len(released) == 1 and "encoder still judged frozen" in released["reason"].iloc[0]


def test_an_anemometer_stuck_in_daylight_raises_an_alarm_and_counts_as_missing():
    frame = synthetic("lanzhou", "2021-06-21", weather="sunny", seed=2)
    clock = frame.index.tz_convert("Asia/Shanghai")
    wind = frame["wind_speed"].to_numpy().copy()
    wind[clock.hour >= 9] = 0.0  # stuck at zero from 09:00 on
    result = simulate(frame.assign(wind_speed=wind), "lanzhou")
    check_safety(result)
    alarm = result.events[result.events["reason"].str.contains("anemometer stuck at 0.00 m/s")]
    assert len(alarm) == 1 and alarm["time"].iloc[0].tz_convert("Asia/Shanghai").hour == 12  # 3 h of daylight
    after = result.log.loc[alarm["time"].iloc[0]:]
    assert (after.loc[after["target_true"].notna(), "mode"] == "stow_wind").all()  # missing wind: stow
    stowed = result.events.loc[result.events["to"] == "stow_wind", "reason"]
    assert list(stowed) == ["wind reading missing"]  # not "wind 0.0 m/s > 17.2": the stuck reading is no speed
    track = SimulationConfig(controller=ControllerConfig(wind_missing="track"))
    tracked_on = simulate(frame.assign(wind_speed=wind), "lanzhou", config=track)
    assert tracked_on.events["reason"].str.contains("anemometer stuck").any()
    assert tracked_on.summary["energy_capture"] > 0.95


def test_a_clock_that_creeps_is_caught_with_its_rate_and_taken_out():
    frame = sunny_day()
    steps = np.arange(len(frame), dtype=float)
    creep = np.where(steps >= 600, (steps - 600) * 4.0, 0.0)  # 4 s more every scan from 10:00: under the step detector
    result = simulate(frame, "lanzhou", strategy="astronomical", faults={"clock": creep})
    check_safety(result)
    alarm = result.events[result.events["reason"].str.contains("clock creeping")]
    assert len(alarm) == 1 and "+240 s an hour" in alarm["reason"].iloc[0]
    assert alarm["time"].iloc[0] <= pd.Timestamp("2021-06-21 11:01", tz="Asia/Shanghai")
    assert tracked(result).abs().max() < 1.0  # without the alarm the error would reach 17-20 degrees


def test_a_replayed_file_without_wind_is_tracked_through_and_says_so(tmp_path, capsys):
    frame = synthetic("lanzhou", "2021-06-21", weather="sunny", seed=1)[["ghi", "dni", "dhi"]]
    path = tmp_path / "no-wind.csv"
    frame.to_csv(path)
    assert main(["replay", str(path), "--site", "lanzhou", "--out", str(tmp_path / "out")]) == 0
    out = capsys.readouterr().out
    assert "wind: MISSING" in out and "not as calm" in out
    import json

    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["wind_data"] == "missing" and summary["energy_capture"] > 0.95
    assert simulate(frame, "lanzhou").summary["mode_share"]["stow_wind"] > 0.4  # a live controller stows instead


@pytest.mark.parametrize("scenario, better", [("sensor-bias", "model"), ("sensor-drift", "model"),
                                              ("encoder-step", "sensor")])
def test_whom_to_trust_on_a_disagreement_is_a_policy_and_each_wins_where_it_should(scenario, better):
    """A biased or drifting sensor is caught by trusting the model; a slipped encoder coupling (the
    mount moved, the sensor is right) by trusting the sensor. Both log the disagreement."""
    from hybridtrack.faults import SCENARIOS

    case = SCENARIOS[scenario]
    frame, faults, _, onset = case.build(case.site)
    rms = {}
    for policy in ("model", "sensor"):
        config = SimulationConfig(controller=ControllerConfig(on_disagreement=policy))
        result = simulate(frame, case.site, config=config, faults=faults)
        after = result.log["error"][result.log.index >= result.log.index[0].normalize() + pd.Timedelta(onset + ":00")]
        rms[policy] = float(np.sqrt(np.nanmean(after.to_numpy() ** 2)))
        reasons = result.events["reason"]
        assert reasons.str.contains("disagree").any()
        assert reasons.str.contains("rolled back" if policy == "model" else "sensor trusted").any()
    other = "sensor" if better == "model" else "model"
    assert rms[better] < 0.6 * rms[other], rms


def test_an_unknown_trust_policy_is_refused():
    with pytest.raises(HybridtrackError, match="on_disagreement 'both'; choose 'model' or 'sensor'"):
        ControllerConfig(on_disagreement="both")


@pytest.mark.parametrize("policy", ["model", "sensor"])
def test_a_creeping_encoder_that_leaves_the_sensor_beyond_the_bound_raises_an_alarm_naming_both_suspects(policy):
    """A coupling slipping 1° an hour from 11:00: the sensor (which is right) ends beyond the
    plausibility bound of the calibrated model and is no longer used. Held there an hour with no
    plausible reading, the controller says so once, naming how far off the sensor reads: by hand,
    the slip then is (alarm time - 11:00) x 1°/h, less what the calibration took up before the
    readings went beyond the bound (under 2°, the bound itself)."""
    from hybridtrack.faults import SCENARIOS

    case = SCENARIOS["encoder-creep"]
    frame, faults, _, onset = case.build(case.site)
    config = SimulationConfig(controller=ControllerConfig(on_disagreement=policy))
    result = simulate(frame, case.site, config=config, faults=faults)
    events = result.events[result.events["reason"].str.contains("held beyond the plausibility bound")]
    assert len(events) == 1
    reason, when = events["reason"].iloc[0], events["time"].iloc[0]
    assert "slipping coupling" in reason and "faulty sensor" in reason
    slip = (when - when.normalize() - pd.Timedelta(onset + ":00")) / pd.Timedelta(hours=1)
    miss = float(reason.split("°")[0].split()[-1])
    assert slip - 2.0 <= miss <= slip + 0.3, (slip, miss)
    status = result.log["sensor_status"]
    held = status.index[(status == "implausible") & (status.index < when)]
    assert when - held[0] >= pd.Timedelta(minutes=60)  # not before an hour beyond the bound


def test_a_healthy_sensor_on_a_sunny_day_raises_no_held_off_alarm():
    frame = synthetic("lanzhou", "2021-06-21", weather="sunny", seed=1)
    assert not simulate(frame, "lanzhou").events["reason"].str.contains("held beyond").any()


@pytest.mark.slow
@pytest.mark.parametrize("site", ["lanzhou", "nanjing"])
def test_a_healthy_year_under_clouds_raises_no_held_off_alarm(site):
    """A sensor trusted under every sky (hybrid-always), pulled by cloud light a whole climate year,
    is never beyond the bound an hour without a plausible reading between."""
    frame = synthetic(site, "2021-01-01", "2021-12-31", weather="climate", seed=2)
    result = simulate(frame, site, strategy="hybrid-always")
    assert not result.events["reason"].str.contains("held beyond").any()


@pytest.mark.parametrize("engine", ["reference", "compiled"])
def test_a_stuck_anemometer_stays_stuck_through_the_night(engine):
    """Stuck at 3.00 m/s from 08:00 on the first of two sunny days: alarmed at 11:00, and at dusk
    the guard had forgotten it, so the next morning the same 3.00 m/s was 'moving again' and taken
    for calm for three more hours of daylight (helper-45). It stays stuck until a reading moves,
    and the night is stepped (not passed over in bulk) while it is, alike on either setting."""
    import dataclasses

    frame = synthetic("lanzhou", "2021-06-21", "2021-06-22", weather="sunny", seed=1)
    wind = np.clip(frame["wind_speed"].to_numpy(), 0.0, 11.0)
    wind[8 * 60:] = 3.0
    config = dataclasses.replace(SimulationConfig(), engine=engine)
    result = simulate(frame.assign(wind_speed=wind), "lanzhou", config=config)
    reasons = result.events["reason"]
    assert reasons.str.contains("anemometer stuck at 3.00 m/s").sum() == 1
    assert not reasons.str.contains("anemometer moving again").any()
    day_two = result.log.loc["2021-06-22 05:00":"2021-06-22 23:59", "mode"]
    assert (day_two == "stow_wind").all()  # missing wind: stowed all day, as from 11:00 on the first
    stepped = simulate(frame.assign(wind_speed=wind), "lanzhou", config=config, bulk_nights=False)
    pd.testing.assert_frame_equal(result.log, stepped.log)
    pd.testing.assert_frame_equal(result.events, stepped.events)


def test_a_stuck_anemometer_is_judged_through_missing_readings_and_cleared_when_it_moves():
    """A reading missing every two hours had restarted the three-hour count, so an anemometer stuck
    at 3.00 m/s with a dropout now and then was never judged (helper-45); a reading off the value
    clears it, by night as by day."""
    frame = synthetic("lanzhou", "2021-06-21", weather="sunny", seed=1)
    wind = np.clip(frame["wind_speed"].to_numpy(), 0.0, 11.0)
    wind[8 * 60:] = 3.0
    wind[np.arange(9 * 60, 24 * 60, 120)] = np.nan  # a dropout every two hours from 09:00
    wind[22 * 60:] = 0.4  # a calm night after ten: the anemometer moves
    result = simulate(frame.assign(wind_speed=wind), "lanzhou")
    events = result.events.set_index(result.events["time"].dt.tz_convert("Asia/Shanghai").dt.strftime("%H:%M"))
    stuck = events["reason"].str.contains("anemometer stuck at 3.00 m/s")
    assert list(events.index[stuck]) == ["11:01"]  # three hours from 08:00; 11:00 itself is a dropout
    moving = events["reason"].str.contains("anemometer moving again")
    assert list(events.index[moving]) == ["22:00"]


@pytest.mark.parametrize("engine", ["reference", "compiled"])
def test_the_sensor_only_tracker_says_when_its_sensor_sticks_and_searches_with_its_cells(engine):
    """It has no sun model to fall back on; with its fine sensor stuck it had coasted, then held
    while the sun moved on (37.4° off on a north-south trough) and said nothing (helper-45). Stuck
    for `sensor_loss` (3 min), it says so and follows the sun on its acquisition cells."""
    import dataclasses

    from hybridtrack.faults import SCENARIOS

    scenario = SCENARIOS["sensor-stuck"]
    frame, faults, _, _ = scenario.build(scenario.site)
    config = dataclasses.replace(SimulationConfig(), engine=engine)
    result = simulate(frame, scenario.site, collector="trough-ns", strategy="sensor", faults=faults, config=config)
    lost = result.events[result.events["reason"] == "sensor lost (stuck)"]
    assert len(lost) >= 1 and (lost["to"] == "search").all()
    midday = result.log.between_time("11:00", "14:30")
    assert midday["error"].abs().max() < 10.0  # the cells' coarse aim, where holding had reached 37°
