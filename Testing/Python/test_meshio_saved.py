"""Every .vtu a stage produces, saved by ParaView's SaveData (2D and 3D: stages 2, 3, 4 and 6), reads
in meshio with its cells when the appended data is base64-encoded (EncodeAppendedData, the writer's
"Encode Appended Data"). In ParaView's default raw encoding meshio reads a file exactly when its
offsets do not collide: meshio re-encodes raw blocks one by one, finding each block's DataArray by
its offset, and a block whose new base64 offset equals a later block's raw offset takes that later
block's place (a meshio bug; `offset_collisions` replays it). This test fails if a file without a
collision fails or one with a collision reads: either would change what the README says."""
import math
import os
import re

import meshio

import fmtest as ft

np = ft.np
out = ft.scratch("featuremesh-meshio-")


def offset_collisions(path):
    """Names of the DataArrays meshio's raw-appended re-encoding (meshio 5, vtu/_vtu.py) would
    rewrite in place of another's: meshio takes the first DataArray whose offset equals each raw
    block's, and rewritten offsets are base64 positions."""
    raw = open(path, "rb").read()
    header = raw[:raw.find(b"<AppendedData")].decode()
    arrays = [(m.group(1), int(m.group(2))) for m in re.finditer(r'<DataArray[^>]*?Name="([^"]+)"[^>]*?offset="(\d+)\s*"', header)]
    start = re.search(rb'<AppendedData[^>]+">', raw).end()
    data = raw[start:raw.find(b"</AppendedData>")].split(b"_", 1)[1].rsplit(b"\n", 1)[0]
    width = 8 if 'header_type="UInt64"' in header else 4
    current = [o for _, o in arrays]
    wrong, encoded, i = [], 0, 0
    while i < len(data):
        taken = current.index(i)
        owner = [o for _, o in arrays].index(i)
        if taken != owner:
            wrong.append(arrays[owner][0])
        current[taken] = encoded
        size = int.from_bytes(data[i:i + width], "little")
        encoded += 4 * math.ceil((size + width) / 3)
        i += size + width
    return wrong


def meshio_cells(path, kind):
    try:
        return len(meshio.read(path).cells_dict.get(kind, []))
    except Exception:  # noqa: BLE001 -- the failure is what is counted
        return None


abdomen = os.path.join(ft.DATA, "multilabel", "abdomen-ct-totalseg")
for case in ("nuclei-dsb2018", "liver-ct-totalseg", "abdomen (5 organs)"):
    if case.startswith("abdomen"):
        c = ft.fm.MultiLabelCase(abdomen)
        smooth = c.mesh()
        mesh = smooth.Mesh
        kind = "tetra"
    else:
        c = ft.fm.Case(ft.case_dir(case))
        _, mesh, _ = c.pipeline()
        smooth = c.smoothing(mesh)
        kind = "tetra" if c.is3d else "triangle"
    cut = c.super_voxel_cut(smooth)
    surface = ft.ps.SegmentationSurfaceSmoothing(LabelledMesh=ft.ps.OutputPort(cut, 0))
    for stage, port in (("Delaunay Image Mesh", ft.ps.OutputPort(mesh, 0)), ("Image Mesh Smoothing", ft.ps.OutputPort(smooth, 0)),
                        ("Super-Voxel Cut", ft.ps.OutputPort(cut, 0)), ("Segmentation Surface Smoothing", ft.ps.OutputPort(surface, 1))):
        tag = "%s %s" % (case, stage)
        name = os.path.join(out, tag.replace(" ", "_"))
        ft.ps.SaveData(name + "_base64.vtu", proxy=port, EncodeAppendedData=1)
        ft.ps.SaveData(name + "_raw.vtu", proxy=port)
        got = meshio_cells(name + "_base64.vtu", kind)
        ft.check(got is not None and got > 0, "%s: meshio reads the base64-encoded file (%s %s cells)" % (tag, got, kind))
        wrong = offset_collisions(name + "_raw.vtu")
        raw = meshio_cells(name + "_raw.vtu", kind)
        ft.check((raw == got) == (not wrong), "%s: meshio reads the raw file %s (offset collisions: %s)"
                 % (tag, "(%s cells)" % raw if raw is not None else "not", wrong or "none"))
ft.finish()
