"""Shared helpers of the pvpython tests: plugin loading, data lookup, seeds, Dice, hashing."""
import atexit
import hashlib
import os
import shutil
import subprocess
import sys

from paraview import servermanager as sm
from paraview.simple import *  # noqa: F401,F403
from vtkmodules.util.numpy_support import vtk_to_numpy as v2n

import numpy as np

PLUGIN = os.environ["FEATUREMESH_PLUGIN"]
DATA = os.environ["FEATUREMESH_DATA"]
SHARED = os.environ.get("FEATUREMESH_SHARED_DATA", "")
LoadPlugin(PLUGIN, ns=globals())
import paraview.simple as ps  # noqa: E402

SKIP = 77


def case_dir(case):
    """Bundled case folder, else the shared one; exits with the skip code when neither exists."""
    for root in (DATA, os.path.join(SHARED, "cases")):
        d = os.path.join(root, case)
        if os.path.isfile(os.path.join(d, "image.mha")):
            return d
    print("SKIP: case %s not found (bundled Data/ or ../shared/data/cases)" % case)
    sys.exit(SKIP)


def open_case(case):
    d = case_dir(case)
    image = ps.OpenDataFile(os.path.join(d, "image.mha"))
    image.UpdatePipeline()
    truth = ps.OpenDataFile(os.path.join(d, "truth.mha"))
    return d, image, truth


def seeds(path):
    reader = ps.CSVReader(FileName=[path])
    return ps.TableToPoints(Input=reader, XColumn="x", YColumn="y", ZColumn="z")


def array(data, name=None, cells=False):
    attrs = data.GetCellData() if cells else data.GetPointData()
    a = attrs.GetArray(name) if name else attrs.GetScalars()
    assert a is not None, "missing array %s" % name
    return v2n(a)


def fetch(proxy, port=0):
    return sm.Fetch(proxy, idx=port)


def dice(a, b):
    a = np.asarray(a).astype(bool)
    b = np.asarray(b).astype(bool)
    return 2.0 * (a & b).sum() / max(1, a.sum() + b.sum())


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


FAILURES = []


def check(condition, message):
    """Records a check; every failure is reported, and the test exits 1 at the end if any failed."""
    if not condition:
        FAILURES.append(message)
        print("FAIL:", message, flush=True)
        return False
    print("ok:", message, flush=True)
    return True


def finish():
    if FAILURES:
        print("%d check(s) failed:\n  %s" % (len(FAILURES), "\n  ".join(FAILURES)), flush=True)
        os._exit(1)


atexit.register(finish)
