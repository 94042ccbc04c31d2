"""Every filter stores the value range of each output array where ParaView reads it (the array's
range cache): after each Apply ParaView asks every array for its range and its finite range, which
VTK 9.2 computes at ~20 ns per value. The cached ranges must be present and equal what VTK computes
from the values; a change of the values (Modified) must drop them, also where a re-cut rewrites a
kept label image in place. Bundled cases: the liver (3D, every filter), nuclei (2D) and the
abdomen's labelled seeds."""
import os

import fmtest as ft
import paraview.simple as ps
from vtkmodules.vtkCommonCore import vtkAbstractArray, vtkDataArray


def cached(array, key):
    """The per-component ranges stored under `key`, or None when any is missing or stale."""
    per = array.GetInformation().Get(key)
    if per is None or per.GetNumberOfInformationObjects() < array.GetNumberOfComponents():
        return None
    out = []
    for c in range(array.GetNumberOfComponents()):
        info = per.GetInformationObject(c)
        if not info.Has(vtkDataArray.COMPONENT_RANGE()) or array.GetMTime() > info.GetMTime():
            return None
        out.append(tuple(info.Get(vtkDataArray.COMPONENT_RANGE())))
    return out


def computed(array):
    """(ranges, finite ranges) per component, computed by VTK from a fresh copy of the values."""
    copy = array.NewInstance()
    copy.DeepCopy(array)
    n = copy.GetNumberOfComponents()
    return [tuple(copy.GetRange(c)) for c in range(n)], [tuple(copy.GetFiniteRange(c)) for c in range(n)]


def arrays_of(data):
    for attrs, where in ((data.GetPointData(), "point"), (data.GetCellData(), "cell")):
        for i in range(attrs.GetNumberOfArrays()):
            a = attrs.GetArray(i)
            if a is not None and a.GetNumberOfTuples() > 0:
                yield "%s array %s" % (where, a.GetName()), a
    if hasattr(data, "GetPoints") and data.GetPoints() is not None and data.GetNumberOfPoints() > 0:
        yield "points", data.GetPoints().GetData()


def check_outputs(label, proxy):
    proxy.UpdatePipeline()
    algorithm = proxy.GetClientSideObject()
    checked = 0
    for port in range(proxy.GetNumberOfOutputPorts()):
        data = algorithm.GetOutputDataObject(port)
        for what, a in arrays_of(data):
            ranges, finite = computed(a)
            has, has_finite = cached(a, vtkAbstractArray.PER_COMPONENT()), cached(a, vtkAbstractArray.PER_FINITE_COMPONENT())
            ok = has == ranges and has_finite == finite
            if not ok:
                ft.check(False, "%s port %d %s: cached %s / %s, computed %s / %s" % (label, port, what, has, has_finite, ranges, finite))
            checked += 1
    ft.check(checked > 0, "%s: every output array's cached range equals VTK's (%d arrays)" % (label, checked))
    return checked


liver = ft.fm.Case(ft.case_dir("liver-ct-totalseg"))
nodes = liver.feature_nodes()
delaunay = liver.mesh(nodes)
smoothed = liver.smoothing(delaunay)
cut = liver.super_voxel_cut(smoothed)
for label, proxy in (("Feature Nodes", nodes), ("Delaunay Image Mesh", delaunay), ("Image Mesh Smoothing", smoothed),
                     ("Super-Voxel Cut", cut), ("Voxel Cut", liver.voxel_cut()), ("RSP Edge Enhancement", liver.rsp()),
                     ("Segmentation Surface Smoothing", liver.surface_smoothing(cut))):
    check_outputs("liver, " + label, proxy)

nuclei = ft.fm.Case(ft.case_dir("nuclei-dsb2018"))
check_outputs("nuclei, Super-Voxel Cut", nuclei.super_voxel_cut(nuclei.smoothing(nuclei.mesh(nuclei.feature_nodes()))))

# The label image's range follows a re-cut, and a change of its values drops the cache.
labels = cut.GetClientSideObject().GetOutputDataObject(2).GetPointData().GetArray(ft.names.Label)
ft.check(cached(labels, vtkAbstractArray.PER_COMPONENT()) == [(0.0, 1.0)], "liver: the label image's cached range is 0..1")
labels.SetValue(0, 7)
labels.Modified()
ft.check(cached(labels, vtkAbstractArray.PER_COMPONENT()) is None and labels.GetRange(0) == (0.0, 7.0),
         "a changed label image drops its cached range, and VTK computes the new one")

# A re-cut rewrites the label image of the cut before last in place (the one no one holds): its range
# must follow, and its values too. Labels 1..k kept, k = 5, 3, 4, 2: the third cut rewrites the first
# one's image.


