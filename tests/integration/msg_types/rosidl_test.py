#!/usr/bin/env python3
"""The gateway's ROS 2 .msg reader against rosidl, ROS 2's own (python3-rosidl, rosidl 3.3 "Humble").

  rosidl_test.py PEER TYPE_PATH

PEER is cosmic-msg-types-peer (tests/peers/msg_types_peer.cpp), which prints cosmic's reading as
JSON. rosidl_adapter reads each .msg file (rosidl_adapter.parser) and writes the IDL rosidl
generates from it (its msg.idl.em template, as rosidl_adapter.msg does); rosidl_parser reads that IDL back. Checked:
  1. every message of TYPES (the messages of TYPE_PATH: ROS 2's Twist, Vector3, Header and
     LaserScan as shipped, and cosmic_test's messages with every kind of field, constant, default
     and unit; builtin_interfaces/Time and Duration from cosmic's built-in definitions, TYPE_PATH
     has none): the fields (name, package, type, string bound, array kind and size, default value,
     unit) and constants (type, name, value) cosmic reads are rosidl's;
  2. the channel type cosmic builds is the IDL struct rosidl generates, member by member and
     nested struct by nested struct: the same names in the same order, boolean as bool, octet and
     uint8 as uint8, float and double as float32 and float64, strings and sequences with rosidl's
     bound (an unbounded one with max_length's or 65536), arrays with their length, rosidl's
     placeholder member for a message without fields, and the @unit of numeric members;
  3. CASES, one-to-three-line texts: cosmic refuses exactly the texts rosidl refuses (rosidl
     raising while reading the file, or having no IDL type for a field, as for ROS 1's time), except the
     DIVERGENCES listed with their reason; where both accept, the fields and constants agree.
Exit status 0 when everything agrees; otherwise each disagreement is printed.
"""
import contextlib
import io
import json
import pathlib
import subprocess
import sys
import tempfile

from rosidl_adapter.msg import get_idl_type
from rosidl_adapter.resource import expand_template
from rosidl_adapter.parser import Type, parse_message_string, parse_primitive_value_string, parse_value_string
from rosidl_parser.definition import (Array, BasicType, BoundedSequence, BoundedString, IdlLocator, Message,
                                      NamespacedType, UnboundedSequence, UnboundedString)
from rosidl_parser.parser import parse_idl_file

UNBOUNDED = 65536  # cosmic's bound of an unbounded string or sequence without max_length

TYPES = [
    ("geometry_msgs/msg/Twist", {}),
    ("geometry_msgs/msg/Vector3", {}),
    ("std_msgs/msg/Header", {}),
    ("std_msgs/msg/Header", {"frame_id": 64}),
    ("sensor_msgs/msg/LaserScan", {"ranges": 1081, "intensities": 1081, "header.frame_id": 64}),
    ("cosmic_test/msg/Everything", {"bytes": 64, "many_parts": 8, "text": 100, "pair[]": 12}),
    ("cosmic_test/msg/Part", {}),
    ("cosmic_test/msg/Nothing", {}),
]

CASES = [
    # accepted by both
    "int32 a\n",
    "float64\tx   # tabs read as spaces [m]\n",
    "string<=5 s 'abc'\n",
    "int32[<=3] a [1, 2]\n",
    "bool B=True\nbool b false\n",
    "int64 BIG=-0x10\nuint8 b 0b101\n",
    "string S=\"a \\\"quoted\\\" word\"\n",
    "string[] names ['x, y', \"z\"]\n",
    "float32 f -inf\nfloat64 g 1e400\n",
    "char C=0\nbyte b 255\n",
    "Vector3 v\ngeometry_msgs/Point p\n",
    "Foo_Request r\n",
    "# only a comment\n",
    "",
    "int32 a # one [m]\n  # two [s]\n",
    "# [K]\nfloat32 t\n",
    "int32 a\n\n  # an indented comment after a blank line is still a's [A]\n",
    # refused by both
    "float x\n",
    "int32 Speed\n",
    "int32 a__b\n",
    "int32 a_\n",
    "int32 x\nint32 x\n",
    "int32\n",
    "  int32 y\n",
    "int32 foo=1\n",
    "int8 BIG=128\n",
    "uint8 NEG=-1\n",
    "int32[2] ARR=1\n",
    "string<=3 S='a'\n",
    "bool B=yes\n",
    "int32 B_=1\n",
    "int32 A__B=1\n",
    "float64 F=x\n",
    "int32 D=1\nint32 D=2\n",
    "string S=\"a\"b\"\n",
    "int32[2] a [1]\n",
    "int32[<=1] b [1, 2]\n",
    "int32[] c 1\n",
    "int32[] c [1,,2]\n",
    "string<=2 d abc\n",
    "Vector3 v 0\n",
    "char e 256\n",
    "int64 f 0x\n",
    "int32[0] a\n",
    "int32[<=0] a\n",
    "string<=0 s\n",
    "string<=x c\n",
    "int32[2][3] d\n",
    "int32] e\n",
    "geometry_msgs/msg/Point p\n",
    "Bad_Pkg/Point q\n",
    "pkg/point r\n",
    "time t\n",
    "duration[] d\n",
    "int32 a b c\n",
]

