// The bad-input matrix: every filter on empty, degenerate, non-finite, extreme, oriented and
// malformed inputs and absurd properties. Each case asserts its outcome: a clear error naming the
// problem and an empty output, or a correct result. ctest runs every case in its own process with
// a time limit, so a crash or a hang fails one case, not the suite.
#include "Contract.h"
#include "SeedGeodesics.h"
#include "vtkDelaunayImageMesh.h"
#include "vtkFeatureNodes.h"
#include "vtkImageMeshSmoothing.h"
#include "vtkRSPEdgeEnhancement.h"
#include "vtkSegmentationSurfaceSmoothing.h"
#include "vtkSuperVoxelCut.h"
#include "vtkVoxelCut.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkExecutive.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkIdList.h"
#include "vtkImageData.h"
#include "vtkMatrix3x3.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkStringArray.h"
#include "vtkTable.h"
#include "vtkTypeTraits.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <tuple>
#include <vector>

namespace
{
using Point = std::array<double, 3>;

// Collects the errors and warnings a filter reports (and keeps them off the console).
class Messages : public vtkCommand
{
public:
  static Messages* New() { return new Messages; }
  void Execute(vtkObject*, unsigned long event, void* data) override
  {
    (event == vtkCommand::ErrorEvent ? this->Errors : this->Warnings).push_back(static_cast<const char*>(data));
    if (std::getenv("FEATUREMESH_SHOW_MESSAGES"))
    {
      std::cout << (event == vtkCommand::ErrorEvent ? "error: " : "warning: ") << static_cast<const char*>(data);
    }
  }
  std::string All() const
  {
    std::string all;
    for (const auto& e : this->Errors)
      all += e + " | ";
    return all;
  }
  std::vector<std::string> Errors, Warnings;
};

template <typename Filter>
struct Run
{
  vtkNew<Filter> F;
  vtkNew<Messages> Log;
  Run()
  {
    this->F->AddObserver(vtkCommand::ErrorEvent, this->Log);
    this->F->AddObserver(vtkCommand::WarningEvent, this->Log);
    this->F->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, this->Log);
  }
  Filter* operator->() { return this->F.GetPointer(); }
  void Update() { this->F->Update(); }
  bool HasError(const std::string& words) const
  {
    for (const auto& e : this->Log->Errors)
      if (e.find(words) != std::string::npos)
        return true;
    return false;
  }
  bool HasWarning(const std::string& words) const
  {
    for (const auto& w : this->Log->Warnings)
      if (w.find(words) != std::string::npos)
        return true;
    return false;
  }
};

using Fill = std::function<double(int, int, int)>;

vtkSmartPointer<vtkImageData> Image(std::array<int, 3> dims, const Fill& fill, int type = VTK_FLOAT, int components = 1)
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(dims.data());
  vtkSmartPointer<vtkDataArray> a = vtkSmartPointer<vtkDataArray>::Take(vtkDataArray::CreateDataArray(type));
  a->SetName("values");
  a->SetNumberOfComponents(components);
  a->SetNumberOfTuples(static_cast<vtkIdType>(dims[0]) * dims[1] * dims[2]);
  vtkIdType t = 0;
  for (int k = 0; k < dims[2]; ++k)
    for (int j = 0; j < dims[1]; ++j)
      for (int i = 0; i < dims[0]; ++i, ++t)
        for (int c = 0; c < components; ++c)
          a->SetComponent(t, c, fill(i, j, k));
  image->GetPointData()->SetScalars(a);
  return image;
}

// The two base inputs: a noisy 64^2 disc and a noisy 40^3 ball (values ~ 20 background, 100 object).
Fill Noisy(double cx, double cy, double cz, double r)
{
  return [=](int i, int j, int k) {
    const unsigned h = (static_cast<unsigned>(i) * 73856093u) ^ (static_cast<unsigned>(j) * 19349663u) ^
      (static_cast<unsigned>(k) * 83492791u);
    const double noise = static_cast<double>(h % 1000) / 100.0 - 5.0;
    return (std::hypot(i - cx, j - cy, k - cz) <= r ? 100.0 : 20.0) + noise;
  };
}
vtkSmartPointer<vtkImageData> Disc(int type = VTK_FLOAT)
{
  return Image({ { 64, 64, 1 } }, Noisy(31.5, 30.0, 0.0, 16.0), type);
}
vtkSmartPointer<vtkImageData> Ball()
{
  return Image({ { 40, 40, 40 } }, Noisy(19.5, 20.0, 19.0, 11.0));
}

vtkSmartPointer<vtkPolyData> Points(const std::vector<Point>& p)
{
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  for (const auto& x : p)
    pts->InsertNextPoint(x.data());
  poly->SetPoints(pts);
  return poly;
}

// World position of a voxel index of an image.
Point World(vtkImageData* image, double i, double j, double k)
{
  Point w;
  image->TransformContinuousIndexToPhysicalPoint(i, j, k, w.data());
  return w;
}

template <typename T>
vtkSmartPointer<T> Copy(T* data)
{
  auto copy = vtkSmartPointer<T>::New();
  copy->DeepCopy(data);
  return copy;
}

vtkSmartPointer<vtkPolyData> NodesOf(vtkImageData* image)
{
  Run<vtkFeatureNodes> nodes;
  nodes->SetInputData(image);
  nodes.Update();
  EXPECT_TRUE(nodes.Log->Errors.empty()) << nodes.Log->All();
  return Copy(nodes->GetOutput());
}

vtkSmartPointer<vtkUnstructuredGrid> MeshOf(vtkImageData* image, int backend = 0)
{
  Run<vtkDelaunayImageMesh> mesh;
  mesh->SetInputData(0, NodesOf(image));
  mesh->SetInputData(1, image);
  mesh->SetBackend(backend);
  mesh.Update();
  EXPECT_TRUE(mesh.Log->Errors.empty()) << mesh.Log->All();
  return Copy(mesh->GetOutput());
}

// Seeds: in the disc / ball centre, and near a corner.
vtkSmartPointer<vtkPolyData> ObjectSeeds(vtkImageData* image)
{
  const bool is2D = image->GetDimensions()[2] == 1;
  return Points({ World(image, 31, 30, is2D ? 0 : 19), World(image, 33, 31, is2D ? 0 : 20) });
}
vtkSmartPointer<vtkPolyData> BackgroundSeeds(vtkImageData* image)
{
  const bool is2D = image->GetDimensions()[2] == 1;
  return Points({ World(image, 3, 3, is2D ? 0 : 3), World(image, 5, 58 * (is2D ? 1 : 0) + 3, is2D ? 0 : 30) });
}

struct CutOutputs
{
  vtkSmartPointer<vtkUnstructuredGrid> Mesh;
  vtkSmartPointer<vtkImageData> Labels;
};

// Runs the Super-Voxel Cut; `image` may be null (then the mesh's field data give the grid).
template <typename Check>
void SuperVoxelCut(vtkUnstructuredGrid* mesh, vtkPointSet* object, vtkPointSet* background, vtkImageData* image,
  const Check& check, const std::function<void(vtkSuperVoxelCut*)>& set = nullptr)
{
  Run<vtkSuperVoxelCut> cut;
  cut->SetInputData(0, mesh);
  cut->SetInputData(1, object);
  cut->SetInputData(2, background);
  if (image)
    cut->SetInputData(3, image);
  if (set)
    set(cut.F);
  cut.Update();
  check(cut, CutOutputs{ cut->GetOutput(), vtkImageData::SafeDownCast(cut->GetOutputDataObject(2)) });
}

void ExpectCutError(Run<vtkSuperVoxelCut>& cut, const CutOutputs& out, const std::string& words)
{
  EXPECT_TRUE(cut.HasError(words)) << "wanted an error with '" << words << "', got: " << cut.Log->All();
  EXPECT_EQ(out.Mesh->GetNumberOfCells(), 0);
}

// A correct cut: no error, labels of both kinds, every seed's element keeps its seed's label.
void ExpectGoodCut(Run<vtkSuperVoxelCut>& cut, const CutOutputs& out, vtkImageData* image, vtkPointSet* object,
  vtkPointSet* background)
{
  ASSERT_TRUE(cut.Log->Errors.empty()) << cut.Log->All();
  vtkDataArray* label = out.Mesh->GetCellData()->GetArray("Label");
  ASSERT_NE(label, nullptr);
  double object_ = 0;
  for (vtkIdType c = 0; c < label->GetNumberOfTuples(); ++c)
    object_ += label->GetComponent(c, 0);
  EXPECT_GT(object_, 0);
  EXPECT_LT(object_, label->GetNumberOfTuples());
  vtkDataArray* voxels = out.Labels->GetPointData()->GetScalars();
  for (auto [seeds, want] : { std::pair<vtkPointSet*, int>{ object, 1 }, { background, 0 } })
    for (vtkIdType s = 0; s < seeds->GetNumberOfPoints(); ++s)
    {
      double x[3], ijk[3];
      seeds->GetPoint(s, x);
      image->TransformPhysicalPointToContinuousIndex(x, ijk);
      int dims[3];
      image->GetDimensions(dims);
      const vtkIdType v = (static_cast<vtkIdType>(std::lround(ijk[2])) * dims[1] + std::lround(ijk[1])) * dims[0] + std::lround(ijk[0]);
      EXPECT_EQ(voxels->GetComponent(v, 0), want) << "seed " << s;
    }
}

template <typename Filter>
void ExpectError(Run<Filter>& run, const std::string& words, vtkDataObject* output)
{
  EXPECT_TRUE(run.HasError(words)) << "wanted an error with '" << words << "', got: " << run.Log->All();
  vtkDataSet* ds = vtkDataSet::SafeDownCast(output);
  EXPECT_TRUE(!ds || ds->GetNumberOfPoints() == 0) << "the output is not empty";
}

// Feature Nodes on `image`; `check` sees the run and the nodes.
template <typename Check>
void FeatureNodes(vtkImageData* image, const Check& check, const std::function<void(vtkFeatureNodes*)>& set = nullptr,
  vtkImageData* edgeMap = nullptr)
{
  Run<vtkFeatureNodes> nodes;
  nodes->SetInputData(0, image);
  if (edgeMap)
    nodes->SetInputData(1, edgeMap);
  if (set)
    set(nodes.F);
  nodes.Update();
  check(nodes, nodes->GetOutput());
}

void ExpectNodesInside(Run<vtkFeatureNodes>& run, vtkPolyData* nodes, vtkImageData* image, vtkIdType atLeast = 4)
{
  ASSERT_TRUE(run.Log->Errors.empty()) << run.Log->All();
  EXPECT_GE(nodes->GetNumberOfPoints(), atLeast);
  int dims[3];
  image->GetDimensions(dims);
  const int* ext = image->GetExtent();
  for (vtkIdType i = 0; i < nodes->GetNumberOfPoints(); ++i)
  {
    double x[3], ijk[3];
    nodes->GetPoint(i, x);
    image->TransformPhysicalPointToContinuousIndex(x, ijk);
    for (int a = 0; a < 3; ++a)
    {
      ASSERT_NEAR(ijk[a], std::round(ijk[a]), 1e-6) << "node " << i << " is not on a voxel centre";
      ASSERT_GE(std::round(ijk[a]), ext[2 * a]);
      ASSERT_LE(std::round(ijk[a]), ext[2 * a + 1]);
    }
  }
}

template <typename Check>
void DelaunayMesh(vtkPointSet* nodes, vtkImageData* image, const Check& check,
  const std::function<void(vtkDelaunayImageMesh*)>& set = nullptr)
{
  Run<vtkDelaunayImageMesh> mesh;
  mesh->SetInputData(0, nodes);
  mesh->SetInputData(1, image);
  if (set)
    set(mesh.F);
  mesh.Update();
  check(mesh, mesh->GetOutput());
}

// A correct image mesh: PixelCount sums to the voxels, every element has positive measure in the
// image's index space.
template <typename Filter>
void ExpectTiling(Run<Filter>& run, vtkUnstructuredGrid* mesh, vtkImageData* image)
{
  ASSERT_TRUE(run.Log->Errors.empty()) << run.Log->All();
  ASSERT_GT(mesh->GetNumberOfCells(), 0);
  vtkDataArray* count = mesh->GetCellData()->GetArray("PixelCount");
  ASSERT_NE(count, nullptr);
  double total = 0;
  for (vtkIdType c = 0; c < count->GetNumberOfTuples(); ++c)
    total += count->GetComponent(c, 0);
  EXPECT_EQ(total, static_cast<double>(image->GetNumberOfPoints()));
}

template <typename Check>
void VoxelCut(vtkImageData* image, vtkPointSet* object, vtkPointSet* background, const Check& check,
  const std::function<void(vtkVoxelCut*)>& set = nullptr)
{
  Run<vtkVoxelCut> cut;
  cut->SetInputData(0, image);
  cut->SetInputData(1, object);
  cut->SetInputData(2, background);
  if (set)
    set(cut.F);
  cut.Update();
  check(cut, cut->GetOutput());
}

