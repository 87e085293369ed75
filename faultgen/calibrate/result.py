"""What a calibration found: the steps (each effect added, with its evidence) and the
:class:`Calibration` record behind ``report.json``, the terminal summary and the figure; and the
augmented model's parameter table (``parameters.json``, :func:`parameters`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from faultgen import axes
from faultgen.calibrate.effects import Effect
from faultgen.calibrate import remainder, residual_tests, separable
from faultgen.effects.coulomb import Coulomb
from faultgen.effects.friction import FIELDS as FRICTION_FIELDS
from faultgen.effects.friction import UNITS as FRICTION_UNITS
from faultgen.model import robots


@dataclass(frozen=True)
class Step:
    """One effect added to the model.

    Attributes
    ----------
    effect : Effect
        The effect as the model holds it after the step: absolute parameters on every axis, in SI
        units (:attr:`faultgen.effects.Effect.units`); the step changed them on ``axes`` only.
    axes : list of int
        Axes it was added on, 0-based (:meth:`record` numbers them 1..6).
    evidence : dict
        Why it was chosen: held-out gain per axis, the score, the runner-up, the margin (score
        minus the runner-up's, in held-out total nrmse) and every effect's score (axes numbered 1..6).
    gap_after : dict
        Held-out gap of the model with this and all earlier effects (see :func:`faultgen.calibrate.search.gap`).
    standard_errors : dict
        Standard error of each fitted parameter (:func:`faultgen.calibrate.search.standard_errors`), keyed by axis
        (0-based; None when robot-wide), in the parameter's unit.
    """

    effect: Effect
    axes: list[int]
    evidence: dict
    gap_after: dict
    standard_errors: dict = field(default_factory=dict)

    def record(self) -> dict:
        """The step in ``report.json``: effect id, axes numbered 1..6, the parameters on them
        (:meth:`faultgen.effects.Effect.report`) with their standard errors (keyed the same way)
        and units, the evidence and the gap after."""
        errors = {"robot" if key is None else str(axes.number(key)): values
                  for key, values in self.standard_errors.items()}
        return {"effect": self.effect.id, "axes": axes.numbers(self.axes), "params": self.effect.report(self.axes),
                "standard_errors": errors, "units": dict(self.effect.units), "evidence": self.evidence,
                "gap_after": self.gap_after}


@dataclass(frozen=True)
class Calibration:
    """What :func:`faultgen.calibrate.calibrate` found.

    Attributes
    ----------
    robot : str
    measured : str
        The measured file.
    gap_before, gap_after : dict
        Held-out gap of the nominal and of the augmented model.
    steps : list of Step
        Effects in the order they were added; empty when nothing significant was missing.
    model_out : Path
        The augmented MJCF (a copy of the nominal one when no effect was added).
    time : ndarray of shape (n,)
    held_out : ndarray of shape (n, 6)
        Mask of the held-out samples per axis (moving, in the held-out part).
    moving : ndarray of shape (n, 6)
        Mask of the samples where the axis moves (faster than the rest speed).
    tau, nominal, calibrated : ndarray of shape (n, 6)
        Measured torque and the torque of the nominal and of the augmented model, N m.
    searches : int or None
        How many times every effect was fitted to the residual (the steps, and the search that
        found nothing more when there was one).
    model : Robot or None
        The augmented model as written to ``model_out``, read from it once by its writer
        (:func:`faultgen.model.robots.write`): who needs the calibrated robot takes it from here
        rather than loading ``model_out`` again.
    nominal_digest : str or None
        SHA-1 of the nominal model's MJCF (:attr:`Robot.digest`; None for one edited in memory),
        which :func:`faultgen.calibrate.refit.refit` checks the nominal robot it is handed against.
    residual_tests : list of dict or None
        The residual tests of the calibrated model, per axis (:func:`faultgen.calibrate.residual_tests.run`);
        None: not made (nothing is then called unexplained).
    tests_after_steps : list of dict
        The tests' short record (:func:`faultgen.calibrate.residual_tests.summary`) of the nominal
        model, after each step of the search and of the calibrated model: ``after`` and ``axes``.
    delay : dict or None
        The channel delay check (:func:`faultgen.calibrate.loop.check_delay`).
    follows : dict
        Per unexplained axis (numbered 1..N), what its remainder follows
        (:func:`faultgen.calibrate.remainder.explain`): the generic terms in words, their shares.
    declined : list of dict
        Library effects not written on an axis because a generic term explains more of its
        remainder (no forced fit, :func:`faultgen.calibrate.guard.check`).
    why_unexplained : str or None
        Why the unexplained axes are left, where the calibration knows it (faultgen's own null log,
        :func:`faultgen.calibrate.synth.simulator_remainder`); None otherwise.
    """

    robot: str
    measured: str
    gap_before: dict
    steps: list[Step]
    gap_after: dict
    model_out: Path
    time: np.ndarray
    held_out: np.ndarray
    moving: np.ndarray
    tau: np.ndarray
    nominal: np.ndarray
    calibrated: np.ndarray
    searches: int | None = None
    model: robots.Robot | None = None
    nominal_digest: str | None = None
    residual_tests: list[dict] | None = None
    tests_after_steps: list[dict] = field(default_factory=list)
    delay: dict | None = None
    follows: dict = field(default_factory=dict)
    declined: list[dict] = field(default_factory=list)
    why_unexplained: str | None = None

    def report(self) -> dict:
        """The ``report.json`` record of the design document."""
        return {
            "robot": self.robot,
            "measured": self.measured,
            "gap_before": self.gap_before,
            "steps": [s.record() for s in self.steps],
            "gap_after": self.gap_after,
            "model_out": str(self.model_out),
            "ambiguous": self.ambiguous(),
            # null: the residual tests were not run (faultgen.calibrate.loop.run's tests=False): nothing known
            "unexplained": None if self.residual_tests is None else self.unexplained(),
            "residual_tests": None if self.residual_tests is None else self.tests_after_steps,
            "channel_delay": self.delay,
            "not_written": self.declined,
            **({"why_unexplained": self.why_unexplained} if self.why_unexplained else {}),
        }

    def unexplained(self) -> list[dict]:
        """The axes the calibrated model leaves unexplained: a residual test failed and the axis
        is above its noise floor (:func:`faultgen.calibrate.residual_tests.unexplained`), or a delay
        of the torque channels shows on it (:func:`faultgen.calibrate.delay.shown`; the axis's record then
        has ``channel_delay``: the log's delay, its interval and level, the rule and the axis's own
        estimate); each with its tests' statistics and p-values and the effects added on it (with their step)."""
        if self.residual_tests is None:
            return []
        shown = (self.delay or {}).get("shown") or {}
        found = residual_tests.unexplained(self.residual_tests, self.tau, self.held_out, self.gap_after,
                                           also=shown.get("axes", []))
        empty = {"terms": [], "explained_share": 0.0, "explained_interval": [0.0, 0.0]}
        return [{**u, "added": [f"{s.effect.id} (step {k})" for k, s in enumerate(self.steps, start=1)
                                if u["axis"] - 1 in s.axes],
                 **({"channel_delay": {**{k: shown[k] for k in ("seconds", "interval_s", "level", "rule")},
                                       "axis": shown["per_axis"][u["axis"]]}} if u["axis"] in shown.get("axes", []) else {}),
                 **{k: v for k, v in self.follows.get(u["axis"], empty).items() if k != "axis"},
                 "not_written": [d for d in self.declined if d["axis"] == u["axis"]]} for u in found]

    def not_separable(self) -> list[dict]:
        """The parameters this log cannot place, held at the nominal model's: per axis (numbered),
        ``parameter`` (the Coulomb effect's id: the dry level of the own-friction fit,
        :func:`faultgen.calibrate.loop.own_friction`) and the identifiability check's figures
        (:func:`faultgen.calibrate.separable.dry_and_viscous`). Empty when every fitted level was
        separable or none was fitted on every axis."""
        return [{"axis": int(axis), "parameter": Coulomb.id, "held_at": "nominal", **check}
                for s in self.steps if s.evidence.get("every_axis") and s.effect.id == Coulomb.id
                for axis, check in s.evidence.get("not_separable", {}).items()]

    def ambiguous(self) -> list[dict]:
        """The steps whose effect this log cannot tell apart from another (held-out AIC within
        :data:`faultgen.calibrate.search.SEPARABLE`, :func:`faultgen.calibrate.search.compare`): step number (1..), the effect fitted (the
        simplest), every candidate with its evidence, and per candidate the motion that would
        separate them (:attr:`faultgen.effects.Effect.excited_by`)."""
        found = []
        for k, step in enumerate(self.steps, start=1):
            if step.evidence.get("separable", True):
                continue
            found.append({"step": k, "fitted": step.effect.id,
                          "candidates": [c for c in step.evidence["candidates"] if not c["separable"]],
                          "separate_by": step.evidence["separate_by"],
                          "excitation": f"faultgen excitation {self.robot} -o excitation.csv"})
        return found

    def summary(self) -> str:
        """A few lines for a terminal: each effect, its axes and parameters, the gap before -> after."""
        lines = [f"{self.robot}: held-out total nrmse {self.gap_before['total_nrmse']:.4f} (nominal model)"]
        if self.delay is not None:
            lines.append(self.delay.get("line", self.delay.get("reason", "")))
        if not self.steps:
            lines.append("no significant missing effect found")
        for k, step in enumerate(self.steps, start=1):
            s = step.record()
            values = "; ".join(
                f"{'axis ' + where if where != 'robot' else 'robot'}: "
                + ", ".join(f"{name} = {value:.4g} ± {s['standard_errors'].get(where, {}).get(name, np.nan):.2g}"
                            f"{_unit(s['units'][name])}" for name, value in p.items())
                for where, p in s["params"].items())
            lines.append(f"{k}. {s['effect']} on axes {', '.join(map(str, s['axes']))} -> total nrmse "
                         f"{s['gap_after']['total_nrmse']:.4f}  ({values})")
            refined = step.evidence.get("sysid")
            if refined is not None and refined["used"]:
                lines.append(f"   refined by mujoco.sysid: held-out total nrmse "
                             f"{refined['gap_after']['faultgen']['total_nrmse']:.4f} (faultgen's fit) -> "
                             f"{refined['gap_after']['sysid']['total_nrmse']:.4f}; "
                             + ("sysid's values kept" if refined["kept"] else "faultgen's fit kept"))
            elif refined is not None:
                lines.append(f"   not refined by mujoco.sysid: {refined['reason']}")
            if not step.evidence.get("separable", True):
                tied = [c for c in step.evidence["candidates"] if not c["separable"]]
                lines.append("   NOT SEPARABLE on this log: " + ", ".join(
                    f"{c['effect']} (delta AIC {c['delta_aic']:.1f}, weight {c['weight']:.2f})" for c in tied)
                    + f"; fitted the simplest, {s['effect']}")
                for name, motion in step.evidence["separate_by"].items():
                    lines.append(f"   to tell {name} apart: {motion}")
                lines.append(f"   a designed excitation: faultgen excitation {self.robot} -o excitation.csv")
        lines += [f"axis {h['axis']}: dry friction NOT SEPARABLE: {separable.words(h)}: held at the nominal model's"
                  for h in self.not_separable()]
        lines.append(f"gap {self.gap_before['total_nrmse']:.4f} -> {self.gap_after['total_nrmse']:.4f}; "
                     f"model: {self.model_out}")
        if self.residual_tests is None:  # as the report's null: not "nothing unexplained"
            lines.append("residual tests not run (tests=False): what the model leaves unexplained is not known")
        for u in self.unexplained():
            lines.append(residual_tests.line(u))
            lines.append(remainder.line(u))
            lines += [f"   not written on axis {d['axis']}: {d['effect']} (held-out nrmse drop {d['effect_gain_nrmse']:.4f}; "
                      f"{d['generic_words']} alone: {d['generic_gain_nrmse']:.4f})" for d in u["not_written"]]
        if self.why_unexplained and self.unexplained():
            lines.append(self.why_unexplained)
        # the static model: for a per-step friction update, or a Stribeck curve MuJoCo's LuGre
        # (Gaussian only) cannot represent
        static_only = any(s.effect.stepped for s in self.steps) or any(
            p.get("stribeck_exponent", 2.0) != 2.0 for s in self.steps for p in s.record()["params"].values())
        friction = " --friction stribeck" if static_only else ""
        lines.append(f"simulate it: faultgen simulate --model {self.model_out}{friction}")
        return "\n".join(lines)


def parameters(robot: robots.Robot) -> dict:
    """A robot's parameters as plain lists over axes 1..6, with their units (``parameters.json``):
    gear ratios, the motor-side friction (:data:`faultgen.effects.friction.FIELDS`) and every effect the
    robot carries in its own MJCF elements, by effect id and parameter name
    (:attr:`faultgen.effects.Effect.units`)."""
    friction = {name: [float(v) for v in getattr(robot.friction, name)] for name in FRICTION_FIELDS}
    return {
        "robot": robot.name,
        "units": {"gear_ratio": "1", "friction": {name: f"{unit} (motor side)" for name, unit in FRICTION_UNITS.items()},
                  "effects": {e.id: dict(e.units) for e in robot.effects.values()}},
        "gear_ratio": [float(v) for v in robot.gear_ratio],
        "friction": friction,
        "effects": {e.id: e.table() for e in robot.effects.values()},
    }


def _unit(unit: str) -> str:
    """`` <unit>`` for a summary line; nothing for a dimensionless parameter."""
    return "" if unit == "1" else f" {unit}"