# Texts cosmic refuses and rosidl accepts, and why.
DIVERGENCES = {
    "wstring w\n": "wstring: a channel's strings are bytes (a wide string's CDR form is not agreed)",
    "wstring<=5 w\n": "wstring, bounded",
    "int32[70000] big\n": "a length beyond kMaxTypeBound (65536)",
    "string<=70000 s\n": "a bound beyond kMaxTypeBound (65536)",
    "int32 a 1_000\n": "Python's digit separators are not read",
}


class Rosidl:
    """rosidl's reading of one .msg text and the IDL struct it generates."""

    def __init__(self, work):
        self.work = pathlib.Path(work)
        self.count = 0

    def spec(self, package, name, text):
        with contextlib.redirect_stderr(io.StringIO()):
            return parse_message_string(package, name, text)

    def struct(self, package, name, text):
        self.count += 1
        base = self.work / str(self.count)
        out = base / package / "msg"
        out.mkdir(parents=True)
        # rosidl_adapter.msg.convert_msg_to_idl without its progress lines (empy's stdout proxy
        # does not survive a redirection of stdout): the same reading and the same template.
        data = {"pkg_name": package, "relative_input_file": f"msg/{name}.msg", "msg": self.spec(package, name, text)}
        expand_template("msg.idl.em", data, out / (name + ".idl"), encoding="iso-8859-1")
        with contextlib.redirect_stderr(io.StringIO()):
            idl = parse_idl_file(IdlLocator(base, pathlib.Path(package) / "msg" / (name + ".idl")))
        return idl.content.get_elements_of_type(Message)[0].structure

    def accepts(self, package, name, text):
        """Whether rosidl reads the text and has an IDL type for each field and constant (the types
        its template writes; a failure inside empy's template would break the interpreter's stdout)."""
        try:
            spec = self.spec(package, name, text)
            for typed in spec.fields + spec.constants:
                get_idl_type(typed.type)
            return True
        except Exception:  # rosidl's refusals are exceptions of many kinds (ValueError, KeyError, ...)
            return False


def peer(path, *args, text=None):
    done = subprocess.run([path, *args], input=text, capture_output=True, text=True, check=True)
    return json.loads(done.stdout)


def array_kind(t):
    if not t.is_array:
        return "none"
    if t.is_upper_bound:
        return "bounded"
    return "fixed" if t.array_size else "unbounded"


def compare_file(where, package, ours, spec, problems):
    """cosmic's fields and constants of one file against rosidl's MessageSpecification."""
    if [f["name"] for f in ours["fields"]] != [f.name for f in spec.fields]:
        problems.append(f"{where}: fields {[f['name'] for f in ours['fields']]} != {[f.name for f in spec.fields]}")
        return
    for f, r in zip(ours["fields"], spec.fields):
        t = r.type
        theirs = {
            "package": "" if t.pkg_name is None else t.pkg_name,
            "type": t.type,
            "string_bound": t.string_upper_bound or 0,
            "array": array_kind(t),
            "array_size": t.array_size or 0,
            "unit": r.annotations.get("unit", ""),
        }
        mine = {k: f[k] for k in theirs}
        if mine["package"] == "" and theirs["package"] == package and t.pkg_name is not None:
            mine["package"] = package  # a bare message name: the file's own package, as rosidl says
        if mine != theirs:
            problems.append(f"{where}.{f['name']}: {mine} != {theirs}")
        if (f["default"] is None) != (r.default_value is None):
            problems.append(f"{where}.{f['name']}: default {f['default']!r} != {r.default_value!r}")
        elif f["default"] is not None and parse_value_string(t, f["default"]) != r.default_value:
            problems.append(f"{where}.{f['name']}: default {f['default']!r} reads other than {r.default_value!r}")
    mine = [(c["type"], c["name"], parse_primitive_value_string(Type(c["type"]), c["value"])) for c in ours["constants"]]
    theirs = [(c.type, c.name, c.value) for c in spec.constants]
    if mine != theirs:
        problems.append(f"{where}: constants {mine} != {theirs}")


BASIC = {"boolean": "bool", "octet": "uint8", "float": "float32", "double": "float64"}


