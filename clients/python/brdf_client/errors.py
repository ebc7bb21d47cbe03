"""BrdfError: what a failed call to brdfd raises.

brdfd answers failures with gRPC status codes (brdf.proto: INVALID_ARGUMENT for a bad plan or a
direction out of range, NOT_FOUND for an unknown session, FAILED_PRECONDITION for a verb the
session's state does not allow, UNAUTHENTICATED / PERMISSION_DENIED for tokens, UNAVAILABLE when
the daemon or a device is down, ...) and a message saying what failed and what to do. BrdfError
keeps both, so callers can branch on `code` and show `message` as is.
"""

import grpc


class BrdfError(Exception):
    """A gRPC call to brdfd failed.

    Attributes:
      code:    grpc.StatusCode, e.g. grpc.StatusCode.UNAUTHENTICATED.
      message: the daemon's message (what failed, where, what to do).
      method:  the API call that failed, e.g. "Control.SubmitPlan".
    """

    def __init__(self, code, message, method=""):
        self.code = code
        self.message = message
        self.method = method
        where = f"{method}: " if method else ""
        super().__init__(f"{where}{code.name}: {message}")

    @property
    def code_name(self):
        """The status code's name, e.g. "NOT_FOUND"."""
        return self.code.name

    @classmethod
    def from_rpc_error(cls, error, method=""):
        """Converts a grpc.RpcError (as raised by a stub or a stream) into a BrdfError."""
        code = error.code() if hasattr(error, "code") else grpc.StatusCode.UNKNOWN
        details = error.details() if hasattr(error, "details") else str(error)
        if code == grpc.StatusCode.UNAVAILABLE and not details:
            details = "brdfd is not reachable; check the address and that the daemon runs"
        return cls(code, details or "", method)
