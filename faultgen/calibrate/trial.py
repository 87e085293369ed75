"""The models a calibration tries, held in memory: an MJCF text and the robot compiled from it.

A trial (the model with one effect added, taken out or changed) is compiled from its MJCF text in
memory (:func:`faultgen.model.robots.from_spec`); undoing a trial is keeping the model held before
it. Nothing is written while the search runs: :func:`faultgen.calibrate.calibrate` writes the model
kept, once, at the end. A trial is compiled from the very text the file will hold (the edited
spec's ``to_xml``, parsed again), not from the edited spec, so the model the search judged is the
model the written file loads.
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import mujoco
import numpy as np

from faultgen.calibrate import search
from faultgen.calibrate.effects import Effect, Motion
from faultgen.calibrate.prediction import predicted_motion
from faultgen.logs import measured as measured_io
from faultgen.model import robots, sources


@dataclass(frozen=True)
class Model:
    """One model of a calibration, in memory.

    Attributes
    ----------
    text : str
        The MJCF text the model file holds when this model is the one kept (the nominal file's own
        text for the nominal model).
    robot : Robot
        The robot compiled from it; its ``path`` names the file it would be written to.
    xml : str
        The text an edit starts from (:meth:`spec`): MuJoCo's ``to_xml`` of the model, which is
        ``text`` except for the nominal model, whose file may be laid out by hand.
    """

    text: str
    robot: robots.Robot
    xml: str

    @classmethod
    def nominal(cls, robot: robots.Robot) -> Model:
        """The nominal model: ``robot`` as loaded (:func:`faultgen.model.robots.load`) and its file's
        text (:func:`file_text`: read once, bounded); the text to edit is the loaded spec's, so the
        file is not parsed again.

        Raises
        ------
        ModelError
            As :func:`file_text`.
        """
        return cls(file_text(robot), robot, robot.new_spec().to_xml())

    def spec(self) -> mujoco.MjSpec:
        """A fresh ``MjSpec`` of the model, to edit."""
        return mujoco.MjSpec.from_string(self.xml)

    def edited(self, edit: Callable[[mujoco.MjSpec, robots.Robot], None], path: Path) -> Model:
        """The model with ``edit(spec, robot)`` applied (``robot`` this model's), compiled in memory
        and named ``path`` (:func:`compiled`)."""
        spec = self.spec()
        edit(spec, self.robot)
        return compiled(spec, path)

    def with_effect(self, effect: Effect, axes: list[int] | None, path: Path) -> Model:
        """The model with ``effect`` written on ``axes`` (array indices; :meth:`Effect.write`)."""
        return self.edited(lambda spec, robot: effect.write(spec, robot, axes), path)


def file_text(robot: robots.Robot) -> str:
    """The text of ``robot``'s MJCF file, read once and bounded (a regular file of at most
    :data:`faultgen.model.sources.MAX_DESCRIPTION_BYTES`, its size checked before the read: a file
    swapped for a sparse one of 20 GiB since the robot was loaded was read whole), and checked to be
    the file the robot was compiled from (its SHA-1, :attr:`Robot.digest`, where known).

    Raises
    ------
    ModelError
        Naming the file: not a regular file, above the bound, changed since the robot was loaded,
        or not UTF-8 text.
    """
    path = Path(robot.path)
    data = sources.read_bytes(path, what="robot MJCF", error=robots.ModelError)
    if robot.digest is not None and hashlib.sha1(data).hexdigest() != robot.digest:
        raise robots.ModelError(f"{path}: changed since the robot was read; load it again")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as err:
        raise robots.ModelError(f"{path}: not UTF-8 text at byte {err.start}; a robot MJCF is UTF-8") from None


def compiled(spec: mujoco.MjSpec, path: Path) -> Model:
    """The model an edited ``spec`` describes: its ``to_xml`` text and the robot compiled from that
    text in memory, named ``path`` (nothing is written there).

    Raises
    ------
    ModelError
        If the text does not compile (:func:`faultgen.model.robots.from_spec`).
    """
    text = spec.to_xml()
    # the robot keeps the spec parsed from the text, so its edits (an effect's regressors compile
    # edited copies, e.g. the payload's probe bodies) start from that text too
    return Model(text, robots.from_spec(mujoco.MjSpec.from_string(text), path), text)


@dataclass(frozen=True)
class Judged:
    """A model with its prediction along the log and its held-out gap.

    Attributes
    ----------
    model : Model
    prediction : ndarray of shape (n, 6)
        Its torque along the log, N m (:func:`faultgen.calibrate.prediction.predicted_motion`).
    motion : Motion
        The log's motion as its robot sees it (the effects' regressors).
    gap : dict
        Its held-out gap (:func:`faultgen.calibrate.search.gap`).
    """

    model: Model
    prediction: np.ndarray
    motion: Motion
    gap: dict


def judge(model: Model, data: measured_io.MeasuredData, tau: np.ndarray, held_out: np.ndarray) -> Judged:
    """``model``'s prediction and motion along ``data`` and its held-out gap on ``held_out`` (n, 6)
    against the measured ``tau`` (n, 6), N m."""
    prediction, motion = predicted_motion(model.robot, data)
    return Judged(model, prediction, motion, search.gap(tau, prediction, held_out))
