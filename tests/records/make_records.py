"""Write the recorded-file corpus: known weather (the truths) in the shapes real loggers write.

``python tests/records/make_records.py`` rewrites every file here from the truth tables
(``truth-*.csv``, plain ISO-UTC CSV read with pandas alone). The truths were made once with
hybridtrack's synthetic sky; the script only reshapes them, so a reader that gets a file right
gives back exactly the truth. `CASES` says, for each file, the flags it is read with and what
must come out: the truth's stamps and values (with the changes the file's quirks call for) or
a refusal naming the problem, row and column. README.md here says what each file imitates.
"""

from __future__ import annotations

import gzip
import io
import zipfile
from pathlib import Path

import numpy as np
import pandas as pd

HERE = Path(__file__).resolve().parent
SHANGHAI, MST, PST = "Asia/Shanghai", "Etc/GMT+7", "Etc/GMT+8"
WEATHER = ["ghi", "dni", "dhi", "wind_speed", "temp_air"]


def make_truths() -> None:  # pragma: no cover - run once; the truths are committed
    from hybridtrack import sites
    from hybridtrack.sky import synthetic

    golden = sites.custom(39.742, -105.18, MST, 1829.0, name="golden")
    bondville = sites.custom(40.05, -88.37, "UTC", 213.0, name="bondville")
    eugene = sites.custom(44.0467, -123.0743, PST, 150.0, name="eugene")
    specs = {"lanzhou-day": ("lanzhou", "2021-06-05 05:00", "2021-06-05 21:00", "10min", "sunny"),
             "lanzhou-days": ("lanzhou", "2021-06-05", "2021-06-14", "1h", "mixed"),
             "golden-day": (golden, "2021-06-05 05:00", "2021-06-05 20:00", "10min", "sunny"),
             "bondville-day": (bondville, "2021-06-05", "2021-06-05", "10min", "sunny"),
             "eugene-day": (eugene, "2021-06-05 04:00", "2021-06-05 21:00", "10min", "sunny")}
    for name, (site, start, end, freq, weather) in specs.items():
        frame = synthetic(site, start, end, weather=weather, freq=freq, seed=3)[WEATHER]
        frame = frame.round({"ghi": 1, "dni": 1, "dhi": 1, "wind_speed": 2, "temp_air": 1})
        frame.index = frame.index.tz_convert("UTC").strftime("%Y-%m-%dT%H:%M:%SZ")
        frame.to_csv(HERE / f"truth-{name}.csv", index_label="time")


def truth(name: str) -> pd.DataFrame:
    """A truth table: UTC stamps, the weather columns in the frame's units."""
    frame = pd.read_csv(HERE / f"truth-{name}.csv", index_col="time")
    frame.index = pd.DatetimeIndex(pd.to_datetime(frame.index, utc=True))
    return frame


def _local(frame: pd.DataFrame, tz: str, fmt: str) -> pd.Index:
    return frame.index.tz_convert(tz).strftime(fmt)


def _csv(frame: pd.DataFrame, **options) -> str:
    buffer = io.StringIO()
    frame.to_csv(buffer, lineterminator="\n", **options)
    return buffer.getvalue()


def _renamed(frame: pd.DataFrame, names: dict, stamps, stamp_name=None) -> pd.DataFrame:
    out = frame.rename(columns=names)[[names[c] for c in names]]
    out.index = pd.Index(stamps, name=stamp_name)
    return out


# --- the files -------------------------------------------------------------------------------

def pandas_index() -> str:
    day = truth("lanzhou-day")
    day.index = day.index.tz_convert(SHANGHAI).rename(None)
    return _csv(day)  # pandas writes the index without a name: the header starts with ','


def pandas_index_naive() -> str:
    day = truth("lanzhou-day")
    day.index = day.index.tz_convert(SHANGHAI).tz_localize(None).rename(None)
    return _csv(day)


