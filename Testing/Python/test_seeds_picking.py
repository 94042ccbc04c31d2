"""Seeds by clicking: points picked in the render view (Select Points On, one click per seed, as
the GUI's toolbar does through the same selection proxies) and Extract Selection connect to the
Super-Voxel Cut's seed ports as they are; the cut equals the one from the same points written to a
CSV and read through the CSV reader and Table To Points. Each pick lands within two pixels' worth
of voxels of where it was aimed."""
import os

import fmtest as ft

np = ft.np
ps = ft.ps
d = ft.case_dir("nuclei-dsb2018")
case = ft.fm.Case(d)
_, mesh, _ = case.pipeline()

view = ps.CreateRenderView(ViewSize=[1024, 1024])
shown = ps.Show(case.image, view)
shown.Representation = "Surface"
view.InteractionMode = "2D"
ps.ResetCamera(view)
ps.Render(view)
renderer = view.GetRenderer()


def picked(csv):
    """The image points picked where each seed of `csv` shows on screen, as Extract Selection gives them."""
    aimed = np.loadtxt(csv, delimiter=",", skiprows=1, ndmin=2)
    ps.ClearSelection(case.image)
    for i, p in enumerate(aimed):
        renderer.SetWorldPoint(p[0], p[1], p[2], 1.0)
        renderer.WorldToDisplay()
        x, y, _ = (int(round(v)) for v in renderer.GetDisplayPoint())
        ps.SetActiveSource(case.image)
        ps.SelectSurfacePoints(Rectangle=[x, y, x, y], View=view, Modifier=None if i == 0 else "ADD")
    # Extract Selection keeps its copy of the selection when the next kind's clicks replace it.
    frozen = ps.ExtractSelection(Input=case.image)
    points = ft.fetch(frozen)
    got = np.array([points.GetPoint(i) for i in range(points.GetNumberOfPoints())])
    return frozen, aimed, got


seeds = {}
out = ft.scratch("featuremesh-picking-")
for kind in ("object", "background"):
    frozen, aimed, got = picked(os.path.join(d, "seeds_%s.csv" % kind))
    ft.check(len(got) == len(aimed), "%s: one point per click (%d of %d)" % (kind, len(got), len(aimed)))
    worst = max(np.abs(got[:, :2] - a[:2]).max(axis=1).min() for a in aimed) if len(got) else np.inf
    ft.check(worst <= 3, "%s: every click picks a voxel within 3 of its aim (worst %.0f)" % (kind, worst))
    csv = os.path.join(out, "%s.csv" % kind)
    np.savetxt(csv, got, delimiter=",", header="x,y,z", comments="")
    table = ps.TableToPoints(Input=ps.CSVReader(FileName=[csv]), XColumn="x", YColumn="y", ZColumn="z")
    seeds[kind] = (frozen, table)

labels = [ft.fm.labels(ps.SuperVoxelCut(Mesh=mesh, ObjectSeeds=seeds["object"][k], BackgroundSeeds=seeds["background"][k],
                                        Image=case.image, Task="Class")) for k in (0, 1)]
truth = case.truth()
ft.check(labels[0].sum() > 1000, "the picked seeds segment the nuclei (%d pixels, Dice %.3f)" % (labels[0].sum(), ft.dice(labels[0] > 0, truth > 0)))
ft.check(np.array_equal(labels[0], labels[1]), "picked seeds give the labels of the same points through CSV and Table To Points")
ft.finish()
