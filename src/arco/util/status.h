// Expected-failure reporting (error kind 3 in docs/architecture.md): a Status
// carries one readable line; StatusOr<T> carries a value or that line.
// Bugs use ARCO_CHECK (check.h); caller mistakes throw std::invalid_argument.
// Both are [[nodiscard]]: an ignored error is a compiler warning. Where ignoring one is
// deliberate, say why and cast to void.
#pragma once

#include <optional>
#include <string>
#include <utility>

#include "arco/util/check.h"

namespace arco {

class [[nodiscard]] Status {
 public:
  Status() = default;  // OK
  static Status Ok() { return Status(); }
  static Status Error(std::string message) { return Status(std::move(message)); }

  bool ok() const { return !message_.has_value(); }
  const std::string& message() const {
    static const std::string kOk = "OK";
    return message_ ? *message_ : kOk;
  }
  // Prefixes context, e.g. the file name: "rig.xml: camera 3 has no transform".
  Status WithContext(const std::string& context) const {
    return ok() ? *this : Status(context + ": " + *message_);
  }

 private:
  explicit Status(std::string message) : message_(std::move(message)) {}
  std::optional<std::string> message_;
};

template <typename T>
class [[nodiscard]] StatusOr {
 public:
  StatusOr(T value) : value_(std::move(value)) {}  // NOLINT: implicit by design
  StatusOr(Status status) : status_(std::move(status)) {  // NOLINT
    ARCO_CHECK(!status_.ok()) << "StatusOr constructed from an OK status without a value";
  }
  bool ok() const { return value_.has_value(); }
  const Status& status() const { return status_; }
  const T& value() const& {
    ARCO_CHECK(ok()) << status_.message();
    return *value_;
  }
  T& value() & {
    ARCO_CHECK(ok()) << status_.message();
    return *value_;
  }
  T&& value() && {
    ARCO_CHECK(ok()) << status_.message();
    return std::move(*value_);
  }
  const T& operator*() const& { return value(); }
  T& operator*() & { return value(); }
  const T* operator->() const { return &value(); }
  T* operator->() { return &value(); }

 private:
  Status status_;
  std::optional<T> value_;
};

}  // namespace arco

// Returns early from a Status-returning function when `expr` fails.
#define ARCO_RETURN_IF_ERROR(expr)          \
  do {                                      \
    ::arco::Status arco_status_ = (expr);   \
    if (!arco_status_.ok()) return arco_status_; \
  } while (0)

#define ARCO_CONCAT_INNER(a, b) a##b
#define ARCO_CONCAT(a, b) ARCO_CONCAT_INNER(a, b)
// ARCO_ASSIGN_OR_RETURN(auto x, MakeX()); returns the error Status on failure.
#define ARCO_ASSIGN_OR_RETURN(lhs, expr) \
  ARCO_ASSIGN_OR_RETURN_IMPL(ARCO_CONCAT(arco_statusor_, __LINE__), lhs, expr)
#define ARCO_ASSIGN_OR_RETURN_IMPL(tmp, lhs, expr) \
  auto tmp = (expr);                               \
  if (!tmp.ok()) return tmp.status();              \
  lhs = std::move(tmp).value()
