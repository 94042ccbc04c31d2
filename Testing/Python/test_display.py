"""Display defaults after Show (the GUI's Apply uses the same controller): the meshes of stages 2
and 3 with their edges, coloured by their elements' quality; the cut's labelled mesh with its edges,
coloured by Label; 2D and 3D."""
import fmtest as ft

for case in ("nuclei-dsb2018", "liver-ct-totalseg"):
    c = ft.fm.Case(ft.case_dir(case))
    nodes, mesh, cut = c.pipeline()
    smooth = c.smoothing(mesh)
    quality = "MinDihedralAngle" if c.is3d else "MinAngle"
    view = ft.ps.CreateRenderView()
    for name, proxy, port, representation, colour in (
            ("Delaunay Image Mesh", mesh, 0, "Surface With Edges", ["CELLS", quality]),
            ("Image Mesh Smoothing", smooth, 0, "Surface With Edges", ["CELLS", quality]),
            ("Super-Voxel Cut", cut, 0, "Surface With Edges", ["CELLS", "Label"])):
        shown = ft.ps.Show(ft.ps.OutputPort(proxy, port), view)
        ft.check(shown.Representation == representation and list(shown.ColorArrayName) == colour,
                 "%s %s: %s coloured by %s (got %s, %s)" % (case, name, representation, colour[1], shown.Representation,
                                                           list(shown.ColorArrayName)))
ft.finish()
