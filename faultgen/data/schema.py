"""The dataset format as data: what a faultgen HDF5 dataset holds and how it is labelled.

One file holds any number of runs. Layout (h5py; every array carries ``units``, ``axes`` and
``description`` attributes; docs/dataset.md explains each field)::

    /                         attrs: format = "faultgen", format_version, faultgen_version,
                                     n_runs, command, grid (JSON, sweeps only),
                                     complete (written last: True only for a finished file)
    /runs/<run id>/           attrs: labels (robot, task, friction_model, cycles, seed, worn_axes,
                                     program_sha256: what the program is (PROGRAM_ATTRIBUTE;
                                     older files lack it),
                                     a program file's or log's program: name, file, sha256, program_text,
                                     a log's format (not the measured one);
                                     wear JSON, noise JSON) and provenance (faultgen_version,
                                     model_sha256, log_period, config JSON, command;
                                     n_axes, drivetrain JSON, limits JSON, LIMITS: older
                                     files lack them; on a friction test's run:
                                     record = "friction_test", RECORD_ATTRIBUTE)
        t, cycles, q_ref                       time base, recorded cycles, reference
        q_a, q_m, qd_a, qd_m, tau_m            (n_cycles, n_log, N) logged signals, 250 Hz, N the
                                               robot's axes (attr n_axes; 6 in files before it)
        tau_f, tau_dist                        (n_cycles, n_log, N) truth
        friction_multiplier, mean_friction_torque, tracking_error        (n_cycles, N) truth
        mean_abs_torque, rms_torque                                       (n_cycles, N) features
        average_speed, average_load_torque     (n_cycles, N) each axis's duty (DUTY_ARRAYS; runs
                                               simulated since it exists)
        angle_hist, speed_hist, torque_hist                               (n_cycles, N, 12) features
        torque_counts          (n_cycles, N, 1200) samples per fine |tau_m| bin, what detection
                               bins from (COUNT_ARRAYS; runs recorded per cycle since it exists)
        day, hour, joint_temperature, ...      operating conditions per cycle, truth (only runs
                                               with conditions: CONDITION_ARRAYS; attr conditions)

Only tables and the small rules read from them live here (array names, units, axes and the
dtypes and shapes they imply, run attributes, the format version, :class:`DatasetError`): the
writer (:mod:`faultgen.data.writer`), the gate every read passes (:mod:`faultgen.data.opening`),
the validator, the reader and the summary all read them, and this module imports none of those.
"""

from __future__ import annotations

from faultgen.simulation import sensors
from faultgen.simulation.signals import ARRAYS  # the signal set, defined once
from faultgen.simulation.signals import SIGNAL_AXES as SIGNAL_AXES  # re-exported for the readers

FORMAT = "faultgen"
FORMAT_VERSION = 1

#: name -> (units, axes, description) of the per-cycle sample counts of every run recorded per
#: cycle (not daily records; files written before they existed lack them, and stay valid).
COUNT_AXES = "cycle, axis, fine bin"
COUNT_ARRAYS = {
    "torque_counts": ("1", COUNT_AXES, (f"samples of the cycle in each 1/{sensors.TORQUE_COUNT_BINS} of 0..peak "
                                        "motor torque (|tau_m| as stored, larger in the last bin)")),
}

#: name -> (units, axes, description) of each axis's duty per cycle (:func:`faultgen.simulation.sensors.duty`),
#: what the speed and torque indicators are made from; files written before it existed lack it,
#: and stay valid.
DUTY_ARRAYS = {
    "average_speed": ("rad/s", "cycle, axis", "mean |qd_a| per cycle, the gearbox's average output speed"),
    "average_load_torque": ("N m", "cycle, axis", (f"(mean(|qd_a| |tau_m|^p) / mean |qd_a|)^(1/p) per cycle, "
                                                   f"p = {sensors.LOAD_EXPONENT:.4g} (motor side)")),
}

