#!/usr/bin/python3
"""Seeded generator of point-light sets in the points_csv format.

Writes one light per line, "x,y,z,r,g,b" (docs/scene-format.md), for any
count and a handful of spatial distributions. The total intensity is fixed
independently of the count (each light gets total / count), so a scene keeps
the same brightness when its light set is scaled from 10^3 to 10^6 lights.

Examples:
  scripts/gen_lights.py --shape room --count 10000 --out scenes/room/lights_1e4.csv
  scripts/gen_lights.py --shape clusters --count 1000000 --box=-1,0,-1,1,2,1 \\
      --total-intensity 20 --out /tmp/lights_1e6.csv

Standard library only, so it runs on any python3.
"""

import argparse
import math
import os
import random
import sys

# The demo room built by scripts/make_room.py: x in [-2.5, 2.5], y in [0, 3],
# z in [-3, 3]. make_room.py imports these so the two never disagree.
ROOM_MIN = (-2.5, 0.0, -3.0)
ROOM_MAX = (2.5, 3.0, 3.0)
ROOM_TOTAL_INTENSITY = 12.0  # W/sr, summed over all lights (mean of r, g, b)

# Room light layout: (weight, centre, sigma xyz, colour). Three warm clusters
# hang well below the ceiling, two cool/coloured ones sit low in the back
# corners so the boxes throw long, clearly visible shadows towards the camera,
# and a thin uniform scatter fills the upper half of the room.
ROOM_CLUSTERS = [
    (0.25, (-1.2, 2.35, -1.9), (0.22, 0.08, 0.22), (1.00, 0.86, 0.68)),
    (0.25, (1.3, 2.45, -0.9), (0.22, 0.08, 0.22), (1.00, 0.90, 0.75)),
    (0.15, (0.0, 2.40, 1.3), (0.25, 0.08, 0.25), (0.95, 0.95, 1.00)),
    (0.12, (-2.15, 1.10, -2.65), (0.10, 0.15, 0.10), (0.55, 0.70, 1.00)),
    (0.13, (2.15, 0.85, -2.65), (0.10, 0.15, 0.10), (1.00, 0.62, 0.45)),
]
ROOM_SCATTER_WEIGHT = 0.10
ROOM_SCATTER_MIN = (-2.3, 1.9, -2.8)
ROOM_SCATTER_MAX = (2.3, 2.8, 2.0)
ROOM_MARGIN = 0.05  # lights stay this far inside the walls


def luminance_scale(colour):
    """Factor that makes the mean of r, g, b equal 1."""
    return 3.0 / sum(colour)


def truncated_gauss(rng, mean, sigma, limit=2.5):
    """Gaussian sample cut at limit * sigma, so a blob has a hard extent."""
    while True:
        v = rng.gauss(0.0, 1.0)
        if abs(v) <= limit:
            return mean + v * sigma


def split_counts(count, weights):
    """Integer counts proportional to weights that sum exactly to count."""
    total = sum(weights)
    raw = [count * w / total for w in weights]
    counts = [int(math.floor(r)) for r in raw]
    # Hand the remainder to the largest fractional parts (largest remainder method).
    order = sorted(range(len(raw)), key=lambda i: raw[i] - counts[i], reverse=True)
    for i in order[: count - sum(counts)]:
        counts[i] += 1
    return counts


def clamp(v, lo, hi):
    return min(max(v, lo), hi)


# Each shape returns a list of (x, y, z, cr, cg, cb) with colours of mean 1.

