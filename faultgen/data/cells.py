"""The cells of every CSV file faultgen writes, neutralised against formula injection and split
rows (OWASP, "CSV Injection"): the one place a CSV row is made (:func:`writer`, :func:`line`,
:func:`escaped` for a pandas table; each through :func:`text`).

- a text cell that a spreadsheet would take for a formula (starting with ``=``, ``+``, ``-``,
  ``@``, a tab or a carriage return: a unit folder named ``=HYPERLINK(...)``) is written with a
  leading ``'``; a text cell that reads as a number (``-1.5``, ``+3e-2``, ``-inf``) is left as it
  is, and so is every number: only text is escaped;
- a line break inside a text cell (CR, LF, or any other character Python's ``str.splitlines``
  splits at) is replaced by a space, so that no row splits in any reader, quoting or not (a unit
  named ``x\\r=1+1`` made a row starting with ``=1+1``).
"""

from __future__ import annotations

import csv
import re
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import pandas as pd

#: The first characters that make a spreadsheet read a cell as a formula.
FORMULA = ("=", "+", "-", "@", "\t", "\r")
#: Every character a reader may end a row at (``str.splitlines``'s line boundaries).
_BREAKS = re.compile("[\n\r\v\f\x1c\x1d\x1e\x85\u2028\u2029]")
#: A number as a spreadsheet reads it (left unescaped).
_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|[+-]?(?:inf|nan)", re.IGNORECASE)


def text(value: str) -> str:
    """``value`` on one line (each line break a space), with a leading ``'`` when it starts (after
    spaces) with one of :data:`FORMULA` and is not a number."""
    value = _BREAKS.sub(" ", value)
    if value.lstrip(" ").startswith(FORMULA) and not _NUMBER.fullmatch(value.strip(" ")):
        return "'" + value
    return value


def cell(value):
    """A cell for :mod:`csv`: text through :func:`text`, anything else as it is."""
    return text(value) if isinstance(value, str) else value


def figure(value) -> str:
    """A table's cell of a number or a word: a float to 6 significant digits, None empty, anything
    else as text (which :func:`writer` then neutralises)."""
    if value is None:
        return ""
    if isinstance(value, float):
        return f"{value:.6g}"
    return value if isinstance(value, str) else str(value)


class _Writer:
    """:func:`csv.writer`'s ``writerow`` and ``writerows``, every cell through :func:`cell`."""

    def __init__(self, out, **options):
        self._writer = csv.writer(out, **options)

    def writerow(self, row):
        return self._writer.writerow([cell(v) for v in row])

    def writerows(self, rows):
        for row in rows:
            self.writerow(row)


def writer(out, **options) -> _Writer:
    """A :func:`csv.writer` on the open text file ``out`` (opened with ``newline=""``) whose rows'
    cells go through :func:`cell`; ``options`` as :func:`csv.writer`'s."""
    return _Writer(out, **options)


def line(values) -> str:
    """One CSV row of ``values`` (each through :func:`cell`, quoted where needed), without its line
    end: a header of ``numpy.savetxt`` or a line of a file written whole."""
    import io

    out = io.StringIO()
    writer(out, lineterminator="").writerow(values)
    return out.getvalue()


def _texts(values):
    """A column or index with its text cells through :func:`text`; other dtypes as they are."""
    import pandas as pd

    if values.dtype != object and not pd.api.types.is_string_dtype(values.dtype):
        return values
    return values.map(lambda v: text(v) if isinstance(v, str) else v)


def _labels(index):
    """An index or the columns' labels through :func:`_texts` (each level of a MultiIndex)."""
    import pandas as pd

    if isinstance(index, pd.MultiIndex):
        return pd.MultiIndex.from_tuples([tuple(cell(v) for v in key) for key in index], names=index.names)
    return _texts(index)


def escaped(table: pd.DataFrame) -> pd.DataFrame:
    """``table`` for a CSV file: every text cell of its columns, index and column labels through
    :func:`text` (a shallow copy: the number columns are shared, not copied)."""
    out = table.copy(deep=False)
    for position in range(out.shape[1]):
        out.isetitem(position, _texts(out.iloc[:, position]))
    out.index = _labels(out.index)
    out.columns = _labels(out.columns)
    return out
