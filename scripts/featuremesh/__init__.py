"""FeatureMesh from pvpython: plugin lookup, cases, seeds, the pipeline, Dice.

One place for the glue the main script, the benchmarks and the tests share:

    import featuremesh as fm
    fm.load_plugin()                      # $FEATUREMESH_PLUGIN, else build/**/FeatureMesh.so
    case = fm.Case(fm.case_dir("nuclei-dsb2018"))
    cut = case.super_voxel_cut(case.mesh(case.feature_nodes()))
    print(fm.dice(fm.labels(cut), case.truth()))
"""
import csv
import glob
import os

import numpy as np
from paraview import servermanager as sm
import paraview.simple as ps
from vtkmodules.util.numpy_support import vtk_to_numpy as v2n

from . import names  # noqa: F401  (featuremesh.names.Label ...)

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DATA = os.environ.get("FEATUREMESH_DATA", os.path.join(ROOT, "Data"))
SHARED = os.environ.get("FEATUREMESH_SHARED_DATA", os.path.join(os.path.dirname(ROOT), "shared", "data"))

__all__ = ["ROOT", "DATA", "SHARED", "np", "v2n", "names", "find_plugin", "load_plugin", "cases", "case_dir", "seeds", "fetch",
           "labels", "element_owners", "element_labels", "dice", "case_task", "Case", "open_image", "multilabel_cases", "MultiLabelCase", "label_names_from_csv"]


def find_plugin():
    """$FEATUREMESH_PLUGIN, else the plugin in the repository's build/ tree."""
    path = os.environ.get("FEATUREMESH_PLUGIN")
    if path:
        return path
    hits = sorted(glob.glob(os.path.join(ROOT, "build", "**", "FeatureMesh.so"), recursive=True))
    if not hits:
        raise SystemExit("FeatureMesh.so not found: build the project (bash scripts/setup.sh) or set FEATUREMESH_PLUGIN")
    return hits[0]


_loaded = []


def load_plugin(path=None, ns=None):
    """Loads the plugin once; its filters join paraview.simple (and `ns` when given)."""
    if not _loaded:
        ps.LoadPlugin(path or find_plugin(), ns=None)
        _loaded.append(True)
    if ns is not None:
        for name in ("FeatureNodes", "DelaunayImageMesh", "ImageMeshSmoothing", "RSPEdgeEnhancement", "SuperVoxelCut",
                     "VoxelCut", "SegmentationSurfaceSmoothing"):
            ns[name] = getattr(ps, name)


def cases(selection=()):
    """{name: folder} of the bundled cases, then those of the shared data; `selection` (names, or a
    comma-separated string as the scripts' --cases take it) filters by name."""
    if isinstance(selection, str):
        selection = [c for c in selection.split(",") if c]
    found = {}
    for root in (DATA, os.path.join(SHARED, "cases")):
        for image in sorted(glob.glob(os.path.join(root, "*", "image.mha"))):
            found.setdefault(os.path.basename(os.path.dirname(image)), os.path.dirname(image))
    return {k: v for k, v in found.items() if not selection or k in selection}


def case_task(name, folder=None):
    """The task a case's seeds ask for ("object" or "class"), from the cases.csv beside its `folder`
    when given (a made case's list), else the shared data's, else Data/cases.csv; None when no list
    names it."""
    roots = [os.path.dirname(os.path.normpath(folder))] if folder else []
    for root in roots + [os.path.join(SHARED, "cases"), DATA]:
        path = os.path.join(root, "cases.csv")
        if os.path.isfile(path):
            with open(path, newline="") as f:
                for row in csv.DictReader(f):
                    if row.get("case") == name and row.get("task"):
                        return row["task"]
    return None


def case_dir(name):
    """The folder of case `name` (bundled first), or None."""
    return cases([name]).get(name)


def seeds(arg):
    """A point-set proxy from a CSV file (columns x,y,z, world coordinates) or from "x,y,z;x,y,z"."""
    if os.path.isfile(arg):
        return ps.TableToPoints(Input=ps.CSVReader(FileName=[arg]), XColumn="x", YColumn="y", ZColumn="z")
    coords = [float(v) for p in arg.split(";") if p.strip() for v in p.split(",")]
    return ps.PolyPointSource(Points=coords)


NIFTI_SUFFIXES = (".nii", ".nii.gz")


