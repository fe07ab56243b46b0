"""fetch_cmu_mocap when the server states no length, trickles, or the fetching process is
killed: a local HTTP server on 127.0.0.1 (never the network)."""

import http.server
import os
import signal
import subprocess
import sys
import textwrap
import threading
import time

import pytest

from skmotion.datasets import _fetch, fetch_cmu_mocap
from tests.io.test_asf_amc import ASF, _amc, _frames


def _at_frame(body, frame):
    """The body cut just before frame ``frame``: every frame before it complete."""
    return body[: body.index(f"\r\n{frame}\r\n".encode()) + 2]  # the files have CRLF


class Handler(http.server.BaseHTTPRequestHandler):
    def do_GET(self):  # noqa: N802
        name = self.path.rsplit("/", 1)[1]
        with self.server.lock:
            self.server.requests.append(name)
            plan = self.server.plan.get(name, [])
            how = plan.pop(0) if plan else "ok"
        body = self.server.files.get(name)
        if body is None:
            return self.send_error(404)
        if how == "cut_at_frame":  # the connection closes after frame 3; no length stated
            body = _at_frame(body, 4)
        self.send_response(200)
        if self.server.content_length and how == "ok":
            self.send_header("Content-Length", str(len(body)))
        self.send_header("Connection", "close")  # without a length, the close ends the body
        self.end_headers()
        try:
            if how == "trickle":  # two bytes at a time, each well within any read timeout
                for k in range(0, len(body), 2):
                    self.wfile.write(body[k : k + 2])
                    self.wfile.flush()
                    time.sleep(self.server.trickle_pause)
            else:
                self.wfile.write(body)
        except OSError:  # the client gave up
            pass
        self.close_connection = True

    def log_message(self, *args):
        pass


@pytest.fixture
def server(monkeypatch, rng):
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
    httpd.daemon_threads = True
    httpd.files = {"05.asf": ASF.encode(), "05_01.amc": _amc(_frames(rng, 9)).encode()}
    httpd.plan, httpd.requests, httpd.lock = {}, [], threading.Lock()
    httpd.content_length, httpd.trickle_pause = False, 0.02
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    monkeypatch.setattr(_fetch, "CMU_URL", f"http://127.0.0.1:{httpd.server_port}/subjects")
    monkeypatch.setattr(_fetch, "_BACKOFF", 0.01)
    yield httpd
    httpd.shutdown()
    httpd.server_close()


def _cached(tmp_path):
    return sorted(p.name for p in (tmp_path / "cmu-asfamc" / "05").iterdir())


def test_without_content_length_a_second_copy_confirms_the_body(server, tmp_path):
    data = fetch_cmu_mocap(5, trials=[1], data_home=tmp_path)
    assert len(data.clips[0]) == 9
    assert server.requests.count("05_01.amc") == 2 and server.requests.count("05.asf") == 2
    assert _cached(tmp_path) == ["05.asf", "05_01.amc"]


def test_a_body_cut_between_frames_without_content_length_is_not_cached(server, tmp_path):
    """The cut body parses (three whole frames), so only a second copy can tell."""
    from skmotion.io import read_amc, read_asf

    (tmp_path / "cut.amc").write_bytes(_at_frame(server.files["05_01.amc"], 4))
    (tmp_path / "05.asf").write_bytes(server.files["05.asf"])
    assert read_amc(tmp_path / "cut.amc", read_asf(tmp_path / "05.asf")).n_frames == 3
    server.plan["05_01.amc"] = ["cut_at_frame"]
    data = fetch_cmu_mocap(5, trials=[1], data_home=tmp_path)
    assert len(data.clips[0]) == 9  # not 3
    assert server.requests.count("05_01.amc") == 3  # cut, whole, whole again
    assert _cached(tmp_path) == ["05.asf", "05_01.amc"]


def test_a_server_that_always_cuts_is_one_error_and_leaves_nothing(server, tmp_path):
    server.plan["05_01.amc"] = ["cut_at_frame", "ok", "cut_at_frame", "ok"]
    with pytest.raises(ConnectionError, match="no Content-Length: a second copy must confirm"):
        fetch_cmu_mocap(5, trials=[1], data_home=tmp_path)
    assert _cached(tmp_path) == ["05.asf"]


def test_a_trickling_server_meets_the_transfer_deadline(server, tmp_path):
    server.content_length = True
    server.plan["05_01.amc"] = ["trickle"] * 3
    start = time.monotonic()
    with pytest.raises(ConnectionError, match="did not finish within transfer_timeout"):
        fetch_cmu_mocap(5, trials=[1], data_home=tmp_path, timeout=5.0, transfer_timeout=0.3)
    assert time.monotonic() - start < 5.0
    assert _cached(tmp_path) == ["05.asf"]  # no .part left


_KILLED = """
import sys
from skmotion.datasets import _fetch, fetch_cmu_mocap
_fetch.CMU_URL = sys.argv[1]
fetch_cmu_mocap(5, trials=[1], data_home=sys.argv[2], transfer_timeout=600)
"""


@pytest.mark.skipif(not hasattr(signal, "SIGKILL"), reason="needs SIGKILL")
def test_a_killed_fetch_leaves_no_part_file_behind_the_next_one(server, tmp_path):
    server.content_length = True
    (tmp_path / "cmu-asfamc" / "05").mkdir(parents=True)
    (tmp_path / "cmu-asfamc" / "05" / "05.asf").write_bytes(server.files["05.asf"])
    server.plan["05_01.amc"] = ["trickle"]
    server.trickle_pause = 0.2  # minutes for the whole file: the kill comes first
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    child = subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(_KILLED), _fetch.CMU_URL, str(tmp_path)],
        cwd=root,
    )
    try:
        deadline = time.monotonic() + 120  # the child imports skmotion first: slow under load
        while time.monotonic() < deadline and child.poll() is None:
            if any(n.endswith(".part") for n in _cached(tmp_path)):
                break
            time.sleep(0.02)
        assert any(n.endswith(".part") for n in _cached(tmp_path))
    finally:
        child.send_signal(signal.SIGKILL)
        child.wait()
    data = fetch_cmu_mocap(5, trials=[1], data_home=tmp_path)
    assert len(data.clips[0]) == 9
    assert _cached(tmp_path) == ["05.asf", "05_01.amc"]
