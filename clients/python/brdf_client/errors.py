"""BrdfError: what a failed call to brdfd raises, one subclass per status code worth branching on.

brdfd answers failures with gRPC status codes (brdf.proto: INVALID_ARGUMENT for a bad plan or a
direction out of range, NOT_FOUND for an unknown session, FAILED_PRECONDITION for a verb the
session's state does not allow, UNAUTHENTICATED / PERMISSION_DENIED for tokens, UNAVAILABLE when
the daemon or a device is down, ...) and a message saying what failed and what to do. BrdfError
keeps both, so callers can branch on `code` and show `message` as is:

    try:
        brdf.get_session("99")
    except brdf_client.NotFound as e:        # or: except BrdfError as e: if e.code_name == ...
        print(e.code_name, e.message)         # NOT_FOUND session 99 does not exist ...

As OSError does with errno, BrdfError(code, ...) makes the subclass of that code (NotFound for
NOT_FOUND, ...), so `except BrdfError` catches them all and every existing check of `.code` holds.
"""

from typing import Any, Dict, Type

import grpc


class BrdfError(Exception):
    """A gRPC call to brdfd failed.

    Attributes:
      code:    grpc.StatusCode, e.g. grpc.StatusCode.UNAUTHENTICATED.
      message: the daemon's message (what failed, where, what to do).
      method:  the API call that failed, e.g. "Control.SubmitPlan".
    """

    code: grpc.StatusCode
    message: str
    method: str

    def __new__(cls, code: grpc.StatusCode = grpc.StatusCode.UNKNOWN, message: str = "",
                method: str = "") -> "BrdfError":
        # pylint: disable=unused-argument
        if cls is BrdfError:
            cls = _BY_CODE.get(code, BrdfError)
        return super().__new__(cls)

    def __init__(self, code: grpc.StatusCode = grpc.StatusCode.UNKNOWN, message: str = "",
                 method: str = "") -> None:
        self.code = code
        self.message = message
        self.method = method
        where = f"{method}: " if method else ""
        super().__init__(f"{where}{code.name}: {message}")

    def __reduce__(self) -> Any:
        return (BrdfError, (self.code, self.message, self.method))

    @property
    def code_name(self) -> str:
        """The status code's name, e.g. "NOT_FOUND"."""
        return str(self.code.name)

    @classmethod
    def from_rpc_error(cls, error: Any, method: str = "") -> "BrdfError":
        """Converts a grpc.RpcError (as raised by a stub or a stream) into a BrdfError."""
        code = error.code() if hasattr(error, "code") else grpc.StatusCode.UNKNOWN
        details = error.details() if hasattr(error, "details") else str(error)
        if code == grpc.StatusCode.UNAVAILABLE and not details:
            details = "brdfd is not reachable; check the address and that the daemon runs"
        return BrdfError(code, details or "", method)


class InvalidArgument(BrdfError):
    """INVALID_ARGUMENT: a bad plan, direction, step or option; the message names it."""


class NotFound(BrdfError):
    """NOT_FOUND: no such session (or reading)."""


class FailedPrecondition(BrdfError):
    """FAILED_PRECONDITION: the session's state does not allow the call, or it has no usable
    readings for it."""


class Unauthenticated(BrdfError):
    """UNAUTHENTICATED: no token, or one the daemon does not know."""


class PermissionDenied(BrdfError):
    """PERMISSION_DENIED: the token's role may not do this (an analyst token only reads)."""


class Unavailable(BrdfError):
    """UNAVAILABLE: the daemon cannot be reached, or a device is down."""


class DeadlineExceeded(BrdfError):
    """DEADLINE_EXCEEDED: the call's timeout passed."""


class Cancelled(BrdfError):
    """CANCELLED: the call was cancelled (by this client or the daemon's shutdown)."""


class DataLoss(BrdfError):
    """DATA_LOSS: a stream arrived incomplete (a gap, a byte count that disagrees)."""


_BY_CODE: Dict[grpc.StatusCode, Type[BrdfError]] = {
    grpc.StatusCode.INVALID_ARGUMENT: InvalidArgument,
    grpc.StatusCode.NOT_FOUND: NotFound,
    grpc.StatusCode.FAILED_PRECONDITION: FailedPrecondition,
    grpc.StatusCode.UNAUTHENTICATED: Unauthenticated,
    grpc.StatusCode.PERMISSION_DENIED: PermissionDenied,
    grpc.StatusCode.UNAVAILABLE: Unavailable,
    grpc.StatusCode.DEADLINE_EXCEEDED: DeadlineExceeded,
    grpc.StatusCode.CANCELLED: Cancelled,
    grpc.StatusCode.DATA_LOSS: DataLoss,
}