void ExpectGoodVoxelCut(Run<vtkVoxelCut>& run, vtkImageData* labels)
{
  ASSERT_TRUE(run.Log->Errors.empty()) << run.Log->All();
  vtkDataArray* l = labels->GetPointData()->GetScalars();
  ASSERT_NE(l, nullptr);
  double object = 0;
  for (vtkIdType v = 0; v < l->GetNumberOfTuples(); ++v)
    object += l->GetComponent(v, 0);
  EXPECT_GT(object, 0);
  EXPECT_LT(object, l->GetNumberOfTuples());
}

const double NaN = std::numeric_limits<double>::quiet_NaN();
const double Inf = std::numeric_limits<double>::infinity();
} // namespace

//------------------------------------------------------------------------------------------------
// Feature Nodes: images.
TEST(FeatureNodes, EmptyImage)
{
  vtkNew<vtkImageData> empty;
  FeatureNodes(empty, [](auto& run, vtkPolyData* out) { ExpectError(run, "empty", out); });
}
TEST(FeatureNodes, OneVoxel)
{
  auto image = Image({ { 1, 1, 1 } }, [](int, int, int) { return 1.0; });
  FeatureNodes(image, [](auto& run, vtkPolyData* out) { ExpectError(run, "at least 2 voxels", out); });
}
TEST(FeatureNodes, OneByN)
{
  auto image = Image({ { 1, 50, 1 } }, [](int, int j, int) { return j; });
  FeatureNodes(image, [](auto& run, vtkPolyData* out) { ExpectError(run, "at least 2 voxels", out); });
}
TEST(FeatureNodes, NByOneByN)
{
  auto image = Image({ { 30, 1, 30 } }, [](int i, int, int) { return i; });
  FeatureNodes(image, [](auto& run, vtkPolyData* out) { ExpectError(run, "at least 2 voxels", out); });
}
TEST(FeatureNodes, TwoByTwo)
{
  auto image = Image({ { 2, 2, 1 } }, [](int i, int j, int) { return i + j; });
  FeatureNodes(image, [&](auto& run, vtkPolyData* out) { ExpectNodesInside(run, out, image, 4); });
}
TEST(FeatureNodes, NaN)
{
  auto image = Image({ { 32, 32, 1 } }, [](int i, int j, int) { return i == 5 && j == 7 ? NaN : 1.0 * i; });
  FeatureNodes(image, [](auto& run, vtkPolyData* out) { ExpectError(run, "NaN", out); });
}
TEST(FeatureNodes, Infinity)
{
  auto image = Image({ { 32, 32, 1 } }, [](int i, int, int) { return i == 3 ? -Inf : 1.0 * i; }, VTK_DOUBLE);
  FeatureNodes(image, [](auto& run, vtkPolyData* out) { ExpectError(run, "infinite", out); });
}
// Images whose values are cell data (as ParaView's GDAL reader gives a PNG): read at the cell centres.
vtkSmartPointer<vtkImageData> CellValued(vtkImageData* voxels)
{
  auto cells = vtkSmartPointer<vtkImageData>::New();
  int dims[3];
  voxels->GetDimensions(dims);
  cells->SetDimensions(dims[0] + 1, dims[1] + 1, dims[2] > 1 ? dims[2] + 1 : 1);
  cells->GetCellData()->SetScalars(voxels->GetPointData()->GetScalars());
  return cells;
}
TEST(FeatureNodes, CellDataImageIsReadAtTheCellCentres)
{
  auto cells = CellValued(Image({ { 48, 40, 1 } }, Noisy(20, 18, 0, 10)));
  FeatureNodes(cells, [&](auto& run, vtkPolyData* out) {
    ASSERT_TRUE(run.Log->Errors.empty()) << run.Log->All();
    ASSERT_GT(out->GetNumberOfPoints(), 20);
    for (vtkIdType i = 0; i < out->GetNumberOfPoints(); ++i)
    {
      double x[3];
      out->GetPoint(i, x);
      ASSERT_EQ(x[0] - 0.5, std::round(x[0] - 0.5)) << "node " << i << " is not on a cell centre";
      ASSERT_EQ(x[1] - 0.5, std::round(x[1] - 0.5)) << "node " << i << " is not on a cell centre";
      ASSERT_TRUE(x[0] > 0 && x[0] < 48 && x[1] > 0 && x[1] < 40);
    }
  });
}
TEST(FeatureNodes, CellDataWithThreeComponents)
{
  auto cells = CellValued(Image({ { 32, 32, 1 } }, [](int i, int, int) { return i; }, VTK_FLOAT, 3));
  FeatureNodes(cells, [](auto& run, vtkPolyData* out) { ExpectError(run, "components", out); });
}
TEST(FeatureNodes, OneCell)
{
  auto cells = CellValued(Image({ { 1, 1, 1 } }, [](int, int, int) { return 1.0; }));
  FeatureNodes(cells, [](auto& run, vtkPolyData* out) { ExpectError(run, "at least 2 voxels", out); });
}
TEST(FeatureNodes, StepsNearTheFloatLimit)
{
  auto image = Image({ { 64, 64, 1 } }, [](int i, int j, int) { return std::hypot(i - 31.5, j - 30) < 16 ? 3e38 : -3e38; });
  FeatureNodes(image, [&](auto& run, vtkPolyData* out) { ExpectNodesInside(run, out, image, 20); });
}
TEST(FeatureNodes, DenormalValues)
{
  auto image = Image({ { 64, 64, 1 } }, [](int i, int j, int) { return std::hypot(i - 31.5, j - 30) < 16 ? 1e-39 : 1e-41; });
  FeatureNodes(image, [&](auto& run, vtkPolyData* out) { ExpectNodesInside(run, out, image, 20); });
}
TEST(FeatureNodes, DoublesBeyondTheFloatRange)
{
  auto image = Image({ { 32, 32, 1 } }, [](int i, int, int) { return i < 16 ? 1e300 : -1e300; }, VTK_DOUBLE);
  FeatureNodes(image, [](auto& run, vtkPolyData* out) { ExpectError(run, "beyond", out); });
}
TEST(FeatureNodes, DoublesNearTheDoubleLimit)
{
  auto image = Image({ { 32, 32, 1 } }, [](int i, int, int) { return i < 16 ? 1.7e308 : 0.0; }, VTK_DOUBLE);
  FeatureNodes(image, [](auto& run, vtkPolyData* out) { ExpectError(run, "beyond", out); });
}

// Every VTK scalar type.
class ScalarType : public ::testing::TestWithParam<int>
{
};
TEST_P(ScalarType, DiscGivesNodes)
{
  auto image = Image({ { 64, 64, 1 } }, [](int i, int j, int) { return std::hypot(i - 31.5, j - 30) < 16 ? 100 : 20; }, GetParam());
  FeatureNodes(image, [&](auto& run, vtkPolyData* out) { ExpectNodesInside(run, out, image, 20); });
}
INSTANTIATE_TEST_SUITE_P(FeatureNodes, ScalarType,
  ::testing::Values(VTK_CHAR, VTK_SIGNED_CHAR, VTK_UNSIGNED_CHAR, VTK_SHORT, VTK_UNSIGNED_SHORT, VTK_INT,
    VTK_UNSIGNED_INT, VTK_LONG, VTK_UNSIGNED_LONG, VTK_LONG_LONG, VTK_UNSIGNED_LONG_LONG, VTK_FLOAT, VTK_DOUBLE,
    VTK_ID_TYPE));

TEST(FeatureNodes, TwoComponents)
{
  auto image = Image({ { 32, 32, 1 } }, [](int i, int, int) { return i; }, VTK_FLOAT, 2);
  FeatureNodes(image, [](auto& run, vtkPolyData* out) { ExpectError(run, "components", out); });
}
TEST(FeatureNodes, ThreeComponents)
{
  auto image = Image({ { 32, 32, 1 } }, [](int i, int, int) { return i; }, VTK_UNSIGNED_CHAR, 3);
  FeatureNodes(image, [](auto& run, vtkPolyData* out) { ExpectError(run, "components", out); });
}
TEST(FeatureNodes, NoScalars)
{
  vtkNew<vtkImageData> image;
  image->SetDimensions(16, 16, 1);
  FeatureNodes(image, [](auto& run, vtkPolyData* out) { ExpectError(run, "scalars", out); });
}
TEST(FeatureNodes, NegativeSpacing)
{
  auto image = Disc();
  image->SetSpacing(1.0, -0.5, 1.0);
  FeatureNodes(image, [&](auto& run, vtkPolyData* out) { ExpectNodesInside(run, out, image, 20); });
}
TEST(DelaunayImageMesh, SpacingBeyondTheExactRange)
{
  auto image = Ball();
  image->SetSpacing(1e30, 1e30, 1e30);
  DelaunayMesh(NodesOf(Ball()), image, [](auto& run, vtkUnstructuredGrid* out) { ExpectError(run, "1e-12 and 1e12", out); });
}
TEST(DelaunayImageMesh, LargeSpacingTilesExactly)
{
  auto image = Ball();
  image->SetSpacing(1e9, 2e9, 1e9);
  auto nodes = NodesOf(image);
  DelaunayMesh(nodes, image, [&](auto& run, vtkUnstructuredGrid* out) { ExpectTiling(run, out, image); });
}
TEST(FeatureNodes, ZeroSpacing)
{
  auto image = Disc();
  image->SetSpacing(1.0, 0.0, 1.0);
  FeatureNodes(image, [](auto& run, vtkPolyData* out) { ExpectError(run, "spacing", out); });
}
TEST(FeatureNodes, AnisotropicSpacingRotatedDirectionAndOrigin)
{
  auto image = Ball();
  image->SetSpacing(0.5, 1.5, 3.0);
  image->SetOrigin(-100, 20, 7.5);
  const double c = std::cos(0.4), s = std::sin(0.4);
  const double direction[9] = { c, -s, 0, s, c, 0, 0, 0, 1 };
  image->SetDirectionMatrix(direction);
  FeatureNodes(image, [&](auto& run, vtkPolyData* out) { ExpectNodesInside(run, out, image, 50); });
}
TEST(FeatureNodes, SingularDirection)
{
  auto image = Disc();
  const double direction[9] = { 1, 0, 0, 1, 0, 0, 0, 0, 1 };
  image->SetDirectionMatrix(direction);
  FeatureNodes(image, [](auto& run, vtkPolyData* out) { ExpectError(run, "direction", out); });
}
TEST(FeatureNodes, ExtentNotStartingAtZero)
{
  auto image = Disc();
  image->SetExtent(10, 73, -5, 58, 3, 3);
  FeatureNodes(image, [&](auto& run, vtkPolyData* out) { ExpectNodesInside(run, out, image, 20); });
}
TEST(FeatureNodes, ConstantImageWarns)
{
  auto image = Image({ { 32, 32, 1 } }, [](int, int, int) { return 7.0; });
  FeatureNodes(image, [&](auto& run, vtkPolyData* out) {
    ExpectNodesInside(run, out, image, 4);
    ASSERT_FALSE(run.Log->Warnings.empty());
    EXPECT_NE(run.Log->Warnings[0].find("no edges"), std::string::npos);
  });
}
TEST(FeatureNodes, NegativeSigma)
{
  FeatureNodes(Disc(), [](auto& run, vtkPolyData* out) { ExpectError(run, "sigma", out); },
    [](vtkFeatureNodes* f) { f->SetGaussianSigma(-1); });
}
TEST(FeatureNodes, ThresholdsOutOfOrder)
{
  FeatureNodes(Disc(), [](auto& run, vtkPolyData* out) { ExpectError(run, "threshold", out); },
    [](vtkFeatureNodes* f) {
      f->SetLowThreshold(0.8);
      f->SetHighThreshold(0.2);
    });
}
TEST(FeatureNodes, SigmaWiderThanTheImage)
{
  auto image = Disc();
  FeatureNodes(image, [&](auto& run, vtkPolyData* out) { ExpectNodesInside(run, out, image, 4); },
    [](vtkFeatureNodes* f) { f->SetGaussianSigma(40); });
}
TEST(FeatureNodes, ZeroSpacingOfNodes)
{
  FeatureNodes(Disc(), [](auto& run, vtkPolyData* out) { ExpectError(run, "spacing", out); },
    [](vtkFeatureNodes* f) { f->SetUniformSpacing(0); });
}
TEST(FeatureNodes, DenseNodeBudget)
{
  auto image = Disc();
  FeatureNodes(image, [&](auto& run, vtkPolyData* out) { ExpectNodesInside(run, out, image, 64 * 64 / 2); },
    [](vtkFeatureNodes* f) {
      f->SetUniformSpacing(1);
      f->SetBoundarySpacing(1);
      f->SetExclusionWindow(1);
    });
}
TEST(FeatureNodes, EdgeMapOnAnotherGrid)
{
  auto edges = Image({ { 10, 10, 1 } }, [](int, int, int) { return 1; }, VTK_UNSIGNED_CHAR);
  FeatureNodes(Disc(), [](auto& run, vtkPolyData* out) { ExpectError(run, "same grid", out); }, nullptr, edges);
}
TEST(FeatureNodes, EdgeMapEverywhere)
{
  auto image = Disc();
  auto edges = Image({ { 64, 64, 1 } }, [](int, int, int) { return 1; }, VTK_UNSIGNED_CHAR);
  FeatureNodes(image, [&](auto& run, vtkPolyData* out) { ExpectNodesInside(run, out, image, 20); }, nullptr, edges);
}

