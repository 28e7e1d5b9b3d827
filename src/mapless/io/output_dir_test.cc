#include "mapless/io/output_dir.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "mapless/core/check.h"
#include "mapless/core/testing.h"
#include "mapless/io/atomic_file.h"

namespace mapless::io {
namespace {

namespace fs = std::filesystem;

std::string Fresh(const std::string& name) {
  const std::string dir = ::testing::TempDir() + "mapless_outdir_" + name;
  fs::remove_all(dir);
  for (const auto& e : fs::directory_iterator(::testing::TempDir())) {
    if (e.path().filename().string().rfind("mapless_outdir_" + name + ".", 0) == 0)
      fs::remove_all(e.path());
  }
  return dir;
}

TEST(OutputDirectory, ANewDirectoryIsWrittenInPlace) {
  const std::string dir = Fresh("new");
  OutputDirectory out(dir, false, "route", "old.txt");
  EXPECT_EQ(out.path(), dir);
  EXPECT_FALSE(out.staged());
  WriteFileAtomic(dir + "/a.txt", "a");
  out.Commit();
  EXPECT_EQ(ReadFile(dir + "/a.txt", 16), "a");
}

TEST(OutputDirectory, WhatIsThereIsReplacedOnlyWhenAskedAndOnlyOnCommit) {
  const std::string dir = Fresh("replace");
  MakeDirectories(dir);
  WriteFileAtomic(dir + "/old.txt", "old");
  EXPECT_NE(testing::InputErrorOf([&] {
              OutputDirectory(dir, false, "route", "old.txt");
            }).find("not empty"),
            std::string::npos);
  EXPECT_NE(testing::InputErrorOf([&] {
              OutputDirectory(dir, true, "route", "manifest.json");
            }).find("holds something else than a route (no manifest.json)"),
            std::string::npos);
  {
    OutputDirectory out(dir, true, "route", "old.txt");
    EXPECT_TRUE(out.staged());
    WriteFileAtomic(out.path() + "/new.txt", "new");
    EXPECT_TRUE(fs::exists(dir + "/old.txt"));  // untouched until the commit
  }  // not committed: the old content stays, the staging directory goes
  EXPECT_EQ(ReadFile(dir + "/old.txt", 16), "old");
  EXPECT_FALSE(fs::exists(dir + "/new.txt"));
  {
    OutputDirectory out(dir, true, "route", "old.txt");
    WriteFileAtomic(out.path() + "/new.txt", "new");
    out.Commit();
  }
  EXPECT_FALSE(fs::exists(dir + "/old.txt"));
  EXPECT_EQ(ReadFile(dir + "/new.txt", 16), "new");
  int siblings = 0;
  for (const auto& e : fs::directory_iterator(fs::path(dir).parent_path())) {
    if (e.path().filename().string().rfind("mapless_outdir_replace.", 0) == 0) ++siblings;
  }
  EXPECT_EQ(siblings, 0);  // no staging or old directory left behind
}

TEST(OutputDirectory, ASecondWriterIsRefusedWhileTheFirstHoldsTheDirectory) {
  const std::string dir = Fresh("locked");
  OutputDirectory first(dir, false, "route", "a.txt");
  WriteFileAtomic(dir + "/a.txt", "a");
  EXPECT_NE(testing::InputErrorOf([&] {
              OutputDirectory(dir, true, "route", "a.txt");
            }).find("another mapless process is writing"),
            std::string::npos);
}

TEST(OutputDirectory, AFileIsNotADirectory) {
  const std::string file = Fresh("file");
  WriteFileAtomic(file, "x");
  EXPECT_NE(testing::InputErrorOf([&] {
              OutputDirectory(file, true, "route", "a.txt");
            }).find("is a file"),
            std::string::npos);
}

}  // namespace
}  // namespace mapless::io
