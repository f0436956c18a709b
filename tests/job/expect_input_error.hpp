#pragma once
// Shared checks for the job-parser tests: a malformed job must raise an
// InputError that names the field, its line and the problem.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "robomill/core/error.hpp"
#include "robomill/job/job.hpp"

namespace robomill::test {

/// Parses `yaml` (with `--set` overrides) and returns the InputError it must raise.
inline InputError parse_error(const std::string& yaml, const std::vector<job::Override>& set = {}) {
  try {
    job::parse_job(yaml, "job.yaml", set);
  } catch (const InputError& error) {
    return error;
  }
  ADD_FAILURE() << "accepted:\n" << yaml;
  return InputError("", 0, "");
}

/// The error names `field`, `line` and a message containing `fragment`.
inline void expect_error(const std::string& yaml, const std::string& field, int line,
                         const std::string& fragment) {
  SCOPED_TRACE(yaml);
  const InputError error = parse_error(yaml);
  EXPECT_EQ(error.field(), field) << error.what();
  EXPECT_EQ(error.line(), line) << error.what();
  EXPECT_NE(std::string(error.what()).find(fragment), std::string::npos)
      << "message: " << error.what() << "\nexpected to contain: " << fragment;
}

}  // namespace robomill::test
