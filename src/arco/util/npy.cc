#include "arco/util/npy.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <type_traits>

#include "arco/util/file_io.h"

namespace arco {
namespace {

static_assert(sizeof(float) == 4 && sizeof(double) == 8, "IEEE types required");

template <typename T>
const char* DescrFor() {
  if constexpr (std::is_same_v<T, float>) return "<f4";
  if constexpr (std::is_same_v<T, double>) return "<f8";
  if constexpr (std::is_same_v<T, int32_t>) return "<i4";
  if constexpr (std::is_same_v<T, int64_t>) return "<i8";
  if constexpr (std::is_same_v<T, uint8_t>) return "|u1";
}

struct Header {
  std::string descr;
  bool fortran_order = false;
  std::vector<int64_t> shape;
};

// Extracts the value text after 'key': in a Python dict literal.
bool FindValue(const std::string& dict, const std::string& key, std::string* value) {
  const std::string needle = "'" + key + "'";
  const size_t k = dict.find(needle);
  if (k == std::string::npos) return false;
  size_t colon = dict.find(':', k + needle.size());
  if (colon == std::string::npos) return false;
  size_t start = colon + 1;
  while (start < dict.size() && dict[start] == ' ') ++start;
  if (start >= dict.size()) return false;
  size_t end = start;
  if (dict[start] == '\'') {
    end = dict.find('\'', start + 1);
    if (end == std::string::npos) return false;
    *value = dict.substr(start + 1, end - start - 1);
  } else if (dict[start] == '(') {
    end = dict.find(')', start);
    if (end == std::string::npos) return false;
    *value = dict.substr(start + 1, end - start - 1);
  } else {
    end = dict.find_first_of(",}", start);
    if (end == std::string::npos) return false;
    *value = dict.substr(start, end - start);
  }
  return true;
}

Status ParseHeader(const std::string& dict, const std::string& source, Header* header) {
  std::string fortran, shape;
  if (!FindValue(dict, "descr", &header->descr) || !FindValue(dict, "fortran_order", &fortran) ||
      !FindValue(dict, "shape", &shape)) {
    return Status::Error(source + ": malformed .npy header");
  }
  header->fortran_order = fortran.rfind("True", 0) == 0;
  std::stringstream ss(shape);
  std::string item;
  while (std::getline(ss, item, ',')) {
    size_t a = item.find_first_not_of(' ');
    if (a == std::string::npos) continue;
    size_t b = item.find_last_not_of(' ');
    item = item.substr(a, b - a + 1);
    if (!item.empty() && item.back() == 'L') item.pop_back();
    if (item.empty() || item.size() > 18 ||
        item.find_first_not_of("0123456789") != std::string::npos) {
      return Status::Error(source + ": malformed .npy shape '" + shape + "'");
    }
    header->shape.push_back(std::stoll(item));
  }
  return Status::Ok();
}

template <typename From, typename To>
Status Convert(const char* raw, int64_t count, const std::string& source, std::vector<To>* out) {
  // Appended into reserved memory rather than resized first: a resize zero-fills the
  // whole array before it is overwritten (3% of `arco run` on a 118 MB keypoints2d.npy).
  out->clear();
  out->reserve(static_cast<size_t>(count));
  for (int64_t i = 0; i < count; ++i) {
    From v;
    std::memcpy(&v, raw + i * static_cast<int64_t>(sizeof(From)), sizeof(From));
    if constexpr (std::is_floating_point_v<From> && !std::is_floating_point_v<To>) {
      if (!std::isfinite(v)) {
        return Status::Error(source + ": non-finite value in an array read as integers");
      }
      // A finite value beyond the integer type's range is undefined behaviour to convert
      // (found by fuzz_npy): [-2^digits, 2^digits) for signed, [0, 2^digits) for unsigned,
      // bounds that are exact powers of two in any floating type.
      const From hi = std::ldexp(From(1), std::numeric_limits<To>::digits);
      const From lo = std::numeric_limits<To>::is_signed ? -hi : From(0);
      const From t = std::trunc(v);
      if (!(t >= lo && t < hi)) {
        return Status::Error(source + ": value out of the integer range in an array read as "
                                      "integers");
      }
    }
    out->push_back(static_cast<To>(v));
  }
  return Status::Ok();
}

// The magic, version and header dict of `bytes` (at least the whole preamble); sets
// `data_offset` to where the array data starts.
Status ParsePreamble(std::string_view bytes,
                     const std::string& source,
                     Header* header,
                     size_t* data_offset) {
  static const char kMagic[] = "\x93NUMPY";
  if (bytes.size() < 10 || bytes.compare(0, 6, std::string_view(kMagic, 6)) != 0) {
    return Status::Error(source + ": not a .npy file (bad magic)");
  }
  const int major = static_cast<unsigned char>(bytes[6]);
  size_t header_len = 0, offset = 0;
  if (major == 1) {
    header_len = static_cast<unsigned char>(bytes[8]) |
                 (static_cast<size_t>(static_cast<unsigned char>(bytes[9])) << 8);
    offset = 10;
  } else if (major == 2 || major == 3) {
    if (bytes.size() < 12) return Status::Error(source + ": truncated .npy header");
    for (int i = 0; i < 4; ++i) {
      header_len |= static_cast<size_t>(static_cast<unsigned char>(bytes[8 + i])) << (8 * i);
    }
    offset = 12;
  } else {
    return Status::Error(source + ": unsupported .npy version " + std::to_string(major));
  }
  if (header_len > bytes.size() - offset) return Status::Error(source + ": truncated .npy header");
  ARCO_RETURN_IF_ERROR(ParseHeader(std::string(bytes.substr(offset, header_len)), source, header));
  if (header->fortran_order) return Status::Error(source + ": Fortran-order .npy not supported");
  *data_offset = offset + header_len;
  return Status::Ok();
}

}  // namespace

std::string NpyDtypeName(const std::string& descr) {
  if (descr == "<f4") return "float32";
  if (descr == "<f8") return "float64";
  if (descr == "<i4") return "int32";
  if (descr == "<i8") return "int64";
  if (descr == "|u1" || descr == "<u1") return "uint8";
  if (descr == "|b1") return "bool";
  return "'" + descr + "'";
}

StatusOr<NpyHeader> ReadNpyHeader(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) return Status::Error(path + ": file not found");
  if (std::filesystem::is_directory(path, ec)) {
    return Status::Error(path + ": is a directory, expected a file");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return Status::Error(path + ": cannot open: " + std::strerror(errno));
  // The preamble is 10 or 12 bytes; the dict's length is in it.
  std::string bytes(12, '\0');
  in.read(bytes.data(), 12);
  bytes.resize(static_cast<size_t>(in.gcount()));
  size_t header_len = 0;
  if (bytes.size() >= 10 && bytes[6] == 1) {
    header_len = static_cast<unsigned char>(bytes[8]) |
                 (static_cast<size_t>(static_cast<unsigned char>(bytes[9])) << 8);
  } else if (bytes.size() >= 12) {
    for (int i = 0; i < 4; ++i) {
      header_len |= static_cast<size_t>(static_cast<unsigned char>(bytes[8 + i])) << (8 * i);
    }
  }
  // A header dict is a few hundred bytes; cap what a corrupt length makes us read.
  const size_t more = std::min<size_t>(header_len, size_t{1} << 20);
  std::string rest(more, '\0');
  in.read(rest.data(), static_cast<std::streamsize>(more));
  rest.resize(static_cast<size_t>(in.gcount()));
  bytes += rest;
  return ParseNpyHeader(bytes, path);
}

StatusOr<NpyHeader> ParseNpyHeader(std::string_view bytes, const std::string& source) {
  Header header;
  size_t data_offset = 0;
  ARCO_RETURN_IF_ERROR(ParsePreamble(bytes, source, &header, &data_offset));
  NpyHeader out;
  out.descr = header.descr;
  out.dtype = NpyDtypeName(header.descr);
  out.is_float = header.descr == "<f4" || header.descr == "<f8";
  out.shape = header.shape;
  return out;
}

template <typename T>
int64_t NpyArray<T>::size() const {
  int64_t n = 1;
  for (int64_t d : shape) n *= d;
  return n;
}

template <typename T>
T& NpyArray<T>::at(int64_t i0, int64_t i1, int64_t i2, int64_t i3) {
  return const_cast<T&>(static_cast<const NpyArray<T>*>(this)->at(i0, i1, i2, i3));
}

template <typename T>
const T& NpyArray<T>::at(int64_t i0, int64_t i1, int64_t i2, int64_t i3) const {
  const int64_t idx[4] = {i0, i1, i2, i3};
  int64_t flat = 0;
  for (size_t d = 0; d < shape.size(); ++d) {
    ARCO_CHECK(d < 4 && idx[d] >= 0 && idx[d] < shape[d]) << "npy index out of range";
    flat = flat * shape[d] + idx[d];
  }
  return data[static_cast<size_t>(flat)];
}

template <typename T>
StatusOr<NpyArray<T>> ParseNpy(std::string_view bytes, const std::string& source) {
  Header header;
  size_t data_offset = 0;
  ARCO_RETURN_IF_ERROR(ParsePreamble(bytes, source, &header, &data_offset));
  NpyArray<T> array;
  array.shape = header.shape;
  int64_t count = 1;
  for (int64_t d : header.shape) {
    if (d < 0 || (d > 0 && count > std::numeric_limits<int64_t>::max() / 16 / d)) {
      return Status::Error(source + ": .npy shape too large");
    }
    count *= d;
  }
  const size_t available = bytes.size() - data_offset;
  const char* raw = bytes.data() + data_offset;
  auto need = [&](size_t item) -> Status {
    if (static_cast<uint64_t>(count) > available / item) {
      return Status::Error(source + ": truncated .npy data (expected " + std::to_string(count) +
                           " items)");
    }
    return Status::Ok();
  };
  const std::string& d = header.descr;
  if (d == "<f4") {
    ARCO_RETURN_IF_ERROR(need(4));
    ARCO_RETURN_IF_ERROR((Convert<float, T>(raw, count, source, &array.data)));
  } else if (d == "<f8") {
    ARCO_RETURN_IF_ERROR(need(8));
    ARCO_RETURN_IF_ERROR((Convert<double, T>(raw, count, source, &array.data)));
  } else if (d == "<i4") {
    ARCO_RETURN_IF_ERROR(need(4));
    ARCO_RETURN_IF_ERROR((Convert<int32_t, T>(raw, count, source, &array.data)));
  } else if (d == "<i8") {
    ARCO_RETURN_IF_ERROR(need(8));
    ARCO_RETURN_IF_ERROR((Convert<int64_t, T>(raw, count, source, &array.data)));
  } else if (d == "|u1" || d == "<u1" || d == "|b1") {
    ARCO_RETURN_IF_ERROR(need(1));
    ARCO_RETURN_IF_ERROR((Convert<uint8_t, T>(raw, count, source, &array.data)));
  } else {
    return Status::Error(source + ": unsupported .npy dtype '" + d + "'");
  }
  return array;
}

template <typename T>
StatusOr<NpyArray<T>> ReadNpy(const std::string& path) {
  ARCO_ASSIGN_OR_RETURN(const FileBytes bytes, FileBytes::Open(path));
  return ParseNpy<T>(bytes.view(), path);
}

template <typename T>
std::string SerializeNpy(const NpyArray<T>& array) {
  ARCO_CHECK(static_cast<int64_t>(array.data.size()) == array.size()) << "npy shape/data mismatch";
  std::string dict =
      std::string("{'descr': '") + DescrFor<T>() + "', 'fortran_order': False, 'shape': (";
  for (size_t i = 0; i < array.shape.size(); ++i) {
    dict += std::to_string(array.shape[i]);
    if (array.shape.size() == 1 || i + 1 < array.shape.size()) dict += ",";
    if (i + 1 < array.shape.size()) dict += " ";
  }
  dict += "), }";
  // Pad so the data starts on a 64-byte boundary (numpy convention).
  const size_t preamble = 10;
  size_t total = preamble + dict.size() + 1;
  dict.append((64 - total % 64) % 64, ' ');
  dict.push_back('\n');
  std::string out("\x93NUMPY\x01\x00", 8);
  out.push_back(static_cast<char>(dict.size() & 0xff));
  out.push_back(static_cast<char>((dict.size() >> 8) & 0xff));
  out += dict;
  out.append(reinterpret_cast<const char*>(array.data.data()), array.data.size() * sizeof(T));
  return out;
}

template <typename T>
Status WriteNpy(const std::string& path, const NpyArray<T>& array) {
  if (static_cast<int64_t>(array.data.size()) != array.size()) {
    throw std::invalid_argument("WriteNpy: data size does not match shape");
  }
  return AtomicWriteFile(path, SerializeNpy(array));
}

#define ARCO_NPY_INSTANTIATE(T)                                                     \
  template struct NpyArray<T>;                                                      \
  template StatusOr<NpyArray<T>> ReadNpy<T>(const std::string&);                    \
  template StatusOr<NpyArray<T>> ParseNpy<T>(std::string_view, const std::string&); \
  template Status WriteNpy<T>(const std::string&, const NpyArray<T>&);              \
  template std::string SerializeNpy<T>(const NpyArray<T>&);
ARCO_NPY_INSTANTIATE(float)
ARCO_NPY_INSTANTIATE(double)
ARCO_NPY_INSTANTIATE(int32_t)
ARCO_NPY_INSTANTIATE(int64_t)
ARCO_NPY_INSTANTIATE(uint8_t)
#undef ARCO_NPY_INSTANTIATE

}  // namespace arco
