"""A Python client of the runout avalanche hazard-mapping service (gRPC ``runout.v1.Runout``).

    import runout_client
    with runout_client.Client("127.0.0.1:50051", token="secret") as c:
        job = c.submit("scenario.json")            # uploads its DEM, area and releases
        job = c.wait(job.id, timeout=600)          # follows its progress to the end
        c.fetch(job.id, "results")                 # every result file, checksums verified
        print(c.run_record(job.id)["results"])     # run.json as a dict

The generated protobuf modules live in ``runout_client._proto`` and are re-exported here as
``scenario_pb2``, ``service_pb2`` and ``run_record_pb2``. They are made from the service's .proto
files by ``generate_stubs.py`` (during ``pip install``, or by hand into a folder of their own: this
package extends its ``__path__`` pkgutil-style, so ``DIR/runout_client/_proto`` on ``sys.path`` is
found when the package itself is imported from the source tree).
"""
import pkgutil

__path__ = pkgutil.extend_path(__path__, __name__)  # the generated _proto may lie in another sys.path entry

__version__ = "0.1.0"

try:
    from ._proto import run_record_pb2, scenario_pb2, service_pb2
except ModuleNotFoundError as _e:  # pragma: no cover - the message is the point
    if _e.name not in (__name__ + "._proto", __name__ + "._proto.service_pb2"):
        raise
    raise ImportError(
        "runout_client: the generated protobuf modules (runout_client._proto) are missing. Install the package "
        "(pip install clients/python), or generate them: python3 clients/python/generate_stubs.py --out DIR, "
        "and put DIR on sys.path beside clients/python.") from None

from .client import FINAL_STATES, Client, is_final, state_name
from .errors import RunoutError
from .scenarios import COMPANION_EXTENSIONS, load_scenario

#: Job states (runout.v1.JobState), for comparing with ``Job.state``.
QUEUED = service_pb2.QUEUED
RUNNING = service_pb2.RUNNING
SUCCEEDED = service_pb2.SUCCEEDED
FAILED = service_pb2.FAILED
CANCELLED = service_pb2.CANCELLED

__all__ = [
    "Client", "RunoutError", "state_name", "is_final", "load_scenario", "FINAL_STATES", "COMPANION_EXTENSIONS",
    "QUEUED", "RUNNING", "SUCCEEDED", "FAILED", "CANCELLED",
    "scenario_pb2", "service_pb2", "run_record_pb2",
]
