"""Held-out object cases: binary Task Object cases made from the multi-label cases' references, on
which no default was chosen (benchmark_seeds.py --held-out, benchmark_clicks.py --held-out). Each
abdomen organ but the liver (the liver case's own image), and BraTS's tumour core (core + enhancing)
and enhancing tumour on T1c, the regions BraTS scores beside the whole tumour (the binary cases'
object, on FLAIR)."""
import os
import zlib

import numpy as np
from vtkmodules.util.numpy_support import numpy_to_vtk
from vtkmodules.vtkCommonDataModel import vtkImageData
from vtkmodules.vtkImagingCore import vtkImageExtractComponents
from vtkmodules.vtkIOImage import vtkMetaImageReader, vtkMetaImageWriter

import featuremesh as fm
from featuremesh import metrics

# The binary 3D cases' seed files: 10 object seeds, 20 background seeds.
SEEDS = (10, 20)

# (multi-label case, name, its labels that form the object, image channel) of each held-out object case.
HELD_OUT = [("abdomen-ct-totalseg", "abdomen-spleen", (2,), 0),
            ("abdomen-ct-totalseg", "abdomen-kidney-right", (3,), 0),
            ("abdomen-ct-totalseg", "abdomen-kidney-left", (4,), 0),
            ("abdomen-ct-totalseg", "abdomen-stomach", (5,), 0),
            ("brain-tumour-regions-brats-0005", "brats-0005-tumour-core-t1c", (2, 3), 1),
            ("brain-tumour-regions-brats-0005", "brats-0005-enhancing-t1c", (3,), 1),
            ("brain-tumour-regions-brats-0006", "brats-0006-tumour-core-t1c", (2, 3), 1),
            ("brain-tumour-regions-brats-0006", "brats-0006-enhancing-t1c", (3,), 1)]


def _read(path):
    reader = vtkMetaImageReader()
    reader.SetFileName(path)
    reader.Update()
    return reader.GetOutput()


def cases(root, selection, generator):
    """{name: folder} of the held-out object cases (HELD_OUT), written under `root` as binary case
    folders (one channel's image.mha, truth.mha and seed files drawn by the generator rule) with a
    cases.csv that gives each Task Object."""
    wanted = [c for c in selection.split(",") if c]
    found = fm.multilabel_cases()
    sources = {}  # each multi-label case's image and label array, read once
    out = {}
    for source, name, labels, channel in HELD_OUT:
        if source not in found or (wanted and name not in wanted):
            continue
        if source not in sources:
            truth_image = _read(os.path.join(found[source], "truth.mha"))
            sources[source] = (_read(os.path.join(found[source], "image.mha")), truth_image,
                               fm.v2n(truth_image.GetPointData().GetScalars()))
        multichannel, truth_image, label_array = sources[source]
        folder = os.path.join(root, name)
        os.makedirs(folder, exist_ok=True)
        extract = vtkImageExtractComponents()
        extract.SetInputData(multichannel)
        extract.SetComponents(channel)
        extract.Update()
        image = extract.GetOutput()
        image.GetPointData().GetScalars().SetName("Channel%d" % channel)
        truth = np.isin(label_array, labels).astype(np.uint8)
        mask = vtkImageData()
        mask.ShallowCopy(truth_image)
        mask.GetPointData().SetScalars(numpy_to_vtk(truth, deep=True))
        for data, file in ((image, "image.mha"), (mask, "truth.mha")):
            writer = vtkMetaImageWriter()
            writer.SetFileName(os.path.join(folder, file))
            writer.SetCompression(True)
            writer.SetInputData(data)
            writer.Write()
        rng = np.random.default_rng([generator, zlib.crc32(("files " + name).encode())])
        shape = image.GetDimensions()[::-1]
        obj, bg = metrics.draw_seeds(truth.reshape(shape).astype(bool), SEEDS[0], SEEDS[1], rng)
        origin, spacing = np.array(image.GetOrigin()), np.array(image.GetSpacing())
        for seeds, file in ((obj, "seeds_object.csv"), (bg, "seeds_background.csv")):
            np.savetxt(os.path.join(folder, file), origin + np.asarray(seeds, float) * spacing, delimiter=",",
                       header="x,y,z", comments="", fmt="%.6g")
        out[name] = folder
    with open(os.path.join(root, "cases.csv"), "w") as f:
        f.write("case,task\n" + "".join("%s,object\n" % name for name in out))
    return out
