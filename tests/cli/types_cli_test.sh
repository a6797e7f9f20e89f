#!/usr/bin/env bash
# `cosmicctl types FILE` end to end (issue 35): what a DBC file's messages (and a ROS 2 message's, an
# IDL file's structs) become as typed channels,
# in text and in the --json shape, and every bad input refused with its exit status and a clear
# message (a file that is not a DBC file, one that does not exist, a directory, a DBC with errors).
# Usage: types_cli_test.sh PATH_TO_cosmicctl PROJECT_SOURCE_DIR
set -u

. "$(dirname "${BASH_SOURCE[0]}")/cli_lib.sh"
DBC=$SRC/tests/integration/dbc/signals.dbc

# 1. Text: each message's head line, each signal's field beside its layout.
run text 0 types "$DBC"
contains text out "signals.dbc: DBC, 5 messages"
contains text out "BodyStatus: id 0x100, 8 bytes, every 100 ms"
contains text out "  Ignition: enum uint8 {Off=0, Accessory=1, Run=2, Start=3}   <- 0|2@1+ (1,0)"
contains text out "  BatteryVoltage: float64 [V, 0..655.35]   <- 8|16@1+ (0.01,0)"
contains text out "  Odometer: int32 [m]   <- 32|20@1+ (10,-100)"
contains text out "  Brake: bool [0..1]   <- 52|1@1+ (1,0)"
contains text out "Diagnostics: id 0x18FEF100 (extended), 8 bytes, on event"
contains text out "  Freeze: int32 when Mode=1   <- 8|32@1- (1,0)"
contains text out "  Pressure: float32 [bar] when Mode=2   <- 8|32@1- (1,0) float32"
contains text out "  State: enum uint8 {Idle=0, Busy=1, Not_available=15}   <- 488|4@1+ (1,0)"
contains text out "  Offset: int64 [ns]   <- 71|40@0- (1,0)"

# 2. JSON: every message, every field with its layout; a multiplexed field names its selector.
run json 0 --json types "$DBC"
json_check json '
  d["format"] == "dbc" and len(d["types"]) == 5
  [t["name"] for t in d["types"]] == ["BodyStatus", "WheelSpeeds", "Diagnostics", "Fluid", "Wide"]
  all("fields" in t and "error" not in t for t in d["types"])
  d["types"][0]["cycle_ms"] == 100 and d["types"][2]["cycle_ms"] is None
  d["types"][2]["can_id"] == 0x18FEF100 and d["types"][2]["extended"]
  d["types"][4]["length"] == 64
  [f["name"] for f in d["types"][1]["fields"]] == ["SpeedFL", "SpeedFR", "Yaw", "Slip", "Valid"]
  d["types"][1]["fields"][2] == {"name": "Yaw", "type": "float64", "layout": "39|12@0- (0.1,2.5)", "unit": "deg/s", "min": -202.3, "max": 207.2}
  d["types"][2]["fields"][2]["present_when"] == {"selector": "Mode", "value": 1}
  "present_when" not in d["types"][2]["fields"][0]
'

# 3. A message that cannot be a type says why, and the others still list.
printf 'BO_ 1 Good: 8 X\n SG_ S : 0|8@1+ (1,0) [0|0] "" X\nBO_ 2 Bad: 8 X\n SG_ _s : 0|8@1+ (1,0) [0|0] "" X\nBO_ 3 Empty: 0 X\n' >"$WORK/mixed.dbc"
run mixed 0 types "$WORK/mixed.dbc"
contains mixed out "  S: uint8   <- 0|8@1+ (1,0)"
contains mixed out "  not a type: line 4: signal name '_s' is not a field name"
contains mixed out "  not a type: line 5: message 'Empty' has no signals to make fields of"
run mixed_json 0 --json types "$WORK/mixed.dbc"
json_check mixed_json '
  "fields" in d["types"][0] and "error" in d["types"][1] and d["types"][1]["error"].startswith("4:2: signal name")
'

