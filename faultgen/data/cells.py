"""Text cells of the CSV tables faultgen writes, escaped against formula injection: a cell that a
spreadsheet would take for a formula (starting with ``=``, ``+``, ``-``, ``@``, a tab or a carriage
return: a unit folder named ``=HYPERLINK(...)``) is written with a leading ``'`` (OWASP, "CSV
Injection"). Numbers are left as they are: only text is escaped."""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import pandas as pd

#: The first characters that make a spreadsheet read a cell as a formula.
FORMULA = ("=", "+", "-", "@", "\t", "\r")


def text(value: str) -> str:
    """``value`` with a leading ``'`` when it starts with one of :data:`FORMULA`."""
    return "'" + value if value.startswith(FORMULA) else value


def _texts(values):
    """A column or index with its text cells through :func:`text`; other dtypes as they are."""
    import pandas as pd

    if values.dtype != object and not pd.api.types.is_string_dtype(values.dtype):
        return values
    return values.map(lambda v: text(v) if isinstance(v, str) else v)


def escaped(table: pd.DataFrame) -> pd.DataFrame:
    """``table`` for a CSV file: every text cell of its columns and index through :func:`text`
    (a shallow copy: the number columns are shared, not copied)."""
    import pandas as pd

    out = table.copy(deep=False)
    for position in range(out.shape[1]):
        out.isetitem(position, _texts(out.iloc[:, position]))
    if isinstance(out.index, pd.MultiIndex):
        out.index = pd.MultiIndex.from_tuples(
            [tuple(text(v) if isinstance(v, str) else v for v in key) for key in out.index], names=out.index.names)
    else:
        out.index = _texts(out.index)
    return out
