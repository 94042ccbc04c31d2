"""Stage 3 on real data (nuclei, liver): a valid, exactly summarised mesh of better quality, Fixed
nodes in place, box nodes on their faces, the same output across runs and thread counts; on
BraTS-0005 (shared data, else skipped) the second refinement run that keeps the dihedral bound; the
liver with every fourth slice (12 mm) and resampled to 1.5 mm slices keep the 3D bounds."""
import os
import sys

import numpy as np

import fmtest as ft
from vtkmodules.util.numpy_support import numpy_to_vtk
from vtkmodules.vtkCommonDataModel import vtkImageData
from vtkmodules.vtkIOImage import vtkMetaImageWriter
from featuremesh import metrics

CASES = ("nuclei-dsb2018", "liver-ct-totalseg")
rng = np.random.default_rng(5)


def smoothed(case):
    d, image, truth = ft.open_case(case)
    nodes = ft.FeatureNodes(Input=image)
    mesh = ft.DelaunayImageMesh(Nodes=nodes, Image=image)
    out = ft.ImageMeshSmoothing(Mesh=mesh, Image=image)
    out.UpdatePipeline()
    return image, ft.fetch(mesh), ft.fetch(out)


def cells(ug):
    return ft.v2n(ug.GetCells().GetConnectivityArray()).reshape(ug.GetNumberOfCells(), -1)


if len(sys.argv) > 1:  # child run for the thread-count check: a digest of the output
    _, _, ug = smoothed(sys.argv[1])
    print(ft.digest(ft.v2n(ug.GetPoints().GetData()), cells(ug), ft.array(ug, ft.names.MeanIntensity, cells=True)))
    sys.exit(0)

