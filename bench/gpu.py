#!/usr/bin/env python3
"""The Vulkan path on a hardware GPU, in one run (docs/results/gpu.md).

  bench/gpu.py [--out DIR] [--exe PATH] [--width W] [--height H] [--runs N]
               [--lights FILE] [--parts 1,2,3,4,5,6] [--brute-timeout S] [--quick]

Renders through Vulkan on the device the renderer picks (VK_DRIVER_FILES
chooses the driver), each scene after one 8x8 render that compiles its
pipelines, so that the timed renders measure rendering:

1. the shipped room with 10^5 lights (scenes/room/room_1e5.json) at
   W x H (default 1920x1080), lightcuts at the defaults, --runs times
   (default 3): the GPU time (the timestamps of the camera-ray and shading
   dispatches, summed over the tile passes), the render call (device
   set-up, uploads, every pass and the read-back), shadow rays per pixel and
   per second of GPU time, the cut, where the cut heaps live and the samples
   whose heap waited in global memory between dispatches;
2. every shipped scene at the same size, once;
3. the cut heap on the 10^5 room: K = 8, 16, 32 and 64 slots, each with the
   heaps in workgroup shared memory and in each invocation's private memory
   (LC_VK_HEAP_MEMORY), cuts shared by 2x2 quads, and tile passes sized for
   200 ms of GPU time instead of the 30 ms a GPU's are sized for;
4. brute force against lightcuts on the rooms at an eighth of the size each
   way (brute force at 1080p and 10^5 lights is 2 x 10^11 shadow rays): the
   shading time per shadow ray of each, their ratio and the speedup;
5. the CPU path of the same machine on the 10^5 room at full size with a cut
   per pixel (the kernels' cuts, so the same image up to rounding): its
   time, and the relative RMSE of the Vulkan image against it;
6. with --lights FILE (a points_csv list, e.g. 10^7 lights from
   scripts/gen_lights.py): the room with those lights at full size: light
   loading, tree build, GPU time, bytes per light of the light buffers.

--parts runs some of them, in the order given. Writes DIR/gpu.md and DIR/gpu.json (default out/gpu). Nothing here passes
or fails. On a CPU device (lavapipe) it runs too, but measures nothing a GPU
would: --quick (64x36, one run, two scenes) only checks that it works.
"""
import argparse
import json
import os
import resource
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import speed  # noqa: E402  (compare, missing: the same image comparison and data checks)

SCENES = ["scenes/room/room_1e4.json", "scenes/room/room_1e5.json", "scenes/panels/panels.json",
          "scenes/gallery/gallery.json", "scenes/sky/sky.json", "scenes/materials/materials.json",
          "scenes/bunny/bunny.json", "scenes/gltf/textured.gltf"]
ROOM_1E5 = "scenes/room/room_1e5.json"


def render(out, scene, name, width, height, method="lightcuts", device="vulkan", extra=(), env_add=None,
           timeout=None):
    """Renders and returns the image's path and the --stats; raises on failure."""
    exr = os.path.join(out, name + ".exr")
    stats = os.path.join(out, name + ".json")
    cmd = [speed.EXE, "render", scene if os.path.isabs(scene) else os.path.join(ROOT, scene), "-o", exr,
           "--method", method, "--device", device, "--width", str(width), "--height", str(height),
           "--stats", stats, "--no-png", *extra]
    env = dict(os.environ)
    env.update(env_add or {})
    done = subprocess.run(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                          timeout=timeout)
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{done.stderr}")
    return exr, json.load(open(stats))


def figures(s):
    """The numbers a row shows, from a render's --stats."""
    sec = s["seconds"]
    gpu = sec.get("primary", 0.0) + sec.get("shading", 0.0)
    lc = s.get("lightcuts", {})
    pixels = s["width"] * s["height"]
    return {"gpu_s": gpu, "primary_s": sec.get("primary", 0.0), "shading_s": sec.get("shading", 0.0),
            "call_s": sec["render"], "shadow_rays": s["shadow_rays"],
            "rays_per_px": s["shadow_rays"] / pixels,
            "shadow_rays_per_gpu_s": s["shadow_rays"] / sec["shading"] if sec.get("shading") else 0.0,
            "cut_mean": lc.get("cut_size_mean", 0.0), "heap_memory": lc.get("heap_memory", ""),
            "heap_bytes_per_workgroup": lc.get("heap_bytes_per_workgroup", 0),
            "paused": lc.get("heap_paused_samples", 0) / (pixels * s["spp"]) if lc else 0.0,
            "device": s.get("device", "")}


def row(label, f):
    return (f"| {label} | {1e3 * f['gpu_s']:.1f} | {1e3 * f['primary_s']:.1f} | {1e3 * f['shading_s']:.1f} | "
            f"{1e3 * f['call_s']:.0f} | {f['rays_per_px']:.1f} | {f['shadow_rays_per_gpu_s'] / 1e9:.3f} | "
            f"{f['cut_mean']:.1f} | {f['heap_memory']} {f['heap_bytes_per_workgroup']} B | "
            f"{100 * f['paused']:.2f}% |")


