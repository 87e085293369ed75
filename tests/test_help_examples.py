"""Every example in every command's ``--help`` runs (issue 51, item 3), and what it writes is in
``.gitignore`` (run in the checkout, it would leave ``git status`` clean).

The examples are read from the help text itself, one test per help page, each page in a folder
of its own holding what the docs tell a user to make before it (``quick.h5``, ``j2.h5``,
``fleet.h5``, a program, a URDF, ``mine.py``), each made once by its documented command (an
example that is that same command gets the file made so: same seed, the same file). The data is
kept small (:data:`SMALL`, appended: click takes an option's last value): a ``simulate`` or
``sweep`` records fewer cycles, a sweep that does not choose them one task and two axes, a
``fleet`` has fewer robots, days and cycles a day; ``classify`` (on its own page the logistic
regression alone), ``training-source``, ``excitation`` and ``hidden-log`` do less work; a ``sweep``,
``fleet`` or ``classify`` that does not choose ``--jobs`` runs in the test's process. The rest of
each command line is the example's own. A ``--scheduler`` address is replaced by the address of a local Dask cluster.
A ``fleet`` line's command runs through conftest.py's ``shared_fleet_command``: once per session for the
pages and test files that run the same one. ``sweep --preset j2 --jobs 2 -o j2.h5`` gets the j2.h5 that its
documented command made (a sweep's bits do not depend on ``--jobs``).
"""

from __future__ import annotations

import contextlib
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import rtbdata
from conftest import shared_folder
from filelock import FileLock
from typer.main import get_command
from typer.testing import CliRunner

from faultgen.cli import app

ROOT = Path(__file__).resolve().parents[1]
runner = CliRunner()

#: Appended to the data-making and the slowest commands of the examples: small data, the
#: example's own options otherwise. A sweep records 10 cycles, as the quick preset does.
SMALL = {"simulate": ["--cycles", "2", "--record", "1-2"], "sweep": ["--cycles", "10", "--record", "1-10"],
         "fleet": ["--robots", "2", "--days", "6", "--cycles-per-day", "1"], "hidden-log": ["--cycles", "1"],
         # the optimiser's one iteration on the same design (puma560, 5 harmonics, 2 starts): 5 s of CPU;
         # tests/test_calibrate_selection.py checks it (limits, at rest, conditioned better than its start)
         "excitation": ["--iterations", "0", "--starts", "2"],
         # one held-out pair of a failing and a healthy robot, not every pair (the slowest examples:
         # every row's classifiers and its 19 label exchanges still fit and print, on one pair)
         "classify": ["--pairs", "1"],
         # the thesis's window (40 + 15 + 5 days) on the small fleet's 16
         "training-source": ["--training-days", "8", "--test-days", "4", "--gap-days", "2"]}
#: The fleets the docs analyse: enough robots and days for classify's leave-pair-out and horizon (6
#: robots, 3 failing: with a pair held out, the fewest that leave 5 failed samples to train on; 5 leave
#: 3, and classify refuses; horizon 3 needs 14 days).
ANALYSED_FLEETS = {"fleet.h5": ["--robots", "6", "--days", "16", "--cycles-per-day", "1"],
                   "fleet8.h5": ["--robots", "4", "--days", "12", "--cycles-per-day", "1"]}


def pages() -> dict[str, list[str]]:
    """Command path -> the example lines of its ``--help``."""
    out = {}
    built = get_command(app)

    def walk(command, path):
        if hasattr(command, "commands"):
            for name, sub in command.commands.items():
                walk(sub, [*path, name])
        if path:
            text = runner.invoke(app, [*path, "--help"], terminal_width=300).output
            lines = [line.strip() for line in text.splitlines() if line.strip().startswith("faultgen ")]
            if lines:
                out[" ".join(path)] = lines

    walk(built, [])  # the runner's command is built once per session (tests/conftest.py, _built_once)
    return out


PAGES = pages()