#: name -> (units, axes, description, condition that writes it) of the operating-condition
#: arrays (:mod:`faultgen.operation.conditions`), written for a run that has conditions: the
#: calendar and the friction factors always, the rest when their condition is on
#: (``condition.setting``: when that setting of the condition is on, not 0).
CONDITION_ARRAYS = {
    "day": ("d", "cycle", "day of the year of the cycle (counts on past 365)", None),
    "hour": ("h", "cycle", "time of day of the cycle", None),
    "dry_friction_factor": ("1", "cycle, axis", ("multiplier of Coulomb and static friction from temperature and "
                                                 "unit spread (wear not included)"), None),
    "viscous_factor": ("1", "cycle, axis", "multiplier of viscous friction from temperature and unit spread", None),
    "ambient_temperature": ("degC", "cycle", "air temperature", "thermal"),
    "joint_temperature": ("degC", "cycle, axis", "joint temperature", "thermal"),
    "payload_part": ("1", "cycle", "index of the part carried (into the conditions' payload masses)", "payloads"),
    "payload_mass": ("kg", "cycle", "mass of the part carried", "payloads"),
    "link_mass_factor": ("1", "axis", "multiplier of each link's mass and inertia (this unit's)", "spread"),
    "task_index": ("1", "cycle", "index of the task the cycle ran (into the conditions' task_mix tasks)", "task_mix"),
    "gear_loss": ("1", "axis", ("load-dependent friction coefficient this unit's gearbox adds (share of the "
                                "transmitted torque lost as Coulomb friction)"), "spread.gear_loss"),
}

#: The array of a run whose fault is not friction wear (attribute ``fault``): its units are the
#: fault parameter's, named by the effect (``faultgen.effects``), so the array says where to look.
FAULT_ARRAYS = {
    "fault_value": ("of the fault parameter", "cycle", "the growing fault's parameter at each cycle (attr fault)"),
}

#: name -> (units, axes, description) of what a run imported from measured logs holds beside the
#: features (attribute ``source = "measured"``, :mod:`faultgen.data.fleetlogs`): a record is a log;
#: ``joint_temperature`` and ``payload_mass`` only when every log of the unit has them. Such a run has
#: no simulated truth (``mean_friction_torque``, ``tracking_error``); its ``friction_multiplier`` holds
#: the labels (2 on worn logs, 1 elsewhere, ``faultgen.data.fleetlogs.WORN_MARK``).
MEASURED_ARRAYS = {
    "label": ("1", "cycle, axis", "per log and axis: 1 worn, 0 healthy, -1 unknown (from the logs' events.csv)"),
    "stamp": ("", "cycle", "the log's stamp, as in its file name (ISO date or date-time, or a sequence number)"),
    "stamp_key": ("s since 1970-01-01 UTC, or 1 for sequence numbers", "cycle", "the stamp as a number, increasing"),
    "log_file": ("", "cycle", "the log's file, <unit>/<name>, relative to the logs folder"),
    "log_cycles": ("1", "cycle", "cycles in the log, reduced to its record as a simulated day's are"),
    "log_duration": ("s", "cycle", "recorded time span of the log"),
    "joint_temperature": ("degC", "cycle, axis", "the log's mean joint temperature"),
    "payload_mass": ("kg", "cycle", "the largest payload mass in the log"),
}
#: The :data:`MEASURED_ARRAYS` an imported run holds only when its logs have them.
MEASURED_OPTIONAL = ("joint_temperature", "payload_mass")
#: The simulated truths a measured run lacks.
SIMULATED_TRUTH = ("mean_friction_torque", "tracking_error")
#: The ``source`` attribute of a run imported from measured logs (absent: simulated).
MEASURED = "measured"
#: The arrays that hold text (variable-length UTF-8 strings), not numbers.
TEXT_ARRAYS = ("stamp", "log_file")


def kinds(name: str) -> str:
    """The NumPy type kinds an array of a run may hold (:func:`faultgen.inputs.bounded_dataset`):
    text for :data:`TEXT_ARRAYS`, numbers (and booleans) for the others."""
    return "SOU" if name in TEXT_ARRAYS else "fiub"