for case in CASES:
    image, before, ug = smoothed(case)
    im = ft.fetch(image)
    dims = np.array(im.GetDimensions())
    sp = np.array(im.GetSpacing())
    k = 2 if dims[2] == 1 else 3
    P, C = ft.v2n(ug.GetPoints().GetData()), cells(ug)
    P0, C0 = ft.v2n(before.GetPoints().GetData()), cells(before)
    n0 = len(P0)
    # Validity: positive measure, tiling the box, every voxel once.
    a, b = P[C[:, 1]] - P[C[:, 0]], P[C[:, 2]] - P[C[:, 0]]
    m = 0.5 * (a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]) if k == 2 else np.einsum("ij,ij->i", a, np.cross(b, P[C[:, 3]] - P[C[:, 0]])) / 6.0
    box = np.prod((dims - 1)[:k] * sp[:k])
    ft.check(m.min() > 0, "%s: no inverted or zero-measure element (min %.3g)" % (case, m.min()))
    ft.check(abs(m.sum() - box) <= 1e-9 * box, "%s: measures sum to the box (rel. err %.1e)" % (case, abs(m.sum() - box) / box))
    pc = ft.array(ug, ft.names.PixelCount, cells=True)
    ft.check(pc.sum() == np.prod(dims), "%s: PixelCount sums to the %d voxels" % (case, np.prod(dims)))
    values = ft.array(im).astype(float).reshape(dims[::-1])
    checked = ft.brute_force_statistics(P, C, values, dims, sp, pc, ft.array(ug, ft.names.MeanIntensity, cells=True),
                                        rng.choice(len(C), 400, replace=False))
    ft.check(checked >= 50, "%s: MeanIntensity and PixelCount match brute force on %d moved elements" % (case, checked))
    # Which nodes moved.
    fixed = ft.array(before, ft.names.Fixed).astype(bool)
    I0, I = P0 / sp, P[:n0] / sp
    # 3D: nodes within 1.5 voxels of the box move onto it before refinement (SnappedNodes).
    near_box = ((I0[:, :k] > 1e-9) & (I0[:, :k] <= 1.5)) | ((I0[:, :k] < dims[:k] - 1 - 1e-9) & (I0[:, :k] >= dims[:k] - 2.5))
    snappable = near_box.any(1) if k == 3 else np.zeros(n0, bool)
    ft.check(np.array_equal(P[:n0][fixed & ~snappable], P0[fixed & ~snappable]),
             "%s: the %d Fixed nodes away from the box did not move" % (case, (fixed & ~snappable).sum()))
    snapped = fixed & snappable & (np.abs(P[:n0] - P0) > 0).any(1)
    landed = ((np.abs(I[snapped][:, :k]) < 1e-9) | (np.abs(I[snapped][:, :k] - (dims[:k] - 1)) < 1e-9)).any(1)
    ft.check(landed.all() and (np.abs(I[snapped] - I0[snapped]) <= 1.5 + 1e-9).all(),
             "%s: the %d Fixed nodes that moved moved onto the box, by at most 1.5 voxels" % (case, snapped.sum()))
    if k == 3:
        fd = ug.GetFieldData()
        ft.check(fd.GetArray(ft.names.SliverFlips).GetValue(0) > 0 and fd.GetArray(ft.names.RefinementRuns).GetValue(0) == 1,
                 "%s: %d sliver flips, one refinement run" % (case, fd.GetArray(ft.names.SliverFlips).GetValue(0)))
        ft.check(ug.GetFieldData().GetArray(ft.names.SnappedNodes).GetValue(0) >= snapped.sum() > 0,
                 "%s: SnappedNodes counts them (%d)" % (case, ug.GetFieldData().GetArray(ft.names.SnappedNodes).GetValue(0)))
    on_face = (np.abs(I0) < 1e-9) | (np.abs(I0 - (dims - 1)) < 1e-9)
    on_face[:, k:] = False
    ft.check(np.array_equal(I[on_face], I0[on_face]), "%s: box nodes stay on their faces (%d coordinates)" % (case, on_face.sum()))
    moved = (np.abs(P[:n0] - P0) > 0).any(1)
    ft.check(moved[~fixed].mean() > 0.5, "%s: %.0f %% of the free nodes moved" % (case, 100 * moved[~fixed].mean()))
    ft.check(((I >= -1e-9) & (I <= dims - 1 + 1e-9)).all(), "%s: every node inside the image box" % case)
    # Arrays: node arrays of the input nodes pass through, added nodes are NodeType 4, free.
    types, fx = ft.array(ug, ft.names.NodeType), ft.array(ug, ft.names.Fixed)
    ft.check(np.array_equal(types[:n0], ft.array(before, ft.names.NodeType)) and (types[n0:] == 4).all() and (fx[n0:] == 0).all(),
             "%s: node arrays pass through; %d added nodes are NodeType 4, free" % (case, len(P) - n0))
    ft.check(len(P) - n0 <= 0.15 * n0, "%s: %.1f %% nodes added (<= 15 %%)" % (case, 100.0 * (len(P) - n0) / n0))
    # Quality: strictly better minimum, and the goals: 2D 20 deg and 140 deg; 3D 10 deg and 165 deg
    # (the liver's worst stood against the box before its nearby nodes moved onto it).
    q0, q1 = metrics.mesh_quality(P0, C0), metrics.mesh_quality(P, C)
    name = ft.names.MinAngle if k == 2 else ft.names.MinDihedralAngle
    ft.check(q1["min"] > q0["min"], "%s: minimum angle %.2f -> %.2f deg" % (case, q0["min"], q1["min"]))
    ft.check(abs(ft.array(ug, name, cells=True).min() - q1["min"]) < 1e-6, "%s: the %s array agrees" % (case, name))
    fd = ug.GetFieldData()
    ft.check(abs(fd.GetArray(name + "Before").GetValue(0) - q0["min"]) < 1e-6, "%s: %sBefore records the input's" % (case, name))
    if k == 2:
        ft.check(q1["min"] >= 20.0 - 1e-9 and q1["max"] <= 140.0, "%s: 2D angles in [%.2f, %.2f] (goal >= 20, <= 140)" % (case, q1["min"], q1["max"]))
    else:
        ft.check(q1["min"] >= 10.0 and q1["max"] <= 165.0 and q1["p1"] >= 20.0,
                 "%s: 3D dihedral min %.2f (goal >= 10), 1st pct %.2f (goal >= 20), max %.2f (goal <= 165)" % (case, q1["min"], q1["p1"], q1["max"]))
    # Determinism: another run in this process, and 1 thread against 2.
    _, _, again = smoothed(case)
    digest = ft.digest(P, C, ft.array(ug, ft.names.MeanIntensity, cells=True))
    ft.check(digest == ft.digest(ft.v2n(again.GetPoints().GetData()), cells(again), ft.array(again, ft.names.MeanIntensity, cells=True)),
             "%s: identical across two runs" % case)
    one = ft.run_script_with_backend(__file__, "Sequential", case)
    two = ft.run_script_with_backend(__file__, "STDThread", case)
    ft.check(one == two == digest, "%s: identical with 1 thread (Sequential) and 2 threads (STDThread)" % case)

# The last resort (docs/smoothing.md): at 4 sweeps TetGen's optimisation leaves a tetrahedron of
# four Canny nodes at 8.7 degrees on BraTS-0005 that no flip improves; its vertices, fixed ones
# included, take perturbation's steps and the bound holds without a second refinement run.
case = "brain-tumour-brats-0005"
if ft.fm.case_dir(case) is None:
    print("SKIP %s: not found (bundled Data/ or ../shared/data/cases)" % case)
