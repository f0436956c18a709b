// write_point_edits: the compensation's moved and added points written into
// a G-code or APT program (the feed and spindle edits are program_writer.cpp).

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

constexpr double kNotKnown = std::numeric_limits<double>::quiet_NaN();

// A word of a G-code line outside comments: its letter (upper case), the
// span [begin, end) from the letter to the number's last character, and its
// value (NaN when written as an expression, [..] or #n, or without number).
struct GcodeWord {
  char letter = 0;
  std::size_t begin = 0, end = 0;
  double value = kNotKnown;
  bool expression = false;
};

// The words of a line and where its code ends (a ';' comment or the end).
std::vector<GcodeWord> gcode_words(std::string_view line, std::size_t& code_end) {
  std::vector<GcodeWord> words;
  code_end = line.size();
  std::size_t i = 0;
  while (i < line.size()) {
    const char c = line[i];
    if (c == ';') {
      code_end = i;
      break;
    }
    if (c == '(' || c == '<') {
      const std::size_t close = line.find(c == '(' ? ')' : '>', i + 1);
      if (close == std::string_view::npos) {
        code_end = c == '(' ? i : line.size();
        break;
      }
      i = close + 1;
      continue;
    }
    if (!std::isalpha(static_cast<unsigned char>(c))) {
      ++i;
      continue;
    }
    GcodeWord word;
    word.letter = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    word.begin = i;
    std::size_t j = i + 1;
    while (j < line.size() && (line[j] == ' ' || line[j] == '\t'))
      ++j;
    if (j < line.size() && (line[j] == '[' || line[j] == '#')) {
      word.expression = true;
      std::size_t k = j;
      if (line[j] == '[') {
        int depth = 0;
        for (; k < line.size(); ++k) {
          depth += line[k] == '[' ? 1 : line[k] == ']' ? -1 : 0;
          if (depth == 0)
            break;
        }
        k = std::min(k + 1, line.size());
      } else {
        ++k;
        while (k < line.size() && std::isdigit(static_cast<unsigned char>(line[k])))
          ++k;
      }
      word.end = k;
      words.push_back(word);
      i = k;
      continue;
    }
    // RS274NGC lets spaces stand inside a number ("X 1 0.5").
    std::size_t k = j;
    if (k < line.size() && (line[k] == '+' || line[k] == '-'))
      ++k;
    std::size_t last = j;
    while (k < line.size() && (std::isdigit(static_cast<unsigned char>(line[k])) ||
                               line[k] == '.' || line[k] == ' ' || line[k] == '\t')) {
      if (line[k] != ' ' && line[k] != '\t')
        last = k + 1;
      ++k;
    }
    std::string digits;
    for (std::size_t n = j; n < last; ++n)
      if (line[n] != ' ' && line[n] != '\t' && line[n] != '+')
        digits += line[n];
    double value = 0.0;
    const auto [stop, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (!digits.empty() && error == std::errc() && stop == digits.data() + digits.size())
      word.value = value;
    word.end = std::max(last, i + 1);
    words.push_back(word);
    i = word.end;
  }
  return words;
}

// A coordinate as the post writes it: fixed decimals (0.1 µm in mm, 0.25 µm
// in inch), no trailing zeros.
std::string coordinate(double value, bool inch) {
  std::string text = fmt::format("{:.{}f}", value, inch ? 5 : 4);
  while (text.back() == '0')
    text.pop_back();
  if (text.back() == '.')
    text.pop_back();
  return text == "-0" ? "0" : text;
}

struct Lines {
  std::vector<std::string_view> body, end;  // [0] unused; end: the line's own line end
};

Lines split_lines_keeping_ends(std::string_view text) {
  Lines lines;
  lines.body.emplace_back();
  lines.end.emplace_back();
  std::size_t position = 0;
  while (position < text.size()) {
    const std::size_t end = text.find('\n', position);
    const std::size_t stop = end == std::string_view::npos ? text.size() : end + 1;
    std::string_view body = text.substr(position, stop - position);
    std::size_t content = body.size();
    while (content > 0 && (body[content - 1] == '\n' || body[content - 1] == '\r'))
      --content;
    lines.body.push_back(body.substr(0, content));
    lines.end.push_back(body.substr(content));
    position = stop;
  }
  return lines;
}

constexpr char kAxes[3] = {'X', 'Y', 'Z'};

/// What write_gcode_points carries from line to line: per axis the
/// programmed value in force and the one the written program holds, in the
/// units in force (NaN: unknown), and the modes in force.
struct GcodeModes {
  double programmed[3] = {kNotKnown, kNotKnown, kNotKnown};
  double written[3] = {kNotKnown, kNotKnown, kNotKnown};
  bool inch = false, incremental = false, cycle = false, control_flow = false;
  bool absolute_centres = false;  // G90.1; G91.1 (rs274's default): I J K from the start
};

/// Reads the modes a line sets (inch or mm, G90/G91, G90.1/G91.1, canned
/// cycles, M98/M99 and O-word control flow) into the state; whether the line
/// holds G28/G30/G53 or G10/G92 (special: the position is not known after).
bool read_gcode_modes(std::string_view body, const std::vector<GcodeWord>& words,
                      std::size_t code_end, GcodeModes& state) {
  double(&programmed)[3] = state.programmed;
  double(&written)[3] = state.written;
  bool& inch = state.inch;
  bool& incremental = state.incremental;
  bool& cycle = state.cycle;
  bool& control_flow = state.control_flow;
  bool& absolute_centres = state.absolute_centres;
  bool special = false, starts_cycle = false, ends_cycle = false;
  for (const GcodeWord& w : words) {
    if (w.letter == 'M' && (w.value == 98.0 || w.value == 99.0))
      control_flow = true;
    if (w.letter != 'G' || w.expression || !std::isfinite(w.value))
      continue;
    const int code = static_cast<int>(std::lround(w.value * 10.0));
    if ((code == 200 && !inch) || (code == 210 && inch)) {
      const double scale = code == 200 ? 1.0 / 25.4 : 25.4;
      for (int a = 0; a < 3; ++a) {
        programmed[a] *= scale;
        written[a] *= scale;
      }
      inch = code == 200;
    }
    incremental = code == 910 ? true : code == 900 ? false : incremental;
    absolute_centres = code == 901 ? true : code == 911 ? false : absolute_centres;
    special = special || code == 280 || code == 300 || code == 530 || code == 920 || code == 100;
    starts_cycle = starts_cycle || code == 730 || code == 760 || (code >= 810 && code <= 890);
    ends_cycle = ends_cycle || code == 800 || code == 0 || code == 10 || code == 20 || code == 30;
  }
  if (ends_cycle)
    cycle = false;
  if (starts_cycle)
    cycle = true;
  // An O word with a keyword (O100 sub, O101 while, O<name> call …) is
  // control flow; a bare program number (O1000) is not.
  if (!words.empty() && words.front().letter == 'O') {
    std::string rest;
    for (char c : body.substr(words.front().end, code_end - words.front().end))
      rest += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    for (const char* keyword :
         {"SUB", "CALL", "WHILE", "DO", "IF", "ELSE", "REPEAT", "RETURN", "BREAK", "CONTINUE"})
      control_flow = control_flow || rest.find(keyword) != std::string::npos;
  }
  return special;
}

/// Why an edit of the line cannot be written (empty: it can).
std::string gcode_skip_reason(const GcodeModes& state, bool special, const PointEdit& edit,
                              const std::vector<GcodeWord>& words,
                              const GcodeWord* const (&explicit_word)[3],
                              const double (&line_programmed)[3]) {
  const double(&programmed)[3] = state.programmed;
  const double(&written)[3] = state.written;
  const bool inch = state.inch;
  const bool incremental = state.incremental;
  const bool cycle = state.cycle;
  const bool control_flow = state.control_flow;
  const bool absolute_centres = state.absolute_centres;
  std::string reason;
  if (incremental)
    reason = "incremental coordinates (G91) in force";
  else if (cycle || special)
    reason = "a canned cycle, G28/G30/G53 or G10/G92 on the line";
  else if (control_flow)
    reason = "O-word control flow or subprogram calls in the program";
  for (int a = 0; a < 3 && reason.empty(); ++a) {
    if (explicit_word[a] && explicit_word[a]->expression)
      reason = fmt::format("its {} word is an expression", kAxes[a]);
    else if (!std::isfinite(line_programmed[a]) &&
             std::abs(edit.offset_m[a]) / (inch ? 25.4e-3 : 1e-3) >= (inch ? 5e-6 : 5e-5))
      reason = fmt::format("the {} in force is not known here", kAxes[a]);
  }
  for (int a = 0; a < 3 && reason.empty() && !edit.points.empty(); ++a)
    if (!std::isfinite(programmed[a]))
      reason = fmt::format("the line's start ({} in force) is not known", kAxes[a]);
  if (reason.empty() && edit.arc) {
    bool has_centre = false;
    for (const GcodeWord& w : words) {
      const bool centre_word = w.letter == 'I' || w.letter == 'J' || w.letter == 'K';
      if (!centre_word && w.letter != 'R')
        continue;
      has_centre = true;
      if (w.expression || !std::isfinite(w.value))
        reason = fmt::format("its {} word is an expression", w.letter);
      else if (centre_word && !absolute_centres && !std::isfinite(written[w.letter - 'I']))
        reason = fmt::format("the arc's start ({} in force) is not known", kAxes[w.letter - 'I']);
    }
    if (!has_centre)
      reason = "an arc without I, J, K or R words";
  }
  return reason;
}

/// The points an edit adds inside the line, absolute, before it (appended to
/// `before`); the written values follow them.
void write_gcode_vias(std::string_view body, const std::vector<GcodeWord>& words,
                      const PointEdit& edit, bool inch, const double (&programmed)[3],
                      const double (&line_programmed)[3], double (&written)[3],
                      std::string& before) {
  const double unit = inch ? 25.4e-3 : 1e-3;
  std::string feed;
  for (const GcodeWord& w : words)
    if (w.letter == 'F')
      feed = fmt::format(" {}", body.substr(w.begin, w.end - w.begin));
  const std::size_t count = edit.points.size();
  for (std::size_t k = 0; k < count; ++k) {
    const PointEdit::Via& via = edit.points[k];
    std::string block = "G1";
    for (int a = 0; a < 3; ++a) {
      const double value =
          programmed[a] + via.u * (line_programmed[a] - programmed[a]) + via.offset_m[a] / unit;
      block.append(" ").push_back(kAxes[a]);
      block += coordinate(value, inch);
      written[a] = std::stod(coordinate(value, inch));
    }
    before += block + (k == 0 ? feed : std::string()) +
              fmt::format(" ({}, point {} of {})\n", gcode_comment(edit.comment), k + 1, count);
  }
}

void write_gcode_points(const Lines& lines, const std::map<int, const PointEdit*>& edits,
                        std::vector<std::string>& out, std::vector<std::string>& before,
                        PointEditResult& result) {
  GcodeModes state;
  double(&programmed)[3] = state.programmed;
  double(&written)[3] = state.written;
  bool& inch = state.inch;
  bool& incremental = state.incremental;
  bool& cycle = state.cycle;
  bool& control_flow = state.control_flow;
  bool& absolute_centres = state.absolute_centres;
  auto differs = [&](int a) {
    return std::isfinite(written[a]) && std::isfinite(programmed[a]) &&
           std::abs(written[a] - programmed[a]) > 1e-9;
  };
  for (std::size_t l = 1; l < lines.body.size(); ++l) {
    const std::string_view body = lines.body[l];
    std::size_t code_end = 0;
    const std::vector<GcodeWord> words = gcode_words(body, code_end);
    const bool special = read_gcode_modes(body, words, code_end, state);
    const GcodeWord* explicit_word[3] = {nullptr, nullptr, nullptr};
    for (const GcodeWord& w : words)
      for (int a = 0; a < 3; ++a)
        if (w.letter == kAxes[a])
          explicit_word[a] = &w;
    const bool moves = explicit_word[0] || explicit_word[1] || explicit_word[2];

    // The values this line leaves in force, as programmed and as written.
    double line_programmed[3], line_written[3];
    for (int a = 0; a < 3; ++a) {
      const GcodeWord* w = explicit_word[a];
      const double value = w && !w->expression ? w->value : kNotKnown;
      line_programmed[a] = !w ? programmed[a] : incremental ? programmed[a] + value : value;
      line_written[a] = !w ? written[a] : incremental ? written[a] + value : value;
    }
    const auto edit = edits.find(static_cast<int>(l));
    std::string reason;
    if (edit != edits.end()) {
      reason =
          gcode_skip_reason(state, special, *edit->second, words, explicit_word, line_programmed);
      if (!reason.empty())
        result.skipped.push_back({static_cast<int>(l), reason});
    }
    // The points added inside the line, absolute, before it: the line's own
    // F (if it has one) goes with the first, so that they run at its feed.
    if (edit != edits.end() && reason.empty() && !edit->second->points.empty()) {
      write_gcode_vias(body, words, *edit->second, inch, programmed, line_programmed, written,
                       before[l]);
      for (int a = 0; a < 3; ++a)
        if (!explicit_word[a])
          line_written[a] = written[a];
    }
    // Which axes get a word written, and what it holds: the edit's moved
    // values, or an axis put back on the programmed path after an earlier
    // edit (in G91 the increment less the offset still carried).
    const bool restore = moves && !cycle && !special && !control_flow;
    bool rewrite = false;
    double word_value[3] = {0.0, 0.0, 0.0};
    bool write_axis[3] = {false, false, false};
    for (int a = 0; a < 3; ++a) {
      if (edit != edits.end() && reason.empty()) {
        const double offset = edit->second->offset_m[a] / (inch ? 25.4e-3 : 1e-3);
        word_value[a] = line_programmed[a] + offset;
        write_axis[a] = std::isfinite(line_programmed[a]) &&
                        (explicit_word[a] || std::abs(offset) >= (inch ? 5e-6 : 5e-5) ||
                         std::abs(written[a] - line_programmed[a]) > 1e-9);
        rewrite = true;
      } else if (restore && differs(a) && (incremental || !explicit_word[a])) {
        const double carried = written[a] - programmed[a];
        word_value[a] = incremental ? (explicit_word[a] ? explicit_word[a]->value : 0.0) - carried
                                    : line_programmed[a];
        write_axis[a] = true;
        rewrite = true;
      }
    }
    // An arc moved: I J K from the start as written (or absolute), R the
    // moved radius, in the units in force.
    const bool arc_edit = edit != edits.end() && reason.empty() && edit->second->arc;
    auto centre_word = [&](const GcodeWord& w) -> std::optional<double> {
      if (!arc_edit)
        return std::nullopt;
      const double unit = inch ? 25.4e-3 : 1e-3;
      if (w.letter == 'R')
        return w.value + std::copysign(edit->second->arc->radius_change_m / unit, w.value);
      if (w.letter < 'I' || w.letter > 'K')
        return std::nullopt;
      const int a = w.letter - 'I';
      const double moved = edit->second->arc->centre_offset_m[a] / unit;
      return absolute_centres ? w.value + moved : w.value + programmed[a] - written[a] + moved;
    };
    if (rewrite) {
      std::string line;
      std::size_t copied = 0;
      for (const GcodeWord& w : words) {
        int a = -1;
        for (int k = 0; k < 3; ++k)
          if (&w == explicit_word[k] && write_axis[k])
            a = k;
        const std::optional<double> centre = centre_word(w);
        if (a < 0 && !centre)
          continue;
        line.append(body.substr(copied, w.begin - copied));
        line += a >= 0 ? kAxes[a] + coordinate(word_value[a], inch)
                       : w.letter + coordinate(*centre, inch);
        copied = w.end;
      }
      line.append(body.substr(copied, code_end - copied));
      for (int a = 0; a < 3; ++a)
        if (write_axis[a] && !explicit_word[a])
          line += std::string(" ") + kAxes[a] + coordinate(word_value[a], inch);
      if (edit != edits.end() && reason.empty())
        line += fmt::format(" ({})", gcode_comment(edit->second->comment));
      else
        line += " (robomill: back on the programmed path)";
      line.append(body.substr(code_end));
      out[l] = std::move(line);
      for (int a = 0; a < 3; ++a) {
        if (!write_axis[a])
          continue;
        const double as_written = std::stod(coordinate(word_value[a], inch));
        line_written[a] = incremental ? written[a] + as_written : as_written;
      }
    }
    for (int a = 0; a < 3; ++a) {
      programmed[a] = line_programmed[a];
      written[a] = line_written[a];
    }
    if (special || control_flow)
      for (int a = 0; a < 3; ++a)
        programmed[a] = written[a] = kNotKnown;
    if (cycle)  // the tool ends at the R plane or the initial level
      programmed[2] = written[2] = kNotKnown;
  }
}

// The numbers of a CIRCLE record over its '$' lines (line, span, value),
// waiting for the GOTO that ends its arc; empty where one is not a number.
struct AptNumber {
  std::size_t line = 0, begin = 0, end = 0;
  double value = 0.0;
};

/// The rotation an MSYS/CSYS record on line l (upper: its code in capitals)
/// sets: part-frame offsets to the record's numbers; none where robomill does
/// not read the frame.
std::optional<Eigen::Matrix3d> apt_frame(const Lines& lines, std::size_t l,
                                         const std::string& upper) {
  // The record's numbers, over its '$' continuation lines.
  std::string record(upper.substr(std::min(upper.size(), upper.find('/') + 1)));
  for (std::size_t next = l + 1;
       !record.empty() && record.back() == '$' && next < lines.body.size(); ++next) {
    record.pop_back();
    const std::size_t more = lines.body[next].find("$$");
    record.append(",").append(trimmed(
        more == std::string_view::npos ? lines.body[next] : lines.body[next].substr(0, more)));
  }
  std::vector<double> numbers;
  bool all_numbers = true;
  for (std::size_t at = 0; at <= record.size();) {
    std::size_t stop = record.find(',', at);
    if (stop == std::string::npos)
      stop = record.size();
    const std::string_view token = trimmed(std::string_view(record).substr(at, stop - at));
    double value = 0.0;
    const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (!token.empty() && (error != std::errc() || end != token.data() + token.size()))
      all_numbers = false;
    else if (!token.empty())
      numbers.push_back(value);
    at = stop + 1;
  }
  std::optional<Eigen::Matrix3d> to_frame;
  if (record.find("OFF") != std::string::npos) {
    to_frame = Eigen::Matrix3d::Identity();
  } else if (all_numbers && numbers.size() == 9) {  // origin, X axis, Y axis (NX)
    const Eigen::Vector3d x = Eigen::Vector3d(numbers[3], numbers[4], numbers[5]).normalized();
    const Eigen::Vector3d y = Eigen::Vector3d(numbers[6], numbers[7], numbers[8]).normalized();
    Eigen::Matrix3d a;
    a << x, y, x.cross(y);
    to_frame = a.transpose();
  } else if (all_numbers && numbers.size() == 12) {  // the APT matrix, rows a1..a4 …
    Eigen::Matrix3d a;
    a << numbers[0], numbers[1], numbers[2], numbers[4], numbers[5], numbers[6], numbers[8],
        numbers[9], numbers[10];
    if (std::abs(a.determinant()) > 1e-9)
      to_frame = a.inverse();
  }
  return to_frame;
}

/// The numbers of the CIRCLE record on line l, over its '$' lines; none
/// unless it holds at least seven.
std::optional<std::vector<AptNumber>> apt_circle_numbers(const Lines& lines, std::size_t l) {
  std::vector<AptNumber> numbers;
  for (std::size_t k = l; k < lines.body.size(); ++k) {
    const std::string_view text_k = lines.body[k];
    const std::size_t comment_k = text_k.find("$$");
    std::size_t stop_k = comment_k == std::string_view::npos ? text_k.size() : comment_k;
    std::size_t position = k == l ? text_k.find('/') + 1 : 0;
    const std::string_view code_k = trimmed(text_k.substr(0, stop_k));
    const bool continued = !code_k.empty() && code_k.back() == '$';
    if (continued)
      stop_k = static_cast<std::size_t>(code_k.data() - text_k.data()) + code_k.size() - 1;
    while (position < stop_k) {
      std::size_t comma = text_k.find(',', position);
      if (comma == std::string_view::npos || comma > stop_k)
        comma = stop_k;
      const std::string_view token = trimmed(text_k.substr(position, comma - position));
      double value = 0.0;
      const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
      if (!token.empty()) {
        if (error != std::errc() || end != token.data() + token.size())
          break;
        const std::size_t at = static_cast<std::size_t>(token.data() - text_k.data());
        numbers.push_back({k, at, at + token.size(), value});
      }
      position = comma + 1;
    }
    if (!continued)
      break;
  }
  return numbers.size() >= 7 ? std::optional(numbers) : std::nullopt;
}

/// A GOTO's x, y, z (their spans in body, and values) from the code between
/// code_begin and code_stop: after GOTO/ on the record's line, or from the
/// start of a further point's line.
void read_goto_point(std::string_view body, const std::string& upper, std::size_t code_begin,
                     std::size_t code_stop, std::vector<std::pair<std::size_t, std::size_t>>& spans,
                     std::vector<double>& values) {
  std::size_t position = code_begin;
  if (starts_with_word(upper, "GOTO")) {
    const std::size_t slash = body.find('/', code_begin);
    position = slash == std::string_view::npos ? body.size() : slash + 1;
  }
  while (spans.size() < 3 && position < code_stop) {
    std::size_t stop = body.find(',', position);
    if (stop == std::string_view::npos || stop > code_stop)
      stop = code_stop;
    const std::string_view token = trimmed(body.substr(position, stop - position));
    double value = 0.0;
    const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (token.empty() || error != std::errc() || end != token.data() + token.size())
      break;
    const std::size_t at = static_cast<std::size_t>(token.data() - body.data());
    spans.emplace_back(at, at + token.size());
    values.push_back(value);
    position = stop + 1;
  }
}

void write_apt_points(std::string_view text, const Lines& lines,
                      const std::map<int, const PointEdit*>& edits, std::vector<std::string>& out,
                      std::vector<std::string>& before, PointEditResult& result,
                      AptLengthUnit apt_units) {
  const std::vector<int> starts = statement_starts(text, Format::apt);
  // Before a UNITS record, the unit the reader read the lengths in (an NX
  // CLSF has none: toolpath.units, else its first feed's unit).
  std::optional<AptOptions::Unit> job_units;
  if (apt_units != AptLengthUnit::unset)
    job_units = apt_units == AptLengthUnit::inch ? AptOptions::Unit::inch : AptOptions::Unit::mm;
  bool inch = apt_leading_unit(text, job_units) == AptOptions::Unit::inch, cycle = false;
  // The MSYS/CSYS frame in force: coordinates p map to the part as A p + t,
  // so an offset in the part frame is A⁻¹ offset in the record's numbers.
  // (A matrix and a flag rather than std::optional<Matrix3d>: GCC 12 at -O3
  // reads the optional's payload as maybe-uninitialized.)
  Eigen::Matrix3d to_frame = Eigen::Matrix3d::Identity();
  bool frame_known = true;
  std::optional<Eigen::Vector3d> last_point;  // the last GOTO's x, y, z as written
  bool last_record_was_goto = false;
  std::optional<std::vector<AptNumber>> pending_circle, circle;
  for (std::size_t l = 1; l < lines.body.size(); ++l) {
    const std::string_view body = lines.body[l];
    const std::size_t comment = body.find("$$");
    const std::string_view code =
        trimmed(comment == std::string_view::npos ? body : body.substr(0, comment));
    std::string upper(code);
    std::transform(upper.begin(), upper.end(), upper.begin(),
                   [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
    if (starts_with_word(upper, "UNITS") || starts_with_word(upper, "UNIT"))
      inch = upper.find("INCH") != std::string::npos
                 ? true
                 : (upper.find("MM") != std::string::npos ? false : inch);
    if (starts_with_word(upper, "MSYS") || starts_with_word(upper, "CSYS")) {
      const std::optional<Eigen::Matrix3d> frame = apt_frame(lines, l, upper);
      frame_known = frame.has_value();
      if (frame)
        to_frame = *frame;
    }
    if (starts_with_word(upper, "CYCLE"))
      cycle = upper.find("OFF") == std::string::npos;
    if (starts_with_word(upper, "CIRCLE")) {
      pending_circle = apt_circle_numbers(lines, l);
    }
    // A GOTO's point: x, y, z after GOTO/ on the record's line, or from the
    // start of a further point's line in a GOTO record.
    const int record = l < starts.size() ? starts[l] : static_cast<int>(l);
    const bool record_line = record == static_cast<int>(l);
    const bool goto_record =
        starts_with_word(upper, "GOTO") || (!record_line && last_record_was_goto && !code.empty());
    if (record_line)
      last_record_was_goto = starts_with_word(upper, "GOTO");
    if (record_line && starts_with_word(upper, "GOTO")) {
      circle = std::move(pending_circle);
      pending_circle.reset();
    } else if (record_line && !code.empty()) {
      circle.reset();
    }
    std::vector<std::pair<std::size_t, std::size_t>> spans;  // [begin, end) of x, y, z
    std::vector<double> values;
    const std::size_t code_begin = static_cast<std::size_t>(code.data() - body.data());
    const std::size_t code_stop = code_begin + code.size();
    if (goto_record)
      read_goto_point(body, upper, code_begin, code_stop, spans, values);
    const std::optional<Eigen::Vector3d> start = last_point;
    if (spans.size() == 3)
      last_point = Eigen::Vector3d(values[0], values[1], values[2]);
    const auto edit = edits.find(static_cast<int>(l));
    if (edit == edits.end())
      continue;
    std::string reason;
    if (!frame_known)
      reason = "the MSYS/CSYS frame in force is not one robomill reads";
    else if (cycle)
      reason = "the point runs in a CYCLE";
    else if (spans.size() < 3)
      reason = "the line does not hold the point's three coordinates";
    else if (!edit->second->points.empty() &&
             (!record_line || !start || code.back() == '$' ||
              code.find(',', spans[2].second - code_begin) != std::string_view::npos))
      reason =
          "points cannot be added before a GOTO that is not a record of its own with three "
          "coordinates";
    else if (edit->second->arc && (!record_line || !circle || code.back() == '$' ||
                                   (l + 1 < starts.size() && starts[l + 1] == static_cast<int>(l))))
      reason =
          "the arc's CIRCLE record is not numbers, or serves further points (arc pieces) after "
          "this GOTO";
    if (!reason.empty()) {
      result.skipped.push_back({static_cast<int>(l), reason});
      continue;
    }
    const double unit = inch ? 25.4e-3 : 1e-3;
    const Eigen::Vector3d end = *last_point;
    std::string inserted = "$$ " + edit->second->comment + "\n";
    for (const PointEdit::Via& via : edit->second->points) {
      const Eigen::Vector3d p = *start + via.u * (end - *start) + to_frame * via.offset_m / unit;
      inserted += fmt::format("GOTO/{},{},{}\n", coordinate(p.x(), inch), coordinate(p.y(), inch),
                              coordinate(p.z(), inch));
    }
    std::string line;
    std::size_t copied = 0;
    const Eigen::Vector3d offset = to_frame * edit->second->offset_m / unit;
    for (int k = 0; k < 3; ++k) {
      line.append(body.substr(copied, spans[k].first - copied));
      line += coordinate(values[k] + offset[k], inch);
      copied = spans[k].second;
    }
    line.append(body.substr(copied));
    out[l] = std::move(line);
    before[static_cast<std::size_t>(record)] += inserted;
    if (edit->second->arc) {  // the CIRCLE's centre and radius, last span first
      const Eigen::Vector3d centre = to_frame * edit->second->arc->centre_offset_m / unit;
      for (int k : {6, 2, 1, 0}) {
        const AptNumber& n = (*circle)[static_cast<std::size_t>(k)];
        const double value =
            n.value + (k == 6 ? edit->second->arc->radius_change_m / unit : centre[k]);
        out[n.line].replace(n.begin, n.end - n.begin, coordinate(value, inch));
      }
    }
  }
}

}  // namespace

PointEditResult write_point_edits(std::string_view text, ProgramFormat format,
                                  std::vector<PointEdit> edits, AptLengthUnit apt_units) {
  if (format == Format::krl && !edits.empty())
    throw InputError("toolpath.format", 0,
                     "write_point_edits writes G-code and APT; a KRL program's points are "
                     "moved where they are written (io/krl_point_edits.hpp)");
  std::map<int, const PointEdit*> by_line;
  for (const PointEdit& edit : edits)
    by_line[edit.line] = &edit;
  const Lines lines = split_lines_keeping_ends(text);
  std::vector<std::string> out(lines.body.size()), before(lines.body.size());
  for (std::size_t l = 1; l < lines.body.size(); ++l)
    out[l] = std::string(lines.body[l]);
  PointEditResult result;
  if (format == Format::gcode)
    write_gcode_points(lines, by_line, out, before, result);
  else
    write_apt_points(text, lines, by_line, out, before, result, apt_units);
  const std::string_view newline =
      text.find("\r\n") != std::string_view::npos ? std::string_view("\r\n") : "\n";
  result.text.reserve(text.size() + 64 * edits.size());
  for (std::size_t l = 1; l < lines.body.size(); ++l) {
    if (!before[l].empty()) {
      std::string inserted = before[l];
      if (newline != "\n") {  // the file's own line ends
        std::string converted;
        for (char c : inserted)
          converted += c == '\n' ? std::string(newline) : std::string(1, c);
        inserted = converted;
      }
      result.text += inserted;
    }
    result.text += out[l];
    result.text.append(lines.end[l]);
  }
  return result;
}

}  // namespace robomill::io
