#!/usr/bin/python3
"""Writes scenes/sky/sky.exr: a generated HDR sky with a sun, as a lat-long
RGB OpenEXR of radiance (docs/scene-format.md, "environment").

The sky is a smooth gradient, bright blue-white at the horizon and deeper
blue at the zenith, a dim brown ground below the horizon, and a sun: a disc
of 0.53 degrees (drawn over the few texels it covers) whose irradiance is
about five times the sky's. Nothing is downloaded; the EXR writer below is
the minimal single-part, scanline, uncompressed, 32-bit float layout of the
OpenEXR file format, which every reader accepts.

  /usr/bin/python3 scripts/make_sky.py [--out scenes/sky/sky.exr] [--width 512]
      [--sun-elevation 35] [--sun-azimuth 60]

Standard library only.
"""

import argparse
import math
import os
import struct


def exr_bytes(width, height, rows):
    """rows[y] is a list of (r, g, b) floats for y = 0 (top) .. height-1."""
    def attribute(name, kind, value):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value

    channels = b"".join(c.encode() + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for c in "BGR") + b"\0"
    window = struct.pack("<iiii", 0, 0, width - 1, height - 1)
    header = (struct.pack("<ii", 20000630, 2)
              + attribute("channels", "chlist", channels)
              + attribute("compression", "compression", b"\0")
              + attribute("dataWindow", "box2i", window)
              + attribute("displayWindow", "box2i", window)
              + attribute("lineOrder", "lineOrder", b"\0")
              + attribute("pixelAspectRatio", "float", struct.pack("<f", 1.0))
              + attribute("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0))
              + attribute("screenWindowWidth", "float", struct.pack("<f", 1.0))
              + b"\0")
    line_bytes = width * 3 * 4
    chunk = 8 + line_bytes
    table_end = len(header) + 8 * height
    offsets = b"".join(struct.pack("<Q", table_end + y * chunk) for y in range(height))
    body = bytearray()
    for y, row in enumerate(rows):
        body += struct.pack("<ii", y, line_bytes)
        for c in (2, 1, 0):  # channels in name order: B, G, R
            body += struct.pack("<%df" % width, *(p[c] for p in row))
    return header + offsets + bytes(body)


def direction(u, v):
    """The unit direction through lat-long position (u, v), +Y up."""
    phi = 2.0 * math.pi * (u - 0.5)
    theta = math.pi * v
    return (math.sin(theta) * math.sin(phi), math.cos(theta), -math.sin(theta) * math.cos(phi))


def sky(width, height, sun_elevation, sun_azimuth):
    e, a = math.radians(sun_elevation), math.radians(sun_azimuth)
    sun = (math.cos(e) * math.sin(a), math.sin(e), -math.cos(e) * math.cos(a))
    sun_radius = math.radians(0.53 / 2)
    # Sun radiance: irradiance 5x the sky's (pi * ~1.2) over its disc.
    sun_radiance = 5.0 * math.pi * 1.2 / (math.pi * sun_radius ** 2)
    # Texels whose centre is within this angle of the sun share its power,
    # so the disc is not lost at any resolution.
    texel = math.pi / height
    reach = max(sun_radius, 0.75 * texel)
    sun_texels = []
    rows = []
    for y in range(height):
        row = []
        for x in range(width):
            d = direction((x + 0.5) / width, (y + 0.5) / height)
            up = d[1]
            if up >= 0.0:
                t = 1.0 - up
                colour = (0.35 + 0.9 * t ** 3, 0.55 + 0.75 * t ** 3, 1.2 + 0.3 * t ** 3)
            else:
                colour = (0.12, 0.09, 0.06)
            cos_sun = sum(p * q for p, q in zip(d, sun))
            if math.acos(max(-1.0, min(1.0, cos_sun))) <= reach:
                sun_texels.append((y, x))
            row.append(colour)
        rows.append(row)
    # Spread the sun's power (radiance x disc solid angle) over its texels.
    disc = 2.0 * math.pi * (1.0 - math.cos(sun_radius))
    total_angle = 0.0
    for y, x in sun_texels:
        total_angle += 2.0 * math.pi / width * (math.cos(math.pi * y / height) - math.cos(math.pi * (y + 1) / height))
    for y, x in sun_texels:
        extra = sun_radiance * disc / total_angle
        r, g, b = rows[y][x]
        rows[y][x] = (r + extra * 1.0, g + extra * 0.92, b + extra * 0.8)
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    here = os.path.dirname(os.path.abspath(__file__))
    parser.add_argument("--out", default=os.path.join(here, "..", "scenes", "sky", "sky.exr"))
    parser.add_argument("--width", type=int, default=512)
    parser.add_argument("--sun-elevation", type=float, default=35.0)
    parser.add_argument("--sun-azimuth", type=float, default=60.0)
    args = parser.parse_args()
    height = args.width // 2
    data = exr_bytes(args.width, height, sky(args.width, height, args.sun_elevation, args.sun_azimuth))
    tmp = args.out + ".tmp"
    with open(tmp, "wb") as f:
        f.write(data)
    os.replace(tmp, args.out)
    print("wrote %s (%dx%d)" % (os.path.normpath(args.out), args.width, height))


if __name__ == "__main__":
    main()
