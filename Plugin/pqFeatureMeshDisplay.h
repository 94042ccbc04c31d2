// The GUI's part of the plugin (not loaded by pvpython or pvbatch): after Apply, a 3D Super-Voxel
// Cut shows the object's boundary instead of its labelled mesh, whose outer faces are the image box
// and would hide the object (the labelled mesh stays one click on its eye away); Feature Nodes made
// with RSP Edge Enhancement selected takes RSP's image as its Input and RSP as its Edge Map.
#ifndef pqFeatureMeshDisplay_h
#define pqFeatureMeshDisplay_h

#include <QObject>

class pqDataRepresentation;
class pqPipelineSource;

class pqFeatureMeshDisplay : public QObject
{
  Q_OBJECT
public:
  explicit pqFeatureMeshDisplay(QObject* parent = nullptr);
  void onStartup();
  void onShutdown();

private Q_SLOTS:
  // A cut shown: a categorical Label legend; in 3D its labelled mesh hidden.
  void onCutShown(pqPipelineSource* source, pqDataRepresentation* representation, int port);
};

#endif
