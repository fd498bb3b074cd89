"""Running a scenario file: locally with the ``runout`` program, or as a job of a ``runout serve``.

Nothing here imports QGIS: ``feedback`` is anything with QgsProcessingFeedback's ``isCanceled()``,
``setProgress(percent)``, ``setProgressText(text)``, ``pushInfo(text)`` and ``pushDebugInfo(text)``,
so the module can be used (and tested) outside QGIS as well.

Both runners put the results into ``out_dir`` as ``runout run --out DIR --force`` does: an existing
``out_dir`` is replaced only when it holds a previous result of runout (its ``run.json``), and
only once the new result is complete.
"""
from __future__ import annotations

import hashlib
import json
import os
import queue
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

#: runout's exit codes (docs/user/cli.md) and what they mean.
EXIT_CODES = {
    1: "a verification figure outside its tolerance",
    2: "bad command line",
    3: "internal error",
    4: "invalid scenario or input data",
    5: "the output directory exists, is not a previous result or cannot be written",
    6: "run cancelled",
    7: "the server cannot be reached or refused the call",
    8: "the job failed",
}

#: The progress line `runout run` writes to standard error (service/cli/run_cmd.cpp), one per line
#: when standard error is not a terminal:
#: "t =   12.34 s  dt = 0.0123 s  volume = 2.873e+05 m3  max speed =  45.10 m/s  active =  12.3 %  time left <= 4 s"
PROGRESS_LINE = re.compile(r"^\s*t =\s*(?P<t>[-+0-9.eE]+) s\s+dt =\s*(?P<dt>[-+0-9.eE]+) s"
                           r"(?:.*?max speed =\s*(?P<speed>[-+0-9.eE]+) m/s)?"
                           r"(?:.*?time left <=\s*(?P<left>[-+0-9.eE]+) s)?")


class RunError(Exception):
    """A run that failed; the message is runout's own (or the service's) error."""


class RunCancelled(RunError):
    """The run was cancelled through the feedback (local: SIGTERM to runout; service: CancelJob)."""


def find_program(given: str | None = None) -> str:
    """The runout program: ``given`` (a path or a name on PATH), else ``runout`` on PATH, else $RUNOUT_PROGRAM."""
    def executable(p: str) -> str | None:
        q = Path(p).expanduser()
        if q.is_file() and os.access(q, os.X_OK):
            return str(q)
        return shutil.which(p)

    if given:
        found = executable(given)
        if found:
            return found
        raise RunError(f"the runout program '{given}' does not exist or is not executable")
    found = shutil.which("runout")
    if found:
        return found
    env = os.environ.get("RUNOUT_PROGRAM")
    if env:
        found = executable(env)
        if found:
            return found
        raise RunError(f"runout is not on PATH, and RUNOUT_PROGRAM='{env}' is not an executable file")
    raise RunError("the runout program was not found: give its path (parameter PROGRAM), put 'runout' on PATH, "
                   "or set the environment variable RUNOUT_PROGRAM")


def end_time_of(scenario: dict) -> float:
    """The simulated time at most (numerics.end_time_s, default 600 s; VOF: the lab's or 600)."""
    try:
        lab = scenario.get("lab") or {}
        if lab:
            return float(lab.get("end_time_s") or lab.get("endTimeS") or 1.0)
        num = scenario.get("numerics") or {}
        return float(num.get("end_time_s") or num.get("endTimeS") or 600.0)
    except (TypeError, ValueError, AttributeError):
        return 600.0


