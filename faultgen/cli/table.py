"""The command table of ``faultgen``: the module that defines each command and the command's line
in ``faultgen --help``, so that a command line imports the module of the command it runs and no
other (``faultgen --help`` and ``faultgen --version`` import none; issue 87).

:class:`LazyTyper` is the app: run (``faultgen ...``, ``python -m faultgen.cli``, ``app(args)``),
it builds a :class:`LazyGroup` from what is imported so far, whose commands import their module
when first looked up. Read as a typer app (``app.registered_commands``, ``typer.main.get_command(app)``,
typer's ``CliRunner``), it imports every command module first: the same app, every command in it,
as when ``faultgen.cli`` imported them all. tests/test_cli_lazy.py checks the table against the
commands and that the lazy help is the same text.
"""

from __future__ import annotations

import importlib
from collections.abc import Iterator, MutableMapping

import click
import typer

from faultgen.cli.base import Group

#: Command name -> (its module in ``faultgen.cli``, its line in ``faultgen --help``: the first
#: sentence of its help), in the order ``faultgen --help`` lists them (the order the modules
#: register them in: the commands, then the groups).
COMMANDS: dict[str, tuple[str, str]] = {
    "robots": ("robots", "List the robot models, show one model's nominal parameters, or add a robot from an arm "
               "file."),
    "simulate": ("runs", "Simulate one run: a robot repeating a task while chosen axes wear, into an HDF5 file."),
    "sweep": ("runs", "Simulate a grid of runs (robot x task x worn axis x wear x schedule x seed) into one dataset."),
    "fleet": ("runs", "Simulate a fleet like the thesis's 26 robots (chapter 5) as daily remote-monitoring records."),
    "calibrate": ("calibration", "Find what the model misses in a measured torque log, add it, and show the gap "
                  "shrink."),
    "excitation": ("calibration", "Design a periodic excitation on which a torque log tells the calibration's "
                   "effects apart."),
    "hidden-log": ("calibration", "Make a torque log of a robot with a hidden effect, to try `faultgen calibrate` "
                   "on."),
    "friction-test": ("calibration", "Read a friction test: each axis's friction against speed, by direction "
                      "differencing, fitted."),
    "info": ("data", "Summarise a dataset: runs, robots, tasks, worn axes, cycles, provenance."),
    "validate": ("data", "Check a dataset against the schema (docs/dataset.md); exit 1 with the reasons if it fails."),
    "export": ("data", "Write every per-cycle feature of a dataset as one tidy table (CSV or Parquet)."),
    "plot": ("data", "Draw how each axis's mean |motor torque| follows its true wear, as a PNG."),
    "monitor": ("monitoring", "Monitor your own robots: learn each unit's normal operation from its first logs "
                "against its twin, score every later log, and name the worn axis."),
    "report": ("reporting", "Write the fleet report page OUT/report.html again from a monitor's output folder: one "
               "file that opens in a browser offline (plotly.js inside it, no server, nothing fetched)."),
    "bench-isolators": ("analysis", "Accuracy of every registered isolator (`faultgen bench baselines`: transfer "
                        "entropy, cross-correlation, Granger, ...) at finding the worn axis, per task and wear level: "
                        "CSV, Markdown (thesis Table 6.2 layout) and a PNG heatmap."),
    "detect": ("analysis", "PCA onset detection (Q statistic) and location per worn run, thesis Table 3.5 layout, "
               "with the false-alarm rate on healthy runs; summary per task and axis."),
    "training-source": ("analysis", "The training-source study of thesis chapter 4 (Table 4.1) on a fleet."),
    "classify": ("analysis", "AUC of LR, SVM, RF and stacking per preprocessing combination, thesis Table 5.2 "
                 "layout."),
    "reproduce": ("reproduce", "Regenerate every table of docs/reproduction.md (thesis Tables 3.5, 4.1-4.4, 5.2, "
                  "6.1, 6.2 and Fig."),
    "tasks": ("programs", "A robot's programs: the thesis tasks (pick_place, spot_weld, arc_weld) and program "
              "files."),
    "logs": ("logs", "Your robots' measured logs: import a fleet's folder of logs (LOGS/<unit>/<stamp>.csv) into a "
             "dataset that every command reads (docs/dataset.md, \"A fleet's logs\")."),
    "bench": ("bench", "The benchmark: frozen tracks of seeded train and test files (test labels apart), and one "
              "score for any detector or isolator with bootstrap intervals over test units (docs/bench.md; results "
              "in docs/leaderboard.md)."),
}

#: The command modules, in the order they register their commands.
MODULES = tuple(dict.fromkeys(module for module, _ in COMMANDS.values()))


