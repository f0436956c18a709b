#pragma once
// The uncertainty module refuses parameters that describe no distribution,
// and correlations or samples it cannot draw, with std::invalid_argument:
// its message, for the tests to check what it names.

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace robomill::uncertainty::test_support {

/// The message of the std::invalid_argument `call` throws; a test failure
/// (and "") when it throws nothing.
template <typename Call>
std::string refusal(Call call) {
  try {
    call();
  } catch (const std::invalid_argument& error) {
    return error.what();
  }
  ADD_FAILURE() << "accepted";
  return {};
}

inline bool mentions(const std::string& message, const std::string& part) {
  return message.find(part) != std::string::npos;
}

}  // namespace robomill::uncertainty::test_support
