// The Boykov-Kolmogorov max-flow graph of every cut (libmaxflow) and the one way it reports that
// memory ran out. Private to FeatureMeshSegmentation: the headers of the cuts do not show it.
#pragma once

#include <maxflow.h>

#include <stdexcept>
#include <string>

namespace featuremesh
{
using FlowGraph = maxflow::Graph_DDD;

// libmaxflow calls this before exit(1) when an allocation fails: throwing keeps the host alive.
inline void ThrowOutOfMemory(const char* what)
{
  throw std::runtime_error(std::string("max-flow: ") + what);
}
} // namespace featuremesh
