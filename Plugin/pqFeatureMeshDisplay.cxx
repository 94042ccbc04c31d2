#include "pqFeatureMeshDisplay.h"

#include "pqApplicationCore.h"
#include "pqDataRepresentation.h"
#include "pqOutputPort.h"
#include "pqPipelineSource.h"
#include "pqServerManagerModel.h"
#include "vtkPVDataInformation.h"
#include "vtkSMProxy.h"

#include <cstring>

pqFeatureMeshDisplay::pqFeatureMeshDisplay(QObject* parent)
  : QObject(parent)
{
}

void pqFeatureMeshDisplay::onStartup()
{
  QObject::connect(pqApplicationCore::instance()->getServerManagerModel(), &pqServerManagerModel::sourceAdded, this,
    [this](pqPipelineSource* source) {
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
