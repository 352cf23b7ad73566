#!/usr/bin/env python3
"""Writes the committed seed corpus of the fuzz harnesses (test/fuzz/corpus); rerun to regenerate."""
import os
import random
import struct

HERE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus")
rng = random.Random(11)


def put(harness, name, data):
    with open(os.path.join(HERE, harness, name), "wb") as f:
        f.write(data)


pts = [(rng.uniform(0, 5), rng.uniform(0, 5), rng.uniform(0, 2)) for _ in range(20)]
body = b"".join(struct.pack("<fff", *p) for p in pts)
head = ("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 20\nHEIGHT 1\n"
        "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS 20\nDATA %s\n")
# The harness reads byte 0 as the format (even: PCD, odd: PLY), the rest as the file.
put("fuzz_cloud_io", "binary.pcd", b"\x00" + (head % "binary").encode() + body)
put("fuzz_cloud_io", "ascii.pcd", b"\x00" + (head % "ascii").encode()
    + "".join("%g %g %g\n" % p for p in pts).encode())
soa = b"".join(struct.pack("<f", p[k]) for k in range(3) for p in pts)
lzf = b"".join(bytes([len(soa[i:i + 32]) - 1]) + soa[i:i + 32] for i in range(0, len(soa), 32))
put("fuzz_cloud_io", "compressed.pcd", b"\x00" + (head % "binary_compressed").encode()
    + struct.pack("<II", len(lzf), len(soa)) + lzf)
ply = ("ply\nformat binary_little_endian 1.0\nelement vertex 20\nproperty float x\n"
       "property float y\nproperty float z\nproperty uchar intensity\nend_header\n").encode()
put("fuzz_cloud_io", "binary.ply", b"\x01" + ply
    + b"".join(struct.pack("<fffB", *p, 7) for p in pts))
put("fuzz_cloud_io", "ascii.ply", b"\x01" + ("ply\nformat ascii 1.0\nelement vertex 3\n"
    "property double x\nproperty double y\nproperty double z\nend_header\n"
    "0 0 0\n1 2 3\n-1 0.5 2\n").encode())

put("fuzz_dataset", "pairs.txt", b"scan001.pcd scan000.pcd 1.2 0.1 0 0 0 0.0998 0.995\n"
    b"# comment\n\nscan002.pcd scan001.pcd 0.9 -0.2 0.01 0.01 0 0.05 0.9986\n")
put("fuzz_dataset", "tum.txt", b"1.0 0 0 0 0 0 0 1\n2.0 1 0 0 0 0 0.7071 0.7071\n")

for k in range(4):
    put("fuzz_cloud_conversion", "random%d" % k, bytes(rng.randrange(256) for _ in range(64 + 200 * k)))
    put("fuzz_registration", "random%d" % k, bytes(rng.randrange(256) for _ in range(200 + 600 * k)))
