"""featuremesh.names, the Python side's array names, read from Filters/Core/Contract.h: they are
the names the filters write (stage 1's point arrays, stage 2's cell arrays, the cut's label and
element-id arrays, on the bundled nuclei), and the scripts and the package use them."""
import os
import re

import fmtest as ft

N = ft.fm.names
ft.check(len(N.all_names()) >= 80, "names read from Contract.h (%d)" % len(N.all_names()))
case = ft.fm.Case(ft.case_dir("nuclei-dsb2018"))
nodes = case.feature_nodes()
mesh = case.mesh(nodes)
cut = case.super_voxel_cut(mesh, SuperVoxelIds=1)
points = ft.fetch(nodes).GetPointData()
ft.check(all(points.GetArray(a) for a in (N.NodeType, N.Fixed, N.SampleRadius)), "stage 1 writes NodeType, Fixed, SampleRadius")
cells = ft.fetch(mesh).GetCellData()
ft.check(all(cells.GetArray(a) for a in (N.PixelCount, N.MeanIntensity, N.IntensityStdDev, N.Interpolated, N.MinAngle,
                                          N.RadiusRatio)), "stage 2 writes its cell arrays under those names")
ft.check(ft.fetch(cut).GetCellData().GetArray(N.Label) is not None, "the cut writes Label")
ft.check(ft.fetch(cut, 2).GetPointData().GetArray(N.ElementId) is not None, "the label image carries ElementId")
# The package and the scripts name no contract array by a literal.
root = ft.fm.ROOT
literal = re.compile(r'GetArray\("(%s)"\)' % "|".join(re.escape(v) for v in N.all_names().values()))
found = []
for folder in ("scripts/featuremesh", "scripts", "Testing/Python", "Testing/MPI"):
    for name in sorted(os.listdir(os.path.join(root, folder))):
        if name.endswith(".py"):
            with open(os.path.join(root, folder, name)) as f:
                found += ["%s/%s: %s" % (folder, name, m) for m in literal.findall(f.read())]
ft.check(not found, "no GetArray(\"...\") literal of a contract name in the package, the scripts or the tests %s" % found)
# One way to the package: the scripts find it beside them, the tests through ctest's PYTHONPATH.
hacks, needle = [], "sys.path." + "insert"  # not written whole: this file would match
for top in ("scripts", "Testing"):
    for folder, _, files in os.walk(os.path.join(root, top)):
        for name in files:
            if name.endswith(".py"):
                with open(os.path.join(folder, name)) as f:
                    if needle in f.read():
                        hacks.append(os.path.relpath(os.path.join(folder, name), root))
ft.check(not hacks, "no script or test edits sys.path %s" % hacks)
