#pragma once
// Small text helpers shared by the file formats (CSV, UFF) and the job parser.

#include <string_view>

namespace robomill::text {

/// `text` without leading and trailing spaces, tabs, carriage returns and newlines.
inline std::string_view trim(std::string_view text) noexcept {
  constexpr std::string_view kBlank = " \t\r\n";
  const auto first = text.find_first_not_of(kBlank);
  if (first == std::string_view::npos)
    return {};
  const auto last = text.find_last_not_of(kBlank);
  return text.substr(first, last - first + 1);
}

/// `c` is a decimal digit, 0 to 9.
inline bool is_digit(char c) {
  return c >= '0' && c <= '9';
}

}  // namespace robomill::text
