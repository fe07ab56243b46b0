"""fetch_cmu_mocap against a local HTTP server on 127.0.0.1 (never the network): cut
downloads, HTML error pages, IncompleteRead, concurrent fetches, recovering servers, bad ids."""

import http.client
import http.server
import threading
import urllib.error

import numpy as np
import pytest

from skmotion.datasets import _fetch, fetch_cmu_mocap
from skmotion.io import MotionFileError, read_amc, read_asf
from tests.io.test_asf_amc import ASF, _amc, _frames

HTML = b"<!DOCTYPE html><html><body><h1>503 Service Unavailable</h1></body></html>"


class Handler(http.server.BaseHTTPRequestHandler):
    """Serves ``server.files``; ``server.plan[name]`` lists how the next requests fail."""

    def do_GET(self):  # noqa: N802 (the name http.server calls)
        name = self.path.rsplit("/", 1)[1]
        with self.server.lock:
            self.server.requests.append(name)
            plan = self.server.plan.get(name, [])
            how = plan.pop(0) if plan else "ok"
        body = self.server.files.get(name)
        if body is None or how == "404":
            return self.send_error(404)
        if how.isdigit():
            return self.send_error(int(how))
        if how == "html":  # an error page with status 200, as some proxies send
            body = HTML
        self.send_response(200)
        html = how in ("html", "mislabelled")
        self.send_header("Content-Type", "text/html" if html else "text/plain")
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        if how == "cut":  # the connection drops halfway: IncompleteRead for the client
            self.wfile.write(body[: len(body) // 2])
            self.close_connection = True
            return
        self.wfile.write(body)

    def log_message(self, *args):
        pass


@pytest.fixture
def server(monkeypatch, rng):
    httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
    httpd.files = {
        "05.asf": ASF.encode(),
        "05_01.amc": _amc(_frames(rng, 5)).encode(),
        "05_02.amc": _amc(_frames(rng, 7)).encode(),
    }
    httpd.plan, httpd.requests, httpd.lock = {}, [], threading.Lock()
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    # https cannot be served locally without a certificate: the scheme is a module constant.
    assert _fetch.CMU_URL.startswith("https://")
    monkeypatch.setattr(_fetch, "CMU_URL", f"http://127.0.0.1:{httpd.server_port}/subjects")
    monkeypatch.setattr(_fetch, "_BACKOFF", 0.01)
    yield httpd
    httpd.shutdown()
    httpd.server_close()


def _cache(tmp_path):
    return tmp_path / "cmu-asfamc" / "05"


def _expected(server, tmp_path, name):
    """What the served file reads as (an independent read of the server's bytes)."""
    path = tmp_path / f"expected_{name}"
    path.write_bytes(server.files[name])
    if name.endswith(".asf"):
        return read_asf(path)
    asf = tmp_path / "expected.asf"
    asf.write_bytes(server.files["05.asf"])
    return read_amc(path, read_asf(asf)).channels


def test_a_cut_download_is_retried_and_never_cached(server, tmp_path):
    server.plan["05_02.amc"] = ["cut"]
    data = fetch_cmu_mocap(5, trials=[2], data_home=tmp_path)
    assert server.requests.count("05_02.amc") == 2
    np.testing.assert_array_equal(data.clips[0], _expected(server, tmp_path, "05_02.amc"))
    assert len(data.clips[0]) == 7  # every frame, not the half that first arrived
    assert sorted(p.name for p in _cache(tmp_path).iterdir()) == ["05.asf", "05_02.amc"]


def test_a_cut_that_persists_is_one_clear_error_and_leaves_nothing(server, tmp_path):
    server.plan["05_01.amc"] = ["cut"] * 3
    with pytest.raises(ConnectionError, match=r"05_01.amc \(.*\) after 3 attempts") as info:
        fetch_cmu_mocap(5, trials=[1], data_home=tmp_path)
    assert isinstance(info.value.__cause__, type(None))
    assert sorted(p.name for p in _cache(tmp_path).iterdir()) == ["05.asf"]  # no .part left


def test_an_html_page_with_status_200_is_not_cached_and_the_recovered_server_is_used(
    server, tmp_path
):
    server.plan["05.asf"] = ["html"] * 3
    with pytest.raises(ConnectionError, match="an HTML page, not a motion file"):
        fetch_cmu_mocap(5, trials=[1], data_home=tmp_path)
    assert not (_cache(tmp_path) / "05.asf").exists()
    # The server recovers: the next call works (nothing bad was cached).
    data = fetch_cmu_mocap(5, trials=[1], data_home=tmp_path)
    assert data.skeletons[0] == _expected(server, tmp_path, "05.asf")


def test_a_server_recovering_after_failures(server, tmp_path):
    server.plan["05.asf"] = ["503", "cut"]
    server.plan["05_01.amc"] = ["502", "html"]
    data = fetch_cmu_mocap(5, trials=[1], data_home=tmp_path, verbose=1)
    assert server.requests == ["05.asf"] * 3 + ["05_01.amc"] * 3
    np.testing.assert_array_equal(data.clips[0], _expected(server, tmp_path, "05_01.amc"))


def test_a_motion_file_labelled_text_html_is_judged_by_its_content(server, tmp_path):
    server.plan["05.asf"] = ["mislabelled"]
    data = fetch_cmu_mocap(5, trials=[1], data_home=tmp_path)
    assert server.requests == ["05.asf", "05_01.amc"]
    assert data.skeletons[0] == _expected(server, tmp_path, "05.asf")


def test_a_permanent_http_error_is_not_retried(server, tmp_path):
    server.plan["05.asf"] = ["403"]
    with pytest.raises(ConnectionError, match="HTTP 403"):
        fetch_cmu_mocap(5, data_home=tmp_path)
    assert server.requests == ["05.asf"]


def test_a_body_that_does_not_parse_is_refused_with_its_reason(server, tmp_path):
    server.files["05_01.amc"] = server.files["05_01.amc"].replace(b"femur", b"femurX", 1)
    with pytest.raises(ConnectionError, match="does not read as a motion file.*unknown bone"):
        fetch_cmu_mocap(5, trials=[1], data_home=tmp_path)
    assert not (_cache(tmp_path) / "05_01.amc").exists()


def test_incomplete_read_from_the_opener_is_retried(monkeypatch, tmp_path, server):
    """An opener that raises IncompleteRead mid-body (the raw http.client error)."""
    real = _fetch._urlopen
    calls = []

    def flaky(url, timeout):
        calls.append(url)
        if len(calls) == 1:
            raise http.client.IncompleteRead(b"partial", 100)
        return real(url, timeout)

    monkeypatch.setattr(_fetch, "_urlopen", flaky)
    data = fetch_cmu_mocap(5, trials=[2], data_home=tmp_path)
    assert len(calls) == 3 and len(data.clips[0]) == 7


def test_concurrent_fetches_of_one_file(server, tmp_path):
    """Eight threads fetch the same subject at once: unique temporary names, atomic
    renames; every thread gets the whole file and the cache holds it once."""
    results, errors = [], []

    def fetch():
        try:
            results.append(fetch_cmu_mocap(5, trials=[1, 2], data_home=tmp_path))
        except Exception as exc:  # pragma: no cover - reported below
            errors.append(exc)

    threads = [threading.Thread(target=fetch) for _ in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    expected = _expected(server, tmp_path, "05_02.amc")
    assert all(np.array_equal(r.clips[1], expected) for r in results) and len(results) == 8
    assert sorted(p.name for p in _cache(tmp_path).iterdir()) == [
        "05.asf",
        "05_01.amc",
        "05_02.amc",
    ]


def test_verify_removes_a_bad_cached_file_and_downloads_it_again(server, tmp_path):
    fetch_cmu_mocap(5, data_home=tmp_path)
    cached = _cache(tmp_path) / "05_02.amc"
    cached.write_bytes(cached.read_bytes()[: len(cached.read_bytes()) // 2])  # an old cut file
    (_cache(tmp_path) / ".05_02.amc.abc.part").write_bytes(b"left by a killed process")
    with pytest.raises(MotionFileError):
        fetch_cmu_mocap(5, data_home=tmp_path)  # the cache is trusted without verify
    server.requests.clear()
    data = fetch_cmu_mocap(5, data_home=tmp_path, verify=True)
    assert "05_02.amc" in server.requests and "05_01.amc" not in server.requests
    np.testing.assert_array_equal(data.clips[1], _expected(server, tmp_path, "05_02.amc"))


@pytest.mark.parametrize(
    "subjects, trials, error, message",
    [
        ([2.7], None, TypeError, r"subjects must be whole numbers \(int\), got 2.7"),
        (2.0, None, TypeError, "got 2.0 of type float"),
        ([True], None, TypeError, "got True of type bool"),
        (np.array([5.0]), None, TypeError, "of type float64"),
        (["05"], None, TypeError, "got '05' of type str"),
        ([0], None, ValueError, "subjects must be positive, got 0"),
        ([], None, ValueError, "subjects is empty"),
        (5, [1.5], TypeError, "trials must be whole numbers"),
        (5, [-1], ValueError, "trials must be positive"),
    ],
)
def test_bad_ids_are_refused_before_any_request(server, tmp_path, subjects, trials, error, message):
    with pytest.raises(error, match=message):
        fetch_cmu_mocap(subjects, trials=trials, data_home=tmp_path)
    assert server.requests == []


def test_numpy_integers_are_ids(server, tmp_path):
    data = fetch_cmu_mocap(np.array([5]), trials=np.int64(1), data_home=tmp_path)
    assert data.trials.tolist() == ["05_01"]


def test_offline_is_one_error_naming_the_cache(monkeypatch, tmp_path):
    monkeypatch.setattr(_fetch, "_BACKOFF", 0.0)

    def offline(url, timeout):
        raise urllib.error.URLError("network is unreachable")

    monkeypatch.setattr(_fetch, "_urlopen", offline)
    with pytest.raises(ConnectionError, match=r"\(network is unreachable\) after 3 attempts"):
        fetch_cmu_mocap(5, data_home=tmp_path)
    assert list(_cache(tmp_path).iterdir()) == []
