// Text helpers shared by the program writers (internal to src/io):
// program_writer.cpp (feed and spindle edits) and program_point_edits.cpp
// (moved and added points).
#pragma once

#include <algorithm>
#include <cctype>
#include <string>
#include <string_view>

namespace robomill::io::program_edit_text {

// A comment's text as a G-code ( ) comment can hold it: ( ) become [ ].
inline std::string gcode_comment(std::string comment) {
  std::replace(comment.begin(), comment.end(), '(', '[');
  std::replace(comment.begin(), comment.end(), ')', ']');
  return comment;
}

// The text without leading and trailing white space.
inline std::string_view trimmed(std::string_view text) {
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front())))
    text.remove_prefix(1);
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back())))
    text.remove_suffix(1);
  return text;
}

// Whether the text (trimmed) starts with the word (upper case), followed by
// its end, `/` or a blank; the text's case does not matter.
inline bool starts_with_word(std::string_view text, std::string_view word) {
  text = trimmed(text);
  if (text.size() < word.size())
    return false;
  for (std::size_t i = 0; i < word.size(); ++i)
    if (std::toupper(static_cast<unsigned char>(text[i])) != word[i])
      return false;
  return text.size() == word.size() || text[word.size()] == '/' || text[word.size()] == ' ';
}

}  // namespace robomill::io::program_edit_text
