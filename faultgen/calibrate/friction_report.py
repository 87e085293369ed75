"""``faultgen friction-test``'s work: a test log read (:mod:`faultgen.calibrate.friction_test`),
fitted (:mod:`faultgen.calibrate.friction_fit`), written as a set to the output folder:
``friction_curve.csv`` (the points and the fit at each), ``friction_fit.csv`` (each axis's curve
with 95 % intervals) and ``friction_axis<k>.png`` per axis read (friction against signed speed, both
directions, the fit, and a reference test's curve when given).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from faultgen.calibrate import friction_fit, friction_test
from faultgen.data import cells
from faultgen.logs import measured
from faultgen.data.atomic import output_set
from faultgen.model.robots import Robot


@dataclass(frozen=True)
class Reading:
    """A test read: ``points`` (friction_curve.csv's table), ``fits`` (friction_fit.csv's), the
    ``notes`` a reader must see, and the ``files`` written."""

    points: pd.DataFrame
    fits: pd.DataFrame
    notes: tuple[str, ...]
    files: tuple[Path, ...] = ()


def read(log: measured.MeasuredData, robot: Robot) -> Reading:
    """The friction test in ``log`` read and fitted per axis; raises as
    :func:`faultgen.calibrate.friction_test.friction_points`."""
    points, notes = friction_test.friction_points(log, robot)
    fits = friction_fit.fit(points, robot.gear_ratio)
    return Reading(friction_fit.points_table(points, fits), fits, (*notes, *sign_notes(fits)))


def reference_fits(path: Path, robot: Robot) -> pd.DataFrame:
    """A reference test's curves: ``path`` an output folder of ``faultgen friction-test`` (its
    friction_fit.csv) or a test log, read here. ValueError for a folder without friction_fit.csv."""
    path = Path(path)
    if path.is_dir():
        if not ((path / "friction_fit.csv").exists() or (path / "friction_fit.csv").is_symlink()):
            raise ValueError(f"--reference {path}: a folder without friction_fit.csv; expected a "
                             "`faultgen friction-test` output folder or a test log")
        return friction_fit.read_fits(path / "friction_fit.csv", path)  # bounded, a link out of the folder refused
    return read(measured.read(path, robot, accelerations=False), robot).fits


def _figure(target: Path, axis: int, points: pd.DataFrame, fit: pd.Series, reference: pd.Series | None) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    v = points["speed_rad_s"].to_numpy()
    f = points["friction_Nm"].to_numpy()
    e = 1.96 * points["stderr_Nm"].to_numpy()
    model = (points["source"] == "model").to_numpy()
    for sign, marker, name in ((1, "o", "+ direction"), (-1, "s", "- direction")):
        ax.errorbar(sign * v[~model], sign * f[~model], yerr=e[~model], fmt=marker, ms=4, label=f"{name} (differenced)")
        if model.any():
            ax.errorbar(sign * v[model], sign * f[model], yerr=e[model], fmt=marker, mfc="none", ms=5,
                        label=f"{name} (through the model)")
    grid = np.geomspace(max(v.min() / 2, 1e-4), v.max() * 1.05, 200)

    def curve(row):
        return friction_fit.curve(grid, row["coulomb_Nm"], row["static_excess_Nm"], row["stribeck_velocity_rad_s"],
                                  row["viscous_Nms_rad"])

    for sign in (1, -1):
        ax.plot(sign * grid, sign * curve(fit), "k-", lw=1, label="fit" if sign > 0 else None)
        if reference is not None:
            ax.plot(sign * grid, sign * curve(reference), "r--", lw=1, label="reference test" if sign > 0 else None)
    ax.set_xlabel("arm speed, rad/s")
    ax.set_ylabel("friction torque (arm side), N m")
    ax.set_title(f"axis {axis}: F_c = {fit['coulomb_Nm']:.4g} N m "
                 f"[{fit['coulomb_Nm_low']:.4g}, {fit['coulomb_Nm_high']:.4g}], 95 %")
    ax.axhline(0, color="0.8", lw=0.5)
    ax.axvline(0, color="0.8", lw=0.5)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(target, dpi=100)
    plt.close(fig)


def write(reading: Reading, out: Path, reference: pd.DataFrame | None = None) -> Reading:
    """Write ``reading`` to the folder ``out`` (created), all files or none (module docstring)."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    axes = [int(a) for a in reading.fits["axis"]]
    targets = [out / "friction_curve.csv", out / "friction_fit.csv", *(out / f"friction_axis{a}.png" for a in axes)]
    with output_set(targets) as staged:
        cells.escaped(reading.points).to_csv(staged(targets[0]), index=False)
        cells.escaped(reading.fits).to_csv(staged(targets[1]), index=False)
        for a, target in zip(axes, targets[2:]):
            ref = None
            if reference is not None and (reference["axis"] == a).any():
                ref = reference[reference["axis"] == a].iloc[0]
            _figure(staged(target), a, reading.points[reading.points["axis"] == a],
                    reading.fits[reading.fits["axis"] == a].iloc[0], ref)
    return Reading(reading.points, reading.fits, reading.notes, tuple(targets))


def sign_notes(fits: pd.DataFrame) -> list[str]:
    """A note for each axis of ``fits`` (friction_fit.csv's table) whose dry level is read below 0:
    friction opposes motion, so a negative level is a sign error in the log or a side error."""
    return [f"axis {int(r['axis'])}: dry friction read negative ({r['coulomb_Nm']:.4g} N m): a likely sign error "
            f"(tau{int(r['axis'])} or q{int(r['axis'])} negated against the other) or side error (a motor-side torque "
            "referred to the arm through a gear ratio of the wrong sign); check the log's sign convention"
            for _, r in fits.iterrows() if r["coulomb_Nm"] < 0]
