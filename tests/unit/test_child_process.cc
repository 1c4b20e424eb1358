// ChildProcess::Wait: the blocking end of a child started with Start, as
// `pvtwin-bench ident` times `pvtwin calibrate` with it.
#include <gtest/gtest.h>

#include <csignal>
#include <string>

#include "io/platform/child_process.h"

namespace pvtwin {
namespace {

TEST(ChildProcess, WaitReturnsTheExitCodeOrTheSignal) {
  ChildProcess child;
  std::string error;
  ASSERT_TRUE(child.Start({"/bin/sh", "-c", "exit 3"}, "/dev/null", &error)) << error;
  EXPECT_EQ(child.Wait(), 3);
  EXPECT_FALSE(child.running());
  EXPECT_EQ(child.Wait(), -1);  // nothing left to wait for

  ASSERT_TRUE(child.Start({"/bin/sh", "-c", "kill -TERM $$"}, "/dev/null", &error)) << error;
  EXPECT_EQ(child.Wait(), -SIGTERM);
}

}  // namespace
}  // namespace pvtwin
