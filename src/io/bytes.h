#pragma once
/// \file bytes.h
/// Scalars in a binary file's bytes, one copy for every format: the readers of binary PLY, STL,
/// PCD and LAS, and the binary PLY writer. Loads go through memcpy, so a record's fields need no
/// alignment.

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstring>

namespace focal::io_detail {

/// The T stored at p, its bytes reversed when `swap` (the file's byte order is not the host's).
template <class T>
T load(const unsigned char* p, bool swap) {
  unsigned char bytes[sizeof(T)];
  if (swap) {
    for (std::size_t i = 0; i < sizeof(T); ++i) bytes[i] = p[sizeof(T) - 1 - i];
  } else {
    std::memcpy(bytes, p, sizeof(T));
  }
  T value;
  std::memcpy(&value, bytes, sizeof(T));
  return value;
}

/// The T stored little endian at p (STL, PCD and LAS store every scalar so).
template <class T>
T load_little_endian(const void* p) {
  return load<T>(static_cast<const unsigned char*>(p), std::endian::native == std::endian::big);
}

/// Stores `value` little endian at p (the byte order focal writes); returns the byte after it.
template <class T>
char* put_little_endian(char* p, T value) {
  std::memcpy(p, &value, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(p, p + sizeof(T));
  return p + sizeof(T);
}

}  // namespace focal::io_detail
