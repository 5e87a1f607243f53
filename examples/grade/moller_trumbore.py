#!/usr/bin/python3
# Textbook Moller-Trumbore (Moller & Trumbore 1997, "Fast, minimum storage
# ray-triangle intersection", with the paper's EPSILON) in numpy, for `rayaudit audit --grade`.
#
#   rayaudit audit --export-cases cases.csv --families edge,vertex,closed-mesh
#   /usr/bin/python3 moller_trumbore.py cases.csv answers.csv
#   rayaudit audit --grade answers.csv --cases cases.csv --json graded.json
#
# Reads the exported cases (id, ox..cz as C99 hex floats), writes one row per
# case: id,hit,t (t as a hex float, exact). Vectorised over every case at once.
import sys

import numpy as np

EPSILON = 0.000001  # the paper's


def read_cases(path):
    with open(path) as f:
        header = f.readline()
        while header.startswith("#"):  # the export's stamp: version, seed, rays, precision, families
            header = f.readline()
        header = header.strip().split(",")
        col = {name: i for i, name in enumerate(header)}
        ids, rows = [], []
        for line in f:
            if not line.strip():
                continue
            fields = line.rstrip("\r\n").split(",")
            ids.append(fields[col["id"]])
            rows.append([float.fromhex(fields[col[c]]) for c in
                         ("ox", "oy", "oz", "dx", "dy", "dz", "ax", "ay", "az",
                          "bx", "by", "bz", "cx", "cy", "cz")])
    return ids, np.array(rows, dtype=np.float64).reshape(-1, 15)


def moller_trumbore(orig, dir, v0, v1, v2):
    """The paper's non-culling branch: (hit, t) per row."""
    edge1 = v1 - v0
    edge2 = v2 - v0
    pvec = np.cross(dir, edge2)
    det = np.einsum("ij,ij->i", edge1, pvec)
    with np.errstate(divide="ignore", invalid="ignore"):
        inv_det = 1.0 / det
        tvec = orig - v0
        u = np.einsum("ij,ij->i", tvec, pvec) * inv_det
        qvec = np.cross(tvec, edge1)
        v = np.einsum("ij,ij->i", dir, qvec) * inv_det
        t = np.einsum("ij,ij->i", edge2, qvec) * inv_det
    hit = (np.abs(det) >= EPSILON) & (u >= 0) & (u <= 1) & (v >= 0) & (u + v <= 1) & (t >= 0)
    return hit, t


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: moller_trumbore.py CASES.csv ANSWERS.csv")
    ids, c = read_cases(sys.argv[1])
    hit, t = moller_trumbore(c[:, 0:3], c[:, 3:6], c[:, 6:9], c[:, 9:12], c[:, 12:15])
    with open(sys.argv[2], "w") as out:
        out.write("id,hit,t\n")
        for i, h, tt in zip(ids, hit, t):
            out.write(f"{i},{'true' if h else 'false'},{float(tt).hex() if h else ''}\n")


if __name__ == "__main__":
    main()
