"""Minimal PNG reader for the browser test (8-bit RGB/RGBA, non-interlaced: what Chromium writes), with zlib and
numpy only, so the test needs no imaging library."""
import struct
import zlib

import numpy as np


def read_png(path):
    """Returns an H×W×C uint8 array (C = 3 or 4)."""
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError(path + ": not a PNG")
    pos, idat, width = 8, [], None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        pos += 12 + length
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or colour not in (2, 6) or interlace:
                raise ValueError("%s: unsupported PNG (depth %d, colour %d, interlace %d)" % (path, depth, colour, interlace))
            channels = 3 if colour == 2 else 4
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            break
    if width is None:
        raise ValueError(path + ": no IHDR")
    raw = np.frombuffer(zlib.decompress(b"".join(idat)), dtype=np.uint8)
    stride = width * channels
    rows = raw.reshape(height, stride + 1)
    out = np.zeros((height, stride), dtype=np.uint8)
    prev = np.zeros(stride, dtype=np.uint8)
    for y in range(height):
        f, line = rows[y, 0], rows[y, 1:]
        if f == 0:
            cur = line.copy()
        elif f == 1:  # Sub: running sum per channel
            cur = np.cumsum(line.reshape(width, channels).astype(np.uint32), axis=0).astype(np.uint8).ravel()
        elif f == 2:  # Up
            cur = (line.astype(np.uint16) + prev).astype(np.uint8)
        elif f == 3:  # Average: sequential over pixels
            cur = np.zeros(stride, dtype=np.int32)
            lp, pv = line.astype(np.int32), prev.astype(np.int32)
            left = np.zeros(channels, dtype=np.int32)
            for x in range(0, stride, channels):
                left = (lp[x:x + channels] + ((left + pv[x:x + channels]) >> 1)) & 255
                cur[x:x + channels] = left
            cur = cur.astype(np.uint8)
        elif f == 4:  # Paeth: sequential over pixels
            cur = np.zeros(stride, dtype=np.int32)
            lp, pv = line.astype(np.int32), prev.astype(np.int32)
            a = np.zeros(channels, dtype=np.int32)
            c = np.zeros(channels, dtype=np.int32)
            for x in range(0, stride, channels):
                b = pv[x:x + channels]
                p = a + b - c
                pa, pb, pc = np.abs(p - a), np.abs(p - b), np.abs(p - c)
                pred = np.where((pa <= pb) & (pa <= pc), a, np.where(pb <= pc, b, c))
                a = (lp[x:x + channels] + pred) & 255
                cur[x:x + channels] = a
                c = b
            cur = cur.astype(np.uint8)
        else:
            raise ValueError("%s: bad filter %d in row %d" % (path, f, y))
        out[y] = cur
        prev = cur
    return out.reshape(height, width, channels)


def distinct_colours(img):
    rgb = img[..., :3].reshape(-1, 3).astype(np.uint32)
    return len(np.unique((rgb[:, 0] << 16) | (rgb[:, 1] << 8) | rgb[:, 2]))


def non_background_fraction(img, tolerance=8):
    """Fraction of pixels differing from the most common colour (the background) by more than `tolerance`."""
    rgb = img[..., :3].reshape(-1, 3).astype(np.int32)
    keys = (rgb[:, 0] << 16) | (rgb[:, 1] << 8) | rgb[:, 2]
    values, counts = np.unique(keys, return_counts=True)
    bg = values[np.argmax(counts)]
    bgc = np.array([(bg >> 16) & 255, (bg >> 8) & 255, bg & 255])
    return float(np.mean(np.abs(rgb - bgc).max(axis=1) > tolerance))
