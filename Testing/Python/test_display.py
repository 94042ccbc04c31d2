"""Display defaults after Show (the GUI's Apply uses the same controller): the meshes of stages 2
and 3 with their edges, coloured by their elements' quality; the cut's labelled mesh with its edges,
coloured by Label; 2D and 3D. RSP Edge Enhancement shows its edge confidence only; the
panels group the controls one dimension ignores."""
import fmtest as ft

for case in ("nuclei-dsb2018", "liver-ct-totalseg"):
    c = ft.fm.Case(ft.case_dir(case))
    nodes, mesh, cut = c.pipeline()
    smooth = c.smoothing(mesh)
    quality = ft.names.MinDihedralAngle if c.is3d else ft.names.MinAngle
    view = ft.ps.CreateRenderView()
    for name, proxy, port, representation, colour in (
            ("Delaunay Image Mesh", mesh, 0, "Surface With Edges", ["CELLS", quality]),
            ("Image Mesh Smoothing", smooth, 0, "Surface With Edges", ["CELLS", quality]),
            ("Super-Voxel Cut", cut, 0, "Surface With Edges", ["CELLS", ft.names.Label])):
        shown = ft.ps.Show(ft.ps.OutputPort(proxy, port), view)
        ft.check(shown.Representation == representation and list(shown.ColorArrayName) == colour,
                 "%s %s: %s coloured by %s (got %s, %s)" % (case, name, representation, colour[1], shown.Representation,
                                                           list(shown.ColorArrayName)))

# What Apply shows: the controller's preferred view, None where a port's hint says so.
controller = ft.ps.servermanager.vtkSMParaViewPipelineControllerWithRendering()
c = ft.fm.Case(ft.case_dir("nuclei-dsb2018"))
rsp = c.rsp()
rsp.UpdatePipeline()
view = ft.ps.CreateRenderView()
shown = [controller.ShowInPreferredView(rsp.SMProxy, port, view.SMProxy) is not None for port in range(3)]
ft.check(shown == [True, False, False], "RSP Edge Enhancement: Apply shows the edge confidence only (%s)" % shown)
edges = ft.ps.GetDisplayProperties(ft.ps.OutputPort(rsp, 0), view)
ft.check(list(edges.ColorArrayName) == ["POINTS", ft.names.EdgeConfidence], "RSP: coloured by EdgeConfidence (%s)" % list(edges.ColorArrayName))

def unconnected(xml_name):
    return ft.ps.servermanager.vtkSMProxyManager.GetProxyManager().NewProxy("filters", xml_name)


for name, make, want in (
        ("Delaunay Image Mesh", "DelaunayImageMesh", {"3D images only (tetrahedra)": ["Backend", "QualityRefinement", "RadiusEdgeRatio", "MinDihedralAngle"]}),
        ("Image Mesh Smoothing", "ImageMeshSmoothing", {"2D images only (triangles)": ["MinAngle"],
                                                            "3D images only (tetrahedra)": ["MinDihedralAngle", "MaxDihedralAngle", "SliverRemoval", "SliverAngle",
                                                                                            "DihedralFloor"]})):
    proxy = unconnected(make)
    groups = {}
    for g in range(proxy.GetNumberOfPropertyGroups()):
        group = proxy.GetPropertyGroup(g)
        groups[group.GetXMLLabel()] = [proxy.GetPropertyName(group.GetProperty(i)) for i in range(group.GetNumberOfProperties())]
    ft.check(groups == want, "%s: the panel groups the controls by dimension (%s)" % (name, groups))
lam = unconnected("SuperVoxelCut").GetProperty("Lambda").FindDomain("vtkSMDoubleRangeDomain")
ft.check(lam.GetMaximum(0) == 2.0 and lam.GetMinimum(0) == 0.0, "Super-Voxel Cut: the Lambda slider runs 0-2 around 0.2")
ft.finish()
