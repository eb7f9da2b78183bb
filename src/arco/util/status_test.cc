#include "arco/util/status.h"

#include <gtest/gtest.h>

#include "arco/util/validated.h"

namespace arco {
namespace {

StatusOr<int> Half(int x) {
  if (x % 2) return Status::Error("odd");
  return x / 2;
}

Status Quarter(int x, int* out) {
  ARCO_ASSIGN_OR_RETURN(int h, Half(x));
  ARCO_ASSIGN_OR_RETURN(int q, Half(h));
  *out = q;
  return Status::Ok();
}

TEST(StatusOr, PropagatesErrorsAndValues) {
  int q = 0;
  EXPECT_TRUE(Quarter(8, &q).ok());
  EXPECT_EQ(q, 2);
  Status s = Quarter(6, &q);
  EXPECT_FALSE(s.ok());
  EXPECT_EQ(s.message(), "odd");
  EXPECT_EQ(s.WithContext("f.json").message(), "f.json: odd");
}

struct CountedOptions {
  int value = 1;
  mutable int checks = 0;
  Status Validate() const {
    ++checks;
    return value > 0 ? Status::Ok() : Status::Error("value must be > 0");
  }
};

TEST(Validated, ChecksOnceAndCarriesTheOptionsOrTheError) {
  CountedOptions o;
  StatusOr<Validated<CountedOptions>> valid = Validated<CountedOptions>::Check(o);
  ASSERT_TRUE(valid.ok());
  EXPECT_EQ((*valid)->value, 1);
  EXPECT_EQ((*valid)->checks, 1);  // the copy it holds was checked once
  o.value = 0;
  StatusOr<Validated<CountedOptions>> invalid = Validated<CountedOptions>::Check(o);
  ASSERT_FALSE(invalid.ok());
  EXPECT_EQ(invalid.status().message(), "value must be > 0");
}

TEST(StatusOrDeathTest, ValueOfErrorAborts) {
  StatusOr<int> bad = Status::Error("boom");
  EXPECT_DEATH((void)bad.value(), "boom");
}

}  // namespace
}  // namespace arco
