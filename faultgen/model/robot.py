"""The robot as one constant model (Pinocchio's ``Model``): :class:`Robot`, its compiled MuJoCo model,
element names, nominal parameters, the effects it carries, and its inverse dynamics.

A :class:`Robot` is made once (by :func:`faultgen.model.robots.load` from a file, or by
:func:`from_spec` from an edited spec in memory) and handed down to every layer that needs it; it
never changes. It keeps the parsed ``mujoco.MjSpec`` its model was compiled from, so a simulation
model or an edited robot is derived from it in memory (:meth:`Robot.new_spec`, :meth:`Robot.edited`)
instead of being read and parsed again from the file.

Each model pairs N arm joints ``joint{i}`` (5 <= N <= 7, read from the model: ``joint1``,
``joint2``, ... as far as they go) with N motor-rotor joints ``rotor{i}``, coupled by
fixed tendons ``gearbox{i}`` (``L = rotor{i} / G - joint{i}``, thesis eq. 6.2a), driven by torque
actuators ``motor{i}`` on the rotors, with motor-side friction parameters in the custom numerics
``friction{i}`` and a ``home`` keyframe.

Every effect is read from its own MJCF elements by its class in :mod:`faultgen.effects`
(:func:`faultgen.effects.read_all`): the motor-side friction, which every robot carries, is the
registered effect ``motor_friction`` (:class:`faultgen.effects.motor_friction.MotorFriction`,
held as :attr:`Robot.friction`); the further effects a robot may carry (a torque offset,
cogging, backlash, a payload, ...; absent, they are zero) are held in :attr:`Robot.effects`. The
inverse dynamics add the friction's eq. 6.3 torque and the effects' torques.
"""

from __future__ import annotations

import threading
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import mujoco
import numpy as np

from faultgen import axes
from faultgen.effects.base import ModelError, read_all
from faultgen.effects.friction import FIELDS as FRICTION_FIELDS
from faultgen.effects.motor_friction import MotorFriction
from faultgen.model import drivetrain, sources

__all__ = ["RATED_PAYLOAD", "ModelError", "Robot", "drivetrain_of", "from_model", "from_spec"]

#: Name of the custom numeric holding a robot's rated payload in kg (robots added by ``faultgen robots
#: add`` have one; :attr:`Robot.rated_payload`).
RATED_PAYLOAD = "rated_payload"


def _joint_addresses(names: str, kind: str, what: str) -> cached_property:
    """A cached property of :class:`Robot`: the ``kind`` address (``qposadr`` or ``dofadr``) of each joint
    named in its attribute ``names``, ``ndarray of shape (N,)``; ``what`` opens its docstring."""

    def addresses(robot: Robot) -> np.ndarray:
        return np.array([getattr(robot.model.joint(n), kind)[0] for n in getattr(robot, names)])

    addresses.__doc__ = f"{what}, ``ndarray of shape (N,)``."
    return cached_property(addresses)


