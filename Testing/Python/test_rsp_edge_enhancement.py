"""Stage 5 on real data: the edge confidence follows the object (EM, nuclei), the final contour of a
BraTS tumour slice is closed and encloses the tumour, outputs are on the input's frame, identical
across runs and thread counts, and feed seed-aware Feature Nodes."""
import os
import sys

import numpy as np
from scipy import ndimage
from vtkmodules.util.numpy_support import numpy_to_vtk
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.vtkCommonDataModel import vtkImageData, vtkPolyData

import fmtest as ft


def ec_ratio(ec, truth):
    """Mean EC within 1 voxel of the reference boundary over the mean EC farther than 5 voxels
    (scripts/benchmark_rsp.py measures the same)."""
    inner = truth & ~ndimage.binary_erosion(truth)
    outer = ndimage.binary_dilation(truth) & ~truth
    d = ndimage.distance_transform_edt(~(inner | outer))
    return ec[d <= 1].mean() / ec[d > 5].mean()


def rsp_of(case, **properties):
    d = ft.case_dir(case)
    image = ft.OpenDataFile(os.path.join(d, "image.mha"))
    rsp = ft.RSPEdgeEnhancement(Input=image, ObjectSeeds=ft.seeds(os.path.join(d, "seeds_object.csv")),
                                BackgroundSeeds=ft.seeds(os.path.join(d, "seeds_background.csv")), **properties)
    rsp.UpdatePipeline()
    return d, image, rsp


if len(sys.argv) > 1:  # child run for the thread-count check
    _, _, rsp = rsp_of(sys.argv[1])
    out = ft.fetch(rsp)
    print(ft.digest(ft.array(out, ft.names.EdgeConfidence), ft.array(out, ft.names.EdgeMap), ft.array(out, ft.names.ContourRegion),
                    ft.v2n(ft.fetch(rsp, 2).GetPoints().GetData())))
    sys.exit(0)

# 1. Outputs on nuclei (bundled): frame, arrays, samples, paths.
d, image, rsp = rsp_of("nuclei-dsb2018")
im, out = ft.fetch(image), ft.fetch(rsp)
shape = im.GetDimensions()[::-1]
ft.check(out.GetDimensions() == im.GetDimensions() and out.GetSpacing() == im.GetSpacing()
         and out.GetOrigin() == im.GetOrigin(), "the EC image has the input's frame")
ec = ft.array(out, ft.names.EdgeConfidence)
ft.check(out.GetPointData().GetScalars().GetName() == ft.names.EdgeConfidence and ec.dtype == np.float32,
         "EdgeConfidence is the active float array")
ft.check(ft.array(out, ft.names.EdgeMap).dtype == np.uint8, "EdgeMap is uint8")
paths = out.GetFieldData().GetArray(ft.names.Paths).GetValue(0)
ft.check(paths == 50 * 100, "50 x 100 paths (%d)" % paths)
roles = ft.array(ft.fetch(rsp, 2), ft.names.SampleRole)
ft.check((roles == 0).sum() == 50 and (roles == 1).sum() == 100, "50 sources and 100 sinks")
contour = ft.fetch(rsp, 1)
ids = ft.v2n(contour.GetLines().GetConnectivityArray())
ft.check(contour.GetNumberOfPoints() > 8 and ids[0] == ids[-1], "the 2D contour is a closed polyline")

# 2. EC follows the object (the goal is 5; asserted 3).
for case in ("em-isbi2012-00", "nuclei-dsb2018"):
    if ft.fm.case_dir(case) is None:
        print("SKIP: %s not found" % case)
        continue
    d, image, r = rsp_of(case)
    truth = ft.v2n(ft.fetch(ft.OpenDataFile(os.path.join(d, "truth.mha"))).GetPointData().GetScalars())
    shape = ft.fetch(image).GetDimensions()[::-1]
    ratio = ec_ratio(ft.array(ft.fetch(r), ft.names.EdgeConfidence).reshape(shape), truth.reshape(shape).astype(bool))
    ft.check(ratio >= 3.0, "%s: EC near the boundary / far from it = %.2f >= 3" % (case, ratio))

# 3. Same output across runs and for Sequential against STDThread.
again = ft.fetch(rsp_of("nuclei-dsb2018")[2])
ft.check(np.array_equal(ft.array(again, ft.names.EdgeConfidence), ec), "identical EC across runs")
digests = {b: ft.run_script_with_backend(__file__, b, "nuclei-dsb2018") for b in ("Sequential", "STDThread")}
ft.check(len(set(digests.values())) == 1, "identical output for Sequential and STDThread: %s" % digests)
other = ft.fetch(rsp_of("nuclei-dsb2018", RandomSeed=7)[2])
ft.check(not np.array_equal(ft.array(other, ft.names.EdgeConfidence), ec), "another RandomSeed draws other paths")

