// Injectable parallel-for, so that the algorithms stay free of VTK: the VTK wrappers pass one
// built on vtkSMPTools, unit tests use the serial default. Every loop handed to it writes only to
// its own indices, so results do not depend on how the range is split (bit-identical outputs
// whatever the thread count).
#pragma once
#include <cstdint>
#include <functional>

namespace featuremesh
{
using RangeFunction = std::function<void(std::int64_t begin, std::int64_t end)>;
using ParallelFor = std::function<void(std::int64_t n, std::int64_t grain, const RangeFunction&)>;

inline ParallelFor SerialFor()
{
  return [](std::int64_t n, std::int64_t, const RangeFunction& f) {
    if (n > 0)
    {
      f(0, n);
    }
  };
}

// Progress in [0,1]; returns false when the caller asked to abort.
using ProgressFunction = std::function<bool(double)>;
inline ProgressFunction NoProgress()
{
  return [](double) { return true; };
}
} // namespace featuremesh