@dataclass(frozen=True, eq=False)
class Robot:
    """A compiled robot model and its nominal parameters, all read from the MJCF.

    Attributes
    ----------
    name : str
        Robot name (the folder name, or the MJCF file stem when loaded from a path).
    description : str
        One line describing the model and the source of its numbers.
    path : Path
        The MJCF file.
    model : mujoco.MjModel
        The compiled model (arm joints, rotors, gearbox tendons, motors).
    joint_names, rotor_names, gearbox_names, actuator_names : tuple of str
        Names of the arm joints, rotor joints, gearbox tendons and motors, axis 1..N in order.
    gear_ratio : ndarray of shape (N,)
        Gear ratio G (motor angle / arm angle), dimensionless, positive.
    motor_inertia : ndarray of shape (N,)
        Rotor inertia Jm in kg m^2 at the motor side (the rotor joints' armature).
    gearbox_stiffness : ndarray of shape (N,)
        Gearbox stiffness K in N m/rad at the arm side (thesis eq. 6.2a).
    gearbox_damping : ndarray of shape (N,)
        Gearbox damping D in N m s/rad at the arm side (thesis eq. 6.2a).
    joint_range : ndarray of shape (N, 2)
        Arm joint limits in rad.
    motor_torque_limit : ndarray of shape (N,)
        Largest motor torque the actuators accept, N m at the motor side.
    friction : MotorFriction
        Nominal motor-side friction parameters: the registered effect ``motor_friction``
        (:mod:`faultgen.effects.motor_friction`), read from the ``friction{i}`` numerics.
    home : ndarray of shape (N,)
        Arm joint angles of the ``home`` keyframe in rad.
    effects : dict of str to Effect
        The effects stored in their own MJCF elements (:func:`faultgen.effects.read_all`), by id,
        each with its absolute parameters (absent ones at their absent values); all but the
        motor friction, which is :attr:`friction`.
    digest : str or None
        SHA-1 of the MJCF file's bytes the robot was compiled from (what
        :func:`faultgen.model.robots.load` caches it by); None for a robot compiled from an edited
        spec in memory (:func:`from_spec`), which no file holds.

    Notes
    -----
    The parsed spec the model was compiled from stays with the robot (:meth:`new_spec` hands out
    copies), so models derived from it (the simulation model, a robot carrying a payload) are
    compiled in memory, never read and parsed again from :attr:`path`.
    """

    name: str
    description: str
    path: Path
    model: mujoco.MjModel
    joint_names: tuple[str, ...]
    rotor_names: tuple[str, ...]
    gearbox_names: tuple[str, ...]
    actuator_names: tuple[str, ...]
    gear_ratio: np.ndarray
    motor_inertia: np.ndarray
    gearbox_stiffness: np.ndarray
    gearbox_damping: np.ndarray
    joint_range: np.ndarray
    motor_torque_limit: np.ndarray
    friction: MotorFriction
    home: np.ndarray
    effects: dict = field(default_factory=dict)
    digest: str | None = None
    _spec: mujoco.MjSpec | None = field(default=None, repr=False, compare=False)
    _threads: threading.local = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        # load() hands the same Robot to every caller: its arrays are read-only
        arrays = [self.gear_ratio, self.motor_inertia, self.gearbox_stiffness, self.gearbox_damping,
                  self.joint_range, self.motor_torque_limit, self.home]
        arrays += [getattr(self.friction, name) for name in FRICTION_FIELDS]  # effects are read-only already
        for array in arrays:
            array.setflags(write=False)
        object.__setattr__(self, "_threads", threading.local())

    @property
    def _inverse(self) -> tuple[mujoco.MjModel, mujoco.MjData]:
        """This thread's private copy of the model for inverse dynamics and its ``MjData``: a
        continuous-time integrator keeps ``mj_inverse`` a map from qacc (the discrete integrator
        would invert its step map), and without constraints joint limits add no force."""
        own = getattr(self._threads, "inverse", None)
        if own is None:
            model = self.model.__copy__()
            model.opt.integrator = mujoco.mjtIntegrator.mjINT_EULER
            model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
            own = self._threads.inverse = (model, mujoco.MjData(model))
        return own

    def __getstate__(self) -> dict:
        # MjSpec does not pickle: a robot read from a file parses it again on arrival
        # (new_spec checks the content is unchanged); an edited one travels as its MJCF text
        state = dict(self.__dict__)
        state.pop("_threads")
        spec = state.pop("_spec")
        state["_spec"] = None
        if self.digest is None and spec is not None:
            state["_spec_xml"] = spec.to_xml()
        return state

    def __setstate__(self, state: dict) -> None:
        xml = state.pop("_spec_xml", None)
        self.__dict__.update(state)
        object.__setattr__(self, "_threads", threading.local())
        if xml is not None:
            spec = mujoco.MjSpec.from_string(xml)
            spec.modelfiledir = str(self.path.parent)
            object.__setattr__(self, "_spec", spec)

    def new_spec(self) -> mujoco.MjSpec:
        """A copy of the spec the robot's model was compiled from, to edit and compile (a
        simulation model, a robot carrying a part). Raises ModelError if the robot was pickled and
        its file has changed since."""
        if self._spec is None:
            if self.digest is None or sources.sha1_of(self.path, ModelError) != self.digest:  # bounded, size first
                raise ModelError(f"{self.path}: changed since the robot was read; load it again")
            object.__setattr__(self, "_spec", mujoco.MjSpec.from_file(str(self.path)))
        return self._spec.copy()

    @cached_property
    def rated_payload(self) -> float:
        """Rated payload in kg from the model's ``rated_payload`` numeric; NaN when it has none (the
        built-in robots: their parts are in ``faultgen.runs.fleet.PARTS``)."""
        idx = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_NUMERIC, RATED_PAYLOAD)
        return float(self.model.numeric_data[self.model.numeric_adr[idx]]) if idx >= 0 else float("nan")

    @property
    def n_axes(self) -> int:
        """Number of axes N (5 to 7), read from the model (``joint1`` .. ``jointN``)."""
        return len(self.joint_names)

    arm_qpos = _joint_addresses("joint_names", "qposadr", "Indices of the arm joints in ``qpos``")
    arm_dof = _joint_addresses("joint_names", "dofadr", "Indices of the arm joints in ``qvel``")
    rotor_qpos = _joint_addresses("rotor_names", "qposadr", "Indices of the rotor joints in ``qpos``")
    rotor_dof = _joint_addresses("rotor_names", "dofadr", "Indices of the rotor joints in ``qvel``")

    def rigid_state(self, q: np.ndarray, qd: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Full-model ``qpos`` and ``qvel`` for arm-side angles with an undeflected gearbox.

        Parameters
        ----------
        q : ndarray of shape (N,)
            Arm joint angles in rad.
        qd : ndarray of shape (N,), optional
            Arm joint velocities in rad/s; zero when omitted.

        Returns
        -------
        qpos : ndarray of shape (nq,)
            Arm joints at ``q``, rotors at ``G q`` (motor-side rad).
        qvel : ndarray of shape (nv,)
            Arm joints at ``qd``, rotors at ``G qd`` (motor-side rad/s).
        """
        q = _check_vector("q", q, self.n_axes)
        qd = np.zeros(self.n_axes) if qd is None else _check_vector("qd", qd, self.n_axes)
        qpos = np.zeros(self.model.nq)
        qvel = np.zeros(self.model.nv)
        qpos[self.arm_qpos] = q
        qpos[self.rotor_qpos] = self.gear_ratio * q
        qvel[self.arm_dof] = qd
        qvel[self.rotor_dof] = self.gear_ratio * qd
        return qpos, qvel

    def inverse_dynamics(
        self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray, friction: bool = True,
        t: np.ndarray | None = None,
    ) -> np.ndarray:
        """Arm-side joint torque needed to follow a trajectory, rigid gearbox assumed.

        ``tau = M(q) qdd + C(q, qd) + g(q) - tau_spring(q) + G^2 Jm qdd + G f_m(G qd)``: the
        rigid-body terms of thesis eq. 6.1 from MuJoCo's recursive Newton-Euler (``mj_inverse``,
        joint limits ignored), passive joint springs such as the IRB-6700-like axis-2 balancing,
        the motor inertia reflected through G^2 and, with ``friction=True``, the motor-side static
        friction of thesis eq. 6.3 reflected through G (the Robotics Toolbox convention).

        Parameters
        ----------
        q, qd, qdd : ndarray of shape (n, N)
            Arm joint angles (rad), velocities (rad/s) and accelerations (rad/s^2).
        friction : bool, default True
            Include motor-side friction (:meth:`MotorFriction.stribeck_torque` at ``G qd``)
            and the torque of the robot's :attr:`effects` (:meth:`faultgen.effects.Effect.torque`).
            An effect that lets the arm trail the motor (backlash, with or without the friction
            flag) is taken quasi-statically: ``q`` is read as the motor angle over G and the arm's
            rigid-body terms are evaluated at ``q`` plus :meth:`arm_offset` (backlash b: the arm
            rests on the loaded flank, ``q - (b/2) sign(load)``). Crossing a dead band is a matter
            of the flexible gearbox (:func:`faultgen.calibrate.gearbox.compliance_torque`), not of
            this rigid model.
        t : ndarray of shape (n,), optional
            Time since the start of the run in s, for effects that drift with time (warm-up);
            zero when omitted.

        Returns
        -------
        ndarray of shape (n, N)
            Arm-side joint torque in N m (motor torque times G).

        Notes
        -----
        Uses one private ``MjData`` per thread: safe to call from several threads.

        Raises
        ------
        ValueError
            If an input is not of shape (n, N) with a common n, or holds a non-finite value.
        """
        q = _check_trajectory("q", q, None, self.n_axes)
        qd = _check_trajectory("qd", qd, q.shape[0], self.n_axes)
        qdd = _check_trajectory("qdd", qdd, q.shape[0], self.n_axes)
        G = self.gear_ratio
        tau, load = self._rigid(q, qd, qdd)
        offset = self.arm_offset(load)
        if offset is not None:
            # Quasi-static: q is the motor angle over G, and the arm trails it (a dead band's
            # flank); the arm's rigid-body terms are taken there.
            tau, load = self._rigid(q + offset, qd, qdd, q_motor=q)
        if friction:
            tau += G * self.friction.stribeck_torque(G * qd)
            tau += self.effect_torque(q, qd, load, t)
        return tau

    def gearbox_load(self, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> np.ndarray:
        """Arm-side load the gearboxes carry along a motion, N m, shape (n, N).

        The rigid-body torque of the arm joints (thesis eq. 6.1 without motor inertia and
        friction) with the arm at the motor angle ``q`` (no backlash shift, :meth:`arm_offset`); the input of the
        flexible-gearbox equation (:mod:`faultgen.calibrate.gearbox`).

        Parameters
        ----------
        q, qd, qdd : ndarray of shape (n, N)
            Joint angles (rad), velocities (rad/s) and accelerations (rad/s^2).

        Raises
        ------
        ValueError
            As :meth:`inverse_dynamics`.
        """
        q = _check_trajectory("q", q, None, self.n_axes)
        qd = _check_trajectory("qd", qd, q.shape[0], self.n_axes)
        qdd = _check_trajectory("qdd", qdd, q.shape[0], self.n_axes)
        return self._rigid(q, qd, qdd)[1]

    def static_load(self, q: np.ndarray) -> np.ndarray:
        """Arm-side torque that holds the arm still at ``q``, N m, shape (n, N): gravity plus the
        joints' passive springs (the IRB-6700-like axis-2 balancing), the static gearbox load of
        load-dependent friction's gravity form (Bittencourt & Gunnarsson 2012). :meth:`gearbox_load`
        at zero speed and acceleration.

        Parameters
        ----------
        q : ndarray of shape (n, N)
            Arm joint angles in rad.

        Raises
        ------
        ValueError
            As :meth:`inverse_dynamics`.
        """
        q = _check_trajectory("q", q, None, self.n_axes)
        zero = np.zeros_like(q)
        return self._rigid(q, zero, zero)[1]

    def static_load_of(self, subtree_com: np.ndarray, xanchor: np.ndarray, xaxis: np.ndarray,
                       qpos: np.ndarray) -> np.ndarray:
        """:meth:`static_load` from MuJoCo's position-stage fields of r simulations, N m, (r, N):
        ``-a . ((c - p) x m g) + k (q - q_spring)`` per arm joint (axis ``a``, anchor ``p``, mass
        ``m`` and centre ``c`` of the body subtree it carries, spring stiffness ``k``). For a
        simulation stepping many runs at once, where ``mj_inverse`` per run would cost too much.

        Parameters
        ----------
        subtree_com : ndarray of shape (r, nbody, 3)
        xanchor, xaxis : ndarray of shape (r, njnt, 3)
        qpos : ndarray of shape (r, nq)
        """
        return static_load_from(self.static_terms, subtree_com, xanchor, xaxis, qpos[:, self.arm_qpos])

    @cached_property
    def static_terms(self) -> tuple:
        """Arm joint ids, the bodies they carry, those subtrees' masses (kg), the gravity's cross-
        product matrix ``[g]x`` (3, 3), the joints' spring stiffness and rest angles."""
        model = self.model
        joints = np.array([model.joint(n).id for n in self.joint_names])
        bodies = model.jnt_bodyid[joints]
        g = model.opt.gravity
        cross = np.array([[0.0, -g[2], g[1]], [g[2], 0.0, -g[0]], [-g[1], g[0], 0.0]])
        return (joints, bodies, model.body_subtreemass[bodies].copy(), cross, model.jnt_stiffness[joints].copy(),
                model.qpos_spring[self.arm_qpos].copy())

    def _rigid(self, q, qd, qdd, q_motor=None) -> tuple[np.ndarray, np.ndarray]:
        """Rigid-body drive torque and arm-side gearbox load, both (n, N), by ``mj_inverse``
        (arm at ``q``, rotors at ``G q_motor``, ``q_motor = q`` by default)."""
        model, data = self._inverse
        G = self.gear_ratio
        q_motor = q if q_motor is None else q_motor
        n = q.shape[0]
        qpos, qvel, qacc = (np.tile(x, (n, 1)) for x in (data.qpos, data.qvel, data.qacc))  # whole states first
        qpos[:, self.arm_qpos], qpos[:, self.rotor_qpos] = q, G * q_motor
        qvel[:, self.arm_dof], qvel[:, self.rotor_dof] = qd, G * qd
        qacc[:, self.arm_dof], qacc[:, self.rotor_dof] = qdd, G * qdd
        force = np.empty((n, model.nv))
        # a sample with the state bits of the one before (a hold: up to 2/5 of a task's steps) takes its force
        new = np.ones(n, dtype=bool)
        for x in (qpos, qvel, qacc):
            new[1:] &= np.all(x.view(np.int64)[1:] == x.view(np.int64)[:-1], axis=1)
        new[1:] = ~new[1:]
        at_qpos, at_qvel, at_qacc, inverse = data.qpos, data.qvel, data.qacc, data.qfrc_inverse
        for k in np.flatnonzero(new).tolist():
            at_qpos[:], at_qvel[:], at_qacc[:] = qpos[k], qvel[k], qacc[k]
            mujoco.mj_inverse(model, data)
            force[k] = inverse
        force = force[np.flatnonzero(new)[np.cumsum(new) - 1]]
        # The rigid gearbox carries the rotor's generalized force to the arm through G.
        load = force[:, self.arm_dof]
        return load + G * force[:, self.rotor_dof], load

    def arm_mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """The arm's joint-space inertia matrix (rotor spin excluded), kg m^2, shape (n, N, N).

        The arm block of MuJoCo's mass matrix (``mj_fullM``) with the rotors at ``G q``: what
        the arm joints' torques need per unit arm acceleration with the rotors held (thesis eq.
        6.1's ``M(q)``; the rotors' masses ride on the links and are included).

        Parameters
        ----------
        q : ndarray of shape (n, N)
            Arm joint angles in rad.
        """
        q = _check_trajectory("q", q, None, self.n_axes)
        model, data = self._inverse
        qpos = np.tile(data.qpos, (q.shape[0], 1))
        qpos[:, self.arm_qpos], qpos[:, self.rotor_qpos] = q, self.gear_ratio * q
        full = np.zeros((q.shape[0], model.nv, model.nv))
        for k in range(q.shape[0]):
            data.qpos[:] = qpos[k]
            mujoco.mj_kinematics(model, data)  # the stages the mass matrix needs, not all of mj_fwdPosition
            mujoco.mj_comPos(model, data)
            mujoco.mj_makeM(model, data)
            mujoco.mj_fullM(model, data, full[k])
        return full[np.ix_(np.arange(q.shape[0]), self.arm_dof, self.arm_dof)]

    def effect_torque(self, q: np.ndarray, qd: np.ndarray, load: np.ndarray, t: np.ndarray | None = None
                      ) -> np.ndarray:
        """Arm-side drive torque of the robot's :attr:`effects`, N m, shape (n, N).

        ``load`` is the arm-side gearbox load torque (rigid-body torque of the arm joints), N m;
        ``t`` the time since the start of the run, s (zero when omitted).
        """
        time = np.zeros(len(q)) if t is None else np.asarray(t, dtype=float)
        tau = np.zeros_like(np.asarray(q, dtype=float))
        for effect in self.effects.values():
            if np.any(effect.active()):
                part = effect.torque(self, q, qd, load, time)
                if part is not None:
                    tau = tau + part
        return tau

    def arm_offset(self, load: np.ndarray) -> np.ndarray | None:
        """Arm angle minus motor angle over G under the arm-side gearbox ``load`` (n, N), rad, from
        the :attr:`effects` that let the arm trail the motor (backlash); None when none does."""
        offsets = [effect.arm_offset(load) for effect in self.effects.values() if np.any(effect.active())]
        offsets = [o for o in offsets if o is not None]
        return sum(offsets[1:], offsets[0]) if offsets else None

    def edited(self, edit) -> Robot:
        """A copy of the robot with ``edit(spec)`` applied to a copy of its spec (:meth:`new_spec`),
        compiled in memory (:func:`from_spec`)."""
        spec = self.new_spec()
        edit(spec)
        return from_spec(spec, self.path)


