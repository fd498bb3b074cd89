"""runout_client.Client: the runout.v1.Runout service from Python.

It talks to ``runout serve`` as the C++ client (service/client/client.cpp) and ``runout submit``,
``status``, ``watch``, ``cancel`` and ``fetch`` do: the bearer token as ``authorization: Bearer
TOKEN`` metadata on every call of the service (none on the health check), a deadline on unary calls
only, inputs uploaded with ``UploadInput`` in chunks of 256 KiB and named in the scenario by the
reference the upload returns, downloads checked against the SHA-256 the server sends last.
"""
from __future__ import annotations

import hashlib
import io
import json
import os
from pathlib import Path
from typing import Any, BinaryIO, Callable, Iterable, Iterator, Mapping, Sequence

import grpc

from ._proto import health_pb2, health_pb2_grpc, scenario_pb2, service_pb2, service_pb2_grpc
from .errors import RunoutError
from .scenarios import UPLOAD_PREFIX, ScenarioLike, input_fields, load_scenario, local_files

#: Bytes per upload chunk: well below the server's smallest message limit (as the C++ client).
CHUNK_BYTES = 256 << 10

#: The states a job ends in.
FINAL_STATES = frozenset({service_pb2.SUCCEEDED, service_pb2.FAILED, service_pb2.CANCELLED})


def state_name(state: int) -> str:
    """The word the command line uses for a job state: "queued", "running", "succeeded", ..."""
    return {
        service_pb2.QUEUED: "queued",
        service_pb2.RUNNING: "running",
        service_pb2.SUCCEEDED: "succeeded",
        service_pb2.FAILED: "failed",
        service_pb2.CANCELLED: "cancelled",
    }.get(state, "unknown")


def is_final(state: int) -> bool:
    """True for succeeded, failed and cancelled."""
    return state in FINAL_STATES


def _plain_name(name: str) -> bool:
    """A result name that is safe to write under the output folder (as runout fetch checks): a plain
    file name, or one folder and a plain file name (a nest's ``nest/run.json``)."""
    def plain(part: str) -> bool:
        return bool(part) and not part.startswith(".") and "/" not in part and "\\" not in part
    folder, slash, rest = name.partition("/")
    return plain(folder) and (not slash or plain(rest))


