#include "robomill/io/program_writer.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "program_edit_text.hpp"
#include "robomill/core/error.hpp"
#include "robomill/io/program_readers.hpp"

namespace robomill::io {
namespace {

using Format = ProgramFormat;
using program_edit_text::gcode_comment;
using program_edit_text::starts_with_word;
using program_edit_text::trimmed;

std::string spindle_statement(const SpindleEdit& edit, Format format, std::string_view newline) {
  const double rpm = std::abs(edit.spindle_rad_s) * 60.0 / (2.0 * std::numbers::pi);
  if (format == Format::apt) {
    return fmt::format("$$ {}{}SPINDL/RPM,{:.0f},{}{}", edit.comment, newline, rpm,
                       edit.spindle_rad_s < 0.0 ? "CCLW" : "CLW", newline);
  }
  return fmt::format("S{:.0f} ({}){}", rpm, gcode_comment(edit.comment), newline);
}

// A feed value as the dialects write numbers: six significant digits, never
// an exponent, no trailing zeros.
std::string feed_number(double value) {
  std::string text =
      value >= 1e-4 && value < 1e6 ? fmt::format("{:.6g}", value) : fmt::format("{:.6f}", value);
  if (text.find('e') == std::string::npos && text.find('.') != std::string::npos) {
    while (text.back() == '0')
      text.pop_back();
    if (text.back() == '.')
      text.pop_back();
  }
  return text;
}

// Where a line's G-code F word's number lies, outside comments: ( … ), ; …
// and O-word names < … >. `expression` when F is followed by [ or #.
struct FeedWord {
  std::size_t begin = 0, end = 0;
  double value = 0.0;
  bool expression = false;
};

std::optional<FeedWord> gcode_feed_word(std::string_view line) {
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (c == ';')
      return std::nullopt;
    if (c == '(' || c == '<') {
      const std::size_t close = line.find(c == '(' ? ')' : '>', i + 1);
      if (close == std::string_view::npos)
        return std::nullopt;
      i = close;
      continue;
    }
    if (c != 'F' && c != 'f')
      continue;
    std::size_t j = i + 1;
    while (j < line.size() && (line[j] == ' ' || line[j] == '\t'))
      ++j;
    FeedWord word;
    if (j < line.size() && (line[j] == '[' || line[j] == '#')) {
      word.expression = true;
      return word;
    }
    // RS274NGC lets spaces stand inside a number ("F 6 0 0"): they are
    // skipped, and the rescaled number replaces the whole span.
    std::size_t k = j;
    if (k < line.size() && (line[k] == '+' || line[k] == '-'))
      ++k;
    std::size_t last = k;  // one past the number's last digit or point
    while (k < line.size() && (std::isdigit(static_cast<unsigned char>(line[k])) ||
                               line[k] == '.' || line[k] == ' ' || line[k] == '\t')) {
      if (line[k] != ' ' && line[k] != '\t')
        last = k + 1;
      ++k;
    }
    k = last;
    std::string digits;
    for (std::size_t i = j; i < k; ++i)
      if (line[i] != ' ' && line[i] != '\t' && line[i] != '+')
        digits += line[i];
    const auto [end, error] =
        std::from_chars(digits.data(), digits.data() + digits.size(), word.value);
    if (error != std::errc() || end != digits.data() + digits.size())
      return std::nullopt;
    word.begin = j;
    word.end = k;
    return word;
  }
  return std::nullopt;
}

// An APT FEDRAT record with its number multiplied by `scale` (FEDRAT/MMPM,250,
// FEDRAT/742.7,MMPM, FEDRAT/250 alike).
std::string scaled_fedrat(std::string_view record, double scale, int line) {
  const std::size_t slash = record.find('/');
  std::size_t start = slash == std::string_view::npos ? record.size() : slash + 1;
  while (start < record.size()) {
    std::size_t stop = record.find(',', start);
    if (stop == std::string_view::npos)
      stop = record.size();
    const std::string_view token = trimmed(record.substr(start, stop - start));
    double value = 0.0;
    const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (error == std::errc() && end == token.data() + token.size() && !token.empty()) {
      const std::size_t at = record.find(token, start);
      return std::string(record.substr(0, at)) + feed_number(value * scale) +
             std::string(record.substr(at + token.size()));
    }
    start = stop + 1;
  }
  throw InputError("toolpath.file", 0,
                   fmt::format("program line {}: the FEDRAT in force ('{}') has no number to "
                               "rescale",
                               line, record));
}

}  // namespace

