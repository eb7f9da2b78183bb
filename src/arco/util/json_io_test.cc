#include "arco/util/json_io.h"

#include <gtest/gtest.h>

#include <cmath>

namespace arco {
namespace {

TEST(ParseJsonLenient, AcceptsBareNaNAndInfinityTokens) {
  auto json = ParseJsonLenient(R"({"a": [1.5, NaN, -Infinity, Infinity], "s": "NaN"})", "x.json");
  ASSERT_TRUE(json.ok()) << json.status().message();
  const Json& a = (*json)["a"];
  EXPECT_DOUBLE_EQ(JsonNumberOrNaN(a[0]), 1.5);
  EXPECT_TRUE(std::isnan(JsonNumberOrNaN(a[1])));
  EXPECT_TRUE(std::isnan(JsonNumberOrNaN(a[2])));
  EXPECT_TRUE(std::isnan(JsonNumberOrNaN(a[3])));
  EXPECT_EQ((*json)["s"], "NaN");  // strings untouched
}

TEST(ParseJsonMarkingNonFinite, TellsTheTokensFromNullAndStrings) {
  auto json = ParseJsonMarkingNonFinite(
      R"({"a": [NaN, -Infinity, Infinity, null], "s": "NaN", "t": "x NaN"})", "x.json");
  ASSERT_TRUE(json.ok()) << json.status().message();
  const Json& a = (*json)["a"];
  EXPECT_EQ(NonFiniteToken(a[0]), "NaN");
  EXPECT_EQ(NonFiniteToken(a[1]), "-Infinity");
  EXPECT_EQ(NonFiniteToken(a[2]), "Infinity");
  EXPECT_EQ(NonFiniteToken(a[3]), "");          // a real null
  EXPECT_EQ(NonFiniteToken((*json)["s"]), "");  // a string "NaN" is a string
  EXPECT_EQ((*json)["t"], "x NaN");
}

TEST(ParseJsonLenient, MalformedJsonNamesTheSource) {
  auto json = ParseJsonLenient("{\"a\": [1, 2", "broken.json");
  ASSERT_FALSE(json.ok());
  EXPECT_NE(json.status().message().find("broken.json"), std::string::npos);
}

TEST(ReadJsonFile, MissingFileIsAnError) {
  auto json = ReadJsonFile("/nonexistent/file.json");
  ASSERT_FALSE(json.ok());
  EXPECT_NE(json.status().message().find("not found"), std::string::npos);
}

TEST(JsonFromDouble, NonFiniteBecomesNull) {
  EXPECT_TRUE(JsonFromDouble(NAN).is_null());
  EXPECT_EQ(JsonFromDouble(2.0), Json(2.0));
}

}  // namespace
}  // namespace arco