def small(argv: list[str], page: str, scheduler: str | None) -> list[str]:
    """``argv`` (after ``faultgen``) with the small-data options appended, the scheduler replaced;
    a sweep that does not choose its tasks or axes runs pick and place, without wear and on axis 2."""
    extra = list(SMALL.get(argv[0], []))
    if argv[:2] == ["bench", "make"]:  # the test-sized version of the track (seconds)
        extra = ["--size", "small"]
    if argv[0] == "fleet" and argv[argv.index("-o") + 1] in ANALYSED_FLEETS:
        extra = ANALYSED_FLEETS[argv[argv.index("-o") + 1]]
    if argv[0] == "sweep":
        extra += [] if "--task" in argv else ["--task", "pick_place"]
        extra += [] if "--axis" in argv else ["--axis", "0", "--axis", "2"]
    if argv[0] == "classify" and page == "classify" and "--classifier" not in argv:
        # classify's own page: its protocols, rows (--full's nineteen) and outputs on the logistic
        # regression alone (its four lines: 33 s of CPU with the four classifiers, 21 s with lr);
        # the fleet page's `classify fleet.h5` runs all four through the command, and
        # tests/test_classify.py fits every classifier on every row of Table 5.2
        extra += ["--classifier", "lr"]
    if argv[0] in ("sweep", "fleet", "classify") and not {"--jobs", "--scheduler"} & set(argv):
        # in this test process (2 to 5 s of CPU less than the default's worker processes, on a machine
        # whose cores pytest-xdist's workers fill); an example that chooses --jobs keeps its own
        extra += ["--jobs", "1"]
    argv = [scheduler if a.startswith("tcp://") and scheduler else a for a in argv]
    return [*argv, *extra]


def run_line(line: str, page: str, scheduler: str | None, made_files: dict[str, Path], bench=None,
             fleets=None) -> None:
    """One example line: commands joined by ``&&``, an optional ``> FILE``, ``#`` comments.
    ``bench``: conftest.py's ``shared_bench``, whose folders are made by the command a ``bench make``
    line becomes here when it gives no other option (``bench make TRACK --size small -o OUT``).
    ``fleets``: conftest.py's ``shared_fleet_command``, which runs a ``fleet`` line's command (its
    options, the small-data ones last) once per session for the pages and test files that run it."""
    for part in line.split("&&"):
        words = shlex.split(part, comments=True)
        target = None
        if ">" in words:
            words, target = words[:words.index(">")], words[words.index(">") + 1]
        assert words[0] == "faultgen", line
        outputs = [words[i + 1] for i, w in enumerate(words[:-1]) if w in ("-o", "--out")]
        for produced in outputs:
            path = Path(produced)  # the example makes it: a file the docs' earlier step made is remade here
            if path.is_file():
                path.unlink()
        same = [name for name in outputs if name in made_files and without_jobs(shlex.split(MADE[name])) == without_jobs(words)]
        if same:  # the documented command a file of MADE was made by: same seed, the same file bit for bit
            # (--jobs aside: `sweep --preset j2 --jobs 2` makes j2.h5's bits on any number of jobs, which
            # tests/test_sweep.py's test_parallel_jobs_give_the_same_dataset checks on 2 jobs against 1;
            # --no-progress aside: it silences the progress on stderr, not what is written)
            (shutil.copytree if made_files[same[0]].is_dir() else shutil.copy)(made_files[same[0]], same[0])
            continue
        argv = small(words[1:], page, scheduler)
        options = dict(zip(argv[3::2], argv[4::2], strict=True)) if argv[:2] == ["bench", "make"] and len(argv) % 2 else {}
        if bench is not None and set(options) - {"--jobs"} == {"--size", "-o"} and options["--size"] == "small":
            # the command conftest.py's shared_bench ran (tests/bench_plugins.py's make_small, the same
            # options and --no-progress; --jobs aside: the thesis track is made there on the two jobs of
            # its example, and on any number of jobs a make gives the frozen bits or fails): its folder,
            # without the score-NAME outputs other tests added
            shutil.copytree(bench(argv[2]), options["-o"], ignore=shutil.ignore_patterns("score-*", ".*"))
            continue
        fleet = fleet_options(argv) if fleets is not None else None
        if fleet is not None:
            shutil.copy(fleets(*[word for option in fleet.items() for word in option])[0], outputs[0])
            continue
        if words[1:3] == ["bench", "make"]:  # as a command: it starts itself again in the track's numeric profile
            done = subprocess.run([sys.executable, "-m", "faultgen.cli", *argv],
                                  check=False, capture_output=True, text=True, timeout=600)
            assert done.returncode == 0, f"{line}\n{done.stdout}{done.stderr}"
            output = done.stdout
        else:
            result = runner.invoke(app, argv)
            assert result.exit_code == 0, f"{line}\n{result.output}"
            output = result.output
        if target:
            Path(target).write_text(output)


