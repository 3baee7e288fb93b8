#!/usr/bin/env bash
# The lightcuts command line end to end: a small render with stats and
# heatmaps, compare on identical and on different images, info, bad input
# (a clear message naming the file and field, a non-zero exit, no output file
# left behind), the settings' range edges, the device fallback, and failures
# after the render that must leave no output and no temporary.
#   tests/cli_test.sh BUILD_DIR
set -uo pipefail
# Checks pipe into `grep PATTERN >/dev/null`, not `grep -q`: -q stops reading
# at the first match, the writer can then die of SIGPIPE, and pipefail makes
# that a failure (it did, now and then, under load).
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
grep -q '"black_lights": 0' "$tmp/a.json" || fail "stats JSON lacks black_lights"
ls "$tmp" | grep '\.tmp' >/dev/null && fail "temporary files left behind"

# compare: identical images give zero error; brute force differs from lightcuts a little.
"$exe" compare "$tmp/a.exr" "$tmp/a.exr" --json >"$tmp/same.json" || fail "compare exited non-zero"
grep -Eq '"relative_rmse": 0\.0,?$' "$tmp/same.json" || fail "identical images: $(cat "$tmp/same.json")"
"$exe" render "$root/scenes/room/room.json" -o "$tmp/b.exr" --width 24 --height 16 --device cpu \
  --method brute --no-png >/dev/null 2>&1 || fail "brute render exited non-zero"
"$exe" compare "$tmp/a.exr" "$tmp/b.exr" --heatmap "$tmp/err.png" >"$tmp/cmp.txt" || fail "compare failed"
grep -q "relative RMSE" "$tmp/cmp.txt" && [ -s "$tmp/err.png" ] || fail "compare output: $(cat "$tmp/cmp.txt")"
# A relative RMSE above zero and below 10%: lightcuts at its 2% threshold.
awk '/^relative RMSE/ { found = 1; ok = ($3 > 0 && $3 < 0.1) } END { exit !(found && ok) }' "$tmp/cmp.txt" ||
  fail "brute force against lightcuts: $(grep 'relative RMSE' "$tmp/cmp.txt")"

"$exe" info "$root/scenes/room/room.json" | grep "point lights       1000" >/dev/null || fail "info"
# info sizes the buffers for the area-light samples asked for, as render would make them.
"$exe" info "$root/scenes/panels/panels.json" --area-samples 5000 | grep "area-light samples 5000$" >/dev/null ||
  fail "info --area-samples"
"$exe" info "$root/scenes/panels/panels.json" --area-samples 0 2>/dev/null && fail "info --area-samples 0 accepted"
# ... and for none where the path tracer, which samples the surfaces itself, renders.
"$exe" info "$root/scenes/panels/panels.json" --method path | grep "area-light samples 0$" >/dev/null ||
  fail "info --method path"
# A write to stdout that fails (a full disk) is an error, not an empty success.
if [ -w /dev/full ]; then
  "$exe" info "$root/scenes/room/room.json" >/dev/full 2>/dev/null && fail "info into a full disk succeeded"
  "$exe" compare "$tmp/a.exr" "$tmp/a.exr" --json >/dev/full 2>/dev/null && fail "compare into a full disk succeeded"
fi
# ... and for the VPLs render would make with the same options and seed.
v_info=$("$exe" info "$root/scenes/cornell/cornell.json" --vpls 2000 --seed 7 | sed -n 's/^  VPLs *\([0-9]*\) from.*/\1/p')
v_render=$("$exe" render "$root/scenes/cornell/cornell.json" --vpls 2000 --seed 7 --width 8 --height 8 --no-png \
  -o "$tmp/vpls.exr" 2>&1 | sed -n 's/.*and \([0-9]*\) VPLs from.*/\1/p')
[ -n "$v_info" ] && [ "$v_info" = "$v_render" ] || fail "info --vpls --seed: $v_info VPLs, render $v_render"

# Bad input: message names the file and the field, exit is non-zero, no output.
expect_error() {  # expected-substring, then the command's arguments
  local want="$1"; shift
  if "$exe" "$@" >"$tmp/err.txt" 2>&1; then fail "succeeded: $*"; return; fi
  grep -qF -- "$want" "$tmp/err.txt" || fail "'$*' said: $(cat "$tmp/err.txt") (wanted '$want')"
}
expect_error "missing.json: file not found" render "$tmp/missing.json" -o "$tmp/c.exr"
expect_error "lights" render "$root/tests/data/scenes/bad_empty_lights.json" -o "$tmp/c.exr"
expect_error "bad_fov.json: camera.fov_y_degrees" render "$root/tests/data/scenes/bad_fov.json" -o "$tmp/c.exr"
# Each kind of light of the light model: spot, spots CSV, environment, emission.
expect_error "bad_spot_outer.json: lights[0].outer_cone_degrees" \
  render "$root/tests/data/scenes/bad_spot_outer.json" -o "$tmp/c.exr"