def open_image(path):
    """A ParaView source of the image at `path`: NIfTI (.nii, .nii.gz) through nibabel, every other
    format through ParaView's readers. NIfTI's affine is RAS; it becomes the LPS origin, spacing and
    direction matrix that ITK and MetaImage use, so that the world coordinates of a case's seeds mean
    the same voxels in its .mha and in its .nii. Channels (a fourth axis) become components."""
    if not path.lower().endswith(NIFTI_SUFFIXES):
        return voxel_valued(ps.OpenDataFile(path))
    import nibabel
    from vtkmodules.util.numpy_support import numpy_to_vtk
    from vtkmodules.vtkCommonDataModel import vtkImageData
    nifti = nibabel.load(path)
    data = np.asanyarray(nifti.dataobj)
    if data.ndim < 3:
        data = data.reshape(data.shape + (1,) * (3 - data.ndim))
    lps = np.diag([-1.0, -1.0, 1.0, 1.0]) @ nifti.affine
    spacing = np.linalg.norm(lps[:3, :3], axis=0)
    direction = lps[:3, :3] / spacing
    channels = data.shape[3] if data.ndim > 3 else 1
    image = vtkImageData()
    image.SetDimensions(*data.shape[:3])
    image.SetSpacing(*spacing)
    image.SetOrigin(*lps[:3, 3])
    image.SetDirectionMatrix(*direction.ravel())
    # Voxel (i, j, k) at i + nx (j + ny k): NIfTI's first axis runs fastest, as VTK's does.
    values = numpy_to_vtk(np.ascontiguousarray(data.reshape((-1, channels), order="F")), deep=True)
    values.SetName("NIfTI")
    image.GetPointData().SetScalars(values)
    source = ps.TrivialProducer()
    source.GetClientSideObject().SetOutput(image)
    source.UpdatePipeline()
    return source


def voxel_valued(source):
    """`source`, or, when its image carries its values as cell data (ParaView's GDAL reader gives a
    PNG or TIFF so, each cell a pixel), a source of the image of its cell centres with those values
    as point data: what the filters do with such an image (VoxelValuedImage), made once so that the
    script's views, truth and Dice read point data."""
    source.UpdatePipeline()
    if source.PointData.keys() or not source.CellData.keys():
        return source
    from vtkmodules.vtkCommonDataModel import vtkDataSetAttributes, vtkImageData
    cells = fetch(source)
    extent = list(cells.GetExtent())
    half = [0.0, 0.0, 0.0]
    for a in range(3):
        if extent[2 * a + 1] > extent[2 * a]:
            extent[2 * a + 1] -= 1
            half[a] = 0.5
    # Index i of the new image is the old continuous index i + 1/2: its origin is the old (1/2, ...).
    origin = [0.0, 0.0, 0.0]
    cells.TransformContinuousIndexToPhysicalPoint(*half, origin)
    image = vtkImageData()
    image.SetExtent(extent)
    image.SetSpacing(cells.GetSpacing())
    image.SetDirectionMatrix(cells.GetDirectionMatrix())
    image.SetOrigin(origin)
    image.GetPointData().ShallowCopy(cells.GetCellData())
    image.GetPointData().RemoveArray(vtkDataSetAttributes.GhostArrayName())
    producer = ps.TrivialProducer()
    producer.GetClientSideObject().SetOutput(image)
    producer.UpdatePipeline()
    return producer


def owner_map(proxy, port=0):
    """The voxel -> element map (vtkIntArray) a stage 2 or 3 proxy keeps on its output's information
    (key FeatureMesh.VOXEL_OWNERS), or None. Writers and Fetch leave it behind, so this reads the
    output object itself: builtin sessions (pvpython, the tests) only."""
    from vtkmodules.vtkCommonCore import vtkInformationIterator
    info = proxy.GetClientSideObject().GetOutputDataObject(port).GetInformation()
    keys = vtkInformationIterator()
    keys.SetInformation(info)
    keys.InitTraversal()
    while not keys.IsDoneWithTraversal():
        key = keys.GetCurrentKey()
        if key.GetLocation() == "FeatureMesh" and key.GetName() == "VOXEL_OWNERS":
            return info.Get(key)
        keys.GoToNextItem()
    return None


def fetch(proxy, port=0):
    return sm.Fetch(proxy, idx=port)


