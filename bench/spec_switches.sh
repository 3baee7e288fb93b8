#!/usr/bin/env bash
# What each Vulkan specialization-constant switch saves: renders a scene that
# needs neither shadow rays, nor the GGX lobe, nor the spot/oriented light
# code (scenes/plane) with the switches as the scene allows them, and with
# each one forced on (LC_VK_FORCE_FEATURES), and prints the median GPU
# shading time of 5 runs after a warm-up. FEATURES lists the forcings to
# run (LC_VK_FORCE_FEATURES values; "none" forces nothing), e.g.
# "none disney sheen,clearcoat" for the Disney lobes (docs/results/disney.md).
#
# METHODS: the methods to time (default "lightcuts brute").
#
#   bench/spec_switches.sh [SCENE] [SIZE] [FEATURES] [METHODS]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
scene="${1:-$root/scenes/plane/plane.json}"
size="${2:-128}"
features="${3:-none ggx shadows oriented all}"
methods="${4:-lightcuts brute}"
exe="$root/build/host/lightcuts"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

printf '%-10s %-14s %s\n' method forced "median shading [s] (5 runs)"
for method in $methods; do
  for force in $features; do
    times=()
    for run in 0 1 2 3 4 5; do
      # A render that fails (a feature name the renderer does not know, say)
      # stops the script with the renderer's message.
      if ! LC_VK_FORCE_FEATURES="$force" "$exe" render "$scene" -o "$tmp/x.exr" --device vulkan --method "$method" \
        --width "$size" --height "$size" --no-png --stats "$tmp/s.json" >"$tmp/log" 2>&1; then
        echo "spec_switches: $method with LC_VK_FORCE_FEATURES=$force failed: $(tail -1 "$tmp/log")" >&2
        exit 1
      fi
      [ "$run" -eq 0 ] && continue  # warm-up
      times+=("$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['seconds']['shading'])" "$tmp/s.json")")
    done
    median="$(printf '%s\n' "${times[@]}" | sort -g | sed -n 3p)"
    printf '%-10s %-14s %.3f\n' "$method" "$force" "$median"
  done
done