//------------------------------------------------------------------------------------------------
// Delaunay Image Mesh: nodes and images.
TEST(DelaunayImageMesh, NoNodes)
{
  DelaunayMesh(Points({}), Disc(), [](auto& run, vtkUnstructuredGrid* out) { ExpectError(run, "too few", out); });
}
TEST(DelaunayImageMesh, ThreeNodesIn3D)
{
  auto image = Ball();
  DelaunayMesh(Points({ World(image, 0, 0, 0), World(image, 5, 0, 0), World(image, 0, 5, 0) }), image,
    [](auto& run, vtkUnstructuredGrid* out) { ExpectError(run, "too few", out); });
}
TEST(DelaunayImageMesh, CollinearNodes)
{
  auto image = Disc();
  DelaunayMesh(Points({ World(image, 0, 0, 0), World(image, 5, 5, 0), World(image, 9, 9, 0) }), image,
    [](auto& run, vtkUnstructuredGrid* out) { ExpectError(run, "collinear", out); });
}
TEST(DelaunayImageMesh, CoplanarNodes)
{
  auto image = Ball();
  DelaunayMesh(Points({ World(image, 0, 0, 4), World(image, 9, 0, 4), World(image, 0, 9, 4), World(image, 7, 7, 4) }), image,
    [](auto& run, vtkUnstructuredGrid* out) { ExpectError(run, "coplanar", out); });
}
TEST(DelaunayImageMesh, DuplicatedNodes)
{
  auto image = Disc();
  DelaunayMesh(Points({ World(image, 0, 0, 0), World(image, 9, 0, 0), World(image, 0, 9, 0), World(image, 9, 0, 0) }), image,
    [](auto& run, vtkUnstructuredGrid* out) { ExpectError(run, "duplicate", out); });
}
TEST(DelaunayImageMesh, NodesOutside)
{
  auto image = Disc();
  DelaunayMesh(Points({ World(image, 0, 0, 0), World(image, 90, 0, 0), World(image, 0, 9, 0) }), image,
    [](auto& run, vtkUnstructuredGrid* out) { ExpectError(run, "outside", out); });
}
TEST(DelaunayImageMesh, NodesOffVoxelCentres)
{
  // Off the lattice (as stage 3 leaves nodes): meshed, every voxel owned once.
  auto image = Disc();
  DelaunayMesh(Points({ World(image, 0, 0, 0), World(image, 9.5, 0, 0), World(image, 0, 9.25, 0), World(image, 20, 20, 0),
                 World(image, 31.3, 40.7, 0), World(image, 50.5, 12.5, 0) }),
    image, [&](auto& run, vtkUnstructuredGrid* out) { ExpectTiling(run, out, image); });
}
TEST(DelaunayImageMesh, NodesOffVoxelCentresIn3D)
{
  auto image = Ball();
  auto nodes = NodesOf(image);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-0.45, 0.45);
  for (vtkIdType i = 0; i < nodes->GetNumberOfPoints(); ++i)
  {
    double x[3];
    nodes->GetPoint(i, x);
    bool box = false;
    for (int a = 0; a < 3; ++a)
      box = box || x[a] <= 0.0 || x[a] >= 39.0;
    if (!box)
      nodes->GetPoints()->SetPoint(i, x[0] + jitter(rng), x[1] + jitter(rng), x[2] + jitter(rng));
  }
  DelaunayMesh(nodes, image, [&](auto& run, vtkUnstructuredGrid* out) { ExpectTiling(run, out, image); });
}
TEST(DelaunayImageMesh, NodesOffThe2DPlane)
{
  auto image = Disc();
  DelaunayMesh(Points({ World(image, 0, 0, 0), World(image, 9, 0, 0), World(image, 0, 9, 1) }), image,
    [](auto& run, vtkUnstructuredGrid* out) { ExpectError(run, "slice plane", out); });
}
TEST(DelaunayImageMesh, NaNNode)
{
  auto image = Disc();
  DelaunayMesh(Points({ World(image, 0, 0, 0), World(image, 9, 0, 0), { { NaN, 3, 0 } } }), image,
    [](auto& run, vtkUnstructuredGrid* out) { ExpectError(run, "outside", out); });
}
TEST(DelaunayImageMesh, ImageWithNaN)
{
  auto image = Disc();
  auto bad = Image({ { 64, 64, 1 } }, [](int i, int, int) { return i == 9 ? NaN : 1.0; });
  DelaunayMesh(NodesOf(image), bad, [](auto& run, vtkUnstructuredGrid* out) { ExpectError(run, "NaN", out); });
}
TEST(DelaunayImageMesh, ImageBeyondDoubleSquares)
{
  auto image = Disc();
  auto huge = Image({ { 64, 64, 1 } }, [](int i, int, int) { return i < 30 ? 1e200 : 0.0; }, VTK_DOUBLE);
  DelaunayMesh(NodesOf(image), huge, [](auto& run, vtkUnstructuredGrid* out) { ExpectError(run, "beyond", out); });
}
TEST(DelaunayImageMesh, OnlyCornersIn3D)
{
  auto image = Ball();
  DelaunayMesh(Points({ World(image, 0, 0, 0), World(image, 39, 0, 0), World(image, 0, 39, 0), World(image, 0, 0, 39) }),
    image, [&](auto& run, vtkUnstructuredGrid* out) { ExpectTiling(run, out, image); });
}
TEST(DelaunayImageMesh, Disc)
{
  auto image = Disc();
  DelaunayMesh(NodesOf(image), image, [&](auto& run, vtkUnstructuredGrid* out) { ExpectTiling(run, out, image); });
}
TEST(DelaunayImageMesh, BallWithTetGen)
{
  auto image = Ball();
  DelaunayMesh(NodesOf(image), image, [&](auto& run, vtkUnstructuredGrid* out) { ExpectTiling(run, out, image); });
}
TEST(DelaunayImageMesh, BallWithCGAL)
{
  auto image = Ball();
  DelaunayMesh(NodesOf(image), image, [&](auto& run, vtkUnstructuredGrid* out) { ExpectTiling(run, out, image); },
    [](vtkDelaunayImageMesh* m) { m->SetBackend(vtkDelaunayImageMesh::CGAL); });
}
TEST(DelaunayImageMesh, MirroredDirection)
{
  auto image = Ball();
  const double direction[9] = { -1, 0, 0, 0, 1, 0, 0, 0, 1 };
  image->SetDirectionMatrix(direction);
  DelaunayMesh(NodesOf(image), image, [&](auto& run, vtkUnstructuredGrid* out) { ExpectTiling(run, out, image); });
}
TEST(DelaunayImageMesh, QualityRefinement)
{
  auto image = Ball();
  image->SetSpacing(1.0, 1.5, 2.0);
  DelaunayMesh(NodesOf(image), image,
    [&](auto& run, vtkUnstructuredGrid* out) {
      ExpectTiling(run, out, image);
      vtkDataArray* angle = out->GetCellData()->GetArray("MinDihedralAngle");
      ASSERT_NE(angle, nullptr);
      EXPECT_GE(angle->GetRange()[0], 9.99);
    },
    [](vtkDelaunayImageMesh* m) { m->SetQualityRefinement(true); });
}
TEST(DelaunayImageMesh, RefinementParametersOutOfRange)
{
  auto image = Ball();
  DelaunayMesh(NodesOf(image), image, [](auto& run, vtkUnstructuredGrid* out) { ExpectError(run, "radius-edge", out); },
    [](vtkDelaunayImageMesh* m) {
      m->SetQualityRefinement(true);
      m->SetRadiusEdgeRatio(0.5);
    });
}
// TetGen's refinement did not return with these (the matrix; the liver's nodes, 25 degrees).
TEST(DelaunayImageMesh, RefinementThatNeedNotTerminate)
{
  auto image = Ball();
  for (const auto& set : std::vector<std::function<void(vtkDelaunayImageMesh*)>>{
         [](vtkDelaunayImageMesh* m) { m->SetRadiusEdgeRatio(1.0); }, [](vtkDelaunayImageMesh* m) { m->SetMinDihedralAngle(25); } })
    DelaunayMesh(NodesOf(image), image, [](auto& run, vtkUnstructuredGrid* out) { ExpectError(run, "may not terminate", out); },
      [&](vtkDelaunayImageMesh* m) {
        m->SetQualityRefinement(true);
        set(m);
      });
}

//------------------------------------------------------------------------------------------------
// Super-Voxel Cut: meshes, seeds, properties.
namespace
{
struct Case2D
{
  vtkSmartPointer<vtkImageData> image = Disc();
  vtkSmartPointer<vtkUnstructuredGrid> mesh = MeshOf(image);
  vtkSmartPointer<vtkPolyData> object = ObjectSeeds(image), background = BackgroundSeeds(image);
};
} // namespace

