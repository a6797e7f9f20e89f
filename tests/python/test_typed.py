"""A typed channel's events as dicts and numpy structured arrays (issue 35; cosmic._typed): the
channel's type as cosmicd's loader reads it (a DBC message with a value table and multiplexing, an
inline type with strings, sequences, arrays and records), events in the compact layout as
docs/typed-layout.md sets them out, each bad value refused naming its field, and a batch through
numpy's own reading of the bytes agreeing with decode()."""
from __future__ import annotations

import struct
from pathlib import Path

import numpy as np
import pytest

import cosmic

DBC = """BO_ 256 BodyStatus: 8 Ecu
 SG_ Ignition : 0|2@1+ (1,0) [0|3] "" Gateway
 SG_ BatteryVoltage : 8|16@1+ (0.01,0) [0|655.35] "V" Gateway
 SG_ Brake : 24|1@1+ (1,0) [0|1] "" Gateway
BO_ 257 Diagnostics: 8 Ecu
 SG_ Mode M : 0|8@1+ (1,0) [0|255] "" Gateway
 SG_ Dtc m0 : 8|16@1+ (1,0) [0|65535] "" Gateway
 SG_ Level m2 : 8|8@1+ (1,0) [0|255] "" Gateway
VAL_ 256 Ignition 0 "Off" 1 "Accessory" 2 "Run" ;
"""

YAML = """gateway: {name: typed-py}
segments:
  - {name: lan, type: dds, domain: 0}
  - {name: viz, type: lcm, url: "udpm://239.255.76.67:7969?ttl=0"}
channels:
  - {name: body, subject: 0x10, class: nrt, omission_degree: 0, publishers: [lan], subscribers: [viz],
     type: {dbc: body.dbc, message: BodyStatus}}
  - {name: diagnostics, subject: 0x11, class: nrt, omission_degree: 0, publishers: [lan], subscribers: [viz],
     type: {dbc: body.dbc, message: Diagnostics}}
  - name: scan
    subject: 0x12
    class: nrt
    omission_degree: 0
    publishers: [lan]
    subscribers: [viz]
    type:
      fields:
        - {name: label, type: string, max_length: 8}
        - {name: ranges, type: sequence, max_length: 3, element: float32}
        - {name: pose, type: record, fields: [{name: x, type: float64}, {name: corners, type: array, length: 2, element: int16}]}
  - {name: plain, subject: 0x13, class: nrt, omission_degree: 0, payload: 8B, publishers: [lan], subscribers: [viz]}
"""


@pytest.fixture
def config(tmp_path: Path) -> str:
    (tmp_path / "body.dbc").write_text(DBC)
    (tmp_path / "gw.yaml").write_text(YAML)
    return str(tmp_path / "gw.yaml")


def test_a_dbc_channel_decodes_and_encodes_its_fields(config):
    body = cosmic.load_channel(config, "body").type
    assert body.names == ["Ignition", "BatteryVoltage", "Brake"]
    # The compact layout: Ignition enum uint8, BatteryVoltage float64, Brake bool: 10 bytes.
    event = bytes([2]) + struct.pack("<d", 12.5) + bytes([1])
    assert body.decode(event) == {"Ignition": "Run", "BatteryVoltage": 12.5, "Brake": True}
    assert body.encode({"Ignition": "Run", "BatteryVoltage": 12.5, "Brake": True}) == event
    assert body.encode({"Ignition": 2, "BatteryVoltage": 12.5, "Brake": 1}) == event
    assert body.decode(bytes([3]) + event[1:])["Ignition"] == 3  # a value the table does not name


def test_a_multiplexed_signal_is_present_only_while_its_switch_selects_it(config):
    diagnostics = cosmic.load_channel(config, "diagnostics").type
    # Mode uint8, Dtc uint16 (Mode 0), Level uint8 (Mode 2): each always has its place.
    assert diagnostics.decode(bytes([0]) + struct.pack("<H", 513) + bytes([0])) == {"Mode": 0, "Dtc": 513}
    assert diagnostics.decode(bytes([2, 0, 0, 7])) == {"Mode": 2, "Level": 7}
    assert diagnostics.encode({"Mode": 2, "Level": 7}) == bytes([2, 0, 0, 7])
    with pytest.raises(cosmic.InvalidError, match="Dtc: present only while Mode is 0"):
        diagnostics.encode({"Mode": 2, "Dtc": 1})


