"""Each axis's friction curve fitted to a friction test's points, with intervals; the outputs of
``faultgen friction-test`` (``friction_curve.csv``, ``friction_fit.csv``).

The curve, arm side, for a speed ``v > 0`` (the Stribeck curve of thesis eq. 6.3 with exponent 2,
Olsson et al. 1998)::

    F(v) = F_c + F_s exp(-(v / v_s)^2) + F_v v

``F_c`` the dry (Coulomb) level, N m; ``F_s`` the static excess, N m; ``v_s`` the Stribeck velocity,
rad/s; ``F_v`` the viscous coefficient, N m s/rad. Fitted by ``scipy.optimize.least_squares``
(unweighted: the points' spread, not their standard errors, sets the scale); 95 % intervals from the
Jacobian (``s^2 (J^T J)^-1``, Student's t on n - p degrees of freedom). The hump is fitted when the
axis has at least :data:`HUMP_SPEEDS` speeds and the excess's interval excludes zero; otherwise
``F_c + F_v v`` alone (``model`` says which). Faultgen's own friction is motor side: arm side is
``G`` times it (``G`` the gear ratio), so the motor-side dry level is ``F_c / G`` (``coulomb_motor_Nm``).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
from scipy import optimize, stats

from faultgen.calibrate.friction_test import Point

#: Speeds an axis needs for the Stribeck hump to be fitted.
HUMP_SPEEDS = 5
#: The interval's coverage.
LEVEL = 0.95
#: Columns of friction_fit.csv (each estimate with its interval's low and high end).
PARAMETERS = ("coulomb_Nm", "static_excess_Nm", "stribeck_velocity_rad_s", "viscous_Nms_rad")


def curve(v: np.ndarray, coulomb: float, static: float, stribeck: float, viscous: float) -> np.ndarray:
    """``F(v)`` of the module docstring at speeds ``v`` (rad/s, >= 0), N m; ``static`` 0 for no hump."""
    v = np.asarray(v, dtype=float)
    hump = static * np.exp(-(v / stribeck) ** 2) if static else 0.0
    return coulomb + hump + viscous * v


def fit_axis(v: np.ndarray, f: np.ndarray) -> dict:
    """Fit ``F(v)`` to one axis's speeds ``v`` (rad/s, shape (n,)) and friction ``f`` (N m): a dict
    of :data:`PARAMETERS`, each with ``_low`` and ``_high`` (NaN where not fitted or not bounded),
    ``model`` (``"stribeck"`` or ``"coulomb+viscous"``) and ``rms_Nm`` (the residual's RMS).
    ValueError for fewer than 3 speeds."""
    v, f = np.asarray(v, dtype=float), np.asarray(f, dtype=float)
    if v.size < 3:
        raise ValueError(f"{v.size} speeds; a friction curve needs at least 3")
    linear = _fit(v, f, np.array([f.min(), (f.max() - f.min()) / max(np.ptp(v), 1e-9)]),
                  lambda p: p[0] + p[1] * v, ([-np.inf, -np.inf], [np.inf, np.inf]))
    out = None
    if v.size >= HUMP_SPEEDS:
        x0 = np.array([linear[0][0], max(f[0] - linear[0][0] - linear[0][1] * v[0], 1e-6 * abs(f).max()),
                       v[min(1, v.size - 1)], linear[0][1]])
        bounds = ([-np.inf, 0.0, v.min() / 10, -np.inf], [np.inf, np.inf, v.max(), np.inf])
        hump = _fit(v, f, x0, lambda p: curve(v, *p), bounds)
        if np.isfinite(hump[1][1]) and hump[1][1] > 0 and hump[0][1] > hump[1][1]:
            out = dict(zip(PARAMETERS, zip(hump[0], hump[1])), model="stribeck", rms_Nm=hump[2])
    if out is None:
        (c, fv), (hc, hv), rms = linear
        out = dict(zip(PARAMETERS, ((c, hc), (0.0, math.nan), (math.nan, math.nan), (fv, hv))),
                   model="coulomb+viscous", rms_Nm=rms)
    row = {"model": out.pop("model"), "rms_Nm": out.pop("rms_Nm")}
    for name, (value, half) in out.items():
        row[name], row[f"{name}_low"], row[f"{name}_high"] = value, value - half, value + half
    return row


def _fit(v, f, x0, model, bounds) -> tuple[np.ndarray, np.ndarray, float]:
    """Least squares of ``model(p) - f``: the parameters, their intervals' half widths and the residual RMS."""
    result = optimize.least_squares(lambda p: model(p) - f, x0, bounds=bounds, x_scale="jac")
    dof = v.size - x0.size
    rms = float(np.sqrt(np.mean(result.fun**2)))
    if dof <= 0:
        return result.x, np.full(x0.size, math.nan), rms
    s2 = float(np.sum(result.fun**2) / dof)
    try:
        cov = np.linalg.inv(result.jac.T @ result.jac) * s2
        half = stats.t.ppf(0.5 + LEVEL / 2, dof) * np.sqrt(np.clip(np.diag(cov), 0, None))
    except np.linalg.LinAlgError:
        half = np.full(x0.size, math.nan)
    return result.x, half, rms


def fit(points: list[Point], gear_ratio: np.ndarray) -> pd.DataFrame:
    """One row per axis read: ``axis`` (1-based), ``speeds``, ``temperature_degC`` (the mean logged),
    ``model_points`` (points read through the model), the :func:`fit_axis` columns and
    ``coulomb_motor_Nm`` (the dry level over the gear ratio, motor side)."""
    rows = []
    for k in sorted({p.axis for p in points}):
        mine = sorted((p for p in points if p.axis == k), key=lambda p: p.speed)
        if len(mine) < 3:
            continue
        row = {"axis": k + 1, "speeds": len(mine),
               "temperature_degC": float(np.mean([p.temperature for p in mine])),
               "model_points": sum(p.source == "model" for p in mine)}
        row.update(fit_axis(np.array([p.speed for p in mine]), np.array([p.friction for p in mine])))
        row["coulomb_motor_Nm"] = row["coulomb_Nm"] / float(gear_ratio[k])
        rows.append(row)
    return pd.DataFrame(rows)


def points_table(points: list[Point], fits: pd.DataFrame) -> pd.DataFrame:
    """``friction_curve.csv``: one row per axis (1-based) and speed: the friction read, its standard
    error, the log rows used, its source, the temperature, and the fitted curve there (``fit_Nm``)."""
    rows = []
    for p in sorted(points, key=lambda p: (p.axis, p.speed)):
        row = fits[fits["axis"] == p.axis + 1]
        fitted = math.nan
        if len(row):
            r = row.iloc[0]
            fitted = float(curve(p.speed, r["coulomb_Nm"], r["static_excess_Nm"], r["stribeck_velocity_rad_s"],
                                 r["viscous_Nms_rad"]))
        rows.append({"axis": p.axis + 1, "speed_rad_s": p.speed, "friction_Nm": p.friction, "stderr_Nm": p.stderr,
                     "samples": p.samples, "source": p.source, "temperature_degC": p.temperature, "fit_Nm": fitted})
    return pd.DataFrame(rows)


#: Size bound of a reference ``friction_fit.csv`` read back (:func:`read_fits`), bytes: one row per
#: axis of some 20 numbers, under 4 kB as :func:`fit`'s rows are written.
FITS_MAX_BYTES = 2**20


def read_fits(path: Path, folder: Path | None = None) -> pd.DataFrame:
    """A ``friction_fit.csv`` written by :func:`fit` (a reference test's), read back through
    :mod:`faultgen.inputs`: a regular file (inside ``folder`` when given: a link out of it is
    refused, never read) of at most :data:`FITS_MAX_BYTES`, checked on its size before the read,
    UTF-8; ``axis`` a whole number from 1 and each of :data:`PARAMETERS` a number, or empty
    (NaN: not fitted). Was read by pandas unguarded: a text cell was a TypeError traceback in the
    figure, a link out of the folder was followed, a 362 MB file accepted.

    Raises
    ------
    faultgen.inputs.InputError
        (a ValueError) Naming the file and what is wrong: not a regular file, a link out of
        ``folder``, too large, not a CSV table, missing columns, or the row and column of a cell
        that is not a number.
    """
    import io

    from faultgen import inputs

    if folder is not None:
        inputs.within(path, folder, "reference folder")
    text = inputs.read_text(path, "friction_fit.csv", FITS_MAX_BYTES)
    try:
        table = pd.read_csv(io.StringIO(text), dtype=str, keep_default_na=False)
    except (pd.errors.ParserError, pd.errors.EmptyDataError) as err:
        raise inputs.InputError(f"{path}: not a CSV table ({' '.join(str(err).split())[:200]}); a friction_fit.csv "
                                "written by `faultgen friction-test` is expected") from None
    missing = [c for c in ("axis", *PARAMETERS) if c not in table.columns]
    if missing:
        raise inputs.InputError(f"{path}: not a friction_fit.csv (no columns {', '.join(missing)})")
    for column in ("axis", *PARAMETERS):
        cells = table[column].str.strip()
        empty = ((cells == "") | (cells.str.lower() == "nan")).to_numpy()
        values = pd.to_numeric(cells.where(~empty, "nan"), errors="coerce").to_numpy(dtype=float)
        if column == "axis":
            ok = np.isfinite(values) & (values >= 1) & (values == np.round(values))
        else:
            ok = np.isfinite(values) | empty
        bad = np.flatnonzero(~ok)
        if bad.size:
            raw = str(table[column].iloc[bad[0]])
            shown = repr(raw) if len(raw) <= 40 else f"{raw[:40]!r}... ({len(raw)} characters)"
            expected = "a whole axis number from 1" if column == "axis" else "a finite number, or empty (not fitted)"
            raise inputs.InputError(f"{path}: row {bad[0] + 1} (line {bad[0] + 2}), column {column}: {shown}; "
                                    f"expected {expected}")
        table[column] = values.astype(int) if column == "axis" else values
    return table
