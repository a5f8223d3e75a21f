// The scorer's JSON reader.
#include <gtest/gtest.h>

#include "score/json.hpp"

namespace fieldguard::score {
namespace {

TEST(ScoreJson, ReadsEveryKindOfValue) {
  const auto r = parse_json(R"( {"a": 1, "b": -2.5e3, "c": "x\"y\\u00e9\ud83d\ude00", "d": [true, false, null, []],
                                 "e": {}, "a": 7} )");
  ASSERT_TRUE(r.value) << r.error.message;
  const JsonValue& v = *r.value;
  ASSERT_TRUE(v.is_object());
  EXPECT_EQ(v.find("a")->number, 1.0);  // a repeated key keeps its first value
  EXPECT_EQ(v.find("b")->number, -2500.0);
  EXPECT_EQ(v.find("c")->string, "x\"y\\u00e9\xF0\x9F\x98\x80");
  const JsonValue* d = v.find("d");
  ASSERT_TRUE(d != nullptr && d->is_array());
  ASSERT_EQ(d->items.size(), 4U);
  EXPECT_TRUE(d->items[0].boolean);
  EXPECT_EQ(d->items[2].kind, JsonValue::Kind::Null);
  EXPECT_TRUE(d->items[3].is_array());
  EXPECT_TRUE(v.find("e")->is_object());
  EXPECT_EQ(v.find("zzz"), nullptr);
}

TEST(ScoreJson, UnicodeEscapes) {
  const auto r = parse_json(R"("\u00e9\u20ac\n\t\/")");
  ASSERT_TRUE(r.value);
  EXPECT_EQ(r.value->string, "\xC3\xA9\xE2\x82\xAC\n\t/");
}

TEST(ScoreJson, RejectsWhatIsNotJson) {
  for (const char* bad : {"", "{", "{\"a\" 1}", "{\"a\": 1,}", "[1 2]", "01", "1.", "-", ".5", "1e", "nul", "tru",
                          "\"abc", "\"\\x\"", "\"\\ud83d\"", "{\"a\": 1} x", "{a: 1}", "[1e999]", "\"a\tb\"", "'a'"}) {
    const auto r = parse_json(bad);
    EXPECT_FALSE(r.value) << "accepted: " << bad;
  }
  std::string deep(100, '[');
  deep += std::string(100, ']');
  EXPECT_FALSE(parse_json(deep).value);
  const auto r = parse_json("{\"stamp\": 1.0, \"obstacles\": [}");
  ASSERT_FALSE(r.value);
  EXPECT_EQ(r.error.offset, 29U);  // the '}' where a value was expected
}

}  // namespace
}  // namespace fieldguard::score