def test_strings_sequences_arrays_and_records(config):
    scan = cosmic.load_channel(config, "scan").type
    event = (struct.pack("<I", 2) + b"ok" + struct.pack("<I", 2) + struct.pack("<ff", 1.5, -2.0)
             + struct.pack("<d", 0.25) + struct.pack("<hh", -1, 7))
    value = {"label": "ok", "ranges": [1.5, -2.0], "pose": {"x": 0.25, "corners": [-1, 7]}}
    assert scan.decode(event) == value
    assert scan.encode(value) == event
    assert scan.dtype is None  # a string and a sequence: events vary in size
    with pytest.raises(cosmic.InvalidError, match="decode"):
        scan.decode_batch([event])


@pytest.mark.parametrize("values, why", [
    ({"Ignition": "Start", "BatteryVoltage": 1.0, "Brake": False}, "Ignition: 'Start' is not one of Off, Accessory, Run"),
    ({"Ignition": 300, "BatteryVoltage": 1.0, "Brake": False}, "Ignition: 300 does not fit uint8"),
    ({"Ignition": 0, "Brake": False}, "BatteryVoltage: missing"),
    ({"Ignition": 0, "BatteryVoltage": 1.0, "Brake": 2}, "Brake: a bool is True or False, not 2"),
    ({"Ignition": 0, "BatteryVoltage": 1.0, "Brake": False, "Horn": 1}, "no field 'Horn' in the type"),
])
def test_a_bad_value_is_refused_naming_its_field(config, values, why):
    with pytest.raises(cosmic.InvalidError) as raised:
        cosmic.load_channel(config, "body").type.encode(values)
    assert why in raised.value.message


def test_what_is_not_one_event_is_refused(config):
    body = cosmic.load_channel(config, "body").type
    with pytest.raises(cosmic.InvalidError, match="BatteryVoltage: the event ends inside it"):
        body.decode(bytes([0, 1, 2]))
    with pytest.raises(cosmic.InvalidError, match="1 bytes after the event's last field"):
        body.decode(bytes(11))
    with pytest.raises(cosmic.InvalidError, match="Brake: a bool is 0 or 1, not 5"):
        body.decode(bytes(9) + bytes([5]))
    scan = cosmic.load_channel(config, "scan").type
    with pytest.raises(cosmic.InvalidError, match="label: 9 is more than its bound 8"):
        scan.decode(struct.pack("<I", 9) + bytes(40))
    with pytest.raises(cosmic.InvalidError, match="ranges: 4 elements, more than its bound 3"):
        scan.encode({"label": "", "ranges": [0, 0, 0, 0], "pose": {"x": 0, "corners": [0, 0]}})


def test_a_batch_reads_through_numpy_as_decode_reads_each(config):
    body = cosmic.load_channel(config, "body").type
    events = [body.encode({"Ignition": i % 3, "BatteryVoltage": 11.0 + i / 4, "Brake": bool(i % 2)}) for i in range(5)]
    table = body.decode_batch(events)
    assert table.dtype.itemsize == 10 and table.shape == (5,)
    for row, event in zip(table, events):
        one = body.decode(event)
        assert row["BatteryVoltage"] == one["BatteryVoltage"] and bool(row["Brake"]) == one["Brake"]
    assert list(table["Ignition"]) == [0, 1, 2, 0, 1]  # enumerations as their integers
    assert np.allclose(table["BatteryVoltage"], [11.0, 11.25, 11.5, 11.75, 12.0])
    with pytest.raises(cosmic.InvalidError, match="event 1: 9 bytes"):
        body.decode_batch([events[0], events[1][:9]])


def test_an_untyped_channel_has_no_type(config):
    assert cosmic.load_channel(config, "plain").type is None
