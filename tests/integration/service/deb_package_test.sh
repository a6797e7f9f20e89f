#!/usr/bin/env bash
# `cpack -G DEB` builds installable packages (issue 5, item 8; split as Debian does in issue 23,
# item 7): cosmic-gateway holds the binaries, the units, the sysusers file, the example
# configuration (a conffile), the manual pages and the bash completions (cosmic-fmu's with its
# template unit, man page and docs/fmu.md too, issue 38); libcosmic-client0 the
# shared library (with a shlibs file), libcosmic-client-dev what building a component needs,
# python3-cosmic the Python package; every binary is stripped and its debug symbols are in the
# PACKAGE-dbgsym .ddeb under its build id. Every package's Depends (dpkg-shlibdeps) cover every
# library its binaries load; the library exports exactly the functions of cosmic/client.h.
# cosmic-gateway installs, keeps a locally changed configuration on reinstall, and purges
# cleanly. Installation goes into a scratch root (dpkg --root with chrootless maintainer scripts,
# which honour DPKG_ROOT), never into this machine's /. installed_build_test.sh builds a
# component against the packages.
#
# Usage: deb_package_test.sh BUILD_DIR
set -u
BUILD=${1:?build directory}
FAILURES=0
fail() {
  echo "FAIL: $*" >&2
  FAILURES=$((FAILURES + 1))
}
note() { echo "-- $*"; }
for tool in cpack dpkg dpkg-deb dpkg-shlibdeps; do
  command -v "$tool" >/dev/null || { echo "SKIP: no $tool"; exit 77; }
done

WORK=$(mktemp -d /tmp/cosmic-svc-deb.XXXXXX)
trap 'rm -rf "$WORK"' EXIT

note "cpack -G DEB"
if ! cpack -G DEB --config "$BUILD/CPackConfig.cmake" -B "$WORK/pkg" >"$WORK/cpack.log" 2>&1; then
  fail "cpack failed"
  sed 's/^/    /' "$WORK/cpack.log" >&2
  exit 1
fi
grep -qi "warning" "$WORK/cpack.log" && { fail "cpack warned"; sed 's/^/    /' "$WORK/cpack.log" >&2; }
ARCH=$(dpkg --print-architecture)
VERSION=$(sed -n 's/^set(CPACK_PACKAGE_VERSION "\(.*\)")$/\1/p' "$BUILD/CPackConfig.cmake")
PACKAGES="cosmic-gateway libcosmic-client0 libcosmic-client-dev python3-cosmic"
expected_files=$(for p in $PACKAGES; do echo "${p}_${VERSION}_$ARCH.deb"; done
                 for p in cosmic-gateway libcosmic-client0 python3-cosmic; do echo "$p-dbgsym_${VERSION}_$ARCH.ddeb"; done)
actual_files=$(find "$WORK/pkg" -maxdepth 1 -name '*.*deb' -printf '%f\n')
[ "$(sort <<<"$expected_files")" = "$(sort <<<"$actual_files")" ] ||
  fail "package files: $(echo $actual_files), expected $(echo $expected_files)"
DEB=$WORK/pkg/cosmic-gateway_${VERSION}_$ARCH.deb
[ -f "$DEB" ] || exit 1

note "contents"
dpkg-deb -c "$DEB" >"$WORK/contents"
expect_entry() {  # expect_entry MODE PATH
  grep -qE "^$1 root/root +[0-9]+ [0-9-]+ [0-9:]+ \./${2#/}\$" "$WORK/contents" ||
    { fail "the package lacks $2 (mode $1, root/root)"; grep -F "${2#/}" "$WORK/contents" | sed 's/^/    /' >&2; }
}
expect_entry -rwxr-xr-x /usr/sbin/cosmicd
expect_entry -rwxr-xr-x /usr/bin/cosmicctl
expect_entry -rwxr-xr-x /usr/bin/cosmic-fmu
expect_entry -rw-r--r-- /usr/lib/systemd/system/cosmicd.service
expect_entry -rw-r--r-- /usr/lib/systemd/system/cosmic-fmu@.service
expect_entry -rw-r--r-- /usr/lib/sysusers.d/cosmic.conf
expect_entry -rw-r--r-- /etc/cosmic/cosmicd.yaml
expect_entry -rw-r--r-- /usr/share/doc/cosmic-gateway/operations.md
expect_entry -rw-r--r-- /usr/share/doc/cosmic-gateway/examples/overloaded.yaml
expect_entry -rw-r--r-- /usr/share/man/man8/cosmicd.8.gz
expect_entry -rw-r--r-- /usr/share/man/man1/cosmicctl.1.gz
expect_entry -rw-r--r-- /usr/share/man/man1/cosmic-fmu.1.gz
expect_entry -rw-r--r-- /usr/share/bash-completion/completions/cosmicctl
expect_entry -rw-r--r-- /usr/share/bash-completion/completions/cosmic-fmu
expect_entry -rw-r--r-- /usr/share/doc/cosmic-gateway/fmu.md
strays=$(awk '{ print $6 }' "$WORK/contents" | grep -vE '^\./(etc/|etc/cosmic/.*|usr/.*)$')
[ -z "$strays" ] || fail "files outside /etc/cosmic and /usr: $strays"

