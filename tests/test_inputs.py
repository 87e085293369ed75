"""faultgen.inputs, the readers' guard against hostile files (issue 50, items 2 and 4): non-regular
files, TOML nesting bombs, gzip bombs, HDF5 links out of the file and oversized declared shapes, each
refused with an InputError naming the file before the content is parsed or read."""

import gzip
import os
import time

import h5py
import numpy as np
import pytest

from faultgen import inputs
from faultgen.inputs import InputError


def test_a_device_a_folder_or_a_symlink_to_a_device_is_not_a_regular_file(tmp_path):
    with pytest.raises(InputError, match=r"/dev/zero: not a regular file \(a character device\)"):
        inputs.read_toml("/dev/zero", "drivetrain file")
    with pytest.raises(InputError, match="not a regular file \\(a folder\\)"):
        inputs.regular_file(tmp_path, "log")
    (tmp_path / "zero").symlink_to("/dev/zero")
    with pytest.raises(InputError, match="zero: not a regular file \\(a symlink to /dev/zero, a character device"):
        inputs.regular_file(tmp_path / "zero", "log")
    os.mkfifo(tmp_path / "pipe")
    with pytest.raises(InputError, match="FIFO"):
        inputs.open_text(tmp_path / "pipe", "log")
    with pytest.raises(InputError, match="missing.toml: no such file"):
        inputs.read_toml(tmp_path / "missing.toml", "program file")


def test_a_file_over_the_bound_is_refused_with_its_size(tmp_path):
    big = tmp_path / "big.toml"
    big.write_text("a = 1\n" * 100)
    with pytest.raises(InputError, match="big.toml: 600 bytes; a program file is read up to 100 bytes"):
        inputs.read_toml(big, "program file", max_bytes=100)


@pytest.mark.parametrize(("text", "message"), [
    ("a" + ".a" * 100_000 + " = 1\n", "line 1: a dotted key of more than 32 parts"),
    ("x = 1\n[" + ".".join(["t"] * 40) + "]\n", "line 2: a dotted key of more than 32 parts"),
    ("a = " + "[" * 50_000 + "]" * 50_000 + "\n", "line 1: brackets nested more than 32 deep"),
    ("a = " + "{b = " * 40 + "1" + "}" * 40 + "\n", "line 1: brackets nested more than 32 deep"),
])
def test_a_toml_nesting_bomb_is_refused_before_parsing(tmp_path, text, message):
    bomb = tmp_path / "bomb.toml"
    bomb.write_text(text)
    start = time.perf_counter()
    with pytest.raises(InputError, match=f"bomb.toml: {message}"):
        inputs.read_toml(bomb, "DH table")
    assert time.perf_counter() - start < 1.0


def test_brackets_and_dots_in_strings_and_comments_are_text(tmp_path):
    good = tmp_path / "good.toml"
    good.write_text('# [[[[ a.b.c.d.e\nname = "x.y" # ' + "." * 50 + '\n[a.b]\nc = [1.5, {x = 1, y.z = [2]}]\n'
                    'd = """[[[[\n' + "." * 40 + '"""\n[[moves]]\nt = 1e-3\n')
    assert inputs.read_toml(good, "program file") == {
        "name": "x.y", "a": {"b": {"c": [1.5, {"x": 1, "y": {"z": [2]}}], "d": "[[[[\n" + "." * 40}},
        "moves": [{"t": 1e-3}]}


