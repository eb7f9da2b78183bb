// Broken invariants (bugs): ARCO_CHECK(cond) << "context"; aborts with file:line.
#pragma once

#include <cstdlib>
#include <iostream>
#include <sstream>

namespace arco::internal {

class CheckFailure {
 public:
  CheckFailure(const char* file, int line, const char* condition) {
    stream_ << file << ":" << line << ": check failed: " << condition << " ";
  }
  [[noreturn]] ~CheckFailure() {
    std::cerr << stream_.str() << std::endl;
    std::abort();
  }
  std::ostream& stream() { return stream_; }

 private:
  std::ostringstream stream_;
};

struct Voidify {
  void operator&(std::ostream&) {}
};

}  // namespace arco::internal

#define ARCO_CHECK(condition) \
  (condition) ? (void)0       \
              : ::arco::internal::Voidify() & \
                    ::arco::internal::CheckFailure(__FILE__, __LINE__, #condition).stream()
