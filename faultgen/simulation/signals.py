"""The signal set, defined once: every array a run records (:data:`ARRAYS`, the dataset's schema of
a run group, :mod:`faultgen.data.dataset`), and from it the signals the stepping logs
(:data:`TRUE_SIGNALS`, :class:`faultgen.simulation.batch.Raw`), the signals of a
:class:`~faultgen.simulation.results.RunResult` (:data:`SIGNALS`) and its per-cycle truths
(:data:`TRUTHS`)."""

from __future__ import annotations

#: The axes of a signal: one value per recorded cycle, log sample and axis.
SIGNAL_AXES = "cycle, sample, axis"

#: name -> (units, axes, description) of every array of a run group.
ARRAYS = {
    "t": ("s", "sample", "log time within a cycle (250 Hz)"),
    "cycles": ("1", "cycle", "1-based index of each recorded cycle"),
    "q_ref": ("rad", "sample, axis", "reference arm angle"),
    "q_a": ("rad", SIGNAL_AXES, "arm angle from the encoder"),
    "q_m": ("rad", SIGNAL_AXES, "motor angle from the encoder (motor side)"),
    "qd_a": ("rad/s", SIGNAL_AXES, "arm speed, backward difference of q_a"),
    "qd_m": ("rad/s", SIGNAL_AXES, "motor speed, backward difference of q_m (motor side)"),
    "tau_m": ("N m", SIGNAL_AXES, "motor torque (drive output, motor side)"),
    "tau_f": ("N m", SIGNAL_AXES, "true friction torque, motor side, positive opposing positive motion"),
    "tau_dist": ("N m", SIGNAL_AXES, "true load disturbance on the arm joint (arm side)"),
    "friction_multiplier": ("1", "cycle, axis", "true wear multiplier of Coulomb and static friction"),
    "mean_friction_torque": ("N m", "cycle, axis", "mean absolute true friction torque per cycle (motor side)"),
    "tracking_error": ("rad", "cycle, axis", "largest absolute error of the true arm angle against q_ref"),
    "mean_abs_torque": ("N m", "cycle, axis", "mean absolute motor torque per cycle (motor side)"),
    "rms_torque": ("N m", "cycle, axis", "RMS motor torque per cycle (motor side)"),
    "angle_hist": ("1", "cycle, axis, bin", "fraction of the cycle in each twelfth of the joint range"),
    "speed_hist": ("1", "cycle, axis, bin", "fraction of the cycle in each twelfth of 0..max arm speed"),
    "torque_hist": ("1", "cycle, axis, bin", "fraction of the cycle in each twelfth of 0..peak motor torque"),
}

#: The signals of a run, ``(n_cycles, n_log, N)`` each, in :data:`ARRAYS`' order.
SIGNALS = tuple(name for name, (_, axes, _) in ARRAYS.items() if axes == SIGNAL_AXES)

#: The load disturbance is drawn before stepping (:func:`faultgen.simulation.sensors.disturbance`);
#: the other signals are what the stepping logs at the log times (true values, before the sensors).
TRUE_SIGNALS = tuple(name for name in SIGNALS if name != "tau_dist")

#: The per-cycle truths of a run (:class:`~faultgen.simulation.results.RunResult` attributes; the
#: other per-cycle arrays of :data:`ARRAYS` are its features).
TRUTHS = ("friction_multiplier", "mean_friction_torque", "tracking_error")
