#!/usr/bin/env python3
"""A crowd of large balls around a point light, for whitted and the Embree peer.

    scripts/crowd_scene.py N [--dist 2.5] [--radius 1] [--outdir DIR]

writes DIR/crowd_N.toml (whitted's scene format) and DIR/crowd_N.txt (the peers'
format, as ../shared/peers/make_hw3.py writes it): N balls of radius R at DIST to
1.2 DIST from a light at the origin, in random directions, and the camera outside
at z = 30 looking at them. Each ball is seen over a large part of the light's sky,
which fills a directional grid's cells (docs/log.md, 5 December afternoon: 20,000
such balls took 37.8 s and 11.3 GB before the grids' entries were bounded).
"""
import argparse
import math
import os
import random


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("n", type=int)
    ap.add_argument("--dist", type=float, default=2.5, help="nearest centre distance from the light")
    ap.add_argument("--radius", type=float, default=1.0)
    ap.add_argument("--outdir", default=".")
    args = ap.parse_args()
    rng = random.Random(1)
    toml = ["# crowd_%d: %d balls of radius %g at %g-%g from a light (scripts/crowd_scene.py)"
            % (args.n, args.n, args.radius, args.dist, 1.2 * args.dist), "",
            "[camera]", "origin = [0, 0, 30]", "lower_left = [-4, -2.25, 20]",
            "horizontal = [8, 0, 0]", "vertical = [0, 4.5, 0]", "",
            "[[light]]", "position = [0, 0, 0]", "intensity = [1, 1, 1]", "",
            "[image]", "width = 640", "height = 360", "max_depth = 5", ""]
    txt = ["camera 0 0 30  -4 -2.25 20  8 0 0  0 4.5 0", "light 0 0 0  1 1 1",
           "size 640 360", "depth 5"]
    for _ in range(args.n):
        while True:
            v = [rng.gauss(0, 1) for _ in range(3)]
            length = math.sqrt(sum(x * x for x in v))
            if length > 1e-6:
                break
        d = args.dist * (1 + 0.2 * rng.random())
        c = [x / length * d for x in v]
        toml += ["[[sphere]]", "center = [%.6f, %.6f, %.6f]" % tuple(c),
                 "radius = %g" % args.radius, "color = [0.8, 0.5, 0.3]",
                 "reflect = 0.3", "transmit = 0", "ior = 1.5", ""]
        txt.append("sphere %.6f %.6f %.6f  %g  0.8 0.5 0.3  0.3 0  1.5" % (*c, args.radius))
    os.makedirs(args.outdir, exist_ok=True)
    base = os.path.join(args.outdir, "crowd_%d" % args.n)
    with open(base + ".toml", "w") as f:
        f.write("\n".join(toml))
    with open(base + ".txt", "w") as f:
        f.write("\n".join(txt) + "\n")


if __name__ == "__main__":
    main()
