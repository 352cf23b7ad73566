#!/usr/bin/env python3
"""Writes the bad-file corpus of test/data/bad_clouds (committed; rerun to regenerate).

Each file is a cloud a user could hand a tool by mistake; expected.txt lists, for each, a phrase
the tools' one-line error must contain. good.pcd / good.ply are small valid clouds (a floor, two
walls and a box) that the tests register against the bad ones.
"""
import math
import os
import random
import struct

HERE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "bad_clouds")


def scene(n, seed):
    rng = random.Random(seed)
    pts = []
    for i in range(n):
        a, b = rng.random(), rng.random()
        k = i % 4
        if k == 0:
            pts.append((10 * a, 10 * b, 0.0))
        elif k == 1:
            pts.append((10 * a, 0.0, 3 * b))
        elif k == 2:
            pts.append((0.0, 10 * a, 3 * b))
        else:
            pts.append((2 + a, 5 + 1.5 * b, 1.2 * rng.random()))
    return pts


def pcd_header(n, data="binary", fields="x y z", size="4 4 4", typ="F F F", count="1 1 1",
               points=None):
    return (f"# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS {fields}\n"
            f"SIZE {size}\nTYPE {typ}\nCOUNT {count}\nWIDTH {n if points is None else points}\n"
            f"HEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n if points is None else points}\n"
            f"DATA {data}\n").encode()


def binary(pts):
    return b"".join(struct.pack("<fff", *p) for p in pts)


def write(name, data):
    with open(os.path.join(HERE, name), "wb") as f:
        f.write(data)


def main():
    os.makedirs(HERE, exist_ok=True)
    good = scene(2000, 1)
    write("good.pcd", pcd_header(len(good)) + binary(good))
    ply = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(good)}\n"
           "property float x\nproperty float y\nproperty float z\nend_header\n").encode()
    write("good.ply", ply + binary(scene(2000, 2)))

    rng = random.Random(7)
    pts = scene(500, 3)
    write("empty.pcd", b"")
    write("random_bytes.pcd", bytes(rng.randrange(256) for _ in range(4096)))
    write("truncated_header.pcd", pcd_header(500)[:60])
    write("truncated_body.pcd", pcd_header(500) + binary(pts)[: 12 * 100])
    write("lying_count.pcd", pcd_header(500, points=50000000) + binary(pts))
    write("count_over_limit.pcd", pcd_header(500, points=999999999) + binary(pts))
    # binary_compressed: sizes that fit, then bytes that are no LZF stream.
    garbage = bytes(rng.randrange(256) for _ in range(3000))
    write("compressed_garbage.pcd", pcd_header(500, data="binary_compressed")
          + struct.pack("<II", len(garbage), 500 * 12) + garbage)
    write("no_xyz.pcd", pcd_header(500, fields="a b c") + binary(pts))
    write("nan_only.pcd", pcd_header(500) + binary([(math.nan,) * 3] * 500))
    write("huge_coordinates.pcd", pcd_header(500) + binary([(1e30, 1e30, 1e30)] + pts[1:]))
    write("bad_type.pcd", pcd_header(500, typ="F F Q") + binary(pts))
    write("bad_ascii.pcd", pcd_header(3, data="ascii") + b"1 2 3\n4 five 6\n7 8 9\n")
    write("not_ply.ply", b"plx\nformat ascii 1.0\n")
    write("truncated_body.ply", (f"ply\nformat binary_little_endian 1.0\nelement vertex 500\n"
                                 "property float x\nproperty float y\nproperty float z\n"
                                 "end_header\n").encode() + binary(pts)[:600])
    write("lying_count.ply", ("ply\nformat binary_little_endian 1.0\nelement vertex 999999999\n"
                              "property float x\nproperty float y\nproperty float z\n"
                              "end_header\n").encode() + binary(pts))
    write("wrong_extension.xyz", binary(pts))


if __name__ == "__main__":
    main()
