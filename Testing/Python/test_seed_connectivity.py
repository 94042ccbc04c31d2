"""Connectivity of both cuts on a synthetic image: two bright disks, the right one with a dark hole,
an object seed in the left disk only. Seeded Object keeps the left disk alone; Fill Holes (the
default) keeps both and fills the hole; Off keeps both with the hole. The field data count the
object components and give their areas."""
import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk
from vtkmodules.vtkCommonDataModel import vtkImageData

import fmtest as ft

W, H = 96, 48
j, i = np.mgrid[0:H, 0:W]
left = (i - 24) ** 2 + (j - 24) ** 2 <= 14 ** 2
right = ((i - 72) ** 2 + (j - 24) ** 2 <= 14 ** 2) & ((i - 72) ** 2 + (j - 24) ** 2 > 5 ** 2)
hole = (i - 72) ** 2 + (j - 24) ** 2 <= 5 ** 2
values = np.where(left | right, 200.0, 20.0) + 5.0 * np.sin(i * 0.7) * np.cos(j * 0.5)  # a little texture
image_data = vtkImageData()
image_data.SetDimensions(W, H, 1)
array = numpy_to_vtk(values.ravel().astype(np.float32), deep=True)
array.SetName("Intensity")
image_data.GetPointData().SetScalars(array)
image = ft.ps.TrivialProducer()
image.GetClientSideObject().SetOutput(image_data)
image.UpdatePipeline()

so = ft.ps.PolyPointSource(Points=[24, 24, 0, 20, 28, 0])
sb = ft.ps.PolyPointSource(Points=[2, 2, 0, 93, 45, 0, 48, 24, 0, 48, 5, 0])
mesh = ft.DelaunayImageMesh(Nodes=ft.FeatureNodes(Input=image), Image=image)
mesh.UpdatePipeline()


def field(data, name):
    a = data.GetFieldData().GetArray(name)
    return ft.v2n(a) if a is not None else None


for name in ("SuperVoxelCut", "VoxelCut"):
    results = {}
    for mode in (None, 0, 1, 2, "class"):
        # Task Class on the image's values (its default reads their local contrast): the rule alone differs.
        props = {} if mode is None else ({"Task": "Class", "Intensity": "Image"} if mode == "class" else {"Connectivity": mode})
        if name == "SuperVoxelCut":
            cut = ft.SuperVoxelCut(Mesh=mesh, ObjectSeeds=so, BackgroundSeeds=sb, Image=image, **props)
            out = ft.fetch(cut, 2)
        else:
            cut = ft.VoxelCut(Input=image, ObjectSeeds=so, BackgroundSeeds=sb, Scalars=["POINTS", "Intensity"], **props)
            out = ft.fetch(cut, 0)
        L = ft.array(out).reshape(H, W).astype(bool)
        results[mode] = (L, field(out, ft.names.ObjectComponents), field(out, ft.names.ObjectComponentVolumes))
    off, fill, seeded = results[0][0], results[1][0], results[2][0]
    # Elements straddle the disks' edges: the super-voxel labels are right up to them.
    good, bad = (0.9, 0.3) if name == "SuperVoxelCut" else (0.99, 0.01)
    ft.check((results[None][0] == seeded).all(), "%s: the default (Task Object, Connectivity From Task) is Seeded Object" % name)
    ft.check((results["class"][0] == fill).all(), "%s: Task Class (Connectivity From Task) is Fill Holes" % name)
    ft.check(off[left].mean() > good and off[right].mean() > good and off[hole].mean() < bad,
             "%s, off: both disks, the hole background (%.2f %.2f %.2f)" % (name, off[left].mean(), off[right].mean(), off[hole].mean()))
    ft.check(fill[left].mean() > good and fill[right].mean() > good and fill[hole].all(),
             "%s, fill holes: both disks and the hole" % name)
    ft.check(seeded[left].mean() > good and not seeded[right | hole].any(),
             "%s, seeded object: the seeded disk alone" % name)
    ft.check(seeded[~left].sum() <= 0.05 * left.sum(), "%s, seeded object: nothing outside the seeded disk" % name)
    ft.check(results[0][1][0] == 2 and results[1][1][0] == 2 and results[2][1][0] == 1,
             "%s: ObjectComponents 2 / 2 / 1 (got %s)" % (name, [results[m][1][0] for m in (0, 1, 2)]))
    volumes = results[1][2]
    ft.check(len(volumes) == 2 and abs(volumes.sum() - fill.sum()) < 1e-9 and volumes[0] >= volumes[1],
             "%s: ObjectComponentVolumes sum to the object area, largest first (%s)" % (name, volumes))
ft.finish("seed-connectivity")