def toa5(wind_name="WS_ms_Avg", offsets=False) -> str:
    day = truth("lanzhou-day")
    names = {"ghi": "GHI_Avg", "dni": "DNI_Avg", "dhi": "DHI_Avg", "wind_speed": wind_name, "temp_air": "AirTC_Avg"}
    out = _renamed(day, names, _local(day, SHANGHAI, "%Y-%m-%d %H:%M:%S"))
    if offsets:  # an anemometer's zero offset in calm air before sunrise
        out.iloc[:4, out.columns.get_loc(wind_name)] = [-0.12, -0.3, -0.05, -0.2]
    out.insert(0, "RECORD", np.arange(len(out)))
    rows = [f'"{t}",' + ",".join(f"{v:g}" for v in row) for t, row in zip(out.index, out.to_numpy())]
    head = ['"TOA5","LZ_roof","CR1000","12345","CR1000.Std.32","CPU:solar.CR1","4321","Ten_Min"',
            '"TIMESTAMP",' + ",".join(f'"{c}"' for c in out.columns),
            '"TS","RN","W/m^2","W/m^2","W/m^2","meters/second","Deg C"',
            '"","","Avg","Avg","Avg",' + ('"WVc"' if "WVT" in wind_name else '"Avg"') + ',"Avg"']
    return "\n".join(head + rows) + "\n"


def toa5_padded() -> bytes:
    """A TOA5 file copied whole from a logger's card: NUL bytes after the last line."""
    return toa5().encode("utf-8") + b"\x00" * 512


def dotted_dates() -> str:
    day = truth("lanzhou-day")
    out = _renamed(day, {"ghi": "Global", "dni": "Direct", "dhi": "Diffuse", "wind_speed": "Wind",
                         "temp_air": "Temp"}, _local(day, SHANGHAI, "%d.%m.%Y %H:%M"), "Datum")
    return "Anlage: Lanzhou Dach\n" + _csv(out, sep=";", decimal=",")


def _date_and_clock(frame, names: dict, zone, date: tuple, clock: str):
    """`frame` renamed (`names`), its local date in a column (``date``: name and format) and its
    local clock in column `clock` first, as loggers that split the stamp write it."""
    out = _renamed(frame, names, _local(frame, zone, date[1]), date[0])
    out.insert(0, clock, _local(frame, zone, "%H:%M"))
    return out


def iso_t_semicolons() -> str:
    day = truth("lanzhou-day")
    out = _renamed(day, {"ghi": "GHI (W/m2)", "dni": "DNI (W/m2)", "dhi": "DHI (W/m2)",
                         "wind_speed": "Wind speed (m/s)", "temp_air": "Temperature (°C)"}, _local(day, SHANGHAI, "%Y-%m-%dT%H:%M:%S"), "Timestamp")
    return _csv(out, sep=";", decimal=",")


def french_date_heure() -> bytes:
    days = truth("lanzhou-days")
    out = _date_and_clock(days, {"ghi": "Rayonnement global (W/m²)", "dni": "Rayonnement direct (W/m²)",
                                 "dhi": "Rayonnement diffus (W/m²)", "wind_speed": "Vitesse du vent (m/s)",
                                 "temp_air": "Température (°C)"}, SHANGHAI, ("Date", "%d/%m/%Y"), "Heure")
    return _csv(out, sep=";", decimal=",").replace("\n", "\r\n").encode("cp1252")


def tab_decimal_commas() -> bytes:
    day = truth("lanzhou-day")
    out = _renamed(day, {"ghi": "GHI", "dni": "DNI", "dhi": "DHI", "temp_air": "Temperatur (°C)"},
                   _local(day, SHANGHAI, "%d.%m.%Y %H:%M"), "Zeitstempel")
    return _csv(out, sep="\t", decimal=",").replace("\n", "\r\n").encode("cp1252")


def quoted_decimal_commas() -> str:
    day = truth("lanzhou-day")
    out = _renamed(day, {"ghi": "GHI", "dni": "DNI", "dhi": "DHI", "wind_speed": "Wind", "temp_air": "Temp"},
                   _local(day, SHANGHAI, "%Y-%m-%d %H:%M"), "Timestamp")
    return _csv(out, decimal=",")  # the cells holding a comma quoted, as LibreOffice writes them


def day_month(fmt: str, name: str = "lanzhou-days") -> str:
    days = truth(name)
    out = _renamed(days, {"ghi": "GHI", "dni": "DNI", "dhi": "DHI"}, _local(days, SHANGHAI, fmt), "Date/Time")
    return _csv(out)


def clock_only() -> str:
    day = truth("lanzhou-day")
    return _csv(_renamed(day, {"ghi": "GHI", "dni": "DNI"}, _local(day, SHANGHAI, "%H:%M"), "Time"))


def date_and_time_columns() -> str:
    day = truth("lanzhou-day")
    out = _renamed(day, {"ghi": "GHI", "dni": "DNI", "dhi": "DHI", "wind_speed": "WindSpeed"},
                   _local(day, SHANGHAI, "%Y-%m-%d"), "Date")
    out.insert(0, "Time", _local(day, SHANGHAI, "%H:%M"))
    return _csv(out)


