// The main() of every GoogleTest binary: OpenCV on one thread, as in the `mapless` command
// (apps/main.cc) and the benchmarks, so that a test runs what users run, and `ctest -j2` does not
// put two tests' thread pools on two cores.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

int main(int argc, char** argv) {
  cv::setNumThreads(1);
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
