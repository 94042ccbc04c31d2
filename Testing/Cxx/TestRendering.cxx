// Rendering regression tests: each scene runs the filters on bundled data and compares the
// picture with a committed baseline (vtkRegressionTestImage, -V baseline -T temporary dir).
#include "vtkDelaunayImageMesh.h"
#include "vtkImageMeshSmoothing.h"
#include "vtkFeatureNodes.h"
#include "vtkRSPEdgeEnhancement.h"
#include "vtkSegmentationSurfaceSmoothing.h"
#include "vtkSuperVoxelCut.h"

#include "vtkActor.h"
#include "vtkLookupTable.h"
#include "vtkBox.h"
#include "vtkCamera.h"
#include "vtkCellArray.h"
#include "vtkDataSetMapper.h"
#include "vtkExtractGeometry.h"
#include "vtkFieldData.h"
#include "vtkImageActor.h"
#include "vtkImageData.h"
#include "vtkImageMapToColors.h"
#include "vtkImageMapper3D.h"
#include "vtkImageProperty.h"
#include "vtkMetaImageReader.h"
#include "vtkNew.h"
#include "vtkPlane.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRegressionTestImage.h"
#include "vtkRenderWindow.h"
#include "vtkRenderer.h"
#include "vtkTableBasedClipDataSet.h"
#include "vtkUnstructuredGrid.h"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

namespace
{
vtkSmartPointer<vtkPolyData> ReadSeeds(const std::string& file)
{
  auto pd = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> pts;
  std::ifstream in(file);
  std::string line;
  std::getline(in, line); // header x,y,z
  while (std::getline(in, line))
  {
    std::stringstream ss(line);
    double x[3];
    char comma;
    if (ss >> x[0] >> comma >> x[1] >> comma >> x[2])
    {
      pts->InsertNextPoint(x);
    }
  }
  pd->SetPoints(pts);
  return pd;
}

// One point array of an image through a lookup table (values above the range black: the marching
// maps are infinite beyond their thresholds).
void AddColouredImage(vtkRenderer* ren, vtkImageData* image, const char* array, double lo, double hi, bool log)
{
  vtkNew<vtkLookupTable> table;
  table->SetTableRange(log ? std::max(1.0, lo) : lo, hi);
  if (log)
  {
    table->SetScaleToLog10();
  }
  table->SetHueRange(0.7, 0.0);
  table->SetBelowRangeColor(0, 0, 0, 1);
  table->SetAboveRangeColor(0, 0, 0, 1);
  table->UseBelowRangeColorOn();
  table->UseAboveRangeColorOn();
  table->Build();
  vtkNew<vtkImageData> copy;
  copy->ShallowCopy(image);
  copy->GetPointData()->SetActiveScalars(array);
  vtkNew<vtkImageMapToColors> colours;
  colours->SetInputData(copy);
  colours->SetLookupTable(table);
  colours->Update();
  vtkNew<vtkImageActor> actor;
  actor->GetMapper()->SetInputConnection(colours->GetOutputPort());
  actor->SetPosition(0, 0, -0.5);
  ren->AddViewProp(actor);
}

void AddPoints(vtkRenderer* ren, vtkPolyData* points, double r, double g, double b, double size)
{
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputData(points);
  mapper->ScalarVisibilityOff();
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(r, g, b);
  actor->GetProperty()->SetPointSize(size);
  actor->GetProperty()->SetLineWidth(2);
  actor->SetPosition(0, 0, 1);
  ren->AddActor(actor);
}

// Halves the window: `ren` on the left, a new renderer with the same camera on the right (returned;
// the window holds it).
vtkRenderer* SideBySide(vtkRenderWindow* win, vtkRenderer* ren)
{
  win->SetSize(800, 400);
  ren->SetViewport(0, 0, 0.5, 1);
  vtkNew<vtkRenderer> right;
  right->SetBackground(0.1, 0.1, 0.15);
  right->SetViewport(0.5, 0, 1, 1);
  right->SetActiveCamera(ren->GetActiveCamera());
  win->AddRenderer(right);
  return right;
}

void AddImage(vtkRenderer* ren, vtkImageData* image, double window, double level)
{
  vtkNew<vtkImageActor> actor;
  actor->GetMapper()->SetInputData(image);
  actor->GetProperty()->SetColorWindow(window);
  actor->GetProperty()->SetColorLevel(level);
  actor->SetPosition(0, 0, -0.5);
  ren->AddViewProp(actor);
}
} // namespace