def _check_vector(name: str, value: np.ndarray, n_axes: int) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if arr.shape != (n_axes,):
        raise ValueError(f"{name} must have shape ({n_axes},), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} holds a non-finite value at axis {int(np.argmin(np.isfinite(arr))) + 1}")
    return arr


def _check_trajectory(name: str, value: np.ndarray, n: int | None, n_axes: int) -> np.ndarray:
    arr = np.asarray(value, dtype=float)
    if arr.ndim != 2 or arr.shape[1] != n_axes or (n is not None and arr.shape[0] != n):
        expected = f"(n, {n_axes})" if n is None else f"({n}, {n_axes})"
        raise ValueError(f"{name} must have shape {expected}, got {arr.shape}")
    bad = np.argwhere(~np.isfinite(arr))
    if bad.size:
        row, col = bad[0]
        raise ValueError(f"{name} holds a non-finite value at row {row}, axis {col + 1}")
    return arr


def from_spec(spec: mujoco.MjSpec, path: str | Path) -> Robot:
    """Compile an edited ``MjSpec`` of a robot in memory; ``path`` names it (and locates its
    ``tasks.toml``) as if it had been written there.

    Raises
    ------
    ModelError
        As :func:`load`.
    """
    path = Path(path)
    try:
        model = spec.compile()
    except ValueError as err:
        raise ModelError(f"{path}: {str(err).strip()}") from err
    return from_model(model, path, spec)