TEST(SuperVoxelCut, Disc)
{
  Case2D c;
  SuperVoxelCut(c.mesh, c.object, c.background, c.image,
    [&](auto& cut, const CutOutputs& out) { ExpectGoodCut(cut, out, c.image, c.object, c.background); });
}
TEST(SuperVoxelCut, DiscWithoutTheImage)
{
  Case2D c;
  SuperVoxelCut(c.mesh, c.object, c.background, nullptr,
    [&](auto& cut, const CutOutputs& out) { ExpectGoodCut(cut, out, c.image, c.object, c.background); });
}
TEST(SuperVoxelCut, EmptyMesh)
{
  Case2D c;
  vtkNew<vtkUnstructuredGrid> empty;
  SuperVoxelCut(empty, c.object, c.background, c.image, [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "empty"); });
}
TEST(SuperVoxelCut, MeshWithoutMeanIntensity)
{
  Case2D c;
  c.mesh->GetCellData()->RemoveArray("MeanIntensity");
  SuperVoxelCut(c.mesh, c.object, c.background, c.image,
    [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "MeanIntensity"); });
}
TEST(SuperVoxelCut, MeanIntensityNaNWithoutImage)
{
  Case2D c;
  c.mesh->GetCellData()->GetArray("MeanIntensity")->SetComponent(17, 0, NaN);
  SuperVoxelCut(c.mesh, c.object, c.background, nullptr,
    [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "MeanIntensity cell array holds 1 NaN"); });
}
TEST(SuperVoxelCut, NegativePixelCountWithoutImage)
{
  Case2D c;
  c.mesh->GetCellData()->GetArray("PixelCount")->SetComponent(3, 0, -5);
  SuperVoxelCut(c.mesh, c.object, c.background, nullptr,
    [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "PixelCount cell array holds 1 negative"); });
}
TEST(SuperVoxelCut, QuadMesh)
{
  Case2D c;
  vtkNew<vtkUnstructuredGrid> quads;
  quads->ShallowCopy(c.mesh);
  vtkNew<vtkCellArray> cells;
  const vtkIdType q[4] = { 0, 1, 2, 3 };
  cells->InsertNextCell(4, q);
  quads->SetCells(VTK_QUAD, cells);
  quads->GetCellData()->Initialize();
  quads->GetCellData()->AddArray(c.mesh->GetCellData()->GetArray("MeanIntensity"));
  quads->GetCellData()->AddArray(c.mesh->GetCellData()->GetArray("PixelCount"));
  SuperVoxelCut(quads, c.object, c.background, c.image,
    [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "triangles"); });
}
TEST(SuperVoxelCut, MixedCellTypes)
{
  Case2D c;
  vtkNew<vtkUnstructuredGrid> mixed;
  mixed->DeepCopy(c.mesh);
  const vtkIdType line[2] = { 0, 1 };
  mixed->InsertNextCell(VTK_LINE, 2, line);
  for (const char* name : { "MeanIntensity", "PixelCount" })
    mixed->GetCellData()->GetArray(name)->InsertNextTuple1(1.0);
  SuperVoxelCut(mixed, c.object, c.background, c.image, [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "mixes"); });
}
TEST(SuperVoxelCut, CellIdOutOfRange)
{
  Case2D c;
  vtkNew<vtkUnstructuredGrid> bad;
  bad->DeepCopy(c.mesh);
  vtkNew<vtkIdList> ids;
  bad->GetCellPoints(5, ids);
  ids->SetId(1, 1000000);
  bad->ReplaceCell(5, 3, ids->GetPointer(0));
  SuperVoxelCut(bad, c.object, c.background, c.image, [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "outside"); });
}
TEST(SuperVoxelCut, ClockwiseMeshGivesTheSameLabels)
{
  Case2D c;
  vtkNew<vtkUnstructuredGrid> clockwise;
  clockwise->DeepCopy(c.mesh);
  vtkNew<vtkIdList> ids;
  for (vtkIdType e = 0; e < clockwise->GetNumberOfCells(); ++e)
  {
    clockwise->GetCellPoints(e, ids);
    const vtkIdType flipped[3] = { ids->GetId(0), ids->GetId(2), ids->GetId(1) };
    clockwise->ReplaceCell(e, 3, flipped);
  }
  std::vector<double> want, got;
  SuperVoxelCut(c.mesh, c.object, c.background, c.image, [&](auto&, const CutOutputs& out) {
    for (vtkIdType e = 0; e < out.Mesh->GetNumberOfCells(); ++e)
      want.push_back(out.Mesh->GetCellData()->GetArray("Label")->GetComponent(e, 0));
  });
  SuperVoxelCut(clockwise, c.object, c.background, c.image, [&](auto& cut, const CutOutputs& out) {
    ExpectGoodCut(cut, out, c.image, c.object, c.background);
    for (vtkIdType e = 0; e < out.Mesh->GetNumberOfCells(); ++e)
      got.push_back(out.Mesh->GetCellData()->GetArray("Label")->GetComponent(e, 0));
  });
  EXPECT_EQ(want, got);
}
TEST(SuperVoxelCut, MeshFromAnotherImage)
{
  Case2D c;
  auto other = Image({ { 70, 64, 1 } }, [](int i, int, int) { return i; });
  SuperVoxelCut(c.mesh, c.object, c.background, other,
    [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "another image grid"); });
}
TEST(SuperVoxelCut, MeshWithoutFrameOrImage)
{
  Case2D c;
  c.mesh->GetFieldData()->Initialize();
  SuperVoxelCut(c.mesh, c.object, c.background, nullptr,
    [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "connect the Image"); });
}
TEST(SuperVoxelCut, NoObjectSeeds)
{
  Case2D c;
  SuperVoxelCut(c.mesh, Points({}), c.background, c.image, [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "no object seeds"); });
}
TEST(SuperVoxelCut, NoBackgroundSeeds)
{
  Case2D c;
  SuperVoxelCut(c.mesh, c.object, Points({}), c.image,
    [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "no background seeds"); });
}
TEST(SuperVoxelCut, SeedsOutside)
{
  Case2D c;
  SuperVoxelCut(c.mesh, Points({ { { 500, 500, 0 } }, World(c.image, 31, 30, 0) }), c.background, c.image,
    [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "1 of 2 object seeds fall outside"); });
}
TEST(SuperVoxelCut, NaNSeed)
{
  Case2D c;
  SuperVoxelCut(c.mesh, c.object, Points({ { { NaN, 3, 0 } } }), c.image,
    [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "fall outside"); });
}
TEST(SuperVoxelCut, ConflictingSeeds)
{
  Case2D c;
  SuperVoxelCut(c.mesh, c.object, c.object, c.image, [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "both"); });
}
TEST(SuperVoxelCut, SeedsOfBothKindsInOneElement)
{
  // Two voxels of one element of the disc's interior (it spans voxels 31..35 x 28..30), one seed
  // of each kind: the element cannot be both.
  Case2D c;
  SuperVoxelCut(c.mesh, Points({ World(c.image, 32, 29, 0) }), Points({ World(c.image, 34, 28, 0), World(c.image, 3, 3, 0) }),
    c.image, [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "holds both"); });
}
TEST(SuperVoxelCut, ThousandsOfSeeds)
{
  Case2D c;
  std::vector<Point> inside, outside;
  for (int j = 0; j < 64; ++j)
    for (int i = 0; i < 64; ++i)
    {
      const double r = std::hypot(i - 31.5, j - 30.0);
      if (r < 10)
        inside.push_back(World(c.image, i, j, 0));
      else if (r > 24)
        outside.push_back(World(c.image, i, j, 0));
    }
  auto object = Points(inside), background = Points(outside);
  ASSERT_GT(inside.size() + outside.size(), 1500u);
  SuperVoxelCut(c.mesh, object, background, c.image,
    [&](auto& cut, const CutOutputs& out) { ExpectGoodCut(cut, out, c.image, object, background); });
}
TEST(SuperVoxelCut, TinySigmaKeepsTheSeeds)
{
  Case2D c;
  SuperVoxelCut(c.mesh, c.object, c.background, c.image,
    [&](auto& cut, const CutOutputs& out) { ExpectGoodCut(cut, out, c.image, c.object, c.background); },
    [](vtkSuperVoxelCut* f) { f->SetSigma(1e-300); });
}
TEST(SuperVoxelCut, NegativeSigma)
{
  Case2D c;
  SuperVoxelCut(c.mesh, c.object, c.background, c.image, [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "sigma"); },
    [](vtkSuperVoxelCut* f) { f->SetSigma(-1); });
}
TEST(SuperVoxelCut, BillionBins)
{
  Case2D c;
  SuperVoxelCut(c.mesh, c.object, c.background, c.image, [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "bin"); },
    [](vtkSuperVoxelCut* f) { f->SetBins(1000000000); });
}
TEST(SuperVoxelCut, HugeLambda)
{
  Case2D c;
  SuperVoxelCut(c.mesh, c.object, c.background, c.image, [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "lambda"); },
    [](vtkSuperVoxelCut* f) { f->SetLambda(1e300); });
}
TEST(SuperVoxelCut, ZeroBandwidth)
{
  Case2D c;
  SuperVoxelCut(c.mesh, c.object, c.background, c.image, [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "bandwidth"); },
    [](vtkSuperVoxelCut* f) { f->SetBandwidth(0); });
}
TEST(SuperVoxelCut, SeedRadiusOutOfRange)
{
  Case2D c;
  SuperVoxelCut(c.mesh, c.object, c.background, c.image, [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "seed radius"); },
    [](vtkSuperVoxelCut* f) {
      f->SampleSeedElementsOff();
      f->SetSeedRadius(-1);
    });
}
TEST(SuperVoxelCut, SeedElementRadiusOutOfRange)
{
  Case2D c;
  for (const double radius : { -1.0, 51.0, std::nan("") })
    SuperVoxelCut(c.mesh, c.object, c.background, c.image,
      [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "seed element radius"); },
      [radius](vtkSuperVoxelCut* f) { f->SetSeedElementRadius(radius); });
}
TEST(SuperVoxelCut, SampleSeedElementsOnGivesACut)
{
  Case2D c;
  SuperVoxelCut(c.mesh, c.object, c.background, c.image,
    [&](auto& cut, const CutOutputs& out) { ExpectGoodCut(cut, out, c.image, c.object, c.background); },
    [](vtkSuperVoxelCut* f) { f->SampleSeedElementsOn(); });
}
TEST(SuperVoxelCut, SeedElementRadiusZeroSamplesWholeElements)
{
  Case2D c;
  SuperVoxelCut(c.mesh, c.object, c.background, c.image,
    [&](auto& cut, const CutOutputs& out) { ExpectGoodCut(cut, out, c.image, c.object, c.background); },
    [](vtkSuperVoxelCut* f) {
      f->SampleSeedElementsOn();
      f->SetSeedElementRadius(0);
    });
}
TEST(SuperVoxelCut, VoxelRefinementOutOfRange)
{
  Case2D c;
  for (const int rings : { -1, 9 })
    SuperVoxelCut(c.mesh, c.object, c.background, c.image,
      [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "voxel refinement"); },
      [rings](vtkSuperVoxelCut* f) { f->SetVoxelRefinement(rings); });
}
TEST(SuperVoxelCut, VoxelRefinementOverEveryElement)
{
  // Eight rings reach every element of the small mesh: a good cut whose seeds keep their labels.
  Case2D c;
  SuperVoxelCut(c.mesh, c.object, c.background, c.image,
    [&](auto& cut, const CutOutputs& out) { ExpectGoodCut(cut, out, c.image, c.object, c.background); },
    [](vtkSuperVoxelCut* f) { f->SetVoxelRefinement(8); });
}
TEST(SuperVoxelCut, TaskOutOfRange)
{
  Case2D c;
  SuperVoxelCut(c.mesh, c.object, c.background, c.image, [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "task"); },
    [](vtkSuperVoxelCut* f) { f->SetTask(7); });
}
TEST(SuperVoxelCut, BadIntensityParameters)
{
  // Each with its words; the local contrast without the Image input too.
  Case2D c;
  const std::vector<std::tuple<std::function<void(vtkSuperVoxelCut*)>, std::string, bool>> cases = {
    { [](vtkSuperVoxelCut* f) { f->SetIntensity(3); }, "intensity", true },
    { [](vtkSuperVoxelCut* f) { f->SetIntensity(-1); }, "intensity", true },
    { [](vtkSuperVoxelCut* f) { f->SetContrastScale(NaN); }, "contrast scale", true },
    { [](vtkSuperVoxelCut* f) { f->SetContrastScale(0.1); }, "contrast scale", true },
    { [](vtkSuperVoxelCut* f) { f->SetIntensity(1); }, "Image input", false },
  };
  for (const auto& [set, words, image] : cases)
    SuperVoxelCut(c.mesh, c.object, c.background, image ? c.image.GetPointer() : nullptr,
      [&](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, words); }, set);
}
TEST(SuperVoxelCut, ClassTaskWithoutTheImageReadsTheMeans)
{
  Case2D c;
  SuperVoxelCut(c.mesh, c.object, c.background, nullptr, [&](auto& cut, const CutOutputs& out) {
    ExpectGoodCut(cut, out, c.image, c.object, c.background);
    EXPECT_TRUE(cut.HasWarning("MeanIntensity"));
  },
    [](vtkSuperVoxelCut* f) { f->SetTask(1); });
}
TEST(SuperVoxelCut, LocalContrastOfAConstantImage)
{
  // Every voxel's contrast is 0: no NaN from 0 / 0, a cut that keeps its seeds.
  auto image = Image({ { 32, 32, 1 } }, [](int, int, int) { return 7.0; });
  auto mesh = MeshOf(image);
  auto object = Points({ World(image, 8, 8, 0) }), background = Points({ World(image, 24, 24, 0) });
  SuperVoxelCut(mesh, object, background, image,
    [&](auto& cut, const CutOutputs& out) { ASSERT_TRUE(cut.Log->Errors.empty()) << cut.Log->All(); (void)out; },
    [](vtkSuperVoxelCut* f) { f->SetIntensity(1); });
}
TEST(SuperVoxelCut, NegativeGeodesicWeight)
{
  Case2D c;
  SuperVoxelCut(c.mesh, c.object, c.background, c.image, [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "geodesic weight"); },
    [](vtkSuperVoxelCut* f) { f->SetGeodesicWeight(-1); });
}
TEST(SuperVoxelCut, AdaptiveGeodesicWeightWhereTheSeedsLookAlike)
{
  // A constant image: both seeds' densities are the same (overlap 1), so the adaptive weight is at its
  // largest, GeodesicWeight / SeedOverlapReference; the geodesic term alone places the cut.
  auto image = Image({ { 32, 32, 1 } }, [](int, int, int) { return 7.0; });
  auto mesh = MeshOf(image);
  auto object = Points({ World(image, 8, 8, 0) }), background = Points({ World(image, 24, 24, 0) });
  SuperVoxelCut(mesh, object, background, image, [&](auto& cut, const CutOutputs& out) {
    ExpectGoodCut(cut, out, image, object, background);
    vtkDataArray* overlap = out.Mesh->GetFieldData()->GetArray(featuremesh::names::SeedOverlap);
    vtkDataArray* weight = out.Mesh->GetFieldData()->GetArray(featuremesh::names::SpatialWeight);
    ASSERT_TRUE(overlap && weight);
    EXPECT_NEAR(overlap->GetComponent(0, 0), 1.0, 1e-9);
    EXPECT_NEAR(weight->GetComponent(0, 0), featuremesh::SeedGeodesicParameters{}.Weight / featuremesh::SeedOverlapReference, 1e-9);
  });
}
TEST(SuperVoxelCut, NaNGeodesicLength)
{
  Case2D c;
  SuperVoxelCut(c.mesh, c.object, c.background, c.image, [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "geodesic length"); },
    [](vtkSuperVoxelCut* f) { f->SetGeodesicLength(NaN); });
}
TEST(SuperVoxelCut, NegativeSeedReachWeight)
{
  Case2D c;
  SuperVoxelCut(c.mesh, c.object, c.background, c.image, [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "seed reach weight"); },
    [](vtkSuperVoxelCut* f) { f->SetSeedReachWeight(-1); });
}
TEST(SuperVoxelCut, NaNSeedReach)
{
  Case2D c;
  SuperVoxelCut(c.mesh, c.object, c.background, c.image, [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "seed reach"); },
    [](vtkSuperVoxelCut* f) { f->SetSeedReach(NaN); });
}
TEST(SuperVoxelCut, SeedReachWithSeedsAFewVoxelsApart)
{
  // Seeds four voxels apart: R is four voxels, and all but a small disc round the object seed pays
  // the reach term; the cut keeps its seeds and gives a valid result.
  auto image = Image({ { 32, 32, 1 } }, [](int i, int, int) { return i < 16 ? 10.0 : 20.0; });
  auto mesh = MeshOf(image);
  auto object = Points({ World(image, 13, 16, 0) }), background = Points({ World(image, 17, 16, 0) });
  SuperVoxelCut(mesh, object, background, image,
    [&](auto& cut, const CutOutputs& out) { ExpectGoodCut(cut, out, image, object, background); });
}
TEST(SuperVoxelCut, ClassTaskKeepsTheSeeds)
{
  Case2D c;
  SuperVoxelCut(c.mesh, c.object, c.background, c.image,
    [&](auto& cut, const CutOutputs& out) { ExpectGoodCut(cut, out, c.image, c.object, c.background); },
    [](vtkSuperVoxelCut* f) { f->SetTask(1); });
}
TEST(SuperVoxelCut, ASeedInEveryElement)
{
  // One seed at the centroid of every element, object where the element is bright: every node is a
  // hard constraint and both geodesics are 0 on their seeds. Either a cut that keeps every seed or,
  // where a centroid's voxel belongs to a neighbour of the other kind, the two-kinds error.
  Case2D c;
  std::vector<std::array<double, 3>> object, background;
  vtkDataArray* mean = c.mesh->GetCellData()->GetArray("MeanIntensity");
  double range[2];
  mean->GetRange(range, 0);
  for (vtkIdType e = 0; e < c.mesh->GetNumberOfCells(); ++e)
  {
    vtkIdType n;
    const vtkIdType* ids;
    c.mesh->GetCellPoints(e, n, ids);
    std::array<double, 3> centre{ { 0, 0, 0 } };
    for (vtkIdType k = 0; k < n; ++k)
    {
      double x[3];
      c.mesh->GetPoint(ids[k], x);
      for (int a = 0; a < 3; ++a)
        centre[a] += x[a] / n;
    }
    (mean->GetComponent(e, 0) > 0.5 * (range[0] + range[1]) ? object : background).push_back(centre);
  }
  auto objectSeeds = Points(object), backgroundSeeds = Points(background);
  SuperVoxelCut(c.mesh, objectSeeds, backgroundSeeds, c.image, [&](auto& cut, const CutOutputs& out) {
    if (cut.Log->Errors.empty())
      ExpectGoodCut(cut, out, c.image, objectSeeds, backgroundSeeds);
    else
      ExpectCutError(cut, out, "both");
  });
}
TEST(SuperVoxelCut, SeededObjectKeepsTheSeeds)
{
  Case2D c;
  SuperVoxelCut(c.mesh, c.object, c.background, c.image,
    [&](auto& cut, const CutOutputs& out) { ExpectGoodCut(cut, out, c.image, c.object, c.background); },
    [](vtkSuperVoxelCut* f) { f->SetConnectivity(2); });
}
TEST(SuperVoxelCut, ZeroLambdaIsBoundaryOnly)
{
  Case2D c;
  SuperVoxelCut(c.mesh, c.object, c.background, c.image,
    [&](auto& cut, const CutOutputs& out) { ExpectGoodCut(cut, out, c.image, c.object, c.background); },
    [](vtkSuperVoxelCut* f) { f->SetLambda(0); });
}
TEST(SuperVoxelCut, NegativeSpacingIn3DFinishes)
{
  auto image = Ball();
  image->SetSpacing(1.0, -1.0, 2.0);
  auto mesh = MeshOf(image);
  auto object = ObjectSeeds(image), background = BackgroundSeeds(image);
  SuperVoxelCut(mesh, object, background, image,
    [&](auto& cut, const CutOutputs& out) { ExpectGoodCut(cut, out, image, object, background); });
}
TEST(SuperVoxelCut, MeanIntensityNaNIn3DWithoutImageFinishes)
{
  auto image = Ball();
  auto mesh = MeshOf(image);
  mesh->GetCellData()->GetArray("MeanIntensity")->SetComponent(0, 0, NaN);
  SuperVoxelCut(mesh, ObjectSeeds(image), BackgroundSeeds(image), nullptr,
    [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "NaN"); });
}
TEST(SuperVoxelCut, TetGenAndCGALMeshesBothCut)
{
  auto image = Ball();
  auto object = ObjectSeeds(image), background = BackgroundSeeds(image);
  for (int backend : { 0, 1 })
    SuperVoxelCut(MeshOf(image, backend), object, background, image,
      [&](auto& cut, const CutOutputs& out) { ExpectGoodCut(cut, out, image, object, background); });
}
TEST(SuperVoxelCut, TriangleMeshOnA3DImage)
{
  Case2D c;
  auto ball = Ball();
  SuperVoxelCut(c.mesh, ObjectSeeds(ball), BackgroundSeeds(ball), ball,
    [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "another image grid"); });
}

