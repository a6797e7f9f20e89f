#!/usr/bin/env bash
# `cpack -G DEB` builds an installable package (issue 5, item 8): it holds the binaries, the
# unit, the sysusers file and the example configuration (a conffile); its Depends come from
# dpkg-shlibdeps and cover every library cosmicd and cosmicctl load; it installs, keeps a
# locally changed configuration on reinstall, and purges cleanly. Installation goes into a
# scratch root (dpkg --root with chrootless maintainer scripts, which honour DPKG_ROOT), never
# into this machine's /.
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
mapfile -t debs < <(find "$WORK/pkg" -maxdepth 1 -name '*.deb')
[ "${#debs[@]}" -eq 1 ] || { fail "expected one .deb, found ${#debs[@]}"; exit 1; }
DEB=${debs[0]}
ARCH=$(dpkg --print-architecture)
VERSION=$(sed -n 's/^set(CPACK_PACKAGE_VERSION "\(.*\)")$/\1/p' "$BUILD/CPackConfig.cmake")
[ "$(basename "$DEB")" = "cosmic-gateway_${VERSION}_$ARCH.deb" ] ||
  fail "package file is $(basename "$DEB"), expected cosmic-gateway_${VERSION}_$ARCH.deb"

note "contents"
dpkg-deb -c "$DEB" >"$WORK/contents"
expect_entry() {  # expect_entry MODE PATH
  grep -qE "^$1 root/root +[0-9]+ [0-9-]+ [0-9:]+ \./${2#/}\$" "$WORK/contents" ||
    { fail "the package lacks $2 (mode $1, root/root)"; grep -F "${2#/}" "$WORK/contents" | sed 's/^/    /' >&2; }
}
expect_entry -rwxr-xr-x /usr/sbin/cosmicd
expect_entry -rwxr-xr-x /usr/bin/cosmicctl
expect_entry -rw-r--r-- /usr/lib/systemd/system/cosmicd.service
expect_entry -rw-r--r-- /usr/lib/sysusers.d/cosmic.conf
expect_entry -rw-r--r-- /etc/cosmic/cosmicd.yaml
expect_entry -rw-r--r-- /usr/share/doc/cosmic-gateway/operations.md
expect_entry -rw-r--r-- /usr/share/doc/cosmic-gateway/examples/overloaded.yaml
strays=$(awk '{ print $6 }' "$WORK/contents" | grep -vE '^\./(etc/|etc/cosmic/.*|usr/.*)$')
[ -z "$strays" ] || fail "files outside /etc/cosmic and /usr: $strays"

note "control: Depends from dpkg-shlibdeps"
field() { dpkg-deb -f "$DEB" "$1"; }
[ "$(field Package)" = cosmic-gateway ] || fail "Package: $(field Package)"
[ "$(field Version)" = "$VERSION" ] || fail "Version: $(field Version), expected $VERSION"
[ "$(field Architecture)" = "$ARCH" ] || fail "Architecture: $(field Architecture), expected $ARCH"
DEPENDS=$(field Depends)
[ -n "$DEPENDS" ] || fail "no Depends"
# Every library the two binaries link directly (DT_NEEDED) comes from a package that Depends
# names, itself or through its Provides (libspdlog1.10 provides libspdlog1.10-fmt9).
dpkg-deb -x "$DEB" "$WORK/extracted"
if ! python3 - "$DEPENDS" "$WORK/extracted/usr/sbin/cosmicd" "$WORK/extracted/usr/bin/cosmicctl" <<'PY'
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
then
  fail "Depends ($DEPENDS) misses libraries the binaries need"
fi
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
for f in /usr/sbin/cosmicd /usr/bin/cosmicctl /usr/lib/systemd/system/cosmicd.service \
         /usr/lib/sysusers.d/cosmic.conf /etc/cosmic/cosmicd.yaml; do
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
