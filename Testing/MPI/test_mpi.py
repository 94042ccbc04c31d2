"""Parallel ParaView: `mpirun -np 2 pvbatch` runs the pipeline on the bundled cases and saves
.pvtu / .pvti without a deadlock, with no error on the rank that holds no data, and what it saved
equals the serial labels. Skips (77) when mpirun is absent."""
import os
import shutil
import subprocess
import sys

import fmtest as ft
from vtkmodules.vtkIOXML import vtkXMLPImageDataReader, vtkXMLPUnstructuredGridReader

mpirun, pvbatch = shutil.which("mpirun"), shutil.which("pvbatch")
if not mpirun or not pvbatch:
    print("SKIP: mpirun or pvbatch not found")
    sys.exit(ft.SKIP)
out = ft.scratch("featuremesh-mpi-")
command = [mpirun, "-np", "2"] + (["--allow-run-as-root", "--oversubscribe"] if os.geteuid() == 0 else ["--oversubscribe"]) + [
    pvbatch, os.path.join(os.path.dirname(os.path.abspath(__file__)), "save_pipeline.py"), out]
# pvpython initialised MPI as a singleton: its OMPI_/PMIX_ variables would make mpirun fail.
env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMIX_", "OPAL_", "PRTE_"))}
try:
    run = subprocess.run(command, capture_output=True, text=True, timeout=600, env=env)
    log, status = run.stdout + run.stderr, run.returncode
except subprocess.TimeoutExpired:
    log, status = "timed out after 600 s (a deadlock?)", -1
ft.check(status == 0, "mpirun -np 2 pvbatch saves .pvtu and .pvti and exits (%s)" % (status if status == 0 else "%s: %s" % (status, log[-1500:])))
ft.check("ERR|" not in log and "ERROR" not in log, "no rank reports an error%s" % ("" if "ERR" not in log else ": " + log[-600:]))
for name in ("nuclei-dsb2018", "liver-ct-totalseg"):
    c = ft.fm.Case(ft.case_dir(name))
    nodes, mesh, cut = c.pipeline()
    cut.UpdatePipeline()
    vc = c.voxel_cut()
    vc.UpdatePipeline()
    r = vtkXMLPUnstructuredGridReader()
    r.SetFileName(os.path.join(out, name + "_labelled.pvtu"))
    r.Update()
    saved = r.GetOutput().GetCellData().GetArray(ft.names.Label)
    ft.check(saved is not None and ft.np.array_equal(ft.v2n(saved), ft.array(ft.fetch(cut), ft.names.Label, cells=True)),
             "%s: the parallel run's element labels equal the serial run's" % name)
    r = vtkXMLPUnstructuredGridReader()
    r.SetFileName(os.path.join(out, name + "_fem.pvtu"))
    r.Update()
    serial = ft.fetch(c.surface_smoothing(cut), 1)
    ft.check(r.GetOutput().GetNumberOfPoints() == serial.GetNumberOfPoints() and
             ft.np.array_equal(ft.v2n(r.GetOutput().GetPoints().GetData()), ft.v2n(serial.GetPoints().GetData())),
             "%s: the parallel run's smoothed labelled mesh equals the serial run's" % name)
    for suffix, proxy, port in (("_labels.pvti", cut, 2), ("_voxelcut.pvti", vc, 0)):
        ri = vtkXMLPImageDataReader()
        ri.SetFileName(os.path.join(out, name + suffix))
        ri.Update()
        a = ri.GetOutput().GetPointData().GetScalars()
        ft.check(a is not None and ft.np.array_equal(ft.v2n(a), ft.fm.labels(proxy, port)),
                 "%s: the parallel run's %s equal the serial run's" % (name, suffix[1:-5].replace("_", " ")))
