#pragma once
// Text helpers shared by the APT / CL and KUKA KRL readers (src/io/apt_reader.cpp,
// src/io/krl_reader.cpp): case folding, trimming, splitting at top-level commas,
// strict numbers by std::from_chars. Both languages are case-insensitive ASCII;
// the readers fold a statement to upper case once and compare words afterwards.

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

namespace robomill::io::program_text {

inline bool is_blank(char c) noexcept {
  return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f' || c == '\v';
}

/// `text` without leading and trailing blanks.
inline std::string_view trim(std::string_view text) noexcept {
  std::size_t first = 0;
  while (first < text.size() && is_blank(text[first]))
    ++first;
  std::size_t last = text.size();
  while (last > first && is_blank(text[last - 1]))
    --last;
  return text.substr(first, last - first);
}

inline char upper(char c) noexcept {
  return (c >= 'a' && c <= 'z') ? static_cast<char>(c - 'a' + 'A') : c;
}

/// ASCII upper case (the languages' words are ASCII; other bytes pass through).
inline std::string to_upper(std::string_view text) {
  std::string folded(text);
  for (char& c : folded)
    c = upper(c);
  return folded;
}

/// A strict decimal number: optional sign, digits with an optional point and
/// exponent, nothing else; finite. Programs write "+1.5", "-.5", "5.", "1.0E+02".
inline std::optional<double> parse_number(std::string_view text) noexcept {
  text = trim(text);
  if (!text.empty() && text.front() == '+')
    text.remove_prefix(1);
  if (text.empty())
    return std::nullopt;
  // from_chars accepts "inf" and "nan"; a program never means them.
  const char first = text[0] == '-' && text.size() > 1 ? text[1] : text[0];
  if (!(std::isdigit(static_cast<unsigned char>(first)) || first == '.'))
    return std::nullopt;
  double value = 0.0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || !std::isfinite(value))
    return std::nullopt;
  return value;
}

/// A strict integer (optional sign, digits) that fits in `long long`.
inline std::optional<long long> parse_integer(std::string_view text) noexcept {
  text = trim(text);
  if (!text.empty() && text.front() == '+')
    text.remove_prefix(1);
  long long value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || error != std::errc() || end != text.data() + text.size())
    return std::nullopt;
  return value;
}

/// Pieces of `text` between commas that are outside braces, brackets and
/// parentheses, each trimmed ("{X 1,Y 2}, {X 3}" → two pieces).
inline std::vector<std::string_view> split_top_level(std::string_view text, char separator = ',') {
  std::vector<std::string_view> pieces;
  int depth = 0;
  std::size_t begin = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '{' || c == '[' || c == '(')
      ++depth;
    else if ((c == '}' || c == ']' || c == ')') && depth > 0)
      --depth;
    else if (c == separator && depth == 0) {
      pieces.push_back(trim(text.substr(begin, i - begin)));
      begin = i + 1;
    }
  }
  pieces.push_back(trim(text.substr(begin)));
  return pieces;
}

/// Whether `text` starts with `word` followed by a non-identifier character
/// (or the end): "LIN P1" starts with the word LIN, "LINE" does not.
inline bool starts_with_word(std::string_view text, std::string_view word) noexcept {
  if (text.substr(0, word.size()) != word)
    return false;
  if (text.size() == word.size())
    return true;
  const char next = text[word.size()];
  return !(std::isalnum(static_cast<unsigned char>(next)) || next == '_' || next == '$');
}

/// A short, printable excerpt of user text for messages (fuzzed input may
/// hold control bytes or megabytes on one line).
inline std::string excerpt(std::string_view text, std::size_t limit = 40) {
  std::string shown;
  for (char c : text.substr(0, limit))
    shown +=
        (static_cast<unsigned char>(c) >= 0x20 && static_cast<unsigned char>(c) < 0x7f) ? c : '?';
  if (text.size() > limit)
    shown += "...";
  return shown;
}

}  // namespace robomill::io::program_text