expect_error "bad_spots.csv: line 3" render "$root/tests/data/scenes/bad_spots_csv.json" -o "$tmp/c.exr"
expect_error "bad_env_nan.exr: pixel (1, 0)" render "$root/tests/data/scenes/bad_env_nan.json" -o "$tmp/c.exr"
expect_error "bad_env_two.json: lights[1]" render "$root/tests/data/scenes/bad_env_two.json" -o "$tmp/c.exr"
expect_error "bad_ke.obj: material 'glow'.Ke" render "$root/tests/data/scenes/bad_mtl_ke.json" -o "$tmp/c.exr"
expect_error "--area-samples" render "$root/scenes/room/room.json" -o "$tmp/c.exr" --area-samples 0
expect_error "--spp: must be an integer from 1 to 65536" render "$root/scenes/room/room.json" -o "$tmp/c.exr" --spp 2.5
# A whole number written with a point or an exponent is that integer, as in a scene file.
"$exe" render "$root/scenes/room/room.json" -o "$tmp/w.exr" --no-png --device cpu --width 1.2e1 --height 8.0 \
  --stats "$tmp/w.json" >/dev/null 2>&1 || fail "--width 1.2e1 --height 8.0 were refused"
grep -Eq '"width": 12,?$' "$tmp/w.json" || fail "--width 1.2e1 did not give 12 columns"
rm -f "$tmp/w.exr" "$tmp/w.json"
expect_error "folder $tmp/nowhere does not exist" render "$root/scenes/room/room.json" -o "$tmp/nowhere/c.exr"
expect_error "must end in .exr" render "$root/scenes/room/room.json" -o "$tmp/c.png"
expect_error "nope.exr" compare "$tmp/a.exr" "$tmp/nope.exr"
expect_error "heatmap $tmp/err.exr: must end in .png" compare "$tmp/a.exr" "$tmp/a.exr" --heatmap "$tmp/err.exr"
expect_error "bad_env_nan.exr: pixel (1, 0)" compare "$root/tests/data/scenes/bad_env_nan.exr" "$root/tests/data/scenes/bad_env_nan.exr"
# compare's heatmap is checked before anything is read or printed: not into
# a missing folder, not over one of the images compared.
"$exe" compare "$tmp/a.exr" "$tmp/a.exr" --heatmap "$tmp/nowhere/h.png" >"$tmp/cmp_out.txt" 2>"$tmp/cmp_err.txt" &&
  fail "compare wrote a heatmap into a missing folder"
grep -qF "heatmap $tmp/nowhere/h.png: folder $tmp/nowhere does not exist" "$tmp/cmp_err.txt" &&
  [ ! -s "$tmp/cmp_out.txt" ] || fail "compare --heatmap into a missing folder: $(cat "$tmp/cmp_out.txt" "$tmp/cmp_err.txt")"
cp "$tmp/a.exr" "$tmp/a_copy.png"
expect_error "heatmap $tmp/a_copy.png: is the image compared" compare "$tmp/a_copy.png" "$tmp/a.exr" --heatmap "$tmp/a_copy.png"
cmp -s "$tmp/a.exr" "$tmp/a_copy.png" || fail "compare --heatmap replaced the image it compared"
rm -f "$tmp/a_copy.png"
# A file option given as "" names no file; it is refused, not ignored.
expect_error "--stats: the file name is empty" render "$root/scenes/room/room.json" -o "$tmp/c.exr" --stats ""
expect_error "--heatmap: the file name is empty" compare "$tmp/a.exr" "$tmp/a.exr" --heatmap ""
# Outputs are renamed into place, which would replace a symbolic link
# (/dev/stdout is one) or a device's name: both refused.
ln -s "$tmp/linked.json" "$tmp/link.json"
expect_error "stats file $tmp/link.json: is a symbolic link" render "$root/scenes/room/room.json" -o "$tmp/c.exr" \
  --stats "$tmp/link.json"
[ -L "$tmp/link.json" ] || fail "a refused render replaced the symbolic link"
rm -f "$tmp/link.json"
# (A pipe of our own, not /dev/null: a build that took the rename would
# replace the system's /dev/null when the tests run as root.)
mkfifo "$tmp/pipe.json"
expect_error "stats file $tmp/pipe.json: is not a regular file" render "$root/scenes/room/room.json" -o "$tmp/c.exr" \
  --stats "$tmp/pipe.json"
[ -p "$tmp/pipe.json" ] || fail "a refused render replaced the pipe"
rm -f "$tmp/pipe.json"
expect_error "$root/scenes: is a folder, not a file" render "$root/scenes" -o "$tmp/c.exr"
# A relative error against a black reference is infinite: compare --json
# says "inf" (JSON has no infinite number; null would read as no value).
sed 's/"look_at": \[0, 0.5, 0\]/"look_at": [0, 0.5, 10]/' "$root/tests/data/scenes/minimal.json" >"$tmp/black.json"
cp "$root/tests/data/scenes/tri.obj" "$tmp/"
"$exe" render "$tmp/black.json" -o "$tmp/black.exr" --no-png --device cpu >/dev/null 2>&1 &&
  "$exe" render "$root/tests/data/scenes/minimal.json" -o "$tmp/lit.exr" --no-png --device cpu >/dev/null 2>&1 ||
  fail "rendering the black and the lit triangle"
