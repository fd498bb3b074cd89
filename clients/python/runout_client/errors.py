"""The one exception runout_client raises for a failed call or a refused input."""
from __future__ import annotations

import grpc


class RunoutError(Exception):
    """A call to the runout server failed, or the client refused an input before calling.

    Attributes:
        code: the gRPC status code (a ``grpc.StatusCode``), as the server answered it; the client's
            own refusals use the code the C++ client uses for them (``INVALID_ARGUMENT`` for a
            scenario or input file it cannot read, ``DATA_LOSS`` for a download whose checksum
            does not match, ``UNAVAILABLE`` when the server cannot be reached).
        message: the server's message (the gRPC status details), e.g. ``"no job 'abc'"``.
        context: what the client was doing, e.g. ``"status of abc"``.

    The service's codes (service/proto/runout/v1/service.proto): INVALID_ARGUMENT (a bad scenario or
    request; the message names the field), FAILED_PRECONDITION (e.g. results of a job that has not
    succeeded), RESOURCE_EXHAUSTED (queue limit, upload size), NOT_FOUND (unknown job, result or
    upload; also another client's job), ALREADY_EXISTS (a request id reused for another scenario),
    CANCELLED, UNAUTHENTICATED (missing or unknown bearer token), INTERNAL.
    """

    def __init__(self, code: grpc.StatusCode, message: str, context: str = "") -> None:
        self.code = code
        self.message = message
        self.context = context
        text = f"{code.name}: {message}"
        super().__init__(f"{context}: {text}" if context else text)

    @classmethod
    def from_rpc(cls, e: grpc.RpcError, context: str) -> "RunoutError":
        """The RunoutError of a failed gRPC call (``e`` is a grpc.RpcError that is also a grpc.Call)."""
        code = e.code() if hasattr(e, "code") else grpc.StatusCode.UNKNOWN
        message = (e.details() if hasattr(e, "details") else "") or str(e)
        if code == grpc.StatusCode.UNAVAILABLE:
            message = f"cannot reach the server ({message})"
        return cls(code, message, context)
