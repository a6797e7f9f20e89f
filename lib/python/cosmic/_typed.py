"""A typed channel's events as Python values (docs/typed-layout.md, "The compact layout").

A component on the gateway's own segments sends and receives a typed channel's events in the
compact layout: fields in order, nothing between them, little-endian numbers, a string or a sequence
as a uint32 count and then its bytes or elements. ``ChannelType`` reads and writes it:

    desc = cosmic.load_channel("robot.yaml", "wheel_speed")   # type: {dbc: body.dbc, message: ...}
    fields = desc.type.decode(event.payload)                  # {"Speed": 12.34, "Gear": -1, ...}
    channel.publish(desc.type.encode({"Speed": 3.5, "Gear": 2, "Valid": True}))
    table = desc.type.decode_batch([e.payload for e in events])  # a numpy structured array

An enumeration reads as its value's name (its integer when it names none) and is written from
either. A field present only while another one holds a value (a DBC multiplexed signal) is left
out of the dict while not selected, and written as zeros when not given.
"""
from __future__ import annotations

import struct
from typing import Any, Iterable, Mapping, Optional, Union

from ._errors import E_INVALID, InvalidError

_CODES = {"bool": "?", "int8": "b", "int16": "h", "int32": "i", "int64": "q", "uint8": "B", "uint16": "H",
          "uint32": "I", "uint64": "Q", "float32": "f", "float64": "d"}
_NUMPY = {"bool": "?", "int8": "i1", "int16": "<i2", "int32": "<i4", "int64": "<i8", "uint8": "u1", "uint16": "<u2",
          "uint32": "<u4", "uint64": "<u8", "float32": "<f4", "float64": "<f8"}
_COUNT = struct.Struct("<I")

Payload = Union[bytes, bytearray, memoryview]


def _invalid(path: str, why: str) -> InvalidError:
    return InvalidError(E_INVALID, f"{path}: {why}")


class _Reader:
    def __init__(self, data: memoryview) -> None:
        self.data = data
        self.pos = 0

    def take(self, size: int, path: str) -> memoryview:
        if self.pos + size > len(self.data):
            raise _invalid(path, "the event ends inside it")
        chunk = self.data[self.pos:self.pos + size]
        self.pos += size
        return chunk

    def scalar(self, name: str, path: str) -> Any:
        code = struct.Struct("<" + _CODES[name])
        raw = self.take(code.size, path)
        if name == "bool" and raw[0] > 1:
            raise _invalid(path, f"a bool is 0 or 1, not {raw[0]}")
        return code.unpack(raw)[0]

    def count(self, bound: int, path: str) -> int:
        n = _COUNT.unpack(self.take(4, path))[0]
        if n > bound:
            raise _invalid(path, f"{n} is more than its bound {bound}")
        return n


class ChannelType:
    """The fields of a typed channel (ChannelDesc.type), and its events in the compact layout."""

    def __init__(self, fields: list[dict]) -> None:
        self.fields = fields

    def __repr__(self) -> str:
        return f"<cosmic.ChannelType {[f['name'] for f in self.fields]}>"

    @property
    def names(self) -> list[str]:
        return [f["name"] for f in self.fields]

    def decode(self, payload: Payload) -> dict[str, Any]:
        """One event in the compact layout as a dict; cosmic.InvalidError when it is not one event of
        the type (cut short, a count over its bound, a bool not 0 or 1, bytes after the last field)."""
        reader = _Reader(memoryview(payload).cast("B"))
        value = _read_record(self.fields, reader, "")
        if reader.pos != len(reader.data):
            raise InvalidError(E_INVALID, f"{len(reader.data) - reader.pos} bytes after the event's last field")
        return value

    def encode(self, values: Mapping[str, Any]) -> bytes:
        """The event in the compact layout; cosmic.InvalidError names the field that is missing, not
        of the type, out of its range or over its bound."""
        out = bytearray()
        _write_record(self.fields, values, out, "")
        return bytes(out)

    @property
    def dtype(self) -> Optional[Any]:
        """The numpy structured dtype of one event (packed, little-endian), or None when the type
        has a string or a sequence (its events vary in size)."""
        import numpy as np
        spec = _dtype_of_fields(self.fields)
        return None if spec is None else np.dtype(spec)

    def decode_batch(self, payloads: Iterable[Payload]) -> Any:
        """Events of a fixed-size type as one numpy structured array (enumerations as their integers)."""
        import numpy as np
        dtype = self.dtype
        if dtype is None:
            raise InvalidError(E_INVALID, "the type has a string or a sequence: its events vary in size; decode() each")
        chunks = [bytes(p) for p in payloads]
        for i, chunk in enumerate(chunks):
            if len(chunk) != dtype.itemsize:
                raise InvalidError(E_INVALID, f"event {i}: {len(chunk)} bytes, an event of the type has {dtype.itemsize}")
        return np.frombuffer(b"".join(chunks), dtype=dtype)


def _selected(field: dict, raw: Mapping[str, Any]) -> bool:
    when = field["present_when"]
    return when is None or raw.get(when[0]) == when[1]