def labels(cut, port=2):
    """The label image of a cut proxy (Super-Voxel Cut port 2, or Voxel Cut port 0) as a flat array."""
    return v2n(fetch(cut, port).GetPointData().GetScalars())


def element_owners(mesh):
    """A stage 2 or 3 proxy's voxel -> element map as a flat int64 array, -1 where no element owns
    the voxel."""
    return v2n(owner_map(mesh)).ravel().astype(np.int64)


def element_labels(cut, mesh, owner=None):
    """The Super-Voxel Cut's elements' labels on the voxels each element owns, flat (0 where none
    does): the label image without the voxel refinement, the labelling the mesh's oracle bounds.
    `mesh` is the cut's mesh proxy (stage 2 or 3), whose owner map it reads unless `owner`
    (element_owners of it) is given."""
    owner = element_owners(mesh) if owner is None else owner
    cells = v2n(fetch(cut, 0).GetCellData().GetArray(names.Label))
    out = np.zeros(owner.shape, dtype=cells.dtype)
    inside = owner >= 0
    out[inside] = cells[owner[inside]]
    return out


def parse_properties(text):
    """{name: number} from "Lambda=1,Connectivity=0" (a script's --cut or --surface argument)."""
    return {k: int(v) if v.lstrip("-").isdigit() else float(v) for k, v in (p.split("=") for p in text.split(",") if p)}


def dice(a, b):
    a, b = np.asarray(a).astype(bool), np.asarray(b).astype(bool)
    return 2.0 * (a & b).sum() / max(1, a.sum() + b.sum())


class Case:
    """A case folder (image.mha, seeds_object.csv, seeds_background.csv, optional truth.mha) and its
    pipeline with fresh proxies on every call; properties pass through as keyword arguments. Both cuts
    get the case's task (cases.csv: "object" or "class"; the filters' default when none is listed)
    unless the keywords set Task."""

    def __init__(self, folder, image=None, object_seeds=None, background_seeds=None):
        self.folder = folder
        self.name = os.path.basename(os.path.normpath(folder))
        self.image = open_image(image or os.path.join(folder, "image.mha"))
        self.image.UpdatePipeline()
        self.scalars = ["POINTS", self.image.PointData.keys()[0]]
        self.object_seeds = seeds(object_seeds or os.path.join(folder, "seeds_object.csv"))
        self.background_seeds = seeds(background_seeds or os.path.join(folder, "seeds_background.csv"))
        self.is3d = fetch(self.image).GetDimensions()[2] > 1
        self.task = case_task(self.name, folder)

    def with_task(self, properties):
        """`properties` with Task set to the case's task, unless they set it."""
        if self.task and "Task" not in properties:
            properties = dict(properties, Task=self.task.capitalize())
        return properties

    def truth(self):
        path = os.path.join(self.folder, "truth.mha")
        return v2n(fetch(ps.OpenDataFile(path)).GetPointData().GetScalars()) if os.path.isfile(path) else None

    def feature_nodes(self, edges=None, **properties):
        """Feature Nodes; `edges` (an RSP Edge Enhancement proxy) feeds its Edge Map input."""
        if edges is not None:
            properties["EdgeMap"] = edges
        return ps.FeatureNodes(Input=self.image, Scalars=self.scalars, **properties)

    def rsp(self, **properties):
        return ps.RSPEdgeEnhancement(Input=self.image, ObjectSeeds=self.object_seeds,
                                     BackgroundSeeds=self.background_seeds, Scalars=self.scalars, **properties)

    def mesh(self, nodes, **properties):
        return ps.DelaunayImageMesh(Nodes=nodes, Image=self.image, Scalars=self.scalars, **properties)

    def smoothing(self, mesh, **properties):
        return ps.ImageMeshSmoothing(Mesh=mesh, Image=self.image, Scalars=self.scalars, **properties)

    def super_voxel_cut(self, mesh, **properties):
        return ps.SuperVoxelCut(Mesh=mesh, ObjectSeeds=self.object_seeds, BackgroundSeeds=self.background_seeds,
                                Image=self.image, Scalars=self.scalars, **self.with_task(properties))

    def surface_smoothing(self, cut, **properties):
        """Segmentation Surface Smoothing of a Super-Voxel Cut proxy (port 0 the smoothed boundary, 1 the labelled mesh)."""
        return ps.SegmentationSurfaceSmoothing(LabelledMesh=ps.OutputPort(cut, 0), **properties)

    def voxel_cut(self, **properties):
        return ps.VoxelCut(Input=self.image, ObjectSeeds=self.object_seeds, BackgroundSeeds=self.background_seeds,
                           Scalars=self.scalars, **self.with_task(properties))

    def pipeline(self, **properties):
        """(nodes, mesh, cut) proxies; `properties` maps a filter name to its keyword arguments."""
        nodes = self.feature_nodes(**properties.get("FeatureNodes", {}))
        mesh = self.mesh(nodes, **properties.get("DelaunayImageMesh", {}))
        return nodes, mesh, self.super_voxel_cut(mesh, **properties.get("SuperVoxelCut", {}))