else:
    d, image, truth = ft.open_case(case)
    out = ft.ImageMeshSmoothing(Mesh=ft.DelaunayImageMesh(Nodes=ft.FeatureNodes(Input=image), Image=image), Image=image, Iterations=4)
    out.UpdatePipeline()
    ug = ft.fetch(out)
    q = metrics.mesh_quality(ft.v2n(ug.GetPoints().GetData()), cells(ug))
    runs = ug.GetFieldData().GetArray(ft.names.RefinementRuns).GetValue(0)
    ft.check(runs == 1 and q["min"] >= 10.0, "%s, 4 sweeps: %d refinement run, smallest dihedral %.2f (>= 10)" % (case, runs, q["min"]))

# Thick slices: the bundled liver with every fourth slice (3 x 3 x 12 mm voxels, 8 slices) keeps
# the 3D bounds. With Feature Nodes' lattices in voxels on every axis the box's edges held nodes
# 21 mm apart across the slices and 84 mm along them, and the mesh ended at 5.7 / 166.0 degrees.
d, image, truth = ft.open_case("liver-ct-totalseg")
thick = ft.ps.ExtractSubset(Input=image, SampleRateK=4)
out = ft.ImageMeshSmoothing(Mesh=ft.DelaunayImageMesh(Nodes=ft.FeatureNodes(Input=thick), Image=thick), Image=thick)
out.UpdatePipeline()
ft.check(ft.fetch(thick).GetSpacing()[2] == 12.0, "thick-slice liver: 12 mm slices")
ug = ft.fetch(out)
q = metrics.mesh_quality(ft.v2n(ug.GetPoints().GetData()), cells(ug))
ft.check(q["min"] >= 10.0 and q["max"] <= 165.0,
         "thick-slice liver: dihedral min %.2f (goal >= 10), max %.2f (goal <= 165)" % (q["min"], q["max"]))

# Thin slices: the liver resampled to 1.5 mm across its 3 mm in-plane voxels (59 slices), as a
# volume whose slices are thinner than its pixels (VTK's headsq: 3.2 x 3.2 x 1.5 mm). With the
# Canny points thinned in voxels on every axis they stood twice as dense across the slices, and the
# mesh ended with a 1st percentile of 18.3 degrees and 18.5 % nodes added. n0 is the cubic liver's
# node count (the last case above).
liver = ft.fetch(image)
values = ft.v2n(liver.GetPointData().GetScalars()).reshape(liver.GetDimensions()[::-1]).astype(np.float64)
between = np.rint(0.5 * (values[:-1] + values[1:]))  # linear interpolation halfway, as ITK would resample
fine = np.empty((2 * values.shape[0] - 1,) + values.shape[1:])
fine[0::2], fine[1::2] = values, between
path = os.path.join(ft.scratch("featuremesh-thin-"), "liver_thin.mha")
grid = vtkImageData()
grid.SetDimensions(fine.shape[2], fine.shape[1], fine.shape[0])
grid.SetOrigin(liver.GetOrigin())
grid.SetSpacing(np.array(liver.GetSpacing()) / [1, 1, 2])
grid.GetPointData().SetScalars(numpy_to_vtk(fine.astype(np.int16).ravel(), deep=1))
writer = vtkMetaImageWriter()
writer.SetFileName(path)
writer.SetInputData(grid)
writer.Write()
thin = ft.ps.OpenDataFile(path)
thin.UpdatePipeline()
ft.check(abs(ft.fetch(thin).GetSpacing()[2] - 1.5) < 1e-9, "thin-slice liver: 1.5 mm slices")
out = ft.ImageMeshSmoothing(Mesh=ft.DelaunayImageMesh(Nodes=ft.FeatureNodes(Input=thin), Image=thin), Image=thin)
out.UpdatePipeline()
ug = ft.fetch(out)
q = metrics.mesh_quality(ft.v2n(ug.GetPoints().GetData()), cells(ug))
added = 100.0 * ug.GetFieldData().GetArray(ft.names.AddedNodes).GetValue(0) / (ug.GetNumberOfPoints() - ug.GetFieldData().GetArray(ft.names.AddedNodes).GetValue(0))
ft.check(q["min"] >= 10.0 and q["max"] <= 165.0 and q["p1"] >= 20.0,
         "thin-slice liver: dihedral min %.2f (goal >= 10), max %.2f (<= 165), 1st percentile %.2f (>= 20)" % (
             q["min"], q["max"], q["p1"]))
ft.check(added <= 15.0, "thin-slice liver: %.1f %% nodes added (goal <= 15)" % added)
# The same anatomy gets about the same mesh: with halftone points placed on the voxel grid the thin
# liver had 1.70 times the cubic liver's nodes.
stage1 = ug.GetNumberOfPoints() - int(ug.GetFieldData().GetArray(ft.names.AddedNodes).GetValue(0))
ft.check(stage1 <= 1.25 * n0, "thin-slice liver: %d nodes from stage 1, %.2f times the cubic liver's %d (<= 1.25)" % (
    stage1, stage1 / n0, n0))
