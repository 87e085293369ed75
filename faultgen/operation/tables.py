"""One table of a program file (or of a robot folder's ``tasks.toml``) read into checked values.

:class:`Table` reads numbers, arrays, fractions, joint angles and strings; every error is a
:class:`~faultgen.operation.tasks.ProgramError` naming the file, the table and the key, and saying
what was expected. :func:`toml_value` writes a value back as TOML text.
"""

from __future__ import annotations

import math

import numpy as np

from faultgen.model.robots import Robot
from faultgen.operation.tasks import ProgramError

#: The smallest speed or acceleration scale a program takes: 1 % of the limits (a robot's
#: slowest override; below it the planner's arithmetic fails, RuckigError at 1e-300 and an
#: invalid result at an acceleration scale of 1e-9, and a cycle would last hours).
MIN_SCALE = 0.01


def _numbers_only(value) -> bool:
    """Whether ``value`` is a number or a (nested) list of them: no string, no bool."""
    if isinstance(value, list):
        return all(_numbers_only(v) for v in value)
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def toml_value(value) -> str:
    """A TOML value: numbers as Python writes them (they read back to the same float), lists inline."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (int, float)):
        return repr(value)
    if isinstance(value, str):
        return '"' + value.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(value, list):
        if value and isinstance(value[0], list):
            return "[\n" + "".join(f"    {toml_value(v)},\n" for v in value) + "]"
        return "[" + ", ".join(toml_value(v) for v in value) + "]"
    raise TypeError(f"cannot write {value!r} as TOML")


class Table:
    """The table ``data`` of the file ``where``, its keys among ``keys``; ``prefix`` names the table
    in messages (e.g. ``"[limits] "``, ``"segment 3 (move) "``, empty for the file's top)."""

    def __init__(self, where: str, prefix: str, data, keys: tuple[str, ...]) -> None:
        if not isinstance(data, dict):
            raise ProgramError(f"{where}: {prefix.strip() or 'file'}: expected a table, got {data!r}")
        self.where, self.prefix, self.data = where, prefix, data
        for key in data:
            if key not in keys:
                self.fail(key, f"unknown key; expected one of {', '.join(keys)}")

    def fail(self, key: str, problem: str):
        raise ProgramError(f"{self.where}: {self.prefix}{key}: {problem}")

    def text(self, key: str) -> str:
        value = self.get(key)
        if not isinstance(value, str) or not value.strip():
            self.fail(key, f"expected a non-empty string, got {value!r}")
        return value

    def get(self, key: str):
        if key not in self.data:
            self.fail(key, "missing")
        return self.data[key]

    def array(self, key, shape, scale=1.0, positive=False, nonnegative=False) -> np.ndarray:
        value = self.get(key)
        if not _numbers_only(value):  # NumPy would read "1" as 1.0 and True as 1.0
            self.fail(key, f"expected numbers, got {value!r}")
        try:
            arr = np.array(value, dtype=float)
        except (TypeError, ValueError):
            self.fail(key, f"expected numbers, got {value!r}")
        expected = tuple(
            arr.shape[i] if n is None and arr.ndim == len(shape) else n for i, n in enumerate(shape)
        )
        if arr.shape != expected or arr.size == 0:
            self.fail(key, f"expected shape {tuple('m' if n is None else n for n in shape)}, got {arr.shape}")
        if (
            not np.all(np.isfinite(arr))
            or (positive and np.any(arr <= 0))
            or (nonnegative and np.any(arr < 0))
        ):
            sign = " positive" if positive else " non-negative" if nonnegative else ""
            self.fail(key, f"expected finite{sign} numbers, got {value!r}")
        return arr * scale

    def number(self, key: str, minimum: float | None = None) -> float:
        value = self.get(key)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            self.fail(key, f"expected a number, got {value!r}")
        if (minimum is None and value <= 0) or (minimum is not None and value < minimum):
            self.fail(
                key, f"expected a {'positive' if minimum is None else 'non-negative'} number, got {value}"
            )
        return float(value)

    def fraction(self, key: str, default: float | None = None) -> float:
        """A speed or acceleration scale: a fraction of the limit in :data:`MIN_SCALE`..1."""
        if default is not None and key not in self.data:
            return default
        value = self.number(key)
        if not MIN_SCALE <= value <= 1:
            self.fail(key, f"expected a fraction of the limit in {MIN_SCALE:g}..1, got {value}")
        return value

    def angles(self, key: str, robot: Robot) -> np.ndarray:
        """Joint angles given in deg, shape (N,), as rad within the robot's joint ranges."""
        n = len(robot.joint_names)
        q = self.array(key, (n,), np.pi / 180).reshape(-1, n)
        low, high = robot.joint_range[:, 0], robot.joint_range[:, 1]
        bad = np.argwhere((q < low) | (q > high))
        if bad.size:
            row, axis = bad[0]
            value = q[row, axis]
            edge = low[axis] if value < low[axis] else high[axis]
            self.fail(key, f"axis {axis + 1} at {np.degrees(value):.2f} deg is {abs(np.degrees(value - edge)):.2f} deg "
                      f"outside its range {np.degrees(low[axis]):.1f}..{np.degrees(high[axis]):.1f} deg")
        return q[0]
