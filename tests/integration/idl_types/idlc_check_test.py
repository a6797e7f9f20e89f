#!/usr/bin/env python3
"""The gateway's IDL reader (cosmic/idl_types.hpp) against Cyclone DDS's idlc, an implementation we did not write.

  idlc_check_test.py IDLC C_COMPILER DDSC_LIBRARY COSMIC_CDR_PEER SOURCE_DIR

SOURCE_DIR/idl holds three sets of .idl files:
  good/     ROS 2's rosidl output (builtin_interfaces Time, std_msgs Header, sensor_msgs LaserScan,
            geometry_msgs Vector3 and Twist, each #including the next as rosidl writes them) and an
            idlc user's files (enums with @value, modules nested three deep, typedefs of arrays,
            constants as bounds, multi-dimensional arrays, bounded strings and sequences, sequences
            of sequences, @appendable structs, an include guard, units and ranges);
  bad/      files both must refuse (a syntax error, an undeclared type, a declaration twice, a constant
            its type does not hold, long double; not a struct containing itself, on which idlc 0.10.2
            never ends: tests/unit/idl_types_test.cpp covers that one);
  refused/  files idlc reads but the gateway refuses by design, each for a reason named below
            (keys, unions, optional members, mutable types, macros).
1. Acceptance: idlc (`-x final -I good`) and cosmic-cdr-peer idl-check (the gateway's reader, its
   includes read from good/) accept exactly the good files, refuse exactly the bad ones; for the
   refused ones idlc accepts and the gateway names the expected reason.
2. Layout: for structs of the good files, idlc's C code is compiled with cyclone_idl_peer.c (a
   generic peer: Cyclone's receive path reads samples, prints them, writes them again). Our peer
   writes samples of the struct as the gateway reads it (values from a fixed seed, in XCDR1 and
   XCDR2; appendable types XCDR2 only, as Cyclone writes them); Cyclone must read every sample and
   print exactly the values we wrote; Cyclone's own serialization of what it read must decode, with
   the gateway's type, to the very values, and be byte for byte what we wrote.
Run through scripts/netns-run: the Cyclone participant stays private (local delivery, no traffic).
Exit status 0 when everything agrees; otherwise each disagreement is printed.
"""
import os
import re
import shutil
import subprocess
import sys
import tempfile

SAMPLES = 12

# Refused by the gateway though idlc reads them: the file and a phrase of the reason.
REFUSED = {
    "keyed.idl": "keyed type",
    "keylist.idl": "#pragma keylist declares keys",
    "union.idl": "unions are not read",
    "optional.idl": "@optional members are not read",
    "mutable.idl": "@mutable types are not read",
    "macro.idl": "#define is not read",
}

# Structs checked sample by sample, with max_length for their unbounded strings and sequences.
LAYOUT_CASES = [
    ("geometry_msgs/msg/Twist.idl", "geometry_msgs::msg::Twist", {}),
    ("builtin_interfaces/msg/Time.idl", "builtin_interfaces::msg::Time", {}),
    ("std_msgs/msg/Header.idl", "std_msgs::msg::Header", {"frame_id": 24}),
    ("sensor_msgs/msg/LaserScan.idl", "sensor_msgs::msg::LaserScan",
     {"header.frame_id": 16, "ranges": 8, "intensities": 8}),
    ("cosmic_check/msg/Shapes.idl", "cosmic_check::msg::Shapes", {}),
    ("cosmic_check/msg/Appendable.idl", "cosmic_check::msg::Outer", {}),
    ("cosmic_check/msg/Guarded.idl", "cosmic_check::msg::Guarded", {"label": 10}),
]

CYCLONE_ENV = dict(os.environ, CYCLONEDDS_URI='<CycloneDDS><Domain id="any"><General><Interfaces>'
                   '<NetworkInterface name="lo" multicast="true"/></Interfaces></General></Domain></CycloneDDS>')

failures = []


def fail(what):
    failures.append(what)
    print("FAIL: " + what)


