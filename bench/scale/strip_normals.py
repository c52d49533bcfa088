#!/usr/bin/python3
"""strip_normals.py IN.ply OUT.ply — a raw scan from a synthetic one: drops the normals of a binary
little-endian PLY written by `hsr synth` (vertex properties double x y z [nx ny nz]), keeps x y z."""
import sys
import numpy as np


def main():
    src, dst = sys.argv[1], sys.argv[2]
    with open(src, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    count = next(int(l.split()[2]) for l in header if l.startswith("element vertex"))
    props = [l.split()[2] for l in header if l.startswith("property double")]
    if "binary_little_endian" not in header[1] or props[:3] != ["x", "y", "z"]:
        sys.exit("strip_normals.py: expected a binary little-endian PLY of doubles x y z ...")
    body = np.frombuffer(data, dtype="<f8", count=count * len(props), offset=end).reshape(count, len(props))
    xyz = np.ascontiguousarray(body[:, :3])
    out_header = ("ply\nformat binary_little_endian 1.0\ncomment normals removed by strip_normals.py\n"
                  "element vertex %d\nproperty double x\nproperty double y\nproperty double z\nend_header\n" % count)
    with open(dst, "wb") as f:
        f.write(out_header.encode("ascii"))
        f.write(xyz.tobytes())


if __name__ == "__main__":
    main()
