"""Stage 4 on real data: Dice of the super-voxel and voxel cuts, seeds honoured, closed 3D surface
enclosing the object elements, determinism across runs and thread counts, bad input."""
import os
import sys

import numpy as np
from scipy import ndimage as ndi
from vtkmodules.vtkFiltersCore import vtkFeatureEdges

import fmtest as ft
from featuremesh.metrics import next_seed

# Floors: the Dice measured at the defaults with each case's task (cases.csv; lambda 0.2, Connectivity
# From Task, the geodesic term for Task Object) on the Delaunay mesh, minus 0.02; measured
# super-voxel / voxel: nuclei (class, on its local contrast) 0.858 / 0.850, liver 0.871 / 0.937 (automatic bins), BraTS-0005 0.824 / 0.847,
# BraTS-0006 0.914 / 0.920. Cases absent from this machine are skipped with a message.
FLOORS = {"nuclei-dsb2018": (0.838, 0.830), "liver-ct-totalseg": (0.851, 0.917),
          "brain-tumour-brats-0005": (0.804, 0.827), "brain-tumour-brats-0006": (0.894, 0.900)}
# How far the super-voxel cut may fall below the voxel cut: 0.02, except where today's mesh cannot
# follow the object as well as voxels do (the liver's elements' oracle Dice, 0.92, is below the voxel
# cut's; nuclei lose 0.03 on elements straddling faint edges; BraTS-0005's Delaunay elements, 0.023
# below the voxel cut with the geodesic term). The mesh stages must close these gaps; until then
# they may not widen.
GAP = {"nuclei-dsb2018": 0.05, "liver-ct-totalseg": 0.095, "brain-tumour-brats-0005": 0.03}


def task(case):
    return (ft.fm.case_task(case) or "object").capitalize()


def run(case):
    d, image, truth = ft.open_case(case)
    so = ft.seeds(os.path.join(d, "seeds_object.csv"))
    sb = ft.seeds(os.path.join(d, "seeds_background.csv"))
    mesh = ft.DelaunayImageMesh(Nodes=ft.FeatureNodes(Input=image), Image=image)
    cut = ft.SuperVoxelCut(Mesh=mesh, ObjectSeeds=so, BackgroundSeeds=sb, Image=image, Task=task(case))
    cut.UpdatePipeline()
    return d, image, truth, so, sb, cut


def digests(cut):
    """The elements' labels and the label image (refined along the cut), as one string."""
    return ft.digest(ft.array(ft.fetch(cut), ft.names.Label, cells=True)) + " " + ft.digest(ft.array(ft.fetch(cut, 2)))


if len(sys.argv) > 1:  # child run for the thread-count check
    *_, cut = run(sys.argv[1])
    print(digests(cut))
    sys.exit(0)

