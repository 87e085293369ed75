"""Fuzzing the data-file readers (issue 50, "a fuzz test ... over the TOML/CSV/HDF5 readers"):
hypothesis generates malformed TOML, CSV (plain and gzip, truncated) and HDF5 files (logs and
datasets with edited attributes, arrays, links); every reader either reads the file or refuses it
with a ``ValueError`` whose message names the file, never another exception (a traceback on the
command line). The example counts are in docs/reliability.md ("Threat model: data files")."""

import gzip
import shutil
import tempfile
from pathlib import Path

import h5py
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import faultgen
from faultgen import inputs
from faultgen.data import dataset
from faultgen.logs import longlog, measured
from faultgen.model import robots
from faultgen.operation import programs

FUZZ = settings(deadline=None, suppress_health_check=list(HealthCheck), derandomize=True)
COLUMNS = ["t", *(f"q{i}" for i in range(1, 7)), *(f"tau{i}" for i in range(1, 7))]


@pytest.fixture(scope="module")
def puma():
    return robots.load("puma560")


def _refuses_by_name(path: Path, read) -> None:
    """``read()`` reads the file or raises a ValueError naming it; anything else fails the test."""
    try:
        read()
    except ValueError as err:
        assert str(path) in str(err), f"{type(err).__name__} without the file: {err}"


# -- TOML ------------------------------------------------------------------------------------------

TOML_PIECES = st.sampled_from(["[", "]", "{", "}", ".", "=", ",", '"', "'", "#", "\n", " ", "a", "b.c", "1", "1.5",
                               '"""', "'''", "[[x]]", "[t]", "k = ", "true", "\\", "\t", "é", "\x00", "1e300",
                               "[" * 40, "a." * 40, "x = [" * 3])


@settings(FUZZ, max_examples=2000)
@given(st.one_of(st.lists(TOML_PIECES, max_size=60).map("".join), st.text(max_size=200), st.binary(max_size=200)))
def test_toml_reader(text):
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "table.toml"
        path.write_bytes(text if isinstance(text, bytes) else text.encode("utf-8", "surrogatepass"))
        _refuses_by_name(path, lambda: inputs.read_toml(path, "TOML table"))


# -- CSV logs --------------------------------------------------------------------------------------

CELLS = st.one_of(st.floats(allow_nan=True, allow_infinity=True).map(repr), st.integers(-10, 10).map(str),
                  st.sampled_from(["", "nan", "abc", "1e400", "-", " 0.1 ", '"1"', "0x10", "1,2"]))


@st.composite
def csv_logs(draw):
    header = draw(st.one_of(st.just(COLUMNS), st.lists(st.sampled_from([*COLUMNS, "qd1", "x", "t", ""]),
                                                       max_size=16)))
    rows = draw(st.integers(0, 40))
    regular = draw(st.booleans())
    lines = []
    for i in range(rows):
        if regular:  # mostly numbers at 250 Hz, a few cells broken
            cells = [f"{i * 0.004:.3f}"] + [f"{0.01 * np.sin(i):.4f}"] * (len(header) - 1)
            if draw(st.booleans()):
                cells[draw(st.integers(0, max(len(cells) - 1, 0)))] = draw(CELLS) if cells else ""
        else:
            cells = draw(st.lists(CELLS, max_size=len(header) + 2))
        lines.append(",".join(cells))
    text = ",".join(header) + "\n" + "\n".join(lines) + draw(st.sampled_from(["", "\n", "\n\n"]))
    data = text.encode()
    if draw(st.booleans()):
        data = gzip.compress(data)
        if draw(st.booleans()):
            data = data[: draw(st.integers(0, len(data)))]  # a truncated gzip stream
    return data


@settings(FUZZ, max_examples=300)
@given(csv_logs(), st.sampled_from(["log.csv", "log.csv.gz"]))
def test_csv_log_readers(puma, data, name):
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / name
        path.write_bytes(data)
        _refuses_by_name(path, lambda: measured.read(path, puma))
        _refuses_by_name(path, lambda: programs.load(puma, str(path)))
        _refuses_by_name(path, lambda: longlog.read(path, puma, 5, 1e-3))


# -- HDF5 logs -------------------------------------------------------------------------------------

KINDS = ["ok", "missing", "2d", "text", "group", "external", "soft", "dangling", "short", "empty", "scalar", "int",
         "nan", "virtual"]