class StructCheck:
    """cosmic's channel type against the IDL structs rosidl generates, nested ones included."""

    def __init__(self, rosidl, texts, max_length, problems):
        self.rosidl, self.texts, self.max_length, self.problems = rosidl, texts, max_length, problems
        self.used = set()

    def record(self, where, package, name, fields, path):
        struct = self.rosidl.struct(package, name, self.texts[f"{package}/msg/{name}"])
        if [m.name for m in struct.members] != [f["name"] for f in fields]:
            self.problems.append(f"{where}: members {[m.name for m in struct.members]} != {[f['name'] for f in fields]}")
            return
        for member, field in zip(struct.members, fields):
            member_path = f"{path}.{member.name}" if path else member.name
            self.member_type(f"{where}.{member.name}", member.type, field["type"], member_path)
            units = [a.value["value"] for a in member.annotations if a.name == "unit"]
            numeric = self.numeric(field["type"])
            expected = units[0] if units and numeric else ""
            if field["unit"] != expected:
                self.problems.append(f"{where}.{member.name}: unit {field['unit']!r} != {expected!r}")

    @staticmethod
    def numeric(t):
        while t["kind"] in ("array", "sequence"):
            t = t["element"]
        return t["kind"] == "scalar"

    def bound(self, path):
        self.used.add(path)
        return self.max_length.get(path, UNBOUNDED)

    def member_type(self, where, idl, ours, path):
        def expect(condition, what):
            if not condition:
                self.problems.append(f"{where}: {what} (ours: {json.dumps(ours)[:200]})")

        if isinstance(idl, BasicType):
            expect(ours == {"kind": "scalar", "scalar": BASIC.get(idl.typename, idl.typename)}, f"IDL {idl.typename}")
        elif isinstance(idl, BoundedString):
            expect(ours == {"kind": "string", "bound": idl.maximum_size}, f"IDL string<{idl.maximum_size}>")
        elif isinstance(idl, UnboundedString):
            expect(ours == {"kind": "string", "bound": self.bound(path)}, "IDL string (unbounded)")
        elif isinstance(idl, Array):
            expect(ours["kind"] == "array" and ours["bound"] == idl.size, f"IDL array [{idl.size}]")
            if ours["kind"] == "array":
                self.member_type(where + "[]", idl.value_type, ours["element"], path + "[]")
        elif isinstance(idl, BoundedSequence):
            expect(ours["kind"] == "sequence" and ours["bound"] == idl.maximum_size, f"IDL sequence<, {idl.maximum_size}>")
            if ours["kind"] == "sequence":
                self.member_type(where + "[]", idl.value_type, ours["element"], path + "[]")
        elif isinstance(idl, UnboundedSequence):
            expect(ours["kind"] == "sequence" and ours["bound"] == self.bound(path), "IDL sequence (unbounded)")
            if ours["kind"] == "sequence":
                self.member_type(where + "[]", idl.value_type, ours["element"], path + "[]")
        elif isinstance(idl, NamespacedType):
            expect(ours["kind"] == "record" and idl.namespaces[1:] == ["msg"], f"IDL {idl.namespaced_name()}")
            if ours["kind"] == "record":
                self.record(where, idl.namespaces[0], idl.name, ours["fields"], path)
        else:
            expect(False, f"IDL type {idl!r} has no channel type")


def check_types(peer_path, type_path, rosidl, problems):
    for full, max_length in TYPES:
        args = [f"{k}={v}" for k, v in max_length.items()]
        ours = peer(peer_path, "type", type_path, full, *args)
        if ours["errors"]:
            problems.append(f"{full}: cosmic refuses it: {ours['errors']}")
            continue
        texts = {}
        for f in ours["files"]:
            package, _, name = f["name"].split("/")
            texts[f["name"]] = f["text"]
            if f["built_in"] != (package == "builtin_interfaces"):
                problems.append(f"{f['name']}: built_in is {f['built_in']}")
            compare_file(f["name"], package, f, rosidl.spec(package, name, f["text"]), problems)
        package, _, name = full.split("/")
        check = StructCheck(rosidl, texts, max_length, problems)
        check.record(full, package, name, ours["type"], "")
        if set(max_length) - check.used:
            problems.append(f"{full}: max_length {sorted(set(max_length) - check.used)} bounded nothing in rosidl's IDL")
        print(f"{full}: {len(ours['files'])} files, agrees" if not problems else f"{full}: checked")


def check_cases(peer_path, rosidl, problems):
    agreed = 0
    for text in CASES + list(DIVERGENCES):
        ours = peer(peer_path, "parse", text=text)
        theirs = rosidl.accepts("cosmic_test", "Case", text)
        mine = not ours["errors"]
        if text in DIVERGENCES:
            if mine or not theirs:
                problems.append(f"{text!r}: expected cosmic to refuse and rosidl to accept ({DIVERGENCES[text]})")
            continue
        if mine != theirs:
            problems.append(f"{text!r}: cosmic {'accepts' if mine else 'refuses: ' + str(ours['errors'])}, "
                            f"rosidl {'accepts' if theirs else 'refuses'}")
            continue
        if mine:
            compare_file(f"case {text!r}", "cosmic_test", ours, rosidl.spec("cosmic_test", "Case", text), problems)
        agreed += 1
    print(f"{agreed} texts read alike, {len(DIVERGENCES)} known divergences")


def main():
    peer_path, type_path = sys.argv[1], sys.argv[2]
    problems = []
    with tempfile.TemporaryDirectory() as work:
        rosidl = Rosidl(work)
        check_types(peer_path, type_path, rosidl, problems)
        check_cases(peer_path, rosidl, problems)
    for p in problems:
        print("MISMATCH", p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