HEADER = ["| render | GPU ms | camera rays ms | shading ms | call ms | shadow rays/px | G shadow rays/s "
          "| mean cut | heap (per workgroup) | heap paused in global memory |",
          "|---|---|---|---|---|---|---|---|---|---|"]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "gpu"))
    ap.add_argument("--exe", default=speed.EXE, help="the lightcuts binary (default build/host/lightcuts)")
    ap.add_argument("--width", type=int, default=1920)
    ap.add_argument("--height", type=int, default=1080)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--lights", help="a points_csv light list for part 6")
    ap.add_argument("--parts", default="1,2,3,4,5,6", help="the parts to run, in this order")
    ap.add_argument("--brute-timeout", type=float, default=120.0,
                    help="seconds a brute-force render of part 4 may take before it is reported unfinished")
    ap.add_argument("--quick", action="store_true")
    a = ap.parse_args()
    order = [p.strip() for p in a.parts.split(",")]
    if any(p not in ("1", "2", "3", "4", "5", "6") for p in order):
        ap.error(f"--parts {a.parts}: the parts are 1 to 6")
    speed.EXE = a.exe
    w, h, runs = (64, 36, 1) if a.quick else (a.width, a.height, a.runs)
    scenes = [s for s in (SCENES[:2] if a.quick else SCENES) if not speed.missing(s)]
    os.makedirs(a.out, exist_ok=True)
    results = {"width": w, "height": h}
    lines = [f"# The Vulkan path on a GPU ({w}x{h})", "", "Command: `bench/gpu.py " + " ".join(sys.argv[1:]) + "`",
             ""]

    def flush():
        with open(os.path.join(a.out, "gpu.md"), "w") as f:
            f.write("\n".join(lines) + "\n")
        with open(os.path.join(a.out, "gpu.json"), "w") as f:
            json.dump(results, f, indent=1)

    def say(*new):
        lines.extend(new)
        print("\n".join(new), flush=True)
        flush()

    # Pipelines are compiled at a scene's first render of a kind (and the
    # SPIR-V cached): an 8x8 render of the same kind before the first timed
    # one.
    warm = set()

    def timed(scene, name, width, height, method="lightcuts", extra=(), env_add=None, timeout=None, device="vulkan"):
        key = (scene, method, tuple(extra), tuple(sorted((env_add or {}).items())), device)
        if key not in warm:
            render(a.out, scene, "warm-up", 8, 8, method, device, extra, env_add)
            warm.add(key)
        return render(a.out, scene, name, width, height, method, device, extra, env_add, timeout)

    if not scenes:
        sys.exit("bench/gpu.py: none of the scenes' data is here (make demo generates the light lists)")
    _, s = render(a.out, scenes[0], "warm-up", 8, 8)
    results["device"] = s["device"]
    say(f"Device: {s['device']}", "")

    def part1():
        say(f"## 1. The room with 10^5 lights, lightcuts at the defaults, {runs} run(s)", "",
            "GPU ms: the timestamps of the camera-ray and shading dispatches, summed over the tile passes. "
            "call ms: the whole render call (device set-up, uploads, every pass, read-back). G shadow rays/s: "
            "shadow rays over the shading dispatches' time.", "", *HEADER)
        room = []
        for i in range(runs):
            _, s = timed(ROOM_1E5, f"room_1e5_run{i}", w, h)
            room.append(figures(s))
            say(row(f"run {i + 1}", room[-1]))
        results["room_1e5"] = room
        say("", f"Median GPU time {1e3 * statistics.median(f['gpu_s'] for f in room):.1f} ms; median call "
                f"{1e3 * statistics.median(f['call_s'] for f in room):.0f} ms.", "")

    def part2():
        say("## 2. The shipped scenes, lightcuts at the defaults, one run each", "", *HEADER)
        results["scenes"] = {}
        for scene in scenes:
            name = os.path.splitext(os.path.basename(scene))[0]
            _, s = timed(scene, name, w, h)
            results["scenes"][name] = figures(s)
            say(row(name, results["scenes"][name]))
        say("")

    def part3():
        say("## 3. The cut heap and the tile passes on the 10^5 room", "", *HEADER)
        results["heap"] = {}
        variants = []
        for k in (8, 16, 32, 64):
            for memory in ("shared", "private"):
                variants.append((f"K = {k}, {memory} memory", ["--cut-heap", str(k)], {"LC_VK_HEAP_MEMORY": memory}))
        variants += [("cuts shared by 2x2 quads, K = 16, shared memory", ["--cut-sharing", "quad", "--cut-heap", "16"],
                      {"LC_VK_HEAP_MEMORY": "shared"}),
                     ("cuts shared by 2x2 quads, K = 64 (the default), private memory", ["--cut-sharing", "quad"],
                      {"LC_VK_HEAP_MEMORY": "private"}),
                     ("K = 64, tile passes of about 200 ms (LC_VK_TARGET_MS=200)", [], {"LC_VK_TARGET_MS": "200"})]
        for label, extra, env_add in variants:
            try:
                _, s = timed(ROOM_1E5, "heap", w, h, extra=extra, env_add=env_add)
            except RuntimeError as e:  # refused (a heap too large for shared memory), or failed
                say(f"| {label} | did not render: {str(e).splitlines()[-1]} |")
                continue
            results["heap"][label] = figures(s)
            say(row(label, results["heap"][label]))
        say("")

    def part4():
        bw, bh = max(1, w // 8), max(1, h // 8)
        say(f"## 4. Brute force against lightcuts at {bw}x{bh}", "",
            "ns per ray: the shading dispatches' time over the shadow rays (the camera rays are timed apart).", "",
            "| scene | brute GPU ms | brute call ms | brute ns per ray | lightcuts GPU ms | lightcuts ns per ray | ratio "
            "| speedup |", "|---|---|---|---|---|---|---|---|")
        results["brute"] = {}
        for scene in scenes[:2]:
            name = os.path.splitext(os.path.basename(scene))[0]
            try:
                _, b = timed(scene, name + "_brute", bw, bh, "brute", timeout=a.brute_timeout)
            except subprocess.TimeoutExpired:
                say(f"| {name} | did not finish in {a.brute_timeout:.0f} s |")
                continue
            _, l = timed(scene, name + "_lightcuts", bw, bh)
            fb, fl = figures(b), figures(l)
            if min(fb["shadow_rays"], fl["shadow_rays"], fb["gpu_s"], fl["gpu_s"]) <= 0:
                say(f"| {name} | no shadow rays or no GPU time to divide by |")
                continue
            nb, nl = 1e9 * fb["shading_s"] / fb["shadow_rays"], 1e9 * fl["shading_s"] / fl["shadow_rays"]
            results["brute"][name] = {"brute": fb, "lightcuts": fl, "ratio": nl / nb,
                                      "speedup": fb["gpu_s"] / fl["gpu_s"]}
            say(f"| {name} | {1e3 * fb['gpu_s']:.1f} | {1e3 * fb['call_s']:.0f} | {nb:.3f} | {1e3 * fl['gpu_s']:.1f} | "
                f"{nl:.3f} | {nl / nb:.2f} | {fb['gpu_s'] / fl['gpu_s']:.1f} |")
        say("")

    def part5():
        say(f"## 5. The CPU path of this machine on the 10^5 room, {w}x{h}", "")
        vk_exr, _ = timed(ROOM_1E5, "room_1e5_vulkan", w, h)
        cpu_exr, c = render(a.out, ROOM_1E5, "room_1e5_cpu_pixel", w, h, device="cpu",
                            extra=["--cut-sharing", "pixel"])
        _, d = render(a.out, ROOM_1E5, "room_1e5_cpu", w, h, device="cpu")
        rmse = speed.compare(vk_exr, cpu_exr)["rmse"]
        results["cpu"] = {"pixel_s": c["seconds"]["render"], "defaults_s": d["seconds"]["render"],
                          "vulkan_vs_cpu_pixel_rmse": rmse}
        say(f"CPU render, a cut per pixel: {c['seconds']['render']:.3f} s; at the defaults (octets): "
            f"{d['seconds']['render']:.3f} s; the Vulkan image against the CPU's with a cut per pixel: "
            f"relative RMSE {rmse:.2e}.", "")

    def part6():
        if not a.lights:
            return
        scene = os.path.join(a.out, "room_lights_scene.json")
        s = json.load(open(os.path.join(ROOT, "scenes/room/room_1e4.json")))
        for m in s["meshes"]:
            m["obj"] = os.path.join(ROOT, "scenes/room", os.path.basename(m["obj"]))
        s["lights"] = [{"type": "points_csv", "file": os.path.abspath(a.lights)}]
        json.dump(s, open(scene, "w"), indent=1)
        _, s = timed(scene, "room_lights", w, h)
        sec, b, count = s["seconds"], s.get("buffer_bytes", {}), s["lights"]
        per_light = (b.get("lights", 0) + b.get("light_tree_nodes", 0)) / count
        peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
        results["lights"] = {"count": count, "load_s": sec["load"], "tree_s": sec["light_tree_build"],
                             "bytes_per_light": per_light, "peak_kib": peak, **figures(s)}
        say(f"## 6. The room with {count} lights ({os.path.basename(a.lights)}), {w}x{h}", "", *HEADER,
            row("lightcuts", figures(s)), "",
            f"Light list read in {sec['load']:.2f} s, light tree built in {sec['light_tree_build']:.2f} s; "
            f"light and tree buffers {per_light:.1f} bytes per light; largest peak resident memory of a "
            f"render of this run so far {peak} KiB.", "")

    parts = {"1": part1, "2": part2, "3": part3, "4": part4, "5": part5, "6": part6}
    for p in order:
        if p in ("1", "3", "5") and ROOM_1E5 not in scenes:
            say(f"## Part {p} skipped: {speed.missing(ROOM_1E5)} is missing", "")
            continue
        parts[p]()
    for f in os.listdir(a.out):
        if f.startswith(("warm-up", "heap")) and f.endswith((".exr", ".json")):
            os.remove(os.path.join(a.out, f))
    flush()


if __name__ == "__main__":
    main()