//------------------------------------------------------------------------------------------------
// Voxel Cut.
TEST(VoxelCut, Disc)
{
  auto image = Disc();
  VoxelCut(image, ObjectSeeds(image), BackgroundSeeds(image), [](auto& run, vtkImageData* out) { ExpectGoodVoxelCut(run, out); });
}
TEST(VoxelCut, BallWithMirroredSpacing)
{
  auto image = Ball();
  image->SetSpacing(-1.0, 1.0, 1.0);
  VoxelCut(image, ObjectSeeds(image), BackgroundSeeds(image), [](auto& run, vtkImageData* out) { ExpectGoodVoxelCut(run, out); });
}
TEST(VoxelCut, AdaptiveGeodesicWeightWhereTheSeedsLookAlike)
{
  auto image = Image({ { 32, 32, 1 } }, [](int, int, int) { return 7.0; });
  auto object = Points({ World(image, 8, 8, 0) }), background = Points({ World(image, 24, 24, 0) });
  VoxelCut(image, object, background, [&](auto& run, vtkImageData* labels) {
    ExpectGoodVoxelCut(run, labels);
    vtkDataArray* weight = labels->GetFieldData()->GetArray(featuremesh::names::SpatialWeight);
    ASSERT_NE(weight, nullptr);
    EXPECT_NEAR(weight->GetComponent(0, 0), featuremesh::SeedGeodesicParameters{}.Weight / featuremesh::SeedOverlapReference, 1e-9);
    EXPECT_EQ(labels->GetPointData()->GetScalars()->GetComponent((8 * 32) + 8, 0), 1);
    EXPECT_EQ(labels->GetPointData()->GetScalars()->GetComponent((24 * 32) + 24, 0), 0);
  });
}
TEST(VoxelCut, EmptyImage)
{
  vtkNew<vtkImageData> empty;
  auto image = Disc();
  VoxelCut(empty, ObjectSeeds(image), BackgroundSeeds(image), [](auto& run, vtkImageData* out) { ExpectError(run, "empty", out); });
}
TEST(VoxelCut, NaNImage)
{
  auto image = Image({ { 32, 32, 1 } }, [](int i, int, int) { return i == 4 ? NaN : i; });
  VoxelCut(image, Points({ World(image, 20, 20, 0) }), Points({ World(image, 2, 2, 0) }),
    [](auto& run, vtkImageData* out) { ExpectError(run, "NaN", out); });
}
TEST(VoxelCut, SeedsOutside)
{
  auto image = Disc();
  VoxelCut(image, Points({ { { -40, 0, 0 } } }), BackgroundSeeds(image),
    [](auto& run, vtkImageData* out) { ExpectError(run, "outside", out); });
}
TEST(VoxelCut, ConflictingSeeds)
{
  auto image = Disc();
  VoxelCut(image, ObjectSeeds(image), ObjectSeeds(image), [](auto& run, vtkImageData* out) { ExpectError(run, "both", out); });
}
TEST(VoxelCut, TwoComponents)
{
  auto image = Image({ { 32, 32, 1 } }, [](int i, int, int) { return i; }, VTK_FLOAT, 2);
  VoxelCut(image, Points({ World(image, 20, 20, 0) }), Points({ World(image, 2, 2, 0) }),
    [](auto& run, vtkImageData* out) { ExpectError(run, "components", out); });
}
TEST(VoxelCut, SeedRadiusOutOfRange)
{
  auto image = Disc();
  VoxelCut(image, ObjectSeeds(image), BackgroundSeeds(image), [](auto& run, vtkImageData* out) { ExpectError(run, "seed radius", out); },
    [](vtkVoxelCut* f) { f->SetSeedRadius(1000); });
}
TEST(VoxelCut, NegativeSeedReachWeight)
{
  auto image = Disc();
  VoxelCut(image, ObjectSeeds(image), BackgroundSeeds(image), [](auto& run, vtkImageData* out) { ExpectError(run, "seed reach weight", out); },
    [](vtkVoxelCut* f) { f->SetSeedReachWeight(-1); });
}
TEST(VoxelCut, NegativeBandwidth)
{
  auto image = Disc();
  VoxelCut(image, ObjectSeeds(image), BackgroundSeeds(image), [](auto& run, vtkImageData* out) { ExpectError(run, "bandwidth", out); },
    [](vtkVoxelCut* f) { f->SetBandwidth(-1); });
}
TEST(VoxelCut, TaskOutOfRange)
{
  auto image = Disc();
  VoxelCut(image, ObjectSeeds(image), BackgroundSeeds(image), [](auto& run, vtkImageData* out) { ExpectError(run, "task", out); },
    [](vtkVoxelCut* f) { f->SetTask(-1); });
}
TEST(VoxelCut, BadIntensityParameters)
{
  auto image = Disc();
  const std::vector<std::pair<std::function<void(vtkVoxelCut*)>, std::string>> cases = {
    { [](vtkVoxelCut* f) { f->SetIntensity(-1); }, "intensity" },
    { [](vtkVoxelCut* f) { f->SetContrastScale(1000); }, "contrast scale" },
  };
  for (const auto& c : cases)
    VoxelCut(image, ObjectSeeds(image), BackgroundSeeds(image), [&](auto& run, vtkImageData* out) { ExpectError(run, c.second, out); },
      c.first);
}
TEST(VoxelCut, LocalContrastOfAnInfiniteValue)
{
  auto image = Image({ { 32, 32, 1 } }, [](int i, int j, int) { return i == 5 && j == 5 ? INFINITY : (i < 16 ? 5.0 : 0.0); });
  VoxelCut(image, Points({ World(image, 3, 3, 0) }), Points({ World(image, 30, 30, 0) }),
    [](auto& run, vtkImageData* out) { ExpectError(run, "infinite", out); }, [](vtkVoxelCut* f) { f->SetIntensity(1); });
}
TEST(VoxelCut, NoBackgroundSeeds)
{
  auto image = Disc();
  VoxelCut(image, ObjectSeeds(image), Points({}), [](auto& run, vtkImageData* out) { ExpectError(run, "no background seeds", out); });
}
TEST(VoxelCut, ClassTaskWithoutTheGeodesicTerm)
{
  auto image = Disc();
  VoxelCut(image, ObjectSeeds(image), BackgroundSeeds(image), [](auto& run, vtkImageData* out) { ExpectGoodVoxelCut(run, out); },
    [](vtkVoxelCut* f) {
      f->SetTask(1);
      f->SetGeodesicWeight(0);
    });
}
TEST(VoxelCut, TinySigmaKeepsTheSeeds)
{
  auto image = Image({ { 32, 32, 1 } }, [](int i, int, int) { return i < 16 ? 5.0 : 0.0; });
  VoxelCut(image, Points({ World(image, 3, 3, 0) }), Points({ World(image, 30, 30, 0) }),
    [&](auto& run, vtkImageData* out) {
      ExpectGoodVoxelCut(run, out);
      EXPECT_EQ(out->GetPointData()->GetScalars()->GetComponent(3 * 32 + 3, 0), 1);
      EXPECT_EQ(out->GetPointData()->GetScalars()->GetComponent(30 * 32 + 30, 0), 0);
    },
    [](vtkVoxelCut* f) { f->SetSigma(1e-300); });
}

// ---- Image Mesh Smoothing ----
namespace
{
template <typename Check>
void Smoothing(vtkUnstructuredGrid* mesh, vtkImageData* image, const Check& check,
  const std::function<void(vtkImageMeshSmoothing*)>& set = nullptr)
{
  Run<vtkImageMeshSmoothing> run;
  run->SetInputData(0, mesh);
  if (image)
    run->SetInputData(1, image);
  if (set)
    set(run.F);
  run.Update();
  check(run, run->GetOutput());
}

// A valid smoothed mesh: it tiles the image (ExpectTiling), its node arrays cover the added nodes,
// its field data say what smoothing did.
void ExpectSmoothed(Run<vtkImageMeshSmoothing>& run, vtkUnstructuredGrid* mesh, vtkImageData* image)
{
  ExpectTiling(run, mesh, image);
  ASSERT_NE(mesh->GetPointData()->GetArray("Fixed"), nullptr);
  EXPECT_EQ(mesh->GetPointData()->GetArray("Fixed")->GetNumberOfTuples(), mesh->GetNumberOfPoints());
  EXPECT_NE(mesh->GetFieldData()->GetArray("IterationsRun"), nullptr);
}
} // namespace