std::vector<int> statement_starts(std::string_view text, ProgramFormat format) {
  std::vector<int> starts = {0};
  bool continues = false;  // the line before ends in APT's '$'
  int start = 1;
  int line = 1;
  std::size_t position = 0;
  while (position < text.size()) {
    const std::size_t end = text.find('\n', position);
    const std::size_t stop = end == std::string_view::npos ? text.size() : end;
    std::string_view body = text.substr(position, stop - position);
    if (format == Format::apt) {
      const std::size_t comment = body.find("$$");
      const std::string_view code =
          trimmed(comment == std::string_view::npos ? body : body.substr(0, comment));
      // A further point of a GOTO on a line of its own (Creo's CL files)
      // starts with a number; a '$' continues the record on the next line.
      const bool point = !code.empty() && (std::isdigit(static_cast<unsigned char>(code[0])) ||
                                           code[0] == '-' || code[0] == '+' || code[0] == '.');
      if (!continues && !point)
        start = line;
      continues = !code.empty() && code.back() == '$';
    } else {
      start = line;
    }
    starts.push_back(start);
    position = stop + 1;
    ++line;
  }
  return starts;
}

std::vector<FeedEdit> with_feed_restores(const toolpath::Program& program,
                                         std::vector<FeedEdit> changed) {
  bool in_order = true;
  for (std::size_t m = 1; m < program.moves.size(); ++m)
    in_order = in_order && program.moves[m].line >= program.moves[m - 1].line;
  // The feed lines in text order, each with its programmed (slowest) feed.
  std::map<int, double> feed_lines;
  for (const toolpath::Move& move : program.moves) {
    if ((move.kind != toolpath::MotionKind::linear && move.kind != toolpath::MotionKind::arc) ||
        !(move.feed_m_s > 0.0))
      continue;
    auto [it, added] = feed_lines.try_emplace(move.line, move.feed_m_s);
    if (!added)
      it->second = std::min(it->second, move.feed_m_s);
  }
  std::map<int, const FeedEdit*> by_line;
  for (const FeedEdit& edit : changed)
    by_line[edit.line] = &edit;
  std::vector<FeedEdit> edits;
  bool any_changed = false, previous_changed = false;
  for (const auto& [line, feed_m_s] : feed_lines) {
    const auto it = by_line.find(line);
    const bool is_changed = it != by_line.end() && it->second->scale != 1.0;
    if (is_changed)
      edits.push_back(*it->second);
    else if (any_changed && (previous_changed || !in_order))
      edits.push_back({line, 1.0, feed_m_s, "robomill: the programmed feed"});
    any_changed = any_changed || is_changed;
    previous_changed = is_changed;
  }
  return edits;
}

std::string write_spindle_edits(std::string_view text, ProgramFormat format,
                                std::vector<SpindleEdit> edits) {
  return write_program_edits(text, format, std::move(edits), {});
}

