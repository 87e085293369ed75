"""The calibration figure: measured vs simulated torque and the residual before and after, per axis."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

from faultgen.figure_text import plain


def save(result, path: str | Path) -> Path:
    """Draw ``result`` (a :class:`faultgen.calibrate.Calibration`) into a PNG at ``path``.

    Left column: measured torque and the torque of the nominal and of the calibrated model, per
    axis. Right column: the residual (measured minus model) before and after. The held-out part,
    on which the gaps are reported, is shaded. Model torque and residual are left out where the
    axis is at rest (stiction: no kinetic model predicts it, and nothing is fitted there).
    """
    path = Path(path)
    t = result.time - result.time[0]
    held = np.flatnonzero(result.held_out.any(axis=1))
    moving = result.moving
    nominal = np.where(moving, result.nominal, np.nan)
    calibrated = np.where(moving, result.calibrated, np.nan)
    n_axes = result.tau.shape[1]
    fig, axes = plt.subplots(n_axes, 2, figsize=(13, 14 * n_axes / 6), sharex=True)
    added = ", ".join(f"{s['effect']} (axes {', '.join(map(str, s['axes']))})"
                      for s in (step.record() for step in result.steps)) or "nothing"
    ambiguous = "".join(
        f"\nstep {a['step']}: not separable on this log: "
        + " / ".join(f"{c['effect']} (dAIC {c['delta_aic']:.1f})" for c in a["candidates"])
        + f"; fitted {a['fitted']}" for a in result.ambiguous())
    left_over = {u["axis"]: u for u in result.unexplained()}
    unexplained = "".join(
        f"\naxis {a}: LEFT UNEXPLAINED, nrmse {u['nrmse']:.3f} (noise floor {u['noise_floor']:.3f}); failed: "
        f"{_failed(u['failed'])}{_follows(u)}; added: {', '.join(u['added']) or 'none'}" for a, u in left_over.items())
    found = (result.delay or {}).get("estimate")
    delay = "" if found is None else (
        f"\nchannel delay {1e3 * found['seconds']:+.1f} ms ({1e3 * found['interval_s'][0]:+.1f} .. "
        f"{1e3 * found['interval_s'][1]:+.1f} ms), torque moved {1e3 * result.delay['applied_s']:+.1f} ms")
    fig.suptitle(plain(f"{result.robot}: {Path(result.measured).name}; added {added}\n"
                       f"held-out total nrmse {result.gap_before['total_nrmse']:.3f} -> "
                       f"{result.gap_after['total_nrmse']:.3f}{delay}{ambiguous}{unexplained}"), fontsize=11,
                 color="tab:red" if left_over else "black")
    for axis in range(n_axes):
        left, right = axes[axis]
        left.plot(t, result.tau[:, axis], color="black", lw=0.8, label="measured")
        left.plot(t, nominal[:, axis], color="tab:red", lw=0.8, alpha=0.8, label="nominal model")
        left.plot(t, calibrated[:, axis], color="tab:blue", lw=0.8, alpha=0.8, label="calibrated model")
        right.plot(t, result.tau[:, axis] - nominal[:, axis], color="tab:red", lw=0.6,
                   label=f"before (nrmse {result.gap_before['nrmse'][axis]:.3f})")
        right.plot(t, result.tau[:, axis] - calibrated[:, axis], color="tab:blue", lw=0.6, alpha=0.8,
                   label=f"after (nrmse {result.gap_after['nrmse'][axis]:.3f})")
        left.set_ylabel(f"axis {axis + 1}" + (" UNEXPLAINED" if axis + 1 in left_over else "") + "\ntorque, N m",
                        color="tab:red" if axis + 1 in left_over else "black")
        right.set_ylabel("residual, N m")
        for ax in (left, right):
            if held.size:
                ax.axvspan(t[held[0]], t[held[-1]], color="0.9", zorder=0)
            ax.grid(alpha=0.3)
        right.legend(loc="upper left", fontsize=7)
    axes[0, 0].legend(loc="upper left", fontsize=7)
    axes[0, 0].set_title("torque (held-out part shaded)")
    axes[0, 1].set_title("residual: measured minus model")
    for ax in axes[-1]:
        ax.set_xlabel("time, s")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def _follows(found: dict) -> str:
    """What an unexplained axis's residual follows, for the title: the first generic term named
    (:mod:`faultgen.calibrate.remainder`), else the variable of the tests' largest correlation
    (nothing when only whiteness failed)."""
    terms = found.get("terms") or []
    if terms:
        return f"; follows: {terms[0]['words']} ({100 * terms[0]['share']:.0f} % of the gap left)"
    follows = found["follows"]
    return "" if follows is None else f"; follows {follows['variable']} at {1e3 * follows['lag_s']:+.0f} ms"


def _failed(names: list[str], most: int = 4) -> str:
    """The failed tests for the title, the first ``most`` and how many more."""
    return ", ".join(names[:most]) + (f" and {len(names) - most} more" if len(names) > most else "")
