#!/usr/bin/python3
"""Variants of the 112 shared buildings (issue 24), to see whether a rule holds on data it was not tuned on:
the same scans changed the way other surveys differ from them. Writes NAME.ply (binary, double x y z, float
normals) and NAME_city3d.obj (City3D's model moved the same way) for every scan of ../shared/airborne and
../shared/airborne_more into OUT/KIND, ready for `airborne.py --dir OUT/KIND`.

Kinds:
  sub50  a seeded half of the points (a sparser survey: Vaihingen's 4 points/m² become 2);
  rot    turned 37 degrees about z around the scan's centre and moved to UTM-sized coordinates
         (x + 451234.5, y + 5401234.25): another main direction, large coordinates;
  noise  3 cm of Gaussian noise on every coordinate (normals kept).

    /usr/bin/python3 bench/building/variants.py OUT [--kinds sub50,rot,noise] [--seed 7]
    /usr/bin/python3 bench/building/airborne.py --dir OUT/sub50 --jobs 2 --csv sub50.csv --out sub50.md
"""
import argparse, os, re, sys

import numpy as np

PLY_TYPES = {"float": "f4", "float32": "f4", "double": "f8", "float64": "f8", "uchar": "u1", "uint8": "u1",
             "char": "i1", "int8": "i1", "short": "i2", "int16": "i2", "ushort": "u2", "uint16": "u2",
             "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4"}


def read_ply(path):
    """Points and normals of a binary little-endian PLY with x y z nx ny nz among its vertex properties."""
    with open(path, "rb") as f:
        header = b""
        while not header.endswith(b"end_header\n"):
            line = f.readline()
            if not line:
                sys.exit(f"variants.py: {path}: no end_header")
            header += line
        text = header.decode("ascii", "replace")
        if "binary_little_endian" not in text:
            sys.exit(f"variants.py: {path}: only binary little-endian PLY is read")
        n = int(re.search(r"element vertex (\d+)", text).group(1))
        vertex = text.split("element vertex")[1].split("element")[0]
        props = re.findall(r"property (\w+) (\w+)", vertex)
        dtype = np.dtype([(name, "<" + PLY_TYPES[t]) for t, name in props])
        a = np.frombuffer(f.read(n * dtype.itemsize), dtype, count=n)
    points = np.stack([a["x"], a["y"], a["z"]], 1).astype(float)
    normals = np.stack([a["nx"], a["ny"], a["nz"]], 1).astype(float)
    return points, normals


def write_ply(path, points, normals):
    dtype = np.dtype([("x", "<f8"), ("y", "<f8"), ("z", "<f8"), ("nx", "<f4"), ("ny", "<f4"), ("nz", "<f4")])
    a = np.zeros(len(points), dtype)
    a["x"], a["y"], a["z"] = points.T
    a["nx"], a["ny"], a["nz"] = normals.T
    with open(path, "wb") as f:
        f.write(b"ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty double x\nproperty double y\n"
                b"property double z\nproperty float nx\nproperty float ny\nproperty float nz\nend_header\n" % len(a))
        f.write(a.tobytes())


def variant(kind, points, normals, rng):
    """The changed points and normals, and the map the City3D model's vertices take."""
    if kind == "sub50":
        keep = rng.random(len(points)) < 0.5
        return points[keep], normals[keep], lambda v: v
    if kind == "noise":
        return points + rng.normal(0.0, 0.03, points.shape), normals, lambda v: v
    if kind == "rot":
        a = np.radians(37.0)
        turn = np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]])
        centre = points.mean(0)
        centre[2] = 0.0
        shift = np.array([451234.5, 5401234.25, 0.0])
        move = lambda v: (v - centre) @ turn.T + centre + shift
        return move(points), normals @ turn.T, move
    sys.exit(f"variants.py: unknown kind '{kind}' (sub50, rot, noise)")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    here = os.path.dirname(os.path.abspath(__file__))
    shared = os.path.normpath(os.path.join(here, "..", "..", "..", "shared"))
    ap.add_argument("out")
    ap.add_argument("--kinds", default="sub50,rot,noise")
    ap.add_argument("--seed", type=int, default=7)
    a = ap.parse_args()
    dirs = [os.path.join(shared, d) for d in ("airborne", "airborne_more")]
    scans = [(d, f) for d in dirs if os.path.isdir(d) for f in sorted(os.listdir(d)) if f.endswith(".ply")]
    if not scans:
        sys.exit(f"variants.py: no scans in {dirs}")
    for kind in a.kinds.split(","):
        rng = np.random.default_rng(a.seed)
        out = os.path.join(a.out, kind)
        os.makedirs(out, exist_ok=True)
        for d, f in scans:
            points, normals = read_ply(os.path.join(d, f))
            p, n, move = variant(kind, points, normals, rng)
            write_ply(os.path.join(out, f), p, n)
            lines = []
            with open(os.path.join(d, f[:-4] + "_city3d.obj")) as obj:
                for line in obj:
                    if line.startswith("v "):
                        v = move(np.array([float(x) for x in line.split()[1:4]]))
                        line = "v %.6f %.6f %.6f\n" % tuple(v)
                    lines.append(line)
            with open(os.path.join(out, f[:-4] + "_city3d.obj"), "w") as obj:
                obj.writelines(lines)
        print(f"{out}: {len(scans)} scans")


if __name__ == "__main__":
    main()
