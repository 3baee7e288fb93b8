#!/usr/bin/env bash
# Scale: a room of COUNT point lights (default 10^7) rendered on the CPU path
# and through Vulkan on lavapipe, at SIZE x SIZE (default 128) with the
# scene's settings otherwise (lightcuts, 1 spp, 2% error, max cut 1000).
# Prints, per render (the CPU at its defaults, the CPU cutting each pixel
# alone, Vulkan): loading the light file, building the light tree, the
# render, the peak resident memory of the process, and the buffer sizes that
# grow with the light count; then the difference between the Vulkan image
# and the CPU's with a cut per pixel, which is the same image up to rounding
# (the CPU's default shares each cut between the pixels of a 4x2 octet).
# docs/results/scale.md has the figures and how to read them.
#
# The light file (586 MB at 10^7) is made once with scripts/gen_lights.py
# into OUT (default out/scale) and reused.
#
# --oriented: the shipped panels scene (scenes/panels) with its emissive
# panels sampled into COUNT oriented lights (--area-samples) instead: the
# tree builder's metric then has its cone term.
#
#   bench/scale.sh [--oriented] [COUNT] [SIZE] [OUT]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
oriented=0
if [ "${1:-}" = "--oriented" ]; then oriented=1; shift; fi
count="${1:-10000000}"
size="${2:-128}"
out="${3:-$root/out/scale}"
exe="$root/build/host/lightcuts"
lvp="${LC_LAVAPIPE_ICD:-/usr/share/vulkan/icd.d/lvp_icd.x86_64.json}"
mkdir -p "$out"

lights="$out/lights_$count.csv"
scene="$out/room_$count.json"
extra=()
if [ "$oriented" = 1 ]; then
  scene="$root/scenes/panels/panels.json"
  extra=(--area-samples "$count")
elif [ ! -f "$lights" ] || [ "$(grep -c -v -e '^#' -e '^[[:space:]]*$' "$lights")" != "$((count + 1))" ]; then
  # Made again unless a whole list of COUNT lights (and its header) is there.
  python3 "$root/scripts/gen_lights.py" --shape room --count "$count" --seed 1 --out "$lights"
fi
# The shipped room with this light file (paths relative to the scene file).
[ "$oriented" = 1 ] || python3 - "$root/scenes/room/room_1e4.json" "$scene" "$(basename "$lights")" "$root/scenes/room" <<'PY'
import json, os, sys
src, dst, csv, room = sys.argv[1:]
s = json.load(open(src))
for m in s["meshes"]:
    m["obj"] = os.path.relpath(os.path.join(room, os.path.basename(m["obj"])), os.path.dirname(dst))
s["lights"] = [{"type": "points_csv", "file": csv}]
json.dump(s, open(dst, "w"), indent=1)
PY

"$exe" info "$scene" "${extra[@]}" | sed -n '/buffers:/,$p'
# llvmpipe compiles a kernel it has not cached at its first dispatch (about
# 1.3 s for Lightcuts'), and this scene's kernels differ from smaller
# scenes' (their arrays are split): one small render first puts them in
# Mesa's shader cache, as bench/speed.py does, so that the timed render
# below measures rendering.
VK_DRIVER_FILES="$lvp" "$exe" render "$scene" "${extra[@]}" -o "$out/warm-up.exr" --device vulkan --width 8 --height 8 \
  --no-png >/dev/null 2>&1 || true
rm -f "$out/warm-up.exr"
for run in cpu cpu_pixel vulkan; do
  device="${run%_pixel}"
  env=()
  args=()
  [ "$device" = vulkan ] && env=(VK_DRIVER_FILES="$lvp")
  [ "$run" = cpu_pixel ] && args=(--cut-sharing pixel)
  env "${env[@]}" /usr/bin/time -f "peak resident memory %M KiB, wall %e s, user %U s, sys %S s" \
    "$exe" render "$scene" "${extra[@]}" -o "$out/$run.exr" --device "$device" --width "$size" --height "$size" \
    --stats "$out/$run.json" "${args[@]}" 2>&1 | grep -v '^\s*$'
  python3 - "$out/$run.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1])); n = s["lights"]; sec = s["seconds"]
print(f"  {n} lights; load {sec['load']:.2f} s, area-light sampling {sec['light_sampling']:.2f} s, "
      f"light tree {sec['light_tree_build']:.2f} s, render {sec['render']:.2f} s")
b = s.get("buffer_bytes", {})
per_light = b.get("lights", 0) + b.get("light_tree_nodes", 0)
print(f"  lights {b.get('lights', 0) / 2**20:.1f} MiB + light-tree nodes {b.get('light_tree_nodes', 0) / 2**20:.1f} MiB"
      f" = {per_light / n:.1f} bytes per light; all buffers {sum(b.values()) / 2**20:.1f} MiB")
PY
done
"$exe" compare "$out/vulkan.exr" "$out/cpu_pixel.exr"
