"""cosmic: COSMIC event channels from Python, over libcosmic-client (docs/components.md, "Python").

A component attaches to the segment it lives on and joins channels by name and subject, never by
address; cosmicd forwards its events like any other publisher's::

    import cosmic, numpy as np
    with cosmic.Client("dds:0") as lan:
        # ready=5.0: returns once the gateway's reader matched (cosmic.NotReadyError after 5 s)
        distance = lan.announce_from("config/robot.yaml", "distance", roles=cosmic.PUBLISH, ready=5.0)
        distance.publish(np.array([1.25], dtype="<f4"))     # the array's memory, no copy
        obstacle = lan.announce("obstacle", 0x100000050, cls="hrt", payload=1, roles="subscribe")
        event = obstacle.get_event(timeout=0.1)              # None after 100 ms without one

Durations (period, reaction_time, temp_validity, timeouts) are seconds, int or float, or a string
in the YAML's units ("10ms"); they reach the C API rounded to whole nanoseconds.
"""
from __future__ import annotations

import atexit
import dataclasses
import enum
from typing import Iterable, Optional, Union

from . import _native
from ._errors import (
    E_AGAIN,
    E_INVALID,
    E_TIMEOUT,
    E_TOO_LARGE,
    E_TRANSPORT,
    E_UNAVAILABLE,
    E_UNBOUND,
    OK,
    ClosedError,
    Error,
    InvalidError,
    NotReadyError,
    TooLargeError,
    TransportError,
    UnavailableError,
    UnboundError,
)
from ._native import Channel, Event, check_channel, parse_duration_ns
from ._typed import ChannelType

__all__ = [
    "Channel", "ChannelDesc", "ChannelType", "Client", "ClosedError", "Error", "Event", "InvalidError", "NotReadyError", "PUBLISH",
    "Role", "SUBSCRIBE", "TooLargeError", "TransportError", "UnavailableError", "UnboundError", "check_channel",
    "load_channel", "parse_duration_ns", "OK", "E_INVALID", "E_TRANSPORT", "E_AGAIN", "E_TOO_LARGE",
    "E_UNBOUND", "E_UNAVAILABLE", "E_TIMEOUT",
]


class Role(enum.IntFlag):
    """A component's roles on a channel (COSMIC_PUBLISH, COSMIC_SUBSCRIBE)."""

    PUBLISH = _native.PUBLISH
    SUBSCRIBE = _native.SUBSCRIBE


PUBLISH = Role.PUBLISH
SUBSCRIBE = Role.SUBSCRIBE

Duration = Union[int, float, str, None]
Roles = Union[Role, int, str, Iterable[str]]

_CLASSES = {"hrt": 0, "srt": 1, "nrt": 2}


def _ns(value: Duration, what: str) -> int:
    """Seconds (int or float) or a YAML duration ("10ms") in whole nanoseconds; None is 0 (not given)."""
    if value is None:
        return 0
    if isinstance(value, str):
        return parse_duration_ns(value)
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise TypeError(f"{what}: seconds (int or float) or a duration such as '10ms', not {type(value).__name__}")
    if not value >= 0:
        raise InvalidError(E_INVALID, f"{what}: {value!r} s is not a duration (>= 0)")
    return round(value * 1_000_000_000)


def _seconds(ns: Optional[int]) -> Optional[float]:
    return None if ns is None else ns / 1e9


def _roles(value: Roles) -> int:
    if isinstance(value, int):
        roles = int(value)
    else:
        names = [value] if isinstance(value, str) else list(value)
        roles = 0
        for name in (part.strip() for text in names for part in text.replace("|", ",").split(",")):
            try:
                roles |= Role[name.upper()]
            except KeyError:
                raise InvalidError(E_INVALID, f"roles: unknown role {name!r} (publish, subscribe)") from None
    if roles & ~(PUBLISH | SUBSCRIBE) or not roles:
        raise InvalidError(E_INVALID, f"roles: {value!r} is none of PUBLISH, SUBSCRIBE, PUBLISH | SUBSCRIBE")
    return roles


def _class(value: Union[str, int]) -> int:
    if isinstance(value, str) and value.lower() in _CLASSES:
        return _CLASSES[value.lower()]
    if isinstance(value, int) and not isinstance(value, bool) and value in _CLASSES.values():
        return value
    raise InvalidError(E_INVALID, f"cls: {value!r} is none of 'hrt', 'srt', 'nrt'")


