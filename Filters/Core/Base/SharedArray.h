// An immutable array that whoever needs it keeps by reference: a cut's problem and the records its
// caches keep for the next cut share one copy of the elements' values, sizes, steps and contacts
// instead of holding three (at 512^3, 4 M elements and 8 M faces, 0.3 GB). Reads as a const
// std::vector; Mutable() copies first when the array is shared, so no holder sees it change.
#pragma once

#include <cstddef>
#include <initializer_list>
#include <memory>
#include <vector>

namespace featuremesh
{
template <typename T>
class SharedArray
{
public:
  SharedArray() = default;
  SharedArray(std::vector<T> values)
    : Data(std::make_shared<std::vector<T>>(std::move(values)))
  {
  }
  SharedArray(std::initializer_list<T> values)
    : SharedArray(std::vector<T>(values))
  {
  }

  std::size_t size() const { return this->Data ? this->Data->size() : 0; }
  bool empty() const { return this->size() == 0; }
  const T* data() const { return this->Data ? this->Data->data() : nullptr; }
  const T& operator[](std::size_t i) const { return (*this->Data)[i]; }
  const T* begin() const { return this->data(); }
  const T* end() const { return this->data() + this->size(); }
  const std::vector<T>& Vector() const
  {
    static const std::vector<T> none;
    return this->Data ? *this->Data : none;
  }

  // The same storage: equal without reading it.
  bool SameStorage(const SharedArray& o) const { return this->Data == o.Data; }
  friend bool operator==(const SharedArray& a, const SharedArray& b)
  {
    return a.SameStorage(b) || a.Vector() == b.Vector();
  }
  friend bool operator!=(const SharedArray& a, const SharedArray& b) { return !(a == b); }

  // The array to change, this holder's own.
  std::vector<T>& Mutable()
  {
    if (!this->Data)
    {
      this->Data = std::make_shared<std::vector<T>>();
    }
    else if (this->Data.use_count() > 1)
    {
      this->Data = std::make_shared<std::vector<T>>(*this->Data);
    }
    return *this->Data;
  }

private:
  std::shared_ptr<std::vector<T>> Data;
};
} // namespace featuremesh
