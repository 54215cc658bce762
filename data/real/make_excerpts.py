"""Cut the real-sky excerpts in this folder from the files pvlib and pvanalytics ship.

The sources are the test and example data inside two packages' source distributions
(see README.md for licences and stations). Get them with pip, then run this script::

    pip download --no-binary :all: --no-deps pvlib==0.16.1 pvanalytics==0.2.2 -d /tmp/src
    (cd /tmp/src && tar xzf pvlib-0.16.1.tar.gz && tar xzf pvanalytics-0.2.2.tar.gz)
    python data/real/make_excerpts.py /tmp/src/pvlib-0.16.1 /tmp/src/pvanalytics-0.2.2

Each excerpt keeps the stations' own values (W/m², rounded to 0.1) for ghi, dni and dhi, in
the station's local standard time, and drops the night: only rows with the apparent sun
above -6° (civil twilight) are kept. Nothing else is changed; a missing value stays empty.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pandas as pd
import pvlib

HERE = Path(__file__).parent

#: name: (latitude, longitude, altitude m, tz) of each station, from the stations' own metadata.
STATIONS = {
    "payerne": (46.815, 6.944, 491.0, "Etc/GMT-1"),
    "golden": (39.742, -105.18, 1829.0, "Etc/GMT+7"),
    "tucson": (32.22969, -110.95534, 786.0, "Etc/GMT+7"),
    "alamosa": (37.70, -105.92, 2317.0, "Etc/GMT+7"),
    "eugene": (44.0467, -123.0743, 150.0, "Etc/GMT+8"),
}


def _bsrn(pvlib_src: Path) -> pd.DataFrame:
    data, _ = pvlib.iotools.read_bsrn(pvlib_src / "tests/data/bsrn-pay0616.dat.gz")
    return data[["ghi", "dni", "dhi"]]


def _rmis(pvanalytics_src: Path, name: str, columns: dict) -> pd.DataFrame:
    data = pd.read_csv(pvanalytics_src / "pvanalytics/data" / name, index_col=0, parse_dates=True)
    return data.tz_localize("Etc/GMT+7").rename(columns=columns)[["ghi", "dni", "dhi"]]


def _midc_uat(pvlib_src: Path) -> pd.DataFrame:
    data = pd.read_csv(pvlib_src / "tests/data/midc_raw_20181018.txt")
    day = pd.to_datetime(data["Year"].astype(str) + data["DOY"].astype(str).str.zfill(3), format="%Y%j")
    stamps = day + pd.to_timedelta(data["MST"] // 100 * 60 + data["MST"] % 100, unit="min")
    data.index = pd.DatetimeIndex(stamps).tz_localize("Etc/GMT+7")
    return data.rename(columns={"Direct Normal [W/m^2]": "dni", "Diffuse Horiz [W/m^2]": "dhi",
                                "Global Horiz (platform) [W/m^2]": "ghi"})[["ghi", "dni", "dhi"]]


def _surfrad(pvlib_src: Path) -> pd.DataFrame:
    data, _ = pvlib.iotools.read_surfrad(pvlib_src / "tests/data/surfrad-slv16001.dat")
    return data[["ghi", "dni", "dhi"]]


def _srml(pvlib_src: Path) -> pd.DataFrame:
    """Eugene has GHI and DNI only; DHI is the closure GHI - DNI cos(zenith), as README.md says."""
    data = pvlib.iotools.read_srml(pvlib_src / "tests/data/SRML-day-EUPO1801.txt", map_variables=True)
    lat, lon, alt, _ = STATIONS["eugene"]
    zenith = pvlib.solarposition.get_solarposition(data.index, lat, lon, altitude=alt)["zenith"]
    ghi, dni = data["ghi_0"], data["dni_0"]
    dhi = (ghi - dni * pvlib.tools.cosd(zenith)).clip(lower=0.0)
    return pd.DataFrame({"ghi": ghi, "dni": dni, "dhi": dhi})


def excerpts(pvlib_src: Path, pvanalytics_src: Path) -> dict[str, tuple[str, pd.DataFrame]]:
    """File name to (station, frame) of every excerpt."""
    bsrn = _bsrn(pvlib_src)
    golden_2019 = _rmis(pvanalytics_src, "irradiance_RMIS_NREL.csv", {
        "irradiance_dhi__7983": "dhi", "irradiance_dni__7982": "dni", "irradiance_ghi__7981": "ghi"})
    golden_2022 = _rmis(pvanalytics_src, "rmis_weather_data.csv", {
        "Diffuse Horizontal": "dhi", "Direct Normal": "dni", "Global Horizontal": "ghi"})
    return {
        "payerne-2016-06-12-overcast.csv": ("payerne", bsrn["2016-06-12":"2016-06-14"]),
        "payerne-2016-06-15-broken.csv": ("payerne", bsrn["2016-06-15":"2016-06-20"]),
        "payerne-2016-06-22-clear.csv": ("payerne", bsrn["2016-06-22":"2016-06-24"]),
        "payerne-2016-06-26-mixed.csv": ("payerne", bsrn["2016-06-26":"2016-06-29"]),
        "golden-2019-02-01-5min.csv": ("golden", golden_2019),
        "golden-2022-01-01-5min.csv": ("golden", golden_2022),
        "tucson-2018-10-18.csv": ("tucson", _midc_uat(pvlib_src)),
        "alamosa-2016-01-01.csv": ("alamosa", _surfrad(pvlib_src)),
        "eugene-2018-01-01.csv": ("eugene", _srml(pvlib_src)),
    }


def trim(frame: pd.DataFrame, station: str) -> pd.DataFrame:
    """Daylight rows (apparent sun above -6°) in local standard time, values rounded to 0.1."""
    lat, lon, alt, tz = STATIONS[station]
    frame = frame.tz_convert(tz)
    elevation = pvlib.solarposition.get_solarposition(frame.index, lat, lon, altitude=alt)["apparent_elevation"]
    out = frame[elevation > -6.0].round(1)
    out.index.name = "time"
    return out


def main(pvlib_src: str, pvanalytics_src: str) -> None:
    for name, (station, frame) in excerpts(Path(pvlib_src), Path(pvanalytics_src)).items():
        out = trim(frame, station)
        out.index = out.index.map(lambda stamp: stamp.isoformat())
        out.to_csv(HERE / name, float_format="%.1f")
        print(f"{name}: {station}, {out.index[0]} to {out.index[-1]}, {len(out)} rows")


if __name__ == "__main__":
    main(*sys.argv[1:3])
