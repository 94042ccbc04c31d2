"""Helpers of the pvpython tests on top of the featuremesh package: skip codes, checks, hashing."""
import atexit
import hashlib
import os
import shutil
import subprocess
import sys
import tempfile

import featuremesh as fm
from featuremesh import dice, fetch, names, np, seeds, v2n  # noqa: F401

from paraview.simple import *  # noqa: F401,F403
import paraview.simple as ps

fm.load_plugin(ns=globals())

PLUGIN, DATA, SHARED = fm.find_plugin(), fm.DATA, fm.SHARED
SKIP = 77


def case_dir(case):
    """Bundled case folder, else the shared one; exits with the skip code when neither exists."""
    d = fm.case_dir(case)
    if d is None:
        print("SKIP: case %s not found (bundled Data/ or ../shared/data/cases)" % case)
        sys.exit(SKIP)
    return d


def open_case(case):
    d = case_dir(case)
    image = ps.OpenDataFile(os.path.join(d, "image.mha"))
    image.UpdatePipeline()
    truth = ps.OpenDataFile(os.path.join(d, "truth.mha"))
    return d, image, truth


def array(data, name=None, cells=False):
    attrs = data.GetCellData() if cells else data.GetPointData()
    a = attrs.GetArray(name) if name else attrs.GetScalars()
    assert a is not None, "missing array %s" % name
    return v2n(a)


def digest(*arrays):
    h = hashlib.sha256()
    for a in arrays:
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()


def run_script_with_backend(script, backend, *args):
    """Runs a pvpython script with the given SMP backend; returns its last stdout line."""
    env = dict(os.environ, VTK_SMP_BACKEND_IN_USE=backend)
    out = subprocess.run([shutil.which("pvpython"), script] + list(args), env=env, capture_output=True, text=True, check=True)
    return out.stdout.strip().splitlines()[-1]


def exact_barycentric(X, p):
    """Barycentric coordinates of point p in the simplex X (rows: vertices), as exact rationals of the doubles."""
    from fractions import Fraction
    V = [[Fraction(float(v)) for v in x] for x in X]
    q = [Fraction(float(v)) for v in p]
    if len(V) == 3:
        def area(a, b, c):
            return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        whole = area(*V)
        return [area(q, V[1], V[2]) / whole, area(V[0], q, V[2]) / whole, area(V[0], V[1], q) / whole]

    def volume(a, b, c, d):
        u = [b[i] - a[i] for i in range(3)]
        v = [c[i] - a[i] for i in range(3)]
        w = [d[i] - a[i] for i in range(3)]
        return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) + u[2] * (v[0] * w[1] - v[1] * w[0])
    whole = volume(*V)
    return [volume(q, V[1], V[2], V[3]) / whole, volume(V[0], q, V[2], V[3]) / whole,
            volume(V[0], V[1], q, V[3]) / whole, volume(V[0], V[1], V[2], q) / whole]


def brute_force_statistics(P, C, values, dims, sp, pc, mean, elements):
    """Checks MeanIntensity and PixelCount of `elements` against the voxel centres they contain
    (barycentric test; a centre on an element's boundary belongs to it when a tiny step towards
    the box centre moves it inside, the filters' tie rule); elements with an undecidable centre are
    skipped: one the step leaves on a face, or one a hair (below 1e-12, exact rationals of the
    coordinates) from a face, which the filters decide exactly and a float test cannot. Asserts on
    a mismatch; returns how many elements were checked."""
    checked = 0
    k = 2 if dims[2] == 1 else 3
    centre = (np.array(dims) - 1) / 2.0
    for e in elements:
        X = P[C[e]] / sp
        lo, hi = np.ceil(X.min(0) - 1e-9).astype(int), np.floor(X.max(0) + 1e-9).astype(int)
        grid = np.stack(np.meshgrid(*[np.arange(lo[a], hi[a] + 1) for a in range(3)], indexing="ij"), -1).reshape(-1, 3)
        T = (X[1:, :k] - X[0, :k]).T
        bary = np.linalg.solve(T, (grid[:, :k] - X[0, :k]).T).T
        bary = np.column_stack([1 - bary.sum(1), bary])
        inside = (bary > 1e-9).all(1)
        touching = (bary > -1e-9).all(1) & ~inside
        q = grid[touching] + 1e-6 * (centre - grid[touching])
        bq = np.linalg.solve(T, (q[:, :k] - X[0, :k]).T).T
        bq = np.column_stack([1 - bq.sum(1), bq])
        if (np.abs(bq) < 1e-10).any() or any(0 < abs(b) < 1e-12 for c in grid[touching] for b in exact_barycentric(X[:, :k], c[:k])):
            continue
        owned = inside.copy()
        owned[np.flatnonzero(touching)] = (bq > 0).all(1)
        if not owned.any():
            continue
        g = grid[owned]
        brute = values[g[:, 2], g[:, 1], g[:, 0]].mean()
        assert abs(brute - mean[e]) <= 1e-9 * max(1.0, abs(brute)), (e, brute, mean[e])
        assert pc[e] == owned.sum(), (e, pc[e], owned.sum())
        checked += 1
    return checked


FAILURES = []


def check(condition, message):
    """Records a check; every failure is reported, and the test exits 1 at the end if any failed."""
    if not condition:
        FAILURES.append(message)
        print("FAIL:", message, flush=True)
        return False
    print("ok:", message, flush=True)
    return True


def finish(what=None):
    """Exits 1 after listing the failed checks; else, with `what`, says that all of them passed."""
    if FAILURES:
        print("%d check(s) failed:\n  %s" % (len(FAILURES), "\n  ".join(FAILURES)), flush=True)
        os._exit(1)
    if what:
        print("all %s checks passed" % what, flush=True)


atexit.register(finish)

_RAISED = []


def _excepthook(kind, value, trace):
    _RAISED.append(kind)
    sys.__excepthook__(kind, value, trace)


sys.excepthook = _excepthook


def scratch(prefix="featuremesh-test-"):
    """A new temporary folder for a test's files. It is removed when the test passes and kept (its
    path printed) when a check fails, an exception escapes, or FEATUREMESH_KEEP_SCRATCH is set."""
    folder = tempfile.mkdtemp(prefix=prefix)

    def remove():
        if FAILURES or _RAISED or os.environ.get("FEATUREMESH_KEEP_SCRATCH"):
            print("kept", folder, flush=True)
        else:
            shutil.rmtree(folder, ignore_errors=True)

    atexit.register(remove)
    return folder
