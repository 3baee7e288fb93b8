#!/usr/bin/env python3
"""Speed and the bounded heap, in one run (docs/results/speed.md).

  bench/speed.py [--out DIR] [--size N] [--heaps 8,16,32,64] [--brute-runs N] [--quick]

1. Lightcuts against brute force on the shipped room with 10^4 and 10^5
   lights (scenes/room/room_1e4.json, room_1e5.json) at SIZE x SIZE on the
   CPU path, both at full resolution in this run: render times, shadow rays,
   the cost of a shadow ray as the issue defines it (everything but the
   camera rays over the shadow rays: the render time less the median of
   three renders of the camera rays alone, LC_CPU_CAMERA_RAYS_ONLY=1; the
   ratio with them left in is printed too) and the speedup, from the medians of brute force's
   renders (--brute-runs, 3 by default) and lightcuts', taken in turn so
   that the machine's drift reaches both; the render times leave out the
   scene's preparation (loading, the BVH and the light tree), which a scene
   pays once however many images it renders; the light tree's build (which
   brute force runs too, for the lights in the tree's order) is printed
   beside them with the speedup when each method's is counted in; at the defaults (the CPU's cuts shared
   by 4x2 octets of pixels) and with a cut per pixel (cut_sharing "pixel", as
   the Vulkan kernels cut).
2. The K table: every shipped scene rendered with lightcuts on the CPU with a
   cut per pixel and a cut heap of K slots for each K of --heaps and with a
   heap as large as the tree needs (nothing frozen), then at the defaults
   (octets, K = 64 slots per pixel pooled by each octet) and with cuts
   shared by 2x2 quads, against brute force:
   relative RMSE, pixels above 2%, mean cut, shadow rays per pixel, the
   share of samples that froze clusters, and the time.
3. The Vulkan path (lavapipe) on the room with 10^4 lights at the same size
   for each K that fits its shared memory, with the CPU path cutting each
   pixel alone (the same image) in the same run, and the CPU at its
   defaults: the Vulkan/CPU time ratios, and the samples whose heap waited
   in global memory between dispatches; and cuts shared by
   quads, on both (cut_sharing "quad", shaders/quadcuts.comp); the kernels
   have no octets.

Writes DIR/speed.md and DIR/speed.json (default out/speed), after each
scene as well (marked incomplete until the run ends). Nothing here
passes or fails. --quick: 32x32 (unless --size says otherwise), two scenes (CI's bench label runs it);
--vulkan-only: part 3 alone.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXE = os.path.join(ROOT, "build", "host", "lightcuts")
LAVAPIPE = os.environ.get("LC_LAVAPIPE_ICD", "/usr/share/vulkan/icd.d/lvp_icd.x86_64.json")
SCENES = ["scenes/room/room_1e4.json", "scenes/room/room_1e5.json", "scenes/panels/panels.json",
          "scenes/gallery/gallery.json", "scenes/sky/sky.json", "scenes/materials/materials.json",
          "scenes/bunny/bunny.json"]
UNBOUNDED = 1000000  # more slots than any tree here can fill


class RenderFailed(RuntimeError):
    """A render that exited non-zero; the message is the renderer's."""


