"""Axis numbering, converted in one place.

Arrays index the six axes 0..5 (a column of an ``(n, 6)`` array, an index into ``gear_ratio``);
everything a user reads or writes numbers them 1..6 as the robot makers do (the command line's
``--wear 2:exp4:20``, the dataset's ``worn_axes``, ``report.json``'s ``axes`` and per-axis
parameter keys). Code that crosses between the two calls :func:`number` / :func:`numbers` on the
way out and :func:`index` on the way in. (Error messages spell ``axis {k + 1}`` in place.)
"""

from __future__ import annotations

from collections.abc import Iterable

#: Axes of every robot faultgen models.
N_AXES = 6


def number(index: int) -> int:
    """The axis number a user reads (1..6) of the array index ``index`` (0..5)."""
    return int(index) + 1


def numbers(indices: Iterable[int]) -> list[int]:
    """:func:`number` of each index, in order."""
    return [number(k) for k in indices]


def index(number: int | str) -> int:
    """The array index (0..5) of the axis number ``number`` (1..6, or its decimal string as in
    ``report.json``'s keys).

    Raises
    ------
    ValueError
        If ``number`` is not a whole number in 1..6.
    """
    try:
        value = int(number)
    except (TypeError, ValueError):
        value = None
    if value is None or str(value) != str(number).strip() or not 1 <= value <= N_AXES:
        raise ValueError(f"axis {number!r} is not an axis number; expected 1..{N_AXES}")
    return value - 1