TEST(ImageMeshSmoothing, Disc)
{
  auto image = Disc();
  Smoothing(MeshOf(image), image, [&](auto& run, vtkUnstructuredGrid* out) { ExpectSmoothed(run, out, image); });
}
TEST(ImageMeshSmoothing, BallMirroredAndAnisotropic)
{
  auto image = Ball();
  const double direction[9] = { -1, 0, 0, 0, 1, 0, 0, 0, 1 };
  image->SetDirectionMatrix(direction);
  image->SetSpacing(1.0, 1.5, 2.0);
  Smoothing(MeshOf(image), image, [&](auto& run, vtkUnstructuredGrid* out) { ExpectSmoothed(run, out, image); });
}
TEST(ImageMeshSmoothing, NoImage)
{
  auto image = Disc();
  Smoothing(MeshOf(image), nullptr, [](auto& run, vtkUnstructuredGrid* out) { ExpectError(run, "Image input is required", out); });
}
TEST(ImageMeshSmoothing, EmptyMesh)
{
  vtkNew<vtkUnstructuredGrid> empty;
  Smoothing(empty, Disc(), [](auto& run, vtkUnstructuredGrid* out) { ExpectError(run, "empty", out); });
}
TEST(ImageMeshSmoothing, MeshWithoutStageTwoArrays)
{
  auto image = Disc();
  auto mesh = MeshOf(image);
  mesh->GetCellData()->RemoveArray("PixelCount");
  Smoothing(mesh, image, [](auto& run, vtkUnstructuredGrid* out) { ExpectError(run, "Delaunay Image Mesh", out); });
}
TEST(ImageMeshSmoothing, MeshWithoutFrameTakesTheImages)
{
  auto image = Disc();
  auto mesh = MeshOf(image);
  mesh->GetFieldData()->RemoveArray("ImageSpacing");
  Smoothing(mesh, image, [&](auto& run, vtkUnstructuredGrid* out) { ExpectSmoothed(run, out, image); });
}
TEST(ImageMeshSmoothing, MixedCellTypes)
{
  auto image = Disc();
  auto mesh = MeshOf(image);
  const vtkIdType vertex[1] = { 0 };
  mesh->InsertNextCell(VTK_VERTEX, 1, vertex);
  Smoothing(mesh, image, [](auto& run, vtkUnstructuredGrid* out) { ExpectError(run, "mixes cell types", out); });
}
TEST(ImageMeshSmoothing, AnotherImageGrid)
{
  auto image = Disc();
  auto mesh = MeshOf(image);
  Smoothing(mesh, Image({ 20, 20, 1 }, Noisy(10, 10, 0, 5)),
    [](auto& run, vtkUnstructuredGrid* out) { ExpectError(run, "another image grid", out); });
}
TEST(ImageMeshSmoothing, TetrahedraOnA2DImage)
{
  auto ball = Ball();
  auto mesh = MeshOf(ball);
  auto disc = Disc();
  // Give the tetrahedral mesh the disc's frame: the cell type no longer matches the dimension.
  for (const char* name : { "ImageDimensions", "ImageSpacing", "ImageOrigin", "ImageDirection" })
  {
    mesh->GetFieldData()->RemoveArray(name);
  }
  auto discMesh = MeshOf(disc);
  for (const char* name : { "ImageDimensions", "ImageSpacing", "ImageOrigin", "ImageDirection" })
  {
    mesh->GetFieldData()->AddArray(discMesh->GetFieldData()->GetArray(name));
  }
  Smoothing(mesh, disc, [](auto& run, vtkUnstructuredGrid* out) { ExpectError(run, "needs a 3D image", out); });
}
TEST(ImageMeshSmoothing, NaNInTheImage)
{
  auto image = Disc();
  auto mesh = MeshOf(image);
  image->GetPointData()->GetScalars()->SetComponent(5, 0, NaN);
  Smoothing(mesh, image, [](auto& run, vtkUnstructuredGrid* out) { ExpectError(run, "NaN", out); });
}
TEST(ImageMeshSmoothing, ZeroIterationsPassesTheMeshThrough)
{
  auto image = Disc();
  auto mesh = MeshOf(image);
  Smoothing(mesh, image,
    [&](auto& run, vtkUnstructuredGrid* out) {
      ASSERT_TRUE(run.Log->Errors.empty()) << run.Log->All();
      ASSERT_EQ(out->GetNumberOfPoints(), mesh->GetNumberOfPoints());
      ASSERT_EQ(out->GetNumberOfCells(), mesh->GetNumberOfCells());
      for (vtkIdType i = 0; i < out->GetNumberOfPoints(); ++i)
      {
        double a[3], b[3];
        out->GetPoint(i, a);
        mesh->GetPoint(i, b);
        ASSERT_TRUE(a[0] == b[0] && a[1] == b[1] && a[2] == b[2]);
      }
    },
    [](vtkImageMeshSmoothing* s) { s->SetIterations(0); });
}
TEST(ImageMeshSmoothing, NegativeIterations)
{
  auto image = Disc();
  Smoothing(MeshOf(image), image, [](auto& run, vtkUnstructuredGrid* out) { ExpectError(run, "iterations", out); },
    [](vtkImageMeshSmoothing* s) { s->SetIterations(-3); });
}
TEST(ImageMeshSmoothing, ZeroSigma)
{
  auto image = Disc();
  Smoothing(MeshOf(image), image, [](auto& run, vtkUnstructuredGrid* out) { ExpectError(run, "sigma", out); },
    [](vtkImageMeshSmoothing* s) { s->SetSigma(0.0); });
}
TEST(ImageMeshSmoothing, NaNFeatureWeight)
{
  auto image = Disc();
  Smoothing(MeshOf(image), image, [](auto& run, vtkUnstructuredGrid* out) { ExpectError(run, "feature weight", out); },
    [](vtkImageMeshSmoothing* s) { s->SetFeatureWeight(NaN); });
}
TEST(ImageMeshSmoothing, UnendingRefinementAngle)
{
  auto image = Disc();
  Smoothing(MeshOf(image), image, [](auto& run, vtkUnstructuredGrid* out) { ExpectError(run, "20.7", out); },
    [](vtkImageMeshSmoothing* s) { s->SetMinAngle(35.0); });
}
TEST(ImageMeshSmoothing, SlackBeyondTwoVoxels)
{
  auto image = Disc();
  Smoothing(MeshOf(image), image, [](auto& run, vtkUnstructuredGrid* out) { ExpectError(run, "slack", out); },
    [](vtkImageMeshSmoothing* s) { s->SetFixedNodeSlack(Inf); });
}
TEST(ImageMeshSmoothing, OptimisationAngleOutOfRange)
{
  auto image = Disc();
  Smoothing(MeshOf(image), image, [](auto& run, vtkUnstructuredGrid* out) { ExpectError(run, "maximum dihedral", out); },
    [](vtkImageMeshSmoothing* s) { s->SetMaxDihedralAngle(NaN); });
}
TEST(ImageMeshSmoothing, DihedralFloorOutOfRange)
{
  auto image = Disc();
  Smoothing(MeshOf(image), image, [](auto& run, vtkUnstructuredGrid* out) { ExpectError(run, "dihedral floor", out); },
    [](vtkImageMeshSmoothing* s) { s->SetDihedralFloor(30); });
}
TEST(ImageMeshSmoothing, MeshWithoutFixedArrayMovesEveryNodeButTheCorners)
{
  auto image = Disc();
  auto mesh = MeshOf(image);
  mesh->GetPointData()->RemoveArray("Fixed");
  Smoothing(mesh, image, [&](auto& run, vtkUnstructuredGrid* out) { ExpectSmoothed(run, out, image); });
}
TEST(ImageMeshSmoothing, ConstantImage)
{
  auto image = Image({ 24, 20, 1 }, [](int, int, int) { return 7.0; });
  // Feature Nodes warns and gives box nodes only; smoothing has no gradient: plain ODT.
  vtkNew<vtkFeatureNodes> nodes;
  nodes->SetInputData(image);
  vtkNew<vtkDelaunayImageMesh> mesh;
  mesh->SetInputConnection(0, nodes->GetOutputPort());
  mesh->SetInputData(1, image);
  mesh->Update();
  Smoothing(mesh->GetOutput(), image, [&](auto& run, vtkUnstructuredGrid* out) { ExpectSmoothed(run, out, image); });
}

//------------------------------------------------------------------------------------------------
// RSP Edge Enhancement: images and seeds.
namespace
{
template <typename Check>
void RSP(vtkImageData* image, vtkPointSet* object, vtkPointSet* background, const Check& check,
  const std::function<void(vtkRSPEdgeEnhancement*)>& set = nullptr)
{
  Run<vtkRSPEdgeEnhancement> rsp;
  rsp->SetInputData(0, image);
  if (object)
    rsp->SetInputData(1, object);
  if (background)
    rsp->SetInputData(2, background);
  if (set)
    set(rsp.F);
  rsp.Update();
  check(rsp, vtkImageData::SafeDownCast(rsp->GetOutputDataObject(0)));
}

void ExpectGoodRSP(Run<vtkRSPEdgeEnhancement>& run, vtkImageData* out, vtkImageData* image)
{
  ASSERT_TRUE(run.Log->Errors.empty()) << run.Log->All();
  vtkDataArray* ec = out->GetPointData()->GetArray("EdgeConfidence");
  ASSERT_NE(ec, nullptr);
  EXPECT_EQ(ec->GetNumberOfTuples(), image->GetNumberOfPoints());
  EXPECT_NE(out->GetPointData()->GetArray("EdgeMap"), nullptr);
  double range[2];
  ec->GetRange(range);
  EXPECT_GT(range[1], 0.0);
  for (int a = 0; a < 3; ++a)
  {
    EXPECT_DOUBLE_EQ(out->GetSpacing()[a], image->GetSpacing()[a]);
    EXPECT_DOUBLE_EQ(out->GetOrigin()[a], image->GetOrigin()[a]);
  }
}
} // namespace

TEST(RSPEdgeEnhancement, Disc)
{
  auto image = Disc();
  RSP(image, ObjectSeeds(image), BackgroundSeeds(image), [&](auto& run, vtkImageData* out) {
    ExpectGoodRSP(run, out, image);
    vtkPolyData* contour = vtkPolyData::SafeDownCast(run->GetOutputDataObject(1));
    EXPECT_GT(contour->GetNumberOfPoints(), 8);
  });
}
TEST(RSPEdgeEnhancement, BallWithMirroredSpacing)
{
  auto image = Ball();
  image->SetSpacing(-1.0, 1.0, 1.0);
  RSP(image, ObjectSeeds(image), BackgroundSeeds(image), [&](auto& run, vtkImageData* out) { ExpectGoodRSP(run, out, image); });
}
TEST(RSPEdgeEnhancement, BallOnACoarserPathGrid)
{
  auto image = Ball();
  RSP(image, ObjectSeeds(image), BackgroundSeeds(image),
    [&](auto& run, vtkImageData* out) {
      ExpectGoodRSP(run, out, image);
      EXPECT_GE(out->GetFieldData()->GetArray("PathGridFactor")->GetTuple1(0), 2);
    },
    [](vtkRSPEdgeEnhancement* f) { f->SetMaximumPathVoxels(4000); });
}
TEST(RSPEdgeEnhancement, NoSeeds)
{
  auto image = Disc();
  RSP(image, nullptr, BackgroundSeeds(image), [](auto& run, vtkImageData* out) { ExpectError(run, "connections", out); });
}
TEST(RSPEdgeEnhancement, EmptySeeds)
{
  auto image = Disc();
  RSP(image, Points({}), BackgroundSeeds(image), [](auto& run, vtkImageData* out) { ExpectError(run, "object", out); });
}
TEST(RSPEdgeEnhancement, OneClassOnly)
{
  auto image = Disc();
  RSP(image, ObjectSeeds(image), ObjectSeeds(image), [](auto& run, vtkImageData* out) { ExpectError(run, "both", out); });
}
TEST(RSPEdgeEnhancement, SeedsOutside)
{
  auto image = Disc();
  RSP(image, Points({ { { -40, 0, 0 } } }), BackgroundSeeds(image), [](auto& run, vtkImageData* out) { ExpectError(run, "outside", out); });
}
TEST(RSPEdgeEnhancement, ConstantImage)
{
  auto image = Image({ { 32, 32, 1 } }, [](int, int, int) { return 3.0; });
  RSP(image, Points({ World(image, 20, 20, 0) }), Points({ World(image, 2, 2, 0) }),
    [](auto& run, vtkImageData* out) { ExpectError(run, "constant", out); });
}
TEST(RSPEdgeEnhancement, OneVoxelImage)
{
  auto image = Image({ { 1, 1, 1 } }, [](int, int, int) { return 3.0; });
  RSP(image, Points({ World(image, 0, 0, 0) }), Points({ World(image, 0, 0, 0) }),
    [](auto& run, vtkImageData* out) { ExpectError(run, "at least 2", out); });
}
TEST(RSPEdgeEnhancement, NaNImage)
{
  auto image = Image({ { 32, 32, 1 } }, [](int i, int, int) { return i == 4 ? NaN : i; });
  RSP(image, Points({ World(image, 20, 20, 0) }), Points({ World(image, 2, 2, 0) }),
    [](auto& run, vtkImageData* out) { ExpectError(run, "NaN", out); });
}
TEST(RSPEdgeEnhancement, NoSources)
{
  auto image = Disc();
  RSP(image, ObjectSeeds(image), BackgroundSeeds(image), [](auto& run, vtkImageData* out) { ExpectError(run, "sources", out); },
    [](vtkRSPEdgeEnhancement* f) { f->SetNumberOfSources(0); });
}
TEST(RSPEdgeEnhancement, EdgeThresholdAboveOne)
{
  auto image = Disc();
  RSP(image, ObjectSeeds(image), BackgroundSeeds(image), [](auto& run, vtkImageData* out) { ExpectError(run, "EdgeThreshold", out); },
    [](vtkRSPEdgeEnhancement* f) { f->SetEdgeThreshold(2.0); });
}
TEST(RSPEdgeEnhancement, FeedsSeedAwareFeatureNodes)
{
  auto image = Disc();
  vtkNew<vtkRSPEdgeEnhancement> rsp;
  rsp->SetInputData(0, image);
  rsp->SetInputData(1, ObjectSeeds(image));
  rsp->SetInputData(2, BackgroundSeeds(image));
  rsp->Update();
  FeatureNodes(image, [&](auto& run, vtkPolyData* out) { ExpectNodesInside(run, out, image, 8); }, nullptr,
    vtkImageData::SafeDownCast(rsp->GetOutputDataObject(0)));
}

