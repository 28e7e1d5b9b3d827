#include "mapless/io/journal.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <filesystem>
#include <sstream>
#include <string>

#include "mapless/core/check.h"
#include "mapless/core/testing.h"
#include "mapless/io/atomic_file.h"
#include "mapless/io/tum.h"

namespace mapless::io {
namespace {

std::string TempPath(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / "mapless_journal_test";
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

TEST(JournalFile, AppendsWholeLines) {
  const std::string path = TempPath("lines.txt");
  {
    JournalFile j(path);
    j.Append("a");
    j.Append("b\n");
    j.Sync();
  }
  EXPECT_EQ(ReadFile(path, 1 << 20), "a\nb\n");
  JournalFile again(path);  // truncates
  EXPECT_EQ(ReadFile(path, 1 << 20), "");
}

TEST(JournalFile, ReplaceAtCloseKeepsTheOldFileWholeUntilTheNewOneIsDone) {
  const std::string path = ::testing::TempDir() + "mapless_journal_replace.jsonl";
  WriteFileAtomic(path, "old\n");
  {
    JournalFile j(path, JournalFile::Mode::kReplaceAtClose);
    j.Append("new 1");
    EXPECT_EQ(ReadFile(path, 1 << 20), "old\n");
    EXPECT_EQ(ReadFile(path + ".partial", 1 << 20), "new 1\n");
    j.Append("new 2");
  }  // destruction closes and replaces, as on unwinding after an error
  EXPECT_EQ(ReadFile(path, 1 << 20), "new 1\nnew 2\n");
  EXPECT_FALSE(std::filesystem::exists(path + ".partial"));
}

TEST(JournalFile, UnwritablePathIsNamed) {
  EXPECT_NE(testing::InputErrorOf([] {
              JournalFile("/nonexistent-dir/x.txt");
            }).find("/nonexistent-dir/x.txt: cannot write"),
            std::string::npos);
}

// A recorder killed with SIGKILL in the middle of a run: every line it finished is there and
// whole, so the trajectory parses.
TEST(JournalFile, AProcessKilledMidRunLeavesOnlyWholeRecords) {
  const std::string path = TempPath("killed.tum");
  std::filesystem::remove(path);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    JournalFile j(path);
    j.Append(kTumHeader);
    for (long i = 0;; ++i) {
      j.Append(FormatTumLine({i * 1'000'000, Pose2{0.001 * static_cast<double>(i), 2.0, 0.5}}));
    }
  }
  // Wait until it has written something, then kill it mid-stream.
  for (int i = 0;
       i < 200 && (!std::filesystem::exists(path) || std::filesystem::file_size(path) < 200'000);
       ++i) {
    ::usleep(10'000);
  }
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status));
  const std::string text = ReadFile(path, 1 << 20);
  ASSERT_FALSE(text.empty());
  const std::vector<StampedPose> poses = ParseTum(text, path);
  ASSERT_GT(poses.size(), 100U);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    EXPECT_NEAR(poses[i].pose.x_m, 0.001 * static_cast<double>(i), 1e-6) << "pose " << i;
  }
}

}  // namespace
}  // namespace mapless::io