note "control: Depends from dpkg-shlibdeps"
field() { dpkg-deb -f "$DEB" "$1"; }
[ "$(field Package)" = cosmic-gateway ] || fail "Package: $(field Package)"
[ "$(field Version)" = "$VERSION" ] || fail "Version: $(field Version), expected $VERSION"
[ "$(field Architecture)" = "$ARCH" ] || fail "Architecture: $(field Architecture), expected $ARCH"
field Description | grep -q "cosmic-fmu runs" || fail "the Description does not mention cosmic-fmu: $(field Description)"
DEPENDS=$(field Depends)
[ -n "$DEPENDS" ] || fail "no Depends"
# Every library each binary of each package links directly (DT_NEEDED) comes from a package that
# its Depends names, itself or through its Provides (libspdlog1.10 provides libspdlog1.10-fmt9).
# depends_cover PACKAGE: extracts it to $WORK/extracted/PACKAGE and checks its ELF files.
depends_cover() {
  local deb=$WORK/pkg/${1}_${VERSION}_$ARCH.deb dir=$WORK/extracted/$1 elves
  mkdir -p "$dir"
  dpkg-deb -x "$deb" "$dir"
  mapfile -t elves < <(find "$dir" -type f -exec sh -c 'head -c 4 "$1" | grep -q "ELF"' _ {} \; -print | sort)
  [ "${#elves[@]}" -gt 0 ] || return 0
  python3 - "$(dpkg-deb -f "$deb" Depends)" "${elves[@]}" <<'PY' || fail "$1: Depends ($(dpkg-deb -f "$deb" Depends)) misses libraries its binaries need"
import os, re, subprocess, sys
depends = {re.sub(r"[ (].*", "", alt.strip()) for part in sys.argv[1].split(",") for alt in part.split("|")}
def run(*args):
    return subprocess.run(args, capture_output=True, text=True).stdout
def owners(path):
    candidates = [path, os.path.realpath(path)]
    candidates += [c.replace("/lib/", "/usr/lib/", 1) for c in candidates if c.startswith("/lib/")]
    candidates += [c.replace("/usr/lib/", "/lib/", 1) for c in candidates if c.startswith("/usr/lib/")]
    for c in candidates:
        out = run("dpkg", "-S", c)
        if out:
            return {line.split(":")[0] for line in out.splitlines()}
    return set()
bad = 0
for binary in sys.argv[2:]:
    needed = re.findall(r"NEEDED\s+(\S+)", run("objdump", "-p", binary))
    listing = run("ldd", binary)
    resolved = dict(re.findall(r"^\s*(\S+) => (/\S+)", listing, re.M))
    # The dynamic loader is listed by path alone; it is NEEDED too where code uses dynamic TLS
    # (__tls_get_addr, e.g. thread_local in position-independent code).
    for loader in re.findall(r"^\s*(/\S+) \(0x", listing, re.M):
        resolved.setdefault(os.path.basename(loader), loader)
    for soname in needed:
        path = resolved.get(soname)
        packages = owners(path) if path else set()
        names = set(packages)
        for p in packages:
            names |= {re.sub(r"[ (].*", "", x.strip()) for x in run("dpkg-query", "-W", "-f=${Provides}", p).split(",") if x.strip()}
        if not names & depends:
            print(f"FAIL: {os.path.basename(binary)} needs {soname} ({path}, from {sorted(packages) or 'no package'}), "
                  f"which Depends does not cover", file=sys.stderr)
            bad += 1
        else:
            print(f"   {os.path.basename(binary)}: {soname} <- {sorted(names & depends)[0]}")
sys.exit(1 if bad else 0)
PY
}
for package in $PACKAGES; do
  depends_cover "$package"
done

note "libcosmic-client0, libcosmic-client-dev, python3-cosmic"
X=$WORK/extracted
LIB=usr/lib/$(gcc -print-multiarch)
[ -f "$X/libcosmic-client0/$LIB/libcosmic-client.so.$VERSION" ] || fail "libcosmic-client0 lacks /$LIB/libcosmic-client.so.$VERSION"
[ "$(readlink "$X/libcosmic-client0/$LIB/libcosmic-client.so.0")" = "libcosmic-client.so.$VERSION" ] ||
  fail "libcosmic-client0: libcosmic-client.so.0 is not a link to libcosmic-client.so.$VERSION"
