"""Axis numbering, converted in one place.

A robot has N revolute axes, 5 <= N <= 7, read from its model (``Robot.n_axes``; :func:`count`).
Arrays index the axes 0..N-1 (a column of an ``(n, N)`` array, an index into ``gear_ratio``);
everything a user reads or writes numbers them 1..N as the robot makers do (the command line's
``--wear 2:exp4:20``, the dataset's ``worn_axes``, ``report.json``'s ``axes`` and per-axis
parameter keys). Code that crosses between the two calls :func:`number` / :func:`numbers` on the
way out and :func:`index` on the way in, with the robot's N where it is known. (Error messages
spell ``axis {k + 1}`` in place.)
"""

from __future__ import annotations

from collections.abc import Iterable

from faultgen.checks import is_whole

#: Fewest and most revolute axes of a robot faultgen models (a serial arm).
MIN_AXES, MAX_AXES = 5, 7


def _limit(n_axes: int | None) -> int:
    if n_axes is None:
        return MAX_AXES
    if isinstance(n_axes, bool) or int(n_axes) != n_axes or not MIN_AXES <= n_axes <= MAX_AXES:
        raise ValueError(f"n_axes = {n_axes!r}; a robot has {MIN_AXES}..{MAX_AXES} axes")
    return int(n_axes)


def number(index: int, n_axes: int | None = None) -> int:
    """The axis number a user reads (1..N) of the array index ``index`` (0..N-1).

    Raises
    ------
    ValueError
        If ``n_axes`` is given and ``index`` is outside 0..N-1 (N = ``n_axes``).
    """
    if n_axes is not None and not 0 <= int(index) < _limit(n_axes):
        raise ValueError(f"axis index {index!r} is out of range 0..{n_axes - 1}")
    return int(index) + 1


def numbers(indices: Iterable[int], n_axes: int | None = None) -> list[int]:
    """:func:`number` of each index, in order."""
    return [number(k, n_axes) for k in indices]


def index(number: int | str, n_axes: int | None = None) -> int:
    """The array index (0..N-1) of the axis number ``number`` (1..N, or its decimal string as in
    ``report.json``'s keys), N the robot's axes ``n_axes``.

    Parameters
    ----------
    number : int or str
    n_axes : int, optional
        The robot's number of axes; when omitted, any axis a robot can have (1..:data:`MAX_AXES`)
        is accepted.

    Raises
    ------
    ValueError
        If ``number`` is not a whole number in 1..N ("axis 7 is out of range 1..6").
    """
    n = _limit(n_axes)
    try:
        value = int(number)
    except (TypeError, ValueError):
        value = None
    if value is None or str(value) != str(number).strip():
        raise ValueError(f"axis {number!r} is not an axis number; expected 1..{n}")
    if not 1 <= value <= n:
        raise ValueError(f"axis {number!r} is out of range 1..{n}")
    return value - 1


def check(number: object, n_axes: int | None = None) -> int:
    """``number`` as an int when it is a whole axis number in 1..N (no bool, no float); the
    check of a label a user gave (a wear plan's or a fault's axis).

    Raises
    ------
    ValueError
        "axis 7 is out of range 1..6" (N = ``n_axes``, or :data:`MAX_AXES` when omitted).
    """
    n = _limit(n_axes)
    if not is_whole(number) or not 1 <= number <= n:
        raise ValueError(f"axis {number!r} is out of range 1..{n}")
    return int(number)


def count(model) -> int:
    """The number of arm axes of a compiled robot model: its joints ``joint1``, ``joint2``, ... as
    far as they go (the naming of faultgen's MJCF). Not checked against 5..7 here."""
    n = 0
    while True:
        try:
            model.joint(f"joint{n + 1}")
        except KeyError:
            return n
        n += 1
