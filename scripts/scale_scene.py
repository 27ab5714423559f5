#!/usr/bin/env python3
"""Scenes that stress how whitted scales beyond the peers' many_N scenes.

    scripts/scale_scene.py lights N L [--outdir DIR]   many_N under L lights
    scripts/scale_scene.py crowd N [--dist 2.5] [--radius 1] [--outdir DIR]
    scripts/scale_scene.py clump N [--outdir DIR]      N glass balls that all overlap

`lights` takes make_hw3.py's many_N scene (../shared/peers) and puts L lights of
intensity 1/L on a ring of radius 60 at heights 40 to 120 in place of its one light
(DIR/many_N_LL.toml): each light has a directional grid, and the lights share one
grid's bound on memory. `crowd` writes N balls of radius R at DIST to 1.2 DIST from a
light at the origin, camera outside at z = 30 (DIR/crowd_N.toml): each ball is seen
over a large part of the light's sky, which fills a directional grid's cells.
`clump` writes N balls of radius 5, mostly glass, whose centres lie within 5 of the
origin, so that each overlaps every other, seen from z = 60 (DIR/clump_N.toml): rays
inside a ball overlapped by more than 16 walk the hierarchy. `crowd` and `clump`
also write DIR/NAME.txt in the peers' format, for the Embree peer.
"""
import argparse
import math
import os
import random
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
MAKE_HW3 = os.path.join(HERE, "..", "..", "shared", "peers", "make_hw3.py")
ONE_LIGHT = "[[light]]\nposition = [-30, 60, 40]\nintensity = [1, 1, 1]\n"


def lights(n, count, outdir):
    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run([sys.executable, MAKE_HW3, "--many", str(n), "--outdir", tmp, "--toml"],
                       check=True, stdout=subprocess.DEVNULL)
        with open(os.path.join(tmp, "many_%d.toml" % n)) as f:
            text = f.read()
    if ONE_LIGHT not in text:
        sys.exit("make_hw3.py's many_%d has no light at (-30, 60, 40)" % n)
    ring = ""
    for i in range(count):
        a = 2 * math.pi * i / count
        ring += ("[[light]]\nposition = [%.4f, %d, %.4f]\nintensity = [%.6f, %.6f, %.6f]\n\n"
                 % (60 * math.cos(a), 40 + 20 * (i % 5), 60 * math.sin(a), *[1.0 / count] * 3))
    path = os.path.join(outdir, "many_%d_L%d.toml" % (n, count))
    with open(path, "w") as f:
        f.write(text.replace(ONE_LIGHT, ring, 1))
    print(path)


def write_pair(outdir, name, comment, camera_z, film_z, light, balls, material):
    """DIR/NAME.toml (whitted) and DIR/NAME.txt (the peers): 640x360, depth 5, one
    light of intensity 1, every ball `(centre, radius)` of `material`
    (color, reflect, transmit, ior)."""
    color, reflect, transmit, ior = material
    toml = ["# %s: %s" % (name, comment), "", "[camera]",
            "origin = [0, 0, %g]" % camera_z, "lower_left = [-4, -2.25, %g]" % film_z,
            "horizontal = [8, 0, 0]", "vertical = [0, 4.5, 0]", "",
            "[[light]]", "position = [%g, %g, %g]" % light, "intensity = [1, 1, 1]", "",
            "[image]", "width = 640", "height = 360", "max_depth = 5", ""]
    txt = ["camera 0 0 %g  -4 -2.25 %g  8 0 0  0 4.5 0" % (camera_z, film_z),
           "light %g %g %g  1 1 1" % light, "size 640 360", "depth 5"]
    for c, r in balls:
        toml += ["[[sphere]]", "center = [%.6f, %.6f, %.6f]" % tuple(c), "radius = %g" % r,
                 "color = [%g, %g, %g]" % color, "reflect = %g" % reflect,
                 "transmit = %g" % transmit, "ior = %g" % ior, ""]
        txt.append("sphere %.6f %.6f %.6f  %g  %g %g %g  %g %g  %g"
                   % (*c, r, *color, reflect, transmit, ior))
    base = os.path.join(outdir, name)
    with open(base + ".toml", "w") as f:
        f.write("\n".join(toml))
    with open(base + ".txt", "w") as f:
        f.write("\n".join(txt) + "\n")
    print(base + ".toml")


def crowd(n, dist, radius, outdir):
    rng = random.Random(1)
    balls = []
    for _ in range(n):
        while True:
            v = [rng.gauss(0, 1) for _ in range(3)]
            length = math.sqrt(sum(x * x for x in v))
            if length > 1e-6:
                break
        d = dist * (1 + 0.2 * rng.random())
        balls.append(([x / length * d for x in v], radius))
    comment = ("%d balls of radius %g at %g-%g from a light (scripts/scale_scene.py)"
               % (n, radius, dist, 1.2 * dist))
    write_pair(outdir, "crowd_%d" % n, comment, 30, 20, (0, 0, 0), balls,
               ((0.8, 0.5, 0.3), 0.3, 0, 1.5))


def clump(n, outdir):
    rng = random.Random(2)
    balls = []
    for _ in range(n):
        while True:
            v = [rng.uniform(-1, 1) for _ in range(3)]
            if sum(x * x for x in v) <= 1:
                break
        balls.append(([5 * x for x in v], 5))
    comment = "%d glass balls of radius 5 within 5 of the origin (scripts/scale_scene.py)" % n
    write_pair(outdir, "clump_%d" % n, comment, 60, 50, (-30, 40, 30), balls,
               ((0.8, 0.5, 0.3), 0.1, 0.8, 1.5))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="kind", required=True)
    lp = sub.add_parser("lights", help="many_N under L lights")
    lp.add_argument("n", type=int)
    lp.add_argument("count", type=int)
    rp = sub.add_parser("crowd", help="N large balls around a light")
    rp.add_argument("n", type=int)
    rp.add_argument("--dist", type=float, default=2.5,
                    help="nearest centre distance from the light")
    rp.add_argument("--radius", type=float, default=1.0)
    cp = sub.add_parser("clump", help="N glass balls that all overlap")
    cp.add_argument("n", type=int)
    for p in (lp, rp, cp):
        p.add_argument("--outdir", default=".")
    args = ap.parse_args()
    os.makedirs(args.outdir, exist_ok=True)
    if args.kind == "lights":
        lights(args.n, args.count, args.outdir)
    elif args.kind == "crowd":
        crowd(args.n, args.dist, args.radius, args.outdir)
    else:
        clump(args.n, args.outdir)


if __name__ == "__main__":
    main()
