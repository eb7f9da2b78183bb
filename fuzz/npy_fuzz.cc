// Fuzzes the .npy reader: any bytes must give an array or an error, never a crash.
#include <cstddef>
#include <cstdint>
#include <string>

#include "arco/util/npy.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  auto a = arco::ParseNpy<double>(bytes, "fuzz.npy");
  if (a.ok()) (void)a->size();
  auto b = arco::ParseNpy<int32_t>(bytes, "fuzz.npy");
  (void)b.ok();
  return 0;
}