namespace
{
// The Super-Voxel Cut's labelled mesh of an image (disc or ball, seeds inside and outside).
vtkSmartPointer<vtkUnstructuredGrid> LabelledMeshOf(vtkImageData* image)
{
  vtkSmartPointer<vtkUnstructuredGrid> labelled;
  SuperVoxelCut(MeshOf(image), ObjectSeeds(image), BackgroundSeeds(image), image,
    [&](auto&, const CutOutputs& out) { labelled = Copy(out.Mesh.GetPointer()); });
  return labelled;
}

template <typename Check>
void SurfaceSmoothing(vtkUnstructuredGrid* labelled, const Check& check,
  const std::function<void(vtkSegmentationSurfaceSmoothing*)>& set = nullptr)
{
  Run<vtkSegmentationSurfaceSmoothing> run;
  run->SetInputData(labelled);
  if (set)
    set(run.F);
  run.Update();
  check(run, run->GetOutput(), vtkUnstructuredGrid::SafeDownCast(run->GetOutputDataObject(1)));
}

// A good run: no error, the same elements and labels, a boundary with faces, every element positive
// in world coordinates (the contract's orientation) and above its floor.
void ExpectSmoothedSurface(Run<vtkSegmentationSurfaceSmoothing>& run, vtkPolyData* surface, vtkUnstructuredGrid* mesh,
  vtkUnstructuredGrid* labelled)
{
  ASSERT_TRUE(run.Log->Errors.empty()) << run.Log->All();
  ASSERT_EQ(mesh->GetNumberOfCells(), labelled->GetNumberOfCells());
  EXPECT_GT(surface->GetNumberOfCells(), 0);
  vtkDataArray* in = labelled->GetCellData()->GetArray("Label");
  vtkDataArray* out = mesh->GetCellData()->GetArray("Label");
  ASSERT_NE(out, nullptr);
  const bool is2D = mesh->GetCellType(0) == VTK_TRIANGLE;
  vtkDataArray* quality = mesh->GetCellData()->GetArray(is2D ? "MinAngle" : "MinDihedralAngle");
  ASSERT_NE(quality, nullptr);
  for (vtkIdType c = 0; c < mesh->GetNumberOfCells(); ++c)
  {
    EXPECT_EQ(in->GetComponent(c, 0), out->GetComponent(c, 0));
    EXPECT_GT(quality->GetComponent(c, 0), 0.0) << c;
  }
}
} // namespace

TEST(SegmentationSurfaceSmoothing, Disc)
{
  auto labelled = LabelledMeshOf(Disc());
  SurfaceSmoothing(labelled, [&](auto& run, vtkPolyData* s, vtkUnstructuredGrid* m) { ExpectSmoothedSurface(run, s, m, labelled); });
}
TEST(SegmentationSurfaceSmoothing, BallMirroredAndAnisotropicTaubin)
{
  auto image = Ball();
  const double direction[9] = { -1, 0, 0, 0, 1, 0, 0, 0, 1 };
  image->SetDirectionMatrix(direction);
  image->SetSpacing(1.0, 1.5, 2.0);
  auto labelled = LabelledMeshOf(image);
  SurfaceSmoothing(labelled, [&](auto& run, vtkPolyData* s, vtkUnstructuredGrid* m) { ExpectSmoothedSurface(run, s, m, labelled); },
    [](vtkSegmentationSurfaceSmoothing* f) { f->SetMethod(vtkSegmentationSurfaceSmoothing::TAUBIN); });
}
TEST(SegmentationSurfaceSmoothing, EverythingObjectSlidesOnTheBox)
{
  auto labelled = LabelledMeshOf(Ball());
  vtkDataArray* label = labelled->GetCellData()->GetArray("Label");
  for (vtkIdType c = 0; c < label->GetNumberOfTuples(); ++c)
    label->SetComponent(c, 0, 1);
  SurfaceSmoothing(labelled, [&](auto& run, vtkPolyData* s, vtkUnstructuredGrid* m) {
    ExpectSmoothedSurface(run, s, m, labelled);
    // The boundary is the box: nothing leaves it.
    double bounds[6], after[6];
    labelled->GetBounds(bounds);
    m->GetBounds(after);
    for (int i = 0; i < 6; ++i)
      EXPECT_EQ(bounds[i], after[i]);
  });
}
TEST(SegmentationSurfaceSmoothing, NoObjectGivesAnEmptyBoundary)
{
  auto labelled = LabelledMeshOf(Disc());
  vtkDataArray* label = labelled->GetCellData()->GetArray("Label");
  for (vtkIdType c = 0; c < label->GetNumberOfTuples(); ++c)
    label->SetComponent(c, 0, 0);
  SurfaceSmoothing(labelled, [&](auto& run, vtkPolyData* s, vtkUnstructuredGrid* m) {
    EXPECT_TRUE(run.Log->Errors.empty()) << run.Log->All();
    EXPECT_EQ(s->GetNumberOfCells(), 0);
    EXPECT_EQ(m->GetNumberOfCells(), labelled->GetNumberOfCells());
  });
}
TEST(SegmentationSurfaceSmoothing, EmptyMesh)
{
  vtkNew<vtkUnstructuredGrid> empty;
  SurfaceSmoothing(empty, [](auto& run, vtkPolyData* s, vtkUnstructuredGrid*) { ExpectError(run, "empty", s); });
}
TEST(SegmentationSurfaceSmoothing, MeshWithoutLabel)
{
  auto image = Disc();
  SurfaceSmoothing(MeshOf(image), [](auto& run, vtkPolyData* s, vtkUnstructuredGrid* m) {
    ExpectError(run, "no Label cell array", s);
    EXPECT_EQ(m->GetNumberOfCells(), 0);
  });
}
TEST(SegmentationSurfaceSmoothing, LabelsNaNNegativeFractionalOrBeyond255)
{
  for (const double bad : { 256.0, NaN, -1.0, 1.5 })
  {
    auto labelled = LabelledMeshOf(Disc());
    vtkNew<vtkDoubleArray> label;
    label->DeepCopy(labelled->GetCellData()->GetArray("Label"));
    label->SetComponent(7, 0, bad);
    labelled->GetCellData()->AddArray(label);
    SurfaceSmoothing(labelled, [](auto& run, vtkPolyData* s, vtkUnstructuredGrid*) { ExpectError(run, "must be 0", s); });
  }
}
TEST(SegmentationSurfaceSmoothing, LabelWithTwoComponents)
{
  auto labelled = LabelledMeshOf(Disc());
  vtkNew<vtkUnsignedCharArray> label;
  label->SetName("Label");
  label->SetNumberOfComponents(2);
  label->SetNumberOfTuples(labelled->GetNumberOfCells());
  label->Fill(0);
  labelled->GetCellData()->AddArray(label);
  SurfaceSmoothing(labelled, [](auto& run, vtkPolyData* s, vtkUnstructuredGrid*) { ExpectError(run, "no Label cell array", s); });
}
TEST(SegmentationSurfaceSmoothing, MeshWithoutItsFrame)
{
  auto labelled = LabelledMeshOf(Disc());
  labelled->GetFieldData()->Initialize();
  SurfaceSmoothing(labelled, [](auto& run, vtkPolyData* s, vtkUnstructuredGrid*) { ExpectError(run, "ImageOrigin", s); });
}
TEST(SegmentationSurfaceSmoothing, QuadMesh)
{
  auto labelled = LabelledMeshOf(Disc());
  vtkNew<vtkCellArray> cells;
  const vtkIdType q[4] = { 0, 1, 2, 3 };
  cells->InsertNextCell(4, q);
  vtkNew<vtkUnstructuredGrid> quads;
  quads->ShallowCopy(labelled);
  quads->SetCells(VTK_QUAD, cells);
  vtkNew<vtkUnsignedCharArray> label;
  label->SetName("Label");
  label->InsertNextValue(1);
  quads->GetCellData()->Initialize();
  quads->GetCellData()->AddArray(label);
  SurfaceSmoothing(quads, [](auto& run, vtkPolyData* s, vtkUnstructuredGrid*) { ExpectError(run, "triangles", s); });
}
TEST(SegmentationSurfaceSmoothing, BadParameters)
{
  auto labelled = LabelledMeshOf(Disc());
  const std::vector<std::pair<std::function<void(vtkSegmentationSurfaceSmoothing*)>, std::string>> cases = {
    { [](vtkSegmentationSurfaceSmoothing* f) { f->SetRelaxation(0); }, "Relaxation" },
    { [](vtkSegmentationSurfaceSmoothing* f) { f->SetRelaxation(NaN); }, "Relaxation" },
    { [](vtkSegmentationSurfaceSmoothing* f) { f->SetPassBand(5); }, "PassBand" },
    { [](vtkSegmentationSurfaceSmoothing* f) { f->SetIterations(-1); }, "Iterations" },
    { [](vtkSegmentationSurfaceSmoothing* f) { f->SetMinDihedralAngle(Inf); }, "MinDihedralAngle" },
    { [](vtkSegmentationSurfaceSmoothing* f) { f->SetRelaxationRings(1000); }, "RelaxationRings" },
  };
  for (const auto& c : cases)
    SurfaceSmoothing(labelled, [&](auto& run, vtkPolyData* s, vtkUnstructuredGrid*) { ExpectError(run, c.second, s); }, c.first);
}
TEST(SegmentationSurfaceSmoothing, ZeroIterationsKeepTheCutsBoundary)
{
  auto labelled = LabelledMeshOf(Ball());
  SurfaceSmoothing(labelled, [&](auto& run, vtkPolyData* s, vtkUnstructuredGrid* m) {
    ExpectSmoothedSurface(run, s, m, labelled);
    for (vtkIdType i = 0; i < m->GetNumberOfPoints(); ++i)
      for (int a = 0; a < 3; ++a)
        ASSERT_EQ(m->GetPoint(i)[a], labelled->GetPoint(i)[a]);
  }, [](vtkSegmentationSurfaceSmoothing* f) { f->SetIterations(0); });
}

