#!/usr/bin/env bash
# The lightcuts command line end to end: a small render with stats and
# heatmaps, compare on identical and on different images, info, and bad
# input (a clear message naming the file and field, a non-zero exit, no
# output file left behind).
#   tests/cli_test.sh BUILD_DIR
set -uo pipefail
exe="$1/host/lightcuts"
root="$(cd "$(dirname "$0")/.." && pwd)"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# A render writes the EXR, the PNG beside it, the stats JSON and the cut map.
"$exe" render "$root/scenes/room/room.json" -o "$tmp/a.exr" --width 24 --height 16 --device cpu \
  --method lightcuts --stats "$tmp/a.json" --cut-heatmap "$tmp/cuts.png" >"$tmp/out.txt" 2>&1 ||
  fail "render exited non-zero: $(cat "$tmp/out.txt")"
for f in a.exr a.png a.json cuts.png; do [ -s "$tmp/$f" ] || fail "render did not write $f"; done
grep -q '"cut_size_mean"' "$tmp/a.json" || fail "stats JSON lacks cut_size_mean"
ls "$tmp" | grep -q '\.tmp' && fail "temporary files left behind"

# compare: identical images give zero error; brute force differs from lightcuts a little.
"$exe" compare "$tmp/a.exr" "$tmp/a.exr" --json >"$tmp/same.json" || fail "compare exited non-zero"
grep -q '"relative_rmse": 0.0' "$tmp/same.json" || fail "identical images: $(cat "$tmp/same.json")"
"$exe" render "$root/scenes/room/room.json" -o "$tmp/b.exr" --width 24 --height 16 --device cpu \
  --method brute --no-png >/dev/null 2>&1 || fail "brute render exited non-zero"
"$exe" compare "$tmp/a.exr" "$tmp/b.exr" --heatmap "$tmp/err.png" >"$tmp/cmp.txt" || fail "compare failed"
grep -q "relative RMSE" "$tmp/cmp.txt" && [ -s "$tmp/err.png" ] || fail "compare output: $(cat "$tmp/cmp.txt")"

"$exe" info "$root/scenes/room/room.json" | grep -q "point lights       1000" || fail "info"

# Bad input: message names the file and the field, exit is non-zero, no output.
expect_error() {  # expected-substring, then the command's arguments
  local want="$1"; shift
  if "$exe" "$@" >"$tmp/err.txt" 2>&1; then fail "succeeded: $*"; return; fi
  grep -qF -- "$want" "$tmp/err.txt" || fail "'$*' said: $(cat "$tmp/err.txt") (wanted '$want')"
}
expect_error "missing.json: file not found" render "$tmp/missing.json" -o "$tmp/c.exr"
expect_error "lights" render "$root/tests/data/scenes/bad_empty_lights.json" -o "$tmp/c.exr"
expect_error "bad_fov.json: camera.fov_y_degrees" render "$root/tests/data/scenes/bad_fov.json" -o "$tmp/c.exr"
expect_error "folder $tmp/nowhere does not exist" render "$root/scenes/room/room.json" -o "$tmp/nowhere/c.exr"
expect_error "must end in .exr" render "$root/scenes/room/room.json" -o "$tmp/c.png"
expect_error "nope.exr" compare "$tmp/a.exr" "$tmp/nope.exr"
[ -e "$tmp/c.exr" ] && fail "a failed render left c.exr behind"

echo "$(( failures == 0 ? 1 : 0 )) passed, $failures failed"
[ "$failures" -eq 0 ]
