#include "mapless/core/worker.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <thread>

namespace mapless {
namespace {

TEST(Worker, RunsEachJobOnItsOwnThreadAndWaitSeesItsResult) {
  Worker worker;
  worker.Wait();  // nothing started: returns
  const std::thread::id here = std::this_thread::get_id();
  for (int i = 0; i < 100; ++i) {
    int result = 0;
    std::thread::id there;
    worker.Start([&] {
      result = i * i;
      there = std::this_thread::get_id();
    });
    worker.Wait();
    EXPECT_EQ(result, i * i);
    EXPECT_NE(there, here);
  }
}

TEST(Worker, RethrowsTheJobsErrorAndGoesOn) {
  Worker worker;
  worker.Start([] { throw std::runtime_error("the job failed"); });
  EXPECT_THROW(worker.Wait(), std::runtime_error);
  bool ran = false;
  worker.Start([&] { ran = true; });
  worker.Wait();
  EXPECT_TRUE(ran);
}

TEST(Worker, OneJobAtATimeAndAPendingJobEndsBeforeTheWorker) {
  bool ran = false;
  {
    Worker worker;
    worker.Start([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      ran = true;
    });
    EXPECT_THROW(worker.Start([] {}), std::exception);
  }
  EXPECT_TRUE(ran);
}

}  // namespace
}  // namespace mapless