def epoch_seconds() -> str:
    day = truth("lanzhou-day")
    seconds = (day.index - pd.Timestamp("1970-01-01", tz="UTC")) // pd.Timedelta(seconds=1)
    return _csv(_renamed(day, {"ghi": "ghi", "dni": "dni", "dhi": "dhi", "wind_speed": "wind"}, seconds, "epoch"))


def utc_declared_local() -> str:
    day = truth("lanzhou-day")
    return _csv(_renamed(day, {"ghi": "GHI", "dni": "DNI", "dhi": "DHI", "wind_speed": "WS"},
                         _local(day, "UTC", "%Y-%m-%d %H:%M"), "TIMESTAMP"))


def kilowatts(label: bool) -> str:
    day = truth("lanzhou-day")
    unit = " [kW/m²]" if label else ""
    out = _renamed(day, {"ghi": f"GHI{unit}", "dni": f"DNI{unit}", "dhi": f"DHI{unit}", "wind_speed": "Wind"},
                   _local(day, SHANGHAI, "%Y-%m-%dT%H:%M:%S+08:00"), "time")
    out.iloc[:, :3] = out.iloc[:, :3] / 1000.0
    return _csv(out, float_format="%.4f")


def non_finite() -> str:
    text = _csv(_renamed(truth("lanzhou-day"), {"ghi": "ghi", "dni": "dni", "dhi": "dhi", "wind_speed": "wind_speed"},
                         _local(truth("lanzhou-day"), SHANGHAI, "%Y-%m-%dT%H:%M:%S+08:00"), "time"))
    lines = text.splitlines()
    for row, word in ((50, "inf"), (51, "1e400")):  # file lines 51 and 52: DNI broken by a logger bug
        fields = lines[row].split(",")
        fields[2] = word
        lines[row] = ",".join(fields)
    return "\n".join(lines) + "\n"


def caret_units() -> str:
    day = truth("lanzhou-day")
    out = _renamed(day, {"ghi": "GHI (W/m^2)", "dni": "DNI (W m-2)", "dhi": "DHI (W/m2)", "wind_speed": "Wind (km/h)",
                         "temp_air": "Temp (K)"}, _local(day, SHANGHAI, "%Y-%m-%dT%H:%M:%S+08:00"), "Timestamp")
    out["Wind (km/h)"] = (out["Wind (km/h)"] * 3.6).round(3)
    out["Temp (K)"] = (out["Temp (K)"] + 273.15).round(2)
    return _csv(out)


def header_note() -> str:
    day = truth("lanzhou-day")
    out = _renamed(day, {"ghi": "GHI (CM21)", "dni": "DNI (vent/cor)", "dhi": "DHI (shaded)"},
                   _local(day, SHANGHAI, "%Y-%m-%dT%H:%M:%S+08:00"), "time")
    return _csv(out)


def semicolon_zero_rows() -> str:
    day = truth("lanzhou-day")
    out = _renamed(day, {"ghi": "GHI", "dni": "DNI"}, _local(day, SHANGHAI, "%Y-%m-%d %H:%M"), "Zeit")
    text = _csv(out, sep=";", decimal=",")
    return text.replace(";0,0;0,0\n", ";0;0\n")  # night rows written as bare zeros, as some loggers do


def plain() -> str:
    day = truth("lanzhou-day")
    return _csv(_renamed(day, {"ghi": "GHI", "dni": "DNI", "dhi": "DHI", "wind_speed": "Wind speed",
                               "temp_air": "Temperature"}, _local(day, SHANGHAI, "%Y-%m-%d %H:%M"), "Timestamp"))


def excel_unicode() -> bytes:
    day = truth("lanzhou-day")
    out = _renamed(day, {"ghi": "GHI", "dni": "DNI", "dhi": "DHI", "temp_air": "Temperatur (°C)"},
                   _local(day, SHANGHAI, "%Y-%m-%d %H:%M"), "Zeitstempel")
    return _csv(out, sep="\t").replace("\n", "\r\n").encode("utf-16")  # Excel's "Unicode text": UTF-16 with BOM, tabs


def latin1() -> bytes:
    day = truth("lanzhou-day")
    out = _renamed(day, {"ghi": "GHI", "dni": "DNI", "temp_air": "Température (°C)"},
                   _local(day, SHANGHAI, "%Y-%m-%d %H:%M"), "Horodatage")
    return ("Station : Lanzhou, capteur n°2\n" + _csv(out, sep=";", decimal=",")).encode("latin-1")