def test_toml_syntax_and_encoding_errors_name_the_file(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("a = = 1\n")
    with pytest.raises(InputError, match="bad.toml: not a valid TOML sweep config: .*line 1"):
        inputs.read_toml(bad, "sweep config")
    bad.write_bytes(b"a = '\xff'\n")
    with pytest.raises(InputError, match="bad.toml: byte 5 is not UTF-8 text"):
        inputs.read_toml(bad, "sweep config")


def test_a_gzip_bomb_is_refused_after_a_few_mib(tmp_path):
    bomb = tmp_path / "log.csv.gz"
    with gzip.open(bomb, "wb", compresslevel=9) as g:
        g.write(b"t,q1\n")
        for _ in range(200):
            g.write(b"0,0\n" * 2**18)
    start = time.perf_counter()
    with pytest.raises(InputError, match=r"log.csv.gz: inflates more than 100 times .* gzip bomb"):
        with inputs.open_text(bomb, "log") as fh:
            while fh.read(2**20):
                pass
    assert time.perf_counter() - start < 2.0


def test_an_ordinary_gzip_log_reads_whole(tmp_path):
    log = tmp_path / "log.csv.gz"
    rows = "".join(f"{i * 1e-3:.3f},{v:.6f}\n" for i, v in enumerate(np.random.default_rng(0).normal(size=50_000)))
    with gzip.open(log, "wt") as g:
        g.write("t,q1\n" + rows)
    with inputs.open_text(log, "log") as fh:
        assert fh.read() == "t,q1\n" + rows


@pytest.fixture
def other(tmp_path):
    path = tmp_path / "other.h5"
    with h5py.File(path, "w") as f:
        f["runs/x"] = np.arange(3.0)
    return path


def _write(path, build):
    with h5py.File(path, "w") as f:
        f["kept/y"] = np.arange(3.0)
        build(f)
    return path


@pytest.mark.parametrize(("build", "message"), [
    (lambda f: f.__setitem__("runs", h5py.ExternalLink("other.h5", "/runs")),
     "/runs is an external link to other.h5:/runs"),
    (lambda f: f.__setitem__("kept/deep", h5py.ExternalLink("other.h5", "/runs/x")),
     "/kept/deep is an external link to other.h5:/runs/x"),
    (lambda f: f.__setitem__("dangling", h5py.SoftLink("/nowhere")),
     "/dangling is a soft link to /nowhere, which does not resolve inside the file"),
    (lambda f: f.create_dataset("e", shape=(10,), dtype="f8", external=[("raw.bin", 0, 80)]),
     "/e keeps its data in external file"),
])
def test_hdf5_links_out_of_the_file_are_refused_and_named(tmp_path, other, build, message):
    path = _write(tmp_path / "hostile.h5", build)
    with pytest.raises(InputError, match=f"hostile.h5: {message}"):
        with inputs.open_hdf5(path):
            pass


def test_a_virtual_dataset_is_refused_naming_its_source(tmp_path, other):
    def build(f):
        layout = h5py.VirtualLayout(shape=(3,), dtype="f8")
        layout[:] = h5py.VirtualSource(str(other), "runs/x", shape=(3,))
        f.create_virtual_dataset("v", layout)
    with pytest.raises(InputError, match="/v is a virtual dataset reading .*other.h5"):
        with inputs.open_hdf5(_write(tmp_path / "hostile.h5", build)):
            pass


def test_a_soft_link_inside_the_file_is_read(tmp_path):
    path = _write(tmp_path / "fine.h5", lambda f: f.__setitem__("kept/alias", h5py.SoftLink("y")))
    with inputs.open_hdf5(path) as f:
        assert list(f["kept/alias"][()]) == [0.0, 1.0, 2.0]


def test_a_declared_shape_is_checked_before_any_read(tmp_path):
    path = tmp_path / "huge.h5"
    with h5py.File(path, "w") as f:
        f.create_dataset("t", shape=(10**10, 6), dtype="f8", chunks=(1024, 6))
        f["s"] = np.array([b"x", b"y"])
        f.create_group("g")
        f["q"] = np.zeros((5, 6))
    with inputs.open_hdf5(path) as f:
        with pytest.raises(InputError, match=r"huge.h5: /t declares \(10000000000, 6\) = 6e\+10 elements"):
            inputs.bounded_dataset(f, "t", path, (None, 6))
        with pytest.raises(InputError, match="/s holds |S1 values; numbers are expected"):
            inputs.bounded_dataset(f, "s", path)
        with pytest.raises(InputError, match="/g is a group, not a dataset"):
            inputs.bounded_dataset(f, "g", path)
        with pytest.raises(InputError, match=r"/q has shape \(5, 6\); \(any, 7\) is expected"):
            inputs.bounded_dataset(f, "q", path, (None, 7))
        assert inputs.bounded_dataset(f, "q", path, (5, 6)).shape == (5, 6)


def test_a_file_that_is_not_hdf5_is_refused(tmp_path):
    path = tmp_path / "text.h5"
    path.write_text("not hdf5")
    with pytest.raises(InputError, match="text.h5: not a readable HDF5 file"):
        with inputs.open_hdf5(path):
            pass