for case, (svc_floor, voxel_floor) in FLOORS.items():
    if ft.fm.case_dir(case) is None:
        print("SKIP %s: not found (bundled Data/ or ../shared/data/cases)" % case)
        continue
    d, image, truth, so, sb, cut = run(case)
    T = ft.array(ft.fetch(truth))
    labelled = ft.fetch(cut, 0)
    label = ft.array(labelled, ft.names.Label, cells=True)
    L = ft.array(ft.fetch(cut, 2))
    vc = ft.VoxelCut(Input=image, ObjectSeeds=so, BackgroundSeeds=sb, Scalars=["POINTS", ft.fetch(image).GetPointData().GetScalars().GetName()],
                     Task=task(case))
    vc.UpdatePipeline()
    V = ft.array(ft.fetch(vc))
    ds, dv = ft.dice(L, T), ft.dice(V, T)
    ft.check(ds >= svc_floor, "%s: super-voxel cut Dice %.3f (>= %.3f)" % (case, ds, svc_floor))
    ft.check(dv >= voxel_floor, "%s: voxel cut Dice %.3f (>= %.3f)" % (case, dv, voxel_floor))
    gap = GAP.get(case, 0.02)
    ft.check(ds >= dv - gap, "%s: super-voxel Dice %.3f not below the voxel cut's %.3f - %.3f" % (case, ds, dv, gap))
    # The object components the field data report are those of the label image.
    im = ft.fetch(image)
    shape = im.GetDimensions()[::-1]
    voxel_volume = np.prod([abs(x) for x in im.GetSpacing()[: 2 if shape[0] == 1 else 3]])
    for what, out, labels in (("super-voxel", ft.fetch(cut, 2), L), ("voxel", ft.fetch(vc), V)):
        count = out.GetFieldData().GetArray(ft.names.ObjectComponents).GetValue(0)
        volumes = ft.v2n(out.GetFieldData().GetArray(ft.names.ObjectComponentVolumes))
        ft.check(abs(volumes.sum() - labels.sum() * voxel_volume) <= 1e-9 * max(1, volumes.sum()) and len(volumes) == count,
                 "%s: %s cut's %d component volumes sum to its object volume" % (case, what, count))
        if what == "voxel":
            _, n = ndi.label(labels.reshape(shape))
            ft.check(n == count, "%s: voxel cut's ObjectComponents %d = face-connected components %d" % (case, count, n))
    # Seeded elements carry their seed's label: find each seed's element through the label image.
    dims, sp = np.array(im.GetDimensions()), np.array(im.GetSpacing())
    for proxy, want in ((so, 1), (sb, 0)):
        P = ft.v2n(ft.fetch(proxy).GetPoints().GetData())
        ijk = np.rint(P / sp).astype(int)
        got = L.reshape(dims[::-1])[ijk[:, 2], ijk[:, 1], ijk[:, 0]]
        ft.check((got == want).all(), "%s: every %s seed's element has label %d" % (case, "object" if want else "background", want))
    if dims[2] > 1:
        surface = ft.fetch(cut, 1)
        fe = vtkFeatureEdges()
        fe.SetInputData(surface)
        fe.BoundaryEdgesOn()
        fe.NonManifoldEdgesOff()
        fe.FeatureEdgesOff()
        fe.ManifoldEdgesOff()
        fe.Update()
        ft.check(fe.GetOutput().GetNumberOfCells() == 0, "%s: boundary surface is closed (no boundary edges)" % case)
        Pm = ft.v2n(labelled.GetPoints().GetData())
        C = ft.v2n(labelled.GetCells().GetConnectivityArray()).reshape(-1, 4)[label == 1]
        tet = np.einsum("ij,ij->i", Pm[C[:, 1]] - Pm[C[:, 0]], np.cross(Pm[C[:, 2]] - Pm[C[:, 0]], Pm[C[:, 3]] - Pm[C[:, 0]])).sum() / 6
        F = ft.v2n(surface.GetPolys().GetConnectivityArray()).reshape(-1, 3)
        Ps = ft.v2n(surface.GetPoints().GetData())
        enclosed = np.einsum("ij,ij->i", Ps[F[:, 0]], np.cross(Ps[F[:, 1]], Ps[F[:, 2]])).sum() / 6
        ft.check(abs(enclosed - tet) <= 1e-6 * tet, "%s: surface encloses the object elements' volume (rel. err %.1e)" % (case, abs(enclosed - tet) / tet))
    digest = digests(cut)
    *_, again = run(case)
    ft.check(digests(again) == digest, "%s: identical labels and label image across runs" % case)
    one = ft.run_script_with_backend(__file__, "Sequential", case)
    two = ft.run_script_with_backend(__file__, "STDThread", case)
    ft.check(one == two == digest, "%s: identical labels and label image with 1 and 2 threads" % case)

# The cut keeps what depends on the mesh alone between runs: after a seed edit, and after the mesh
# changes, it gives what a fresh filter gives.
d, image, truth, so, sb, cut = run("nuclei-dsb2018")
seeds = ft.fetch(so)
points = [c for i in range(seeds.GetNumberOfPoints()) for c in seeds.GetPoint(i)]
edited = ft.PolyPointSource(Points=points)
nodes = ft.FeatureNodes(Input=image)
mesh = ft.DelaunayImageMesh(Nodes=nodes, Image=image)
kept = ft.SuperVoxelCut(Mesh=mesh, ObjectSeeds=edited, BackgroundSeeds=sb, Image=image)
kept.UpdatePipeline()
for step, change in (("a seed edit", lambda: setattr(edited, "Points", points[3:])),
                     ("a mesh change", lambda: setattr(nodes, "UniformSpacing", 9)),
                     ("a parameter change", lambda: setattr(kept, "Lambda", 0.5))):
    change()
    kept.UpdatePipeline()
    fresh = ft.SuperVoxelCut(Mesh=mesh, ObjectSeeds=edited, BackgroundSeeds=sb, Image=image, Lambda=kept.Lambda)
    fresh.UpdatePipeline()
    a, b = ft.fetch(kept), ft.fetch(fresh)
    ft.check(a.GetNumberOfCells() == b.GetNumberOfCells() > 0 and
             ft.np.array_equal(ft.array(a, ft.names.Label, cells=True), ft.array(b, ft.names.Label, cells=True)) and
             ft.np.array_equal(ft.fm.labels(kept), ft.fm.labels(fresh)),
             "after %s the kept cut equals a fresh one (%d elements)" % (step, a.GetNumberOfCells()))
    ft.Delete(fresh)

