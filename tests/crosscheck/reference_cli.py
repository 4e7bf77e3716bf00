"""Command-line conventions and text file formats shared by the cross-check reference scripts
(igl_reference.py, peers_reference.py): errors are UsageError (exit code 1 for every error, also for
bad usage), constraints are `index x y z` lines, matrices are written one row per line.

Imported from the scripts' own directory (Python puts a script's directory first on sys.path).
"""

import argparse
import os
import sys

import numpy as np


class UsageError(Exception):
    pass


class ArgumentParser(argparse.ArgumentParser):
    """argparse exits with code 2 on bad usage; these CLIs use 1 for every error."""

    def error(self, message):
        self.print_usage(sys.stderr)
        self.exit(1, f"{self.prog}: error: {message}\n")


def check_file(path, what):
    if not os.path.isfile(path):
        raise UsageError(f"{what} file not found: {path}")


def read_rows(path, ncols, what):
    """Reads whitespace-separated rows of `ncols` numbers, skipping blanks and '#' comments."""
    check_file(path, what)
    rows = []
    with open(path) as fh:
        for lineno, line in enumerate(fh, 1):
            s = line.strip()
            if not s or s.startswith("#"):
                continue
            parts = s.split()
            if len(parts) != ncols:
                raise UsageError(f"{path}:{lineno}: expected {ncols} fields, got {len(parts)}")
            rows.append(parts)
    if not rows:
        raise UsageError(f"{path}: no {what} rows")
    return rows


def check_indices(b, n, path):
    if b.min() < 0 or b.max() >= n:
        raise UsageError(f"{path}: vertex index out of range [0, {n})")
    if len(np.unique(b)) != len(b):
        raise UsageError(f"{path}: duplicate vertex indices")


def read_vector_constraints(path, n):
    """`index x y z` lines -> (b int64 array, bc float64 (#b, 3) array)."""
    rows = read_rows(path, 4, "constraints")
    b = np.array([int(r[0]) for r in rows], dtype=np.int64)
    bc = np.array([[float(x) for x in r[1:]] for r in rows], dtype=np.float64)
    check_indices(b, n, path)
    return b, bc


def write_matrix(path, A, fmt="%.17g"):
    A = np.asarray(A)
    if A.ndim == 1:
        A = A[:, None]
    np.savetxt(path, A, fmt=fmt, delimiter=" ")


def positive_int(s):
    try:
        v = int(s)
    except ValueError:
        raise argparse.ArgumentTypeError(f"not an integer: {s!r}")
    if v <= 0:
        raise argparse.ArgumentTypeError(f"must be positive: {s!r}")
    return v