def _is_previous_result(d: Path) -> bool:
    """A directory runout itself would replace with --force (its run.json names runout), or an empty one."""
    if not d.is_dir() or d.is_symlink():
        return False
    names = [p.name for p in d.iterdir()]
    if not names or names == ["job.log"]:
        return True
    try:
        rec = json.loads((d / "run.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    return isinstance(rec, dict) and (rec.get("software") or {}).get("name") == "runout"


def _reader(stream, tag: str, q: "queue.Queue[tuple[str, str | None]]") -> None:
    """Lines of a pipe into the queue (a progress line ended by '\\r' counts as a line); None at the end."""
    buf = ""
    while True:
        chunk = stream.read(1024)
        if not chunk:
            break
        buf += chunk
        while True:
            cut = min((i for i in (buf.find("\n"), buf.find("\r")) if i >= 0), default=-1)
            if cut < 0:
                break
            line, buf = buf[:cut], buf[cut + 1:]
            if line.strip():
                q.put((tag, line))
    if buf.strip():
        q.put((tag, buf))
    q.put((tag, None))


def run_local(scenario_path: str | os.PathLike, out_dir: str | os.PathLike, feedback, *, program: str | None = None,
              threads: int | None = None, end_time_s: float | None = None, poll_s: float = 0.2,
              kill_after_s: float = 30.0) -> dict:
    """``runout run SCENARIO --out OUT_DIR --force``, following its progress line.

    The simulated time of the progress line over ``end_time_s`` (default: the scenario's) becomes
    ``feedback.setProgress``. When ``feedback.isCanceled()``, runout gets SIGTERM (it stops at the
    end of the step and leaves no results: exit 6) and RunCancelled is raised; after
    ``kill_after_s`` without an end it is killed. A failed run raises RunError with runout's own
    message (its "runout run: ..." lines on standard error). Returns ``{"program", "stdout",
    "stderr", "seconds"}``.
    """
    exe = find_program(program)
    scenario_path = str(Path(scenario_path).resolve())
    out_dir = str(Path(out_dir).resolve())
    if end_time_s is None:
        try:
            end_time_s = end_time_of(json.loads(Path(scenario_path).read_text(encoding="utf-8")))
        except (OSError, ValueError):
            end_time_s = 600.0
    cmd = [exe, "run", scenario_path, "--out", out_dir, "--force"]
    if threads:
        cmd += ["--threads", str(int(threads))]
    feedback.pushInfo("Running: " + " ".join(_quote(c) for c in cmd))
    t0 = time.monotonic()
    try:
        proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                text=True, encoding="utf-8", errors="replace", bufsize=1)
    except OSError as e:
        raise RunError(f"cannot start '{exe}': {e.strerror or e}") from None
    q: "queue.Queue[tuple[str, str | None]]" = queue.Queue()
    readers = [threading.Thread(target=_reader, args=(proc.stdout, "out", q), daemon=True),
               threading.Thread(target=_reader, args=(proc.stderr, "err", q), daemon=True)]
    for r in readers:
        r.start()
    out_lines: list[str] = []
    err_lines: list[str] = []
    last_progress = ""
    open_streams = 2
    cancelled_at = None
    ended = None  # when runout's own process was seen ended
    shown = 0.0
    while open_streams:
        if cancelled_at is None and feedback.isCanceled():
            cancelled_at = time.monotonic()
            feedback.pushInfo("Cancelling: SIGTERM to runout (it stops at the end of the step)")
            _signal(proc, signal.SIGTERM)
        if cancelled_at is not None and time.monotonic() - cancelled_at > kill_after_s:
            _signal(proc, signal.SIGKILL)
        try:
            tag, line = q.get(timeout=poll_s)
        except queue.Empty:
            # runout has ended but a process it started (an ensemble's worker) still holds the pipes
            # open: stop reading a little after its end instead of waiting on them.
            if proc.poll() is not None:
                ended = ended if ended is not None else time.monotonic()
                if time.monotonic() - ended > 5 * poll_s + 1.0:
                    break
            continue
        if line is None:
            open_streams -= 1
            continue
        if tag == "err":
            m = PROGRESS_LINE.match(line)
            if m:
                last_progress = line.strip()
                t = float(m.group("t"))
                if end_time_s and end_time_s > 0:
                    shown = max(shown, min(99.0, 100.0 * t / end_time_s))
                    feedback.setProgress(shown)
                feedback.setProgressText(f"runout: t = {t:.1f} s of at most {end_time_s:g} s")
                continue
            err_lines.append(line)
            feedback.pushInfo(line)
        else:
            out_lines.append(line)
    rc = proc.wait()
    for r in readers:
        r.join(timeout=5)
    for stream in (proc.stdout, proc.stderr):
        stream.close()
    seconds = time.monotonic() - t0
    if last_progress:
        feedback.pushDebugInfo("last progress line: " + last_progress)
    if cancelled_at is not None or rc == 6:
        raise RunCancelled("the run was cancelled; runout left no results"
                           + (": " + "; ".join(err_lines) if err_lines else ""))
    if rc != 0:
        said = [ln[len("runout run: "):] if ln.startswith("runout run: ") else ln for ln in err_lines]
        what = EXIT_CODES.get(rc, f"killed by signal {-rc}" if rc < 0 else "failed")
        raise RunError(f"runout failed (exit {rc}: {what}): " + ("\n".join(said) if said else "no message"))
    for line in out_lines:
        feedback.pushInfo(line)
    feedback.setProgress(100.0)
    return {"program": exe, "stdout": "\n".join(out_lines), "stderr": "\n".join(err_lines), "seconds": seconds}


def _signal(proc: subprocess.Popen, sig: int) -> None:
    try:
        proc.send_signal(sig)
    except (ProcessLookupError, OSError):
        pass


def _quote(s: str) -> str:
    return s if re.fullmatch(r"[\w@%+=:,./-]+", s) else "'" + s.replace("'", "'\"'\"'") + "'"


# --- the service -------------------------------------------------------------------------------

def import_client():
    """runout_client (clients/python), importable with its generated gRPC modules, or RunError.

    Where it is looked for: QGIS's Python as it is (pip install clients/python); the folders of
    $RUNOUT_CLIENT_PATH (os.pathsep-separated: the package's parent and the generated modules'
    root, see clients/python/README.md); and, when this plugin lies in a runout checkout
    (clients/qgis/runout_provider, also through a symbolic link), clients/python beside it, whose
    modules are then generated from its service/proto into a cache folder, once per version of the
    .proto files (Debian's protoc and grpc_python_plugin: protobuf-compiler, protobuf-compiler-grpc).
    """
    try:
        import grpc  # noqa: F401
    except ImportError as e:
        raise RunError("the service needs gRPC for Python in QGIS's Python (Debian: python3-grpcio; "
                       f"also python3-protobuf): import grpc failed ({e})") from None
    try:
        import google.protobuf  # noqa: F401
    except ImportError as e:
        raise RunError("the service needs protobuf for Python in QGIS's Python (Debian: python3-protobuf): "
                       f"import google.protobuf failed ({e})") from None
    errors = []
    try:
        import runout_client
        return runout_client
    except ImportError as e:
        errors.append(str(e))
        _forget_client()
    extra = [p for p in os.environ.get("RUNOUT_CLIENT_PATH", "").split(os.pathsep) if p]
    checkout = Path(__file__).resolve().parent.parent.parent / "python"
    if (checkout / "runout_client" / "__init__.py").is_file():
        extra.append(str(checkout))
    for p in extra:
        if p not in sys.path:
            sys.path.append(p)
    if extra:
        try:
            import runout_client
            return runout_client
        except ImportError as e:
            errors.append(str(e))
            _forget_client()
    gen = checkout / "generate_stubs.py"
    if gen.is_file():
        try:
            stubs = _generated_stubs(gen)
            if stubs not in sys.path:
                sys.path.append(stubs)
            import runout_client
            return runout_client
        except Exception as e:  # noqa: BLE001 - every failure becomes the message below
            errors.append(f"generating its gRPC modules from {checkout.parent.parent / 'service' / 'proto'} failed: {e}")
            _forget_client()
    raise RunError("the service needs the Python client runout_client (clients/python of runout) with its generated "
                   "modules: install it into QGIS's Python (pip install clients/python), or set RUNOUT_CLIENT_PATH to "
                   "the folders that hold runout_client and its generated modules (clients/python/README.md). "
                   "Tried: " + " | ".join(errors))


def _generated_stubs(generate_stubs: Path) -> str:
    """The checkout's gRPC modules, generated once per version of its .proto files into
    $XDG_CACHE_HOME/runout/qgis-client-stubs/HASH (default ~/.cache): the root to put on sys.path."""
    proto_dir = generate_stubs.parent.parent.parent / "service" / "proto"
    h = hashlib.sha256()
    for p in sorted(proto_dir.rglob("*.proto")):
        h.update(str(p.relative_to(proto_dir)).encode() + b"\0" + p.read_bytes() + b"\0")
    h.update(generate_stubs.read_bytes())
    cache = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "runout" / "qgis-client-stubs"
    dest = cache / h.hexdigest()[:16]
    if (dest / "runout_client" / "_proto" / "service_pb2.py").is_file():
        return str(dest)
    import importlib.util
    spec = importlib.util.spec_from_file_location("runout_generate_stubs", generate_stubs)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    cache.mkdir(parents=True, exist_ok=True)
    tmp = tempfile.mkdtemp(prefix=".part-", dir=cache)
    try:
        mod.generate(tmp, proto_dir)
        try:
            os.rename(tmp, dest)  # atomic; another session may have made it meanwhile
        except OSError:
            if not (dest / "runout_client" / "_proto" / "service_pb2.py").is_file():
                raise
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return str(dest)


def _forget_client() -> None:
    for name in [n for n in sys.modules if n == "runout_client" or n.startswith("runout_client.")]:
        del sys.modules[name]


def run_service(scenario_path: str | os.PathLike, out_dir: str | os.PathLike, feedback, *, server: str | None = None,
                token: str | None = None, tls_ca: str | None = None, poll_s: float = 1.0,
                cancel_wait_s: float = 120.0) -> dict:
    """Submit the scenario to a runout server, follow its progress, fetch its results into out_dir.

    ``server`` defaults to $RUNOUT_SERVER, else 127.0.0.1:50051; ``token`` to $RUNOUT_TOKEN. When
    ``feedback.isCanceled()`` the job is cancelled (CancelJob) and RunCancelled raised once it has
    ended. A failed job raises RunError with the job's error. Returns ``{"job", "server", "files"}``.
    """
    rc = import_client()
    server = server or os.environ.get("RUNOUT_SERVER") or "127.0.0.1:50051"
    token = token or os.environ.get("RUNOUT_TOKEN") or None
    out = Path(out_dir).resolve()
    if out.exists() and not _is_previous_result(out):
        raise RunError(f"the output directory '{out}' exists and is not a previous result of runout "
                       "(its run.json); choose another")
    try:
        with rc.Client(server, token=token, root_certificates=tls_ca or None) as c:
            feedback.pushInfo(f"Submitting {scenario_path} to the runout server {server}")
            job = c.submit(str(scenario_path))
            feedback.pushInfo(f"Job {job.id}: {rc.state_name(job.state)}")
            cancelled = False
            cancel_t = 0.0
            last_state = job.state
            shown = 0.0
            while not rc.is_final(job.state):
                if not cancelled and feedback.isCanceled():
                    feedback.pushInfo(f"Cancelling job {job.id}")
                    c.cancel(job.id)
                    cancelled, cancel_t = True, time.monotonic()
                if cancelled and time.monotonic() - cancel_t > cancel_wait_s:
                    raise RunCancelled(f"job {job.id} was cancelled; it had not ended after {cancel_wait_s:.0f} s")
                time.sleep(poll_s)
                job = c.status(job.id)
                if job.state != last_state:
                    feedback.pushInfo(f"Job {job.id}: {rc.state_name(job.state)}")
                    last_state = job.state
                p = job.progress
                end = p.end_time_s or 0.0
                if end > 0 and p.simulated_s > 0:
                    shown = max(shown, min(99.0, 100.0 * p.simulated_s / end))
                    feedback.setProgress(shown)
                    feedback.setProgressText(f"job {job.id}: t = {p.simulated_s:.1f} s of at most {end:g} s")
            if job.state == rc.CANCELLED or cancelled:
                raise RunCancelled(f"job {job.id} was cancelled; no results fetched")
            if job.state != rc.SUCCEEDED:
                raise RunError(f"job {job.id} failed: {job.error or 'no message'}")
            part = out.parent / f".{out.name}.part-{os.getpid()}"
            if part.exists():
                shutil.rmtree(part)
            files = c.fetch(job.id, part)
            _swap_in(part, out)
            feedback.setProgress(100.0)
            return {"job": job.id, "server": server, "files": [str(out / Path(f).name) for f in files]}
    except rc.RunoutError as e:
        raise RunError(f"runout server {server}: {e}") from None


def _swap_in(new: Path, dest: Path) -> None:
    """new becomes dest; a previous result at dest is removed once new is in place."""
    old = None
    if dest.exists():
        old = dest.parent / f".{dest.name}.old-{os.getpid()}"
        os.replace(dest, old)
    try:
        os.replace(new, dest)
    except OSError:
        if old is not None:
            os.replace(old, dest)
        raise
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)