def on_voxels(cut, voxels, mesh):
    """Whether a cut's label image holds each voxel's element label (0 outside `mesh`)."""
    owner = ft.fm.v2n(ft.fm.owner_map(mesh))
    cells = ft.fm.v2n(cut.GetClientSideObject().GetOutputDataObject(0).GetCellData().GetArray(ft.names.Label))
    return ft.np.array_equal(ft.fm.v2n(voxels), ft.np.where(owner >= 0, cells[ft.np.maximum(owner, 0)], 0))


abdomen = os.path.join(ft.DATA, "multilabel", "abdomen-ct-totalseg")
if os.path.isdir(abdomen):
    image = ps.OpenDataFile(os.path.join(abdomen, "image.mha"))
    mesh = ps.ImageMeshSmoothing(Mesh=ps.DelaunayImageMesh(Nodes=ps.FeatureNodes(Input=image), Image=image), Image=image)
    rows = ft.np.loadtxt(os.path.join(abdomen, "seeds.csv"), delimiter=",", skiprows=1, ndmin=2)
    folder = ft.scratch()
    multi = None
    for k in (5, 3, 4, 2):
        path = os.path.join(folder, "seeds_%d.csv" % k)
        ft.np.savetxt(path, rows[rows[:, 3] <= k], delimiter=",", header="x,y,z,label", comments="", fmt="%g")
        reader = ps.CSVReader(FileName=[path])
        if multi is None:
            multi = ps.SuperVoxelCut(Mesh=mesh, Seeds=reader, Image=image, VoxelRefinement=0)
        else:
            multi.Seeds = reader
        multi.UpdatePipeline()
        voxels = multi.GetClientSideObject().GetOutputDataObject(2).GetPointData().GetArray(ft.names.Label)
        shown = multi.GetDataInformation(2).GetPointDataInformation().GetArrayInformation(ft.names.Label).GetComponentRange(0)
        ft.check(tuple(shown) == (0.0, float(k)) and computed(voxels)[0] == [(0.0, float(k))],
                 "abdomen, labels 0..%d: ParaView shows the label image's range %s" % (k, tuple(shown)))
        ft.check(on_voxels(multi, voxels, mesh), "abdomen, labels 0..%d: the label image is the elements' labels on their voxels" % k)
    # A new cut's first re-cut, its image held (as a view holds it): a copy of it patched where the
    # first seed, moved by a voxel, changed labels.
    edited = rows[rows[:, 3] <= 2].copy()
    for step in (0, 1):
        edited[0, 0] += step * ft.fm.fetch(image).GetSpacing()[0]
        path = os.path.join(folder, "edited_%d.csv" % step)
        ft.np.savetxt(path, edited, delimiter=",", header="x,y,z,label", comments="", fmt="%g")
        if step == 0:
            fresh = ps.SuperVoxelCut(Mesh=mesh, Seeds=ps.CSVReader(FileName=[path]), Image=image, VoxelRefinement=0)
        else:
            fresh.Seeds = ps.CSVReader(FileName=[path])
        fresh.UpdatePipeline()
        held = fresh.GetClientSideObject().GetOutputDataObject(2).GetPointData().GetArray(ft.names.Label)
        ft.check(on_voxels(fresh, held, mesh), "abdomen, a seed moved (%d): the label image is the elements' labels" % step)
    # With the voxel refinement (the default) a re-cut first undoes the last refinement of the image
    # it rewrites: each kept cut's label image equals a fresh filter's, its image held. (A kept
    # expansion from 2 labels to 4 ties with a fresh one's in 2 elements, so the chain does not go up.)
    kept = None
    for k, name in ((5, "seeds_5.csv"), (3, "seeds_3.csv"), (2, "seeds_2.csv"), (2, "edited_0.csv"), (2, "edited_1.csv")):
        reader = ps.CSVReader(FileName=[os.path.join(folder, name)])
        if kept is None:
            kept = ps.SuperVoxelCut(Mesh=mesh, Seeds=reader, Image=image)
        else:
            kept.Seeds = reader
        kept.UpdatePipeline()
        held = ft.fm.v2n(kept.GetClientSideObject().GetOutputDataObject(2).GetPointData().GetArray(ft.names.Label))
        again = ps.SuperVoxelCut(Mesh=mesh, Seeds=reader, Image=image)
        again.UpdatePipeline()
        refined = ft.fm.fetch(again, 2).GetFieldData().GetArray(ft.names.RelabelledVoxels).GetValue(0)
        ft.check(refined > 0 and ft.np.array_equal(held, ft.fm.labels(again)),
                 "abdomen, labels 0..%d refined (%d voxels): a kept cut's label image equals a fresh one's" % (k, refined))
        ps.Delete(again)
ft.finish("value range")
