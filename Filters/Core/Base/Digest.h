// FNV-1a over 64-bit words, then the tail bytes: the key under which a cache recognises data it
// does not keep (a mesh's points and cells, a cut's contact areas).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

namespace featuremesh
{
constexpr std::uint64_t DigestSeed = 0xcbf29ce484222325ULL;

inline std::uint64_t DigestWord(std::uint64_t h, std::uint64_t word)
{
  return (h ^ word) * 0x100000001b3ULL;
}

inline std::uint64_t DigestBytes(std::uint64_t h, const void* data, std::size_t bytes)
{
  const unsigned char* p = static_cast<const unsigned char*>(data);
  std::size_t i = 0;
  for (; i + 8 <= bytes; i += 8)
  {
    std::uint64_t w;
    std::memcpy(&w, p + i, 8);
    h = DigestWord(h, w);
  }
  for (; i < bytes; ++i)
  {
    h = DigestWord(h, p[i]);
  }
  return h;
}
} // namespace featuremesh
