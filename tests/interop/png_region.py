#!/usr/bin/env python3
"""The mean colour of a rectangle of a PNG (8-bit RGB or RGBA, not interlaced), for the tests that look at a
screenshot: `png_region.py FILE X0 Y0 X1 Y1` prints "R G B" (0..255, the mean over [X0, X1) x [Y0, Y1)).
Only the standard library: PNG's chunks, zlib and its five row filters are decoded here."""
import struct
import sys
import zlib


def rows(path):
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise SystemExit(f"{path}: not a PNG")
    at, idat, width, height, channels = 8, b"", 0, 0, 0
    while at < len(data):
        n, kind = struct.unpack(">I4s", data[at:at + 8])
        body = data[at + 8:at + 8 + n]
        at += 12 + n
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or colour not in (2, 6) or interlace:
                raise SystemExit(f"{path}: only 8-bit RGB/RGBA without interlace (depth {depth}, colour {colour})")
            channels = 3 if colour == 2 else 4
        elif kind == b"IDAT":
            idat += body
    raw = zlib.decompress(idat)
    stride = width * channels
    prev = bytearray(stride)
    out = []
    for y in range(height):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - channels] if i >= channels else 0
            b = prev[i]
            c = prev[i - channels] if i >= channels else 0
            if f == 1:
                line[i] = (line[i] + a) & 0xFF
            elif f == 2:
                line[i] = (line[i] + b) & 0xFF
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 0xFF
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 0xFF
        out.append(line)
        prev = line
    return out, width, height, channels


def main():
    if len(sys.argv) != 6:
        raise SystemExit("usage: png_region.py FILE X0 Y0 X1 Y1")
    image, width, height, channels = rows(sys.argv[1])
    x0, y0, x1, y1 = (int(v) for v in sys.argv[2:])
    x1, y1 = min(x1, width), min(y1, height)
    total, n = [0, 0, 0], 0
    for y in range(y0, y1):
        for x in range(x0, x1):
            for k in range(3):
                total[k] += image[y][x * channels + k]
            n += 1
    if n == 0:
        raise SystemExit("empty region")
    print(" ".join(str(round(t / n)) for t in total))


if __name__ == "__main__":
    main()
