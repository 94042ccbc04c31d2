"""The Abaqus deck loads and solves in CalculiX (Debian's calculix-ccx, the free solver that reads
Abaqus input): a steady heat problem over every element set of the bundled liver's and abdomen's
labelled meshes after stage 6, 0 on the box side z min and 100 on z max. Every node gets a
temperature within the boundary values, and the two sides keep theirs."""
import os
import re
import shutil
import subprocess

import fmtest as ft
from featuremesh import fem

np = ft.np
ccx = shutil.which("ccx")
if ccx is None:
    print("SKIP: CalculiX (ccx) is not installed; scripts/setup.sh installs calculix-ccx")
    raise SystemExit(ft.SKIP)


def labelled_meshes():
    liver = ft.fm.Case(ft.case_dir("liver-ct-totalseg"))
    _, mesh, _ = liver.pipeline()
    cut = liver.super_voxel_cut(liver.smoothing(mesh))
    yield "liver", ft.fetch(ft.ps.SegmentationSurfaceSmoothing(LabelledMesh=ft.ps.OutputPort(cut, 0)), 1)
    abdomen = ft.fm.MultiLabelCase(ft.fm.multilabel_cases()["abdomen-ct-totalseg"])
    cut = abdomen.super_voxel_cut(abdomen.mesh())
    yield "abdomen", ft.fetch(ft.ps.SegmentationSurfaceSmoothing(LabelledMesh=ft.ps.OutputPort(cut, 0)), 1)


out = ft.scratch("featuremesh-calculix-")
for name, grid in labelled_meshes():
    points, cells, labels = fem.grid_arrays(grid)
    mesh_file = fem.write(grid, os.path.join(out, name), formats=("abaqus",))["abaqus"]
    regions = fem.label_names(grid, labels)
    deck = ["*INCLUDE, INPUT=%s" % os.path.basename(mesh_file), "*NSET, NSET=EVERY, GENERATE", "1, %d, 1" % len(points),
            "*MATERIAL, NAME=TISSUE", "*CONDUCTIVITY", "1.0"]
    deck += ["*SOLID SECTION, ELSET=%s, MATERIAL=TISSUE" % regions[k] for k in sorted(regions)]
    deck += ["*STEP", "*HEAT TRANSFER, STEADY STATE", "*BOUNDARY", "box_zmin, 11, 11, 0.0", "box_zmax, 11, 11, 100.0",
             "*NODE PRINT, NSET=EVERY", "NT", "*END STEP"]
    with open(os.path.join(out, name + "_heat.inp"), "w") as f:
        f.write("\n".join(deck) + "\n")
    run = subprocess.run([ccx, "-i", name + "_heat"], cwd=out, capture_output=True, text=True, timeout=600)
    solved = run.returncode == 0 and "ERROR" not in run.stdout
    ft.check(solved, "%s: CalculiX solves the deck%s" % (name, "" if solved else " (%s)" % (run.stdout + run.stderr)[-600:]))
    dat = os.path.join(out, name + "_heat.dat")
    values = {}
    if os.path.isfile(dat):
        for line in open(dat):
            m = re.match(r"\s*(\d+)\s+([-+0-9.Ee]+)\s*$", line)
            if m:
                values[int(m.group(1))] = float(m.group(2))
    t = np.array([values.get(i + 1, np.nan) for i in range(len(points))])
    ft.check(np.isfinite(t).all(), "%s: a temperature for each of the %d nodes" % (name, len(points)))
    ft.check(np.nanmin(t) >= -1e-6 and np.nanmax(t) <= 100 + 1e-6,
             "%s: temperatures within the boundary values (%.4g .. %.4g)" % (name, np.nanmin(t), np.nanmax(t)))
    z = points[:, 2]
    ft.check(np.allclose(t[np.isclose(z, z.min())], 0.0) and np.allclose(t[np.isclose(z, z.max())], 100.0),
             "%s: the box sides z min / z max keep 0 / 100" % name)
ft.finish()
