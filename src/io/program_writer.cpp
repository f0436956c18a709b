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

#include "robomill/core/error.hpp"
#include "robomill/io/program_readers.hpp"

namespace robomill::io {
namespace {

using Format = ToolpathSettings::Format;

std::string gcode_comment(std::string comment) {
  std::replace(comment.begin(), comment.end(), '(', '[');
  std::replace(comment.begin(), comment.end(), ')', ']');
  return comment;
}

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
std::string number(double value) {
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

std::string_view trimmed(std::string_view text) {
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front())))
    text.remove_prefix(1);
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back())))
    text.remove_suffix(1);
  return text;
}

bool starts_with_word(std::string_view text, std::string_view word) {
  text = trimmed(text);
  if (text.size() < word.size())
    return false;
  for (std::size_t i = 0; i < word.size(); ++i)
    if (std::toupper(static_cast<unsigned char>(text[i])) != word[i])
      return false;
  return text.size() == word.size() || text[word.size()] == '/' || text[word.size()] == ' ';
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
      return std::string(record.substr(0, at)) + number(value * scale) +
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

std::vector<int> statement_starts(std::string_view text, ToolpathSettings::Format format) {
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

std::string write_spindle_edits(std::string_view text, ToolpathSettings::Format format,
                                std::vector<SpindleEdit> edits) {
  return write_program_edits(text, format, std::move(edits), {});
}

std::string write_program_edits(std::string_view text, ToolpathSettings::Format format,
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
            out += number(own_feed->value * edit->scale);
            out.append(body.substr(own_feed->end));
            out += fmt::format(" ({})", gcode_comment(edit->comment));
            out.append(line_end);
            written = true;
          } else if (!own_feed) {
            if (gcode_feed_expression)
              feed_missing(line, "the F in force is an expression");
            if (!gcode_feed)
              feed_missing(line, "no F word is in force before it");
            out += restore ? fmt::format("F{}{}", number(*gcode_feed), newline)
                           : fmt::format("F{} ({}){}", number(*gcode_feed * edit->scale),
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
          out += fmt::format("$VEL.CP={}{}{}", number(edit->programmed_m_s * edit->scale),
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

namespace robomill::io {
namespace {

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

Lines split_lines(std::string_view text) {
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

void write_gcode_points(const Lines& lines, const std::map<int, const PointEdit*>& edits,
                        std::vector<std::string>& out, std::vector<std::string>& before,
                        PointEditResult& result) {
  constexpr char kAxes[3] = {'X', 'Y', 'Z'};
  // Per axis the programmed value in force and the one the written program
  // holds, in the units in force (NaN: unknown).
  double programmed[3] = {kNotKnown, kNotKnown, kNotKnown};
  double written[3] = {kNotKnown, kNotKnown, kNotKnown};
  bool inch = false, incremental = false, cycle = false, control_flow = false;
  bool absolute_centres = false;  // G90.1; G91.1 (rs274's default): I J K from the start
  auto differs = [&](int a) {
    return std::isfinite(written[a]) && std::isfinite(programmed[a]) &&
           std::abs(written[a] - programmed[a]) > 1e-9;
  };
  for (std::size_t l = 1; l < lines.body.size(); ++l) {
    const std::string_view body = lines.body[l];
    std::size_t code_end = 0;
    const std::vector<GcodeWord> words = gcode_words(body, code_end);
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
                 std::abs(edit->second->offset_m[a]) / (inch ? 25.4e-3 : 1e-3) >=
                     (inch ? 5e-6 : 5e-5))
          reason = fmt::format("the {} in force is not known here", kAxes[a]);
      }
      for (int a = 0; a < 3 && reason.empty() && !edit->second->points.empty(); ++a)
        if (!std::isfinite(programmed[a]))
          reason = fmt::format("the line's start ({} in force) is not known", kAxes[a]);
      if (reason.empty() && edit->second->arc) {
        bool has_centre = false;
        for (const GcodeWord& w : words) {
          const bool centre_word = w.letter == 'I' || w.letter == 'J' || w.letter == 'K';
          if (!centre_word && w.letter != 'R')
            continue;
          has_centre = true;
          if (w.expression || !std::isfinite(w.value))
            reason = fmt::format("its {} word is an expression", w.letter);
          else if (centre_word && !absolute_centres && !std::isfinite(written[w.letter - 'I']))
            reason =
                fmt::format("the arc's start ({} in force) is not known", kAxes[w.letter - 'I']);
        }
        if (!has_centre)
          reason = "an arc without I, J, K or R words";
      }
      if (!reason.empty())
        result.skipped.push_back({static_cast<int>(l), reason});
    }
    // The points added inside the line, absolute, before it: the line's own
    // F (if it has one) goes with the first, so that they run at its feed.
    if (edit != edits.end() && reason.empty() && !edit->second->points.empty()) {
      const double unit = inch ? 25.4e-3 : 1e-3;
      std::string feed;
      for (const GcodeWord& w : words)
        if (w.letter == 'F')
          feed = " " + std::string(body.substr(w.begin, w.end - w.begin));
      const std::size_t count = edit->second->points.size();
      for (std::size_t k = 0; k < count; ++k) {
        const PointEdit::Via& via = edit->second->points[k];
        std::string block = "G1";
        for (int a = 0; a < 3; ++a) {
          const double value =
              programmed[a] + via.u * (line_programmed[a] - programmed[a]) + via.offset_m[a] / unit;
          block += std::string(" ") + kAxes[a] + coordinate(value, inch);
          written[a] = std::stod(coordinate(value, inch));
        }
        before[l] += block + (k == 0 ? feed : std::string()) +
                     fmt::format(" ({}, point {} of {})\n", gcode_comment(edit->second->comment),
                                 k + 1, count);
      }
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

void write_apt_points(std::string_view text, const Lines& lines,
                      const std::map<int, const PointEdit*>& edits, std::vector<std::string>& out,
                      std::vector<std::string>& before, PointEditResult& result,
                      ToolpathSettings::Units apt_units) {
  const std::vector<int> starts = statement_starts(text, Format::apt);
  // Before a UNITS record, the unit the reader read the lengths in (an NX
  // CLSF has none: toolpath.units, else its first feed's unit).
  std::optional<AptOptions::Unit> job_units;
  if (apt_units != ToolpathSettings::Units::unset)
    job_units =
        apt_units == ToolpathSettings::Units::inch ? AptOptions::Unit::inch : AptOptions::Unit::mm;
  bool inch = apt_leading_unit(text, job_units) == AptOptions::Unit::inch, cycle = false;
  // The MSYS/CSYS frame in force: coordinates p map to the part as A p + t,
  // so an offset in the part frame is A⁻¹ offset in the record's numbers.
  std::optional<Eigen::Matrix3d> to_frame = Eigen::Matrix3d::Identity();
  std::optional<Eigen::Vector3d> last_point;  // the last GOTO's x, y, z as written
  bool last_record_was_goto = false;
  // The numbers of a CIRCLE record over its '$' lines (line, span, value),
  // waiting for the GOTO that ends its arc; empty where one is not a number.
  struct Number {
    std::size_t line = 0, begin = 0, end = 0;
    double value = 0.0;
  };
  std::optional<std::vector<Number>> pending_circle, circle;
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
      // The record's numbers, over its '$' continuation lines.
      std::string record(upper.substr(std::min(upper.size(), upper.find('/') + 1)));
      for (std::size_t next = l + 1;
           !record.empty() && record.back() == '$' && next < lines.body.size(); ++next) {
        record.pop_back();
        const std::size_t more = lines.body[next].find("$$");
        record += "," + std::string(trimmed(more == std::string_view::npos
                                                ? lines.body[next]
                                                : lines.body[next].substr(0, more)));
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
      to_frame.reset();
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
    }
    if (starts_with_word(upper, "CYCLE"))
      cycle = upper.find("OFF") == std::string::npos;
    if (starts_with_word(upper, "CIRCLE")) {
      std::vector<Number> numbers;
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
          const auto [end, error] =
              std::from_chars(token.data(), token.data() + token.size(), value);
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
      pending_circle = numbers.size() >= 7 ? std::optional(numbers) : std::nullopt;
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
    if (goto_record) {
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
    const std::optional<Eigen::Vector3d> start = last_point;
    if (spans.size() == 3)
      last_point = Eigen::Vector3d(values[0], values[1], values[2]);
    const auto edit = edits.find(static_cast<int>(l));
    if (edit == edits.end())
      continue;
    std::string reason;
    if (!to_frame)
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
      const Eigen::Vector3d p = *start + via.u * (end - *start) + *to_frame * via.offset_m / unit;
      inserted += fmt::format("GOTO/{},{},{}\n", coordinate(p.x(), inch), coordinate(p.y(), inch),
                              coordinate(p.z(), inch));
    }
    std::string line;
    std::size_t copied = 0;
    const Eigen::Vector3d offset = *to_frame * edit->second->offset_m / unit;
    for (int k = 0; k < 3; ++k) {
      line.append(body.substr(copied, spans[k].first - copied));
      line += coordinate(values[k] + offset[k], inch);
      copied = spans[k].second;
    }
    line.append(body.substr(copied));
    out[l] = std::move(line);
    before[static_cast<std::size_t>(record)] += inserted;
    if (edit->second->arc) {  // the CIRCLE's centre and radius, last span first
      const Eigen::Vector3d centre = *to_frame * edit->second->arc->centre_offset_m / unit;
      for (int k : {6, 2, 1, 0}) {
        const Number& n = (*circle)[static_cast<std::size_t>(k)];
        const double value =
            n.value + (k == 6 ? edit->second->arc->radius_change_m / unit : centre[k]);
        out[n.line].replace(n.begin, n.end - n.begin, coordinate(value, inch));
      }
    }
  }
}

}  // namespace

PointEditResult write_point_edits(std::string_view text, ToolpathSettings::Format format,
                                  std::vector<PointEdit> edits, ToolpathSettings::Units apt_units) {
  if (format == Format::krl && !edits.empty())
    throw InputError("toolpath.format", 0,
                     "write_point_edits writes G-code and APT; a KRL program's points are "
                     "moved where they are written (io/krl_point_edits.hpp)");
  std::map<int, const PointEdit*> by_line;
  for (const PointEdit& edit : edits)
    by_line[edit.line] = &edit;
  const Lines lines = split_lines(text);
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
