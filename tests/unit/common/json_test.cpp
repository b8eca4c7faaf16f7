// JsonWriter and jsonEscape: output is valid JSON that yaml-cpp reads back to the same values.
#include <limits>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <coredem/common/check.h>
#include <coredem/common/json.h>

namespace {

TEST(Json, EscapesQuotesBackslashesAndControlCharacters) {
  EXPECT_EQ(coredem::jsonEscape("a\"b\\c\nd\te\x01"), "a\\\"b\\\\c\\nd\\te\\u0001");
  EXPECT_EQ(coredem::jsonEscape("plain UTF-8 é"), "plain UTF-8 é");
}

TEST(Json, NestedDocumentReadsBack) {
  coredem::JsonWriter w;
  w.beginObject()
      .field("name", "bed \"A\"")
      .field("steps", 12)
      .field("dt", 0.1)
      .field("ok", true)
      .key("list")
      .beginArray()
      .value(1.5)
      .value(std::numeric_limits<double>::quiet_NaN())
      .beginObject()
      .endObject()
      .endArray()
      .key("empty")
      .beginArray()
      .endArray()
      .endObject();
  const std::string text = w.str();
  const YAML::Node n = YAML::Load(text);
  EXPECT_EQ(n["name"].as<std::string>(), "bed \"A\"");
  EXPECT_EQ(n["steps"].as<int>(), 12);
  EXPECT_EQ(n["dt"].as<double>(), 0.1); // shortest round-trip form: exact
  EXPECT_TRUE(n["ok"].as<bool>());
  ASSERT_EQ(n["list"].size(), 3u);
  EXPECT_TRUE(n["list"][1].IsNull()); // NaN is written as null, never as invalid JSON
  EXPECT_TRUE(n["list"][2].IsMap());
  EXPECT_EQ(n["empty"].size(), 0u);
  EXPECT_EQ(text.back(), '\n');
}

TEST(Json, CompactFormHasNoWhitespace) {
  coredem::JsonWriter w(0);
  w.beginObject().field("a", 1).key("b").beginArray().value("x").endArray().endObject();
  EXPECT_EQ(w.str(), "{\"a\":1,\"b\":[\"x\"]}\n");
}

TEST(Json, MisuseIsAnInternalError) {
  coredem::JsonWriter w;
  w.beginObject();
  EXPECT_THROW(w.value(1), coredem::InternalError); // no key
  EXPECT_THROW(w.str(), coredem::InternalError);    // not closed
  EXPECT_THROW(w.endArray(), coredem::InternalError);
}

} // namespace