[ "$(objdump -p "$X/libcosmic-client0/$LIB/libcosmic-client.so.$VERSION" | awk '/SONAME/ { print $2 }')" = libcosmic-client.so.0 ] ||
  fail "the library's SONAME is not libcosmic-client.so.0"
dpkg-deb -e "$WORK/pkg/libcosmic-client0_${VERSION}_$ARCH.deb" "$WORK/control-lib"
grep -qx "libcosmic-client 0 libcosmic-client0 (>= $VERSION)" "$WORK/control-lib/shlibs" 2>/dev/null ||
  fail "libcosmic-client0 has no shlibs line for libcosmic-client.so.0: $(cat "$WORK/control-lib/shlibs" 2>&1)"
grep -qx "activate-noawait ldconfig" "$WORK/control-lib/triggers" 2>/dev/null || fail "libcosmic-client0 does not trigger ldconfig"
# The ABI is the C API: the functions client.h declares, every one of them and nothing else.
declared=$(gcc -E -P -x c "$X/libcosmic-client-dev/usr/include/cosmic/client.h" | grep -oE '\bcosmic_[a-z_]+ *\(' | tr -d ' (' | sort -u)
# (the version node COSMIC_CLIENT_0 is listed as an absolute symbol: it names the ABI, it is no function)
exported=$(nm -D --defined-only "$X/libcosmic-client0/$LIB/libcosmic-client.so.$VERSION" | awk '$2 != "A" { print $3 }' | sed 's/@.*//' | sort -u)
[ -n "$declared" ] && [ "$declared" = "$exported" ] ||
  fail "the library exports $(comm -13 <(echo "$declared") <(echo "$exported") | tr '\n' ' ')beyond client.h and lacks $(comm -23 <(echo "$declared") <(echo "$exported") | tr '\n' ' ')"
for f in usr/include/cosmic/client.h usr/include/cosmic/client.hpp $LIB/pkgconfig/cosmic-client.pc \
         $LIB/cmake/cosmic_client/cosmic_client-config.cmake $LIB/cmake/cosmic_client/cosmic_client-config-version.cmake \
         $LIB/cmake/cosmic_client/cosmic_client-targets.cmake; do
  [ -f "$X/libcosmic-client-dev/$f" ] || fail "libcosmic-client-dev lacks /$f"
done
[ "$(readlink "$X/libcosmic-client-dev/$LIB/libcosmic-client.so")" = libcosmic-client.so.0 ] ||
  fail "libcosmic-client-dev: libcosmic-client.so is not a link to libcosmic-client.so.0"
grep -qx "prefix=/usr" "$X/libcosmic-client-dev/$LIB/pkgconfig/cosmic-client.pc" || fail "cosmic-client.pc: the prefix is not /usr"
ls "$X/python3-cosmic/usr/lib/python3/dist-packages/cosmic/"_native.cpython-*.so >/dev/null 2>&1 &&
  [ -f "$X/python3-cosmic/usr/lib/python3/dist-packages/cosmic/__init__.py" ] ||
  fail "python3-cosmic lacks the package cosmic in /usr/lib/python3/dist-packages"
dpkg-deb -f "$WORK/pkg/python3-cosmic_${VERSION}_$ARCH.deb" Depends | grep -qE "python3 \(<< 3\.[0-9]+\)" ||
  fail "python3-cosmic does not bound the python3 its extension is built for"
# No file in two packages (dpkg would refuse to install the second).
for p in $PACKAGES; do dpkg-deb -c "$WORK/pkg/${p}_${VERSION}_$ARCH.deb" | awk '$1 !~ /^d/ { print $6 }'; done | sort | uniq -d >"$WORK/shared"
[ -s "$WORK/shared" ] && fail "files in more than one package: $(tr '\n' ' ' <"$WORK/shared")"

note "stripped binaries, debug symbols in the -dbgsym packages"
for p in cosmic-gateway libcosmic-client0 python3-cosmic; do
  dpkg-deb -x "$WORK/pkg/$p-dbgsym_${VERSION}_$ARCH.ddeb" "$WORK/dbgsym"
done
while read -r elf; do
  [ -L "$elf" ] && continue
  readelf -S "$elf" | grep -q '\.debug_info' && fail "${elf#"$X"/} is not stripped"
  id=$(readelf -n "$elf" | sed -n 's/^ *Build ID: //p')
  [ -n "$id" ] || { fail "${elf#"$X"/} has no build id"; continue; }
  debug=$WORK/dbgsym/usr/lib/debug/.build-id/${id:0:2}/${id:2}.debug
  readelf -S "$debug" 2>/dev/null | grep -q '\.debug_info' || fail "no debug symbols for ${elf#"$X"/} ($debug)"