# 4. Seed-aware Feature Nodes on the liver (bundled): fewer nodes than Canny's recipe, denser near the
# edge map than far from it.
d, image, r = rsp_of("liver-ct-totalseg")
canny = ft.FeatureNodes(Input=image)
aware = ft.FeatureNodes(Input=image, EdgeMap=r)
nc, na = ft.fetch(canny), ft.fetch(aware)
ft.check(0 < na.GetNumberOfPoints() < nc.GetNumberOfPoints(),
         "seed-aware nodes %d < Canny's %d" % (na.GetNumberOfPoints(), nc.GetNumberOfPoints()))
li = ft.fetch(image)
shape, sp = li.GetDimensions()[::-1], np.array(li.GetSpacing())
edges = ft.array(ft.fetch(aware, 1)).reshape(shape).astype(bool)
dist = ndimage.distance_transform_edt(~edges)
ijk = np.rint(ft.v2n(na.GetPoints().GetData()) / sp).astype(int)
dn = dist[ijk[:, 2], ijk[:, 1], ijk[:, 0]]
near, far = (dn <= 7).sum() / (dist <= 7).sum(), (dn > 20).sum() / max(1, (dist > 20).sum())
ft.check(near > 3 * far, "node density within 7 voxels of the edges %.4f > 3 x beyond 20 %.4f" % (near, far))
rsp_edges = ft.array(ft.fetch(r), ft.names.EdgeMap).reshape(shape).astype(bool)
ft.check((edges | ~rsp_edges).all(), "every RSP edge voxel is an edge of the seed-aware recipe")

# 5. BraTS-0006, its largest tumour slice as a 2D case; seeds drawn as the shared seeds (fixed
# generator: 5 in the eroded tumour, 10 in a band around it). The final contour must enclose the
# tumour: Dice of its region >= 0.8 (median of three draws), and it must be closed.
d = ft.fm.case_dir("brain-tumour-brats-0006")
if d is None:
    print("SKIP: brain-tumour-brats-0006 not found")
    sys.exit(0)
vol_proxy = ft.OpenDataFile(os.path.join(d, "image.mha"))
vol = ft.fetch(vol_proxy)
dims = vol.GetDimensions()[::-1]
V = ft.v2n(vol.GetPointData().GetScalars()).reshape(dims)
T = ft.v2n(ft.fetch(ft.OpenDataFile(os.path.join(d, "truth.mha"))).GetPointData().GetScalars()).reshape(dims).astype(bool)
z = int(np.argmax(T.sum(axis=(1, 2))))
image2, truth2 = np.ascontiguousarray(V[z]), T[z]
slice_image = vtkImageData()
slice_image.SetDimensions(dims[2], dims[1], 1)
slice_image.SetSpacing(vol.GetSpacing())
values = numpy_to_vtk(image2.ravel().astype(np.float32), deep=1)
values.SetName("flair")
slice_image.GetPointData().SetScalars(values)
source = ft.TrivialProducer()
source.GetClientSideObject().SetOutput(slice_image)


def point_source(ji):
    p = vtkPoints()
    for j, i in ji:
        p.InsertNextPoint(i * vol.GetSpacing()[0], j * vol.GetSpacing()[1], 0.0)
    pd = vtkPolyData()
    pd.SetPoints(p)
    producer = ft.TrivialProducer()
    producer.GetClientSideObject().SetOutput(pd)
    return producer


inside = np.argwhere(ndimage.binary_erosion(truth2, iterations=3))
band = np.argwhere(ndimage.binary_dilation(truth2, iterations=10) & ~ndimage.binary_dilation(truth2, iterations=3))
scores = []
for draw in range(3):
    rng = np.random.default_rng(draw)
    obj = inside[rng.choice(len(inside), 5, replace=False)]
    bg = band[rng.choice(len(band), 10, replace=False)]
    r = ft.RSPEdgeEnhancement(Input=source, ObjectSeeds=point_source(obj), BackgroundSeeds=point_source(bg))
    r.UpdatePipeline()
    region = ft.array(ft.fetch(r), ft.names.ContourRegion).reshape(truth2.shape)
    c = ft.fetch(r, 1)
    P = np.rint(ft.v2n(c.GetPoints().GetData())[:, :2] / np.array(vol.GetSpacing()[:2])).astype(int)
    steps = np.abs(np.diff(np.vstack([P, P[:1]]), axis=0)).sum(1)
    ft.check(len(P) > 20 and (steps == 1).all(), "draw %d: the contour is closed, 4-connected (%d points)" % (draw, len(P)))
    scores.append(ft.dice(region, truth2))
    print("draw %d: region Dice %.3f" % (draw, scores[-1]))
ft.check(np.median(scores) >= 0.8 and min(scores) >= 0.7,
         "BraTS-0006 slice %d: contour region Dice %s, median >= 0.8" % (z, ["%.3f" % s for s in scores]))
