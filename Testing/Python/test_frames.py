"""Image frames end to end: an oriented, offset, anisotropic (and a mirrored) copy of a real image runs
through stages 1 -> 2 -> 4 and the voxel cut with seeds in world coordinates, and gives the same nodes,
mesh and labels as the same voxels with an identity frame; the outputs carry the input's frame."""
import math

import numpy as np
from vtkmodules.vtkCommonDataModel import vtkImageData, vtkPolyData
from vtkmodules.vtkCommonCore import vtkPoints

import fmtest as ft


def rotation(axis, degrees):
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    t = math.radians(degrees)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(t) * K + (1 - math.cos(t)) * K @ K


def reframed(base, origin, spacing, direction):
    im = vtkImageData()
    im.ShallowCopy(base)
    im.SetOrigin(origin)
    im.SetSpacing(spacing)
    im.SetDirectionMatrix(np.asarray(direction, float).ravel().tolist())
    return im


def producer(data):
    p = ft.ps.PVTrivialProducer()
    p.GetClientSideObject().SetOutput(data)
    p.UpdatePipeline()
    return p


def world(index, origin, spacing, direction):
    return np.asarray(origin) + (np.asarray(direction) @ (np.asarray(index) * np.asarray(spacing)).T).T


def point_source(P):
    pd = vtkPolyData()
    pts = vtkPoints()
    pts.SetDataTypeToDouble()
    for p in P:
        pts.InsertNextPoint(*p)
    pd.SetPoints(pts)
    return producer(pd)


def run(image, so, sb):
    nodes = ft.FeatureNodes(Input=image)
    mesh = ft.DelaunayImageMesh(Nodes=nodes, Image=image)
    cut = ft.SuperVoxelCut(Mesh=mesh, ObjectSeeds=so, BackgroundSeeds=sb, Image=image)
    cut.UpdatePipeline()
    bare = ft.SuperVoxelCut(Mesh=mesh, ObjectSeeds=so, BackgroundSeeds=sb)  # frame from the mesh's field data
    bare.UpdatePipeline()
    vc = ft.VoxelCut(Input=image, ObjectSeeds=so, BackgroundSeeds=sb)
    vc.UpdatePipeline()
    return {"nodes": ft.fetch(nodes), "mesh": ft.fetch(mesh), "cut": ft.fetch(cut, 0), "labels": ft.fetch(cut, 2),
            "bare": ft.fetch(bare, 2), "voxelcut": ft.fetch(vc)}


def frame_of(im):
    return (np.array(im.GetOrigin()), np.array(im.GetSpacing()),
            np.array([im.GetDirectionMatrix().GetElement(r, c) for r in range(3) for c in range(3)]), im.GetDimensions())


for case, spacing, frames in (
        ("nuclei-dsb2018", (0.7, 1.6, 1.0),
         {"rotated 90 about z, offset": ((-120.5, 33.25, 7.0), rotation((0, 0, 1), 90)),
          "rotated 30 about x, offset": ((4.0, -2.0, 11.0), rotation((1, 0, 0), 30)),
          "mirrored in y": ((0.0, 0.0, 0.0), np.diag([1.0, -1.0, 1.0]))}),
        ("liver-ct-totalseg", (0.8, 1.3, 2.1),
         {"rotated 120 about (1,1,1), offset": ((-80.0, 12.5, -300.0), rotation((1, 1, 1), 120)),
          "rotated 25 about (1,2,3), offset": ((5.5, 6.5, 7.5), rotation((1, 2, 3), 25)),
          "mirrored in x": ((3.0, 0.0, 0.0), np.diag([-1.0, 1.0, 1.0]))})):
    d, image, truth = ft.open_case(case)
    base = ft.fetch(image)
    seeds_index = [ft.v2n(ft.fetch(ft.seeds("%s/seeds_%s.csv" % (d, kind))).GetPoints().GetData()) / np.array(base.GetSpacing())
                   for kind in ("object", "background")]
    ref_image = reframed(base, (0, 0, 0), spacing, np.eye(3))
    ref = run(producer(ref_image), *[point_source(world(s, (0, 0, 0), spacing, np.eye(3))) for s in seeds_index])
    ft.check(ref["cut"].GetNumberOfCells() > 0 and ft.array(ref["labels"]).any(),
             "%s: the identity frame with spacing %s segments something" % (case, spacing))
    for name, (origin, direction) in frames.items():
        tag = "%s, %s" % (case, name)
        img = reframed(base, origin, spacing, direction)
        out = run(producer(img), *[point_source(world(s, origin, spacing, direction)) for s in seeds_index])
        ft.check(out["cut"].GetNumberOfCells() == ref["cut"].GetNumberOfCells(), "%s: the cut runs (%d elements)" % (tag, out["cut"].GetNumberOfCells()))
        n_ref, n_out = ft.v2n(ref["nodes"].GetPoints().GetData()), ft.v2n(out["nodes"].GetPoints().GetData())
        idx = (np.linalg.inv(np.asarray(direction)) @ (n_out - np.asarray(origin)).T).T / np.array(spacing)
        ft.check(np.allclose(idx, n_ref / np.array(spacing), atol=1e-6), "%s: the same nodes, placed in the world frame" % tag)
        vpc = 3 if base.GetDimensions()[2] == 1 else 4
        cells = [np.sort(ft.v2n(m.GetCells().GetConnectivityArray()).reshape(-1, vpc), axis=1) for m in (out["mesh"], ref["mesh"])]
        ft.check(np.array_equal(*cells), "%s: the same elements" % tag)
        ft.check(np.array_equal(ft.array(out["mesh"], ft.names.PixelCount, cells=True), ft.array(ref["mesh"], ft.names.PixelCount, cells=True)),
                 "%s: the same voxel ownership (PixelCount)" % tag)
        ft.check(np.array_equal(ft.array(out["cut"], ft.names.Label, cells=True), ft.array(ref["cut"], ft.names.Label, cells=True)),
                 "%s: the same element labels" % tag)
        for key in ("labels", "bare", "voxelcut"):
            ft.check(np.array_equal(ft.array(out[key]), ft.array(ref[key])), "%s: the same %s" % (tag, key))
            o, s, r, dims = frame_of(out[key])
            o_in, s_in, r_in, dims_in = frame_of(img)
            ft.check(np.allclose(o, o_in) and np.allclose(s, s_in) and np.allclose(r, r_in) and dims == dims_in,
                     "%s: %s carry the input's frame" % (tag, key))
ft.finish()
