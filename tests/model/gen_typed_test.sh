#!/bin/bash
# cosmicctl gen for typed channels (issue 35, item 6): a struct per typed channel with encode and
# decode in the compact layout, checked against the Python package's own implementation of the
# layout (typed/typed_roundtrip.py) under g++ and clang with warnings as errors, and a skeleton whose
# handlers take and give the structs, built with the user's logic file (typed/typed_node_logic.cpp).
# Usage: gen_typed_test.sh COSMICCTL TYPED_DIR PYTHON   (PYTHONPATH: the built package `cosmic`)
set -u
COSMICCTL=$1 TYPED=$2 PYTHON=$3
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
status=0
fail() { echo "FAIL: $*" >&2; status=1; }

OUT="$WORK/node"
mkdir -p "$OUT"
cp "$TYPED/typed_node_logic.cpp" "$OUT/"
"$COSMICCTL" gen "$TYPED/typed_gen.yaml" --component typed_node --output "$OUT" 2>"$WORK/gen.err" || fail "gen exited $?: $(cat "$WORK/gen.err")"
for f in compact.hpp scan_type.hpp diagnostics_type.hpp; do
  [ -s "$OUT/$f" ] || fail "no $f"
done
[ -e "$OUT/plain_type.hpp" ] && fail "a header for the untyped channel plain"
grep -q "kept .*typed_node_logic.cpp" "$WORK/gen.err" || fail "gen did not keep the user's logic file"
header="$OUT/typed_node.hpp"
grep -q "void refresh_diagnostics(const types::diagnostics::Event& event);" "$header" || fail "diagnostics' handler does not take its struct"
grep -q "void refresh_plain(std::span<const std::uint8_t> event);" "$header" || fail "plain's handler does not take its bytes"
grep -q "int publish_scan(const types::scan::Event& event);" "$header" || fail "no publish_scan taking the struct"
# Units and ranges in comments; a field named like a keyword declarable.
grep -q "float distance{};  // m, 0..40" "$OUT/scan_type.hpp" || fail "distance's unit and range are not shown"
grep -q "std::uint8_t class_{};" "$OUT/scan_type.hpp" || fail "the field 'class' is not declared as class_"
grep -q "static constexpr std::size_t ranges_max_size = 3;" "$OUT/scan_type.hpp" || fail "no bound of ranges"

# The structs against Python's compact layout, under each compiler there is.
binaries=()
for cxx in g++-12 clang++-14; do
  command -v "$cxx" >/dev/null || { echo "note: no $cxx" >&2; continue; }
  if "$cxx" -std=c++20 -Wall -Wextra -Werror -I"$OUT" "$TYPED/typed_roundtrip.cpp" -o "$WORK/roundtrip-$cxx" 2>"$WORK/$cxx.err"; then
    binaries+=("$WORK/roundtrip-$cxx")
  else
    fail "$cxx: the generated headers do not compile: $(head -20 "$WORK/$cxx.err")"
  fi
done
[ ${#binaries[@]} -gt 0 ] || fail "no compiler built the round trip"
[ ${#binaries[@]} -gt 0 ] && { "$PYTHON" "$TYPED/typed_roundtrip.py" "$TYPED/typed_gen.yaml" "${binaries[@]}" || fail "round trips against Python"; }

# Names and shapes C++ does not take as they are still compile (typed/edge_gen.yaml), also with
# -Wconversion and -Wshadow.
EDGE="$WORK/edge"
"$COSMICCTL" gen "$TYPED/edge_gen.yaml" --component edge --output "$EDGE" 2>"$WORK/edge.err" || fail "gen edge exited $?: $(cat "$WORK/edge.err")"
printf '#include "new_type.hpp"\n#include "my_channel_v2_type.hpp"\nint main() { return 0; }\n' >"$EDGE/both.cpp"
for cxx in g++-12 clang++-14; do
  command -v "$cxx" >/dev/null || continue
  "$cxx" -std=c++20 -Wall -Wextra -Werror -Wconversion -Wshadow -fsyntax-only -I"$EDGE" "$EDGE/both.cpp" 2>"$WORK/edge-$cxx.err" ||
    fail "$cxx: the edge headers do not compile: $(head -20 "$WORK/edge-$cxx.err")"
done
grep -q "std::int8_t Event_{};" "$EDGE/new_type.hpp" || fail "the field 'Event' is not declared as Event_"
grep -q "namespace types::new_ {" "$EDGE/new_type.hpp" || fail "the channel 'new' is not in namespace types::new_"

# The skeleton builds with its typed handlers and the user's logic, warnings as errors.
if cmake -S "$OUT" -B "$OUT/build" -DCMAKE_CXX_FLAGS=-Werror >"$WORK/cmake.log" 2>&1 &&
  cmake --build "$OUT/build" -j2 >>"$WORK/cmake.log" 2>&1; then
  [ -x "$OUT/build/typed_node" ] || fail "the skeleton built no typed_node"
else
  fail "the skeleton does not build: $(tail -30 "$WORK/cmake.log")"
fi
exit $status
