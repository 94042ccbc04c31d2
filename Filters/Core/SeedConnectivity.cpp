#include "SeedConnectivity.h"
#include "Memory.h"

#include <algorithm>
#include <functional>
#include <numeric>

namespace featuremesh
{
namespace
{
std::int64_t Find(std::vector<std::int64_t>& parent, std::int64_t p)
{
  while (parent[p] != p)
  {
    parent[p] = parent[parent[p]]; // path halving
    p = parent[p];
  }
  return p;
}
} // namespace

std::vector<std::int64_t> LabelComponents(const std::vector<std::uint8_t>& label, const std::vector<std::int64_t>& A,
  const std::vector<std::int64_t>& B, std::int64_t& count, const ProgressFunction& progress)
{
  const std::int64_t n = static_cast<std::int64_t>(label.size());
  std::vector<std::int64_t> parent;
  AssignFresh(parent, static_cast<std::size_t>(n));
  std::iota(parent.begin(), parent.end(), std::int64_t(0));
  constexpr std::size_t CheckEvery = (std::size_t(1) << 18) - 1;
  for (std::size_t e = 0; e < A.size(); ++e)
  {
    if ((e & CheckEvery) == CheckEvery && !progress(0.9 * static_cast<double>(e) / static_cast<double>(A.size())))
    {
      return {};
    }
    if (label[A[e]] == label[B[e]])
    {
      std::int64_t a = Find(parent, A[e]), b = Find(parent, B[e]);
      if (a != b)
      {
        // The smaller root wins, so a component's root is its first node whatever the edge order.
        if (b < a)
        {
          std::swap(a, b);
        }
        parent[b] = a;
      }
    }
  }
  for (std::int64_t p = 0; p < n; ++p)
  {
    parent[p] = Find(parent, p);
  }
  // Every root is its component's smallest node, so it is numbered before its other nodes.
  count = 0;
  for (std::int64_t p = 0; p < n; ++p)
  {
    parent[p] = parent[p] == p ? count++ : parent[parent[p]];
  }
  return parent;
}

std::int64_t ApplyConnectivity(Connectivity mode, std::vector<std::uint8_t>& label,
  const std::vector<std::int64_t>& A, const std::vector<std::int64_t>& B, const std::vector<std::uint8_t>& hard,
  const std::vector<std::uint8_t>& border, const ProgressFunction& progress)
{
  if (mode == Connectivity::Off)
  {
    return 0;
  }
  const std::int64_t n = static_cast<std::int64_t>(label.size());
  std::int64_t changed = 0, count = 0;
  // Relabels every node of a component of label `from` that `keep` does not mark; false on abort.
  auto relabel = [&](std::uint8_t from, const std::function<bool(std::int64_t)>& anchors, const ProgressFunction& part) {
    const std::vector<std::int64_t> id = LabelComponents(label, A, B, count, part);
    if (static_cast<std::int64_t>(id.size()) != n)
    {
      return false;
    }
    std::vector<std::uint8_t> keep(count, 0);
    for (std::int64_t p = 0; p < n; ++p)
    {
      if (label[p] == from && anchors(p))
      {
        keep[id[p]] = 1;
      }
    }
    for (std::int64_t p = 0; p < n; ++p)
    {
      if (label[p] == from && !keep[id[p]])
      {
        label[p] = from ? 0 : 1;
        ++changed;
      }
    }
    return true;
  };
  const bool seeded = mode == Connectivity::SeededObject;
  if (seeded && (!relabel(1, [&](std::int64_t p) { return hard[p] == 1; }, SubProgress(progress, 0.0, 0.5)) || !progress(0.5)))
  {
    return -1;
  }
  if (!relabel(0, [&](std::int64_t p) { return hard[p] == 2 || border[p]; }, SubProgress(progress, seeded ? 0.5 : 0.0, 1.0)))
  {
    return -1;
  }
  return progress(1.0) ? changed : -1;
}

std::vector<double> ObjectComponentSizes(const std::vector<std::uint8_t>& label, const std::vector<std::int64_t>& A,
  const std::vector<std::int64_t>& B, const std::vector<double>& size, const ProgressFunction& progress)
{
  std::int64_t count = 0;
  const std::vector<std::int64_t> id = LabelComponents(label, A, B, count, progress);
  if (id.size() != label.size())
  {
    return {};
  }
  std::vector<double> sizes(count, 0.0);
  std::vector<std::uint8_t> isObject(count, 0);
  for (std::size_t p = 0; p < label.size(); ++p)
  {
    sizes[id[p]] += size.empty() ? 1.0 : size[p];
    isObject[id[p]] = label[p];
  }
  std::vector<double> object;
  for (std::int64_t c = 0; c < count; ++c)
  {
    if (isObject[c])
    {
      object.push_back(sizes[c]);
    }
  }
  std::sort(object.begin(), object.end(), std::greater<double>());
  return object;
}
} // namespace featuremesh