def import_module(name: str):
    """``faultgen.cli.<name>``, imported (its commands registered on the app)."""
    return importlib.import_module(f"faultgen.cli.{name}")


def _loaded_first(name: str) -> property:
    """A registration list of the app (stored as ``name``): read, every command module is imported
    first; set, stored as it is."""

    def read(self):
        self._load_all()
        return getattr(self, name)

    def store(self, value) -> None:
        setattr(self, name, value)

    return property(read, store)


class LazyTyper(typer.Typer):
    """The ``faultgen`` typer app. Run, it imports only the module of the command it runs; read as
    an app (its registered commands and groups), it imports every command module first."""

    _lazy = False  # while it runs: its registrations are what is imported so far
    _loaded = False

    def __init__(self, **kwargs) -> None:
        # the group typer builds of it knows it (a subclass per app): it builds its commands from it
        group = kwargs.pop("cls", None) or LazyGroup
        super().__init__(cls=type(group.__name__, (group,), {"typer_app": self}), **kwargs)

    registered_commands = _loaded_first("_commands")
    registered_groups = _loaded_first("_groups")

    def _load_all(self) -> None:
        if self._lazy or self._loaded:
            return
        self._loaded = True  # before the imports: each module registers on this app
        try:
            for module in MODULES:
                import_module(module)
        except BaseException:
            self._loaded = False
            raise

    def __call__(self, *args, **kwargs):
        lazy, self._lazy = self._lazy, True
        try:
            return super().__call__(*args, **kwargs)
        finally:
            self._lazy = lazy

    def click_command(self, name: str) -> click.Command | None:
        """The click command (or group) ``name`` as typer builds it, its module imported first
        (every command module for a name not in :data:`COMMANDS`: a command added without its line
        in the table still runs); None for a name no module registers."""
        for module in [COMMANDS[name][0]] if name in COMMANDS else MODULES:
            import_module(module)
        for info in self._commands:
            if (info.name or typer.main.get_command_name(info.callback.__name__)) == name:
                return typer.main.get_command_from_info(info, pretty_exceptions_short=self.pretty_exceptions_short,
                                                        rich_markup_mode=self.rich_markup_mode)
        for info in self._groups:
            if info.name == name:
                return typer.main.get_group_from_info(info, pretty_exceptions_short=self.pretty_exceptions_short,
                                                      rich_markup_mode=self.rich_markup_mode,
                                                      suggest_commands=self.suggest_commands)
        if name in COMMANDS:
            raise LookupError(f"faultgen.cli.{COMMANDS[name][0]} registers no command {name!r} (faultgen/cli/table.py)")
        return None


class _Commands(MutableMapping):
    """A group's commands by name: every name of :data:`COMMANDS` and those added, a command built
    (its module imported) when first read."""

    def __init__(self, built: MutableMapping[str, click.Command], app: LazyTyper) -> None:
        self.built = dict(built)
        self.app = app

    def __getitem__(self, name: str) -> click.Command:
        if name not in self.built:
            command = self.app.click_command(name)
            if command is None:
                raise KeyError(name)
            self.built[name] = command
        return self.built[name]

    def __setitem__(self, name: str, command: click.Command) -> None:
        self.built[name] = command

    def __delitem__(self, name: str) -> None:
        del self.built[name]

    def __iter__(self) -> Iterator[str]:
        return iter(dict.fromkeys([*COMMANDS, *self.built]))

    def __len__(self) -> int:
        return len(dict.fromkeys([*COMMANDS, *self.built]))


class LazyGroup(Group):
    """The ``faultgen`` group: its commands built when first looked up (:class:`_Commands`), and
    ``faultgen --help`` listing each command not built yet by its line in :data:`COMMANDS`."""

    #: The app it is built from (set by :class:`LazyTyper`).
    typer_app: LazyTyper

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self.commands = _Commands(self.commands, self.typer_app)

    def list_commands(self, ctx: click.Context) -> list[str]:
        return list(self.commands)

    def format_commands(self, ctx: click.Context, formatter: click.HelpFormatter) -> None:
        """As typer's (each command's name and first sentence, hidden ones left out), from the
        table for a command whose module is not imported."""
        names = self.list_commands(ctx)
        limit = formatter.width - 6 - max(map(len, names), default=0)
        rows = []
        for name in names:
            built = self.commands.built.get(name)
            if built is None:
                rows.append((name, COMMANDS[name][1]))
            elif not built.hidden:
                rows.append((name, built.get_short_help_str(limit)))
        if rows:
            with formatter.section("Commands"):
                formatter.write_dl(rows)