//------------------------------------------------------------------------------------------------
// Labelled seeds (x, y, z, label): several objects by alpha-expansion, several channels.
namespace
{
using Seed = std::array<double, 4>; // voxel i, j, k and the label

// Two discs (100 left, 180 right) on 20, with noise; `components` copies of the value.
vtkSmartPointer<vtkImageData> TwoDiscs(int components = 1)
{
  const Fill noisy = Noisy(0, 0, 0, -1); // background 20 plus noise
  return Image({ { 64, 48, 1 } },
    [=](int i, int j, int k) {
      return noisy(i, j, k) + (std::hypot(i - 18, j - 24) <= 11 ? 80.0 : (std::hypot(i - 46, j - 24) <= 11 ? 160.0 : 0.0));
    },
    VTK_FLOAT, components);
}

std::vector<Seed> ThreeLabels()
{
  return { { 18, 24, 0, 1 }, { 16, 22, 0, 1 }, { 46, 24, 0, 2 }, { 48, 26, 0, 2 }, { 3, 3, 0, 0 }, { 60, 44, 0, 0 },
    { 32, 24, 0, 0 } };
}

// The seeds as a point set with a Label point array of `type`.
vtkSmartPointer<vtkPolyData> LabelledPoints(vtkImageData* image, const std::vector<Seed>& seeds, int type = VTK_INT)
{
  std::vector<Point> p;
  for (const auto& s : seeds)
    p.push_back(World(image, s[0], s[1], s[2]));
  auto poly = Points(p);
  vtkSmartPointer<vtkDataArray> label = vtkSmartPointer<vtkDataArray>::Take(vtkDataArray::CreateDataArray(type));
  label->SetName("Label");
  for (const auto& s : seeds)
    label->InsertNextTuple1(s[3]);
  poly->GetPointData()->AddArray(label);
  return poly;
}

// The seeds as a CSV reader gives them: a table with columns x, y, z, label.
vtkSmartPointer<vtkTable> LabelledTable(vtkImageData* image, const std::vector<Seed>& seeds)
{
  auto table = vtkSmartPointer<vtkTable>::New();
  for (const char* name : { "x", "y", "z", "label" })
  {
    vtkNew<vtkDoubleArray> column;
    column->SetName(name);
    table->AddColumn(column);
  }
  for (const auto& s : seeds)
  {
    const Point w = World(image, s[0], s[1], s[2]);
    table->InsertNextBlankRow();
    for (int c = 0; c < 4; ++c)
      table->SetValue(table->GetNumberOfRows() - 1, c, c < 3 ? w[c] : s[3]);
  }
  return table;
}

template <typename Check>
void LabelledCut(vtkImageData* image, vtkDataObject* seeds, const Check& check,
  const std::function<void(vtkSuperVoxelCut*)>& set = nullptr, bool withImage = true)
{
  auto mesh = MeshOf(image->GetNumberOfScalarComponents() == 1 ? image : TwoDiscs().GetPointer());
  Run<vtkSuperVoxelCut> cut;
  cut->SetInputData(0, mesh);
  if (withImage)
    cut->SetInputData(3, image);
  cut->SetInputData(4, seeds);
  if (set)
    set(cut.F);
  cut.Update();
  check(cut, CutOutputs{ cut->GetOutput(), vtkImageData::SafeDownCast(cut->GetOutputDataObject(2)) });
}

template <typename Check>
void LabelledVoxelCut(vtkImageData* image, vtkDataObject* seeds, const Check& check,
  const std::function<void(vtkVoxelCut*)>& set = nullptr)
{
  Run<vtkVoxelCut> cut;
  cut->SetInputData(0, image);
  cut->SetInputData(3, seeds);
  if (set)
    set(cut.F);
  cut.Update();
  check(cut, cut->GetOutput());
}

// No error; every seed's voxel has its label; each label 0..2 covers at least `least` voxels.
template <typename Filter>
void ExpectLabelled(Run<Filter>& run, vtkImageData* labels, vtkImageData* image, const std::vector<Seed>& seeds,
  vtkIdType least = 200)
{
  ASSERT_TRUE(run.Log->Errors.empty()) << run.Log->All();
  vtkDataArray* l = labels->GetPointData()->GetScalars();
  ASSERT_NE(l, nullptr);
  std::vector<vtkIdType> count(256, 0);
  for (vtkIdType v = 0; v < l->GetNumberOfTuples(); ++v)
    ++count[static_cast<int>(l->GetComponent(v, 0))];
  for (int label = 0; label < 3; ++label)
    EXPECT_GE(count[label], least) << "label " << label;
  int dims[3];
  image->GetDimensions(dims);
  for (const auto& s : seeds)
    EXPECT_EQ(l->GetComponent(static_cast<vtkIdType>(s[1]) * dims[0] + static_cast<vtkIdType>(s[0]), 0), s[3]);
  vtkFieldData* fd = labels->GetFieldData();
  ASSERT_NE(fd->GetArray("Labels"), nullptr);
  EXPECT_EQ(fd->GetArray("Labels")->GetComponent(0, 0), 3);
  EXPECT_NE(fd->GetAbstractArray("LabelNames"), nullptr);
}
} // namespace

TEST(SuperVoxelCut, LabelledSeedsThreeLabels)
{
  auto image = TwoDiscs();
  auto seeds = LabelledPoints(image, ThreeLabels());
  LabelledCut(image, seeds, [&](auto& cut, const CutOutputs& out) {
    ExpectLabelled(cut, out.Labels, image, ThreeLabels());
    vtkAbstractArray* names = out.Labels->GetFieldData()->GetAbstractArray("LabelNames");
    ASSERT_NE(names, nullptr);
    ASSERT_EQ(names->GetNumberOfComponents(), 3);
    EXPECT_STREQ(names->GetComponentName(2), "right");
  }, [](vtkSuperVoxelCut* f) { f->SetLabelNames("background;left;right"); });
}
TEST(SuperVoxelCut, LabelledSeedsFromATableGiveThePointSetsLabels)
{
  auto image = TwoDiscs();
  vtkSmartPointer<vtkDataArray> fromPoints;
  LabelledCut(image, LabelledPoints(image, ThreeLabels()),
    [&](auto&, const CutOutputs& out) { fromPoints = out.Labels->GetPointData()->GetScalars(); });
  LabelledCut(image, LabelledTable(image, ThreeLabels()), [&](auto& cut, const CutOutputs& out) {
    ExpectLabelled(cut, out.Labels, image, ThreeLabels());
    vtkDataArray* l = out.Labels->GetPointData()->GetScalars();
    for (vtkIdType v = 0; v < l->GetNumberOfTuples(); ++v)
      ASSERT_EQ(l->GetComponent(v, 0), fromPoints->GetComponent(v, 0)) << "voxel " << v;
  });
}
TEST(SuperVoxelCut, OneObjectLabelGivesTheBinaryCut)
{
  // Labels 0 and 1 on one channel: the binary cut of the two seed ports, label for label.
  Case2D c;
  std::vector<Seed> seeds;
  for (auto [set, label] : { std::pair<vtkPolyData*, int>{ c.object, 1 }, { c.background, 0 } })
    for (vtkIdType i = 0; i < set->GetNumberOfPoints(); ++i)
    {
      double ijk[3];
      c.image->TransformPhysicalPointToContinuousIndex(set->GetPoint(i), ijk);
      seeds.push_back({ ijk[0], ijk[1], ijk[2], double(label) });
    }
  vtkSmartPointer<vtkDataArray> binary;
  SuperVoxelCut(c.mesh, c.object, c.background, c.image,
    [&](auto&, const CutOutputs& out) { binary = out.Mesh->GetCellData()->GetArray("Label"); });
  LabelledCut(c.image, LabelledTable(c.image, seeds), [&](auto& cut, const CutOutputs& out) {
    ASSERT_TRUE(cut.Log->Errors.empty()) << cut.Log->All();
    vtkDataArray* l = out.Mesh->GetCellData()->GetArray("Label");
    ASSERT_EQ(l->GetNumberOfTuples(), binary->GetNumberOfTuples());
    for (vtkIdType e = 0; e < l->GetNumberOfTuples(); ++e)
      ASSERT_EQ(l->GetComponent(e, 0), binary->GetComponent(e, 0)) << "element " << e;
  });
}
TEST(SuperVoxelCut, TwoChannels)
{
  auto image = TwoDiscs(2);
  LabelledCut(image, LabelledPoints(image, ThreeLabels()),
    [&](auto& cut, const CutOutputs& out) { ExpectLabelled(cut, out.Labels, image, ThreeLabels()); });
}
TEST(SuperVoxelCut, EveryChannelModel)
{
  // Joint, Independent, Gaussian Mixture; beyond the enumeration the setter clamps (to 0 or 2).
  auto image = TwoDiscs(2);
  for (int model : { 0, 1, 2, -3, 7 })
    LabelledCut(image, LabelledPoints(image, ThreeLabels()), [&](auto& cut, const CutOutputs& out) {
      EXPECT_EQ(cut->GetChannelModel(), model < 0 ? 0 : std::min(model, 2));
      ExpectLabelled(cut, out.Labels, image, ThreeLabels());
    }, [&](vtkSuperVoxelCut* f) { f->SetChannelModel(model); });
}
TEST(SuperVoxelCut, NaNInOneChannel)
{
  auto image = TwoDiscs(2);
  image->GetPointData()->GetScalars()->SetComponent(100, 1, NaN);
  LabelledCut(image, LabelledPoints(image, ThreeLabels()), [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "NaN"); });
}
TEST(SuperVoxelCut, TwoChannelsWithoutLabelledSeeds)
{
  auto image = TwoDiscs(2);
  auto mesh = MeshOf(TwoDiscs());
  SuperVoxelCut(mesh, ObjectSeeds(image), BackgroundSeeds(image), image,
    [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "2 components"); });
}
TEST(SuperVoxelCut, LabelBeyond255)
{
  auto image = TwoDiscs();
  auto seeds = ThreeLabels();
  seeds[2][3] = 256;
  LabelledCut(image, LabelledPoints(image, seeds), [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "whole numbers"); });
}
TEST(SuperVoxelCut, NegativeLabel)
{
  auto image = TwoDiscs();
  auto seeds = ThreeLabels();
  seeds[2][3] = -1;
  LabelledCut(image, LabelledPoints(image, seeds), [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "whole numbers"); });
}
TEST(SuperVoxelCut, FractionalLabels)
{
  auto image = TwoDiscs();
  auto seeds = ThreeLabels();
  seeds[2][3] = 1.5;
  LabelledCut(image, LabelledPoints(image, seeds, VTK_FLOAT), [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "whole numbers"); });
}
TEST(SuperVoxelCut, ALabelWithNoSeed)
{
  auto image = TwoDiscs();
  auto seeds = ThreeLabels();
  seeds[2][3] = seeds[3][3] = 3;
  LabelledCut(image, LabelledPoints(image, seeds), [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "label 2 has no seed"); });
}
TEST(SuperVoxelCut, SeedsOfOneLabelOnly)
{
  auto image = TwoDiscs();
  auto seeds = ThreeLabels();
  for (auto& s : seeds)
    s[3] = 1;
  LabelledCut(image, LabelledPoints(image, seeds), [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "one label only"); });
}
TEST(SuperVoxelCut, LabelledSeedsWithoutALabelArray)
{
  auto image = TwoDiscs();
  auto seeds = LabelledPoints(image, ThreeLabels());
  seeds->GetPointData()->RemoveArray("Label");
  LabelledCut(image, seeds, [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "no one-component numeric array named Label"); });
}
TEST(SuperVoxelCut, TwoLabelsInOneElement)
{
  auto image = TwoDiscs();
  auto seeds = ThreeLabels();
  seeds.push_back({ 18, 24, 0, 2 }); // the voxel of a label-1 seed
  LabelledCut(image, LabelledPoints(image, seeds), [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "holds seeds of labels"); });
}
TEST(SuperVoxelCut, SeveralObjectsWithoutTheImage)
{
  auto image = TwoDiscs();
  LabelledCut(image, LabelledPoints(image, ThreeLabels()), [](auto& cut, const CutOutputs& out) { ExpectCutError(cut, out, "need the Image"); },
    nullptr, false);
}
TEST(SuperVoxelCut, NoSeedsAtAll)
{
  Case2D c;
  ::Run<vtkSuperVoxelCut> cut;
  cut->SetInputData(0, c.mesh);
  cut->SetInputData(3, c.image);
  cut.Update();
  ExpectCutError(cut, CutOutputs{ cut->GetOutput(), nullptr }, "connect the Object Seeds");
}
TEST(VoxelCut, LabelledSeedsThreeLabels)
{
  auto image = TwoDiscs();
  LabelledVoxelCut(image, LabelledTable(image, ThreeLabels()), [&](auto& cut, vtkImageData* out) { ExpectLabelled(cut, out, image, ThreeLabels()); });
}
TEST(VoxelCut, LabelledSeedsTwoChannels)
{
  auto image = TwoDiscs(2);
  LabelledVoxelCut(image, LabelledPoints(image, ThreeLabels()), [&](auto& cut, vtkImageData* out) { ExpectLabelled(cut, out, image, ThreeLabels()); });
}
TEST(VoxelCut, GaussianMixtureChannelModel)
{
  auto image = TwoDiscs(2);
  LabelledVoxelCut(image, LabelledPoints(image, ThreeLabels()),
    [&](auto& cut, vtkImageData* out) { ExpectLabelled(cut, out, image, ThreeLabels()); },
    [](vtkVoxelCut* f) { f->SetChannelModel(2); });
}
TEST(VoxelCut, NaNInOneChannel)
{
  auto image = TwoDiscs(2);
  image->GetPointData()->GetScalars()->SetComponent(100, 1, NaN);
  LabelledVoxelCut(image, LabelledPoints(image, ThreeLabels()), [](auto& cut, vtkImageData* out) { ExpectError(cut, "NaN", out); });
}
TEST(VoxelCut, ALabelWithNoSeed)
{
  auto image = TwoDiscs();
  auto seeds = ThreeLabels();
  seeds[2][3] = seeds[3][3] = 3;
  LabelledVoxelCut(image, LabelledPoints(image, seeds), [](auto& cut, vtkImageData* out) { ExpectError(cut, "label 2 has no seed", out); });
}
TEST(VoxelCut, NoSeedsAtAll)
{
  ::Run<vtkVoxelCut> cut;
  cut->SetInputData(0, Disc());
  cut.Update();
  ExpectError(cut, "connect the Object Seeds", cut->GetOutput());
}
