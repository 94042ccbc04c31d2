// Every numeric property default in the plugin's XML equals the default of the VTK filter it sets
// (which the filters take from the Core parameter structs): one source of truth, checked. And every
// value an XML domain offers (range ends, enumeration entries) passes the filter's
// ValidateProperties, the Core's ValidateParameters: the two range checks agree. And each filter's
// PrintSelf names every property its XML sets.
#include "vtkDelaunayImageMesh.h"
#include "vtkImageMeshSmoothing.h"
#include "vtkFeatureNodes.h"
#include "vtkRSPEdgeEnhancement.h"
#include "vtkSegmentationSurfaceSmoothing.h"
#include "vtkSuperVoxelCut.h"
#include "vtkVoxelCut.h"

#include "vtkNew.h"
#include "vtkSmartPointer.h"
#include "vtkXMLDataElement.h"
#include "vtkXMLDataParser.h"

#include <cstdlib>
#include <functional>
#include <iostream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

// A numeric property: its default, and what the filter's ValidateProperties says of a value.
struct Property
{
  std::function<double()> Default;
  std::function<std::string(double)> Check;
};

#define GETTER(cls, name)                                                                          \
  {                                                                                                \
    #cls "::" #name, Property{ []() {                                                              \
                                vtkNew<cls> filter;                                                \
                                return static_cast<double>(filter->Get##name());                   \
                              },                                                                   \
      [](double value) {                                                                           \
        vtkNew<cls> filter;                                                                        \
        filter->Set##name(static_cast<decltype(filter->Get##name())>(value));                      \
        return filter->ValidateProperties();                                                       \
      } }                                                                                          \
  }

#define STRING_GETTER(cls, name)                                                                   \
  {                                                                                                \
    #cls "::" #name, []() {                                                                        \
      vtkNew<cls> filter;                                                                          \
      const char* value = filter->Get##name();                                                     \
      return std::string(value ? value : "");                                                      \
    }                                                                                              \
  }

template <typename Filter>
std::string Printed()
{
  vtkNew<Filter> filter;
  std::ostringstream os;
  filter->Print(os);
  return os.str();
}

