#include "mapless/io/yaml_reader.h"

#include <gtest/gtest.h>

#include "mapless/core/check.h"
#include "mapless/core/testing.h"

namespace mapless::io {
namespace {

TEST(YamlMap, ReadsTypedFieldsAndDefaults) {
  const YamlMap m =
      YamlMap::LoadString("a: 1.5\nb: 3\nc: hello\nd: [1, 2, 3]\ne: true\n", "t.yaml");
  EXPECT_DOUBLE_EQ(m.GetDouble("a"), 1.5);
  EXPECT_EQ(m.GetInt("b"), 3);
  EXPECT_EQ(m.GetString("c"), "hello");
  EXPECT_EQ(m.GetDoubles("d", 3).size(), 3u);
  EXPECT_TRUE(m.GetBool("e", false));
  EXPECT_DOUBLE_EQ(m.GetDouble("missing", 7.0), 7.0);
}

TEST(YamlMap, ADuplicateKeyIsRefusedAtAnyDepth) {
  std::string err =
      testing::InputErrorOf([] { YamlMap::LoadString("a: 1\nb: 2\na: 3\n", "d.yaml"); });
  EXPECT_NE(err.find("d.yaml:3:1: duplicate key 'a'"), std::string::npos) << err;
  err = testing::InputErrorOf(
      [] { YamlMap::LoadString("list:\n  - {x: 1, y: 2, x: 1}\n", "d.yaml"); });
  EXPECT_NE(err.find("duplicate key 'x'"), std::string::npos) << err;
  EXPECT_NO_THROW(YamlMap::LoadString("a: {x: 1}\nb: {x: 1}\n", "ok.yaml"));
}

// "Billion laughs": ten levels of ten aliases each, a 600-byte file that is 10^10 values when
// read. Refused by its expanded size before anything walks it (it took minutes of CPU before).
std::string NestedAliases(int levels) {
  std::string text = "x0: &a0 [x, x, x, x, x, x, x, x, x, x]\n";
  for (int i = 1; i < levels; ++i) {
    text += "x" + std::to_string(i) + ": &a" + std::to_string(i) + " [";
    for (int k = 0; k < 10; ++k) text += (k ? ", *a" : "*a") + std::to_string(i - 1);
    text += "]\n";
  }
  return text;
}

TEST(YamlMap, ADocumentThatExpandsWithItsAliasesIsRefusedByItsSize) {
  const std::string err =
      testing::InputErrorOf([] { YamlMap::LoadString(NestedAliases(10), "laughs.yaml"); });
  EXPECT_NE(err.find("laughs.yaml:"), std::string::npos) << err;
  EXPECT_NE(err.find("expands to more than 1048576 values"), std::string::npos) << err;
  // Aliases as people use them, and five levels (10^5 values), are read.
  EXPECT_NO_THROW(YamlMap::LoadString(NestedAliases(5), "ok.yaml"));
  const YamlMap m = YamlMap::LoadString("base: &b {x: 1}\nother: *b\n", "ok.yaml");
  EXPECT_EQ(m.GetMap("other").GetInt("x"), 1);
}

TEST(YamlMap, AnAliasInsideTheNodeItNamesIsRefused) {
  // A cycle: walking it never ends (fuzz_config found the shape; the walk hung before).
  for (const char* text : {"a: &x {b: *x}\n", "a: &x [1, *x]\n", "a: &x {b: [c, {d: *x}]}\n"}) {
    const std::string err = testing::InputErrorOf([&] { YamlMap::LoadString(text, "cycle.yaml"); });
    EXPECT_NE(err.find("cycle.yaml:1:"), std::string::npos) << err;
    EXPECT_NE(err.find("an alias inside the node it names"), std::string::npos) << err;
  }
  EXPECT_NO_THROW(YamlMap::LoadString("a: &x {b: 1}\nc: {d: *x}\n", "ok.yaml"));
}

TEST(YamlMap, MalformedYamlNamesFileAndLine) {
  const std::string err =
      testing::InputErrorOf([] { YamlMap::LoadString("a: 1\nb: [1, 2\n", "bad.yaml"); });
  EXPECT_NE(err.find("bad.yaml:"), std::string::npos) << err;
  EXPECT_NE(err.find("malformed YAML"), std::string::npos) << err;
}

TEST(YamlMap, WrongTypeNamesFieldPathAndLine) {
  const YamlMap m = YamlMap::LoadString("world:\n  objects:\n    - size: [1, x]\n", "w.yaml");
  const std::string err = testing::InputErrorOf(
      [&] { m.GetMap("world").GetMapList("objects")[0].GetDoubles("size", 2); });
  EXPECT_NE(err.find("w.yaml:3:"), std::string::npos) << err;
  EXPECT_NE(err.find("world.objects[0].size"), std::string::npos) << err;
}

TEST(YamlMap, UnknownKeyIsAnError) {
  const YamlMap m = YamlMap::LoadString("speed: 1\nsped: 2\n", "k.yaml");
  const std::string err = testing::InputErrorOf([&] { m.CheckKnownKeys({"speed"}); });
  EXPECT_NE(err.find("k.yaml:2:"), std::string::npos) << err;
  EXPECT_NE(err.find("sped: unknown field"), std::string::npos) << err;
}

TEST(YamlMap, MissingRequiredFieldIsNamed) {
  const YamlMap m = YamlMap::LoadString("a: 1\n", "m.yaml");
  const std::string err = testing::InputErrorOf([&] { m.GetDouble("b"); });
  EXPECT_NE(err.find("missing required field 'b'"), std::string::npos) << err;
}

TEST(YamlMap, AKeyThatIsNotAPlainScalarIsAnErrorNotACrash) {
  // Found by fuzz/fuzz_config: "? [a]: 1" made yaml-cpp throw its own exception type.
  const YamlMap m = YamlMap::LoadString("render:\n  ? [a, b]\n  : 1\n", "c.yaml");
  const std::string err =
      testing::InputErrorOf([&] { m.GetMap("render").CheckKnownKeys({"near_m"}); });
  EXPECT_NE(err.find("c.yaml:2:"), std::string::npos) << err;
  EXPECT_NE(err.find("render: expected a plain key"), std::string::npos) << err;
}

TEST(YamlMap, AsDoublesChecksEachElement) {
  const YamlMap m = YamlMap::LoadString("p: [[1, 2], [3, x]]\n", "p.yaml");
  const std::vector<YamlMap> list = m.GetList("p");
  EXPECT_EQ(list[0].AsDoubles(2), (std::vector<double>{1.0, 2.0}));
  EXPECT_NE(testing::InputErrorOf([&] { list[1].AsDoubles(2); }).find("p.yaml:1:"),
            std::string::npos);
  EXPECT_NE(testing::InputErrorOf([&] { list[0].AsDoubles(3); }).find("list of 3 numbers"),
            std::string::npos);
}

TEST(YamlMap, WithYamlErrorsTurnsYamlCppExceptionsIntoInputErrors) {
  const std::string err = testing::InputErrorOf(
      [] { WithYamlErrors("x.yaml", [] { return YAML::Load("a: [1]")["a"].as<int>(); }); });
  EXPECT_NE(err.find("x.yaml:1:"), std::string::npos) << err;
}

TEST(YamlMap, MissingFileIsNamed) {
  const std::string err = testing::InputErrorOf([] { YamlMap::LoadFile("/nonexistent/x.yaml"); });
  EXPECT_NE(err.find("/nonexistent/x.yaml: cannot open file"), std::string::npos) << err;
}

}  // namespace
}  // namespace mapless::io
