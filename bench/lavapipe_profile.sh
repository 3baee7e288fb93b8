#!/usr/bin/env bash
# Where lavapipe spends a Vulkan render (docs/results/lavapipe.md): records
# perf samples of the whole render, copies the generated shader code out of
# the running process (its executable anonymous mappings, read through
# /proc/PID/mem: perf sees that code only as addresses), disassembles it,
# and splits the samples in it by the kind of code around them.
#
# llvmpipe 22.3 compiles a storage-buffer or shared-memory access whose
# address differs between lanes into a loop over the 8 lanes (gallivm's
# emit_load_mem / emit_store_mem); a storage-buffer loop reads the buffer's
# size from a table at 16 bytes per binding, which names the binding. The
# table's start (0x7f08 below: binding 0) is what llvmpipe 22.3.6 / LLVM 15
# generated here; check it against the bindings (the heap spill buffer,
# binding 15, is the one that is both loaded and stored in the hot code)
# before trusting the names on another Mesa. Loops without a bounds check
# are shared memory or an invocation's own arrays with a dynamic index.
#
# On today's kernels few such loops are left (the heap is in private
# memory, the walk's stack touched once a trip): nearly every sample falls
# under arithmetic and control, and the split by function is what is left
# to read. docs/results/lavapipe.md §24 measures the accesses another way,
# by doubling each kind. Set LC_PROFILE_DELAY so that the copy is taken
# after the kernels are compiled.
#
# Needs perf, objdump, python3 and permission to read the process's memory
# (root, or ptrace_scope 0).
#
#   bench/lavapipe_profile.sh SCENE [render options...]
#   e.g. bench/lavapipe_profile.sh scenes/room/room_1e4.json --width 128 --height 128
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
exe="$root/build/host/lightcuts"
[ $# -ge 1 ] || { echo "usage: bench/lavapipe_profile.sh SCENE [render options...]" >&2; exit 2; }
scene="$1"
shift
tmp="$(mktemp -d)"
trap 'kill "${perf_pid:-}" 2>/dev/null; rm -rf "$tmp"' EXIT
export VK_DRIVER_FILES="${VK_DRIVER_FILES:-/usr/share/vulkan/icd.d/lvp_icd.x86_64.json}"

perf record -F 499 -o "$tmp/perf.data" "$exe" render "$scene" "$@" --device vulkan \
  -o "$tmp/x.exr" --no-png >"$tmp/render.log" 2>&1 &
perf_pid=$!
# The kernels are compiled before the first tile (0.3 s on the room since
# they are specialized on the host); copy them while the render runs.
# LC_PROFILE_DELAY: seconds to wait first (a render shorter than it leaves
# nothing to copy).
sleep "${LC_PROFILE_DELAY:-1}"
# The renderer is perf's child (not any other lightcuts running).
pid="$(pgrep -P "$perf_pid" -x lightcuts || true)"
if [ -z "$pid" ]; then
  wait "$perf_pid" || true
  echo "lavapipe_profile: the render ended within ${LC_PROFILE_DELAY:-1} s, before its kernels could be copied;" \
       "render a larger image (128x128 on the room takes a few seconds)" >&2
  exit 1
fi
grep -E 'r-xp 00000000 00:00 0' "/proc/$pid/maps" | grep -v vdso | while read -r range _; do
  start="${range%-*}" end="${range#*-}"
  python3 -c "import sys
f = open('/proc/$pid/mem', 'rb'); f.seek(0x$start)
sys.stdout.buffer.write(f.read(0x$end - 0x$start))" >"$tmp/code.bin"
  objdump -D -b binary -m i386:x86-64 --adjust-vma="0x$start" "$tmp/code.bin" >>"$tmp/code.asm"
done
wait "$perf_pid"
grep -E '^ +render ' "$tmp/render.log" || { cat "$tmp/render.log"; exit 1; }

perf report -i "$tmp/perf.data" --sort dso --no-children --stdio 2>/dev/null | grep -E '^ +[0-9]' | head -6
perf script -i "$tmp/perf.data" -F ip 2>/dev/null >"$tmp/ips.txt"
python3 - "$tmp/code.asm" "$tmp/ips.txt" <<'EOF'
import bisect, collections, re, sys

names = ["BVH nodes", "triangles", "normals", "uvs", "materials", "textures", "texels",
         "lights", "light-tree nodes", "environment", "4-wide BVH nodes", "frame", "g-buffer",
         "radiance", "pixel stats", "heap spill", "cut state"]
first_binding = 0x7f08  # llvmpipe 22.3.6: where binding 0's size sits (see the header)

code = []
for line in open(sys.argv[1]):
    m = re.match(r"\s*([0-9a-f]+):\t(?:[0-9a-f ]+)\t(.*)", line)
    if m:
        code.append((int(m.group(1), 16), m.group(2).strip()))
addresses = [a for a, _ in code]

# A lane loop ends with "cmp $0x8,<counter>; jae <exit>" and starts where the
# counter is zeroed.
loops = []
for j, (a, text) in enumerate(code):
    m = re.search(r"cmp\s+\$0x8,%(e\w\w|r\d+d)$", text)
    if not m or j + 1 >= len(code) or not code[j + 1][1].startswith("jae"):
        continue
    try:
        exit_address = int(code[j + 1][1].split()[-1], 16)
    except ValueError:
        continue
    s = j
    while s > 0 and j - s < 80 and not re.search(r"xor\s+%{0},%{0}".format(m.group(1)), code[s][1]):
        s -= 1
    lo, hi = code[s][0], max(exit_address, a)
    body = [t for a2, t in code[bisect.bisect_left(addresses, lo):bisect.bisect_left(addresses, hi)]]
    sizes = [int(x, 16) for t in body for x in re.findall(r"(0x7f[0-9a-f]{2})\(%rbx\),%e", t)]
    store = any(re.match(r"mov\s+%(e\w+|r\d+d),\(%r\w+,%r\w+,4\)", t) for t in body)
    if sizes:
        b = (sizes[0] - first_binding) // 16
        kind = "binding %d (%s)" % (b, names[b] if 0 <= b < len(names) else "?")
    else:
        kind = "no bounds check: shared memory or private array"
    loops.append((lo, hi, kind + (" store" if store else " load")))

samples = [int(x, 16) for x in open(sys.argv[2]).read().split()]
inside = [ip for ip in samples if code and addresses[0] <= ip <= addresses[-1]]
split = collections.Counter()
for ip in inside:
    found = [k for lo, hi, k in loops if lo <= ip < hi]
    split[found[-1] if found else "vector arithmetic and control"] += 1
print("%d of %d samples in the shader code copied out" % (len(inside), len(samples)))
for kind, n in split.most_common():
    print("%5.1f%%  %s" % (100.0 * n / max(1, len(inside)), kind))

# The same samples by function of the generated code (a function ends at a
# ret). The kernels are one large function each; llvmpipe 22.3 reads a
# uniform texel buffer through small functions of its own (about 46
# instructions: the eight lanes' addresses extracted, eight 16-byte loads, a
# transpose), called through a pointer once per texelFetch. The kernels now
# read storage texel buffers with imageLoad, which llvmpipe writes into the
# kernel (docs/results/lavapipe.md, §26), so such functions no longer show.
starts = [0] + [j + 1 for j, (_, text) in enumerate(code) if text.startswith("ret") and j + 1 < len(code)]
by_function = collections.Counter()
for ip in inside:
    k = bisect.bisect_right(starts, bisect.bisect_right(addresses, ip) - 1) - 1
    by_function[starts[k]] += 1
print("by function of the generated code (instructions, share of the samples above):")
for start, n in by_function.most_common(6):
    end = next((s for s in starts if s > start), len(code))
    print("%5.1f%%  %d instructions at %#x" % (100.0 * n / max(1, len(inside)), end - start, code[start][0]))
EOF
