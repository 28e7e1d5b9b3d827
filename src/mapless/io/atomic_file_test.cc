#include "mapless/io/atomic_file.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>

#include "mapless/core/check.h"
#include "mapless/core/testing.h"
#include "mapless/io/tum.h"

namespace mapless::io {
namespace {

TEST(AtomicFile, WritesThenReadsBackAndLeavesNoTemporary) {
  const auto dir = std::filesystem::temp_directory_path() / "mapless_atomic_test";
  std::filesystem::remove_all(dir);
  MakeDirectories(dir.string());
  const std::string path = (dir / "a.txt").string();
  WriteFileAtomic(path, "first");
  WriteFileAtomic(path, "second");
  EXPECT_EQ(ReadFile(path, 1 << 20), "second");
  int files = 0;
  for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++files;
  EXPECT_EQ(files, 1);
  std::filesystem::remove_all(dir);
}

TEST(ReadFile, RefusesDevicesPipesDirectoriesAndFilesOverTheLimit) {
  const auto dir = std::filesystem::temp_directory_path() / "mapless_readfile_test";
  std::filesystem::remove_all(dir);
  MakeDirectories(dir.string());
  EXPECT_NE(testing::InputErrorOf([] {
              ReadFile("/dev/zero", 1 << 20);
            }).find("/dev/zero: not a regular file"),
            std::string::npos);
  const std::string fifo = (dir / "fifo").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0644), 0);
  EXPECT_NE(testing::InputErrorOf([&] { ReadFile(fifo, 1 << 20); }).find("not a regular file"),
            std::string::npos);
  EXPECT_NE(
      testing::InputErrorOf([&] { ReadFile(dir.string(), 1 << 20); }).find("not a regular file"),
      std::string::npos);
  const std::string path = (dir / "ten.txt").string();
  WriteFileAtomic(path, "0123456789");
  EXPECT_EQ(ReadFile(path, 10), "0123456789");
  EXPECT_NE(testing::InputErrorOf([&] {
              ReadFile(path, 9);
            }).find("ten.txt: 10 bytes; the limit for this kind of file is 9 bytes"),
            std::string::npos);
  EXPECT_NE(testing::InputErrorOf([&] {
              ReadFile((dir / "none").string(), 9);
            }).find("none: cannot open file"),
            std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(AtomicFile, UnwritablePathThrowsNamingIt) {
  try {
    WriteFileAtomic("/nonexistent_dir/x.txt", "x");
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent_dir/x.txt"), std::string::npos);
  }
}

TEST(Tum, RoundTripsPlanarPoses) {
  std::vector<StampedPose> poses = {{0, Pose2{1, 2, 0.5}}, {100'000'000, Pose2{-1, 0.25, -2.5}}};
  const auto back = ParseTum(FormatTum(poses), "t");
  ASSERT_EQ(back.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(back[i].t_ns, poses[i].t_ns);
    EXPECT_NEAR(back[i].pose.x_m, poses[i].pose.x_m, 1e-6);
    EXPECT_NEAR(back[i].pose.y_m, poses[i].pose.y_m, 1e-6);
    EXPECT_NEAR(back[i].pose.theta_rad, poses[i].pose.theta_rad, 1e-6);
  }
}

TEST(Tum, ACutLastRecordIsDroppedAMalformedLineElsewhereIsAnError) {
  const std::string whole = FormatTum({{0, Pose2{1, 2, 0.5}}, {100'000'000, Pose2{3, 4, 0.0}}});
  EXPECT_EQ(ParseTum(whole + "0.2 5.0 6", "t").size(), 2U);  // killed mid-record
  EXPECT_NE(testing::InputErrorOf([&] {
              ParseTum(whole + "0.2 5.0 6\n", "t.tum");
            }).find("t.tum:4: expected 8 numbers"),
            std::string::npos);
  EXPECT_NE(testing::InputErrorOf([&] { ParseTum("x\n" + whole, "t.tum"); }).find("t.tum:1:"),
            std::string::npos);
}

}  // namespace
}  // namespace mapless::io