def without_jobs(words: list[str]) -> list[str]:
    """``words`` without ``--no-progress``, and a ``sweep`` command's without its ``--jobs N`` (other
    commands' ``--jobs`` as it is)."""
    words = [word for word in words if word != "--no-progress"]
    if "sweep" not in words[:2] or "--jobs" not in words:
        return words
    at = words.index("--jobs")
    return words[:at] + words[at + 2:]


def fleet_options(argv: list[str]) -> dict[str, str] | None:
    """The options of a ``fleet`` command line ``argv`` (after :func:`small`) but ``-o`` and ``--jobs 1``,
    one value each, as click reads them (an option given again by the small-data options: its last
    value); None for a line that conftest.py's ``shared_fleet_command`` does not run so (a scheduler,
    another ``--jobs``, a flag or an option given twice by the example itself)."""
    names = argv[1::2]
    if argv[0] != "fleet" or "--scheduler" in argv or not len(argv) % 2 or not all(n.startswith("-") for n in names):
        return None
    if {name for name in names if names.count(name) > 1} - {"--robots", "--days", "--cycles-per-day"}:
        return None
    options = dict(zip(names, argv[2::2], strict=True))
    if options.pop("--jobs", None) != "1" or "-o" not in options:
        return None
    options.pop("-o")
    return options


# -- what the docs tell a user to make before the examples ------------------------------------------

def mine_py(folder: Path) -> None:
    """docs/analysis.md's mine.py, as written there."""
    text = (ROOT / "docs/analysis.md").read_text()
    block = re.search(r"```python\n(# mine.py, beside the dataset\n.*?)```", text, re.S).group(1)
    (folder / "mine.py").write_text(block)


def logs_folder(folder: Path) -> None:
    """A fleet's folder of logs in the documented layout (tests/fleetlog_folder.py): 3 units x 40
    days of the IRB 6700's axes, axis 2 of u1 wearing from day 11, written in events.csv."""
    import fleetlog_folder

    from faultgen.model import robots

    fleetlog_folder.write_fleet(folder / "LOGS", robots.load("irb6700"), units=3, days=40, worn={0: (2, 10, 2.0)})
    (folder / "LOGS/events.csv").write_text("unit,stamp,event,axis\nu1,2026-03-11,onset,2\n")


#: file -> the documented command that makes it (run with the small-data options) or a maker.
MADE = {
    "quick.h5": "faultgen sweep --preset quick -o quick.h5",
    "j2.h5": "faultgen sweep --preset j2 -o j2.h5",
    "fleet.h5": "faultgen fleet -o fleet.h5",
    "my_program.toml": "faultgen tasks export irb6700 arc_weld -o my_program.toml",
    "kr210l150.urdf": lambda folder: shutil.copy(
        Path(rtbdata.__file__).parent / "xacro/kuka_description/kuka_kr210/urdf/kr210l150.urdf", folder),
    # a ROS package folder as a vendor ships it (rtb-data's copy): the xacro, its macros, the meshes
    "kuka_kr120": lambda folder: shutil.copytree(
        Path(rtbdata.__file__).parent / "xacro/kuka_description/kuka_kr120", folder / "kuka_kr120"),
    "ur5_dh.toml": lambda folder: shutil.copy(ROOT / "docs/examples/ur5_dh.toml", folder),
    # docs/robots.md: "--drivetrain gives some or all drivetrain numbers (tables [axis.1] .. [axis.N])"
    "my_drives.toml": lambda folder: (folder / "my_drives.toml").write_text("[axis.1]\ngear_ratio = 100.0\n"),
    "mine.py": mine_py,
    # docs/dataset.md's layout, "A fleet's logs": three units' daily logs, an onset on one in events.csv
    "LOGS": logs_folder,
    # the same command on two pages each (logs and logs import; monitor and report): made once, from LOGS
    "fleet-logs.h5": "faultgen logs import LOGS --robot irb6700 -o fleet-logs.h5",
    "monitor-own": "faultgen monitor LOGS --robot irb6700 -o monitor-own --protocol own",
}