@dataclasses.dataclass(frozen=True)
class ChannelDesc:
    """A channel as the model describes it (cosmic_channel_desc without the roles); durations in seconds."""

    name: str
    subject: int
    cls: str = "nrt"
    period: Optional[float] = None
    reaction_time: Optional[float] = None
    temp_validity: Optional[float] = None
    omission_degree: int = 0
    payload: int = 8
    # A typed channel's fields (its events in the compact layout: decode(), encode(), decode_batch());
    # None for opaque bytes.
    type: Optional[ChannelType] = None


def load_channel(yaml_file: str, name: str) -> ChannelDesc:
    """Channel `name` of a gateway configuration, read by cosmicd's own loader (the whole file is
    validated; errors name FILE:LINE:COL as `cosmicctl check` does). Raises cosmic.InvalidError."""
    d = _native._load_channel(str(yaml_file), name)
    return ChannelDesc(
        name=d["name"], subject=d["subject"], cls=d["cls"], period=_seconds(d["period_ns"]),
        reaction_time=_seconds(d["reaction_time_ns"]), temp_validity=_seconds(d["temp_validity_ns"]),
        omission_degree=d["omission_degree"], payload=d["payload"],
        type=None if d["type"] is None else ChannelType(d["type"]))


class Client(_native.Client):
    """A component's attachment to one segment, as a context manager (cosmic_open / cosmic_close).

    ``segment``: ``"dds:DOMAIN[?reliability=best_effort]"``, ``"lcm:udpm://GROUP:PORT?ttl=N"``,
    ``"can:IFACE?node=N"``. Raises cosmic.InvalidError for a malformed segment, cosmic.TransportError
    when the network refuses. The client closes on leaving the ``with`` block, on close(), when it
    and all its channels are garbage, or at interpreter exit.
    """

    def __init__(self, segment: str) -> None:
        super().__init__(segment)

    def __enter__(self) -> "Client":
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"<cosmic.Client {self.segment!r}{' (closed)' if self.closed else ''}>"

    def announce(self, channel: Union[str, ChannelDesc], subject: Optional[int] = None, *, roles: Roles,
                 cls: Optional[Union[str, int]] = None, period: Duration = None, reaction_time: Duration = None,
                 temp_validity: Duration = None, omission_degree: Optional[int] = None, payload: Optional[int] = None,
                 timeout: Duration = 5.0, ready: Duration = None) -> Channel:
        """Sets up a channel for ``roles`` (cosmic_announce) and returns it.

        ``channel`` is the channel's name with ``subject`` and its model as keywords (defaults: nrt,
        no period, omission_degree 0, payload 8 bytes), or a ChannelDesc (from load_channel), whose
        fields the keywords given override. ``roles``: cosmic.PUBLISH, cosmic.SUBSCRIBE, both or'ed,
        or "publish", "subscribe", "publish,subscribe". ``timeout`` bounds a CAN announce's wait for
        the gateway's etag. ``ready`` (seconds, or None: do not wait): then wait_ready(ready) too, so
        that the channel is returned once it is carried (on DDS every role has a matched peer, e.g.
        the gateway's reader; at once on LCM and CAN); cosmic.NotReadyError when that time passed
        (the channel stays announced on the client). Raises cosmic.InvalidError,
        cosmic.TransportError, cosmic.UnboundError, cosmic.NotReadyError.
        """
        given = {k: v for k, v in dict(subject=subject, cls=cls, period=period, reaction_time=reaction_time,
                                        temp_validity=temp_validity, omission_degree=omission_degree,
                                        payload=payload).items() if v is not None}
        if isinstance(channel, ChannelDesc):
            desc = dataclasses.replace(channel, **given)
        elif "subject" not in given:
            raise InvalidError(E_INVALID, f"announce({channel!r}): a subject is needed (or a ChannelDesc)")
        else:
            desc = ChannelDesc(name=channel, **given)
        ready_ns = None if ready is None else _ns(ready, "ready")
        announced = self._announce(
            desc.name, desc.subject, _class(desc.cls), _ns(desc.period, "period"),
            _ns(desc.reaction_time, "reaction_time"), _ns(desc.temp_validity, "temp_validity"),
            desc.omission_degree, desc.payload, _roles(roles), min(_ns(timeout, "timeout") // 1_000_000, 2**31 - 1))
        if ready_ns is not None:
            announced.wait_ready(ready_ns / 1e9)
        return announced

    def announce_from(self, yaml_file: str, name: str, *, roles: Roles, timeout: Duration = 5.0,
                      ready: Duration = None) -> Channel:
        """announce() of channel ``name`` as the gateway configuration ``yaml_file`` describes it
        (``ready``: see announce())."""
        return self.announce(load_channel(yaml_file, name), roles=roles, timeout=timeout, ready=ready)


# No receive thread may still want the GIL once the interpreter finalizes.
atexit.register(_native._close_all)