def utf8_bom() -> bytes:
    return ("\ufeff" + plain()).encode("utf-8")


def comments_anywhere() -> str:
    lines = plain().splitlines()
    lines.insert(0, "# exported by LoggerNet, site Lanzhou roof")
    lines.insert(40, "# 11:30 pyranometer cleaned")
    lines.insert(70, "   # power dip, logger restarted")
    return "\n".join(lines) + "\n"


def messy() -> str:
    """Repeated and out-of-order rows, negative night GHI, 'NAN' cells."""
    lines = plain().splitlines()
    header, rows = lines[0], lines[1:]
    rows[1] = rows[1].replace(",0.0,0.0,0.0,", ",-2.5,0.0,0.0,", 1)
    rows[60] = ",".join(rows[60].split(",")[:2] + ["NAN"] + rows[60].split(",")[3:])
    rows[30], rows[31] = rows[31], rows[30]
    rows.insert(80, rows[79])
    return "\n".join([header] + rows) + "\n"


def ghi_only() -> str:
    day = truth("lanzhou-day")
    return _csv(_renamed(day, {"ghi": "SlrW_Avg"}, _local(day, SHANGHAI, "%Y-%m-%dT%H:%M:%S+08:00"), "TIMESTAMP"))


def epw() -> str:
    days = truth("lanzhou-days").iloc[:48]  # two days, hours ending at the stamp (EPW's convention)
    local = days.index.tz_convert("Etc/GMT-8") - pd.Timedelta(hours=1)
    head = ["LOCATION,Lanzhou,GS,CHN,SYN,528890,36.1056,103.7264,8.0,1520.0", "DESIGN CONDITIONS,0",
            "TYPICAL/EXTREME PERIODS,0", "GROUND TEMPERATURES,0", "HOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0",
            "COMMENTS 1,hybridtrack corpus", "COMMENTS 2,two days", "DATA PERIODS,1,1,Data,Saturday, 6/ 5, 6/ 6"]
    rows = []
    for stamp, row in zip(local, days.itertuples()):
        flags = "?9?9?9?9E0?9?9?9?9?9?9?9?9?9?9?9?9?9?9*9*9?9"
        fields = [stamp.year, stamp.month, stamp.day, stamp.hour + 1, 60, flags,
                  row.temp_air, 5.0, 40, 84000, 0, 0, 350, row.ghi, row.dni, row.dhi, 0, 0, 0, 0, 180, row.wind_speed,
                  5, 5, 20.0, 77777, 9, 999999999, 0, 0.1, 0, 88, 0.2, 0, 1]
        rows.append(",".join(map(str, fields)))
    return "\n".join(head + rows) + "\n"


#: NSRDB PSM3's site lines (the v3.2.2 CSV the NSRDB API and Data Viewer give): names, then values.
_PSM3_NAMES = ("Source,Location ID,City,State,Country,Latitude,Longitude,Time Zone,Elevation,Local Time Zone,"
               "Dew Point Units,DHI Units,DNI Units,GHI Units,Temperature Units,Pressure Units,Relative Humidity Units,"
               "Precipitable Water Units,Wind Direction Units,Wind Speed Units,Cloud Type -15,Cloud Type 0,"
               "Cloud Type 1,Cloud Type 2,Cloud Type 3,Cloud Type 4,Cloud Type 5,Cloud Type 6,Cloud Type 7,"
               "Cloud Type 8,Cloud Type 9,Cloud Type 10,Cloud Type 11,Cloud Type 12,Fill Flag 0,Fill Flag 1,"
               "Fill Flag 2,Fill Flag 3,Fill Flag 4,Fill Flag 5,Surface Albedo Units,Version")
_PSM3_VALUES = ("NSRDB,149190,-,-,-,39.74,-105.18,{zone},1829,-7,c,w/m2,w/m2,w/m2,c,mbar,%,cm,Degrees,m/s,N/A,Clear,"
                "Probably Clear,Fog,Water,Super-Cooled Water,Mixed,Opaque Ice,Cirrus,Overlapping,Overshooting,Unknown,"
                "Dust,Smoke,N/A,Missing Image,Low Irradiance,Exceeds Clearsky,Missing CLoud Properties,"
                "Rayleigh Violation,N/A,3.2.2")