class Client:
    """A connection to a runout server (``runout serve``).

    Args:
        address: ``HOST:PORT`` of the server (``runout serve --listen``; default 127.0.0.1:50051).
        token: the bearer token (a line of the server's ``--tokens`` file); None or "": none sent,
            for a server without tokens.
        root_certificates: TLS with this CA certificate (PEM): a file's path or the PEM bytes, as
            ``runout submit --tls-ca``.
        tls: TLS with the system's root certificates (``--tls``); implied by root_certificates.
        timeout: deadline of unary calls in seconds (default 60, as the C++ client). Uploads,
            downloads and watches have none unless given.
        options: further gRPC channel arguments, e.g. ``[("grpc.ssl_target_name_override", "runout")]``.

    Methods return the service's protobuf messages (``Job``, ``ResultFile``, ``UploadResponse``;
    see ``runout_client.service_pb2``); a failed call raises :class:`RunoutError` with the gRPC
    status code and the server's message. Use as a context manager, or call :meth:`close`.

    Example::

        with Client("127.0.0.1:50051", token="secret") as c:
            job = c.submit("scenarios/arelen.json")
            final = c.wait(job.id, timeout=600)
            c.fetch(job.id, "results/arelen")
    """

    def __init__(self, address: str = "127.0.0.1:50051", *, token: str | None = None,
                 root_certificates: str | os.PathLike | bytes | None = None, tls: bool = False,
                 timeout: float = 60.0, options: Sequence[tuple[str, Any]] = ()) -> None:
        self.address = address
        self.timeout = timeout
        self._metadata = (("authorization", f"Bearer {token}"),) if token else ()
        opts = [("grpc.max_receive_message_length", 64 << 20), *options]
        if root_certificates is not None or tls:
            pem = None
            if isinstance(root_certificates, bytes):
                pem = root_certificates
            elif root_certificates is not None:
                try:
                    pem = Path(root_certificates).read_bytes()
                except OSError as e:
                    raise RunoutError(grpc.StatusCode.INVALID_ARGUMENT,
                                      f"TLS CA certificate '{root_certificates}': cannot read it ({e.strerror})", "connect") from None
            self._channel = grpc.secure_channel(address, grpc.ssl_channel_credentials(root_certificates=pem), options=opts)
        else:
            self._channel = grpc.insecure_channel(address, options=opts)
        self._stub = service_pb2_grpc.RunoutStub(self._channel)

    @classmethod
    def from_env(cls, **kwargs: Any) -> "Client":
        """A client configured as the command line's: ``$RUNOUT_SERVER`` (default 127.0.0.1:50051)
        and ``$RUNOUT_TOKEN``; keyword arguments override them."""
        kwargs.setdefault("address", os.environ.get("RUNOUT_SERVER") or "127.0.0.1:50051")
        kwargs.setdefault("token", os.environ.get("RUNOUT_TOKEN") or None)
        return cls(**kwargs)

    def close(self) -> None:
        """Close the channel (calls in progress are cancelled)."""
        self._channel.close()

    def __enter__(self) -> "Client":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"runout_client.Client({self.address!r})"

    # --- plumbing ---------------------------------------------------------------------------

    def _unary(self, method: Callable[..., Any], request: Any, context: str) -> Any:
        try:
            return method(request, metadata=self._metadata, timeout=self.timeout)
        except grpc.RpcError as e:
            raise RunoutError.from_rpc(e, context) from None

    # --- the service ------------------------------------------------------------------------

    def healthy(self, timeout: float = 5.0) -> bool:
        """The standard gRPC health check of the whole server (no token needed): True when SERVING."""
        stub = health_pb2_grpc.HealthStub(self._channel)
        try:
            r = stub.Check(health_pb2.HealthCheckRequest(), timeout=timeout)
        except grpc.RpcError as e:
            raise RunoutError.from_rpc(e, "health check") from None
        return r.status == health_pb2.HealthCheckResponse.SERVING

    def upload(self, paths: Sequence[str | os.PathLike]) -> service_pb2.UploadResponse:
        """Upload one input: ``paths[0]`` is the file a scenario names, the rest its companions
        (e.g. a shapefile's .shx, .dbf, .prj), all sent under their file names.

        Returns the UploadResponse; its ``ref`` ("upload:ID/NAME") is what a scenario names
        instead of the path. Uploads are content-addressed: sending the same files again is free.
        """
        files = [Path(p) for p in paths]
        if not files:
            raise RunoutError(grpc.StatusCode.INVALID_ARGUMENT, "no file to upload", "upload")
        for f in files:
            if not f.is_file() or not os.access(f, os.R_OK):
                raise RunoutError(grpc.StatusCode.INVALID_ARGUMENT, f"cannot read '{f}' to upload it", "upload")

        def chunks() -> Iterator[service_pb2.UploadChunk]:
            for f in files:
                with f.open("rb") as src:
                    data = src.read(CHUNK_BYTES)
                    yield service_pb2.UploadChunk(file_name=f.name, data=data)  # an empty file: one empty chunk
                    while data:
                        data = src.read(CHUNK_BYTES)
                        if data:
                            yield service_pb2.UploadChunk(file_name=f.name, data=data)

        try:
            return self._stub.UploadInput(chunks(), metadata=self._metadata)
        except grpc.RpcError as e:
            raise RunoutError.from_rpc(e, f"upload of '{files[0]}'") from None

    def upload_inputs(self, scenario: ScenarioLike, *, files: Mapping[str, str | os.PathLike] | None = None,
                      base_dir: str | os.PathLike | None = None) -> scenario_pb2.Scenario:
        """The scenario with every input uploaded and its path replaced by the upload's reference.

        The inputs are those the C++ client uploads (``dem.path``, ``area_of_interest.path``,
        ``releases[].path``), each with its companion files (runout_client.scenarios). A path that
        already is an upload reference is kept. Relative paths start in ``base_dir`` (default: the
        scenario file's folder, or the current folder for a dict or message); ``files`` maps a path
        as the scenario writes it to the local file to upload for it.
        """
        s, base = load_scenario(scenario, base_dir)
        for f in input_fields(s):
            if f.path.startswith(UPLOAD_PREFIX):
                continue
            f.set(self.upload(local_files(f.path, base, files)).ref)
        return s

    def submit(self, scenario: ScenarioLike, *, files: Mapping[str, str | os.PathLike] | None = None,
               base_dir: str | os.PathLike | None = None, request_id: str = "",
               server_paths: bool = False) -> service_pb2.Job:
        """Upload the scenario's inputs and queue it (``runout submit``); returns the Job.

        ``scenario`` is a JSON file's path, a dict in the JSON form or a runout.v1.Scenario. Its
        inputs are uploaded as :meth:`upload_inputs` describes (``files``, ``base_dir``); with
        ``server_paths=True`` they are sent as written, for files inside the server's data roots
        (``runout submit --server-paths``). ``request_id`` makes retries of one submission safe:
        a repeated id answers the job it created. An identical scenario of the same client
        answers its existing job (unless that one failed or was cancelled).
        """
        if server_paths:
            s, _ = load_scenario(scenario, base_dir)
        else:
            s = self.upload_inputs(scenario, files=files, base_dir=base_dir)
        return self._unary(self._stub.SubmitScenario, service_pb2.SubmitRequest(scenario=s, request_id=request_id), "submit")

    def status(self, job_id: str) -> service_pb2.Job:
        """The job now: state, progress while it runs, error, transitions, result size."""
        return self._unary(self._stub.GetJob, service_pb2.GetJobRequest(id=job_id), f"job {job_id}")

    def list_jobs(self, states: Iterable[int] = (), page_size: int = 200) -> Iterator[service_pb2.Job]:
        """This client's jobs, newest first, over every page; ``states`` (e.g.
        ``[runout_client.RUNNING]``) keeps only those."""
        token = ""
        while True:
            r = self._unary(self._stub.ListJobs,
                            service_pb2.ListJobsRequest(states=list(states), page_size=page_size, page_token=token), "list jobs")
            yield from r.jobs
            token = r.next_page_token
            if not token:
                return

    def cancel(self, job_id: str) -> service_pb2.Job:
        """Cancel a queued or running job. A queued job is cancelled at once; a running one stays
        RUNNING until its worker stops at the end of its current step (see :meth:`wait`)."""
        return self._unary(self._stub.CancelJob, service_pb2.CancelJobRequest(id=job_id), f"cancel {job_id}")

    def watch(self, job_id: str, timeout: float | None = None) -> Iterator[service_pb2.Job]:
        """Follow a job: yields the Job at every event until it ends (``runout watch``).

        The first event is the job's current state; then one per change of state or progress
        (``job.progress``: simulated time, step, volume, speed, ...), the last one in a final
        state. ``timeout`` bounds the whole watch (RunoutError DEADLINE_EXCEEDED). The call starts
        when iteration starts, so an unknown job raises RunoutError (NOT_FOUND) at the first
        ``next()``. Leaving the loop early cancels the call.
        """
        call = self._stub.WatchJob(service_pb2.WatchJobRequest(id=job_id), metadata=self._metadata, timeout=timeout)
        try:
            for ev in call:
                yield ev.job
        except grpc.RpcError as e:
            raise RunoutError.from_rpc(e, f"watch {job_id}") from None
        finally:
            call.cancel()

    def wait(self, job_id: str, timeout: float | None = None,
             on_event: Callable[[service_pb2.Job], None] | None = None) -> service_pb2.Job:
        """Follow a job to its end and return it in its final state (succeeded, failed with
        ``job.error``, or cancelled); ``on_event`` sees every event on the way. ``timeout`` (s)
        bounds the wait: RunoutError DEADLINE_EXCEEDED (the job goes on)."""
        last = None
        for job in self.watch(job_id, timeout=timeout):
            last = job
            if on_event is not None:
                on_event(job)
        if last is None or not is_final(last.state):
            raise RunoutError(grpc.StatusCode.UNKNOWN, "the server ended the watch before the job ended", f"watch {job_id}")
        return last

    def list_results(self, job_id: str) -> list[service_pb2.ResultFile]:
        """The files of a job that can be downloaded (name, bytes): the results of a succeeded
        job and its log ``job.log``; of a failed or cancelled job the log only."""
        return list(self._unary(self._stub.ListResults, service_pb2.ListResultsRequest(job_id=job_id),
                                f"results of {job_id}").files)

    def _download(self, job_id: str, name: str, sink: BinaryIO) -> int:
        """Stream one result into ``sink``; checks its SHA-256 and size; returns the bytes."""
        context = f"download {name} of {job_id}"
        h = hashlib.sha256()
        expected, total, n = "", -1, 0
        call = self._stub.DownloadResult(service_pb2.DownloadResultRequest(job_id=job_id, name=name), metadata=self._metadata)
        try:
            for c in call:
                if n == 0 and c.total_bytes:
                    total = c.total_bytes
                if c.offset != n:
                    raise RunoutError(grpc.StatusCode.DATA_LOSS, f"chunk at offset {c.offset}, expected {n}", context)
                sink.write(c.data)
                h.update(c.data)
                n += len(c.data)
                if c.sha256:
                    expected = c.sha256
        except grpc.RpcError as e:
            raise RunoutError.from_rpc(e, context) from None
        finally:
            call.cancel()
        if not expected or h.hexdigest() != expected or (total >= 0 and n != total):
            raise RunoutError(grpc.StatusCode.DATA_LOSS, "checksum mismatch", context)
        return n

    def download(self, job_id: str, name: str, dest: str | os.PathLike) -> Path:
        """Download one result (a name from :meth:`list_results`) to the file ``dest``.

        Written to ``dest.part`` first and renamed once its SHA-256 matches the server's, so
        ``dest`` is either complete or untouched. Returns ``dest`` as a Path.
        """
        dest = Path(dest)
        part = dest.with_name(dest.name + ".part")
        try:
            with part.open("wb") as out:
                self._download(job_id, name, out)
            os.replace(part, dest)
        except BaseException:
            part.unlink(missing_ok=True)
            raise
        return dest

    def read_result(self, job_id: str, name: str) -> bytes:
        """One result's content in memory (checksum verified)."""
        buf = io.BytesIO()
        self._download(job_id, name, buf)
        return buf.getvalue()

    def fetch(self, job_id: str, out_dir: str | os.PathLike) -> list[Path]:
        """Download every file :meth:`list_results` names into ``out_dir`` (created when missing;
        files of the same names are replaced). Returns their paths, in the server's order.

        For a job that did not succeed only its log is listed, so only ``job.log`` arrives:
        check the job's state (:meth:`status`) to tell.
        """
        out = Path(out_dir)
        out.mkdir(parents=True, exist_ok=True)
        paths = []
        for f in self.list_results(job_id):
            if not _plain_name(f.name):
                raise RunoutError(grpc.StatusCode.DATA_LOSS, f"the server named a result '{f.name}': not a plain file name",
                                  f"fetch {job_id}")
            (out / f.name).parent.mkdir(parents=True, exist_ok=True)
            paths.append(self.download(job_id, f.name, out / f.name))
        return paths

    def run_record(self, job_id: str) -> dict[str, Any]:
        """The run record of a succeeded job (its ``run.json``) as a dict.

        Field names as in run_record.proto (snake_case); a figure that could not be computed is
        the string "NaN" (protobuf's JSON form). ``json_format.ParseDict(record,
        runout_client.run_record_pb2.RunRecord(), ignore_unknown_fields=True)`` gives the typed
        message. A job that has not succeeded raises RunoutError FAILED_PRECONDITION.
        """
        return json.loads(self.read_result(job_id, "run.json"))
