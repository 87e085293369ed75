"""What a program file holds, as data: the keys of its top table, its ``[limits]``, ``[tool]`` and
each segment type, the bounds of its limits, the processes it may name, its most segments; and its
text written from the table it reads as (:func:`dumps`: what a program generator calls, also known
as ``programs.dumps``). :mod:`faultgen.operation.programs` reads a program by these tables and names
them too."""

from __future__ import annotations

from faultgen.operation.tables import Table, toml_value
from faultgen.operation.tasks import PROCESSES, ProgramError

#: Keys of each segment type (besides ``type`` and ``label``).
SEGMENT_KEYS = {
    "move": ("to", "pose", "standoff", "velocity_scale", "acceleration_scale"),
    "linear": ("to", "speed", "ramp_time"),
    "circular": ("via", "to", "speed", "ramp_time"),
    "seam": ("vertices", "corner_radius", "speed", "ramp_time", "weave_amplitude", "weave_frequency"),
    "dwell": ("time",),
    "grip": ("mass", "size", "com", "inertia"),
    "release": (),
}


#: What a program's ``process`` key may say (a label the user reads; the motion is the segments'):
#: the thesis's three processes (ch. 6.3.1), the robot applications of industry, or "program", the
#: default. A closed list, so that a typo or a stray value is refused, naming the key.
PROGRAM_PROCESSES = (*PROCESSES.values(), "program", "handling", "pick and place", "palletizing", "packaging",
                     "machine tending", "assembly", "spot welding", "arc welding", "laser welding", "cutting",
                     "painting", "dispensing", "gluing", "grinding", "polishing", "deburring", "inspection",
                     "friction test")


#: Most ``[[segment]]`` tables a program may have, counted before any is checked, planned or sampled
#: (a program of 10^4 moves was refused by the cycle's duration bound only after 46 s and 1.4 GB,
#: its moves planned one by one). The thesis tasks have 5 to 20; the largest program the project
#: writes a few hundred.
MAX_SEGMENTS = 1000


TOP_KEYS = ("name", "robot", "process", "description", "start", "velocity_scale", "acceleration_scale", "limits",
            "tool", "segment")


LIMIT_KEYS = ("velocity", "acceleration", "jerk")


#: The bounds of each of a robot's [limits], deg/s, deg/s^2, deg/s^3: around those a robot
#: description may give (faultgen.model.limits: speeds of 1e-3 .. 100 rad/s, 0.057 .. 5730 deg/s)
#: and those faultgen.operation.taskgen derives from them; the thesis robots' are 95-210, 250-700
#: and 1250-6000.
LIMIT_BOUNDS = {"velocity": (0.05, 6000.0, "deg/s"), "acceleration": (0.05, 1e6, "deg/s^2"),
                "jerk": (0.05, 1e8, "deg/s^3")}


TOOL_KEYS = ("z", "x", "offset")


#: Keys of a built-in task's table in ``tasks.toml``: a program's, less those its folder gives (its
#: name is the table's, its robot the folder's, its limits the file's ``[limits]``).
BUILTIN_KEYS = tuple(key for key in TOP_KEYS if key not in ("name", "robot", "limits"))


#: Comments :func:`dumps` writes beside the values it knows.
_UNITS = {"start": "deg", "velocity": "deg/s", "acceleration": "deg/s^2", "jerk": "deg/s^3"}


def dumps(program: dict, header: str = "", where: str = "program") -> str:
    """A program file's text from the table a program file reads as (``tomllib.loads`` of it): what
    a program generator (a robot builder writing thesis-like tasks) calls. Numbers are written as
    Python writes them, so they read back to the same floats.

    Parameters
    ----------
    program : dict
        ``name``, ``start`` (deg) and ``segment`` (a list of tables), optionally ``robot``,
        ``process``, ``description``, ``velocity_scale``, ``acceleration_scale``, ``limits``
        (``velocity``, ``acceleration``, ``jerk`` in deg/s, deg/s^2, deg/s^3) and ``tool`` (``z``,
        ``x``, ``offset``); see the module docstring.
    header : str
        A comment for the file's top (one line or several).
    where : str
        Names the table in an error message.

    Raises
    ------
    ProgramError
        For a key :func:`parse` would not read (checked without a robot; :func:`parse` checks the
        values).
    """
    Table(where, "", program, TOP_KEYS)
    for key in ("limits", "tool"):
        Table(where, f"[{key}] ", program.get(key, {}), LIMIT_KEYS if key == "limits" else TOOL_KEYS)
    for k, table in enumerate(program.get("segment", [])):
        kind = table.get("type") if isinstance(table, dict) else None
        if kind not in SEGMENT_KEYS:
            raise ProgramError(f"{where}: segment {k + 1}: type = {kind!r}; expected one of {', '.join(SEGMENT_KEYS)}")
        Table(where, f"segment {k + 1} ({kind}) ", table, ("type", "label", *SEGMENT_KEYS[kind]))
    lines = [f"# {line}" for line in header.splitlines()]
    if header:
        lines.append("# Units: joint angles in deg, positions in m (world frame), times in s, speeds in m/s.")
    for key in TOP_KEYS:
        if key in program and key not in ("limits", "tool", "segment"):
            unit = f"  # {_UNITS[key]}" if key in _UNITS else ""
            lines.append(f"{key} = {toml_value(program[key])}{unit}")
    for key, title in (("limits", "joint limits for planning, axes 1..N"),
                       ("tool", "flange orientation at Cartesian targets (world frame); offset: tool centre point, "
                                "m, flange frame")):
        if key in program:
            lines += ["", f"[{key}]  # {title}"]
            for name, value in program[key].items():
                unit = f"  # {_UNITS[name]}" if key == "limits" and name in _UNITS else ""
                lines.append(f"{name} = {toml_value(value)}{unit}")
    for segment in program.get("segment", []):
        lines += ["", "[[segment]]"] + [f"{key} = {toml_value(value)}" for key, value in segment.items()]
    return "\n".join(lines) + "\n"