def render(out, scene, name, size, method, device="cpu", cut_heap=None, sharing=None, env_extra=None):
    exr = os.path.join(out, name + ".exr")
    stats = os.path.join(out, name + ".json")
    cmd = [EXE, "render", os.path.join(ROOT, scene), "-o", exr, "--method", method, "--device", device,
           "--width", str(size), "--height", str(size), "--stats", stats, "--no-png"]
    if cut_heap is not None:
        cmd += ["--cut-heap", str(cut_heap)]
    if sharing is not None:
        cmd += ["--cut-sharing", sharing]
    env = dict(os.environ, **(env_extra or {}))
    if device == "vulkan":
        env["VK_DRIVER_FILES"] = LAVAPIPE
    run = subprocess.run(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if run.returncode != 0:
        raise RenderFailed(f"{' '.join(cmd)}: exit {run.returncode}: {run.stderr.strip()}")
    return exr, json.load(open(stats))


def camera_seconds(out, scene, name, size, runs=3):
    """The median time of the CPU path's camera rays alone at this size."""
    return statistics.median(
        render(out, scene, f"{name}_camera{i}", size, "lightcuts", env_extra={"LC_CPU_CAMERA_RAYS_ONLY": "1"})[1]
        ["seconds"]["render"] for i in range(runs))


def compare(image, reference):
    text = subprocess.run([EXE, "compare", image, reference], check=True, capture_output=True, text=True).stdout
    values = {}
    for line in text.splitlines():
        if line.startswith("relative RMSE"):
            values["rmse"] = float(line.split()[-1])
        elif line.startswith("pixels above 2%"):
            values["above_2pct"] = float(line.split()[-1].rstrip("%")) / 100.0
    return values


def missing(scene):
    needs = {"room_1e4": "scenes/room/lights_1e4.csv", "room_1e5": "scenes/room/lights_1e5.csv",
             "gallery": "scenes/gallery/spots_1e4.csv", "bunny": "scenes/bunny/bunny.obj",
             "sky": "scenes/bunny/bunny.obj"}
    for key, path in needs.items():
        if key in scene and not os.path.exists(os.path.join(ROOT, path)):
            return path
    return None


def main():
    global EXE
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "speed"))
    ap.add_argument("--size", type=int, default=None, help="image width and height (default 128; 32 with --quick)")
    ap.add_argument("--heaps", default="8,16,32,64")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--no-vulkan", action="store_true")
    ap.add_argument("--vulkan-only", action="store_true", help="only part 3")
    ap.add_argument("--brute-runs", type=int, default=None,
                    help="brute-force renders of each room (default 3; 1 with --quick)")
    ap.add_argument("--exe", default=EXE, help="the lightcuts binary (default build/host/lightcuts)")
    a = ap.parse_args()
    EXE = a.exe
    if a.brute_runs is None:
        a.brute_runs = 1 if a.quick else 3
    if a.size is None:
        a.size = 32 if a.quick else 128
    if a.size < 1:
        sys.exit("speed: --size takes a positive whole number, not %d" % a.size)
    size = a.size
    scenes = SCENES[:1] + SCENES[3:4] if a.quick else SCENES
    try:
        heaps = [int(k) for k in a.heaps.split(",")]
    except ValueError:
        sys.exit("speed: --heaps takes comma-separated whole numbers, not '%s'" % a.heaps)
    # The K table and the speed rows compare against the default heap.
    if 64 not in heaps or min(heaps) < 1:
        sys.exit("speed: --heaps must hold 64 (the default, which the tables compare against) and no K below 1")
    if not os.access(EXE, os.X_OK):
        sys.exit("speed: no renderer at %s (build it, or name it with --exe)" % EXE)
    os.makedirs(a.out, exist_ok=True)
    results = {"size": size, "speed": [], "heaps": [], "vulkan": []}
    lines = [f"# Speed and the bounded heap ({size}x{size}, CPU path unless said)", "",
             "Command: `bench/speed.py " + " ".join(sys.argv[1:]) + "`", ""]

    # 1 and 2: brute force per scene (the rooms: --brute-runs times), lightcuts per heap size.
    lines += ["## Lightcuts against brute force (defaults: error 0.02, max cut 1000, cut_heap 64, cuts shared "
              "by octets)", "",
              "brute s: the median of brute force's renders, the first before the K table (its image is the "
              "reference) and the others after it, each in brackets. lightcuts s: the median of the renders at "
              "the defaults before brute force, at the end of the K table and after it, taking turns with brute "
              "force's, each in brackets. The speedup is the ratio of the medians. camera s: the median of three "
              "renders of the camera rays alone; us per ray: the render's median time less that, over its shadow "
              "rays (the issue's definition), and their ratio; with camera rays: the ratio of render time over "
              "shadow rays. The times are the renders' (`seconds.render`), without the scene's preparation; "
              "tree s: the median of the light tree's build in lightcuts' runs, and the speedup with each "
              "method's build added to its render (brute force builds the tree too, once, for its lights' "
              "order). pixel s: the render with a cut per pixel and "
              "K = 64 in the K table (as the Vulkan kernels cut), and its speedup.", "",
              "| scene | brute s | brute rays/px | lightcuts s | rays/px | camera s | us per brute ray | "
              "us per lightcuts ray | ratio | with camera rays | speedup | tree s | speedup with tree | pixel s | "
              "pixel rays/px | pixel speedup |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    table = ["## The cut heap: K slots against a heap as large as the tree needs", "",
             "Rows `pixel`: a cut per pixel, K slots per pixel (the Vulkan kernels' heap). Row `quad`: a cut "
             "per 2x2 quad with its pixels' 4 x 64 slots pooled. Row `octet`: the defaults, a cut per 4x2 "
             "octet with its pixels' 8 x 64 slots pooled (a tile's blocks after an octet whose cut reached "
             "max_cut cut as quads). Mean cut and samples that froze: of the pixels that shade a surface "
             "(the sky's background has no cut).", "",
             "| scene | cuts | K | relative RMSE | above 2% | mean cut | rays/px | samples that froze | time s |",
             "|---|---|---|---|---|---|---|---|---|"]
    md_path, json_path = os.path.join(a.out, "speed.md"), os.path.join(a.out, "speed.json")

    def save(partial):
        """Writes speed.md and speed.json as they stand: after each scene
        too, so that a run cut short keeps what it measured."""
        body = lines + ([""] + table + ["", "(Incomplete: the run was still going when this was written.)"]
                        if partial else [])
        with open(md_path, "w") as f:
            f.write("\n".join(body) + "\n")
        with open(json_path, "w") as f:
            json.dump({**results, "complete": not partial}, f, indent=1)

    for scene in [] if a.vulkan_only else scenes:
        why = missing(scene)
        if why:
            print(f"skipping {scene}: {why} is missing", file=sys.stderr)
            continue
        name = os.path.splitext(os.path.basename(scene))[0]
        room = name.startswith("room_1e")
        # This machine's speed drifts within minutes, and brute force runs
        # for a minute: the rooms' lightcuts time is the median of renders
        # before it, in the K table and after the table.
        lightcuts_times, tree_times = [], []
        if room:  # at the defaults, whose cut heap is K = 64
            first = render(a.out, scene, name + "_before", size, "lightcuts")[1]
            lightcuts_times.append(first["seconds"]["render"])
            tree_times.append(first["seconds"]["light_tree_build"])
        print(f"{scene}: brute force", file=sys.stderr)
        ref, bstats = render(a.out, scene, name + "_brute", size, "brute")
        pixels = size * size
        pixel = None
        for sharing, k in [("pixel", k) for k in heaps + [UNBOUNDED]] + [("quad", None), ("octet", None)]:
            print(f"{scene}: lightcuts, {sharing}, cut_heap {k or 'default'}", file=sys.stderr)
            img, s = render(a.out, scene, f"{name}_{sharing}_k{k or 'default'}", size, "lightcuts", cut_heap=k,
                            sharing=sharing)
            c = compare(img, ref)
            lc = s["lightcuts"]
            row = {"scene": scene, "cut_sharing": sharing, "cut_heap": lc["cut_heap"],
                   "heap_slots": lc["heap_slots"], "seconds": s["seconds"]["render"],
                   "rays_per_pixel": s["shadow_rays"] / pixels, "cut_mean": lc["cut_size_mean"],
                   "frozen": lc["heap_frozen_samples"] / max(lc.get("shaded_pixels", pixels), 1), **c}
            results["heaps"].append(row)
            label = "as needed" if k == UNBOUNDED else str(lc["cut_heap"])
            table.append(f"| {name} | {sharing} | {label} | {c['rmse']:.4f} | {100 * c['above_2pct']:.1f}% | "
                         f"{row['cut_mean']:.1f} | {row['rays_per_pixel']:.1f} | {100 * row['frozen']:.1f}% | "
                         f"{row['seconds']:.3f} |")
            if sharing == "pixel" and k == 64:
                pixel = s
            if sharing == "octet" and room:
                lightcuts_times.append(s["seconds"]["render"])
        save(partial=True)
        if not room:
            continue
        # Brute force's time drifts with the machine too (2.26 to 2.66 s
        # for the room at 10^4 lights, 128x128, within one session): after
        # the table, lightcuts and brute force again in turn, and the
        # medians of each.
        brute_times = [bstats["seconds"]["render"]]
        for run in range(max(a.brute_runs, 1)):
            after = render(a.out, scene, f"{name}_after{run}", size, "lightcuts")[1]
            lightcuts_times.append(after["seconds"]["render"])
            tree_times.append(after["seconds"]["light_tree_build"])
            if run + 1 < a.brute_runs:
                print(f"{scene}: brute force again", file=sys.stderr)
                brute_times.append(
                    render(a.out, scene, f"{name}_brute{run + 1}", size, "brute")[1]["seconds"]["render"])
        tb, tl = statistics.median(brute_times), statistics.median(lightcuts_times)
        tt = statistics.median(tree_times)
        tree_brute = bstats["seconds"]["light_tree_build"]
        with_tree = (tb + tree_brute) / (tl + tt)
        rb, rl = bstats["shadow_rays"], first["shadow_rays"]
        tc = camera_seconds(a.out, scene, name, size)
        cb, cl = 1e6 * (tb - tc) / rb, 1e6 * (tl - tc) / rl
        with_camera = (tl / rl) / (tb / rb)
        tp = pixel["seconds"]["render"] if pixel else float("nan")
        rp = pixel["shadow_rays"] if pixel else float("nan")
        results["speed"].append({"scene": scene, "brute_seconds": tb, "brute_runs": brute_times, "brute_rays": rb,
                                 "lightcuts_seconds": tl, "lightcuts_runs": lightcuts_times,
                                 "lightcuts_rays": rl, "camera_seconds": tc, "us_per_brute_ray": cb,
                                 "us_per_lightcuts_ray": cl, "ratio": cl / cb,
                                 "ratio_with_camera_rays": with_camera, "speedup": tb / tl,
                                 "tree_seconds": tt, "tree_runs": tree_times, "brute_tree_seconds": tree_brute,
                                 "speedup_with_tree": with_tree,
                                 "pixel_seconds": tp, "pixel_rays": rp,
                                 "pixel_speedup": tb / tp})
        runs = ", ".join(f"{t:.3f}" for t in lightcuts_times)
        brute_runs = ", ".join(f"{t:.2f}" for t in brute_times)
        lines.append(f"| {name} | {tb:.2f} ({brute_runs}) | {rb / pixels:.0f} | {tl:.3f} ({runs}) | {rl / pixels:.1f} | "
                     f"{tc:.4f} | {cb:.4f} | {cl:.4f} | {cl / cb:.2f} | {with_camera:.2f} | {tb / tl:.1f}x | "
                     f"{tt:.3f} | {with_tree:.1f}x | {tp:.3f} | "
                     f"{rp / pixels:.1f} | {tb / tp:.1f}x |")
        save(partial=True)
    lines += [""] + table + [""]
    table = []

    # 3: Vulkan against the CPU, room 10^4, for the heap sizes that fit.
    if not a.no_vulkan:
        scene = SCENES[0]
        if not missing(scene):
            lines += ["## Vulkan (lavapipe) against the CPU path, room 10^4 lights", "",
                      "Vulkan s is the whole render call (device, pipelines, uploads included); kernels s the GPU "
                      "timestamps of the camera-ray and shading kernels. Each K rendered once at 8x8 first, so that "
                      "its kernels are in Mesa's shader cache.", "",
                      "CPU s: the CPU path with a cut per pixel, the image the Vulkan kernels make; CPU default s: "
                      "at the CPU's defaults (cuts shared by octets, once at K = 64).", "",
                      "| K | CPU s | Vulkan s | Vulkan/CPU | kernels s | kernels/CPU | heaps paused in global memory "
                      "| relative RMSE vulkan vs cpu |",
                      "|---|---|---|---|---|---|---|---|"]
            default_cpu = render(a.out, scene, "vk_cpu_default", size, "lightcuts")[1]["seconds"]["render"]
            for k in heaps:
                cimg, cs = render(a.out, scene, f"vk_cpu_k{k}", size, "lightcuts", cut_heap=k, sharing="pixel")
                try:
                    # Each K is its own pipeline: the first render with it
                    # compiles the kernel (seconds on lavapipe, inside the
                    # kernel timestamps) into Mesa's cache. Warm it first.
                    render(a.out, scene, f"vk_warm_k{k}", 8, "lightcuts", device="vulkan", cut_heap=k)
                    vimg, vs = render(a.out, scene, f"vk_k{k}", size, "lightcuts", device="vulkan", cut_heap=k)
                except RenderFailed as e:
                    # Only a heap in shared memory can fail to fit
                    # (LC_VK_HEAP_MEMORY=shared); anything else stops the run.
                    if "shared memory" not in str(e):
                        raise
                    lines.append(f"| {k} | {cs['seconds']['render']:.3f} | does not fit | | | | | |")
                    continue
                c = compare(vimg, cimg)
                tc, tv = cs["seconds"]["render"], vs["seconds"]["render"]
                tk = vs["seconds"]["primary"] + vs["seconds"]["shading"]
                paused = vs["lightcuts"]["heap_paused_samples"] / (size * size)
                results["vulkan"].append({"cut_heap": k, "cpu_seconds": tc, "vulkan_seconds": tv,
                                          "kernel_seconds": tk, "ratio": tv / tc, "paused": paused,
                                          "rmse": c["rmse"]})
                lines.append(f"| {k} | {tc:.3f} | {tv:.3f} | {tv / tc:.1f} | {tk:.3f} | {tk / tc:.1f} | "
                             f"{100 * paused:.1f}% | {c['rmse']:.2e} |")
                if k == 64:
                    results["vulkan_against_cpu_default"] = {"cpu_default_seconds": default_cpu,
                                                             "ratio": tv / default_cpu}
                    lines.append(f"| 64, CPU at its defaults | {default_cpu:.3f} | {tv:.3f} | {tv / default_cpu:.1f} "
                                 f"| {tk:.3f} | {tk / default_cpu:.1f} | | |")
            # The CPU's quads on Vulkan too (quadcuts.comp), at the default
            # K: the same cuts as the CPU's with cut_sharing "quad" (the
            # image compared), timed against the CPU at its defaults.
            try:
                render(a.out, scene, "vk_warm_quad", 8, "lightcuts", device="vulkan", sharing="quad")
                qimg, qs = render(a.out, scene, "vk_quad", size, "lightcuts", device="vulkan", sharing="quad")
                dimg = render(a.out, scene, "vk_cpu_quad", size, "lightcuts", sharing="quad")[0]
                c = compare(qimg, dimg)
                tq = qs["seconds"]["render"]
                tk = qs["seconds"]["primary"] + qs["seconds"]["shading"]
                paused = qs["lightcuts"]["heap_paused_samples"] / (size * size)
                results["vulkan_quads"] = {"cpu_default_seconds": default_cpu, "vulkan_seconds": tq,
                                           "kernel_seconds": tk, "ratio": tq / default_cpu, "paused": paused,
                                           "rmse": c["rmse"]}
                lines.append(f"| 64, quads on Vulkan (cut_sharing quad), CPU at its defaults | {default_cpu:.3f} | {tq:.3f} | "
                             f"{tq / default_cpu:.1f} | {tk:.3f} | {tk / default_cpu:.1f} | {100 * paused:.1f}% | "
                             f"{c['rmse']:.2e} |")
            except RenderFailed as e:
                if "subgroup quad operations" not in str(e):
                    raise
                lines.append("| 64, quads on both | | the device has no quad subgroup operations | | | | | |")
            lines.append("")

    save(partial=False)
    print("\n".join(lines))


if __name__ == "__main__":
    main()
