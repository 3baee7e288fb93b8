#!/usr/bin/env bash
# The Vulkan path on lavapipe against the CPU path, on the same scenes in
# the same run (docs/results/lavapipe.md): for each round, scene and
# binary, one lightcuts render on the CPU and one on lavapipe, at the
# defaults. Prints the render-call time of each (pipelines and uploads
# included), the GPU time of the kernels, and the two ratios.
#
#   bench/lavapipe_vs_cpu.sh [--size N] [ROUNDS] [BINARY...]
#
# ROUNDS defaults to 2, BINARY to build/host/lightcuts; give two binaries
# (e.g. one built from an older commit in a worktree) to compare before and
# after in the same run. Scenes: the room with 10^4 and 10^5 lights at
# N x N (default 128), the textured glTF scene at its own size. The Vulkan
# render call has a fixed part (the driver's loading, the kernels'
# compilation: about 0.2 s on lavapipe) that a larger N makes smaller
# against the rest. The first render after
# a build also compiles the kernels into Mesa's shader cache; run once to
# warm it, or read the second round.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
side=128
if [ "${1:-}" = "--size" ]; then side="$2"; shift 2; fi
rounds="${1:-2}"
[[ "$rounds" =~ ^[0-9]+$ ]] || { echo "usage: bench/lavapipe_vs_cpu.sh [--size N] [ROUNDS] [BINARY...]: ROUNDS is a number, not '$rounds'" >&2; exit 2; }
shift || true
binaries=("$@")
[ ${#binaries[@]} -gt 0 ] || binaries=("$root/build/host/lightcuts")
export VK_DRIVER_FILES="${VK_DRIVER_FILES:-/usr/share/vulkan/icd.d/lvp_icd.x86_64.json}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

echo "| round | scene | binary | CPU s | Vulkan s | kernels s | Vulkan/CPU | kernels/CPU | command CPU, Vulkan s | command Vulkan/CPU | rays/px CPU, Vulkan |"
echo "|---|---|---|---|---|---|---|---|---|---|---|"
for round in $(seq 1 "$rounds"); do
  for scene in scenes/room/room_1e4.json scenes/room/room_1e5.json scenes/gltf/textured.gltf; do
    size=(--width "$side" --height "$side")
    case "$scene" in *.gltf) size=() ;; esac
    for exe in "${binaries[@]}"; do
      for device in cpu vulkan; do
        begin=$(date +%s.%N)
        "$exe" render "$root/$scene" -o "$tmp/$device.exr" --method lightcuts "${size[@]}" \
          --device "$device" --stats "$tmp/$device.json" --no-png >"$tmp/log" 2>&1 ||
          { cat "$tmp/log" >&2; exit 1; }
        echo "$begin $(date +%s.%N)" >"$tmp/$device.wall"
      done
      python3 - "$round" "$scene" "$exe" "$tmp/cpu.json" "$tmp/vulkan.json" "$tmp/cpu.wall" "$tmp/vulkan.wall" <<'PY'
import json, sys
rnd, scene, exe, cpu_path, vk_path, cpu_wall, vk_wall = sys.argv[1:]
def wall(path):
    begin, end = map(float, open(path).read().split())
    return end - begin
wc, wv = wall(cpu_wall), wall(vk_wall)
cpu, vk = json.load(open(cpu_path)), json.load(open(vk_path))
tc, tv = cpu["seconds"]["render"], vk["seconds"]["render"]
tk = vk["seconds"]["primary"] + vk["seconds"]["shading"]
print(f"| {rnd} | {scene} ({vk['width']}x{vk['height']}) | {exe} | {tc:.3f} | {tv:.3f} | {tk:.3f} | "
      f"{tv / tc:.2f} | {tk / tc:.2f} | {wc:.3f}, {wv:.3f} | {wv / wc:.2f} | "
      f"{cpu['shadow_rays_per_pixel']:.1f}, {vk['shadow_rays_per_pixel']:.1f} |")
PY
    done
  done
done
# The device the Vulkan renders ran on (VK_DRIVER_FILES picks it; lavapipe
# unless the caller set another).
python3 -c "import json, sys; print('Vulkan device:', json.load(open(sys.argv[1]))['device'])" "$tmp/vulkan.json"