# The binary refinement keeps its max-flow on a domain that grows with the band: on the liver (one
# graph), seeds placed where the result is wrong (the band moves and the domain grows) and a seed
# moved by a voxel and back (the band stays inside it) give what a fresh filter gives.
d, image, truth, so, sb, cut = run("liver-ct-totalseg")
# The geodesic weight the cut used: Geodesic Weight times the seed densities' overlap over 0.75
# (Adaptive Geodesic Weight, on), or Geodesic Weight as it is (off), which cuts the liver otherwise.
fields = ft.fetch(cut, 2).GetFieldData()
overlap, used = (fields.GetArray(n).GetValue(0) for n in (ft.names.SeedOverlap, ft.names.SpatialWeight))
weight = float(cut.GeodesicWeight)
ft.check(0.0 < overlap < 1.0 and abs(used - weight * overlap / 0.75) <= 1e-9 * weight,
         "liver: adaptive geodesic weight %.3f = %.2f x overlap %.3f / 0.75" % (used, weight, overlap))
# The seeds' reach: R, the largest distance from an object seed's voxel to its nearest background
# seed's voxel, as the field data reports it.
grid = ft.fetch(image)
at = {k: ft.np.array([[round((ft.fetch(s).GetPoint(i)[a] - grid.GetOrigin()[a]) / grid.GetSpacing()[a]) * grid.GetSpacing()[a]
                       for a in range(3)] for i in range(ft.fetch(s).GetNumberOfPoints())]) for k, s in (("o", so), ("b", sb))}
want = max(ft.np.linalg.norm(at["b"] - o, axis=1).min() for o in at["o"])
reach = fields.GetArray(ft.names.SeedReachDistance).GetValue(0)
ft.check(abs(reach - want) <= 1e-9 * want and want > 0, "liver: the seeds' reach R %.2f mm (%.2f from the seed files)" % (reach, want))
fixed = ft.SuperVoxelCut(Mesh=cut.Mesh, ObjectSeeds=so, BackgroundSeeds=sb, Image=image, AdaptiveGeodesicWeight=0)
fixed.UpdatePipeline()
fixed_used = ft.fetch(fixed, 2).GetFieldData().GetArray(ft.names.SpatialWeight).GetValue(0)
ft.check(fixed_used == weight and not ft.np.array_equal(ft.fm.labels(fixed), ft.fm.labels(cut)),
         "liver: the fixed weight %.3f cuts otherwise" % fixed_used)
ft.Delete(fixed)
vtk_image = ft.fetch(image)
shape, spacing = vtk_image.GetDimensions()[::-1], vtk_image.GetSpacing()
truth = ft.array(ft.fetch(truth)).reshape(shape) != 0
points = {k: [list(ft.fetch(s).GetPoint(i)) for i in range(ft.fetch(s).GetNumberOfPoints())] for k, s in (("o", so), ("b", sb))}
po, pb = ft.PolyPointSource(Points=sum(points["o"], [])), ft.PolyPointSource(Points=sum(points["b"], []))
kept = ft.SuperVoxelCut(Mesh=cut.Mesh, ObjectSeeds=po, BackgroundSeeds=pb, Image=image)
kept.UpdatePipeline()
for step in range(6):
    if step % 2 == 0:
        (k, j, i), is_object = next_seed(ft.fm.labels(kept).reshape(shape).astype(bool), truth, spacing)
        seed = vtk_image.GetPoint(vtk_image.ComputePointId([int(i), int(j), int(k)]))
        points["o" if is_object else "b"].append(list(seed))
    else:
        points["o"][0][0] += spacing[0] * (1 if step % 4 == 1 else -1)
    po.Points, pb.Points = sum(points["o"], []), sum(points["b"], [])
    kept.UpdatePipeline()
    fresh = ft.SuperVoxelCut(Mesh=cut.Mesh, ObjectSeeds=po, BackgroundSeeds=pb, Image=image)
    fresh.UpdatePipeline()
    refined = ft.fetch(fresh, 0).GetFieldData().GetArray(ft.names.RelabelledVoxels).GetValue(0)
    ft.check(refined > 0 and ft.np.array_equal(ft.fm.labels(kept), ft.fm.labels(fresh)),
             "liver, edit %d: the kept refinement equals a fresh one (%d voxels relabelled)" % (step, refined))
    ft.Delete(fresh)