_PSM3_HEADER = ("Year,Month,Day,Hour,Minute,DHI,DNI,GHI,Clearsky DHI,Clearsky DNI,Clearsky GHI,Cloud Type,Dew Point,"
                "Solar Zenith Angle,Fill Flag,Surface Albedo,Wind Speed,Precipitable Water,Wind Direction,"
                "Relative Humidity,Temperature,Pressure")


def psm3(zone: int) -> str:
    """An NSRDB PSM3 half-hourly CSV at Golden, its stamps in UTC`zone` (0: a UTC download; -7: the
    site's standard time): irradiance in whole W/m², wind in tenths of m/s, as NSRDB writes them."""
    import pvlib

    day = truth("golden-day").iloc[::3]  # 05:00, 05:30, ... MST
    zenith = pvlib.solarposition.get_solarposition(day.index, 39.74, -105.18)["zenith"].to_numpy()
    rows = []
    for stamp, row, angle in zip(day.index.tz_convert(f"Etc/GMT{-zone:+d}"), day.itertuples(), zenith):
        rows.append(f"{stamp.year},{stamp.month},{stamp.day},{stamp.hour},{stamp.minute},{row.dhi:.0f},{row.dni:.0f},"
                    f"{row.ghi:.0f},{row.dhi:.0f},{row.dni:.0f},{row.ghi:.0f},0,2.0,{angle:.2f},0,0.18,"
                    f"{row.wind_speed:.1f},1.2,200,30.5,{row.temp_air:.1f},820")
    return "\n".join([_PSM3_NAMES, _PSM3_VALUES.format(zone=zone), _PSM3_HEADER] + rows) + "\n"


def midc() -> str:
    day = truth("golden-day")
    out = _date_and_clock(day, {"ghi": "Global Horizontal [W/m^2]", "dni": "Direct Normal [W/m^2]",
                                "dhi": "Diffuse Horizontal [W/m^2]", "wind_speed": "Avg Wind Speed @ 6ft [m/s]",
                                "temp_air": "Tower Dry Bulb Temp [deg C]"}, MST, ("DATE (MM/DD/YYYY)", "%m/%d/%Y"), "MST")
    return _csv(out)


def surfrad() -> str:
    day = truth("bondville-day")
    rows = []
    for stamp, row in zip(day.index, day.itertuples()):
        values = {"dw_solar": row.ghi, "direct_n": row.dni, "diffuse": row.dhi, "temp": row.temp_air,
                  "windspd": row.wind_speed}
        fields = [stamp.year, stamp.day_of_year, stamp.month, stamp.day, stamp.hour, stamp.minute,
                  f"{stamp.hour + stamp.minute / 60:.3f}", "45.00"]
        for name in ("dw_solar", "uw_solar", "direct_n", "diffuse", "dw_ir", "dw_casetemp", "dw_dometemp", "uw_ir",
                     "uw_casetemp", "uw_dometemp", "uvb", "par", "netsolar", "netir", "totalnet", "temp", "rh",
                     "windspd", "winddir", "pressure"):
            fields += [f"{values.get(name, 0.0):.1f}", "0"]
        rows.append(" ".join(map(str, fields)))
    return "Bondville\n   40.05  -88.37  213 m version   1\n" + "\n".join(rows) + "\n"


def srml() -> str:
    """A University of Oregon SRML archival file: tabs, element numbers, day of year, interval-end HHMM in PST."""
    day = truth("eugene-day")
    local = day.index.tz_convert(PST) + pd.Timedelta(minutes=10)  # stamped at the interval's end
    head = "94255\t2021\t1000\t0\t2010\t0\t3000\t0\t9300\t0\t9210\t0"
    rows = []
    for stamp, row in zip(local, day.itertuples()):
        clock = 2400 if stamp.hour == 0 and stamp.minute == 0 else stamp.hour * 100 + stamp.minute
        values = (row.ghi, row.dni, row.dhi, row.temp_air, row.wind_speed)
        rows.append("\t".join([str((stamp - pd.Timedelta(minutes=1)).day_of_year), str(clock)]
                              + [f"{v:g}\t11" for v in values]))
    return "\n".join([head] + rows) + "\n"


