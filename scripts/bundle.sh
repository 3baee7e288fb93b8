#!/usr/bin/env bash
# Packs the renderer and the GPU tests, with the shared libraries they load
# that a machine without this build's Debian packages may lack, into DIR:
# for a GPU machine that has a Vulkan driver but not the set-up (the NVIDIA
# H200 of docs/results/gpu.md was one). Needs the build (`make demo`).
#
#   scripts/bundle.sh DIR
#   DIR/run DIR/bin/lightcuts render scenes/room/room_1e5.json -o room.exr --device vulkan
#
# DIR/run COMMAND... runs COMMAND with DIR's libraries and validation layer
# found first; DIR/bin holds the two programs. What goes in DIR/lib: the
# programs' own libraries from outside glibc and the C++ runtime, the Vulkan
# loader, and glvnd's dispatch libraries with the X11 client libraries
# they load, without which the loader could not use NVIDIA's driver on
# that machine. The GPU tests read the scenes from the checkout they were
# built in (its path is compiled in): run them from a checkout at the same
# path, or link that path to one.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:?usage: scripts/bundle.sh DIR}"
programs=("$root/build/host/lightcuts" "$root/build/tests/vulkan/lc_vulkan_tests")
for p in "${programs[@]}"; do
  [ -x "$p" ] || { echo "scripts/bundle.sh: $p is missing: build first (make demo)" >&2; exit 1; }
done
mkdir -p "$out/bin" "$out/lib" "$out/layers"
cp "${programs[@]}" "$out/bin/"
strip "$out/bin/"*

libs=$(ldd "${programs[@]}" | awk '/=> \// {print $3}' | sort -u |
       grep -v -E '/(libc|libm|libgcc_s|libstdc\+\+|ld-linux[^/]*)\.so' || true)
multiarch="/usr/lib/$(gcc -print-multiarch 2>/dev/null || echo x86_64-linux-gnu)"
for name in libvulkan.so.1 libGLdispatch.so.0 libGLX.so.0 libEGL.so.1 libGL.so.1 libOpenGL.so.0 \
            libX11.so.6 libXext.so.6 libxcb.so.1 libXau.so.6 libXdmcp.so.6 libbsd.so.0 libmd.so.0; do
  [ -e "$multiarch/$name" ] && libs="$libs $multiarch/$name"
done
for lib in $libs; do cp -L "$lib" "$out/lib/"; done

layer_json=/usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json
if [ -f "$layer_json" ]; then
  cp "$layer_json" "$out/layers/"
  cp -L "$multiarch/libVkLayer_khronos_validation.so" "$out/layers/"
else
  echo "scripts/bundle.sh: no validation layer here (vulkan-validationlayers): the GPU tests need it" >&2
fi

cat > "$out/run" <<'RUN'
#!/bin/sh
# Runs its arguments with this bundle's libraries and validation layer.
d=$(cd "$(dirname "$0")" && pwd)
LD_LIBRARY_PATH="$d/lib:$d/layers${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" VK_LAYER_PATH="$d/layers" exec "$@"
RUN
chmod +x "$out/run"
printf 'scripts/bundle.sh: %s in %s\n' "$(du -sh "$out" | cut -f1)" "$out"