def drivetrain_of(robot: Robot) -> drivetrain.Drivetrain:
    """The robot's drivetrain as data (:class:`faultgen.model.drivetrain.Drivetrain`), read back
    from its compiled model: what ``drivetrain.toml`` of its folder holds."""
    rows = robot.friction.as_rows()
    drives = []
    for k in range(robot.n_axes):
        values = dict(gear_ratio=float(robot.gear_ratio[k]), motor_inertia=float(robot.motor_inertia[k]),
                      gearbox_stiffness=float(robot.gearbox_stiffness[k]),
                      gearbox_damping=float(robot.gearbox_damping[k]),
                      motor_torque_limit=float(robot.motor_torque_limit[k]))
        values.update({name: float(rows[k, j]) for j, name in enumerate(FRICTION_FIELDS)})
        try:
            drives.append(drivetrain.AxisDrive(**values))
        except drivetrain.DrivetrainError as err:
            raise drivetrain.DrivetrainError(f"axis {k + 1}: {err}") from err
    return drivetrain.Drivetrain(tuple(drives))


def from_model(model: mujoco.MjModel, path: Path, spec: mujoco.MjSpec | None = None,
               digest: str | None = None) -> Robot:
    """The :class:`Robot` of a compiled robot ``model`` (``path`` names it), reading its elements
    and nominal parameters; ``spec``: the spec it was compiled from (kept for derived models);
    ``digest``: its file's SHA-1 (:func:`faultgen.model.robots.load`). Raises ModelError naming
    ``path`` and the missing or malformed element."""
    n_axes = axes.count(model)
    if not axes.MIN_AXES <= n_axes <= axes.MAX_AXES:
        raise ModelError(f"{path}: {n_axes} arm joints joint1..joint{n_axes}; a robot has "
                         f"{axes.MIN_AXES}..{axes.MAX_AXES} (joint1, joint2, ... in order)")
    elements = _axis_elements(model, path, n_axes)
    joint_names = elements["joint_names"]
    # the motor friction is a registered effect read with the others (MotorFriction.read: the
    # numerics friction1..frictionN, all required); the robot holds it as ``friction``
    effects = read_all(model, path)
    friction = effects.pop(MotorFriction.id)

    key = _require(model, path, n_axes, "keyframe", mujoco.mjtObj.mjOBJ_KEY, "home")
    joint_qpos = [model.jnt_qposadr[model.joint(n).id] for n in joint_names]
    description_id = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_TEXT, "description")
    description = ""
    if description_id >= 0:
        adr, size = model.text_adr[description_id], model.text_size[description_id]
        description = bytes(model.text_data[adr : adr + size - 1]).decode()

    for k in range(n_axes):
        if model.jnt_limited[model.joint(joint_names[k]).id] == 0:
            raise ModelError(f"{path}: joint {joint_names[k]!r} must be limited (give it a range)")

    return Robot(
        name=path.stem,
        description=description,
        path=path,
        model=model,
        **elements,
        friction=friction,
        home=model.key_qpos[key, joint_qpos].copy(),
        effects=effects,
        digest=digest,
        _spec=spec,
    )