"$exe" compare "$tmp/lit.exr" "$tmp/black.exr" --json >"$tmp/inf.json" || fail "compare against a black reference failed"
grep -q '"relative_rmse": "inf"' "$tmp/inf.json" || fail "compare --json against black: $(cat "$tmp/inf.json")"
# A scene in a folder whose name is not UTF-8 (Linux allows any byte but
# '/' and NUL) renders, and its stats name it with U+FFFD for the odd byte.
odd="$tmp/$(printf 'odd\377')"
mkdir "$odd" && cp "$root/tests/data/scenes/minimal.json" "$root/tests/data/scenes/tri.obj" "$odd/"
"$exe" render "$odd/minimal.json" -o "$tmp/odd.exr" --no-png --device cpu --width 4 --height 4 \
  --stats "$tmp/odd.json" >"$tmp/odd_log.txt" 2>&1 || fail "a scene under a non-UTF-8 folder: $(cat "$tmp/odd_log.txt")"
grep -q "odd$(printf '\357\277\275')/minimal.json" "$tmp/odd.json" || fail "its stats: $(grep scene "$tmp/odd.json")"
rm -rf "$odd" "$tmp"/{odd.exr,odd.json,black.json,black.exr,lit.exr,tri.obj,inf.json}
[ -e "$tmp/c.exr" ] && fail "a failed render left c.exr behind"

# No output may replace a file the scene reads (on a copy of the room, so
# that a broken check cannot damage the repository's).
mkdir -p "$tmp/inputs" && cp "$root"/scenes/room/{room.json,room.obj,room.mtl,torus.obj,room_lights.csv} "$tmp/inputs/" ||
  fail "copying the room"
