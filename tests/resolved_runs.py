"""A run's configuration built as every command builds it, for tests: :func:`run_config` is
``resolve(RunSpec(...)).config`` (:func:`faultgen.simulation.resolve.resolve`, the one place that
loads the robot and plans the task; a :class:`~faultgen.simulation.config.RunConfig` constructed
directly loads nothing)."""

from faultgen.model import robots
from faultgen.simulation.resolve import resolve
from faultgen.simulation.spec import RunSpec


def run_config(*args, resolved: robots.Robot | None = None, **fields):
    """The resolved configuration of ``RunSpec(*args, **fields)`` (the fields of
    :class:`~faultgen.simulation.config.RunConfig`, the same order: robot, task, friction, ...). A
    robot given as a :class:`~faultgen.model.robot.Robot` (first argument or ``robot=``) is taken as
    ``resolved`` and named by :func:`faultgen.model.robots.source_of`, as a RunConfig given a Robot
    does. Raises what :func:`resolve` raises."""
    args = list(args)
    given = args[0] if args else fields.get("robot")
    if isinstance(given, robots.Robot):
        resolved = given
        if args:
            args[0] = robots.source_of(given)
        else:
            fields["robot"] = robots.source_of(given)
    return resolve(RunSpec(*args, **fields), resolved=resolved).config
