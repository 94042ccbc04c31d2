"""Export: every .vtu FeatureMesh writes (stage 2's mesh, stage 4's labelled mesh; 2D and 3D) reads
back in meshio with its points, cells and cell arrays intact, and the label images as .vti in VTK."""
import os

import meshio
from vtkmodules.vtkIOXML import vtkXMLImageDataReader, vtkXMLImageDataWriter, vtkXMLUnstructuredGridWriter

import fmtest as ft

out = ft.scratch("featuremesh-export-")
for case in ("nuclei-dsb2018", "liver-ct-totalseg"):
    c = ft.fm.Case(ft.case_dir(case))
    nodes, mesh, cut = c.pipeline()
    cut.UpdatePipeline()
    for tag, data in (("mesh", ft.fetch(mesh)), ("labelled", ft.fetch(cut, 0))):
        path = os.path.join(out, "%s_%s.vtu" % (case, tag))
        w = vtkXMLUnstructuredGridWriter()
        w.SetInputData(data)
        w.SetFileName(path)
        w.Write()
        try:
            m = meshio.read(path)
        except Exception as e:  # noqa: BLE001 -- the failure is the finding
            ft.check(False, "%s %s: meshio reads %s (%s)" % (case, tag, path, e))
            continue
        kind = "triangle" if not c.is3d else "tetra"
        cells = m.cells_dict.get(kind)
        ft.check(cells is not None and len(cells) == data.GetNumberOfCells(), "%s %s: meshio reads %d %s cells" % (case, tag, data.GetNumberOfCells(), kind))
        ft.check(ft.np.array_equal(m.points, ft.v2n(data.GetPoints().GetData())), "%s %s: the same points" % (case, tag))
        ft.check(ft.np.array_equal(cells, ft.v2n(data.GetCells().GetConnectivityArray()).reshape(len(cells), -1)), "%s %s: the same cells" % (case, tag))
        cd = data.GetCellData()
        for i in range(cd.GetNumberOfArrays()):
            name = cd.GetArrayName(i)
            ft.check(name in m.cell_data and ft.np.array_equal(m.cell_data[name][0], ft.v2n(cd.GetArray(i))),
                     "%s %s: cell array %s round-trips" % (case, tag, name))
        ft.check(all(k in m.field_data for k in (ft.names.ImageOrigin, ft.names.ImageSpacing, ft.names.ImageDimensions, ft.names.ImageDirection)),
                 "%s %s: the image frame is in the field data" % (case, tag))
    labels = ft.fetch(cut, 2)
    path = os.path.join(out, "%s_labels.vti" % case)
    w = vtkXMLImageDataWriter()
    w.SetInputData(labels)
    w.SetFileName(path)
    w.Write()
    r = vtkXMLImageDataReader()
    r.SetFileName(path)
    r.Update()
    ft.check(ft.np.array_equal(ft.array(r.GetOutput()), ft.array(labels)), "%s: the label image round-trips as .vti" % case)

# The label image a user saves holds its labels, not the mesh's per-voxel owner map (issue 28):
# ParaView's SaveData in its default format, under twice the label bytes.
c = ft.fm.Case(ft.case_dir("liver-ct-totalseg"))
_, mesh, cut = c.pipeline()
path = os.path.join(out, "liver_labels_saved.vti")
ft.ps.SaveData(path, proxy=ft.ps.OutputPort(cut, 2))
voxels = ft.fetch(cut, 2).GetNumberOfPoints()
ft.check(os.path.getsize(path) < 2 * voxels, "the saved label image is %d bytes for %d voxels" % (os.path.getsize(path), voxels))
ft.check(ft.fetch(cut, 2).GetFieldData().GetArray(ft.names.VoxelOwner) is None, "the label image carries no VoxelOwner")
# Nor do the meshes of stages 2 and 3: a saved mesh holds its elements' arrays, not 4 bytes per voxel.
smooth = c.smoothing(mesh)
for name, proxy in (("Delaunay Image Mesh", mesh), ("Image Mesh Smoothing", smooth)):
    path = os.path.join(out, "liver_%s.vtu" % name.replace(" ", "_"))
    ft.ps.SaveData(path, proxy=proxy)
    data = ft.fetch(proxy)
    ft.check(ft.fm.owner_map(proxy) is not None and data.GetFieldData().GetArray(ft.names.VoxelOwner) is None,
             "%s keeps its owner map off its arrays" % name)
    ft.check(b"VoxelOwner" not in open(path, "rb").read(), "%s: the saved .vtu (%d bytes) holds no owner map (%d bytes)"
             % (name, os.path.getsize(path), 4 * voxels))
