"""NIfTI input: the bundled liver written as .nii.gz (nibabel; the .mha's LPS frame as a RAS affine)
reads back with the same voxels and frame, gives the .mha's labels through stages 1 -> 2 -> 4, and
the main script reads it."""
import json
import os
import shutil
import subprocess

import nibabel

import fmtest as ft

np = ft.np
out = ft.scratch("featuremesh-nifti-")


def to_nifti(mha, path):
    """Writes the image at `mha` as NIfTI: RAS affine = diag(-1, -1, 1) x the LPS frame."""
    image = ft.fetch(ft.ps.OpenDataFile(mha))
    dims = image.GetDimensions()
    lps = np.eye(4)
    direction = np.array([image.GetDirectionMatrix().GetElement(r, c) for r in range(3) for c in range(3)]).reshape(3, 3)
    lps[:3, :3] = direction * np.array(image.GetSpacing())
    lps[:3, 3] = image.GetOrigin()
    values = ft.v2n(image.GetPointData().GetScalars())
    data = values.reshape(dims, order="F")
    nibabel.save(nibabel.Nifti1Image(data, np.diag([-1.0, -1.0, 1.0, 1.0]) @ lps), path)
    return values


d = ft.case_dir("liver-ct-totalseg")
nii = os.path.join(out, "liver.nii.gz")
values = to_nifti(os.path.join(d, "image.mha"), nii)
read = ft.fetch(ft.fm.open_image(nii))
mha = ft.fetch(ft.ps.OpenDataFile(os.path.join(d, "image.mha")))
ft.check(np.array_equal(ft.v2n(read.GetPointData().GetScalars()), values), "liver: the same voxel values")
ft.check(np.allclose(read.GetOrigin(), mha.GetOrigin()) and np.allclose(read.GetSpacing(), mha.GetSpacing()),
         "liver: the same origin and spacing (%s, %s)" % (read.GetOrigin(), read.GetSpacing()))
labels = []
for image in (os.path.join(d, "image.mha"), nii):
    case = ft.fm.Case(d, image=image)
    _, mesh, cut = case.pipeline()
    labels.append(ft.fm.labels(cut))
ft.check(np.array_equal(labels[0], labels[1]), "liver: the .nii.gz gives the .mha's labels (%d object voxels)" % labels[0].sum())

# An oblique, mirrored frame: each voxel's world position is the affine's, in LPS.
theta = 0.3
rotation = np.array([[np.cos(theta), -np.sin(theta), 0], [np.sin(theta), np.cos(theta), 0], [0, 0, -1.0]])
affine = np.eye(4)
affine[:3, :3] = rotation * np.array([0.8, 1.2, 2.5])
affine[:3, 3] = [10.0, -20.0, 5.0]
oblique = os.path.join(out, "oblique.nii")
nibabel.save(nibabel.Nifti1Image(np.arange(24, dtype=np.int16).reshape((2, 3, 4), order="F"), affine), oblique)
image = ft.fetch(ft.fm.open_image(oblique))
worst = 0.0
for ijk in ((0, 0, 0), (1, 2, 3), (1, 0, 2)):
    world = [0.0, 0.0, 0.0]
    image.TransformIndexToPhysicalPoint(*ijk, world)
    want = (np.diag([-1.0, -1.0, 1.0]) @ (affine @ np.array(ijk + (1,)))[:3])
    worst = max(worst, float(np.abs(np.array(world) - want).max()))
    value = ft.v2n(image.GetPointData().GetScalars())[ijk[0] + 2 * (ijk[1] + 3 * ijk[2])]
    ft.check(value == ijk[0] + 2 * (ijk[1] + 3 * ijk[2]), "oblique: voxel %s holds its value" % (ijk,))
ft.check(worst < 1e-5, "oblique: voxel positions are the affine's in LPS, to its float32 storage (worst %.2g)" % worst)

script = os.path.join(ft.fm.ROOT, "scripts", "featuremesh_segment.py")
run = subprocess.run([shutil.which("pvpython"), script, nii, "--object-seeds", os.path.join(d, "seeds_object.csv"),
                      "--background-seeds", os.path.join(d, "seeds_background.csv"), "--out", out],
                     capture_output=True, text=True)
ft.check(run.returncode == 0, "the main script reads .nii.gz (stderr: %s)" % run.stderr[-600:])
report = os.path.join(out, "liver_report.json")
ft.check(os.path.isfile(report) and json.load(open(report))["object_elements"] > 0, "the main script's report names the case 'liver'")
ft.finish()
