#pragma once
// Fields of the finite-volume vocabulary: one value per cell or per face, indexed by the mesh's int
// cell and face numbers. A field is a std::vector (it binds to const std::vector<T>&), whose
// operator[] takes any integer type, so that the numerics index with the mesh's ints directly.
#include <concepts>
#include <cstddef>
#include <vector>

namespace runout::engine::vof {

template <class T, class Tag>
struct Field : std::vector<T> {
  using std::vector<T>::vector;
  Field() = default;
  Field(std::vector<T> v) : std::vector<T>(std::move(v)) {}  // NOLINT: a field is a vector
  template <std::integral I>
  T& operator[](I i) {
    return std::vector<T>::operator[](std::size_t(i));
  }
  template <std::integral I>
  const T& operator[](I i) const {
    return std::vector<T>::operator[](std::size_t(i));
  }
};

struct CellTag {};
struct FaceTag {};
template <class T>
using CellField = Field<T, CellTag>;  ///< one value per cell
template <class T>
using FaceField = Field<T, FaceTag>;  ///< one value per face (internal faces first, then the patches)

}  // namespace runout::engine::vof