def shape_room(rng, count, _box, colour):
    weights = [c[0] for c in ROOM_CLUSTERS] + [ROOM_SCATTER_WEIGHT]
    counts = split_counts(count, weights)
    lo = [m + ROOM_MARGIN for m in ROOM_MIN]
    hi = [m - ROOM_MARGIN for m in ROOM_MAX]
    out = []
    for (weight, centre, sigma, tint), n in zip(ROOM_CLUSTERS, counts):
        s = luminance_scale(tint)
        c = tuple(t * s * k for t, k in zip(tint, colour))
        for _ in range(n):
            p = [clamp(truncated_gauss(rng, centre[a], sigma[a]), lo[a], hi[a]) for a in range(3)]
            out.append((p[0], p[1], p[2]) + c)
    for _ in range(counts[-1]):
        p = [rng.uniform(ROOM_SCATTER_MIN[a], ROOM_SCATTER_MAX[a]) for a in range(3)]
        out.append((p[0], p[1], p[2]) + tuple(colour))
    rng.shuffle(out)  # file order should not reveal the cluster structure
    return out


def shape_box(rng, count, box, colour):
    lo, hi = box
    return [tuple(rng.uniform(lo[a], hi[a]) for a in range(3)) + tuple(colour) for _ in range(count)]


def shape_grid(_rng, count, box, colour):
    """Regular grid with cells as cubic as the box allows; the last layer
    may be partial so the count is exact."""
    lo, hi = box
    ext = [hi[a] - lo[a] for a in range(3)]
    live = [a for a in range(3) if ext[a] > 0]
    dims = [1, 1, 1]
    if live:
        volume = 1.0
        for a in live:
            volume *= ext[a]
        cell = (volume / count) ** (1.0 / len(live))
        for a in live:
            dims[a] = max(1, int(round(ext[a] / cell)))
        # Grow the coarsest axis until the grid holds enough points.
        while dims[0] * dims[1] * dims[2] < count:
            a = max(live, key=lambda k: ext[k] / dims[k])
            dims[a] += 1
    out = []
    for i in range(dims[0]):
        for j in range(dims[1]):
            for k in range(dims[2]):
                if len(out) == count:
                    return out
                ijk = (i, j, k)
                p = [lo[a] + (ijk[a] + 0.5) * ext[a] / dims[a] for a in range(3)]
                out.append((p[0], p[1], p[2]) + tuple(colour))
    return out


def shape_clusters(rng, count, box, colour, clusters=8, sigma=0.05):
    lo, hi = box
    diag = math.sqrt(sum((hi[a] - lo[a]) ** 2 for a in range(3)))
    centres = [[rng.uniform(lo[a], hi[a]) for a in range(3)] for _ in range(clusters)]
    counts = split_counts(count, [1.0] * clusters)
    out = []
    for centre, n in zip(centres, counts):
        for _ in range(n):
            p = [clamp(truncated_gauss(rng, centre[a], sigma * diag), lo[a], hi[a]) for a in range(3)]
            out.append((p[0], p[1], p[2]) + tuple(colour))
    rng.shuffle(out)
    return out


def shape_plane(rng, count, box, colour):
    """Uniform on the top face (y = max y) of the box: a light panel."""
    lo, hi = box
    return [(rng.uniform(lo[0], hi[0]), hi[1], rng.uniform(lo[2], hi[2])) + tuple(colour)
            for _ in range(count)]


def shape_sphere(rng, count, box, colour):
    """Uniform on the largest sphere centred in the box."""
    lo, hi = box
    centre = [(lo[a] + hi[a]) * 0.5 for a in range(3)]
    radius = min(hi[a] - lo[a] for a in range(3)) * 0.5
    out = []
    for _ in range(count):
        z = rng.uniform(-1.0, 1.0)
        phi = rng.uniform(0.0, 2.0 * math.pi)
        r = math.sqrt(max(0.0, 1.0 - z * z))
        out.append((centre[0] + radius * r * math.cos(phi), centre[1] + radius * z,
                    centre[2] + radius * r * math.sin(phi)) + tuple(colour))
    return out


SHAPES = {
    "room": shape_room,
    "grid": shape_grid,
    "box": shape_box,
    "clusters": shape_clusters,
    "plane": shape_plane,
    "sphere": shape_sphere,
}


