#!/usr/bin/python3
"""Cut an uncompressed LAS file into tiles along plan lines, as a survey is published (issue 40 item 1).

    /usr/bin/python3 bench/city/split_tiles.py IN.las OUTDIR [--x X1,X2,...] [--y Y1,...]

Writes OUTDIR/rRcC.las (row R from the south, column C from the west; a point with x < X1 is in column 0, and
so on) with the input's header, VLRs and EVLRs, its point records in their order, the point counts and the
bounds rewritten (ASPRS LAS 1.4 R15, table 3). Empty tiles are not written. A LAZ file: use its LAS twin.
"""
import argparse
import os
import struct
import sys


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("las")
    ap.add_argument("out")
    ap.add_argument("--x", default="", help="cut lines x = X (file coordinates), comma separated")
    ap.add_argument("--y", default="", help="cut lines y = Y")
    a = ap.parse_args()
    xs = sorted(float(v) for v in a.x.split(",") if v)
    ys = sorted(float(v) for v in a.y.split(",") if v)
    data = open(a.las, "rb").read()
    if data[:4] != b"LASF":
        sys.exit("%s: not a LAS file" % a.las)
    minor = data[25]
    offset_to_points = struct.unpack_from("<I", data, 96)[0]
    fmt = data[104]
    if fmt & 0xC0:
        sys.exit("%s: compressed (LAZ): give its LAS twin" % a.las)
    length = struct.unpack_from("<H", data, 105)[0]
    count = struct.unpack_from("<I", data, 107)[0]
    if minor >= 4 and struct.unpack_from("<Q", data, 247)[0]:
        count = struct.unpack_from("<Q", data, 247)[0]
    scale = struct.unpack_from("<3d", data, 131)
    offset = struct.unpack_from("<3d", data, 155)
    evlr_start = struct.unpack_from("<Q", data, 235)[0] if minor >= 4 else 0
    end = offset_to_points + count * length
    evlrs = data[evlr_start:] if evlr_start else b""
    tiles = {}
    for i in range(count):
        at = offset_to_points + i * length
        x, y, z = struct.unpack_from("<3i", data, at)
        gx, gy, gz = (x * scale[0] + offset[0], y * scale[1] + offset[1], z * scale[2] + offset[2])
        key = (sum(gy >= c for c in ys), sum(gx >= c for c in xs))
        tiles.setdefault(key, []).append((at, gx, gy, gz))
    os.makedirs(a.out, exist_ok=True)
    for (r, c), recs in sorted(tiles.items()):
        header = bytearray(data[:offset_to_points])
        n = len(recs)
        struct.pack_into("<I", header, 107, n if (fmt & 0x3F) < 6 and n < 2**32 else 0)
        for k in range(5):  # points by return (legacy)
            struct.pack_into("<I", header, 111 + 4 * k, 0)
        lo = [min(p[k + 1] for p in recs) for k in range(3)]
        hi = [max(p[k + 1] for p in recs) for k in range(3)]
        struct.pack_into("<6d", header, 179, hi[0], lo[0], hi[1], lo[1], hi[2], lo[2])
        if minor >= 4:
            struct.pack_into("<Q", header, 247, n)
            struct.pack_into("<Q", header, 235, (offset_to_points + n * length) if evlrs else 0)
        body = b"".join(data[at:at + length] for at, _, _, _ in recs)
        path = os.path.join(a.out, "r%dc%d.las" % (r, c))
        with open(path + ".part", "wb") as f:
            f.write(bytes(header) + body + evlrs)
        os.replace(path + ".part", path)
        print("%s: %d points" % (path, n), file=sys.stderr)
    if end > len(data):
        sys.exit("%s: truncated" % a.las)


if __name__ == "__main__":
    main()
