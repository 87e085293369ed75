"""Nothing is written, read or sent through a link in a monitor OUT that leads outside it
(docs/reliability.md, "Threat model"): OUT's ``.state``, ``.cache`` and its entries, the cached
cycles and calibrations, the twin model beside a calibrated one, on the local path and on the
``--scheduler`` path's cache (:class:`faultgen.monitor.remote.Cache`). Every refusal is one line
naming the link, exit 2, and the folder the link leads to is left as it was."""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.data.confined import Confined
from faultgen.inputs import InputError
from faultgen.model import robots
from faultgen.monitor import remote, unit
from faultgen.monitor import state as stored
from faultgen.monitor.history import UnitHistory

sys.path.insert(0, str(Path(__file__).parent))
import shipped_fleet

runner = CliRunner()


@pytest.fixture(scope="module")
def fleet(tmp_path_factory) -> Path:
    spec = shipped_fleet.ShippedFleet(robot="puma560", units=2, days=3, worn={}, parts=(1.0,), no_payload=0)
    return shipped_fleet.write_fleet(tmp_path_factory.mktemp("fleet"), spec)[0]


@pytest.fixture(scope="module")
def monitored(fleet, tmp_path_factory) -> Path:
    """A finished twin run (nominal model) with a real ``.state`` and ``.cache`` (cycles; the replayed
    programs stay in memory)."""
    out = tmp_path_factory.mktemp("monitored") / "out"
    result = _monitor(fleet, out)
    assert result.exit_code == 0, result.output
    assert (out / ".state").is_dir() and any((out / ".cache" / "cycles").iterdir())
    assert not (out / ".cache" / "programs").exists()
    return out


def _monitor(logs: Path, out: Path, *extra: str):
    return runner.invoke(app, ["monitor", str(logs), "--robot", "puma560", "-o", str(out), "--no-calibrate", *extra])


