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
        # An image whose values are cell data (as the GDAL reader gives a PNG) enables Feature Nodes.
        cell_image = ps.PointDatatoCellData(Input=image)
        cell_image.UpdatePipeline()
        lines.append("%s: FeatureNodes is enabled with a cell-data image selected" % ("ok" if enabled("FeatureNodes", cell_image) else "FAIL"))
        # The cut after Apply in the GUI's render view: its labelled mesh with edges, coloured by Label.
        cut = SuperVoxelCut(Mesh=mesh, ObjectSeeds=ps.PolyPointSource(Points=[24, 24, 0]),  # noqa: F821
                            BackgroundSeeds=ps.PolyPointSource(Points=[2, 2, 0, 45, 45, 0]), Image=image)
        cut.UpdatePipeline()
        shown = ps.Show(cut, ps.GetActiveViewOrCreate("RenderView"))
        ok = shown.Representation == "Surface With Edges" and list(shown.ColorArrayName) == ["CELLS", "Label"] and shown.Visibility == 1
        lines.append("%s: the cut shows Surface With Edges coloured by Label (%s, %s)" % ("ok" if ok else "FAIL", shown.Representation,
                                                                                         list(shown.ColorArrayName)))
        lut = ps.GetColorTransferFunction("Label")
        names = list(lut.Annotations)
        ok = lut.InterpretValuesAsCategories == 1 and names[:4] == ["0", "background", "1", "object"]
        lines.append("%s: Label gets a categorical legend (%s)" % ("ok" if ok else "FAIL", names))
        # In 3D the labelled mesh's outer faces are the image box: the GUI shows the boundary instead.
        volume = ps.Wavelet(WholeExtent=[0, 15, 0, 15, 0, 15])
        mesh3 = DelaunayImageMesh(Nodes=FeatureNodes(Input=volume), Image=volume)  # noqa: F821
        cut3 = SuperVoxelCut(Mesh=mesh3, ObjectSeeds=ps.PolyPointSource(Points=[8, 8, 8]),  # noqa: F821
                             BackgroundSeeds=ps.PolyPointSource(Points=[1, 1, 1, 14, 14, 14]), Image=volume)
        cut3.UpdatePipeline()
        view = ps.GetActiveViewOrCreate("RenderView")
        box, boundary = (ps.Show(ps.OutputPort(cut3, port), view) for port in (0, 1))
        ok = box.Visibility == 0 and boundary.Visibility == 1
        lines.append("%s: in 3D the cut shows its boundary, not the box of its labelled mesh (visibility %d, %d)"
                     % ("ok" if ok else "FAIL", box.Visibility, boundary.Visibility))
        # Feature Nodes made with RSP selected: RSP's image as Input, RSP as Edge Map (no Change Input).
        rsp = RSPEdgeEnhancement(Input=image, ObjectSeeds=ps.PolyPointSource(Points=[24, 24, 0]),  # noqa: F821
                                 BackgroundSeeds=ps.PolyPointSource(Points=[2, 2, 0]))
        rsp.UpdatePipeline()  # as after its Apply
        lines.append("%s: FeatureNodes is enabled with RSP Edge Enhancement selected" % ("ok" if enabled("FeatureNodes", rsp) else "FAIL"))
        aware = FeatureNodes(Input=rsp)  # noqa: F821
        ok = aware.Input.SMProxy == image.SMProxy and aware.EdgeMap is not None and aware.EdgeMap.SMProxy == rsp.SMProxy
        aware.UpdatePipeline()
        edges = sm.Fetch(aware, idx=1).GetPointData().GetArray("EdgeMap") if ok else None
        lines.append("%s: FeatureNodes from RSP gets the image as Input and RSP as Edge Map (%s)"
                     % ("ok" if ok and edges is not None else "FAIL", aware.Input.GetXMLName()))
        cells = sm.Fetch(mesh).GetNumberOfCells()
        lines.append(("ok: the GUI session meshes the image (%d triangles)" if cells > 0 else "FAIL: no mesh (%d cells)") % cells)
except Exception:
    lines.append("FAIL: " + traceback.format_exc().replace("\n", " | "))
with open(os.environ["FEATUREMESH_GUI_OUT"], "w") as f:
    f.write("\n".join(lines) + "\n")
os._exit(0)