def idl_files(root):
    out = []
    for directory, _, names in os.walk(root):
        out += [os.path.relpath(os.path.join(directory, n), root) for n in names if n.endswith(".idl")]
    return sorted(out)


def idlc_reads(idlc, include_dir, path, out_dir):
    """Whether idlc compiles the file (its C code into out_dir; under include_dir, the directories kept)."""
    base = ["-b", include_dir] if path.startswith(include_dir + os.sep) else []  # -b fails files outside it
    try:
        run = subprocess.run([idlc, "-x", "final", "-I", include_dir] + base + ["-o", out_dir, path],
                             capture_output=True, text=True, timeout=60)
    except subprocess.TimeoutExpired:
        return False, "idlc ran for a minute"  # idlc 0.10.2 loops on a struct containing itself
    return run.returncode == 0, run.stderr.strip()


def ours_reads(peer, include_dir, path):
    run = subprocess.run([peer, "idl-check", include_dir, path], capture_output=True, text=True)
    return run.returncode == 0, run.stdout.strip()


def check_acceptance(idlc, peer, idl_dir, work):
    good = os.path.join(idl_dir, "good")
    for name in idl_files(good):
        path = os.path.join(good, name)
        idlc_ok, idlc_says = idlc_reads(idlc, good, path, os.path.join(work, "gen"))
        ours_ok, ours_says = ours_reads(peer, good, path)
        print("good     %-36s idlc %-7s ours %s" % (name, "accepts" if idlc_ok else "REFUSES",
                                                      "accepts" if ours_ok else "REFUSES"))
        if not idlc_ok:
            fail("idlc refuses good/%s: %s" % (name, idlc_says))
        if not ours_ok:
            fail("the gateway refuses good/%s: %s" % (name, ours_says))
    for directory, expect in (("bad", None), ("refused", REFUSED)):
        root = os.path.join(idl_dir, directory)
        for name in idl_files(root):
            path = os.path.join(root, name)
            idlc_ok, idlc_says = idlc_reads(idlc, good, path, os.path.join(work, "scratch"))
            ours_ok, ours_says = ours_reads(peer, good, path)
            print("%-8s %-36s idlc %-7s ours %-7s %s" % (directory, name, "accepts" if idlc_ok else "refuses",
                                                         "accepts" if ours_ok else "refuses",
                                                         ours_says.splitlines()[0] if ours_says else ""))
            if ours_ok:
                fail("the gateway accepts %s/%s" % (directory, name))
            if expect is None and idlc_ok:
                fail("idlc accepts bad/%s, which the gateway refuses: %s" % (name, ours_says))
            if expect is not None:
                if not idlc_ok:
                    fail("idlc refuses refused/%s (expected to read it): %s" % (name, idlc_says))
                if expect.get(name, "?") not in ours_says:
                    fail("the gateway refuses refused/%s without naming %r: %s" % (name, expect.get(name), ours_says))


def build_cyclone_peer(compiler, ddsc, source_dir, work):
    gen = os.path.join(work, "gen")
    with open(os.path.join(work, "peer_types.c"), "w") as table:
        headers = sorted({case[0][:-4] + ".h" for case in LAYOUT_CASES})
        table.write('#include "cyclone_idl_peer.h"\n')
        table.writelines('#include "%s"\n' % h for h in headers)
        table.write("const struct peer_type kPeerTypes[] = {\n")
        table.writelines('  {"%s", &%s_desc},\n' % (case[1], case[1].replace("::", "_")) for case in LAYOUT_CASES)
        table.write("};\nconst size_t kPeerTypeCount = sizeof kPeerTypes / sizeof kPeerTypes[0];\n")
    sources = [os.path.join(d, n) for d, _, names in os.walk(gen) for n in names if n.endswith(".c")]
    program = os.path.join(work, "cosmic-cyclone-idl-peer")
    subprocess.run([compiler, "-std=gnu11", "-O1", "-w", "-I", gen, "-I", source_dir,
                    os.path.join(source_dir, "cyclone_idl_peer.c"), os.path.join(work, "peer_types.c")] + sources +
                   ["-o", program, ddsc, "-Wl,-rpath," + os.path.dirname(ddsc)], check=True)
    return program


