"""Images whose values are cell data: the bundled nuclei written as a 16-bit PNG and read by
ParaView's GDAL reader (each cell a pixel, as the GUI and OpenDataFile read it) give the .mha's
labels through stages 1 -> 2 -> 3 -> 4 and in the Voxel Cut, with every filter reading the cell
array directly; the main script segments the PNG."""
import json
import os
import shutil
import subprocess

from vtkmodules.vtkImagingCore import vtkImageFlip
from vtkmodules.vtkIOImage import vtkPNGWriter

import fmtest as ft

np = ft.np
out = ft.scratch("featuremesh-formats-")
d = ft.case_dir("nuclei-dsb2018")
mha = ft.ps.OpenDataFile(os.path.join(d, "image.mha"))
image = ft.fetch(mha)
values = ft.v2n(image.GetPointData().GetScalars())

# GDAL puts the file's first row at y = 0, PNG's writer the image's last: flip so the pixels match.
flip = vtkImageFlip()
flip.SetInputData(image)
flip.SetFilteredAxis(1)
writer = vtkPNGWriter()
writer.SetInputConnection(flip.GetOutputPort())
png = os.path.join(out, "nuclei.png")
writer.SetFileName(png)
writer.Write()

gdal = ft.ps.OpenDataFile(png)
ft.check(gdal.GetXMLName() == "GDALRasterReader", "OpenDataFile reads a PNG with GDAL (%s)" % gdal.GetXMLName())
gdal.UpdatePipeline()
cells = ft.fetch(gdal)
ft.check(cells.GetPointData().GetNumberOfArrays() == 0 and cells.GetCellData().GetNumberOfArrays() > 0,
         "the GDAL image carries its values as cell data")
ft.check(np.array_equal(ft.v2n(cells.GetCellData().GetScalars()), values), "the PNG's pixels are the .mha's voxels")
cell_array = ["CELLS", gdal.CellData.keys()[0]]

# The cell centres lie half a pixel from the .mha's voxel centres: the same seeds by index.
shift = (np.array(cells.GetOrigin()) + 0.5 * np.array(cells.GetSpacing()) - np.array(image.GetOrigin())) * [1, 1, 0]
seed_sources = {}
for kind in ("object", "background"):
    points = np.loadtxt(os.path.join(d, "seeds_%s.csv" % kind), delimiter=",", skiprows=1, ndmin=2)
    moved = os.path.join(out, "seeds_%s.csv" % kind)
    np.savetxt(moved, points + shift, delimiter=",", header="x,y,z", comments="")
    seed_sources[kind] = (os.path.join(d, "seeds_%s.csv" % kind), moved)


def segment(source, scalars, which):
    so, sb = (ft.seeds(seed_sources[k][which]) for k in ("object", "background"))
    nodes = ft.ps.FeatureNodes(Input=source, Scalars=scalars)
    mesh = ft.ps.DelaunayImageMesh(Nodes=nodes, Image=source, Scalars=scalars)
    smooth = ft.ps.ImageMeshSmoothing(Mesh=mesh, Image=source, Scalars=scalars)
    cut = ft.ps.SuperVoxelCut(Mesh=smooth, ObjectSeeds=so, BackgroundSeeds=sb, Image=source, Scalars=scalars)
    voxel = ft.ps.VoxelCut(Input=source, ObjectSeeds=so, BackgroundSeeds=sb, Scalars=scalars)
    rsp = ft.ps.RSPEdgeEnhancement(Input=source, ObjectSeeds=so, BackgroundSeeds=sb, Scalars=scalars)
    edges = ft.fetch(rsp).GetPointData().GetArray(ft.names.EdgeConfidence)
    return ft.fm.labels(cut), ft.fm.labels(voxel, 0), ft.v2n(edges), ft.fetch(smooth).GetNumberOfCells()


from_mha = segment(mha, ["POINTS", mha.PointData.keys()[0]], 0)
from_png = segment(gdal, cell_array, 1)
ft.check(from_mha[0].sum() > 1000, "the .mha's cut finds the nuclei (%d pixels)" % from_mha[0].sum())
ft.check(from_mha[3] == from_png[3], "the same smoothed mesh size (%d, %d elements)" % (from_mha[3], from_png[3]))
ft.check(np.array_equal(from_mha[0], from_png[0]), "Super-Voxel Cut: the PNG gives the .mha's labels")
ft.check(np.array_equal(from_mha[1], from_png[1]), "Voxel Cut: the PNG gives the .mha's labels")
ft.check(np.array_equal(from_mha[2], from_png[2]), "RSP Edge Enhancement: the PNG gives the .mha's edge confidence")

script = os.path.join(ft.fm.ROOT, "scripts", "featuremesh_segment.py")
run = subprocess.run([shutil.which("pvpython"), script, png, "--object-seeds", seed_sources["object"][1],
                      "--background-seeds", seed_sources["background"][1], "--out", out],
                     capture_output=True, text=True)
ft.check(run.returncode == 0, "the main script reads the PNG (stderr: %s)" % run.stderr[-600:])
report = os.path.join(out, "nuclei_report.json")
ft.check(os.path.isfile(report) and json.load(open(report))["object_elements"] > 0, "the main script segments the PNG")
ft.finish()
