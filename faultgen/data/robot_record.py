"""What a run stores of its robot: the drivetrain it was simulated with (or of the robot its logs
were recorded on), the limits its histograms were binned over, and its model's digest, read from
the run's attributes (``drivetrain``, ``limits``, ``n_axes``, ``model_sha256``; docs/dataset.md).

The analyses (``faultgen detect``, ``classify``, ``bench-isolators``, ``training-source``, the
card of ``faultgen info --card``) take what they need of a robot from here (:class:`Drivetrain`,
:class:`Limits`, through :attr:`faultgen.data.reader.Run.drivetrain` and
:attr:`~faultgen.data.reader.Run.limits`), never from the robot's files: a dataset is analysed on a
machine without the robot's folder, or with another version of it, as it was written.

Files written before an attribute existed lack it (``n_axes`` and ``drivetrain`` before robots of 5
to 7 axes, ``limits`` before the planning limits were stored): for those runs alone the robot is loaded by the run's
``robot`` label (:func:`faultgen.model.robots.load`, the task by its ``task`` label), as every
analysis did before, and the record says so (``from_files``).
"""

from __future__ import annotations

import json
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from faultgen.data.schema import DRIVETRAIN, MEASURED, DatasetError


@dataclass(frozen=True)
class Drivetrain:
    """A run's drivetrain, per axis 1..N (index 0 is axis 1).

    Attributes
    ----------
    n_axes : int
        N, the robot's axes (5..7).
    gear_ratio : ndarray of shape (N,)
        Motor turns per arm turn, 1.
    motor_inertia : ndarray of shape (N,)
        Rotor inertia, kg m^2, motor side.
    gearbox_stiffness, gearbox_damping : ndarray of shape (N,)
        N m/rad and N m s/rad, arm side.
    motor_torque_limit : ndarray of shape (N,)
        Peak motor torque, N m, motor side: the range of ``torque_hist`` and ``torque_counts``.
    friction : dict of str to ndarray of shape (N,)
        The nominal motor-side friction parameters by name (``coulomb_pos``, ``coulomb_neg``,
        ``static``, ``stribeck_velocity``, ``stribeck_exponent``, ``viscous``, ``bristle_stiffness``,
        ``bristle_damping``; :data:`faultgen.effects.friction.FIELDS`), units in ``units``.
    units : dict of str to str
        Each entry's unit (``friction.<name>`` for the friction parameters).
    from_files : bool
        True when the run did not store it (a file written before robots of 5-7 axes) and it was
        read from the robot's files on this machine.
    """

    n_axes: int
    gear_ratio: np.ndarray
    motor_inertia: np.ndarray
    gearbox_stiffness: np.ndarray
    gearbox_damping: np.ndarray
    motor_torque_limit: np.ndarray
    friction: dict = field(repr=False)
    units: dict = field(repr=False)
    from_files: bool = False


@dataclass(frozen=True)
class Limits:
    """The robot's limits a run's histograms were binned over.

    Attributes
    ----------
    joint_range : ndarray of shape (N, 2)
        Low and high joint angle per axis, rad: the range of ``angle_hist``.
    velocity : ndarray of shape (N,)
        The robot's speed limit per axis, rad/s, arm side (its folder's ``tasks.toml`` ``[limits]``,
        the limits its thesis tasks are planned to).
    task_velocity : ndarray of shape (N,)
        The speed limit of the run's own task, rad/s: the range of ``speed_hist`` (the robot's for a
        thesis task, a replayed log or a measured log; a program file's own ``[limits]`` if it has
        them). In a file written before it was stored, the task is loaded by its label when this is
        first read (ValueError if it cannot be).
    from_files : bool
        True when the run did not store them (a file written before the limits were stored) and they were read from
        the robot's files on this machine.
    """

    joint_range: np.ndarray
    velocity: np.ndarray
    _task_velocity: np.ndarray | Callable[[], np.ndarray] = field(repr=False)
    from_files: bool = False

    @property
    def task_velocity(self) -> np.ndarray:
        given = self._task_velocity
        return np.asarray(given() if callable(given) else given, dtype=float)


def _array(values, shape: tuple[int, ...]) -> np.ndarray:
    out = np.array(values, dtype=float)
    if out.shape != shape or not np.all(np.isfinite(out)):
        raise ValueError(f"expected {shape} finite numbers")
    out.setflags(write=False)
    return out


def _robot(name: str, where: str, what: str):
    """The robot ``name`` loaded from this machine's files, for a run that does not store ``what``."""
    from faultgen.model import robots

    try:
        return robots.load(name)
    except ValueError as err:
        raise ValueError(f"{where} was written before runs stored {what}, so the robot is read from its files, and "
                         f"they cannot be loaded here: {err}") from None


def drivetrain(attrs: dict, robot: str, where: str) -> Drivetrain:
    """The :class:`Drivetrain` a run stored (its attribute ``drivetrain``, JSON of
    :func:`faultgen.data.writer.drivetrain`; ``attrs`` the run's attributes, ``robot`` its label,
    ``where`` names it in messages); for a file written before it, the robot's loaded from its files.

    Raises
    ------
    faultgen.data.schema.DatasetError
        If the stored JSON is not a drivetrain of N finite numbers per entry.
    ValueError
        For a file without it whose robot cannot be loaded here (the message says so).
    """
    text = attrs.get("drivetrain")
    if text is None:
        from faultgen.data import writer

        table, from_files = writer.drivetrain(_robot(robot, where, "their drivetrain")), True
    else:
        table, from_files = text, False
    try:
        table = json.loads(table) if isinstance(table, str) else table
        n = len(table["gear_ratio"])
        values = {name: _array(table[name], (n,)) for name in DRIVETRAIN}
        friction = {name: _array(values_, (n,)) for name, values_ in table["friction"].items()}
        return Drivetrain(n_axes=n, **values, friction=friction, units=dict(table["units"]), from_files=from_files)
    except (ValueError, KeyError, TypeError, AttributeError) as err:
        raise DatasetError(f"{where}: attribute 'drivetrain' does not read ({err}); faultgen validate names what is "
                           "wrong") from None


def limits(attrs: dict, robot: str, task: str, where: str) -> Limits:
    """The :class:`Limits` a run stored (its attribute ``limits``, JSON of
    :func:`faultgen.data.writer.limits`; ``attrs`` the run's attributes, ``robot`` and ``task`` its
    labels, ``where`` names it in messages); for a file written before it, the robot's (and, when
    asked for, the task's) loaded from their files.

    Raises
    ------
    faultgen.data.schema.DatasetError
        If the stored JSON is not the limits of N axes.
    ValueError
        For a file without it whose robot (or its ``tasks.toml`` ``[limits]``) cannot be loaded here.
    """
    text = attrs.get("limits")
    if text is None:
        from faultgen.operation import programs

        loaded = _robot(robot, where, "their limits")
        velocity = programs.robot_limits(loaded)[0]
        own = velocity if attrs.get("source") == MEASURED else (lambda: programs.load(loaded, task).velocity_limit)
        return Limits(joint_range=loaded.joint_range, velocity=velocity, _task_velocity=own, from_files=True)
    try:
        table = json.loads(text)
        n = len(table["velocity"])
        return Limits(joint_range=_array(table["joint_range"], (n, 2)), velocity=_array(table["velocity"], (n,)),
                      _task_velocity=_array(table["task_velocity"], (n,)))
    except (ValueError, KeyError, TypeError) as err:
        raise DatasetError(f"{where}: attribute 'limits' does not read ({err}); faultgen validate names what is "
                           "wrong") from None


__all__ = ["Drivetrain", "Limits", "drivetrain", "limits"]
