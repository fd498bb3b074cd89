#!/usr/bin/env python3
"""runout_client end to end: a real `runout serve` process, driven through the Python client.

Run with Debian's Python (python3-grpcio, python3-protobuf), from anywhere:

    /usr/bin/python3 clients/python/tests/test_client.py --runout build/bin/runout [-v]

What it does, as the C++ service tests do (tests/support/server_process.hpp):
- generates the protobuf/gRPC modules from service/proto into a temporary folder
  (generate_stubs.py, Debian's protoc and grpc_python_plugin) and imports runout_client from the
  source tree (clients/python) with them: no pip install needed;
- starts `runout serve --listen 127.0.0.1:0` (a free port) with a state directory, log file and
  tokens file in the temporary folder, one worker of one thread; waits for STATE/server.json (written
  once it listens) and reads the address from it;
- submits tests/data/arelen-30m.json (its DEM, area of interest and release uploaded), follows it to
  the end checking progress events, fetches the results and checks run.json and the rasters; checks
  the errors (unknown job: NOT_FOUND; no or a wrong token: UNAUTHENTICATED; a bad scenario:
  INVALID_ARGUMENT), cancels a long job, and talks TLS to a second server (self-signed certificate);
- stops the server by its pid (SIGTERM; SIGKILL to its process group after 20 s) in every case, and
  prints the server's log when a test failed.

Options: --runout PATH (default $RUNOUT_BIN, else build/bin/runout), --protoc, --grpc-python-plugin,
--keep (keep the temporary folder); the rest goes to unittest (e.g. -v, -k NAME).
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
import unittest
from pathlib import Path

import grpc

HERE = Path(__file__).resolve().parent
PACKAGE_ROOT = HERE.parent            # clients/python: runout_client and generate_stubs.py
SOURCE_DIR = PACKAGE_ROOT.parent.parent  # the repository
SCENARIO = SOURCE_DIR / "tests" / "data" / "arelen-30m.json"
ARELEN_DATA = SOURCE_DIR / "scenarios" / "data" / "arelen"
TOKEN = "python-client-test-token"

#: Set by main(): the parsed options and the run's temporary folder.
OPTIONS: argparse.Namespace
TMP: Path
#: Set by setUpModule: the server and the imported package.
SERVER: "ServerProcess"
rc = None  # the runout_client module


def sha256_of(p: Path) -> str:
    return hashlib.sha256(p.read_bytes()).hexdigest()


class ServerProcess:
    """`runout serve` as a child process on 127.0.0.1 with an ephemeral port (as the C++ tests'
    ServerProcess): standard error to DIR/server.err, the log to DIR/server.log."""

    def __init__(self, binary: str, root: Path, extra: list[str]) -> None:
        self.root = root
        self.state = root / "state"
        self.log_path = root / "server.log"
        self.err_path = root / "server.err"
        self.address = ""
        self.exit_code: int | None = None
        self.exited_early = False  # it had ended before stop() was called
        root.mkdir(parents=True, exist_ok=True)
        args = [binary, "serve", "--listen", "127.0.0.1:0", "--state-dir", str(self.state),
                "--log-file", str(self.log_path), *extra]
        with self.err_path.open("ab") as err:
            # A session of its own: a last-resort SIGKILL reaches the workers too.
            self.proc = subprocess.Popen(args, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=err,
                                         start_new_session=True)
        self.pid = self.proc.pid

    def wait_listening(self, timeout: float = 30.0) -> str:
        """Wait for STATE/server.json (written atomically once the server listens); returns the
        address. Fails when the server exits first or does not listen in time."""
        info = self.state / "server.json"
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise RuntimeError(f"runout serve exited with {self.proc.returncode} before listening:\n{self.errors()}")
            if info.exists():
                data = json.loads(info.read_text())
                if int(data.get("pid", 0)) != self.pid:
                    raise RuntimeError(f"server.json names pid {data.get('pid')}, not the server's {self.pid}")
                self.address = data["listen"]
                return self.address
            time.sleep(0.05)
        raise RuntimeError(f"runout serve did not listen within {timeout} s:\n{self.errors()}")

    def stop(self) -> int:
        """SIGTERM to the server's pid and wait for it (20 s; then SIGKILL to its process group).
        Returns its exit code (negative: the signal that ended it)."""
        if self.exit_code is not None:
            return self.exit_code
        self.exited_early = self.proc.poll() is not None
        if not self.exited_early:
            os.kill(self.pid, signal.SIGTERM)
            try:
                self.proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                os.killpg(self.pid, signal.SIGKILL)
                self.proc.wait()
        self.exit_code = self.proc.returncode
        return self.exit_code

    def errors(self) -> str:
        return self.err_path.read_text(errors="replace") if self.err_path.exists() else ""

    def log(self) -> str:
        return self.log_path.read_text(errors="replace") if self.log_path.exists() else ""


def setUpModule() -> None:
    global SERVER, rc
    # The stubs: generated into the temporary folder, found through runout_client's extended __path__.
    sys.path.insert(0, str(PACKAGE_ROOT))
    import generate_stubs

    stubs = TMP / "stubs"
    generate_stubs.generate(stubs, SOURCE_DIR / "service" / "proto", OPTIONS.protoc, OPTIONS.grpc_python_plugin)
    sys.path.insert(1, str(stubs))
    import runout_client

    rc = runout_client
    here = Path(runout_client.__file__).resolve()
    proto = Path(runout_client._proto.__file__).resolve()
    if here.parent != PACKAGE_ROOT / "runout_client" or not proto.is_relative_to(stubs.resolve()):
        raise RuntimeError(f"imported runout_client from {here} with stubs {proto}: expected the source tree and "
                           f"{stubs} (a stale runout_client/_proto in the source tree? remove it)")

    (TMP / "tokens").write_text(f"# the test's token\n{TOKEN}\n")
    SERVER = ServerProcess(OPTIONS.runout, TMP / "server",
                           ["--tokens", str(TMP / "tokens"), "--workers", "1", "--threads-per-run", "1"])
    unittest.addModuleCleanup(stop_server)
    SERVER.wait_listening()


def stop_server() -> None:
    code = SERVER.stop()
    if SERVER.exited_early:
        raise AssertionError(f"runout serve (pid {SERVER.pid}) ended on its own (exit status {code}) before the tests were done")
    if code != 0:
        raise AssertionError(f"runout serve (pid {SERVER.pid}) exited with {code} when stopped by SIGTERM")
    if (SERVER.state / "server.json").exists():
        raise AssertionError("the stopped server left STATE/server.json behind")


class ClientTest(unittest.TestCase):
    """One server for all tests; each test has a client of its own. Run in name order."""

    def setUp(self) -> None:
        self.client = rc.Client(SERVER.address, token=TOKEN, timeout=30)
        self.addCleanup(self.client.close)

    def assertRunoutError(self, code, call, *args, contains: str = "", **kwargs):
        with self.assertRaises(rc.RunoutError) as cm:
            r = call(*args, **kwargs)
            if hasattr(r, "__next__"):  # a watch: the call starts with the iteration
                next(r)
        self.assertEqual(cm.exception.code, code, str(cm.exception))
        self.assertIn(contains, cm.exception.message)
        return cm.exception

    def test_1_health_and_tokens(self) -> None:
        self.assertTrue(self.client.healthy())
        with rc.Client(SERVER.address) as anonymous:  # the health check needs no token ...
            self.assertTrue(anonymous.healthy())
            # ... the service does.
            self.assertRunoutError(grpc.StatusCode.UNAUTHENTICATED, anonymous.status, "any", contains="missing bearer token")
        with rc.Client(SERVER.address, token="not-the-token") as stranger:
            self.assertRunoutError(grpc.StatusCode.UNAUTHENTICATED, stranger.list_jobs().__next__,
                                   contains="unknown bearer token")

    def test_2_submit_watch_fetch(self) -> None:
        c = self.client
        # The inputs are uploaded and named by their upload references.
        sent = c.upload_inputs(SCENARIO)
        paths = [sent.dem.path, sent.area_of_interest.path, sent.releases[0].path]
        for p, name in zip(paths, ["davos_srtm3.tif", "aoi.geojson", "release.geojson"]):
            self.assertTrue(p.startswith("upload:") and p.endswith("/" + name), p)
        job = c.submit(SCENARIO)  # uploads again (free: content-addressed) and queues
        self.assertTrue(job.id)
        self.assertEqual(job.name, "In den Arelen at 30 m (test)")
        self.assertIn(job.state, (rc.QUEUED, rc.RUNNING))

        events = []
        final = c.wait(job.id, timeout=120, on_event=events.append)
        self.assertEqual(final.state, rc.SUCCEEDED, final.error)
        self.assertEqual(events[-1].state, rc.SUCCEEDED)
        progress = [e.progress for e in events if e.state == rc.RUNNING and e.progress.steps > 0]
        self.assertGreaterEqual(len(progress), 1, f"no progress among {len(events)} events")
        times = [p.simulated_s for p in progress]
        self.assertEqual(times, sorted(times))
        self.assertTrue(all(p.end_time_s == 600 and p.dt_s > 0 for p in progress))
        self.assertGreaterEqual(len(final.transitions), 3)  # submitted, started, completed
        self.assertGreater(final.result_bytes, 0)
        self.assertEqual(c.status(job.id).state, rc.SUCCEEDED)
        self.assertEqual(rc.state_name(final.state), "succeeded")
        self.assertIn(job.id, [j.id for j in c.list_jobs()])

        listed = {f.name: f.bytes for f in c.list_results(job.id)}
        for name in ("max_depth.tif", "max_speed.tif", "outline.geojson", "map_max_depth.png", "map_max_depth.pdf", "run.json", "job.log"):
            self.assertIn(name, listed)
        out = TMP / "results"
        fetched = c.fetch(job.id, out)
        self.assertEqual(sorted(p.name for p in fetched), sorted(listed))
        for p in fetched:
            self.assertTrue(p.is_file(), p)
            if p.name != "job.log":  # the log may grow after the listing
                self.assertEqual(p.stat().st_size, listed[p.name], p.name)
        self.assertEqual(list(out.glob("*.part")), [])

        record = c.run_record(job.id)
        self.assertIsInstance(record, dict)
        self.assertEqual(record, json.loads((out / "run.json").read_text()))
        self.assertEqual(record["engine"], "depth-averaged")
        self.assertEqual(record["scenario"]["name"], job.name)
        self.assertEqual(record["software"]["name"], "runout")
        self.assertIn(record["solver"]["stop"], ("end-time", "kinetic-energy"))
        self.assertGreater(record["results"]["max_depth_m"], 1.0)
        self.assertEqual(record["grid"]["crs"], "EPSG:32632")
        # The inputs the run read are the local files, byte for byte.
        digests = {i["sha256"] for i in record["inputs"]}
        for f in ("davos_srtm3.tif", "aoi.geojson", "release.geojson"):
            self.assertIn(sha256_of(ARELEN_DATA / f), digests, f)
        # Every output the record lists arrived; the rasters are GeoTIFFs.
        rasters = [o for o in record["outputs"] if o.endswith(".tif")]
        self.assertIn("max_depth.tif", rasters)
        for o in record["outputs"]:
            self.assertTrue((out / o).is_file(), f"{o} listed in run.json but not fetched")
        for o in rasters:
            self.assertIn((out / o).read_bytes()[:4], (b"II*\x00", b"MM\x00*", b"II+\x00", b"MM\x00+"), o)
        # The server saw three uploads (each input once; the second upload of each is the same one).
        ids = {line.split()[2] for line in SERVER.log().splitlines() if " upload " in line and " file(s), " in line}
        self.assertEqual(len(ids), 3, ids)

    def test_3_unknown_job(self) -> None:
        c, code = self.client, grpc.StatusCode.NOT_FOUND
        e = self.assertRunoutError(code, c.status, "no-such-job", contains="no job 'no-such-job'")
        self.assertIn("NOT_FOUND", str(e))
        for call in (c.cancel, c.list_results, c.run_record, c.watch):
            self.assertRunoutError(code, call, "no-such-job", contains="no-such-job")
        self.assertRunoutError(code, c.fetch, "no-such-job", TMP / "nothing")

    def test_3b_result_names(self) -> None:
        # What fetch writes under its folder: a plain name, or one folder and a plain name (a nest's results).
        from runout_client import client as mod
        for ok in ("run.json", "nest/run.json"):
            self.assertTrue(mod._plain_name(ok), ok)
        for bad in ("", ".x", "../jobs.db", "nest/../x", "a/b/c", "nest/", "/abs", "a\\b", "nest/.x"):
            self.assertFalse(mod._plain_name(bad), bad)

    def test_4_bad_scenarios(self) -> None:
        c, code = self.client, grpc.StatusCode.INVALID_ARGUMENT
        s = json.loads(SCENARIO.read_text())
        # Refused by the client: a field the scenario does not have, an input that is not there.
        self.assertRunoutError(code, c.submit, {**s, "dem_typo": {}}, base_dir=SCENARIO.parent, contains="dem_typo")
        self.assertRunoutError(code, c.submit, {**s, "dem": {"path": "nowhere.tif"}}, base_dir=SCENARIO.parent,
                               contains="nowhere.tif")
        # Refused by the server: a bad option, a path outside its (absent) data roots.
        bad = {**s, "numerics": {**s["numerics"], "limiter": "fancy"}}
        self.assertRunoutError(code, c.submit, bad, base_dir=SCENARIO.parent, contains="numerics.limiter")
        on_server = {**s, "dem": {"path": "data/arelen/davos_srtm3.tif"}}
        self.assertRunoutError(code, c.submit, on_server, server_paths=True, contains="no data roots")

    def test_5_companions_uploaded(self) -> None:
        # An ESRI ASCII grid travels with its .prj, as the C++ client sends it.
        tiny = SOURCE_DIR / "tests" / "data" / "tiny"
        from runout_client.scenarios import local_files

        files = local_files("dem.asc", tiny)
        self.assertEqual([f.name for f in files], ["dem.asc", "dem.prj"])
        r = self.client.upload(files)
        self.assertEqual(list(r.files), ["dem.asc", "dem.prj"])
        self.assertEqual(r.bytes, sum(f.stat().st_size for f in files))
        self.assertTrue(r.ref.startswith("upload:") and r.ref.endswith("/dem.asc"), r.ref)

    def test_6_cancel(self) -> None:
        c = self.client
        s = json.loads(SCENARIO.read_text())
        s["name"] = "long run, cancelled"
        s["numerics"].update(end_time_s=90000, stop_fraction=0)
        job = c.submit(s, base_dir=SCENARIO.parent)
        self.assertIn(job.state, (rc.QUEUED, rc.RUNNING))
        c.cancel(job.id)
        final = c.wait(job.id, timeout=60)
        self.assertEqual(final.state, rc.CANCELLED)
        self.assertEqual([f.name for f in c.list_results(job.id)], ["job.log"])
        self.assertRunoutError(grpc.StatusCode.FAILED_PRECONDITION, c.run_record, job.id, contains="only job.log")

    @unittest.skipUnless(shutil.which("openssl"), "needs the openssl program (Debian: openssl) for a certificate")
    def test_7_tls(self) -> None:
        # A second server, serving TLS with a self-signed certificate for 127.0.0.1.
        d = TMP / "tls"
        d.mkdir()
        cert, key = d / "cert.pem", d / "key.pem"
        subprocess.run(["openssl", "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-days", "1", "-subj", "/CN=localhost",
                        "-addext", "subjectAltName=IP:127.0.0.1,DNS:localhost", "-keyout", str(key), "-out", str(cert)],
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        srv = ServerProcess(OPTIONS.runout, d / "server",
                            ["--tls-cert", str(cert), "--tls-key", str(key), "--tokens", str(TMP / "tokens")])
        self.addCleanup(srv.stop)
        address = srv.wait_listening()
        with rc.Client(address, token=TOKEN, root_certificates=cert) as c:
            self.assertTrue(c.healthy())
            self.assertRunoutError(grpc.StatusCode.NOT_FOUND, c.status, "no-such-job")  # the token went through
        with rc.Client(address, token=TOKEN, root_certificates=cert.read_bytes()) as c:
            self.assertEqual(list(c.list_jobs()), [])
        with rc.Client(address, token=TOKEN) as plain:  # no TLS: no connection
            self.assertRunoutError(grpc.StatusCode.UNAVAILABLE, plain.status, "no-such-job", contains="cannot reach the server")
        self.assertEqual(srv.stop(), 0)


def main(argv: list[str]) -> int:
    global OPTIONS, TMP
    ap = argparse.ArgumentParser(description="runout_client against a real runout serve", add_help=False)
    ap.add_argument("--runout", default=os.environ.get("RUNOUT_BIN") or str(SOURCE_DIR / "build" / "bin" / "runout"))
    ap.add_argument("--protoc")
    ap.add_argument("--grpc-python-plugin")
    ap.add_argument("--keep", action="store_true")
    OPTIONS, rest = ap.parse_known_args(argv[1:])
    if not os.access(OPTIONS.runout, os.X_OK):
        print(f"test_client: no runout program at {OPTIONS.runout} (--runout PATH)", file=sys.stderr)
        return 2
    TMP = Path(tempfile.mkdtemp(prefix="runout-pyclient-"))
    started = time.monotonic()
    try:
        result = unittest.main(module=__name__, argv=[argv[0], *rest], exit=False).result
        ok = result.wasSuccessful() and result.testsRun > 0
        if not ok:
            for name in ("server.err", "server.log"):
                p = TMP / "server" / name
                if p.exists():
                    lines = p.read_text(errors="replace").splitlines()
                    print(f"--- {name} (last 40 lines) ---", *lines[-40:], sep="\n", file=sys.stderr)
        print(f"test_client: {'passed' if ok else 'FAILED'} in {time.monotonic() - started:.1f} s", file=sys.stderr)
        return 0 if ok else 1
    finally:
        if OPTIONS.keep:
            print(f"test_client: kept {TMP}", file=sys.stderr)
        else:
            shutil.rmtree(TMP, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main(sys.argv))