std::string write_program_edits(std::string_view text, ProgramFormat format,
                                std::vector<SpindleEdit> spindles, std::vector<FeedEdit> feeds) {
  if (format == Format::krl && !spindles.empty())
    throw InputError("toolpath.format", 0,
                     "KRL programs carry no spindle speed (the cell's PLC sets it): robomill "
                     "reports the chosen speeds but cannot write them into the .src");
  std::stable_sort(
      spindles.begin(), spindles.end(),
      [](const SpindleEdit& a, const SpindleEdit& b) { return a.before_line < b.before_line; });
  std::stable_sort(feeds.begin(), feeds.end(),
                   [](const FeedEdit& a, const FeedEdit& b) { return a.line < b.line; });
  // Keep the file's own line ends (CR LF from Windows posts).
  const std::string_view newline =
      text.find("\r\n") != std::string_view::npos ? std::string_view("\r\n") : "\n";
  std::string out;
  out.reserve(text.size() + 96 * (spindles.size() + feeds.size()));
  std::size_t next_spindle = 0, next_feed = 0;
  // The feed word in force in the original program: G-code's F number (and
  // whether it was an expression), APT's FEDRAT record.
  std::optional<double> gcode_feed;
  bool gcode_feed_expression = false;
  std::string apt_fedrat;
  int apt_cycle_line = 0;  // the CYCLE with its own feed in force (0: none)

  auto feed_missing = [&](int line, std::string_view what) {
    throw InputError(
        "toolpath.file", 0,
        fmt::format("program line {}: {}: robomill cannot rescale its feed", line, what));
  };
  int line = 1;
  std::size_t position = 0;
  while (position <= text.size()) {
    while (next_spindle < spindles.size() && spindles[next_spindle].before_line <= line)
      out += spindle_statement(spindles[next_spindle++], format, newline);
    if (position == text.size()) {
      while (next_feed < feeds.size() && feeds[next_feed].line < line)
        ++next_feed;
      break;
    }
    const std::size_t end = text.find('\n', position);
    const std::size_t stop = end == std::string_view::npos ? text.size() : end + 1;
    std::string_view content = text.substr(position, stop - position);
    std::string_view body = content;  // without the line end
    while (!body.empty() && (body.back() == '\n' || body.back() == '\r'))
      body.remove_suffix(1);
    const std::string_view line_end = content.substr(body.size());

    std::optional<FeedWord> own_feed;
    if (format == Format::gcode)
      own_feed = gcode_feed_word(body);
    while (next_feed < feeds.size() && feeds[next_feed].line < line)
      ++next_feed;
    const FeedEdit* edit =
        next_feed < feeds.size() && feeds[next_feed].line == line ? &feeds[next_feed] : nullptr;
    bool written = false;
    if (edit) {
      const bool restore = edit->scale == 1.0;
      switch (format) {
        case Format::gcode:
          if (own_feed && own_feed->expression)
            feed_missing(line, "its F word is an expression");
          if (own_feed && !restore) {
            out.append(body.substr(0, own_feed->begin));
            out += feed_number(own_feed->value * edit->scale);
            out.append(body.substr(own_feed->end));
            out += fmt::format(" ({})", gcode_comment(edit->comment));
            out.append(line_end);
            written = true;
          } else if (!own_feed) {
            if (gcode_feed_expression)
              feed_missing(line, "the F in force is an expression");
            if (!gcode_feed)
              feed_missing(line, "no F word is in force before it");
            out += restore ? fmt::format("F{}{}", feed_number(*gcode_feed), newline)
                           : fmt::format("F{} ({}){}", feed_number(*gcode_feed * edit->scale),
                                         gcode_comment(edit->comment), newline);
          }
          break;
        case Format::apt:
          if (apt_cycle_line > 0)
            feed_missing(line, fmt::format("it runs in the CYCLE of line {}, which sets its own "
                                           "feed",
                                           apt_cycle_line));
          if (apt_fedrat.empty())
            feed_missing(line, "no FEDRAT is in force before it");
          if (!edit->comment.empty())
            out += fmt::format("$$ {}{}", edit->comment, newline);
          out += (restore ? apt_fedrat : scaled_fedrat(apt_fedrat, edit->scale, line)) +
                 std::string(newline);
          break;
        case Format::krl:
          if (!(edit->programmed_m_s > 0.0))
            feed_missing(line, "no path speed ($VEL.CP) is known for it");
          out += fmt::format("$VEL.CP={}{}{}", feed_number(edit->programmed_m_s * edit->scale),
                             edit->comment.empty() ? "" : " ; " + edit->comment, newline);
          break;
      }
    }
    if (!written)
      out.append(content);
    if (own_feed) {
      gcode_feed_expression = own_feed->expression;
      gcode_feed = own_feed->value;
    }
    if (format == Format::apt && starts_with_word(body, "FEDRAT"))
      apt_fedrat = std::string(trimmed(body));
    if (format == Format::apt && starts_with_word(body, "CYCLE")) {
      // A cycle with a feed of its own (CYCLE/DRILL, d, f, IPM, …) runs its
      // points at that feed whatever FEDRAT says, until CYCLE/OFF.
      std::string record(trimmed(body));
      std::transform(record.begin(), record.end(), record.begin(),
                     [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
      const bool own_feed =
          record.find("IPM") != std::string::npos || record.find("MMPM") != std::string::npos ||
          record.find("IPR") != std::string::npos || record.find("MMPR") != std::string::npos;
      apt_cycle_line = record.find("OFF") == std::string::npos && own_feed ? line : 0;
    }
    position = stop;
    ++line;
    if (end == std::string_view::npos && next_spindle < spindles.size())
      out += newline;  // a last line without its line end
  }
  while (next_spindle < spindles.size())
    out += spindle_statement(spindles[next_spindle++], format, newline);
  return out;
}

}  // namespace robomill::io
