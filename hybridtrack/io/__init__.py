"""Reading user files: weather records and small tables, with errors that say where.

One module per concern:

``files``      bytes, ``.gz``/``.zip``, encodings (UTF-8 with or without BOM, UTF-16, Latin-1);
               `read_text`, `read_toml`, `write_toml`
``tables``     where a table starts, separator, header, TOA5, units rows, comments; `read_table`,
               `numeric_columns`
``columns``    which column holds which quantity: the alias table and the user's mapping
``units``      unit spellings and conversion to W/m², m/s, °C, mA
``stamps``     time stamps: day/month order for the whole column, epoch seconds, date + time
               columns, the file's zone
``formats``    pvlib's formats, recognised by content, names mapped
``checks``     order, duplicates, gaps, impossible and non-finite values, offsets, magnitude
``suncheck``   the light against the site's sun: light at night, an offset daily curve
``gapfill``    missing components by closure, Erbs or DIRINT (pvlib, true zenith)
``resample``   to any step
``nights``     the nights a logger left out, put back (`fill_nights`)
``report``     `validation_report`
``weather``    `read_weather`, which runs them in that order

docs/records.md describes what is accepted, refused and reported.
"""

from .checks import LIMITS
from .columns import ALIASES, IRRADIANCE, LABEL_COLUMN, WEATHER_COLUMNS
from .files import read_text, read_toml, write_toml
from .formats import PVLIB_FORMATS
from .nights import fill_nights
from .report import validation_report
from .tables import numeric_columns, read_table, table_row
from .weather import read_weather

__all__ = ["read_weather", "fill_nights", "read_table", "read_toml", "write_toml", "read_text", "numeric_columns", "table_row",
           "validation_report", "WEATHER_COLUMNS", "IRRADIANCE", "LABEL_COLUMN", "ALIASES", "PVLIB_FORMATS", "LIMITS"]
