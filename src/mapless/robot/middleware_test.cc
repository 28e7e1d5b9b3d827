#include "mapless/robot/middleware.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "mapless/core/check.h"

namespace mapless::robot {
namespace {

MiddlewareKind Kind(const std::string& name) {
  MiddlewareKind k;
  k.name = name;
  k.open_link = [](const RobotFile&, cv::Size, const std::string&,
                   const Logger&) -> std::unique_ptr<RobotLink> { return nullptr; };
  k.serve = [](sim::Simulation&, int, const RobotFile&, const ServeOptions&) {
    ServeSummary s;
    s.end = "served";
    return s;
  };
  k.bench = [](const LinkBenchOptions&) { return LinkBenchResult{}; };
  return k;
}

TEST(MiddlewareRegistry, FindsWhatWasRegisteredInOrder) {
  MiddlewareRegistry r;
  r.Add(Kind("ros2"));
  r.Add(Kind("ros1"));
  ASSERT_NE(r.Find("ros1"), nullptr);
  EXPECT_EQ(r.Find("ros1")->name, "ros1");
  EXPECT_EQ(r.Find("zenoh"), nullptr);
  EXPECT_EQ(r.names(), (std::vector<std::string>{"ros2", "ros1"}));
  RobotFile file;
  file.middleware = "ros2";
  EXPECT_EQ(&r.For(file), r.Find("ros2"));
}

TEST(MiddlewareRegistry, AFileAskingForAMiddlewareNotBuiltGetsOneLineNamingFileAndBuild) {
  MiddlewareRegistry r;
  RobotFile file;
  file.source = "robots/mine.yaml";
  file.middleware = "ros1";
  try {
    r.For(file);
    FAIL() << "no ros1 in an empty registry";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("robots/mine.yaml"), std::string::npos) << what;
    EXPECT_NE(what.find("ros1"), std::string::npos) << what;
    EXPECT_NE(what.find("none"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  r.Add(Kind("ros2"));
  try {
    r.For(file);
    FAIL() << "no ros1";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("in this build: ros2"), std::string::npos) << e.what();
  }
}

TEST(MiddlewareRegistry, RefusesTwoOfOneNameAndKindsWithoutTheirFunctions) {
  MiddlewareRegistry r;
  r.Add(Kind("ros1"));
  EXPECT_THROW(r.Add(Kind("ros1")), std::logic_error);
  MiddlewareKind no_bench = Kind("ros2");
  no_bench.bench = nullptr;
  EXPECT_THROW(r.Add(no_bench), std::logic_error);
  EXPECT_EQ(r.names().size(), 1u);
}

}  // namespace
}  // namespace mapless::robot