def _require(model: mujoco.MjModel, path: Path, n_axes: int, kind: str, obj_type: mujoco.mjtObj,
             element: str) -> int:
    """The id of ``model``'s ``kind`` named ``element``, or ModelError naming ``path`` and it."""
    idx = mujoco.mj_name2id(model, obj_type, element)
    if idx < 0:
        raise ModelError(f"{path}: no {kind} named {element!r}; a robot needs {kind}s 1..{n_axes}")
    return idx


def _axis_elements(model: mujoco.MjModel, path: Path, n_axes: int) -> dict:
    """The :class:`Robot` fields read per axis: the element names (``joint_names``, ``rotor_names``,
    ``gearbox_names``, ``actuator_names``, each a tuple of ``n_axes``) and the drivetrain numbers
    read off those elements (``gear_ratio``, ``motor_inertia``, ``gearbox_stiffness``,
    ``gearbox_damping``, ``motor_torque_limit``: ndarray of shape (N,); ``joint_range``: (N, 2)).
    Raises ModelError naming ``path`` and the first missing or malformed element."""
    numbers = range(1, n_axes + 1)
    joint_names = tuple(f"joint{i}" for i in numbers)
    rotor_names = tuple(f"rotor{i}" for i in numbers)
    gearbox_names = tuple(f"gearbox{i}" for i in numbers)
    actuator_names = tuple(f"motor{i}" for i in numbers)

    gear_ratio = np.empty(n_axes)
    joint_range = np.empty((n_axes, 2))
    motor_inertia = np.empty(n_axes)
    torque_limit = np.empty(n_axes)
    for k in range(n_axes):
        j = _require(model, path, n_axes, "joint", mujoco.mjtObj.mjOBJ_JOINT, joint_names[k])
        r = _require(model, path, n_axes, "joint", mujoco.mjtObj.mjOBJ_JOINT, rotor_names[k])
        t = _require(model, path, n_axes, "tendon", mujoco.mjtObj.mjOBJ_TENDON, gearbox_names[k])
        a = _require(model, path, n_axes, "actuator", mujoco.mjtObj.mjOBJ_ACTUATOR, actuator_names[k])
        gear_ratio[k] = _gear_ratio(model, path, t, j, r)
        if model.actuator_trnid[a, 0] != r or model.actuator_trntype[a] != mujoco.mjtTrn.mjTRN_JOINT:
            raise ModelError(f"{path}: actuator {actuator_names[k]!r} must drive joint {rotor_names[k]!r}")
        joint_range[k] = model.jnt_range[j]
        motor_inertia[k] = model.dof_armature[model.jnt_dofadr[r]]
        torque_limit[k] = np.max(np.abs(model.actuator_ctrlrange[a]))
    tendon_ids = [model.tendon(n).id for n in gearbox_names]
    return {"joint_names": joint_names, "rotor_names": rotor_names, "gearbox_names": gearbox_names,
            "actuator_names": actuator_names, "gear_ratio": gear_ratio, "joint_range": joint_range,
            "motor_inertia": motor_inertia, "motor_torque_limit": torque_limit,
            "gearbox_stiffness": model.tendon_stiffness[tendon_ids].copy(),
            "gearbox_damping": model.tendon_damping[tendon_ids].copy()}