@pytest.fixture(scope="session")
def made(tmp_path_factory, worker_id, shared_fleet_command):
    """``made(name)``: the path of a file of :data:`MADE`, made once per session; a fleet by
    conftest.py's ``shared_fleet_command`` (tests/test_training_source.py reads the same fleet.h5)."""
    folder = shared_folder(tmp_path_factory, worker_id, "help-examples-made")

    def make(name: str) -> Path:
        maker = MADE[name]
        for source in [] if callable(maker) else [w for w in shlex.split(maker) if w in MADE and w != name]:
            make(source)  # what the command reads (LOGS), made first in the same folder
        with FileLock(folder / f"{name}.lock"):
            if not (folder / name).exists():
                fleet = None if callable(maker) else fleet_options(small(shlex.split(maker)[1:], "", None))
                if callable(maker):
                    maker(folder)
                elif fleet is not None:
                    shutil.copy(shared_fleet_command(*[word for option in fleet.items() for word in option])[0],
                                folder / name)
                else:
                    with contextlib.chdir(folder):
                        result = runner.invoke(app, small(shlex.split(maker)[1:], "", None))
                    assert result.exit_code == 0, f"{maker}\n{result.output}"
        return folder / name

    return make


def test_every_help_page_has_examples_and_they_are_all_read():
    assert len(PAGES) >= 18 and sum(map(len, PAGES.values())) >= 45
    assert {"simulate", "sweep", "fleet", "detect", "classify", "calibrate", "hidden-log", "tasks export",
            "reproduce"} <= set(PAGES)
    # reproduce's runs take minutes each: prose, not example lines (its example line only prints the plan)
    assert PAGES["reproduce"] == ["faultgen reproduce --plan -o repro"]


@pytest.mark.parametrize("page", sorted(PAGES))
def test_the_examples_of_a_help_page_run(page, made, shared_bench, shared_fleet_command, tmp_path, monkeypatch):
    lines = PAGES[page]
    needed = {word for line in lines for word in re.split(r"[\s:/=]+", line) if word in MADE}
    needed |= {"mine.py"} if any("mine:" in line for line in lines) else set()
    made_files = {name: made(name) for name in sorted(needed)}
    for name in sorted(needed):
        if not any(f"-o {name}" in line for line in lines):  # the page makes it itself
            (shutil.copytree if made_files[name].is_dir() else shutil.copy)(made_files[name], tmp_path / name)
    monkeypatch.chdir(tmp_path)
    scheduler = None
    if any("--scheduler" in line for line in lines):
        from distributed import LocalCluster

        cluster = LocalCluster(n_workers=1, threads_per_worker=1, processes=False, protocol="tcp://",
                               dashboard_address=None)
        scheduler = cluster.scheduler_address
    try:
        for line in lines:
            run_line(line, page, scheduler, made_files, shared_bench, shared_fleet_command)
    finally:
        if scheduler:
            cluster.close()
    # run in the checkout, the examples would leave `git status` clean: all they write is ignored
    # (but your own sources: a robot folder of `robots add`, a program of `tasks export` or `tasks friction-test`)
    sources = {w[w.index("-o") + 1] for line in lines for part in line.split("&&")
               if (w := shlex.split(part, comments=True))[1:3] in (["robots", "add"], ["tasks", "export"], ["tasks", "friction-test"])}
    copied = {name for name in needed if not any(f"-o {name}" in line for line in lines)}
    written = sorted(p.name + ("/" if p.is_dir() else "") for p in tmp_path.iterdir()
                     if p.name not in copied | sources and p.name != "__pycache__")
    if written:
        check = subprocess.run(["git", "-C", str(ROOT), "check-ignore", "--no-index", "-v", "-n", *written],
                               capture_output=True, text=True)
        unignored = [line.split("\t")[-1] for line in check.stdout.splitlines() if line.startswith("::")]
        assert not unignored, f"{page}: not in .gitignore: {unignored}"
