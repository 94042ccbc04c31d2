#include "pqFeatureMeshDisplay.h"

#include "pqApplicationCore.h"
#include "pqDataRepresentation.h"
#include "pqOutputPort.h"
#include "pqPipelineSource.h"
#include "pqServerManagerModel.h"
#include "vtkNew.h"
#include "vtkPVArrayInformation.h"
#include "vtkPVDataInformation.h"
#include "vtkPVDataSetAttributesInformation.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMProxy.h"
#include "vtkSMSourceProxy.h"
#include "vtkSMTransferFunctionManager.h"
#include "vtkSMTransferFunctionProxy.h"

#include <cstring>
#include <string>

pqFeatureMeshDisplay::pqFeatureMeshDisplay(QObject* parent)
  : QObject(parent)
{
}

namespace
{
// Feature Nodes made from a selected RSP Edge Enhancement (its menu item enables on the selection's
// image output) gets RSP's image as its Input and RSP's output as its Edge Map, with RSP's Scalars:
// what seed-aware nodes need, without Change Input.
void WireEdgeMap(vtkSMProxy* nodes)
{
  vtkSMPropertyHelper input(nodes, "Input");
  auto* rsp = vtkSMSourceProxy::SafeDownCast(input.GetAsProxy(0));
  if (input.GetNumberOfElements() != 1 || !rsp || std::strcmp(rsp->GetXMLName(), "RSPEdgeEnhancement") != 0 ||
    input.GetOutputPort(0) != 0 || vtkSMPropertyHelper(nodes, "EdgeMap").GetAsProxy(0))
  {
    return;
  }
  vtkSMPropertyHelper image(rsp, "Input");
  vtkSMPropertyHelper(nodes, "EdgeMap").Set(rsp, 0);
  input.Set(image.GetAsProxy(0), image.GetOutputPort(0));
  vtkSMPropertyHelper(nodes, "SelectInputScalars").Copy(vtkSMPropertyHelper(rsp, "SelectInputScalars"));
  nodes->UpdateVTKObjects();
}
} // namespace

void pqFeatureMeshDisplay::onStartup()
{
  QObject::connect(pqApplicationCore::instance()->getServerManagerModel(), &pqServerManagerModel::sourceAdded, this,
    [this](pqPipelineSource* source) {
      if (std::strcmp(source->getProxy()->GetXMLName(), "FeatureNodes") == 0)
      {
        WireEdgeMap(source->getProxy());
      }
      if (std::strcmp(source->getProxy()->GetXMLName(), "SuperVoxelCut") == 0)
      {
        // Emitted while the controller registers the representation, before it pushes the
        // representation's properties and the view first renders it.
        QObject::connect(source, &pqPipelineSource::representationAdded, this, &pqFeatureMeshDisplay::onCutShown);
      }
    });
}

void pqFeatureMeshDisplay::onShutdown() {}

namespace
{
// The lookup table of every Label array: categories named after the labels (LabelNames), one colour
// each, instead of a continuous ramp.
void CategoricalLabels(vtkSMProxy* cut, vtkPVDataInformation* info)
{
  vtkNew<vtkSMTransferFunctionManager> manager;
  vtkSMProxy* lut = manager->GetColorTransferFunction("Label", cut->GetSessionProxyManager());
  if (!lut)
  {
    return;
  }
  vtkPVArrayInformation* given = info->GetFieldDataInformation()->GetArrayInformation("LabelNames");
  const int labels = given ? given->GetNumberOfComponents() : 2;
  vtkSMTransferFunctionProxy::ApplyPreset(lut, "KAAMS", false);
  vtkSMPropertyHelper(lut, "InterpretValuesAsCategories").Set(1);
  vtkSMPropertyHelper annotations(lut, "Annotations");
  annotations.SetNumberOfElements(2 * labels);
  for (int l = 0; l < labels; ++l)
  {
    const char* name = given ? given->GetComponentName(l) : nullptr;
    const std::string text = name && *name ? name : l == 0 ? "background" : labels == 2 ? "object" : "label " + std::to_string(l);
    annotations.Set(2 * l, std::to_string(l).c_str());
    annotations.Set(2 * l + 1, text.c_str());
  }
  lut->UpdateVTKObjects();
}
} // namespace

void pqFeatureMeshDisplay::onCutShown(pqPipelineSource* source, pqDataRepresentation* representation, int port)
{
  if (port != 0 || !representation->isVisible())
  {
    return;
  }
  vtkPVDataInformation* info = source->getOutputPort(0)->getDataInformation();
  CategoricalLabels(source->getProxy(), info);
  double bounds[6];
  info->GetBounds(bounds);
  if (info->GetNumberOfCells() > 0 && bounds[1] > bounds[0] && bounds[3] > bounds[2] && bounds[5] > bounds[4])
  {
    representation->setVisible(false);
  }
}