# Stage 2's owner map (kept off the saved arrays, found by the digest of the mesh's points and
# cells) is what the cut would rasterise: on the lattice mesh of nuclei the cut that reuses it and
# one made to rasterise (the same lattice points in the other float type: another digest) give the same element
# ids; no output carries the map.
d, image, truth, so, sb, cut = run("nuclei-dsb2018")
owner_map = ft.fm.owner_map(cut.Mesh)
ft.check(owner_map is not None and owner_map.GetNumberOfTuples() == ft.fetch(image).GetNumberOfPoints(),
         "Delaunay Image Mesh keeps a VoxelOwner map of one id per voxel")
ft.check(all(ft.fetch(p, port).GetFieldData().GetArray(ft.names.VoxelOwner) is None for p, port in ((cut.Mesh, 0), (cut, 0), (cut, 2))),
         "neither the mesh nor the cut's outputs carry the map in their arrays (writers would save it)")
retyped = ft.ProgrammableFilter(Input=cut.Mesh, OutputDataSetType="vtkUnstructuredGrid", Script="""
from vtkmodules.vtkCommonCore import vtkPoints, VTK_DOUBLE, VTK_FLOAT
out = self.GetOutput()
out.ShallowCopy(self.GetInput())
points = vtkPoints()
points.SetDataType(VTK_FLOAT if out.GetPoints().GetDataType() == VTK_DOUBLE else VTK_DOUBLE)
points.SetNumberOfPoints(out.GetNumberOfPoints())
for i in range(out.GetNumberOfPoints()):
    points.SetPoint(i, out.GetPoint(i))
out.SetPoints(points)""")
ids = [ft.SuperVoxelCut(Mesh=m, ObjectSeeds=so, BackgroundSeeds=sb, Image=image, SuperVoxelIds=1) for m in (cut.Mesh, retyped)]
reused = [ft.fetch(c).GetFieldData().GetArray(ft.names.OwnerMapReused).GetValue(0) for c in ids]
ft.check(reused == [1.0, 0.0], "the cut reuses stage 2's map, and rasterises the mesh stored otherwise (%s)" % reused)
a, b = (ft.array(ft.fetch(c, 2), ft.names.ElementId) for c in ids)
ft.check(ft.np.array_equal(a, b) and ft.np.array_equal(ft.v2n(owner_map), a),
         "the kept owner map equals the cut's own rasterisation (%d voxels)" % a.size)
# A mesh whose points moved since (stage 6, a Transform) is rasterised afresh.
shifted = ft.Transform(Input=cut.Mesh)
shifted.Transform.Translate = [0.25, 0.0, 0.0]
fresh = ft.SuperVoxelCut(Mesh=shifted, ObjectSeeds=so, BackgroundSeeds=sb, Image=image)
fresh.UpdatePipeline()
ft.check(ft.fetch(fresh).GetFieldData().GetArray(ft.names.OwnerMapReused).GetValue(0) == 0.0,
         "a moved mesh is rasterised afresh, not given the map of the mesh it came from")

# A chain of seed edits reuses the last max-flow (Kohli-Torr): after each, labels, flow and label
# image equal a fresh cut's. The edits move a seed by a voxel and back, onto another element, add and drop seeds.
for case in ("nuclei-dsb2018", "liver-ct-totalseg"):
    if ft.fm.case_dir(case) is None:
        print("SKIP %s: not found" % case)
        continue
    d, image, truth, so, sb, cut = run(case)
    seeds = ft.fetch(so)
    pts = [list(seeds.GetPoint(i)) for i in range(seeds.GetNumberOfPoints())]
    step = ft.fetch(image).GetSpacing()
    edits = [lambda p: p[0].__setitem__(0, p[0][0] + step[0]), lambda p: p[0].__setitem__(0, p[0][0] - step[0]),
             lambda p: p[0].__setitem__(1, p[0][1] + 6 * step[1]), lambda p: p.append(list(p[-1])) or p[-1].__setitem__(0, p[-1][0] + 2 * step[0]),
             lambda p: p.pop(0), lambda p: p.pop()]
    edited = ft.PolyPointSource(Points=[c for q in pts for c in q])
    chained = ft.SuperVoxelCut(Mesh=cut.Mesh, ObjectSeeds=edited, BackgroundSeeds=sb, Image=image)
    chained.UpdatePipeline()
    same = 0
    for k, edit in enumerate(edits):
        edit(pts)
        edited.Points = [c for q in pts for c in q]
        chained.UpdatePipeline()
        fresh = ft.SuperVoxelCut(Mesh=cut.Mesh, ObjectSeeds=edited, BackgroundSeeds=sb, Image=image)
        fresh.UpdatePipeline()
        a, b = ft.fetch(chained), ft.fetch(fresh)
        fa, fb = (x.GetFieldData().GetArray(ft.names.Flow).GetValue(0) for x in (a, b))
        # The label image too: from the second edit on, the filter rewrites its image of two cuts back.
        same += (ft.np.array_equal(ft.array(a, ft.names.Label, cells=True), ft.array(b, ft.names.Label, cells=True)) and
                 abs(fa - fb) <= 1e-9 * abs(fb) and ft.np.array_equal(ft.fm.labels(chained), ft.fm.labels(fresh)))
        ft.Delete(fresh)
    ft.check(same == len(edits), "%s: %d of %d chained seed edits give a fresh cut's labels, flow and label image" % (case, same, len(edits)))