def bsrn() -> str:
    """A BSRN station-to-archive file: logical records *U0001, *U0004 (station, coordinates) and *U0100,
    two fixed-width lines per step (GHI and DNI; DHI, long-wave, temperature, humidity, pressure), UTC."""
    day = truth("bondville-day")
    head = ["*U0001", " 31  6 2021   1", "*U0004", " -1 -1 -1", "  1  1", "Bondville, Illinois, USA",
            "217 333 0000        217 333 0000", "0.0.0.0        bsrn@example.org",
            "  130.05   91.63  213 72531", " -1 -1 -1", "   0   0  90   0 180   0 270   0", "*U0100"]
    rows = []
    for stamp, row in zip(day.index, day.itertuples()):
        minute = stamp.hour * 60 + stamp.minute
        first = (f"{stamp.day:3d} {minute:5d} {row.ghi:6.1f}{0.0:6.1f}{row.ghi:5.0f}{row.ghi:5.0f}"
                 f"{row.dni:7.1f}{0.0:6.1f}{row.dni:5.0f}{row.dni:5.0f}")
        second = (f"{'':3} {'':5} {row.dhi:6.1f}{0.0:6.1f}{row.dhi:5.0f}{row.dhi:5.0f}{350.0:7.1f}{0.0:6.1f}"
                  f"{340:5d}{360:5d}{row.temp_air:9.1f}{50.0:6.1f}{990:5d}")
        rows += [first, second]
    return "\n".join(head + rows) + "\n"


def naive_no_zone() -> str:
    return pandas_index_naive()


def _packed_gzip() -> bytes:
    return gzip.compress(plain().encode("utf-8"), mtime=0)


def _packed_zip() -> bytes:
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w") as archive:
        info = zipfile.ZipInfo("logger.csv", date_time=(2021, 6, 5, 0, 0, 0))
        archive.writestr(info, plain())
    return buffer.getvalue()


FILES = {
    "pandas-index.csv": pandas_index, "pandas-index-naive.csv": pandas_index_naive,
    "toa5-cr1000.dat": toa5, "toa5-wvt-offsets.dat": lambda: toa5("WS_ms_S_WVT", offsets=True),
    "toa5-nul-padded.dat": toa5_padded, "dotted-dates.csv": dotted_dates,
    "ddmmyyyy-days.csv": lambda: day_month("%d/%m/%Y %H:%M"),
    "mmddyyyy-days.csv": lambda: day_month("%m/%d/%Y %H:%M"),
    "ambiguous-dates.csv": lambda: day_month("%d/%m/%Y %H:%M", "lanzhou-day"),
    "yymmdd-days.csv": lambda: day_month("%y-%m-%d %H:%M"),
    "yymmdd-one-day.csv": lambda: day_month("%y-%m-%d %H:%M", "lanzhou-day"),
    "yymmdd-six-digits.csv": lambda: day_month("%y%m%d %H:%M"),
    "clock-first-days.csv": lambda: day_month("%H:%M:%S %d/%m/%Y"),
    "iso-t-semicolons.csv": iso_t_semicolons, "french-date-heure.csv": french_date_heure,
    "tab-decimal-commas.txt": tab_decimal_commas, "quoted-decimal-commas.csv": quoted_decimal_commas,
    "clock-only.csv": clock_only, "date-and-time-columns.csv": date_and_time_columns,
    "epoch-seconds.csv": epoch_seconds,
    "utc-declared-local.csv": utc_declared_local, "kilowatts-unlabelled.csv": lambda: kilowatts(False),
    "kilowatts-labelled.csv": lambda: kilowatts(True), "non-finite.csv": non_finite, "caret-units.csv": caret_units,
    "header-notes.csv": header_note, "semicolon-zero-rows.csv": semicolon_zero_rows, "plain.csv": plain,
    "logger.csv.gz": _packed_gzip, "logger.zip": _packed_zip, "excel-unicode.txt": excel_unicode,
    "latin1.csv": latin1, "utf8-bom.csv": utf8_bom, "comments-anywhere.csv": comments_anywhere, "messy.csv": messy,
    "nsrdb-psm3-local.csv": lambda: psm3(-7), "nsrdb-psm3-utc.csv": lambda: psm3(0),
    "ghi-only.csv": ghi_only, "lanzhou.epw": epw, "midc-bms.csv": midc, "surfrad-bon.dat": surfrad,
    "naive-no-zone.csv": naive_no_zone, "srml-eugene.tsv": srml, "bsrn-bon.dat": bsrn,
}


def write_all() -> list[Path]:
    written = []
    for name, make in FILES.items():
        content = make()
        path = HERE / name
        path.write_bytes(content if isinstance(content, bytes) else content.encode("utf-8"))
        written.append(path)
    return written


if __name__ == "__main__":  # pragma: no cover
    import sys

    if "--truths" in sys.argv:
        make_truths()
    for path in write_all():
        print(path.relative_to(HERE.parent.parent))
