"""``faultgen calibrate``: the sim-vs-measured workflow (faultgen.calibrate)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from faultgen.checks import MAX_SEED
from faultgen.cli.base import Command, check_output_folder
from faultgen.cli.main import app
from faultgen.cli.options import LogFormat, Overwrite, TorqueConstants, log_adapter


@app.command("calibrate", cls=Command)
def calibrate_command(
    robot: Annotated[str, typer.Option(help="Robot name (see `faultgen robots`), robot folder or MJCF file of the nominal model.")],
    measured: Annotated[Path, typer.Option(
        help="Measured torque log: CSV (.csv, .csv.gz) or HDF5 with columns t, q1..q6 (rad), tau1..tau6 (N m, arm "
             "side) and optionally qd1..qd6 (rad/s); at least 2 s at >= 100 Hz; or a log in another layout "
             "with --format.")],
    out: Annotated[Path, typer.Option("--out", "-o", help="Output folder (created): model/, report.json, calibration.png.")],
    max_steps: Annotated[int, typer.Option(help="Most effects to add.", min=0, max=20)] = 6,
    sysid: Annotated[bool, typer.Option(
        help="Refine a Stribeck hump's level, velocity and exponent with mujoco.sysid when the mujoco[sysid] "
             "extra is installed (kept when it lowers the held-out gap).")] = True,
    fit_friction_all: Annotated[bool, typer.Option(
        "--fit-friction-all",
        help="After the search, fit the dry (Coulomb) and viscous friction levels of every moving axis, always (not "
             "by model selection): each axis's friction is the unit's own (what `faultgen monitor` reads wear in).")] = False,
    delay: Annotated[str | None, typer.Option(
        metavar="auto|SECONDS",
        help="Correct the delay of the torque columns behind the angles: auto (by the estimate the check reports) or "
             "a number of seconds (positive: the torque was logged late). Default: reported only.")] = None,
    effects: Annotated[list[str] | None, typer.Option(
        "--effects", metavar="MODULE:CLASS",
        help="Your own effect class, fitted beside the library's: module:Class (the module on PYTHONPATH) or "
             "path/to/file.py:Class, a subclass of faultgen.effects.Effect (example: "
             "docs/examples/arm_ripple.py:ArmRipple). Repeat for several.")] = None,
    log_format: LogFormat = "measured",
    torque_constants: TorqueConstants = None,
    overwrite: Overwrite = False,
) -> None:
    """Find what the model misses in a measured torque log, add it, and show the gap shrink.

    The nominal model predicts the measured torque along the measured motion; every effect of the library is
    fitted to the residual on the first 70 % of the record and judged on the last 30 % (held out); the effect
    that cuts the held-out error most, on the axes where the cut is significant, is written into the model,
    and the search repeats until nothing significant is left. When the log cannot tell two effects apart
    (held-out AIC within 2), the simpler is fitted and the summary, report.json and the figure say so, with
    the motion that would separate them. A log the robot cannot explain (another robot, motor-side torque, a
    column in another unit or sign) is refused before anything is written, naming what to check.

    Effects (faultgen.effects; docs/calibration.md): torque_offset, coulomb, viscous, stribeck,
    load_dependent_friction, temperature, payload, cogging, backlash; each parameter with its standard error.

    Before the search, the delay of the torque channels behind the motion is estimated with a 95 % interval
    and reported (--delay corrects it). After every step, the residual of each axis is tested on the held-out
    part for whiteness (Ljung-Box) and for independence from the motion and the torque (cross-correlation over
    lags -25..25), Holm-adjusted at 1 %: an axis that fails, above its noise floor, is printed as LEFT
    UNEXPLAINED with the variable and lag its residual follows, and with what its remainder follows in words
    (a sparse regression on generic terms: periodic in the arm angle, the torque lagging the motion, a gain,
    the speed squared, cross-axis terms), with each term's share of the remaining gap. A library effect is not
    written on an axis where a generic term explains more and the axis still fails the tests (no forced fit).

    Writes into OUT: model/<robot>_calibrated.xml (run it with `faultgen simulate --model ...`) and
    model/parameters.json, report.json (gap before/after per axis, each effect with its axes, parameters and
    evidence) and calibration.png (measured vs model torque and the residual before and after, per axis).
    Method and accuracy: docs/calibration.md.

    A log in another layout: --format ur-rtde (--torque-constants for the measured current) or voraus, read
    as `faultgen logs import` and `faultgen monitor` read it (docs/dataset.md).

    Example (on a log with a hidden effect, `faultgen hidden-log`):

    \b
      faultgen hidden-log puma560 --effect coulomb --cycles 2 -o log.csv
      faultgen calibrate --robot puma560 --measured log.csv --out calib
      faultgen calibrate --robot puma560 --measured log.csv --out calib2 --delay auto
    """
    from faultgen import calibrate
    from faultgen.calibrate import user_effects
    from faultgen.model import robots

    shift = _delay(delay)
    for spec in effects or ():
        user_effects.load(spec)  # a bad --effects is refused before anything is read or written
    check_output_folder(out, overwrite)
    nominal = robots.load(robot)  # once, for the log's reader and the calibration
    adapter = log_adapter(log_format, torque_constants, nominal)
    result = calibrate.calibrate(nominal, measured, out, max_steps=max_steps, progress=True, use_sysid=sysid,
                                 log_format=adapter, friction_every_axis=fit_friction_all, delay=shift,
                                 effects=effects)
    typer.echo(result.summary())
    typer.echo(f"wrote {out / 'report.json'} and {out / 'calibration.png'}")


def _delay(text: str | None) -> str | float | None:
    """--delay: None, "auto" or seconds (ValueError naming the text: exit 2)."""
    if text is None or text == "auto":
        return text
    try:
        seconds = float(text)
    except ValueError:
        raise ValueError(f"--delay {text!r}: expected auto or a delay in seconds, e.g. 0.012") from None
    if not abs(seconds) < 1.0:
        raise ValueError(f"--delay {text!r}: expected a delay of less than 1 s either way, e.g. 0.012")
    return seconds


@app.command("excitation", cls=Command)
def excitation_command(
    robot: Annotated[str, typer.Argument(help="Robot name (see `faultgen robots`) or MJCF file.")],
    out: Annotated[Path, typer.Option("--out", "-o", help="CSV file to write: columns t, q1..qN (s, rad).")],
    period: Annotated[float, typer.Option(help="Fundamental period of the Fourier series, s.", min=0.1, max=600.0)] = 10.0,
    harmonics: Annotated[int, typer.Option(help="Harmonics of the Fourier series.", min=1, max=50)] = 5,
    iterations: Annotated[int, typer.Option(help="Most optimiser iterations.", min=0, max=1000)] = 8,
    seed: Annotated[int, typer.Option(help="Seed of the optimiser's random starts.", min=0, max=MAX_SEED)] = 0,
    starts: Annotated[int, typer.Option(help="Random starts scored; the best is optimised.", min=1, max=1000)] = 8,
    overwrite: Overwrite = False,
) -> None:
    """Design a periodic excitation on which a torque log tells the calibration's effects apart.

    A finite Fourier series per axis (Swevers et al. 1997), at rest at its start and end, within
    the joint ranges and the planning velocity and acceleration limits of the robot's tasks.toml,
    optimised for a small condition number of the effects' stacked regressors. Written at the
    planning period (4 ms), one period, as a program for `--task FILE.csv`. Method:
    docs/calibration.md.

    Example:

    \b
      faultgen excitation puma560 -o excitation.csv
    """
    from faultgen.calibrate import excitation
    from faultgen.cli.base import check_outputs
    from faultgen.model import robots

    check_outputs([out], overwrite)
    designed = excitation.design(robots.load(robot), harmonics=harmonics, period=period, seed=seed,
                                 iterations=iterations, starts=starts)
    designed.write(out)
    typer.echo(f"wrote {out}: {designed.period:g} s period, {len(designed.a)} harmonics, regressor condition "
               f"number {designed.condition_number:.1f} (first random start {designed.start_condition_number:.1f}, "
               f"best of the random starts {designed.best_start_condition_number:.1f})")


@app.command("hidden-log", cls=Command)
def hidden_log_command(
    robot: Annotated[str, typer.Argument(help="Robot name (see `faultgen robots`), robot folder or MJCF file.")],
    out: Annotated[Path, typer.Option("--out", "-o", help="CSV log to write (the measured-log format).")],
    effect: Annotated[str, typer.Option(
        help="The hidden effect, one of `faultgen calibrate --help`'s effects (coulomb, payload, cogging, "
             "backlash, ...), or none.")],
    seed: Annotated[int, typer.Option(help="Seed of the effect's draw (size, axes) and of the noise.", min=0, max=MAX_SEED)] = 0,
    cycles: Annotated[int, typer.Option(help="Cycles of the task in the log, back to back.", min=1, max=100)] = 4,
    task: Annotated[str, typer.Option(
        help="The task the robot runs (a thesis task or a program file).")] = "pick_place",
    overwrite: Overwrite = False,
) -> None:
    """Make a torque log of a robot with a hidden effect, to try `faultgen calibrate` on.

    The effect is drawn at a random size on random axes (faultgen.calibrate.synth, the data of
    docs/calibration.md's accuracy tables), switched on in a copy of the model (written beside
    the log, in OUT-STEM_model/), and the robot runs the task at a 0.1 ms step; the log has the
    measured-log columns t, q1..qN, tau1..tauN with 1 % torque noise. What was hidden is printed.

    Example:

    \b
      faultgen hidden-log puma560 --effect payload --seed 1 -o log.csv
      faultgen calibrate --robot puma560 --measured log.csv --out calib
    """
    import numpy as np

    from faultgen.calibrate import synth
    from faultgen.cli.base import check_outputs
    from faultgen.model import robots

    check_outputs([out], overwrite)
    model = robots.load(robot)
    hidden = synth.draw(model, None if effect == "none" else effect, np.random.default_rng(seed), task=task,
                        cycles=cycles)
    typer.echo(f"{model.name}: hidden {hidden}; simulating {cycles} cycle(s) of {task} at a 0.1 ms step", err=True)
    synth.record(model, hidden, out, task=task, cycles=cycles, seed=seed, progress=True)
    typer.echo(f"wrote {out}: {model.name} {task}, {cycles} cycle(s), hidden {hidden}\n"
               f"calibrate it: faultgen calibrate --robot {robot} --measured {out} --out calib")


@app.command("friction-test", cls=Command)
def friction_test_command(
    log: Annotated[Path, typer.Argument(help="Log of a friction test: t, q1..qN (rad), tau1..tauN (N m, arm side), "
                                             "optionally qd1..qdN and temperature1..N; CSV or HDF5.")],
    robot: Annotated[str, typer.Option(help="Robot name (see `faultgen robots`), robot folder or MJCF file.")],
    out: Annotated[Path, typer.Option("--out", "-o", help="Output folder (created): friction_curve.csv, "
                                                           "friction_fit.csv, friction_axis<k>.png.")],
    reference: Annotated[Path | None, typer.Option(
        help="A reference test (an earlier output folder of this command, or its log): its curve in each figure.")] = None,
    overwrite: Overwrite = False,
) -> None:
    """Read a friction test: each axis's friction against speed, by direction differencing, fitted.

    The constant-speed segments are found without being told where they are (per axis at least 3
    speeds each way, each steady at least 0.5 s with only that axis moving: faultgen's test,
    `faultgen tasks friction-test`, or a maker's own routine). At each speed the friction is half the
    difference of the two directions' torques at the same angles (gravity and inertia cancel: the
    read does not rest on the model; where a direction is missing the model's rigid-body torque is
    subtracted instead, and the output says so). Each axis's curve F = Fc + Fs exp(-(v/vs)^2) + Fv v
    is fitted with 95 % intervals, at the logged temperature. Torques arm side (motor side: over the
    gear ratio). Method: docs/friction-test.md.

    Example:

    \b
      faultgen tasks friction-test puma560 --axes 2 --speeds 4 -o short.toml
      faultgen hidden-log puma560 --effect coulomb --task short.toml --cycles 1 -o log.csv
      faultgen friction-test log.csv --robot puma560 -o friction
      faultgen friction-test log.csv --robot puma560 -o friction-again --reference friction
    """
    from faultgen.calibrate import friction_report
    from faultgen.logs import measured
    from faultgen.model import robots

    check_output_folder(out, overwrite)
    loaded = robots.load(robot)
    reading = friction_report.read(measured.read(log, loaded, accelerations=False), loaded)
    ref = friction_report.reference_fits(reference, loaded) if reference is not None else None
    written = friction_report.write(reading, out, ref)
    for note in reading.notes:
        typer.echo(f"note: {note}")
    for _, row in reading.fits.iterrows():
        temperature = "no temperature logged" if row["temperature_degC"] != row["temperature_degC"] else (
            f"{row['temperature_degC']:.1f} degC")
        typer.echo(f"axis {int(row['axis'])} ({int(row['speeds'])} speeds, {row['model']}, "
                   f"{temperature}): dry {row['coulomb_Nm']:.4g} N m "
                   f"[{row['coulomb_Nm_low']:.4g}, {row['coulomb_Nm_high']:.4g}], viscous {row['viscous_Nms_rad']:.4g} "
                   f"N m s/rad [{row['viscous_Nms_rad_low']:.4g}, {row['viscous_Nms_rad_high']:.4g}] (95 %, arm side)")
    typer.echo(f"wrote {len(written.files)} files into {out}")