def _files(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def _linked_out(monitored: Path, tmp_path: Path, entry: str) -> tuple[Path, Path]:
    """A copy of ``monitored`` whose ``entry`` is a link to DIR, a folder outside it holding what
    the entry held (so every read through it would succeed)."""
    out = tmp_path / "out"
    shutil.copytree(monitored, out, symlinks=True)
    outside = tmp_path / "DIR"
    target = out / entry
    if target.exists():
        shutil.move(target, outside)
    else:
        outside.mkdir()
    target.parent.mkdir(parents=True, exist_ok=True)
    target.symlink_to(outside, target_is_directory=True)
    return out, outside


@pytest.mark.parametrize("entry", [".cache", ".cache/programs", ".cache/calibrated", ".cache/cycles", ".state"])
@pytest.mark.parametrize("calibrate", [False, True], ids=["nominal", "calibrated"])
def test_a_link_out_of_a_continued_out_is_refused_before_anything_is_written(fleet, monitored, tmp_path, entry,
                                                                             calibrate):
    out, outside = _linked_out(monitored, tmp_path, entry)
    before, outputs = _files(outside), _files(out)
    result = runner.invoke(app, ["monitor", str(fleet), "--robot", "puma560", "-o", str(out),
                                 "--calibrate" if calibrate else "--no-calibrate"])
    assert result.exit_code == 2, result.output
    assert f"{out / entry}: a link leading outside the monitor output folder" in result.output
    assert "Traceback" not in result.output and len(result.output.strip().splitlines()) == 1, result.output
    assert _files(outside) == before  # nothing written (or replaced) through the link
    assert {k: v for k, v in _files(out).items()} == outputs


def test_a_cache_file_linked_out_is_neither_read_nor_written_through(monitored, tmp_path):
    out = tmp_path / "out"
    shutil.copytree(monitored, out)
    secret = tmp_path / "secret.json"
    secret.write_text("MARKER")
    cycle = sorted((out / ".cache" / "cycles").iterdir())[0]
    cycle.unlink()
    cycle.symlink_to(secret)
    folder = stored.out_folder(out)
    with pytest.raises(stored.StateError, match=f"{cycle}: a link leading outside"):
        stored.write_cycle(cycle, out, {"k": 1}, [0.0])
    with pytest.raises(stored.StateError, match=f"{cycle}: a link leading outside") as refused:
        folder.read_bytes(cycle, "cached twin cycle", stored.CYCLE_MAX_BYTES)
    assert "MARKER" not in str(refused.value) and secret.read_text() == "MARKER"
    program = tmp_path / "elsewhere"
    program.mkdir()
    (out / ".cache" / "programs").symlink_to(program)
    with pytest.raises(stored.StateError, match="programs: a link leading outside"):
        folder.write_text(out / ".cache" / "programs" / "x.csv", "t,q1\n")
    assert not any(program.iterdir())


def _calibrated_copy(out: Path, digest: str = "d" * 24) -> robots.Robot:
    """The puma560's model folder copied where the monitor caches a unit's calibration, loaded."""
    model = out / ".cache" / "calibrated" / digest / "model"
    shutil.copytree(Path(robots.load("puma560").path).parent, model)
    (model / "puma560.xml").rename(model / "puma560_calibrated.xml")
    return robots.load(model / "puma560_calibrated.xml")


def test_a_twin_model_linked_out_of_out_is_refused_unparsed(tmp_path):
    out = tmp_path / "out"
    calibrated = _calibrated_copy(out)
    outside = tmp_path / "outside.xml"
    outside.write_text("<mujoco><MARKER-parse-error")
    twin = Path(calibrated.path).with_name("puma560_twin.xml")
    twin.symlink_to(outside)
    with pytest.raises(stored.StateError, match=r"puma560_twin\.xml: a link leading outside") as refused:
        unit.without_payload(calibrated, out)
    assert "MARKER" not in str(refused.value)
    twin.unlink()  # a real one is written inside OUT and read back as the twin model
    written = unit.without_payload(calibrated, out)
    assert Path(written.path).is_file() and Path(written.path).parent == Path(calibrated.path).parent


def _scheduler_cache(out: Path) -> remote.Cache:
    return remote.Cache(out, stored.sha256_file(robots.load("puma560").path), None)


def test_the_scheduler_cache_refuses_a_calibration_record_linked_out_and_sends_nothing(tmp_path):
    out = tmp_path / "out"
    nominal = stored.sha256_file(robots.load("puma560").path)
    first = "f" * 64
    digest = stored.key_name(unit.calibration_key(nominal, first, "calibrated"))
    _calibrated_copy(out, digest)
    secret = tmp_path / "secret.json"
    secret.write_text(json.dumps({"MARKER": 1}))
    (out / ".cache" / "calibrated" / f"{digest}.json").symlink_to(secret)
    member = UnitHistory("u1", "calibrated", ("u1", "s"), ("s", first))
    with pytest.raises(stored.StateError, match=f"{digest}.json: a link leading outside") as refused:
        _scheduler_cache(out).for_unit(member, nominal, first, "measured")
    assert "MARKER" not in str(refused.value)


def test_the_scheduler_cache_writes_nothing_through_a_link_and_bounds_a_cycle_file(monitored, tmp_path):
    out, outside = _linked_out(monitored, tmp_path, ".cache/programs")
    with pytest.raises(stored.StateError, match="programs: a link leading outside"):
        _scheduler_cache(out)
    out.joinpath(".cache", "programs").unlink()
    cache = _scheduler_cache(out)
    with pytest.raises(stored.StateError, match="a link leading outside"):
        (out / ".cache" / "cycles" / "planted.json").symlink_to(outside / "planted.json")
        cache.write({"cycles/planted.json": b"{}"})
    assert not (outside / "planted.json").exists()
    (out / ".cache" / "cycles" / "planted.json").unlink()
    big = out / ".cache" / "cycles" / "big.json"
    with open(big, "wb") as f:  # 150 MB declared, never read: refused on its size
        f.truncate(150 * 2**20)
    with pytest.raises(stored.StateError, match=r"big\.json: .*a cached twin cycle is read up to 1048576 bytes"):
        _scheduler_cache(out)


def test_confined_refuses_a_name_leading_out_and_makes_folders_only_inside(tmp_path):
    root = tmp_path / "root"
    confined = Confined(root, "worker's folder")
    confined.write_bytes(root / "a" / "b.txt", b"x")
    assert (root / "a" / "b.txt").read_bytes() == b"x"
    with pytest.raises(InputError, match=r"\.\./escape\.txt: a name leading outside the worker's folder"):
        confined.write_bytes(root / ".." / "escape.txt", b"x")
    assert not (tmp_path / "escape.txt").exists()
    (tmp_path / "elsewhere").mkdir()
    (root / "linked").symlink_to(tmp_path / "elsewhere")
    with pytest.raises(InputError, match="linked: a link leading outside"):
        confined.mkdir(root / "linked" / "deeper")
    assert not (tmp_path / "elsewhere" / "deeper").exists()
    with pytest.raises(InputError, match="linked: a link leading outside"):
        confined.remove(root / "linked")