#: name -> axes of every array a run may hold, and the lengths of the axes that are not cycles,
#: samples or axes: the declared shapes :func:`faultgen.data.structure.check_runs` checks at opening.
SHAPES = {name: spec[1] for table in (ARRAYS, COUNT_ARRAYS, DUTY_ARRAYS, CONDITION_ARRAYS, FAULT_ARRAYS,
                                                        MEASURED_ARRAYS)
          for name, spec in table.items()}
BINS = {"bin": sensors.HISTOGRAM_BINS, "fine bin": sensors.TORQUE_COUNT_BINS}

#: Attributes every run group carries.
RUN_ATTRIBUTES = ("robot", "task", "friction_model", "cycles", "seed", "worn_axes", "wear", "noise",
                  "faultgen_version", "model_sha256", "log_period", "config", "command")


#: The attribute that labels a run's records as friction tests: ``record = "friction_test"``
#: (:data:`FRICTION_TEST`) on a run whose program is a friction test (its ``process`` is ``"friction
#: test"``: ``faultgen tasks friction-test``, :mod:`faultgen.operation.friction_test`); absent on every
#: other run (production records, as in files written before it). A fleet's tests
#: (``faultgen fleet --friction-test-every``) are such runs beside its robots' runs; a reader filters
#: on it (the typed reader keeps a fleet's tests apart: ``Dataset.friction_tests``).
RECORD_ATTRIBUTE = "record"
FRICTION_TEST = "friction_test"
#: The program ``process`` that makes a run a friction test.
FRICTION_TEST_PROCESS = "friction test"

#: The attribute that says what a run's program is (:func:`faultgen.operation.programs.identity`):
#: the SHA-256 of its text, hex. Runs written before it lack it; readers then fall back to the
#: ``task`` label (:attr:`faultgen.data.reader.Run.program`) and analyses say so.
PROGRAM_ATTRIBUTE = "program_sha256"

#: Attributes of a run written since robots of 5 to 7 axes exist (files before them lack them and
#: stay valid: their robots had six axes): ``n_axes`` (int) and ``drivetrain`` (JSON,
#: :func:`faultgen.data.writer.drivetrain`).
ROBOT_ATTRIBUTES = ("n_axes", "drivetrain")

#: The drivetrain numbers a run records (:func:`faultgen.data.writer.drivetrain`): Robot attribute -> SI unit.
DRIVETRAIN = {"gear_ratio": "1", "motor_inertia": "kg m^2", "gearbox_stiffness": "N m/rad",
              "gearbox_damping": "N m s/rad", "motor_torque_limit": "N m"}

#: The robot's limits a run records (attribute ``limits``, JSON, :func:`faultgen.data.writer.limits`):
#: entry -> SI unit. ``joint_range`` (N, 2), the angle histogram's range; ``velocity`` (N,), the
#: robot's speed limit (its folder's ``tasks.toml`` ``[limits]``); ``task_velocity`` (N,), the run's
#: own task's speed limit, the speed histogram's range (the torque histogram's is the drivetrain's
#: ``motor_torque_limit``). With ``drivetrain`` and ``model_sha256`` it is what an analysis needs of
#: the robot, so a dataset is analysed without the robot's files (:mod:`faultgen.data.robot_record`).
#: Files written before it lack it and stay valid: readers then load the robot by its label.
LIMITS = {"joint_range": "rad", "velocity": "rad/s", "task_velocity": "rad/s"}


class DatasetError(ValueError):
    """A file is not a finished, valid faultgen dataset; the message says what is wrong."""

    #: The command line's exit code for it (faultgen.cli.base.Command): the file, not the input, is bad.
    exit_code = 1


def condition_arrays(conditions: dict | None) -> list[str]:
    """The :data:`CONDITION_ARRAYS` a run with ``conditions`` (its JSON labels; None: none) has."""
    if not conditions:
        return []

    def on(condition: str | None) -> bool:
        if condition is None:
            return True
        name, _, setting = condition.partition(".")
        table = conditions.get(name)
        return table is not None and (not setting or bool(table.get(setting)))

    return [name for name, (*_, condition) in CONDITION_ARRAYS.items() if on(condition)]
