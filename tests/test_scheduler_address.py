"""Issue 50 item 3: ``--scheduler`` refuses, in one line and before any work, an address of the
wrong form and one where no Dask scheduler answers (a server that sends other bytes, one that
sends nothing, a closed port), instead of reading another server's bytes as a message length
(``MemoryError: Unable to allocate 3.07 EiB``) or a ``Client.__del__`` traceback. The success
path (a real scheduler) is tests/test_cluster.py's."""

import socket
import threading

import pytest
from typer.testing import CliRunner

from faultgen.cli import app
from faultgen.runs import cluster

runner = CliRunner()


@pytest.fixture
def server():
    """``server(reply)``: the address of a TCP server on 127.0.0.1 that sends ``reply`` to each
    connection (b"": accepts and stays silent) and keeps it open until the test ends."""
    sockets, stop = [], threading.Event()

    def start(reply: bytes) -> str:
        listener = socket.socket()
        listener.bind(("127.0.0.1", 0))
        listener.listen()
        listener.settimeout(0.2)
        sockets.append(listener)

        def serve():
            while not stop.is_set():
                try:
                    conn, _ = listener.accept()
                except OSError:
                    continue
                sockets.append(conn)
                if reply:
                    conn.sendall(reply)

        threading.Thread(target=serve, daemon=True).start()
        return f"tcp://127.0.0.1:{listener.getsockname()[1]}"

    yield start
    stop.set()
    for s in sockets:
        s.close()


def _sweep(tmp_path, address: str):
    return runner.invoke(app, ["sweep", "--preset", "quick", "--no-progress", "--scheduler", address,
                               "-o", str(tmp_path / "q.h5")])


def _one_line_refusal(result, tmp_path, *parts: str) -> None:
    assert result.exit_code == 2, result.output
    lines = result.output.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), result.output
    assert all(part in lines[0] for part in parts), result.output
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("reply", [b"HTTP/1.1 200 OK\r\n\r\nhello" * 10, b"\x01" + b"\x00" * 7 + b"garbage" * 10])
def test_a_server_that_is_not_a_dask_scheduler_is_refused_in_one_line(tmp_path, server, reply):
    address = server(reply)
    result = _sweep(tmp_path, address)
    _one_line_refusal(result, tmp_path, f"no Dask scheduler answers at {address}", "not a Dask scheduler")


def test_a_silent_server_and_a_closed_port_are_refused_in_one_line(tmp_path, server, monkeypatch):
    monkeypatch.setattr(cluster, "PROBE_TIMEOUT", 0.5)
    address = server(b"")
    _one_line_refusal(_sweep(tmp_path, address), tmp_path, f"no Dask scheduler answers at {address}", "timed out")
    closed = socket.socket()
    closed.bind(("127.0.0.1", 0))
    port = closed.getsockname()[1]
    closed.close()  # nothing listens there now
    _one_line_refusal(_sweep(tmp_path, f"tcp://127.0.0.1:{port}"), tmp_path, f"tcp://127.0.0.1:{port}")


@pytest.mark.parametrize(("address", "message"), [
    ("foo", "not a Dask scheduler's address"),
    ("tcp://", "not a Dask scheduler's address"),
    ("tcp://127.0.0.1:99999", "port 99999 is out of range 1..65535"),
    ("ucx://127.0.0.1:8786", "protocol 'ucx' is not taken"),
    ("inproc://x", "not a Dask scheduler's address"),
    ("http://127.0.0.1:8786", "protocol 'http' is not taken"),
])
def test_a_malformed_address_is_refused_before_any_work(tmp_path, address, message):
    _one_line_refusal(_sweep(tmp_path, address), tmp_path, f"--scheduler {address!r}", message)


def test_tls_without_dask_tls_configuration_is_refused(tmp_path, server):
    address = server(b"x").replace("tcp://", "tls://")
    _one_line_refusal(_sweep(tmp_path, address), tmp_path, "tls:// needs Dask's TLS configuration")
