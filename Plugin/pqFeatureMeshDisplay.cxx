#include "pqFeatureMeshDisplay.h"

#include "pqApplicationCore.h"
#include "pqDataRepresentation.h"
#include "pqOutputPort.h"
#include "pqPipelineSource.h"
#include "pqServerManagerModel.h"
#include "vtkPVDataInformation.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMProxy.h"
#include "vtkSMSourceProxy.h"

#include <cstring>

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
        QObject::connect(source, &pqPipelineSource::representationAdded, this, &pqFeatureMeshDisplay::hideBoxIn3D);
      }
    });
}

void pqFeatureMeshDisplay::onShutdown() {}

void pqFeatureMeshDisplay::hideBoxIn3D(pqPipelineSource* source, pqDataRepresentation* representation, int port)
{
  if (port != 0 || !representation->isVisible())
  {
    return;
  }
  vtkPVDataInformation* info = source->getOutputPort(0)->getDataInformation();
  double bounds[6];
  info->GetBounds(bounds);
  if (info->GetNumberOfCells() > 0 && bounds[1] > bounds[0] && bounds[3] > bounds[2] && bounds[5] > bounds[4])
  {
    representation->setVisible(false);
  }
}