done < <(find "$X" -type f -exec sh -c 'head -c 4 "$1" | grep -q "ELF"' _ {} \; -print)
dpkg-deb -e "$DEB" "$WORK/control"
[ "$(cat "$WORK/control/conffiles")" = /etc/cosmic/cosmicd.yaml ] || fail "conffiles: $(cat "$WORK/control/conffiles")"
for script in postinst prerm postrm; do
  [ -x "$WORK/control/$script" ] || fail "no executable $script"
done

# dpkg_root ARGS...: dpkg on the scratch root. Maintainer scripts run outside a chroot with
# DPKG_ROOT set; dependencies are this machine's, not the scratch root's, hence --force-depends.
ROOT=$WORK/root
mkdir -p "$ROOT/var/lib/dpkg/info" "$ROOT/var/lib/dpkg/updates"
: >"$ROOT/var/lib/dpkg/status"
dpkg_root() {
  dpkg --root="$ROOT" --log="$WORK/dpkg.log" --force-script-chrootless --force-not-root --force-depends "$@"
}
HOST_COSMIC_BEFORE=$(getent passwd cosmic; getent group cosmic cosmic-admin)

note "dpkg -i into a scratch root"
if ! dpkg_root -i "$DEB" >"$WORK/install.log" 2>&1; then
  fail "dpkg -i failed"
  sed 's/^/    /' "$WORK/install.log" >&2
fi
dpkg_root -s cosmic-gateway 2>/dev/null | grep -q '^Status: install ok installed$' || fail "the package is not installed in the scratch root"
for f in /usr/sbin/cosmicd /usr/bin/cosmicctl /usr/bin/cosmic-fmu /usr/lib/systemd/system/cosmicd.service \
         /usr/lib/systemd/system/cosmic-fmu@.service /usr/lib/sysusers.d/cosmic.conf /etc/cosmic/cosmicd.yaml; do
  [ -f "$ROOT$f" ] || fail "$f not installed"
done
grep -q '^cosmic:' "$ROOT/etc/passwd" 2>/dev/null || fail "postinst did not create the user cosmic in the root"
for g in cosmic cosmic-admin; do
  grep -q "^$g:" "$ROOT/etc/group" 2>/dev/null || fail "postinst did not create the group $g in the root"
done
[ "$HOST_COSMIC_BEFORE" = "$(getent passwd cosmic; getent group cosmic cosmic-admin)" ] ||
  fail "installing into the scratch root changed this machine's users or groups"
"$ROOT/usr/bin/cosmicctl" check "$ROOT/etc/cosmic/cosmicd.yaml" >"$WORK/check.out" 2>&1 ||
  { fail "the installed cosmicctl does not accept the installed configuration"; sed 's/^/    /' "$WORK/check.out" >&2; }
"$ROOT/usr/sbin/cosmicd" --help >/dev/null 2>&1 || fail "the installed cosmicd does not run"
"$ROOT/usr/bin/cosmic-fmu" --help >/dev/null 2>&1 || fail "the installed cosmic-fmu does not run"

note "reinstall keeps a changed configuration (conffile)"
echo "# changed by the operator" >>"$ROOT/etc/cosmic/cosmicd.yaml"
if ! dpkg_root --force-confold -i "$DEB" >"$WORK/reinstall.log" 2>&1; then
  fail "reinstalling failed"
  sed 's/^/    /' "$WORK/reinstall.log" >&2
fi
grep -q "changed by the operator" "$ROOT/etc/cosmic/cosmicd.yaml" || fail "reinstalling replaced the changed /etc/cosmic/cosmicd.yaml"

note "remove, then purge"
mkdir -p "$ROOT/var/lib/cosmicd" && echo '{}' >"$ROOT/var/lib/cosmicd/bindings.json"
dpkg_root -r cosmic-gateway >"$WORK/remove.log" 2>&1 || { fail "dpkg -r failed"; sed 's/^/    /' "$WORK/remove.log" >&2; }
[ -e "$ROOT/usr/sbin/cosmicd" ] && fail "dpkg -r left /usr/sbin/cosmicd"
[ -e "$ROOT/usr/bin/cosmic-fmu" ] && fail "dpkg -r left /usr/bin/cosmic-fmu"
[ -f "$ROOT/etc/cosmic/cosmicd.yaml" ] || fail "dpkg -r removed the conffile (only purge should)"
dpkg_root -P cosmic-gateway >"$WORK/purge.log" 2>&1 || { fail "dpkg -P failed"; sed 's/^/    /' "$WORK/purge.log" >&2; }
[ -e "$ROOT/etc/cosmic" ] && fail "purge left /etc/cosmic"
[ -e "$ROOT/var/lib/cosmicd" ] && fail "purge left /var/lib/cosmicd"
dpkg_root -s cosmic-gateway >/dev/null 2>&1 && fail "the package is still known after purge"

if [ "$FAILURES" -ne 0 ]; then
  echo "$FAILURES check(s) failed" >&2
  exit 1
fi
echo "all checks passed"
