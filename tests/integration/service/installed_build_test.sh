#!/usr/bin/env bash
# A component builds against the installed packages alone (issue 23, item 7). cpack builds the
# .debs; their contents are unpacked into a scratch root and laid over /usr in a private mount
# namespace (overlayfs, nothing changes outside it), where this source tree and the build tree
# are hidden under empty tmpfs mounts. There, as a component developer would:
#   cosmicctl gen (the installed one) writes the speed controller's skeleton from robot.yaml,
#   the skeleton builds with CMake (find_package(cosmic_client) finds /usr/lib/<triplet>/cmake)
#   and with pkg-config (cosmic-client.pc), links the installed libcosmic-client.so.0 and runs;
#   a C program on cosmic/client.h builds and calls the library; `import cosmic` loads the
#   installed Python package; the manual pages and bash completion are where man and bash look.
# Then the same without libcosmic-client-dev: configuring, pkg-config and compiling must fail,
# which shows that nothing came from the host, the source or the build tree.
# installed_build_inner.sh does the part inside the namespace.
#
# Usage: installed_build_test.sh BUILD_DIR SOURCE_DIR
set -u
BUILD=$(realpath "${1:?build directory}")
SRC=$(realpath "${2:?source directory}")
HERE=$(dirname "$(realpath "$0")")
FAILURES=0
fail() {
  echo "FAIL: $*" >&2
  FAILURES=$((FAILURES + 1))
}
note() { echo "-- $*"; }
[ "$(id -u)" -eq 0 ] || { echo "SKIP: needs root (a mount namespace with overlayfs)"; exit 77; }
for tool in cpack dpkg-deb unshare cmake pkg-config g++ gcc python3; do
  command -v "$tool" >/dev/null || { echo "SKIP: no $tool"; exit 77; }
done

# The host must not already have what the packages bring, or the test could not tell them apart.
ARCH_TRIPLET=$(gcc -print-multiarch)
for leftover in /usr/include/cosmic /usr/local/include/cosmic /usr/lib/"$ARCH_TRIPLET"/cmake/cosmic_client \
                /usr/local/lib/cmake/cosmic_client /usr/local/lib/"$ARCH_TRIPLET"/cmake/cosmic_client \
                /usr/lib/"$ARCH_TRIPLET"/pkgconfig/cosmic-client.pc /usr/local/lib/"$ARCH_TRIPLET"/pkgconfig/cosmic-client.pc; do
  [ -e "$leftover" ] && { echo "SKIP: this machine already has $leftover (an earlier install); remove it to run this test"; exit 77; }
done

WORK=$(mktemp -d /tmp/cosmic-installed-build.XXXXXX)
trap 'rm -rf "$WORK"' EXIT
chmod 755 "$WORK"

note "cpack -G DEB"
if ! cpack -G DEB --config "$BUILD/CPackConfig.cmake" -B "$WORK/pkg" >"$WORK/cpack.log" 2>&1; then
  fail "cpack failed"
  sed 's/^/    /' "$WORK/cpack.log" >&2
  exit 1
fi
VERSION=$(sed -n 's/^set(CPACK_PACKAGE_VERSION "\(.*\)")$/\1/p' "$BUILD/CPackConfig.cmake")
ARCH=$(dpkg --print-architecture)
deb() { echo "$WORK/pkg/${1}_${VERSION}_$ARCH.deb"; }
for package in cosmic-gateway libcosmic-client0 libcosmic-client-dev python3-cosmic; do
  [ -f "$(deb $package)" ] || { fail "cpack made no $(basename "$(deb $package)")"; ls "$WORK/pkg" >&2; exit 1; }
done
dpkg-deb -f "$(deb libcosmic-client-dev)" Depends | grep -qF "libcosmic-client0 (= $VERSION)" ||
  fail "libcosmic-client-dev does not depend on libcosmic-client0 (= $VERSION): $(dpkg-deb -f "$(deb libcosmic-client-dev)" Depends)"

# The installed system: every package; the runtime alone: no -dev.
for package in cosmic-gateway libcosmic-client0 libcosmic-client-dev python3-cosmic; do
  dpkg-deb -x "$(deb $package)" "$WORK/installed"
done
for package in cosmic-gateway libcosmic-client0; do
  dpkg-deb -x "$(deb $package)" "$WORK/runtime"
done
mkdir -p "$WORK/model"
cp "$SRC/config/robot.yaml" "$WORK/model/robot.yaml"
cp "$HERE/installed_build_inner.sh" "$WORK/inner.sh"

# inside MODE ROOT: the inner script in a mount namespace of its own, with a clean environment.
inside() {
  unshare --mount --propagation private -- env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin LANG=C.UTF-8 \
    HOME="$WORK/home-$1" TMPDIR="$WORK" PYTHONNOUSERSITE=1 \
    bash "$WORK/inner.sh" "$1" "$2" "$WORK" "$VERSION" "$ARCH_TRIPLET" "$SRC" "$BUILD"
}
note "build against the installed packages"
inside installed "$WORK/installed"
case $? in
  0) ;;
  77) echo "SKIP: no overlayfs or tmpfs mount in a private namespace here"; exit 77 ;;
  *) fail "building against the installed packages failed (above)" ;;
esac
note "without libcosmic-client-dev nothing builds"
inside runtime "$WORK/runtime"
case $? in
  0) ;;
  77) echo "SKIP: no overlayfs or tmpfs mount in a private namespace here"; exit 77 ;;
  *) fail "without libcosmic-client-dev something still built (above): it came from elsewhere" ;;
esac
[ -e /usr/include/cosmic ] && fail "the overlay leaked out of its namespace: /usr/include/cosmic exists"

if [ "$FAILURES" -ne 0 ]; then
  echo "$FAILURES check(s) failed" >&2
  exit 1
fi
echo "all checks passed"
