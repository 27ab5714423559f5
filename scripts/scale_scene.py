#!/usr/bin/env python3
"""Scenes that stress how whitted scales beyond the peers' many_N scenes.

    scripts/scale_scene.py lights N L [--outdir DIR]   many_N under L lights
    scripts/scale_scene.py clump N [--outdir DIR]      N glass balls that all overlap

`lights` takes make_hw3.py's many_N scene (../shared/peers) and puts L lights of
intensity 1/L on a ring of radius 60 at heights 40 to 120 in place of its one light
(DIR/many_N_LL.toml): each light has a directional grid, and the lights share one
grid's bound on memory. `clump` writes N balls of radius 5, mostly glass, whose
centres lie within 5 of the origin, so that each overlaps every other, seen from
z = 60 (DIR/clump_N.toml, and DIR/clump_N.txt in the peers' format for the Embree
peer): rays inside a ball overlapped by more than 16 walk the hierarchy.
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


def clump(n, outdir):
    rng = random.Random(2)
    toml = ["# clump_%d: %d glass balls of radius 5 within 5 of the origin (scripts/scale_scene.py)"
            % (n, n), "", "[camera]", "origin = [0, 0, 60]", "lower_left = [-4, -2.25, 50]",
            "horizontal = [8, 0, 0]", "vertical = [0, 4.5, 0]", "",
            "[[light]]", "position = [-30, 40, 30]", "intensity = [1, 1, 1]", "",
            "[image]", "width = 640", "height = 360", "max_depth = 5", ""]
    txt = ["camera 0 0 60  -4 -2.25 50  8 0 0  0 4.5 0", "light -30 40 30  1 1 1",
           "size 640 360", "depth 5"]
    for _ in range(n):
        while True:
            v = [rng.uniform(-1, 1) for _ in range(3)]
            if sum(x * x for x in v) <= 1:
                break
        c = [5 * x for x in v]
        toml += ["[[sphere]]", "center = [%.6f, %.6f, %.6f]" % tuple(c), "radius = 5",
                 "color = [0.8, 0.5, 0.3]", "reflect = 0.1", "transmit = 0.8", "ior = 1.5", ""]
        txt.append("sphere %.6f %.6f %.6f  5  0.8 0.5 0.3  0.1 0.8  1.5" % tuple(c))
    base = os.path.join(outdir, "clump_%d" % n)
    with open(base + ".toml", "w") as f:
        f.write("\n".join(toml))
    with open(base + ".txt", "w") as f:
        f.write("\n".join(txt) + "\n")
    print(base + ".toml")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="kind", required=True)
    lp = sub.add_parser("lights", help="many_N under L lights")
    lp.add_argument("n", type=int)
    lp.add_argument("count", type=int)
    cp = sub.add_parser("clump", help="N glass balls that all overlap")
    cp.add_argument("n", type=int)
    for p in (lp, cp):
        p.add_argument("--outdir", default=".")
    args = ap.parse_args()
    os.makedirs(args.outdir, exist_ok=True)
    if args.kind == "lights":
        lights(args.n, args.count, args.outdir)
    else:
        clump(args.n, args.outdir)


if __name__ == "__main__":
    main()