# 4. Bad input: exit 64 for what is not a DBC file, 2 for what does not read, every DBC error located.
run not_dbc 64 types "$SRC/config/robot.yaml"
contains not_dbc err "robot.yaml: not a DBC file (.dbc), an LCM type file (.lcm), an IDL file (.idl) or a ROS 2 message (.msg), the type files this version reads"
run missing 2 types "$WORK/none.dbc"
contains missing err "cannot read $WORK/none.dbc: No such file or directory"
mkdir "$WORK/dir.dbc"
run directory 2 types "$WORK/dir.dbc"
contains directory err "is not a regular file of at most 8 MiB"
printf 'BO_ 1 A: 2 X\n SG_ S : 9|8@1+ (1,0) [0|0] "" X\nVAL_ 7 S 1 "x" ;\n' >"$WORK/broken.dbc"
run broken 2 types "$WORK/broken.dbc"
contains broken err "$WORK/broken.dbc:2:2: signal 'S' (9|8@1+) does not fit the 2 bytes of message 'A'"
contains broken err "$WORK/broken.dbc:3:6: VAL_ names message id 7 (0x7), which no BO_ declares"
run no_file 64 types

# 5. ROS 2 messages and IDL files: the fields a typed channel gets, their dependencies found under
# the root the file lies in (ROOT/pkg/msg/Name.*) or on --type-path, as the configuration finds them.
MSG=$SRC/tests/integration/msg_types/type_path
run twist 0 types "$MSG/geometry_msgs/msg/Twist.msg"
contains twist out "Twist.msg: ROS 2 message geometry_msgs/msg/Twist, 2 messages read"
contains twist out "  linear: {x: float64, y: float64, z: float64}"
contains twist out "  angular: {x: float64, y: float64, z: float64}"
run twist_json 0 --json types "$MSG/geometry_msgs/msg/Twist.msg"
json_check twist_json '
  d["format"] == "msg" and d["types"][0]["name"] == "geometry_msgs/msg/Twist"
  [f["name"] for f in d["types"][0]["fields"]] == ["linear", "angular"]
  [m["name"] for m in d["messages"]] == ["geometry_msgs/msg/Twist", "geometry_msgs/msg/Vector3"]
'
cp "$MSG/geometry_msgs/msg/Twist.msg" "$WORK/Twist.msg"
run msg_placeless 64 types "$WORK/Twist.msg"
contains msg_placeless err "a .msg file's package comes from its place, ROOT/PKG/msg/NAME.msg; give --name PKG/msg/NAME"
run msg_named 0 types "$WORK/Twist.msg" --name geometry_msgs/msg/Twist --type-path "$MSG"
contains msg_named out "  linear: {x: float64, y: float64, z: float64}"
run msg_missing 2 types "$WORK/Twist.msg" --name geometry_msgs/msg/Twist
contains msg_missing err "Vector3"
IDL=$SRC/tests/integration/idl_types/idl/good
run header 0 types "$IDL/std_msgs/msg/Header.idl"
contains header out "Header.idl: IDL, 2 structs, 1 included files"
contains header out "std_msgs::msg::Header (final)"
contains header out "  stamp: {sec: int32, nanosec: uint32}"
contains header out "  frame_id: string<=65536>"
contains header out "builtin_interfaces::msg::Time (final), from "
run header_json 0 --json types "$IDL/std_msgs/msg/Header.idl"
json_check header_json '
  d["format"] == "idl" and [t["name"] for t in d["types"]] == ["builtin_interfaces::msg::Time", "std_msgs::msg::Header"]
  d["read"][0].endswith("builtin_interfaces/msg/Time.idl")
'
run idl_broken 2 types "$SRC/tests/integration/idl_types/idl/bad/syntax.idl"
contains idl_broken err "syntax.idl:"
run idl_name 64 types "$IDL/std_msgs/msg/Header.idl" --name std_msgs/msg/Header
contains idl_name err "--name names a .msg file's message"

finish "cosmicctl types"