def multilabel_cases(selection=()):
    """{name: folder} of the multi-label cases (Data/multilabel, then the shared data's multilabel/),
    filtered by `selection` as cases() does."""
    if isinstance(selection, str):
        selection = [c for c in selection.split(",") if c]
    found = {}
    for root in (os.path.join(DATA, "multilabel"), os.path.join(SHARED, "multilabel")):
        for image in sorted(glob.glob(os.path.join(root, "*", "image.mha"))):
            found.setdefault(os.path.basename(os.path.dirname(image)), os.path.dirname(image))
    return {k: v for k, v in found.items() if not selection or k in selection}


def label_names_from_csv(path):
    """[name of label 0, 1, .., k] from a CSV with columns label,name (label 0 is "background" unless listed)."""
    with open(path, newline="") as f:
        rows = {int(r["label"]): r["name"] for r in csv.DictReader(f)}
    return [rows.get(k, "background" if k == 0 else "label_%d" % k) for k in range(max(rows) + 1)]


class MultiLabelCase:
    """A multi-label case folder (image.mha of one or more channels, seeds.csv with x,y,z,label,
    labels.csv, optional truth.mha). Stages 1-3 run on the first channel; the cuts get every
    channel and the labelled seeds straight from the CSV reader."""

    def __init__(self, folder, seeds_file=None):
        self.folder = folder
        self.name = os.path.basename(os.path.normpath(folder))
        self.image = ps.OpenDataFile(os.path.join(folder, "image.mha"))
        self.image.UpdatePipeline()
        self.array = self.image.PointData.keys()[0]
        self.channels = self.image.PointData[self.array].GetNumberOfComponents()
        if self.channels > 1:
            self.first = ps.ExtractComponent(Input=self.image, InputArray=["POINTS", self.array], Component=0,
                                             OutputArrayName="Channel0")
            self.first_scalars = ["POINTS", "Channel0"]
        else:
            self.first, self.first_scalars = self.image, ["POINTS", self.array]
        self.seeds = ps.CSVReader(FileName=[seeds_file or os.path.join(folder, "seeds.csv")])
        self.names = label_names_from_csv(os.path.join(folder, "labels.csv"))

    def truth(self):
        path = os.path.join(self.folder, "truth.mha")
        return v2n(fetch(ps.OpenDataFile(path)).GetPointData().GetScalars()) if os.path.isfile(path) else None

    def seed_rows(self):
        """[(x, y, z, label)] of seeds.csv."""
        with open(os.path.join(self.folder, "seeds.csv"), newline="") as f:
            return [(float(r["x"]), float(r["y"]), float(r["z"]), int(r["label"])) for r in csv.DictReader(f)]

    def mesh(self, smoothing=True):
        """Stages 1 -> 2 (-> 3) on the first channel: the main job's pipeline."""
        nodes = ps.FeatureNodes(Input=self.first, Scalars=self.first_scalars)
        mesh = ps.DelaunayImageMesh(Nodes=nodes, Image=self.first, Scalars=self.first_scalars)
        return ps.ImageMeshSmoothing(Mesh=mesh, Image=self.first, Scalars=self.first_scalars) if smoothing else mesh

    def super_voxel_cut(self, mesh, **properties):
        properties.setdefault("LabelNames", ";".join(self.names))
        return ps.SuperVoxelCut(Mesh=mesh, Seeds=self.seeds, Image=self.image, Scalars=["POINTS", self.array], **properties)

    def voxel_cut(self, **properties):
        properties.setdefault("LabelNames", ";".join(self.names))
        return ps.VoxelCut(Input=self.image, Seeds=self.seeds, Scalars=["POINTS", self.array], **properties)
