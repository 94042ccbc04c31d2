"""Is the reference boundary where the image's features are? (pvpython, numpy, scipy)

usage: pvpython scripts/boundary_contrast.py [--cases nuclei-dsb2018,liver-ct-totalseg]
For each case, the ratio (mean within 3 voxels of the reference boundary) / (mean farther than 10
voxels) of local feature measures that know nothing of the seeds: Gaussian gradient magnitude at
three scales, the share of voxels whose gradient is in the image's top 10 %, the Hessian's largest
|eigenvalue| at the Feature Nodes' Hessian scale; then the same ratio for the Feature Nodes' node
density (default properties), and once more with the reference boundary itself fed to the Edge Map
input in place of Canny (an oracle edge detector: a diagnostic, never a result). The nodes' ratio
must be >= 1.5 (issue 2); where every measure is below 1, no recipe that places nodes by local
features alone can get there.
"""
import argparse
import os

import numpy as np
from scipy import ndimage
from paraview import servermanager as sm
from paraview.simple import *  # noqa: F401,F403
import paraview.simple as ps
from vtkmodules.util.numpy_support import numpy_to_vtk as n2v
from vtkmodules.util.numpy_support import vtk_to_numpy as v2n
from vtkmodules.vtkCommonDataModel import vtkImageData

import featuremesh as fm

def largest_abs_hessian_eigenvalue(a, sigma):
    axes = range(a.ndim)
    h = np.empty(a.shape + (a.ndim, a.ndim))
    for i in axes:
        for j in axes:
            if j < i:
                continue
            order = [0] * a.ndim
            order[i] += 1
            order[j] += 1
            h[..., i, j] = h[..., j, i] = ndimage.gaussian_filter(a, sigma, order=order, mode="nearest")
    return np.abs(np.linalg.eigvalsh(h)).max(axis=-1)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--cases", default="nuclei-dsb2018,liver-ct-totalseg")
    args = ap.parse_args()
    fm.load_plugin(ns=globals())
    header = ["case", "|grad| s=0.7", "|grad| s=1.5", "|grad| s=3", "top-10% |grad|", "|Hessian| s=2", "nodes",
              "nodes, reference boundary as edge map"]
    print("near / far ratios (near: <= 3 voxels from the reference boundary, far: > 10)")
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for name in args.cases.split(","):
        d = fm.case_dir(name)
        if not d:
            print("note: case %s not found, skipped" % name)
            continue
        reader = ps.OpenDataFile(os.path.join(d, "image.mha"))
        reader.UpdatePipeline()
        image = sm.Fetch(reader)
        dims = image.GetDimensions()
        shape = tuple(x for x in dims[::-1] if x > 1)
        a = v2n(image.GetPointData().GetScalars()).astype(np.float64).reshape(shape)
        t = v2n(sm.Fetch(ps.OpenDataFile(os.path.join(d, "truth.mha"))).GetPointData().GetScalars()).reshape(shape) > 0
        dist = ndimage.distance_transform_edt(~(t ^ ndimage.binary_erosion(t)))
        near, far = dist <= 3, dist > 10
        ratio = lambda m: m[near].mean() / m[far].mean()  # noqa: E731
        cells = [name]
        for s in (0.7, 1.5, 3.0):
            cells.append(ratio(ndimage.gaussian_gradient_magnitude(a, s)))
        g = ndimage.gaussian_gradient_magnitude(a, 0.7)
        cells.append(ratio((g > np.percentile(g, 90)).astype(float)))
        cells.append(ratio(largest_abs_hessian_eigenvalue(a, 2.0)))
        edges = vtkImageData()
        edges.SetDimensions(dims)
        edges.SetSpacing(image.GetSpacing())
        edges.SetOrigin(image.GetOrigin())
        border = n2v((t ^ ndimage.binary_erosion(t)).astype(np.uint8).ravel(), deep=True)
        border.SetName("ReferenceBoundary")
        edges.GetPointData().SetScalars(border)
        oracle = ps.PVTrivialProducer()
        oracle.GetClientSideObject().SetOutput(edges)
        for edge_map in (None, oracle):
            props = dict(Input=reader, Scalars=["POINTS", reader.PointData.keys()[0]])
            if edge_map is not None:
                props["EdgeMap"] = edge_map
            nodes = sm.Fetch(FeatureNodes(**props))
            idx = np.rint(v2n(nodes.GetPoints().GetData()) / np.array(image.GetSpacing())).astype(int)
            occupied = np.zeros(dims[::-1], bool)
            occupied[idx[:, 2], idx[:, 1], idx[:, 0]] = True
            cells.append(ratio(occupied.reshape(shape).astype(float)))
        print("| " + " | ".join([cells[0]] + ["%.2f" % c for c in cells[1:]]) + " |")


if __name__ == "__main__":
    main()
