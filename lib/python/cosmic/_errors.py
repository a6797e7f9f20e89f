"""The exceptions of the package `cosmic`: every one carries the C API's code and the reason.

The codes are those of lib/client/include/cosmic/client.h (COSMIC_E_*).
"""
from __future__ import annotations

OK = 0
E_INVALID = -1
E_TRANSPORT = -2
E_AGAIN = -3
E_TOO_LARGE = -4
E_UNBOUND = -5
E_UNAVAILABLE = -6
E_TIMEOUT = -7

CODE_NAMES = {
    E_INVALID: "COSMIC_E_INVALID",
    E_TRANSPORT: "COSMIC_E_TRANSPORT",
    E_AGAIN: "COSMIC_E_AGAIN",
    E_TOO_LARGE: "COSMIC_E_TOO_LARGE",
    E_UNBOUND: "COSMIC_E_UNBOUND",
    E_UNAVAILABLE: "COSMIC_E_UNAVAILABLE",
    E_TIMEOUT: "COSMIC_E_TIMEOUT",
}


class Error(Exception):
    """A libcosmic-client call failed: ``code`` is its COSMIC_E_* value, ``message`` the reason."""

    def __init__(self, code: int, message: str) -> None:
        super().__init__(code, message)
        self.code = code
        self.message = message

    def __str__(self) -> str:
        return f"{self.message} [{CODE_NAMES.get(self.code, self.code)}]"


class InvalidError(Error, ValueError):
    """COSMIC_E_INVALID: a bad argument (segment text, channel description, role, YAML file)."""


class TransportError(Error):
    """COSMIC_E_TRANSPORT: the network refused (interface down, participant failed)."""


class TooLargeError(Error, ValueError):
    """COSMIC_E_TOO_LARGE: an event larger than the channel's payload."""


class UnboundError(Error):
    """COSMIC_E_UNBOUND: no gateway binds the channel (CAN etag, or check_channel: not_found)."""


class UnavailableError(Error):
    """COSMIC_E_UNAVAILABLE: the gateway's control socket cannot be reached or answers nonsense."""


class NotReadyError(Error, TimeoutError):
    """COSMIC_E_TIMEOUT: no peer matched the channel within wait_ready()'s (or announce(ready=...)'s)
    timeout; the message names the channel, the segment, the role(s) still unmatched and the time
    waited. The channel stays announced and usable. Also a built-in TimeoutError."""


class ClosedError(Error):
    """A call on a client (or one of its channels) after close(); code COSMIC_E_INVALID."""


_BY_CODE = {
    E_INVALID: InvalidError,
    E_TRANSPORT: TransportError,
    E_TOO_LARGE: TooLargeError,
    E_UNBOUND: UnboundError,
    E_UNAVAILABLE: UnavailableError,
    E_TIMEOUT: NotReadyError,
}


def error_for(code: int, message: str) -> Error:
    """The exception for a C result code (the native module raises through this)."""
    return _BY_CODE.get(code, Error)(code, message)
