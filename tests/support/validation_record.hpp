#pragma once
// Validation records: the paper-validation tests append one JSON line per
// compared value (paper, item, quantity, paper value, ours, error, tolerance,
// pass, assumptions) to the file named by ROBOMILL_VALIDATION_LOG, which CTest
// sets in the release build (tests/CMakeLists.txt). After the tests,
// robomill_docgen assembles docs/validation-report.md from the records and a
// final test fails when the committed report differs ("stale; run make
// docs"). Without the variable (a test program run by hand, the sanitizer
// build) nothing is written.
//
// Recording never changes a test's verdict: the test keeps its own
// EXPECT/ASSERT next to the record, with the same tolerance.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include <fmt/format.h>

namespace robomill::test {

/// A number as the report prints it: 4 significant digits, so that compiler
/// and library noise in the last bits cannot change the report.
inline std::string sig4(double value) {
  if (!std::isfinite(value))
    return std::isnan(value) ? "nan" : (value > 0 ? "inf" : "-inf");
  if (value == 0.0)
    return "0";
  std::string text = fmt::format("{:.4g}", value);
  return text == "-0" ? "0" : text;
}

/// `prefix` + sig4(value) + `suffix`, built by appending (GCC 12 warns,
/// wrongly, about `"+" + std::string` under -O2: -Wrestrict).
inline std::string labelled(std::string prefix, double value, std::string_view suffix = {}) {
  prefix.append(sig4(value)).append(suffix);
  return prefix;
}

/// `value` rounded to a multiple of `step`: errors are printed to a thousandth
/// of the tolerance, so that round-off (an error of 1e-15 where the tolerance
/// is 1e-9) cannot change the report.
inline double quantize(double value, double step) {
  return step > 0.0 && std::isfinite(value) ? step * std::round(value / step) : value;
}

/// "+1.23" / "-0.5": a signed difference.
inline std::string signed_sig4(double value, std::string_view suffix = {}) {
  return labelled(value >= 0 ? "+" : "", value, suffix);
}

struct ValidationRecord {
  std::string paper;        ///< "000" … "004"
  std::string item;         ///< the table or figure and row: "Tab. 1, mode X1"
  std::string quantity;     ///< what is compared: "natural frequency"
  std::string unit;         ///< of paper_value and ours ("" when none)
  std::string paper_value;  ///< as the paper gives it: "19.9", "3000-3500", "robot"
  std::string ours;         ///< our value, formatted (sig4)
  std::string error;        ///< "+1.2 %", "-0.03", "—"
  std::string tolerance;    ///< the test's acceptance: "±5 %", "< 0.75", "4000 … 5500"
  bool passed = false;
  std::string assumptions;  ///< what the comparison assumes (values the paper leaves out)
};

/// Appends `record` to $ROBOMILL_VALIDATION_LOG with the running test's name
/// and file: one write() of one line on an O_APPEND descriptor, so records of
/// tests running in parallel processes never interleave.
inline void record_validation(const ValidationRecord& record) {
  const char* log = std::getenv("ROBOMILL_VALIDATION_LOG");
  if (log == nullptr || *log == '\0')
    return;
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string file = info ? info->file() : "";
  if (const auto pos = file.rfind("/tests/"); pos != std::string::npos)
    file = file.substr(pos + 1);
  const nlohmann::json line = {
      {"test", info ? std::string(info->test_suite_name()) + "." + info->name() : ""},
      {"file", file},
      {"paper", record.paper},
      {"item", record.item},
      {"quantity", record.quantity},
      {"unit", record.unit},
      {"paper_value", record.paper_value},
      {"ours", record.ours},
      {"error", record.error},
      {"tolerance", record.tolerance},
      {"passed", record.passed},
      {"assumptions", record.assumptions},
  };
  const std::string text = line.dump() + "\n";
  const int fd = ::open(log, O_WRONLY | O_APPEND | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) {
    ADD_FAILURE() << "cannot open the validation log " << log;
    return;
  }
  const ssize_t written = ::write(fd, text.data(), text.size());
  ::close(fd);
  if (written != static_cast<ssize_t>(text.size()))
    ADD_FAILURE() << "cannot append to the validation log " << log;
}

/// |ours - paper| <= tolerance (in the unit): EXPECT_NEAR's check.
inline void record_near(std::string paper, std::string item, std::string quantity, std::string unit,
                        double paper_value, double ours, double tolerance,
                        std::string assumptions) {
  const double error = ours - paper_value;
  record_validation({std::move(paper), std::move(item), std::move(quantity), std::move(unit),
                     sig4(paper_value), sig4(ours), signed_sig4(quantize(error, 1e-3 * tolerance)),
                     labelled("±", tolerance), std::abs(error) <= tolerance,
                     std::move(assumptions)});
}

/// |ours - paper| <= relative × |paper|: the error printed in percent.
inline void record_relative(std::string paper, std::string item, std::string quantity,
                            std::string unit, double paper_value, double ours, double relative,
                            std::string assumptions) {
  const double error = (ours - paper_value) / std::abs(paper_value);
  record_validation(
      {std::move(paper), std::move(item), std::move(quantity), std::move(unit), sig4(paper_value),
       sig4(ours), signed_sig4(quantize(100.0 * error, 0.1 * relative), " %"),
       labelled("±", 100.0 * relative, " %"),
       std::abs(ours - paper_value) <= relative * std::abs(paper_value), std::move(assumptions)});
}

/// A trend or bound check: the paper's statement, our value, the test's bound
/// as text, and whether our value meets it (the test asserts the same).
inline void record_check(std::string paper, std::string item, std::string quantity,
                         std::string unit, std::string paper_value, std::string ours,
                         std::string tolerance, bool passed, std::string assumptions) {
  record_validation({std::move(paper), std::move(item), std::move(quantity), std::move(unit),
                     std::move(paper_value), std::move(ours), "—", std::move(tolerance), passed,
                     std::move(assumptions)});
}

}  // namespace robomill::test