# Bad input.
mesh = ft.DelaunayImageMesh(Nodes=ft.FeatureNodes(Input=image), Image=image)


def cells_with(obj, bkg, m=mesh):
    c = ft.SuperVoxelCut(Mesh=m, ObjectSeeds=obj, BackgroundSeeds=bkg)
    c.UpdatePipeline()
    return ft.fetch(c).GetNumberOfCells()


ft.check(cells_with(so, sb) > 0, "the cut runs without the optional image")
outside = ft.PolyPointSource(Points=[5000, 5000, 0])
ft.check(cells_with(outside, sb) == 0, "seeds outside the mesh: error")
ft.check(cells_with(so, so) == 0, "the same elements seeded as both: error")
empty = ft.PolyPointSource(Points=[])
ft.check(cells_with(empty, sb) == 0, "no object seeds: error")
ft.check(cells_with(so, empty) == 0, "only one class of seeds: error")
bare = ft.PassArrays(Input=mesh, CellDataArrays=[ft.names.PixelCount], PointDataArrays=[], FieldDataArrays=[])
ft.check(cells_with(so, sb, bare) == 0, "a mesh without MeanIntensity: error")

# Stage 3 rasterises its own moved mesh, so it asks its input for no owner map. Built and updated at
# once (a script), stage 2's mesh comes without one and the cut takes stage 3's. A stage 2 already
# made (ParaView's Apply runs one stage at a time) keeps its map when stage 3 is added: neither it
# nor the image reader runs again. Both ways give the same labels.
def made_at(proxy):
    """When the proxy's output was last made (its own data object; Fetch returns copies)."""
    return proxy.GetClientSideObject().GetOutputDataObject(0).GetMTime()


def smoothed_chain(d, update_each):
    image = ft.OpenDataFile(os.path.join(d, "image.mha"))
    so = ft.seeds(os.path.join(d, "seeds_object.csv"))
    sb = ft.seeds(os.path.join(d, "seeds_background.csv"))
    mesh = ft.DelaunayImageMesh(Nodes=ft.FeatureNodes(Input=image), Image=image)
    made = {}
    if update_each:
        mesh.UpdatePipeline()
        made = {p: made_at(p) for p in (image, mesh)}
    smooth = ft.ImageMeshSmoothing(Mesh=mesh, Image=image)
    cut = ft.SuperVoxelCut(Mesh=smooth, ObjectSeeds=so, BackgroundSeeds=sb, Image=image)
    cut.UpdatePipeline()
    again = [p.GetXMLLabel() for p, t in made.items() if made_at(p) != t]
    has = [ft.fm.owner_map(p) is not None for p in (mesh, smooth)]
    return has, again, ft.fm.labels(cut)


for case in ("nuclei-dsb2018", "brain-tumour-brats-0006"):
    if ft.fm.case_dir(case) is None:
        print("skipped (no %s)" % case)
        continue
    at_once, _, labels_at_once = smoothed_chain(ft.fm.case_dir(case), False)
    each, again, labels_each = smoothed_chain(ft.fm.case_dir(case), True)
    ft.check(at_once == [False, True], "%s at once: stage 2 without an owner map, stage 3 with one (%s)" % (case, at_once))
    ft.check(each == [False, True] and not again,
             "%s one stage at a time: stage 3 releases stage 2's map, nothing upstream runs again (%s, re-run %s)" % (case, each, again))
    ft.check(np.array_equal(labels_at_once, labels_each), "%s: the same labels both ways" % case)
ft.finish("cut")