def _read_record(fields: list[dict], reader: _Reader, path: str) -> dict[str, Any]:
    value: dict[str, Any] = {}
    raw: dict[str, Any] = {}  # the integers the selectors compare (an enumeration's, not its name)
    for field in fields:
        where = f"{path}.{field['name']}" if path else field["name"]
        got, integer = _read(field["type"], reader, where)
        raw[field["name"]] = integer
        if _selected(field, raw):
            value[field["name"]] = got
    return value


def _read(t: dict, reader: _Reader, path: str) -> tuple[Any, Any]:
    kind = t["kind"]
    if kind == "scalar":
        v = reader.scalar(t["scalar"], path)
        return v, v
    if kind == "enum":
        v = reader.scalar(t["scalar"], path)
        names = {number: name for name, number in t["values"].items()}
        return names.get(v, v), v
    if kind == "string":
        n = reader.count(t["bound"], path)
        return bytes(reader.take(n, path)).decode("utf-8", errors="replace"), None
    if kind in ("array", "sequence"):
        n = t["bound"] if kind == "array" else reader.count(t["bound"], path)
        return [_read(t["element"], reader, f"{path}[{i}]")[0] for i in range(n)], None
    return _read_record(t["fields"], reader, path), None


def _write_record(fields: list[dict], values: Mapping[str, Any], out: bytearray, path: str) -> None:
    if not isinstance(values, Mapping):
        raise _invalid(path or "event", f"a record is a dict of its fields, not {type(values).__name__}")
    known = {f["name"] for f in fields}
    unknown = [k for k in values if k not in known]
    if unknown:
        raise _invalid(path or "event", f"no field {unknown[0]!r} in the type (fields: {', '.join(sorted(known))})")
    raw: dict[str, Any] = {}
    for field in fields:
        name = field["name"]
        where = f"{path}.{name}" if path else name
        if name not in values:
            if field["present_when"] is None:
                raise _invalid(where, "missing (every field not conditional on another is needed)")
            _write_zero(field["type"], out)
            continue
        if not _selected(field, raw):
            raise _invalid(where, f"present only while {field['present_when'][0]} is {field['present_when'][1]}")
        raw[name] = _write(field["type"], values[name], out, where)


def _write(t: dict, value: Any, out: bytearray, path: str) -> Any:
    kind = t["kind"]
    if kind in ("scalar", "enum"):
        if kind == "enum" and isinstance(value, str):
            if value not in t["values"]:
                raise _invalid(path, f"{value!r} is not one of {', '.join(t['values'])}")
            value = t["values"][value]
        name = t["scalar"]
        if name == "bool" and value not in (0, 1):  # True and False are 1 and 0
            raise _invalid(path, f"a bool is True or False, not {value!r}")
        try:
            out += struct.pack("<" + _CODES[name], value)
        except struct.error as e:
            raise _invalid(path, f"{value!r} does not fit {name} ({e})") from None
        return value
    if kind == "string":
        data = value.encode("utf-8") if isinstance(value, str) else bytes(value)
        if len(data) > t["bound"]:
            raise _invalid(path, f"{len(data)} bytes, more than its bound {t['bound']}")
        out += _COUNT.pack(len(data)) + data
        return None
    if kind in ("array", "sequence"):
        items = list(value)
        if kind == "array" and len(items) != t["bound"]:
            raise _invalid(path, f"{len(items)} elements, an array of {t['bound']}")
        if len(items) > t["bound"]:
            raise _invalid(path, f"{len(items)} elements, more than its bound {t['bound']}")
        if kind == "sequence":
            out += _COUNT.pack(len(items))
        for i, item in enumerate(items):
            _write(t["element"], item, out, f"{path}[{i}]")
        return None
    _write_record(t["fields"], value, out, path)
    return None


def _write_zero(t: dict, out: bytearray) -> None:
    kind = t["kind"]
    if kind in ("scalar", "enum"):
        out += bytes(struct.calcsize("<" + _CODES[t["scalar"]]))
    elif kind in ("string", "sequence"):
        out += _COUNT.pack(0)
    elif kind == "array":
        for _ in range(t["bound"]):
            _write_zero(t["element"], out)
    else:
        for field in t["fields"]:
            _write_zero(field["type"], out)


def _dtype_of_fields(fields: list[dict]) -> Optional[list]:
    spec = []
    for field in fields:
        sub = _dtype_of(field["type"])
        if sub is None:
            return None
        spec.append((field["name"],) + sub)
    return spec


def _dtype_of(t: dict) -> Optional[tuple]:
    kind = t["kind"]
    if kind in ("scalar", "enum"):
        return (_NUMPY[t["scalar"]],)
    if kind == "array":
        element = _dtype_of(t["element"])
        if element is None:
            return None
        return (element[0], (t["bound"],) + (element[1] if len(element) > 1 else ()))
    if kind == "record":
        spec = _dtype_of_fields(t["fields"])
        return None if spec is None else (spec,)
    return None
