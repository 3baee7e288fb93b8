#!/usr/bin/env bash
# Where Lightcuts' heaps leave the invocation on lavapipe: every shipped
# scene at its own size and the defaults, rendered on the Vulkan path twice,
# once as the renderer splits the cuts on llvmpipe by default (cuts of at
# most Tuning::kLlvmpipeWholeCutSteps steps whole in one dispatch) and once
# split at 512 refinements a dispatch (LC_VK_REFINEMENTS_PER_DISPATCH=512,
# the split before). Prints, for each, the shading time, the passes thrown
# away to llvmpipe's loop limit, the share of pixels whose heap waited in
# global memory between dispatches, and the largest relative difference
# between the two images (docs/results/lavapipe.md, section 12).
#
#   bench/heap_pauses.sh [BINARY]
set -uo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
exe="$(realpath "${1:-$root/build/host/lightcuts}")"  # before the cd below
[ -x "$exe" ] || { echo "heap_pauses: no renderer at $exe" >&2; exit 1; }
export VK_DRIVER_FILES="${VK_DRIVER_FILES:-/usr/share/vulkan/icd.d/lvp_icd.x86_64.json}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
cd "$root"
failed=0
echo "| scene | size | split | shading s | failed passes | heaps paused in global memory | images differ by |"
echo "|---|---|---|---|---|---|---|"
for f in scenes/*/*.json scenes/*/*.gltf; do
  case "$f" in *gallery_1e5*) [ -f scenes/gallery/spots_1e5.csv ] || continue ;; esac
  for split in default 512; do
    if [ "$split" = 512 ]; then export LC_VK_REFINEMENTS_PER_DISPATCH=512; else unset LC_VK_REFINEMENTS_PER_DISPATCH; fi
    if ! "$exe" render "$f" --method lightcuts --device vulkan -o "$tmp/$split.exr" --no-png \
        --stats "$tmp/$split.json" >"$tmp/log" 2>&1; then
      echo "| $f | | $split | failed: $(tail -1 "$tmp/log") | | | |"
      failed=1
      continue 2
    fi
  done
  unset LC_VK_REFINEMENTS_PER_DISPATCH
  diff="$("$exe" compare "$tmp/default.exr" "$tmp/512.exr" 2>&1 | sed -n 's/^max relative error *//p')"
  for split in default 512; do
    python3 - "$tmp/$split.json" "$f" "$split" "$diff" <<'PY'
import json, sys
d = json.load(open(sys.argv[1]))
n = d["width"] * d["height"]
paused = d["lightcuts"]["heap_paused_samples"] / (n * d["spp"])
print(f"| {sys.argv[2]} | {d['width']}x{d['height']} | {sys.argv[3]} | {d['seconds']['shading']:.2f} | "
      f"{d['loop_limit_retries']} | {100 * paused:.2f}% | {sys.argv[4]} |")
PY
  done
done
# A failed render is in the table; the exit status says so too.
exit "$failed"
