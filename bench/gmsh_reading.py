#!/usr/bin/python3
"""Issue 35's reading benchmark: a gmsh mesh of 1,000,000 nodes read by `grip mesh-info`.

Writes a structured grid of 1000 x 1000 nodes (998,001 q4, the bottom as 999 lines in a
physical curve) on the unit square in .msh 4.1 ASCII and binary and 2.2 ASCII and binary into
a temporary folder (nothing is kept), then runs `/usr/bin/time -v grip mesh-info FILE`
`--repeat` times per file and prints a markdown table of file size, wall seconds (fewest, and
the median) and peak resident memory (largest). Goal: under 2 s and under 1 GB.
Usage, from the repository root:
    /usr/bin/python3 bench/gmsh_reading.py [--grip build/apps/grip] [--n 1000] [--repeat 3]
Needs numpy (Debian python3-numpy, with python3-matplotlib)."""
import argparse
import os
import re
import statistics
import subprocess
import tempfile

import numpy as np


def grid(n):
    """Node tags 1..n*n row by row; q4 counter-clockwise; the bottom's lines."""
    i, j = np.meshgrid(np.arange(n), np.arange(n))
    xyz = np.zeros((n * n, 3))
    xyz[:, 0] = (i.ravel() / (n - 1))
    xyz[:, 1] = (j.ravel() / (n - 1))
    tags = np.arange(1, n * n + 1, dtype=np.uint64)
    a = (np.arange(n - 1)[None, :] + n * np.arange(n - 1)[:, None]).ravel() + 1
    quads = np.stack([a, a + 1, a + 1 + n, a + n], axis=1).astype(np.uint64)
    lines = np.stack([np.arange(1, n), np.arange(2, n + 1)], axis=1).astype(np.uint64)
    return tags, xyz, quads, lines


NAMES = b'$PhysicalNames\n2\n1 1 "bottom"\n2 2 "plate"\n$EndPhysicalNames\n'


def ascii_rows(first_columns, values, fmt):
    table = np.column_stack([first_columns, values]) if first_columns is not None else values
    return ("\n".join(fmt % tuple(row) for row in table.tolist()) + "\n").encode()


def write_v41(path, binary, tags, xyz, quads, lines):
    nq, nl = len(quads), len(lines)
    with open(path, "wb") as f:
        f.write(b"$MeshFormat\n4.1 %d 8\n" % binary)
        if binary:
            f.write(np.array([1], dtype="<i4").tobytes() + b"\n")
        f.write(b"$EndMeshFormat\n" + NAMES)
        if binary:
            ent = np.array([0, 1, 1, 0], dtype="<u8").tobytes()
            curve = np.array([1], "<i4").tobytes() + np.zeros(6).tobytes() + np.array([1], "<u8").tobytes() + \
                np.array([1], "<i4").tobytes() + np.array([0], "<u8").tobytes()
            surface = np.array([1], "<i4").tobytes() + np.zeros(6).tobytes() + np.array([1], "<u8").tobytes() + \
                np.array([2], "<i4").tobytes() + np.array([0], "<u8").tobytes()
            f.write(b"$Entities\n" + ent + curve + surface + b"\n$EndEntities\n")
            f.write(b"$Nodes\n" + np.array([1, len(tags), 1, len(tags)], "<u8").tobytes())
            f.write(np.array([2, 1, 0], "<i4").tobytes() + np.array([len(tags)], "<u8").tobytes())
            f.write(tags.astype("<u8").tobytes() + xyz.astype("<f8").tobytes() + b"\n$EndNodes\n")
            f.write(b"$Elements\n" + np.array([2, nq + nl, 1, nq + nl], "<u8").tobytes())
            f.write(np.array([1, 1, 1], "<i4").tobytes() + np.array([nl], "<u8").tobytes())
            f.write(np.column_stack([np.arange(1, nl + 1, dtype=np.uint64), lines]).astype("<u8").tobytes())
            f.write(np.array([2, 1, 3], "<i4").tobytes() + np.array([nq], "<u8").tobytes())
            f.write(np.column_stack([np.arange(nl + 1, nl + nq + 1, dtype=np.uint64), quads]).astype("<u8").tobytes())
            f.write(b"\n$EndElements\n")
        else:
            f.write(b"$Entities\n0 1 1 0\n1 0 0 0 1 0 0 1 1 0\n1 0 0 0 1 1 0 1 2 0\n$EndEntities\n")
            f.write(b"$Nodes\n1 %d 1 %d\n2 1 0 %d\n" % (len(tags), len(tags), len(tags)))
            f.write(ascii_rows(None, tags[:, None], "%d"))
            f.write(ascii_rows(None, xyz, "%.16g %.16g %.16g") + b"$EndNodes\n")
            f.write(b"$Elements\n2 %d 1 %d\n1 1 1 %d\n" % (nq + nl, nq + nl, nl))
            f.write(ascii_rows(np.arange(1, nl + 1), lines, "%d %d %d"))
            f.write(b"2 1 3 %d\n" % nq)
            f.write(ascii_rows(np.arange(nl + 1, nl + nq + 1), quads, "%d %d %d %d %d") + b"$EndElements\n")