def generate(shape, count, seed=1, box=((-1.0, -1.0, -1.0), (1.0, 1.0, 1.0)),
             total_intensity=None, colour=(1.0, 1.0, 1.0), clusters=8, sigma=0.05):
    """Returns [(x, y, z, r, g, b)] with sum of mean(r, g, b) = total_intensity."""
    if count < 1:
        raise ValueError("count must be >= 1")
    if total_intensity is None:
        total_intensity = ROOM_TOTAL_INTENSITY if shape == "room" else 10.0
    rng = random.Random(seed)
    s = luminance_scale(colour)
    colour = tuple(c * s for c in colour)
    if shape == "clusters":
        lights = shape_clusters(rng, count, box, colour, clusters, sigma)
    else:
        lights = SHAPES[shape](rng, count, box, colour)
    per_light = total_intensity / count
    return [(x, y, z, r * per_light, g * per_light, b * per_light) for x, y, z, r, g, b in lights]


def write_csv(path, lights, comment):
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    lines = ["# " + comment, "x,y,z,r,g,b"]
    lines.extend("%.6g,%.6g,%.6g,%.6g,%.6g,%.6g" % light for light in lights)
    # Written beside the target and renamed onto it, so that a killed run
    # leaves the old file or none, never half a list that a later run
    # would take for a whole one.
    part = path + ".part"
    with open(part, "w", encoding="ascii", newline="\n") as f:
        f.write("\n".join(lines))
        f.write("\n")
    os.replace(part, path)


def parse_triple(text, what):
    parts = text.split(",")
    if len(parts) != 3:
        raise argparse.ArgumentTypeError("%s needs 3 comma-separated numbers" % what)
    return tuple(float(p) for p in parts)


def parse_box(text):
    parts = [float(p) for p in text.split(",")]
    if len(parts) != 6:
        raise argparse.ArgumentTypeError("--box needs xmin,ymin,zmin,xmax,ymax,zmax")
    lo, hi = tuple(parts[:3]), tuple(parts[3:])
    if any(hi[a] < lo[a] for a in range(3)):
        raise argparse.ArgumentTypeError("--box max must be >= min on every axis")
    return lo, hi


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--count", type=int, required=True, help="number of point lights")
    parser.add_argument("--shape", choices=sorted(SHAPES), default="box",
                        help="room: the demo room's layout (ignores --box); grid, box (uniform), "
                             "clusters (gaussian blobs), plane (top face of --box), "
                             "sphere (surface of the sphere inscribed in --box)")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--box", type=parse_box, default=((-1.0, -1.0, -1.0), (1.0, 1.0, 1.0)),
                        metavar="XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX")
    parser.add_argument("--total-intensity", type=float, default=None,
                        help="W/sr summed over all lights (mean of r,g,b); default %g for room, 10 "
                             "otherwise" % ROOM_TOTAL_INTENSITY)
    parser.add_argument("--color", type=lambda t: parse_triple(t, "--color"), default=(1.0, 1.0, 1.0),
                        metavar="R,G,B", help="tint, rescaled to mean 1 (room keeps its own tints "
                                              "and multiplies them by this)")
    parser.add_argument("--clusters", type=int, default=8, help="clusters: number of blobs")
    parser.add_argument("--sigma", type=float, default=0.05,
                        help="clusters: blob standard deviation as a fraction of the box diagonal")
    parser.add_argument("--out", required=True, help="CSV file to write")
    args = parser.parse_args(argv)
    if args.count < 1:
        parser.error("--count must be >= 1")
    if args.total_intensity is not None and not (args.total_intensity >= 0.0):
        parser.error("--total-intensity must be >= 0")
    if min(args.color) < 0.0 or sum(args.color) <= 0.0:
        parser.error("--color must be non-negative and not black")

    lights = generate(args.shape, args.count, args.seed, args.box, args.total_intensity,
                      args.color, args.clusters, args.sigma)
    comment = "generated by scripts/gen_lights.py " + " ".join(argv)
    write_csv(args.out, lights, comment)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