def _gear_ratio(model: mujoco.MjModel, path: Path, tendon: int, joint: int, rotor: int) -> float:
    """G of a gearbox tendon ``L = rotor / G - joint``; raises ModelError on any other shape."""
    name = model.tendon(tendon).name
    adr, num = model.tendon_adr[tendon], model.tendon_num[tendon]
    wraps = {int(model.wrap_objid[w]): float(model.wrap_prm[w]) for w in range(adr, adr + num)}
    fixed = all(model.wrap_type[w] == mujoco.mjtWrap.mjWRAP_JOINT for w in range(adr, adr + num))
    if not fixed or set(wraps) != {joint, rotor} or wraps[joint] != -1.0 or wraps[rotor] <= 0:
        raise ModelError(
            f"{path}: tendon {name!r} must be a fixed tendon with coef 1/G > 0 on its rotor joint "
            "and coef -1 on its arm joint (thesis eq. 6.2a)"
        )
    return 1.0 / wraps[rotor]


def static_load_from(terms: tuple, subtree_com: np.ndarray, xanchor: np.ndarray, xaxis: np.ndarray,
                     arm_angles: np.ndarray) -> np.ndarray:
    """:meth:`Robot.static_load_of` from its constant ``terms`` (:attr:`Robot.static_terms`, arrays a
    stepping backend can hold) and the arm angles ``arm_angles`` (r, N) rad, N m, (r, N)."""
    joints, bodies, mass, gravity, stiffness, rest = terms
    lever = subtree_com[:, bodies] - xanchor[:, joints]  # (r, N, 3), m
    # -a . ((c - p) x m g) = m a^T [g]x (c - p), [g]x v = g x v: a product, not a cross product
    moment = np.sum((xaxis[:, joints] @ gravity) * lever, axis=-1)
    return mass * moment + stiffness * (arm_angles - rest)