def _column(f, name, kind, n):
    t = np.arange(n) * 0.004
    values = t if name == "t" else 0.01 * np.sin(t)
    if kind == "ok" or kind == "nan":
        f[name] = values if kind == "ok" else np.where(np.arange(n) == n // 2, np.nan, values)
    elif kind == "2d":
        f[name] = np.zeros((n, 2))
    elif kind == "text":
        f[name] = np.array([b"x"] * n)
    elif kind == "group":
        f.create_group(name)
    elif kind == "external":
        f[name] = h5py.ExternalLink("other.h5", "/t")
    elif kind == "soft":
        f[f"hidden_{name}"] = values
        f[name] = h5py.SoftLink(f"/hidden_{name}")
    elif kind == "dangling":
        f[name] = h5py.SoftLink("/nowhere")
    elif kind == "short":
        f[name] = values[: n // 2]
    elif kind == "empty":
        f.create_dataset(name, shape=(0,), dtype="f8")
    elif kind == "scalar":
        f[name] = 1.0
    elif kind == "int":
        f[name] = np.arange(n)
    elif kind == "virtual":
        layout = h5py.VirtualLayout(shape=(n,), dtype="f8")
        layout[:] = h5py.VirtualSource("other.h5", "t", shape=(n,))
        f.create_virtual_dataset(name, layout)


@settings(FUZZ, max_examples=300)
@given(st.lists(st.sampled_from(KINDS), min_size=len(COLUMNS), max_size=len(COLUMNS)), st.integers(0, 800),
       st.booleans())
def test_hdf5_log_readers(puma, kinds, n, bad_file):
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "log.h5"
        with h5py.File(Path(folder) / "other.h5", "w") as f:
            f["t"] = np.arange(max(n, 1)) * 0.004
        if bad_file:
            path.write_bytes(b"\x89HDF\r\n\x1a\n" + bytes(n % 97))  # an HDF5 signature and nothing after
        else:
            with h5py.File(path, "w") as f:
                for name, kind in zip(COLUMNS, kinds, strict=True):
                    if kind != "missing":
                        _column(f, name, kind, n)
        _refuses_by_name(path, lambda: measured.read(path, puma))
        _refuses_by_name(path, lambda: programs.load(puma, str(path)))
        _refuses_by_name(path, lambda: longlog.read(path, puma, 5, 1e-3))


# -- datasets --------------------------------------------------------------------------------------

ATTRIBUTE_VALUES = st.one_of(st.integers(-2**62, 2**62), st.floats(allow_nan=True),
                             st.text(st.characters(blacklist_characters="\x00"), max_size=8),
                             st.just(np.array([1, 2])), st.just(np.array([b"x"])), st.just(10**15), st.booleans())
ARRAY_EDITS = st.sampled_from(["delete", "text", "group", "external", "huge", "scalar", "transpose", "virtual",
                               "nan", "short"])


@pytest.fixture(scope="module")
def small(shared_sweep, tmp_path_factory):
    """A shared small sweep, and a copy of it beside which each edited file is written (the target
    of the external links and virtual datasets: a file those readers must never open). The sweep is
    tests/test_export.py's (2 runs, 3 recorded cycles each, 2.7 MB: every run array and attribute the
    40-cycle analysis sweep of 35 MB has, the first run worn), copied once an example."""
    path = shared_sweep("export-small", robots=["irb6700"], tasks=["spot_weld"], axes=[0, 3], cycles=20,
                        record=[1, 10, 20])
    folder = tmp_path_factory.mktemp("fuzz-datasets")
    shutil.copy(path, folder / "other.h5")
    return path, folder


def _edit_array(f, group, name, edit):
    if not isinstance(group.get(name), h5py.Dataset) or group[name].is_virtual:
        return  # edited already
    shape, dtype = group[name].shape, group[name].dtype
    del group[name]
    if edit == "text":
        group[name] = np.full(shape, b"x")
    elif edit == "group":
        group.create_group(name)
    elif edit == "external":
        group[name] = h5py.ExternalLink("other.h5", f"{group.name}/{name}")
    elif edit == "huge":
        group.create_dataset(name, shape=(10**10, *shape[1:]), dtype=dtype, chunks=(1, *shape[1:]))
    elif edit == "scalar":
        group[name] = 1.0
    elif edit == "transpose":
        group[name] = np.zeros(shape[::-1], dtype=dtype)
    elif edit == "virtual":
        layout = h5py.VirtualLayout(shape=shape, dtype=dtype)
        layout[...] = h5py.VirtualSource("other.h5", f"{group.name}/{name}", shape=shape)
        group.create_virtual_dataset(name, layout)
    elif edit == "nan":
        group[name] = np.full(shape, np.nan)
    elif edit == "short":
        group.create_dataset(name, shape=(max(shape[0] - 1, 0) if shape else 0, *shape[1:]), dtype=dtype)


@settings(FUZZ, max_examples=120)
@given(st.lists(st.tuples(st.sampled_from([*dataset.RUN_ATTRIBUTES, "n_axes", "signals", "sample", "saturated"]),
                          st.one_of(st.none(), ATTRIBUTE_VALUES)), max_size=3),
       st.lists(st.tuples(st.sampled_from(sorted(dataset.ARRAYS)), ARRAY_EDITS), max_size=3, unique_by=lambda e: e[0]),
       st.booleans())
def test_dataset_readers(small, attributes, arrays, empty_run):
    source, folder = small
    path = folder / "data.h5"
    shutil.copy(source, path)
    with h5py.File(path, "r+") as f:
        group = f["runs"][next(iter(f["runs"]))]
        for key, value in attributes:
            if value is None:
                group.attrs.pop(key, None)
            else:
                group.attrs[key] = value
        for name, edit in arrays:
            _edit_array(f, group, name, edit)
        if empty_run:
            f["runs"].create_group("empty")

    def read():
        with faultgen.open(path) as data:
            data.features()
            for run in data.runs:
                run.array("tau_m")

    _refuses_by_name(path, read)
    _refuses_by_name(path, lambda: dataset.validate(path))
    _refuses_by_name(path, lambda: dataset.summary(path))
