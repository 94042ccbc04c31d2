"""Seeds in one step: a CSV of x, y, z opened with ParaView's CSV reader connects straight to the
seed ports of the Super-Voxel Cut, the Voxel Cut and RSP Edge Enhancement, and gives the labels of
the CSV -> Table To Points path; a seed port given an image is a clear error."""
import os

import fmtest as ft

np = ft.np
d = ft.case_dir("nuclei-dsb2018")
case = ft.fm.Case(d)
tables = {k: ft.ps.CSVReader(FileName=[os.path.join(d, "seeds_%s.csv" % k)]) for k in ("object", "background")}
_, mesh, _ = case.pipeline()
for name, make in (("Super-Voxel Cut", lambda o, b: ft.ps.SuperVoxelCut(Mesh=mesh, ObjectSeeds=o, BackgroundSeeds=b, Image=case.image, Task="Class")),
                   ("Voxel Cut", lambda o, b: ft.ps.VoxelCut(Input=case.image, ObjectSeeds=o, BackgroundSeeds=b, Task="Class"))):
    points = ft.fm.labels(make(case.object_seeds, case.background_seeds), 2 if name == "Super-Voxel Cut" else 0)
    csv = ft.fm.labels(make(tables["object"], tables["background"]), 2 if name == "Super-Voxel Cut" else 0)
    ft.check(np.array_equal(points, csv) and points.sum() > 0, "%s: the CSV reader's table gives the point set's labels" % name)
rsp = [ft.ps.RSPEdgeEnhancement(Input=case.image, ObjectSeeds=o, BackgroundSeeds=b)
       for o, b in ((case.object_seeds, case.background_seeds), (tables["object"], tables["background"]))]
edges = [ft.array(ft.fetch(r), ft.names.EdgeConfidence) for r in rsp]
ft.check(np.array_equal(edges[0], edges[1]), "RSP Edge Enhancement: the same edge confidence from the CSV reader")
bad = ft.ps.SuperVoxelCut(Mesh=mesh, ObjectSeeds=case.image, BackgroundSeeds=tables["background"], Image=case.image)
bad.UpdatePipeline()
ft.check(ft.fetch(bad, 0).GetNumberOfCells() == 0, "an image on a seed port: an error and an empty output")
ft.finish()
