#pragma once
// Shared check for the robot tests: a call must throw std::invalid_argument
// whose message contains a fragment (the message is printed, so a reader of
// the test log sees what a user would).

#include <gtest/gtest.h>

#include <cstdio>
#include <stdexcept>
#include <string>

namespace robomill::test {

template <typename F>
void expect_invalid(F&& call, const std::string& fragment) {
  try {
    call();
    FAIL() << "expected std::invalid_argument mentioning \"" << fragment << "\"";
  } catch (const std::invalid_argument& e) {
    std::printf("  refused: %s\n", e.what());
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

}  // namespace robomill::test
