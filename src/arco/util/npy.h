// NumPy .npy arrays (format version 1.0/2.0, little-endian, C order), so every
// per-frame array arco writes is readable with numpy.load() and no arco.
// Supported dtypes: float32 '<f4', float64 '<f8', int32 '<i4', int64 '<i8',
// uint8 '|u1'. Missing values in float arrays are NaN.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "arco/util/status.h"

namespace arco {

enum class NpyType { kFloat32, kFloat64, kInt32, kInt64, kUInt8 };

// A dense array; data is stored as double for arithmetic convenience when read
// through NpyArray<double>. The template is instantiated for float, double,
// int32_t, int64_t and uint8_t.
template <typename T>
struct NpyArray {
  std::vector<int64_t> shape;
  std::vector<T> data;  // C order

  int64_t size() const;
  // Flat index helper for up to 4 dimensions.
  T& at(int64_t i0, int64_t i1 = 0, int64_t i2 = 0, int64_t i3 = 0);
  const T& at(int64_t i0, int64_t i1 = 0, int64_t i2 = 0, int64_t i3 = 0) const;
};

// Reads an .npy file; converts any supported stored dtype into T (a NaN in a
// float file read as an integer type is an error).
template <typename T>
StatusOr<NpyArray<T>> ReadNpy(const std::string& path);
// Parses .npy bytes; `source` names the file in messages (used by the fuzzer).
template <typename T>
StatusOr<NpyArray<T>> ParseNpy(std::string_view bytes, const std::string& source);

// The header of an .npy file, read without its data (checks before the work).
struct NpyHeader {
  std::string descr;      // as stored, e.g. "<f4"
  std::string dtype;      // NumPy's name, e.g. "float32", "int32"
  bool is_float = false;  // float32 or float64
  std::vector<int64_t> shape;
};
StatusOr<NpyHeader> ReadNpyHeader(const std::string& path);
// The same of a whole file's bytes already read (errors name `source`).
StatusOr<NpyHeader> ParseNpyHeader(std::string_view bytes, const std::string& source);
// "float32", "int32", ... for a stored descr ("'<c8'" quoted for others).
std::string NpyDtypeName(const std::string& descr);

// Writes atomically with the dtype that matches T.
template <typename T>
Status WriteNpy(const std::string& path, const NpyArray<T>& array);
template <typename T>
std::string SerializeNpy(const NpyArray<T>& array);

}  // namespace arco
