// The scorer's JSON lines (read through nlohmann/json): what it takes from a line, and that whatever is not
// JSON stops it with the file, the line and where in the line.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "score/frames.hpp"
#include "tools/tools_test_support.hpp"

namespace fieldguard::score {
namespace {

using tools_test::ScratchDir;
using tools_test::write_file;

class ScoreJson : public ::testing::Test {
 protected:
  // Reads `text` as a detections file; `error` holds the reader's message when it fails.
  bool detections(const std::string& text, std::vector<DetectionFrame>& out, std::string& error) const {
    write_file(dir_.file("det.jsonl"), text);
    return read_detections(dir_.file("det.jsonl"), out, error);
  }
  bool truth(const std::string& text, std::vector<TruthFrame>& out, std::string& error) const {
    write_file(dir_.file("truth.jsonl"), text);
    return read_truth(dir_.file("truth.jsonl"), out, error);
  }
  ScratchDir dir_{"score_json"};
};

TEST_F(ScoreJson, ReadsEveryKindOfValue) {
  // Members the scorer does not use may hold any value; a repeated key keeps its first value.
  std::vector<DetectionFrame> d;
  std::string error;
  ASSERT_TRUE(detections(R"( {"stamp": -2.5e3, "c": "x\"y\\u00e9\ud83d\ude00", "d": [true, false, null, []],)"
                         R"( "e": {}, "obstacles": [{"min": [1, 2E0, 3.0], "max": [4, 5, 6], "points": 7}],)"
                         R"( "partial": true, "stamp": 7} )"
                         "\n",
                         d, error))
      << error;
  ASSERT_EQ(d.size(), 1U);
  EXPECT_EQ(d[0].stamp, -2500.0);
  EXPECT_TRUE(d[0].partial);
  ASSERT_EQ(d[0].obstacles.size(), 1U);
  EXPECT_EQ(d[0].obstacles[0].box.min[1], 2.0);
  EXPECT_EQ(d[0].obstacles[0].box.max[2], 6.0);
  EXPECT_EQ(d[0].obstacles[0].points, 7);

  // Strings: every escape, \u with surrogate pairs, written out as UTF-8.
  std::vector<TruthFrame> t;
  ASSERT_TRUE(truth(R"({"stamp": 1, "objects": [{"id": "x\"y\\u00e9\ud83d\ude00", "class": "p", "min": [0, 0, 0],)"
                    R"( "max": [1, 1, 1], "hits": 3}, {"id": "\u00e9\u20ac\n\t\/", "class": "p", "min": [0, 0, 0],)"
                    R"( "max": [1, 1, 1], "hits": 3, "id": "second"}]})"
                    "\n",
                    t, error))
      << error;
  ASSERT_EQ(t.size(), 1U);
  ASSERT_EQ(t[0].objects.size(), 2U);
  EXPECT_EQ(t[0].objects[0].id, "x\"y\\u00e9\xF0\x9F\x98\x80");
  EXPECT_EQ(t[0].objects[1].id, "\xC3\xA9\xE2\x82\xAC\n\t/");
}

TEST_F(ScoreJson, RejectsWhatIsNotJson) {
  for (const std::string bad :
       {"",    "{",     "{\"a\" 1}", "{\"a\": 1,}", "[1 2]",        "01",     "1.",      "-",        ".5", "1e", "nul",
        "tru", "\"abc", "\"\\x\"",   "\"\\ud83d\"", "{\"a\": 1} x", "{a: 1}", "[1e999]", "\"a\tb\"", "'a'"}) {
    // As a member's value, and (but for the empty text: a blank line is skipped) as the whole line.
    for (const std::string& line : {R"({"stamp": 1, "obstacles": [], "x": )" + bad + "}", bad}) {
      if (line.empty()) continue;
      std::vector<DetectionFrame> d;
      std::string error;
      EXPECT_FALSE(detections("{\"stamp\": 0, \"obstacles\": []}\n" + line + "\n", d, error)) << "accepted: " << line;
      EXPECT_NE(error.find("det.jsonl:2: not valid JSON"), std::string::npos) << line << " -> " << error;
    }
  }
  std::vector<DetectionFrame> d;
  std::string error;
  EXPECT_FALSE(detections("{\"stamp\": 1.0, \"obstacles\": [}\n", d, error));
  EXPECT_NE(error.find("det.jsonl:1: not valid JSON at column 30: "), std::string::npos) << error;  // the '}'
  // Valid JSON that is not one object per line.
  EXPECT_FALSE(detections("[{\"stamp\": 1.0, \"obstacles\": []}]\n", d, error));
  EXPECT_NE(error.find("det.jsonl:1: a line must be one JSON object"), std::string::npos) << error;
}

TEST_F(ScoreJson, DeepNestingIsReadWithoutRecursion) {
  // nlohmann's parser keeps its own stack (the hand-written reader it replaced refused more than 64 levels to
  // protect the call stack): a hostile line nested 100000 deep is read, not a crash.
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  std::vector<DetectionFrame> d;
  std::string error;
  ASSERT_TRUE(detections("{\"stamp\": 1.0, \"x\": " + deep + ", \"obstacles\": []}\n", d, error)) << error;
  EXPECT_EQ(d.size(), 1U);
}

}  // namespace
}  // namespace fieldguard::score
