#include "robomill/io/program_writer.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "robomill/core/error.hpp"

namespace robomill::io {
namespace {

std::string statement(const SpindleEdit& edit, ToolpathSettings::Format format,
                      std::string_view newline) {
  const double rpm = std::abs(edit.spindle_rad_s) * 60.0 / (2.0 * std::numbers::pi);
  if (format == ToolpathSettings::Format::apt) {
    return fmt::format("$$ {}{}SPINDL/RPM,{:.0f},{}{}", edit.comment, newline, rpm,
                       edit.spindle_rad_s < 0.0 ? "CCLW" : "CLW", newline);
  }
  std::string comment = edit.comment;
  std::replace(comment.begin(), comment.end(), '(', '[');
  std::replace(comment.begin(), comment.end(), ')', ']');
  return fmt::format("S{:.0f} ({}){}", rpm, comment, newline);
}

}  // namespace

std::string write_spindle_edits(std::string_view text, ToolpathSettings::Format format,
                                std::vector<SpindleEdit> edits) {
  if (format == ToolpathSettings::Format::krl)
    throw InputError("toolpath.format", 0,
                     "KRL programs carry no spindle speed (the cell's PLC sets it): robomill "
                     "reports the chosen speeds but cannot write them into the .src");
  std::stable_sort(edits.begin(), edits.end(), [](const SpindleEdit& a, const SpindleEdit& b) {
    return a.before_line < b.before_line;
  });
  // Keep the file's own line ends (CR LF from Windows posts).
  const std::string_view newline =
      text.find("\r\n") != std::string_view::npos ? std::string_view("\r\n") : "\n";
  std::string out;
  out.reserve(text.size() + 96 * edits.size());
  std::size_t next = 0;
  int line = 1;
  std::size_t position = 0;
  while (position <= text.size()) {
    while (next < edits.size() && edits[next].before_line <= line)
      out += statement(edits[next++], format, newline);
    if (position == text.size())
      break;
    const std::size_t end = text.find('\n', position);
    const std::size_t stop = end == std::string_view::npos ? text.size() : end + 1;
    out.append(text.substr(position, stop - position));
    position = stop;
    ++line;
    if (end == std::string_view::npos && next < edits.size())
      out += newline;  // a last line without its line end
  }
  while (next < edits.size())
    out += statement(edits[next++], format, newline);
  return out;
}

}  // namespace robomill::io