int main(int argc, char* argv[])
{
  if (argc < 2)
  {
    std::cerr << "usage: FeatureMeshDefaultsTest PLUGIN_DIR\n";
    return 2;
  }
  const std::map<std::string, Property> getters = {
    GETTER(vtkFeatureNodes, GaussianSigma), GETTER(vtkFeatureNodes, HessianSigma),
    GETTER(vtkFeatureNodes, LowThreshold), GETTER(vtkFeatureNodes, HighThreshold),
    GETTER(vtkFeatureNodes, MaximumPercentile), GETTER(vtkFeatureNodes, CovarianceNeighbourhood),
    GETTER(vtkFeatureNodes, NoiseFloor),
    GETTER(vtkFeatureNodes, Halftoning), GETTER(vtkFeatureNodes, HalftoneThreshold),
    GETTER(vtkFeatureNodes, HalftoneGamma), GETTER(vtkFeatureNodes, ExclusionWindow),
    GETTER(vtkFeatureNodes, UniformSpacing), GETTER(vtkFeatureNodes, BoundarySpacing),
    GETTER(vtkFeatureNodes, SeedAware), GETTER(vtkFeatureNodes, EdgeGateRadius),
    GETTER(vtkFeatureNodes, CoarseningLevels),
    GETTER(vtkRSPEdgeEnhancement, GradientScale), GETTER(vtkRSPEdgeEnhancement, GradientSigma),
    GETTER(vtkRSPEdgeEnhancement, NumberOfSources), GETTER(vtkRSPEdgeEnhancement, NumberOfSinks),
    GETTER(vtkRSPEdgeEnhancement, RandomSeed), GETTER(vtkRSPEdgeEnhancement, SamplingThreshold),
    GETTER(vtkRSPEdgeEnhancement, EdgeThreshold), GETTER(vtkRSPEdgeEnhancement, PathMargin),
    GETTER(vtkRSPEdgeEnhancement, MaximumPathVoxels), GETTER(vtkRSPEdgeEnhancement, GapCost),
    GETTER(vtkDelaunayImageMesh, Backend), GETTER(vtkDelaunayImageMesh, QualityRefinement),
    GETTER(vtkDelaunayImageMesh, RadiusEdgeRatio), GETTER(vtkDelaunayImageMesh, MinDihedralAngle),
    GETTER(vtkImageMeshSmoothing, Method), GETTER(vtkImageMeshSmoothing, Iterations),
    GETTER(vtkImageMeshSmoothing, Sigma), GETTER(vtkImageMeshSmoothing, FeatureWeight),
    GETTER(vtkImageMeshSmoothing, FixedNodeSlack), GETTER(vtkImageMeshSmoothing, Flips),
    GETTER(vtkImageMeshSmoothing, QualityRefinement), GETTER(vtkImageMeshSmoothing, MinAngle),
    GETTER(vtkImageMeshSmoothing, MinDihedralAngle), GETTER(vtkImageMeshSmoothing, SliverRemoval),
    GETTER(vtkImageMeshSmoothing, MaxDihedralAngle), GETTER(vtkImageMeshSmoothing, SliverAngle),
    GETTER(vtkImageMeshSmoothing, DihedralFloor),
    GETTER(vtkSuperVoxelCut, Lambda), GETTER(vtkSuperVoxelCut, Sigma), GETTER(vtkSuperVoxelCut, Bins),
    GETTER(vtkSuperVoxelCut, ScaleByContact), GETTER(vtkSuperVoxelCut, VoxelRegionTerm),
    GETTER(vtkSuperVoxelCut, Connectivity), GETTER(vtkSuperVoxelCut, Bandwidth),
    GETTER(vtkSuperVoxelCut, SampleSeedElements), GETTER(vtkSuperVoxelCut, SeedElementRadius),
    GETTER(vtkSuperVoxelCut, SeedRadius),
    GETTER(vtkSuperVoxelCut, VoxelRefinement),
    GETTER(vtkSuperVoxelCut, SuperVoxelIds), GETTER(vtkSuperVoxelCut, Task),
    GETTER(vtkSuperVoxelCut, GeodesicWeight), GETTER(vtkSuperVoxelCut, GeodesicLength), GETTER(vtkSuperVoxelCut, AdaptiveGeodesicWeight),
    GETTER(vtkSuperVoxelCut, SeedReach), GETTER(vtkSuperVoxelCut, SeedReachWeight),
    GETTER(vtkSuperVoxelCut, Intensity), GETTER(vtkSuperVoxelCut, ContrastScale),
    GETTER(vtkVoxelCut, Lambda), GETTER(vtkVoxelCut, Sigma), GETTER(vtkVoxelCut, Bins),
    GETTER(vtkVoxelCut, SeedRadius), GETTER(vtkVoxelCut, Connectivity), GETTER(vtkVoxelCut, Bandwidth),
    GETTER(vtkVoxelCut, Task), GETTER(vtkVoxelCut, GeodesicWeight), GETTER(vtkVoxelCut, GeodesicLength),
    GETTER(vtkVoxelCut, AdaptiveGeodesicWeight), GETTER(vtkVoxelCut, SeedReach), GETTER(vtkVoxelCut, SeedReachWeight),
    GETTER(vtkVoxelCut, Intensity), GETTER(vtkVoxelCut, ContrastScale),
    GETTER(vtkSuperVoxelCut, ChannelModel), GETTER(vtkVoxelCut, ChannelModel),
    GETTER(vtkSegmentationSurfaceSmoothing, Method), GETTER(vtkSegmentationSurfaceSmoothing, Iterations),
    GETTER(vtkSegmentationSurfaceSmoothing, Relaxation), GETTER(vtkSegmentationSurfaceSmoothing, PassBand),
    GETTER(vtkSegmentationSurfaceSmoothing, VolumeMesh), GETTER(vtkSegmentationSurfaceSmoothing, MinAngle),
    GETTER(vtkSegmentationSurfaceSmoothing, MinDihedralAngle), GETTER(vtkSegmentationSurfaceSmoothing, RelaxationRings),
  };
  // String properties with a default (array names, label names).
  const std::map<std::string, std::function<std::string()>> strings = {
    STRING_GETTER(vtkSuperVoxelCut, SeedLabelArray), STRING_GETTER(vtkSuperVoxelCut, LabelNames),
    STRING_GETTER(vtkVoxelCut, SeedLabelArray), STRING_GETTER(vtkVoxelCut, LabelNames),
  };
  int failures = 0, checked = 0, ranges = 0;
  std::set<std::string> seen;
  for (const char* file : { "FeatureNodes.xml", "DelaunayImageMesh.xml", "ImageMeshSmoothing.xml", "RSPEdgeEnhancement.xml",
         "SuperVoxelCut.xml", "SegmentationSurfaceSmoothing.xml" })
  {
    vtkNew<vtkXMLDataParser> parser;
    const std::string path = std::string(argv[1]) + "/" + file;
    parser->SetFileName(path.c_str());
    if (!parser->Parse())
    {
      std::cerr << "FAIL: cannot parse " << path << "\n";
      return 1;
    }
    vtkXMLDataElement* group = parser->GetRootElement()->FindNestedElementWithName("ProxyGroup");
    for (int p = 0; group && p < group->GetNumberOfNestedElements(); ++p)
    {
      vtkXMLDataElement* proxy = group->GetNestedElement(p);
      const std::string cls = proxy->GetAttribute("class") ? proxy->GetAttribute("class") : "";
      for (int q = 0; q < proxy->GetNumberOfNestedElements(); ++q)
      {
        vtkXMLDataElement* property = proxy->GetNestedElement(q);
        const std::string tag = property->GetName();
        const char* command = property->GetAttribute("command");
        const char* value = property->GetAttribute("default_values");
        if (tag == "StringVectorProperty" && command && std::string(command) != "SetInputArrayToProcess")
        {
          const std::string text = value ? value : ""; // the parser drops an empty default
          const std::string key = cls + "::" + std::string(command).substr(3);
          seen.insert(key);
          auto it = strings.find(key);
          ++checked;
          if (it == strings.end() || it->second() != text)
          {
            std::cout << "FAIL: " << key << ": XML default '" << text << "', C++ default '"
                      << (it == strings.end() ? std::string("(no getter in this test)") : it->second()) << "'\n";
            ++failures;
          }
          continue;
        }
        if ((tag != "IntVectorProperty" && tag != "DoubleVectorProperty") || !command || !value)
        {
          continue;
        }
        const std::string key = cls + "::" + std::string(command).substr(3);
        seen.insert(key);
        auto it = getters.find(key);
        if (it == getters.end())
        {
          std::cout << "FAIL: " << file << ": " << key << " has an XML default and no C++ getter in this test\n";
          ++failures;
          continue;
        }
        // Every value the XML's domain offers (range ends, enumeration entries) must pass the Core's
        // ValidateParameters, alone at the other defaults.
        for (int d = 0; d < property->GetNumberOfNestedElements(); ++d)
        {
          vtkXMLDataElement* domain = property->GetNestedElement(d);
          const std::string kind = domain->GetName();
          std::vector<std::string> offered;
          if (kind == "IntRangeDomain" || kind == "DoubleRangeDomain")
          {
            for (const char* end : { "min", "max" })
            {
              if (domain->GetAttribute(end))
                offered.emplace_back(domain->GetAttribute(end));
            }
          }
          if (kind == "EnumerationDomain" || kind == "BooleanDomain")
          {
            for (int e = 0; e < domain->GetNumberOfNestedElements(); ++e)
            {
              if (domain->GetNestedElement(e)->GetAttribute("value"))
                offered.emplace_back(domain->GetNestedElement(e)->GetAttribute("value"));
            }
            if (kind == "BooleanDomain")
              offered = { "0", "1" };
          }
          for (const std::string& text : offered)
          {
            // A bound between two properties, not a range: the low threshold may reach 1 when the
            // high one does, and the high one fall to 0.01 when the low one does.
            if ((key == "vtkFeatureNodes::LowThreshold" && text == "1") ||
              (key == "vtkFeatureNodes::HighThreshold" && text == "0.01"))
              continue;
            double v = 0.0;
            std::istringstream(text) >> v;
            const std::string why = it->second.Check(v);
            ++ranges;
            if (!why.empty())
            {
              std::cout << "FAIL: " << key << ": the XML offers " << text << ", which the filter refuses: " << why << "\n";
              ++failures;
            }
          }
        }
        double xml = 0.0;
        std::istringstream(value) >> xml;
        const double cxx = it->second.Default();
        ++checked;
        if (xml != cxx)
        {
          std::cout << "FAIL: " << key << ": XML default " << value << ", C++ default " << cxx << "\n";
          ++failures;
        }
        else
        {
          std::cout << "ok: " << key << " = " << cxx << "\n";
        }
      }
    }
  }
  const std::map<std::string, std::string> printed = { { "vtkFeatureNodes", Printed<vtkFeatureNodes>() },
    { "vtkDelaunayImageMesh", Printed<vtkDelaunayImageMesh>() }, { "vtkImageMeshSmoothing", Printed<vtkImageMeshSmoothing>() },
    { "vtkRSPEdgeEnhancement", Printed<vtkRSPEdgeEnhancement>() }, { "vtkSuperVoxelCut", Printed<vtkSuperVoxelCut>() },
    { "vtkVoxelCut", Printed<vtkVoxelCut>() },
    { "vtkSegmentationSurfaceSmoothing", Printed<vtkSegmentationSurfaceSmoothing>() } };
  for (const std::string& key : seen)
  {
    const std::string cls = key.substr(0, key.find("::")), name = key.substr(key.find("::") + 2);
    const auto it = printed.find(cls);
    ++checked;
    if (it == printed.end() || it->second.find(name + ": ") == std::string::npos)
    {
      std::cout << "FAIL: " << cls << "::PrintSelf does not print " << name << "\n";
      ++failures;
    }
  }
  std::set<std::string> keys;
  for (const auto& g : getters)
    keys.insert(g.first);
  for (const auto& g : strings)
    keys.insert(g.first);
  for (const auto& g : keys)
  {
    if (!seen.count(g))
    {
      std::cout << "FAIL: " << g << " is not a property with a default in the XML\n";
      ++failures;
    }
  }
  std::cout << checked << " defaults and " << ranges << " domain values checked, " << failures << " failures\n";
  return failures ? EXIT_FAILURE : EXIT_SUCCESS;
}