def write_v22(path, binary, tags, xyz, quads, lines):
    nq, nl = len(quads), len(lines)
    with open(path, "wb") as f:
        f.write(b"$MeshFormat\n2.2 %d 8\n" % binary)
        if binary:
            f.write(np.array([1], dtype="<i4").tobytes() + b"\n")
        f.write(b"$EndMeshFormat\n" + NAMES + b"$Nodes\n%d\n" % len(tags))
        if binary:
            rec = np.zeros(len(tags), dtype=[("t", "<i4"), ("x", "<f8", 3)])
            rec["t"], rec["x"] = tags, xyz
            f.write(rec.tobytes() + b"\n$EndNodes\n$Elements\n%d\n" % (nq + nl))
            for typ, first, nodes, phys in ((1, 1, lines, 1), (3, nl + 1, quads, 2)):
                f.write(np.array([typ, len(nodes), 2], "<i4").tobytes())
                k = len(nodes)
                f.write(np.column_stack([np.arange(first, first + k), np.full(k, phys), np.ones(k, int),
                                         nodes]).astype("<i4").tobytes())
            f.write(b"\n$EndElements\n")
        else:
            f.write(ascii_rows(tags[:, None], xyz, "%d %.16g %.16g %.16g") + b"$EndNodes\n")
            f.write(b"$Elements\n%d\n" % (nq + nl))
            f.write(ascii_rows(np.arange(1, nl + 1), lines, "%d 1 2 1 1 %d %d"))
            f.write(ascii_rows(np.arange(nl + 1, nl + nq + 1), quads, "%d 3 2 2 1 %d %d %d %d") + b"$EndElements\n")


def run(grip, path):
    out = subprocess.run(["/usr/bin/time", "-v", grip, "mesh-info", path], capture_output=True, text=True, check=True)
    wall = re.search(r"Elapsed \(wall clock\) time \(h:mm:ss or m:ss\): (?:(\d+):)?(\d+):([\d.]+)", out.stderr)
    seconds = 3600 * float(wall.group(1) or 0) + 60 * float(wall.group(2)) + float(wall.group(3))
    rss_kb = int(re.search(r"Maximum resident set size \(kbytes\): (\d+)", out.stderr).group(1))
    return seconds, rss_kb / 1024, out.stdout


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--grip", default="build/apps/grip")
    parser.add_argument("--n", type=int, default=1000, help="nodes along each side")
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    tags, xyz, quads, lines = grid(args.n)
    print("| file | size (MB) | wall s, fewest | wall s, median | peak RSS (MB) |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as folder:
        for version, binary in ((4.1, 0), (4.1, 1), (2.2, 0), (2.2, 1)):
            name = "grid_v%s_%s.msh" % (str(version).replace(".", ""), "binary" if binary else "ascii")
            path = os.path.join(folder, name)
            (write_v41 if version == 4.1 else write_v22)(path, binary, tags, xyz, quads, lines)
            runs = [run(args.grip, path) for _ in range(args.repeat)]
            assert '"nodes": %d' % len(tags) in runs[0][2] and '"q4": %d' % len(quads) in runs[0][2], runs[0][2]
            walls = [r[0] for r in runs]
            print("| %s | %.0f | %.2f | %.2f | %.0f |" % (name, os.path.getsize(path) / 1e6, min(walls),
                                                         statistics.median(walls), max(r[1] for r in runs)))
            os.remove(path)


if __name__ == "__main__":
    main()