def check_layout(peer, cyclone_peer, good, case):
    name, struct, max_length = case
    path = os.path.join(good, name)
    bounds = ["%s=%d" % item for item in sorted(max_length.items())]
    typed = subprocess.run([peer, "idl-type", good, path, struct] + bounds, capture_output=True, text=True)
    if typed.returncode != 0:
        return fail("the gateway has no type for %s: %s" % (struct, typed.stdout.strip()))
    versions = ["xcdr2"] if typed.stdout.startswith("@appendable") else ["xcdr1", "xcdr2"]
    ours = ""
    for version in versions:
        written = subprocess.run([peer, "idl-samples", good, path, struct, version, str(SAMPLES)] + bounds,
                                 capture_output=True, text=True)
        if written.returncode != 0:
            return fail("our peer did not write samples of %s: %s" % (struct, written.stdout.strip()))
        ours += written.stdout
    ours_lines = [line.split(" ") for line in ours.splitlines()]  # K VERSION HEX TEXT
    cyclone = subprocess.run([cyclone_peer, struct], input="".join("%s %s %s\n" % tuple(l[:3]) for l in ours_lines),
                             capture_output=True, text=True, env=CYCLONE_ENV)
    back = ""
    agreed = 0
    for mine, theirs in zip(ours_lines, cyclone.stdout.splitlines()):
        parts = theirs.split(" ")
        if parts[0] != "ok" or len(parts) != 5:
            fail("%s sample %s %s: %s" % (struct, mine[0], mine[1], theirs))
            continue
        # "dlh:#": an appendable struct's DHEADER, whose value Cyclone prints glued to the first member.
        if not re.fullmatch(re.escape(mine[3]).replace(re.escape("dlh:#"), r"dlh:\d+"), parts[3]):
            fail("%s sample %s %s: Cyclone reads %s, we wrote %s" % (struct, mine[0], mine[1], parts[3], mine[3]))
            continue
        agreed += 1
        back += "%s %s %s\n" % (parts[1], parts[2], parts[4])
    if len(cyclone.stdout.splitlines()) != len(ours_lines):
        fail("%s: Cyclone answered %d of %d samples (exit %d): %s" % (struct, len(cyclone.stdout.splitlines()),
                                                                      len(ours_lines), cyclone.returncode,
                                                                      cyclone.stderr.strip()))
    decoded = subprocess.run([peer, "idl-decode", good, path, struct] + bounds, input=back, capture_output=True,
                             text=True)
    for line in decoded.stdout.splitlines():
        if not line.startswith("ok"):
            fail("%s: Cyclone's sample, read by the gateway: %s" % (struct, line))
    print("layout   %-36s %s: %s, %d samples read by Cyclone as written, its bytes read back (%s)" %
          (struct, typed.stdout.strip()[:60] + ("..." if len(typed.stdout.strip()) > 60 else ""),
           "/".join(versions), agreed, "ok" if decoded.returncode == 0 else "FAILED"))


def main():
    if len(sys.argv) != 6:
        sys.exit(__doc__)
    idlc, compiler, ddsc, peer, source_dir = sys.argv[1:]
    if os.environ.get("COSMIC_IN_NETNS") != "1":
        sys.exit("run me through scripts/netns-run")
    idl_dir = os.path.join(source_dir, "idl")
    work = tempfile.mkdtemp(prefix="cosmic-idlc.")
    try:
        os.makedirs(os.path.join(work, "gen"))
        os.makedirs(os.path.join(work, "scratch"))
        check_acceptance(idlc, peer, idl_dir, work)
        cyclone_peer = build_cyclone_peer(compiler, ddsc, source_dir, work)
        for case in LAYOUT_CASES:
            check_layout(peer, cyclone_peer, os.path.join(idl_dir, "good"), case)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    print("PASS" if not failures else "FAIL (%d)" % len(failures))
    return 0 if not failures else 1


if __name__ == "__main__":
    sys.exit(main())
