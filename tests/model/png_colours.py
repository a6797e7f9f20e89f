#!/usr/bin/env python3
"""png_colours.py FILE [RRGGBB...]: how many distinct colours an 8-bit RGB(A) PNG holds, and
whether each given colour is among them (within 3 per channel). Exit 0 when the picture has at
least 8 distinct colours and every given colour is present; prints what it found either way."""
import struct
import sys
import zlib


def rows(path):
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    pos, idat, header = 8, b"", None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    width, height, depth, colour_type = header[:4]
    assert depth == 8 and colour_type in (2, 6), "only 8-bit RGB/RGBA"
    bpp = 3 if colour_type == 2 else 4
    raw, stride, previous = zlib.decompress(idat), width * bpp, bytearray(width * bpp)
    for y in range(height):
        start = y * (stride + 1)
        kind, line = raw[start], bytearray(raw[start + 1:start + 1 + stride])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = previous[i], previous[i - bpp] if i >= bpp else 0
            if kind == 1:
                line[i] = (line[i] + a) & 255
            elif kind == 2:
                line[i] = (line[i] + b) & 255
            elif kind == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        previous = line
        yield [tuple(line[x:x + 3]) for x in range(0, stride, bpp)]


def main():
    colours = {}
    for row in rows(sys.argv[1]):
        for pixel in row[::2]:
            colours[pixel] = colours.get(pixel, 0) + 1
    wanted = [tuple(int(h[i:i + 2], 16) for i in (0, 2, 4)) for h in sys.argv[2:]]
    missing = [w for w in wanted if not any(all(abs(p[k] - w[k]) <= 3 for k in range(3)) and n >= 20 for p, n in colours.items())]
    print(f"{len(colours)} distinct colours; missing: {['%02x%02x%02x' % m for m in missing]}")
    sys.exit(0 if len(colours) >= 8 and not missing else 1)


main()
