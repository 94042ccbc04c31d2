"""Runs inside the ParaView GUI (paraview --script=...): are the FeatureMesh filters there, and does
ParaView enable each one when its main input is selected (it tests the input property named Input,
as pqFiltersMenuReaction does)? Writes ok/FAIL lines to $FEATUREMESH_GUI_OUT, then quits."""
import os
import traceback

lines = []
try:
    from paraview import servermanager as sm
    import paraview.simple as ps

    pxm = sm.vtkSMProxyManager.GetProxyManager().GetActiveSessionProxyManager()
    names = ("FeatureNodes", "DelaunayImageMesh", "ImageMeshSmoothing", "RSPEdgeEnhancement", "SuperVoxelCut", "VoxelCut",
             "SegmentationSurfaceSmoothing")
    missing = [n for n in names if not pxm.GetPrototypeProxy("filters", n)]
    lines.append(("FAIL: missing filters %s" % missing) if missing else "ok: the FeatureMesh filters are loaded")
    if not missing:
        ps._add_functions(globals())
        image = ps.Wavelet(WholeExtent=[0, 47, 0, 47, 0, 0])
        nodes = FeatureNodes(Input=image)  # noqa: F821
        mesh = DelaunayImageMesh(Nodes=nodes, Image=image)  # noqa: F821
        mesh.UpdatePipeline()  # as after Apply: the array domains need the data's information

        def enabled(filter_name, selected):
            prop = pxm.GetPrototypeProxy("filters", filter_name).GetProperty("Input")
            if prop is None:
                return None
            prop.RemoveAllUncheckedProxies()
            prop.AddUncheckedInputConnection(selected.SMProxy, 0)
            ok = bool(prop.IsInDomains())
            prop.RemoveAllUncheckedProxies()
            return ok

        for filter_name, selected, what in (("FeatureNodes", image, "the image"), ("DelaunayImageMesh", nodes, "the nodes"),
                                            ("SuperVoxelCut", mesh, "the mesh"), ("VoxelCut", image, "the image"),
                                            ("SegmentationSurfaceSmoothing", mesh, "a mesh")):
            ok = enabled(filter_name, selected)
            lines.append("%s: %s is enabled with %s selected" % ("ok" if ok else "FAIL", filter_name, what))
        lines.append(("ok" if enabled("DelaunayImageMesh", image) is False else "FAIL") +
                     ": DelaunayImageMesh is not enabled with only the image selected")
        cells = sm.Fetch(mesh).GetNumberOfCells()
        lines.append(("ok: the GUI session meshes the image (%d triangles)" if cells > 0 else "FAIL: no mesh (%d cells)") % cells)
except Exception:
    lines.append("FAIL: " + traceback.format_exc().replace("\n", " | "))
with open(os.environ["FEATUREMESH_GUI_OUT"], "w") as f:
    f.write("\n".join(lines) + "\n")
os._exit(0)