int main(int argc, char* argv[])
{
  if (argc < 3)
  {
    std::cerr << "usage: " << argv[0] << " Scene DataDir -V baseline.png -T tmpdir\n";
    return 1;
  }
  const std::string scene = argv[1], data = argv[2];
  const bool liver = scene.rfind("Liver", 0) == 0 || scene == "SegmentationMesh";
  // DataDir is the bundled data, or one case folder (to draw a shared case by hand).
  const bool oneCase = std::ifstream(data + "/image.mha").good();
  const std::string caseDir = oneCase ? data + "/" : data + (liver ? "/liver-ct-totalseg/" : "/nuclei-dsb2018/");

  vtkNew<vtkMetaImageReader> reader;
  reader->SetFileName((caseDir + "image.mha").c_str());
  reader->Update();
  vtkImageData* image = reader->GetOutput();

  vtkNew<vtkFeatureNodes> nodes;
  nodes->SetInputConnection(reader->GetOutputPort());
  vtkNew<vtkDelaunayImageMesh> mesh;
  mesh->SetInputConnection(0, nodes->GetOutputPort(0));
  mesh->SetInputConnection(1, reader->GetOutputPort());
  vtkNew<vtkImageMeshSmoothing> smoothing;
  smoothing->SetInputConnection(0, mesh->GetOutputPort());
  smoothing->SetInputConnection(1, reader->GetOutputPort());
  vtkNew<vtkSuperVoxelCut> cut;
  cut->SetInputConnection(0, mesh->GetOutputPort());
  cut->SetInputData(1, ReadSeeds(caseDir + "seeds_object.csv"));
  cut->SetInputData(2, ReadSeeds(caseDir + "seeds_background.csv"));
  cut->SetInputConnection(3, reader->GetOutputPort());
  // The main job's cut (on the smoothed mesh) and Segmentation Surface Smoothing of it.
  vtkNew<vtkSuperVoxelCut> smoothedCut;
  smoothedCut->SetInputConnection(0, smoothing->GetOutputPort());
  smoothedCut->SetInputData(1, ReadSeeds(caseDir + "seeds_object.csv"));
  smoothedCut->SetInputData(2, ReadSeeds(caseDir + "seeds_background.csv"));
  smoothedCut->SetInputConnection(3, reader->GetOutputPort());
  // The task a user gives: every nucleus like the seeded ones; the one liver or tumour.
  const int task = liver || oneCase ? 0 : 1;
  cut->SetTask(task);
  smoothedCut->SetTask(task);
  vtkNew<vtkSegmentationSurfaceSmoothing> surface;
  surface->SetInputConnection(smoothedCut->GetOutputPort(0));

  vtkNew<vtkRenderer> ren;
  ren->SetBackground(0.1, 0.1, 0.15);
  vtkNew<vtkRenderWindow> win;
  win->SetSize(400, 400);
  win->AddRenderer(ren);
  win->SetMultiSamples(0);

  if (scene == "NucleiNodes")
  {
    nodes->Update();
    AddImage(ren, image, 120, 60);
    vtkNew<vtkPolyDataMapper> mapper;
    mapper->SetInputConnection(nodes->GetOutputPort(0));
    mapper->SetScalarRange(0, 3);
    mapper->SetColorModeToMapScalars();
    vtkNew<vtkActor> actor;
    actor->SetMapper(mapper);
    actor->GetProperty()->SetPointSize(3);
    actor->SetPosition(0, 0, 1);
    ren->AddActor(actor);
  }
  else if (scene == "NucleiMesh")
  {
    vtkNew<vtkDataSetMapper> mapper;
    mapper->SetInputConnection(mesh->GetOutputPort());
    mapper->SetScalarModeToUseCellFieldData();
    mapper->SelectColorArray("MeanIntensity");
    mapper->SetScalarRange(0, 120);
    vtkNew<vtkActor> actor;
    actor->SetMapper(mapper);
    actor->GetProperty()->EdgeVisibilityOn();
    actor->GetProperty()->SetEdgeColor(0.2, 0.2, 0.2);
    ren->AddActor(actor);
  }
  else if (scene == "NucleiSegmentation")
  {
    AddImage(ren, image, 120, 60);
    vtkNew<vtkPolyDataMapper> mapper;
    mapper->SetInputConnection(cut->GetOutputPort(1));
    mapper->ScalarVisibilityOff();
    vtkNew<vtkActor> actor;
    actor->SetMapper(mapper);
    actor->GetProperty()->SetColor(1, 0.2, 0.2);
    actor->GetProperty()->SetLineWidth(2);
    actor->SetPosition(0, 0, 1);
    ren->AddActor(actor);
  }
  else if (scene == "LiverMesh")
  {
    vtkNew<vtkPlane> plane;
    plane->SetOrigin(180, 150, 45);
    plane->SetNormal(0, 0, 1);
    vtkNew<vtkTableBasedClipDataSet> clip;
    clip->SetInputConnection(mesh->GetOutputPort());
    clip->SetClipFunction(plane);
    clip->InsideOutOn();
    vtkNew<vtkDataSetMapper> mapper;
    mapper->SetInputConnection(clip->GetOutputPort());
    mapper->SetScalarModeToUseCellFieldData();
    mapper->SelectColorArray("MeanIntensity");
    mapper->SetScalarRange(-150, 250);
    vtkNew<vtkActor> actor;
    actor->SetMapper(mapper);
    actor->GetProperty()->EdgeVisibilityOn();
    actor->GetProperty()->SetEdgeColor(0.1, 0.1, 0.1);
    ren->AddActor(actor);
    ren->GetActiveCamera()->Elevation(-50);
  }
  else if (scene == "LiverSurface")
  {
    vtkNew<vtkPolyDataMapper> mapper;
    mapper->SetInputConnection(cut->GetOutputPort(1));
    mapper->ScalarVisibilityOff();
    vtkNew<vtkActor> actor;
    actor->SetMapper(mapper);
    actor->GetProperty()->SetColor(0.8, 0.45, 0.35);
    ren->AddActor(actor);
    ren->GetActiveCamera()->Elevation(-60);
    ren->GetActiveCamera()->Azimuth(20);
  }
  else if (scene == "NucleiSmoothing" || scene == "LiverSmoothing")
  {
    // Before (left) and after (right) Image Mesh Smoothing: a nuclei close-up coloured by the
    // elements' mean intensity, the liver clipped and coloured by the minimum dihedral angle.
    vtkRenderer* right = SideBySide(win, ren);
    vtkNew<vtkPlane> plane;
    plane->SetOrigin(180, 150, 45);
    plane->SetNormal(0, 0, 1);
    vtkAlgorithm* sources[2] = { mesh, smoothing };
    vtkRenderer* renderers[2] = { ren, right };
    for (int side = 0; side < 2; ++side)
    {
      vtkNew<vtkTableBasedClipDataSet> clip;
      clip->SetInputConnection(sources[side]->GetOutputPort());
      clip->SetClipFunction(plane);
      clip->InsideOutOn();
      vtkNew<vtkDataSetMapper> mapper;
      mapper->SetInputConnection(liver ? clip->GetOutputPort() : sources[side]->GetOutputPort());
      mapper->SetScalarModeToUseCellFieldData();
      mapper->SelectColorArray(liver ? "MinDihedralAngle" : "MeanIntensity");
      // Liver: red 0 deg, through yellow, to blue at 30 deg and above; nuclei: grey levels.
      vtkNew<vtkLookupTable> table;
      if (liver)
      {
        table->SetHueRange(0.0, 0.65);
      }
      else
      {
        table->SetSaturationRange(0.0, 0.0);
        table->SetValueRange(0.15, 1.0);
      }
      table->Build();
      mapper->SetLookupTable(table);
      mapper->UseLookupTableScalarRangeOff();
      liver ? mapper->SetScalarRange(0, 30) : mapper->SetScalarRange(0, 120);
      vtkNew<vtkActor> actor;
      actor->SetMapper(mapper);
      actor->GetProperty()->EdgeVisibilityOn();
      actor->GetProperty()->SetEdgeColor(0.1, 0.1, 0.1);
      renderers[side]->AddActor(actor);
    }
    if (liver)
    {
      ren->ResetCamera();
      ren->GetActiveCamera()->Elevation(-50);
      ren->GetActiveCamera()->Zoom(1.25);
    }
    else
    {
      // A 90-pixel close-up around a nucleus.
      vtkCamera* camera = ren->GetActiveCamera();
      camera->ParallelProjectionOn();
      camera->SetFocalPoint(300, 200, 0);
      camera->SetPosition(300, 200, 500);
      camera->SetViewUp(0, 1, 0);
      camera->SetParallelScale(45);
    }
    ren->ResetCameraClippingRange();
  }
  else if (scene == "LiverSurfaceSmoothing")
  {
    // The cut's boundary (left) and Segmentation Surface Smoothing's (right, the defaults: Taubin 10,
    // the labelled mesh moved with it), on the image-smoothed mesh as the main job runs it.
    vtkRenderer* right = SideBySide(win, ren);
    vtkAlgorithmOutput* boundaries[2] = { smoothedCut->GetOutputPort(1), surface->GetOutputPort(0) };
    vtkRenderer* renderers[2] = { ren, right };
    for (int side = 0; side < 2; ++side)
    {
      vtkNew<vtkPolyDataMapper> mapper;
      mapper->SetInputConnection(boundaries[side]);
      mapper->ScalarVisibilityOff();
      vtkNew<vtkActor> actor;
      actor->SetMapper(mapper);
      actor->GetProperty()->SetColor(0.8, 0.45, 0.35);
      actor->GetProperty()->EdgeVisibilityOn();
      actor->GetProperty()->SetEdgeColor(0.35, 0.2, 0.15);
      renderers[side]->AddActor(actor);
    }
    ren->ResetCamera();
    ren->GetActiveCamera()->Elevation(-60);
    ren->GetActiveCamera()->Azimuth(20);
    ren->GetActiveCamera()->Zoom(1.1);
    ren->ResetCameraClippingRange();
  }
  else if (scene == "SegmentationMesh")
  {
    // The labelled mesh with the smoothed interface (object red, background blue-grey), whole
    // elements on one side of a plane through the object's centre: the FEM deliverable. DataDir is
    // one case folder (the baseline is BraTS-0006, from the shared data).
    surface->Update();
    // The elements within 30 voxels of the object seeds' box (the tumour; the cut's small
    // components elsewhere stay out of the picture), then those on one side of a plane through
    // its centre.
    double bounds[6];
    ReadSeeds(caseDir + "seeds_object.csv")->GetBounds(bounds);
    const double margin = 30 * image->GetSpacing()[0];
    vtkNew<vtkBox> near;
    near->SetBounds(bounds[0] - margin, bounds[1] + margin, bounds[2] - margin, bounds[3] + margin, bounds[4] - margin,
      bounds[5] + margin);
    vtkNew<vtkExtractGeometry> around;
    around->SetInputConnection(surface->GetOutputPort(1));
    around->SetImplicitFunction(near);
    around->ExtractInsideOn();
    vtkNew<vtkPlane> plane;
    plane->SetOrigin(0.5 * (bounds[0] + bounds[1]), 0.5 * (bounds[2] + bounds[3]), 0.5 * (bounds[4] + bounds[5]));
    plane->SetNormal(0, 1, 0);
    vtkNew<vtkExtractGeometry> half;
    half->SetInputConnection(around->GetOutputPort());
    half->SetImplicitFunction(plane);
    half->ExtractInsideOn();
    vtkNew<vtkLookupTable> table;
    table->SetNumberOfTableValues(2);
    table->SetTableValue(0, 0.45, 0.5, 0.6);
    table->SetTableValue(1, 0.85, 0.3, 0.25);
    vtkNew<vtkDataSetMapper> mapper;
    mapper->SetInputConnection(half->GetOutputPort());
    mapper->SetScalarModeToUseCellFieldData();
    mapper->SelectColorArray("Label");
    mapper->SetColorModeToMapScalars(); // Label is unsigned char: not colours
    mapper->SetLookupTable(table);
    mapper->UseLookupTableScalarRangeOff();
    mapper->SetScalarRange(0, 1);
    vtkNew<vtkActor> actor;
    actor->SetMapper(mapper);
    actor->GetProperty()->EdgeVisibilityOn();
    actor->GetProperty()->SetEdgeColor(0.1, 0.1, 0.1);
    ren->AddActor(actor);
    // The camera looks at the cut face from +y, a little from above.
    ren->ResetCamera();
    vtkCamera* camera = ren->GetActiveCamera();
    camera->SetFocalPoint(plane->GetOrigin());
    camera->SetPosition(plane->GetOrigin()[0] + 150, plane->GetOrigin()[1] + 300, plane->GetOrigin()[2] + 150);
    camera->SetViewUp(0, 0, 1);
    ren->ResetCamera();
    camera->Zoom(1.3);
    ren->ResetCameraClippingRange();
    win->SetSize(600, 500);
  }
  else if (scene == "NucleiRSP")
  {
    // The thesis's figure set: object marching map, background marching map with the sources (red)
    // and sinks (cyan), the edge confidence (black: no path), the final contour (red) on the image.
    vtkNew<vtkRSPEdgeEnhancement> rsp;
    rsp->SetInputConnection(0, reader->GetOutputPort());
    rsp->SetInputData(1, ReadSeeds(caseDir + "seeds_object.csv"));
    rsp->SetInputData(2, ReadSeeds(caseDir + "seeds_background.csv"));
    rsp->Update();
    vtkImageData* ec = vtkImageData::SafeDownCast(rsp->GetOutputDataObject(0));
    vtkPolyData* samples = vtkPolyData::SafeDownCast(rsp->GetOutputDataObject(2));
    const double T0 = ec->GetFieldData()->GetArray("ObjectThreshold")->GetTuple1(0);
    const double T1 = ec->GetFieldData()->GetArray("BackgroundThreshold")->GetTuple1(0);
    const double paths = ec->GetFieldData()->GetArray("Paths")->GetTuple1(0);
    vtkNew<vtkPolyData> sources, sinks;
    for (int role = 0; role < 2; ++role)
    {
      vtkNew<vtkPoints> pts;
      vtkNew<vtkCellArray> verts;
      vtkDataArray* roles = samples->GetPointData()->GetArray("SampleRole");
      for (vtkIdType i = 0; i < samples->GetNumberOfPoints(); ++i)
      {
        if (roles->GetTuple1(i) == role)
        {
          const vtkIdType id = pts->InsertNextPoint(samples->GetPoint(i));
          verts->InsertNextCell(1, &id);
        }
      }
      vtkPolyData* pd = role == 0 ? sources.Get() : sinks.Get();
      pd->SetPoints(pts);
      pd->SetVerts(verts);
    }
    win->SetSize(1200, 300);
    vtkRenderer* panels[4] = { ren, nullptr, nullptr, nullptr };
    for (int i = 0; i < 4; ++i)
    {
      if (i > 0)
      {
        panels[i] = vtkRenderer::New();
        panels[i]->SetBackground(0.1, 0.1, 0.15);
        panels[i]->SetActiveCamera(ren->GetActiveCamera());
        win->AddRenderer(panels[i]);
        panels[i]->Delete(); // the window holds it
      }
      panels[i]->SetViewport(0.25 * i, 0, 0.25 * (i + 1), 1);
    }
    AddColouredImage(panels[0], ec, "ObjectDistance", 0, T0, false);
    AddColouredImage(panels[1], ec, "BackgroundDistance", 0, T1, false);
    AddPoints(panels[1], sources, 1, 0.2, 0.2, 4);
    AddPoints(panels[1], sinks, 0.2, 1, 1, 4);
    AddColouredImage(panels[2], ec, "EdgeConfidence", 0.5, paths / 20, false);
    AddImage(panels[3], image, 120, 60);
    AddPoints(panels[3], vtkPolyData::SafeDownCast(rsp->GetOutputDataObject(1)), 1, 0.2, 0.2, 2);
    AddPoints(panels[3], ReadSeeds(caseDir + "seeds_object.csv"), 1, 1, 0.2, 6);
    ren->ResetCamera();
    ren->GetActiveCamera()->Zoom(1.3);
  }
  else
  {
    std::cerr << "unknown scene " << scene << "\n";
    return 1;
  }
  if (scene != "NucleiSmoothing" && scene != "LiverSmoothing" && scene != "NucleiRSP" && scene != "LiverSurfaceSmoothing" &&
    scene != "SegmentationMesh")
  {
    ren->ResetCamera();
  }
  if (scene.rfind("Nuclei", 0) == 0 && scene != "NucleiSmoothing" && scene != "NucleiRSP")
  {
    ren->GetActiveCamera()->Zoom(1.4);
  }
  win->Render();
  // A missing baseline is a failure, not a silent pass.
  for (int a = 1; a + 1 < argc; ++a)
  {
    if (std::string(argv[a]) == "-V" && !std::ifstream(argv[a + 1]).good() && !std::getenv("FEATUREMESH_MAKE_BASELINES"))
    {
      std::cerr << "baseline " << argv[a + 1] << " is missing (set FEATUREMESH_MAKE_BASELINES=1 to write it)\n";
      return 1;
    }
  }
  const int result = vtkRegressionTestImage(win);
  return result == vtkRegressionTester::FAILED ? 1 : 0;
}