before=$(md5sum "$tmp"/inputs/* | md5sum)
expect_error "stats file $tmp/inputs/room.obj: is the file the scene reads" \
  render "$tmp/inputs/room.json" -o "$tmp/c.exr" --stats "$tmp/inputs/room.obj" --width 8 --height 8
expect_error "is the file the scene reads" \
  render "$tmp/inputs/room.json" -o "$tmp/c.exr" --stats "$tmp/inputs/room_lights.csv" --width 8 --height 8
expect_error "is the file the scene reads" \
  render "$tmp/inputs/room.json" -o "$tmp/c.exr" --stats "$tmp/inputs/room.mtl" --width 8 --height 8
[ "$(md5sum "$tmp"/inputs/* | md5sum)" = "$before" ] || fail "a refused render changed the scene's files"
[ -e "$tmp/c.exr" ] && fail "a refused render left c.exr behind"

# glTF: rendered directly (its camera, or the one --camera names), read by
# info, its notes on stderr, and bad files refused naming the glTF path.
gltf="$root/tests/data/gltf"
"$exe" render "$root/scenes/gltf/textured.gltf" -o "$tmp/g.exr" --width 16 --height 12 --device cpu \
  --method lightcuts --area-samples 256 --no-png >"$tmp/g.txt" 2>&1 || fail "glTF render: $(cat "$tmp/g.txt")"
[ -s "$tmp/g.exr" ] || fail "glTF render wrote no image"
"$exe" render "$gltf/triangle.glb" -o "$tmp/glb.exr" --width 4 --height 4 --device cpu --no-png \
  >/dev/null 2>"$tmp/glb.txt" || fail "glb render: $(cat "$tmp/glb.txt")"
grep -q "^note: .*triangle.glb: no perspective camera" "$tmp/glb.txt" || fail "glb render said: $(cat "$tmp/glb.txt")"
"$exe" info "$root/scenes/gltf/textured.gltf" --camera top | grep "image              256x256" >/dev/null ||
  fail "info --camera top"
"$exe" info "$root/scenes/gltf/textured.gltf" | grep "image              341x256" >/dev/null || fail "info: first camera"
"$exe" info "$gltf/modes.gltf" 2>&1 | grep "^note: .*primitives\[2\].mode: POINTS is not drawn" >/dev/null ||
  fail "info: no note about the skipped points"
expect_error "textured.gltf: --camera: no perspective camera named 'side'" \
  render "$root/scenes/gltf/textured.gltf" -o "$tmp/c.exr" --camera side
expect_error "--camera picks a camera of a glTF scene" render "$root/tests/data/scenes/minimal.json" -o "$tmp/c.exr" --camera top
expect_error "bad_index_range.gltf: meshes[0].primitives[0].indices: index 7" render "$gltf/bad_index_range.gltf" -o "$tmp/c.exr"
expect_error "bad_required_draco.gltf: extensionsRequired[0]" render "$gltf/bad_required_draco.gltf" -o "$tmp/c.exr"
expect_error "bad_no_light.gltf: the scene has no light" render "$gltf/bad_no_light.gltf" -o "$tmp/c.exr"
[ -e "$tmp/c.exr" ] && fail "a refused glTF render left c.exr behind"

# Range edges: the command line takes the ranges of lightcuts/settings.h and
# says what is wrong in the words the scene loader uses.
mini="$root/tests/data/scenes/minimal.json"
accept() {  # options for a CPU render of the one-triangle scene
  "$exe" render "$mini" -o "$tmp/edge.exr" --no-png --device cpu "$@" >"$tmp/err.txt" 2>&1 ||
    fail "refused $*: $(cat "$tmp/err.txt")"
}
accept --width 1 --height 1 --spp 1 --error 0 --max-cut 1 --seed 0 --method lightcuts
accept --width 1 --height 1 --spp 65536 --error 1 --max-cut 4000000000 --seed 4294967295 --method lightcuts
accept --width 1 --height 1 --max-cut 4294967295 --method lightcuts
accept --width 2 --height 2 --method sampled --light-samples 1 --light-pick uniform
accept --width 2 --height 2 --method sampled --light-samples 65536 --light-pick power
accept --width 2 --height 2 --method stochastic --spp 4 --light-pick tree
accept --width 2 --height 2 --method lightcuts --vpls 0 --vpl-bounces 0 --vpl-clamp 0
accept --width 2 --height 2 --method lightcuts --vpls 100 --vpl-bounces 1024 --vpl-clamp 0.5
accept --width 2 --height 2 --method path --spp 2 --max-bounces 0 --time-limit 0
accept --width 3 --height 3 --method lightcuts --cut-sharing quad --stats "$tmp/quad.json"
grep -q '"cut_sharing": "quad"' "$tmp/quad.json" || fail "--cut-sharing quad: the stats do not say quad"
accept --width 3 --height 3 --method lightcuts --cut-sharing pixel --stats "$tmp/quad.json"
grep -q '"cut_sharing": "pixel"' "$tmp/quad.json" || fail "--cut-sharing pixel: the stats do not say pixel"
accept --width 5 --height 3 --method lightcuts --cut-sharing octet --stats "$tmp/quad.json"
grep -q '"cut_sharing": "octet"' "$tmp/quad.json" || fail "--cut-sharing octet: the stats do not say octet"
accept --width 5 --height 3 --method lightcuts --stats "$tmp/quad.json"
grep -q '"cut_sharing": "octet"' "$tmp/quad.json" || fail "the CPU's default sharing is not octet"
rm -f "$tmp/quad.json"
accept --width 2 --height 2 --method path --max-bounces 1024 --time-limit 1e30
accept --width 16384 --height 1 --method brute
accept --width 1 --height 16384 --method brute
integer="must be an integer from"
for bad in "--spp=0" "--spp=65537" "--spp=1.5" "--spp=x"; do
  expect_error "--spp: $integer 1 to 65536" render "$mini" -o "$tmp/edge2.exr" "$bad"; done
for bad in "--error=-0.001" "--error=1.001" "--error=nan"; do
  expect_error "--error: must be a number from 0 to 1" render "$mini" -o "$tmp/edge2.exr" "$bad"; done
for bad in "--max-cut=0" "--max-cut=4294967296"; do
  expect_error "--max-cut: $integer 1 to 4294967295" render "$mini" -o "$tmp/edge2.exr" "$bad"; done
for bad in "--seed=-1" "--seed=4294967296"; do
  expect_error "--seed: $integer 0 to 4294967295" render "$mini" -o "$tmp/edge2.exr" "$bad"
  expect_error "--seed: $integer 0 to 4294967295" info "$mini" "$bad"; done
expect_error "image $tmp/.exr: must end in .exr, after a name" render "$mini" -o "$tmp/.exr"
# Each within its range, their product past the path tracer's paths per pixel.
expect_error "method path: spp x light_samples (paths per pixel) is 16785409, more than 16777216" \
  render "$mini" -o "$tmp/edge2.exr" --method path --spp 4097 --light-samples 4097
for side in width height; do for bad in 0 16385; do
  expect_error "--$side: $integer 1 to 16384" render "$mini" -o "$tmp/edge2.exr" "--$side=$bad"; done; done
for bad in "--light-samples=0" "--light-samples=65537"; do
  expect_error "--light-samples: $integer 1 to 65536" render "$mini" -o "$tmp/edge2.exr" "$bad"; done
for bad in "--vpls=-1" "--vpls=16777217" "--vpls=2.5"; do
  expect_error "--vpls: $integer 0 to 16777216" render "$mini" -o "$tmp/edge2.exr" "$bad"; done
for bad in "--max-bounces=1025" "--vpl-bounces=-1"; do
  expect_error "$integer 0 to 1024" render "$mini" -o "$tmp/edge2.exr" "$bad"; done
for bad in "--vpl-clamp=-0.5" "--time-limit=nan" "--time-limit=-1" "--time-limit=1e308" "--vpl-clamp=1e300"; do
  expect_error "must be a number from 0 to 3.4e38 (the largest float)" render "$mini" -o "$tmp/edge2.exr" "$bad"; done
expect_error "method path (the path tracer) runs on the CPU only" render "$mini" -o "$tmp/edge2.exr" --method path --device vulkan
# Vulkan's options on a render that cannot use Vulkan.
expect_error '--validation is for Vulkan renders, and device "cpu" does not use Vulkan' \
  render "$mini" -o "$tmp/edge2.exr" --device cpu --validation
expect_error '--gpu is for Vulkan renders, and device "cpu" does not use Vulkan' \
  render "$mini" -o "$tmp/edge2.exr" --device cpu --gpu 0
expect_error '--gpu is for Vulkan renders, and method path (the path tracer) runs on the CPU only' \
  render "$mini" -o "$tmp/edge2.exr" --method path --gpu 0
# Cuts shared by quads on Vulkan (quadcuts.comp), and the message where
# the quad's heap cannot fit the device's shared memory. In a sanitizer
# build, leaks are not checked on this render: the driver (lavapipe) keeps a
# few allocations it never frees and is unloaded before LeakSanitizer looks,
# so they show in an unknown module no suppression can name. The Vulkan
# path's own leaks are checked by the gpu tests, which keep the driver
# loaded (tests/vulkan/keep_drivers_loaded.cpp, lsan.supp).
if ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0" "$exe" render "$mini" -o "$tmp/vq.exr" --no-png \
     --width 5 --height 3 --method lightcuts --cut-sharing quad --device vulkan --stats "$tmp/vq.json" \
     >"$tmp/vq.txt" 2>&1; then
  grep '"cut_sharing": "quad"' "$tmp/vq.json" >/dev/null || fail "--cut-sharing quad --device vulkan: the stats do not say quad"
  ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0" LC_VK_HEAP_MEMORY=shared expect_error 'cut_sharing "quad" on ' render "$root/scenes/room/room.json" \
    -o "$tmp/edge2.exr" --width 2 --height 2 --method lightcuts --cut-sharing quad --device vulkan
  # Octets are the CPU's alone.
  ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0" expect_error 'cut_sharing "octet" on ' render "$mini" \
    -o "$tmp/edge2.exr" --width 2 --height 2 --method lightcuts --cut-sharing octet --device vulkan
elif ! grep "no Vulkan device" "$tmp/vq.txt" >/dev/null || [ "${LC_REQUIRE_VULKAN:-0}" != 0 ]; then
  fail "--cut-sharing quad --device vulkan: $(cat "$tmp/vq.txt")"
fi
expect_error '--cut-sharing: must be "auto", "pixel", "quad" or "octet", got "tiles"' render "$mini" -o "$tmp/edge2.exr" --cut-sharing tiles
expect_error '--method: must be "brute", "lightcuts", "sampled", "stochastic" or "path", got "fast"' render "$mini" -o "$tmp/edge2.exr" --method fast
expect_error '--light-pick: must be "tree", "uniform" or "power", got "random"' render "$mini" -o "$tmp/edge2.exr" --light-pick random
expect_error '--device: must be "auto", "cpu" or "vulkan"' render "$mini" -o "$tmp/edge2.exr" --device gpu
# Options the method does not use are named in one note.
"$exe" render "$mini" -o "$tmp/unused.exr" --no-png --device cpu --width 2 --height 2 --method brute \
  --error 0.1 --time-limit 5 --light-pick uniform >/dev/null 2>"$tmp/unused.txt" ||
  fail "unused options: $(cat "$tmp/unused.txt")"
grep -qx "note: method brute does not use --error, --light-pick, --time-limit" "$tmp/unused.txt" ||
  fail "unused options said: $(cat "$tmp/unused.txt")"
# The VPLs' options where the render makes none.
"$exe" render "$mini" -o "$tmp/unused.exr" --no-png --device cpu --width 2 --height 2 --method brute \
  --vpl-bounces 2 >/dev/null 2>"$tmp/unused.txt" || fail "unused VPL options: $(cat "$tmp/unused.txt")"
grep -qx "note: this render makes no VPLs (no --vpls, nor render.indirect.vpls): it does not use --vpl-bounces" \
  "$tmp/unused.txt" || fail "unused VPL options said: $(cat "$tmp/unused.txt")"
# Unused for the method and unused for want of VPLs are told apart; a
# refused command prints its error alone, not the note before it.
"$exe" render "$mini" -o "$tmp/unused.exr" --no-png --device cpu --width 2 --height 2 --method lightcuts \
  --vpls 0 --vpl-bounces 2 --light-pick power >/dev/null 2>"$tmp/unused.txt" ||
  fail "unused options: $(cat "$tmp/unused.txt")"
grep -qx "note: method lightcuts does not use --light-pick; this render makes no VPLs (--vpls 0): it does not use --vpl-bounces" \
  "$tmp/unused.txt" || fail "unused options for two reasons said: $(cat "$tmp/unused.txt")"
"$exe" render "$mini" -o "$tmp/unused.exr" --method brute --error 0.1 --cut-heatmap "$tmp/unused_cuts.png" \
  >/dev/null 2>"$tmp/unused.txt" && fail "--cut-heatmap with brute force was accepted"
[ "$(wc -l <"$tmp/unused.txt")" = 1 ] && grep -q "^error: " "$tmp/unused.txt" ||
  fail "a refused render with an unused option said: $(cat "$tmp/unused.txt")"
# --area-samples on a scene without emissive surfaces is said to be unused;
# on one with them it is not.
"$exe" render "$mini" -o "$tmp/unused.exr" --no-png --device cpu --width 2 --height 2 --area-samples 100 \
  >/dev/null 2>"$tmp/unused.txt" || fail "--area-samples without emitters: $(cat "$tmp/unused.txt")"
grep -qx "note: the scene has no emissive surface: it does not use --area-samples" "$tmp/unused.txt" ||
  fail "--area-samples without emitters said: $(cat "$tmp/unused.txt")"
"$exe" info "$gltf/emissive_only.gltf" --area-samples 100 >/dev/null 2>"$tmp/unused.txt" || fail "info --area-samples"
grep -q "does not use" "$tmp/unused.txt" && fail "--area-samples with emitters said: $(cat "$tmp/unused.txt")"
# info names the options its method leaves unused, and the emissive
# triangles the path tracer samples.
"$exe" info "$gltf/emissive_only.gltf" --method path --vpls 100 >"$tmp/info_path.txt" 2>"$tmp/unused.txt" ||
  fail "info --method path: $(cat "$tmp/unused.txt")"
grep -qx "note: method path does not use --vpls" "$tmp/unused.txt" || fail "info's unused note: $(cat "$tmp/unused.txt")"
grep -Eq "^  triangles +[0-9]+ \([1-9][0-9]* emissive," "$tmp/info_path.txt" ||
  fail "info does not count the emissive triangles: $(grep triangles "$tmp/info_path.txt")"
rm -f "$tmp"/unused* "$tmp/info_path.txt"
# --no-png writes the image and no preview.
"$exe" render "$mini" -o "$tmp/nopng.exr" --no-png --device cpu --width 2 --height 2 >/dev/null 2>&1 ||
  fail "--no-png render failed"
[ -s "$tmp/nopng.exr" ] && [ ! -e "$tmp/nopng.png" ] || fail "--no-png: $(ls "$tmp"/nopng*)"
rm -f "$tmp"/nopng*
# The path tracer under a time limit shorter than a pass: one path a pixel,
# said in the report and in the stats.
"$exe" render "$mini" -o "$tmp/tl.exr" --no-png --device cpu --width 4 --height 4 --method path --spp 64 \
  --time-limit 1e-9 --stats "$tmp/tl.json" >"$tmp/tl.txt" 2>&1 || fail "path with a time limit: $(cat "$tmp/tl.txt")"
grep -q "stopped at the time limit after 1 of 64 spp" "$tmp/tl.txt" && grep -Eq '"spp": 1,?$' "$tmp/tl.json" &&
  grep -Eq '"spp_requested": 64,?$' "$tmp/tl.json" || fail "path stopped at its time limit: $(cat "$tmp/tl.txt")"
rm -f "$tmp"/tl.*
# compare refuses images of two sizes, naming both.
"$exe" render "$mini" -o "$tmp/small.exr" --no-png --device cpu --width 2 --height 3 >/dev/null 2>&1 ||
  fail "2x3 render failed"
expect_error "small.exr: size 2x3 differs from the reference's 24x16" compare "$tmp/small.exr" "$tmp/a.exr"
rm -f "$tmp/small.exr"
# The command line's own errors read as the others do, and exit with 2
# (an error in the input or the render exits with 1).
status=0; "$exe" render "$mini" -o "$tmp/edge2.exr" --spp 2 --spp 3 >"$tmp/err.txt" 2>&1 || status=$?
[ "$status" = 2 ] && grep -qx "error: --spp is given more than once" "$tmp/err.txt" ||
  fail "an option given twice: status $status, $(cat "$tmp/err.txt")"
status=0; "$exe" render "$mini" -o "$tmp/edge2.exr" -s 4 >"$tmp/err.txt" 2>&1 || status=$?
[ "$status" = 2 ] && grep -qx "error: unknown option -s" "$tmp/err.txt" ||
  fail "an unknown short option: status $status, $(cat "$tmp/err.txt")"
status=0; "$exe" render "$mini" -o "$tmp/edge2.exr" --width 0 >/dev/null 2>&1 || status=$?
[ "$status" = 2 ] || fail "a value out of range exited with $status, not 2"
status=0; "$exe" render "$tmp/missing.json" -o "$tmp/edge2.exr" >/dev/null 2>&1 || status=$?
[ "$status" = 1 ] || fail "a missing scene exited with $status, not 1"

expect_error "error: unknown command 'frobnicate' (the commands are render, compare, info)" frobnicate "$mini"
# An unknown option is named before a missing command or argument.
expect_error "error: unknown option --bogus (a command comes first: render, compare or info)" --bogus
expect_error "error: unknown option --bogus" render --spp 2 --bogus
# ... and after a complete command (CLI11 listed its words left over).
expect_error "error: unknown option --bogus" render "$mini" -o "$tmp/edge2.exr" --bogus 3
expect_error "error: unknown option --bogus" info "$mini" --bogus
expect_error "--camera: the camera name is empty" info "$mini" --camera ""
expect_error "--gpu: the device name is empty" render "$mini" -o "$tmp/edge2.exr" --gpu ""
expect_error "--threads: must be an integer from 0 to 1024" render "$mini" -o "$tmp/edge2.exr" --threads 2000
expect_error "error: --width: must be an integer from 1 to 16384" render "$mini" -o "$tmp/edge2.exr" --width=+8
[ -e "$tmp/edge2.exr" ] && fail "a refused render left edge2.exr behind"

# --device auto without any Vulkan driver renders on the CPU and says so in
# one line; --device vulkan fails.
no_vulkan=(env VK_DRIVER_FILES=/nonexistent.json VK_ICD_FILENAMES=/nonexistent.json)
"${no_vulkan[@]}" "$exe" render "$mini" -o "$tmp/auto.exr" --width 4 --height 4 --stats "$tmp/auto.json" \
  >/dev/null 2>"$tmp/auto.txt" || fail "auto without Vulkan failed: $(cat "$tmp/auto.txt")"
[ "$(grep -c '^note: no Vulkan device' "$tmp/auto.txt")" = 1 ] && [ "$(wc -l <"$tmp/auto.txt")" = 1 ] ||
  fail "auto without Vulkan said: $(cat "$tmp/auto.txt")"
grep -q '"device": "cpu"' "$tmp/auto.json" || fail "auto without Vulkan: $(cat "$tmp/auto.json")"
# --validation there: the same one line says it checked nothing.
"${no_vulkan[@]}" "$exe" render "$mini" -o "$tmp/auto.exr" --width 4 --height 4 --validation \
  >/dev/null 2>"$tmp/auto.txt" || fail "auto --validation without Vulkan failed: $(cat "$tmp/auto.txt")"
[ "$(grep -c '^note: no Vulkan device; rendering on the CPU, which --validation does not check$' "$tmp/auto.txt")" = 1 ] &&
  [ "$(wc -l <"$tmp/auto.txt")" = 1 ] || fail "auto --validation without Vulkan said: $(cat "$tmp/auto.txt")"
if "${no_vulkan[@]}" "$exe" render "$mini" -o "$tmp/vk.exr" --device vulkan >"$tmp/vk.txt" 2>&1 ||
   ! grep -q "no Vulkan device" "$tmp/vk.txt"; then fail "--device vulkan without Vulkan: $(cat "$tmp/vk.txt")"; fi
# Drivers that find no device of theirs (Mesa's Intel and AMD drivers,
# installed beside lavapipe, on a machine without those GPUs): the same.
for icd in /usr/share/vulkan/icd.d/intel_icd.x86_64.json /usr/share/vulkan/icd.d/radeon_icd.x86_64.json; do
  [ -e "$icd" ] || continue
  if VK_DRIVER_FILES="$icd" "$exe" render "$mini" -o "$tmp/vk.exr" --device vulkan >"$tmp/vk.txt" 2>&1 ||
     ! grep -q "^error: no Vulkan device" "$tmp/vk.txt"; then
    fail "--device vulkan with only $icd: $(cat "$tmp/vk.txt")"
  fi
done

# Outputs are all or nothing. no_output NAME: no file of that stem and no
# temporary is left.
no_output() {
  local left; left="$(cd "$tmp" && ls -d "$1".* "$1"_* *.tmp* 2>/dev/null)"
  [ -z "$left" ] || fail "$2 left behind: $left"
}
# Combinations refused before rendering.
expect_error "needs method lightcuts" render "$mini" -o "$tmp/v.exr" --method brute --cut-heatmap "$tmp/v_cuts.png"
expect_error "needs method lightcuts or stochastic, not sampled" render "$mini" -o "$tmp/v.exr" --method sampled \
  --cut-heatmap "$tmp/v_cuts.png"
expect_error "is also the PNG preview" render "$mini" -o "$tmp/v.exr" --method lightcuts --cut-heatmap "$tmp/v.png"
expect_error "folder $tmp/nowhere does not exist" render "$mini" -o "$tmp/v.exr" --stats "$tmp/nowhere/v.json"
mkdir "$tmp/v_dir"
expect_error "v_dir: is a folder" render "$mini" -o "$tmp/v.exr" --stats "$tmp/v_dir"
rmdir "$tmp/v_dir"
no_output v "a refused render"
mkdir "$tmp/scene" && cp "$mini" "$root/tests/data/scenes/tri.obj" "$tmp/scene/"
expect_error "is the scene" render "$tmp/scene/minimal.json" -o "$tmp/v.exr" --stats "$tmp/scene/minimal.json"
cmp -s "$mini" "$tmp/scene/minimal.json" || fail "a render overwrote its scene"
no_output v "a render refused for overwriting its scene"

# A write that fails after the render (the stats file exceeds the file size
# limit; SIGXFSZ ignored so the write returns EFBIG), once the image and its
# preview are written: neither may be left. A long scene path makes the JSON
# over 1 KiB, the 1x1 image under.
long="$tmp/scene_$(printf 'x%.0s' {1..200})"
mkdir "$long" && cp "$mini" "$root/tests/data/scenes/tri.obj" "$long/"
(trap '' XFSZ; ulimit -f 1; exec "$exe" render "$long/minimal.json" -o "$tmp/big.exr" --width 1 --height 1 \
  --device cpu --method lightcuts --stats "$tmp/big.json" --cut-heatmap "$tmp/big_cuts.png") >"$tmp/log_big.txt" 2>&1 &&
  fail "a stats file over the size limit did not fail the render"
grep -q "big.json" "$tmp/log_big.txt" || fail "the failed stats write said: $(cat "$tmp/log_big.txt")"
no_output big "a stats write that failed after the render"
# The same write with SIGXFSZ at its default action, which ends the process
# (status 128 + 25) and, through the render's handler, removes what it wrote.
status=0
{ (ulimit -c 0; ulimit -f 1; exec "$exe" render "$long/minimal.json" -o "$tmp/big.exr" --width 1 --height 1 \
  --device cpu --method lightcuts --stats "$tmp/big.json") >/dev/null 2>&1; } 2>/dev/null || status=$?
[ "$status" -eq 153 ] || fail "a render past the file size limit exited with status $status, not 153 (SIGXFSZ)"
no_output big "a render ended by SIGXFSZ"

# A rename that fails after the render: the stats file's path becomes a folder
# while the render runs (after its temporary is reserved). The image written
# before it is taken back and the file it replaced restored.
printf old >"$tmp/late.exr"
# One thread and 128x128 (half a second here): the poll finds the reservation
# long before the render ends, and says so if it did not.
"$exe" render "$root/scenes/room/room.json" -o "$tmp/late.exr" --width 128 --height 128 --device cpu \
  --method brute --threads 1 --stats "$tmp/late.json" >"$tmp/log_late.txt" 2>&1 &
pid=$!
for _ in $(seq 1000); do compgen -G "$tmp/late.json.tmp-*" >/dev/null && break; sleep 0.01; done
kill -STOP "$pid" 2>/dev/null
compgen -G "$tmp/late.json.tmp-*" >/dev/null || fail "the render to fail late reserved no outputs, or had ended"
mkdir "$tmp/late.json"; kill -CONT "$pid" 2>/dev/null
wait "$pid" && fail "a stats path that became a folder did not fail the render"
grep -q "late.json: cannot rename" "$tmp/log_late.txt" || fail "the failed rename said: $(cat "$tmp/log_late.txt")"
printf old | cmp -s - "$tmp/late.exr" || fail "the failed render did not put the earlier late.exr back"
rmdir "$tmp/late.json" && rm "$tmp/late.exr"
no_output late "a rename that failed after the render"

# A render ended by a signal (SIGTERM: a kill, or the end of a CI job; the
# same handler takes SIGINT and SIGHUP) removes its temporaries and exits as
# the signal would have (status 128 + 15). The render would run for a minute.
"$exe" render "$root/scenes/room/room.json" -o "$tmp/killed.exr" --width 512 --height 512 --device cpu \
  --method brute --threads 1 --stats "$tmp/killed.json" >"$tmp/log_killed.txt" 2>&1 &
pid=$!
for _ in $(seq 1000); do compgen -G "$tmp/killed.json.tmp-*" >/dev/null && break; sleep 0.01; done
compgen -G "$tmp/killed.json.tmp-*" >/dev/null || fail "the render to be killed reserved no outputs"
kill -TERM "$pid"
status=0; wait "$pid" || status=$?
[ "$status" -eq 143 ] || fail "a render ended by SIGTERM exited with status $status, not 143"
no_output killed "a render ended by SIGTERM"

echo "$(( failures == 0 ? 1 : 0 )) passed, $failures failed"
[ "$failures" -eq 0 ]
