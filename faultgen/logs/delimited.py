"""A delimited-text log (a header row, then rows of numbers) read for a log format
(:mod:`faultgen.logs.formats`): its header and separator, the columns its layout needs, its cells
as finite numbers, whole or in chunks; every refusal a
:class:`~faultgen.logs.measured.MeasuredDataError` naming the file, the data row and column."""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pandas as pd

from faultgen import inputs
from faultgen.logs import measured
from faultgen.logs.columns import CHUNK_CELLS, LOG_MAX_BYTES, LogBoundError
from faultgen.logs.jointlog import shown_cell

#: Largest foreign log read, bytes on disk (:data:`faultgen.logs.columns.LOG_MAX_BYTES`, every log's).
MAX_BYTES = LOG_MAX_BYTES


def header(path: Path | inputs.Held, what: str, separator: str | None, as_what: str) -> tuple[list[str], str]:
    """The names in the header of the delimited-text log ``path`` and its separator (``None``:
    found), the file a regular one (bounded: :data:`MAX_BYTES`, :func:`faultgen.inputs.csv_header`);
    refused unreadable (as ``as_what``) or with a name twice."""
    inputs.regular_file(path, what, MAX_BYTES)
    try:
        names, separator = inputs.csv_header(path, what, separator=separator)
    except inputs.InputError as err:
        raise LogBoundError(str(err)) from None
    except (OSError, UnicodeDecodeError, EOFError) as err:
        raise measured.MeasuredDataError(f"{path}: cannot read the file as {as_what}: {err}") from err
    twice = sorted(name for name, count in Counter(names).items() if count > 1)
    if twice:
        raise measured.MeasuredDataError(f"{path}: column(s) {', '.join(twice[:10])} appear more than once in the "
                                         "header")
    return names, separator


def require(path: Path, names: list[str], wanted: list[str], what: str) -> None:
    missing = [c for c in wanted if c not in names]
    if missing:
        raise measured.MeasuredDataError(f"{path}: missing column(s) {', '.join(missing)} of the {what} layout; found "
                                         f"{', '.join(names[:40]) or '(none)'}")


def numbers(path: Path, frame: pd.DataFrame, wanted: list[str], label) -> dict[str, np.ndarray]:
    """The ``wanted`` columns as floats, refused at the first cell that is not a finite number."""
    out = {}
    for name in wanted:
        values = pd.to_numeric(frame[name], errors="coerce").to_numpy(dtype=float)
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            raw = frame[name].iloc[bad[0]]
            shown = repr(float(raw)) if isinstance(raw, (float, np.floating)) else shown_cell(str(raw))  # inf, not np.float64(inf)
            raise measured.MeasuredDataError(f"{path}: {label(int(bad[0]))}, column {name}: value {shown}; expected "
                                             "a finite number")
        out[name] = values
    return out


def text_chunks(path: Path, what: str, as_what: str, names: list[str], separator: str, wanted: list[str], label,
                 size: int | None = None) -> Iterator[dict[str, np.ndarray]]:
    """The ``wanted`` columns of a delimited-text log (a header row of ``names``) parsed as numbers,
    ``size`` rows at a time (default: rows bounded by all the columns, as every column of a row is
    tokenized, kept or not; only the wanted converted and kept: memory in proportion to the
    numbers, where reading every cell as text took 7 times the file), refused at the first cell
    that is not a finite number, found from the text (:func:`numbers`: the data row, column and
    value named), or when the text is not such a table (named ``as_what``)."""
    kw = {"sep": separator, "header": None, "names": names, "usecols": wanted, "skipinitialspace": True,
          "skiprows": 1, "chunksize": size or max(1_000, CHUNK_CELLS // len(names))}
    try:
        with inputs.open_text(path, what, MAX_BYTES) as fh:
            for frame in pd.read_csv(fh, dtype=float, **kw):
                values = {name: frame[name].to_numpy(dtype=float) for name in wanted}
                if not all(bool(np.isfinite(column).all()) for column in values.values()):
                    break
                yield values
            else:
                return
    except inputs.InputError:
        raise
    except (ValueError, TypeError):  # a cell that is not a number: found from the text below
        pass
    start = 0
    kw["chunksize"] = max(1_000, CHUNK_CELLS // len(names))
    try:
        with inputs.open_text(path, what, MAX_BYTES) as fh:
            for frame in pd.read_csv(fh, dtype=str, keep_default_na=False, **kw):
                numbers(path, frame, wanted, lambda i, s=start: label(s + i))
                start += len(frame)
    except (inputs.InputError, measured.MeasuredDataError):
        raise
    except (ValueError, OSError, EOFError) as err:  # pandas's ParserError (an unbalanced quote) is a ValueError
        raise measured.MeasuredDataError(f"{path}: cannot read the file as {as_what}: "
                                         f"{' '.join(str(err).split())}") from None
    raise measured.MeasuredDataError(f"{path}: cannot read the file as CSV: a cell is not a number")
