// A KRL program's frames turned about the tool axis (io/krl_frame_turn.hpp).

#include "robomill/io/krl_frame_turn.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <functional>
#include <map>
#include <numbers>
#include <optional>

namespace robomill::io {
namespace {

constexpr double kRadPerDeg = std::numbers::pi / 180.0;

std::string upper(std::string_view text) {
  std::string out(text);
  for (char& c : out)
    c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

std::string_view trim(std::string_view text) {
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front())))
    text.remove_prefix(1);
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back())))
    text.remove_suffix(1);
  return text;
}

std::optional<double> number(std::string_view text) {
  text = trim(text);
  if (!text.empty() && text.front() == '+')
    text.remove_prefix(1);
  double value = 0.0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || !std::isfinite(value))
    return std::nullopt;
  return value;
}

// KUKA's A, B, C (deg): R = Rz(A) Ry(B) Rx(C).
Eigen::Matrix3d rotation_abc(double a_deg, double b_deg, double c_deg) {
  return (Eigen::AngleAxisd(a_deg * kRadPerDeg, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(b_deg * kRadPerDeg, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(c_deg * kRadPerDeg, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

// Its inverse; at B = ±90° (A and C turn about the same axis) the one with
// C = 0: Rz(A) Ry(B) has the column Rz(A) e_y = (−sin A, cos A, 0).
std::array<double, 3> abc_of(const Eigen::Matrix3d& r) {
  const double cos_b = std::hypot(r(0, 0), r(1, 0));
  const double b = std::atan2(-r(2, 0), cos_b);
  if (cos_b > 1e-12)
    return {std::atan2(r(1, 0), r(0, 0)) / kRadPerDeg, b / kRadPerDeg,
            std::atan2(r(2, 1), r(2, 2)) / kRadPerDeg};
  return {std::atan2(-r(0, 1), r(1, 1)) / kRadPerDeg, b / kRadPerDeg, 0.0};
}

// A value as KRL reads it after the component's name: a space, up to 9
// significant digits, -0 as 0.
std::string krl_value(double value) {
  if (std::abs(value) < 5e-10)
    value = 0.0;
  return fmt::format(" {:.9g}", value);
}

struct Item {
  std::size_t value_begin = 0, value_end = 0;  // in the aggregate's text
  std::string name;
};

// The items "NAME value" of an aggregate's inner text.
std::vector<Item> items_of(std::string_view inner) {
  std::vector<Item> items;
  std::size_t start = 0;
  while (start <= inner.size()) {
    std::size_t end = inner.find(',', start);
    if (end == std::string_view::npos)
      end = inner.size();
    std::size_t i = start;
    while (i < end && std::isspace(static_cast<unsigned char>(inner[i])))
      ++i;
    const std::size_t name_begin = i;
    while (i < end && (std::isalnum(static_cast<unsigned char>(inner[i])) || inner[i] == '_'))
      ++i;
    if (i > name_begin)
      items.push_back({i, end, upper(inner.substr(name_begin, i - name_begin))});
    start = end + 1;
  }
  return items;
}

// The turn of the Cartesian aggregate at (line, ordinal): nullopt keeps it.
using TurnAt = std::function<std::optional<KrlFrameEdit>(int line, int ordinal)>;

// Turns the aggregates of one text; `file` names it in refusals. `all`:
// every frame is to turn, so one without all of A, B, C is refused.
std::string turn_text(std::string_view text, const std::string& file, const TurnAt& turn_at,
                      bool all, const Eigen::Vector3d& local_axis, KrlFrameTurn& result) {
  std::string out;
  out.reserve(text.size());
  int line = 1;
  int ordinal = 0;                  // Cartesian aggregates before, on this line
  std::size_t statement_start = 0;  // in `text`: the start of the current line
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n') {
      ++line;
      ordinal = 0;
      statement_start = i + 1;
      out += c;
      continue;
    }
    if (c == ';') {  // a comment (;FOLD … %{PE}) runs to the end of the line
      const std::size_t end = text.find('\n', i);
      const std::size_t stop = end == std::string_view::npos ? text.size() : end;
      out.append(text.substr(i, stop - i));
      i = stop - 1;
      continue;
    }
    if (c == '"') {  // a string
      const std::size_t end = text.find('"', i + 1);
      const std::size_t stop = end == std::string_view::npos ? text.size() : end + 1;
      out.append(text.substr(i, stop - i));
      i = stop - 1;
      continue;
    }
    if (c != '{') {
      out += c;
      continue;
    }
    const std::size_t close = text.find_first_of("}\n", i + 1);
    if (close == std::string_view::npos || text[close] != '}') {
      out += c;
      continue;
    }
    const std::string_view inner = text.substr(i + 1, close - i - 1);
    const std::string target = upper(trim(text.substr(statement_start, i - statement_start)));
    std::vector<Item> items = items_of(inner);
    const Item* abc[3] = {nullptr, nullptr, nullptr};
    for (const Item& item : items)
      for (int k = 0; k < 3; ++k)
        if (item.name == std::string(1, "ABC"[k]))
          abc[k] = &item;
    const int found = (abc[0] != nullptr) + (abc[1] != nullptr) + (abc[2] != nullptr);
    const bool cartesian = std::any_of(items.begin(), items.end(), [](const Item& item) {
      return item.name.size() == 1 &&
             std::string_view("XYZABC").find(item.name[0]) != std::string_view::npos;
    });
    // A system variable ($BASE, $TOOL, …) or the base and tool tables place
    // frames, not the tool's path.
    const bool placement =
        !target.empty() && (target.front() == '$' || target.rfind("BASE_DATA", 0) == 0 ||
                            target.rfind("TOOL_DATA", 0) == 0);
    const std::optional<KrlFrameEdit> edit =
        cartesian ? turn_at(line, ordinal++) : std::optional<KrlFrameEdit>();
    // Turning every frame, one without A, B, C inherits the turned frame
    // before it; one with some of them cannot be turned alone.
    const bool skip = placement || !edit || (all && found == 0);
    if (skip) {
      out.append(text.substr(i, close - i + 1));
      i = close;
      continue;
    }
    if (found < 3 && !edit->in_force_abc_deg) {
      result.refused.push_back(
          {file, line,
           "a partial orientation (not all of A, B, C): the frame before sets the rest"});
      out.append(text.substr(i, close - i + 1));
      i = close;
      continue;
    }
    std::array<double, 3> values = edit->in_force_abc_deg.value_or(std::array<double, 3>{});
    bool plain = true;
    for (int k = 0; k < 3; ++k) {
      if (!abc[k])
        continue;
      const auto v =
          number(inner.substr(abc[k]->value_begin, abc[k]->value_end - abc[k]->value_begin));
      plain = plain && v.has_value();
      values[static_cast<std::size_t>(k)] = v.value_or(0.0);
    }
    if (!plain) {
      result.refused.push_back({file, line, "A, B or C written as an expression"});
      out.append(text.substr(i, close - i + 1));
      i = close;
      continue;
    }
    const std::array<double, 3> turned =
        abc_of(rotation_abc(values[0], values[1], values[2]) *
               Eigen::AngleAxisd(-edit->turn_rad, local_axis).toRotationMatrix());
    // Rebuild the aggregate with the values of A, B, C replaced in place,
    // those it lacked appended.
    std::string rebuilt(inner);
    std::vector<int> which;
    for (int k = 0; k < 3; ++k)
      if (abc[k])
        which.push_back(k);
    std::sort(which.begin(), which.end(),
              [&](int a, int b) { return abc[a]->value_begin > abc[b]->value_begin; });
    for (const int k : which)
      rebuilt.replace(abc[k]->value_begin, abc[k]->value_end - abc[k]->value_begin,
                      krl_value(turned[static_cast<std::size_t>(k)]));
    for (int k = 0; k < 3; ++k)
      if (!abc[k])
        rebuilt += fmt::format(",{}{}", "ABC"[k], krl_value(turned[static_cast<std::size_t>(k)]));
    out += '{';
    out += rebuilt;
    out += '}';
    ++result.frames;
    i = close;
  }
  return out;
}

}  // namespace

KrlFrameTurn turn_krl_frames(std::string_view src, std::string_view dat, double turn_rad,
                             char tool_direction) {
  const Eigen::Vector3d local =
      tool_direction == 'z' ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
  const TurnAt every = [&](int, int) { return std::optional<KrlFrameEdit>({turn_rad, {}}); };
  KrlFrameTurn result;
  result.src = turn_text(src, "src", every, true, local, result);
  result.dat = turn_text(dat, "dat", every, true, local, result);
  return result;
}

KrlFrameTurn turn_krl_frames(std::string_view src, std::string_view dat,
                             const std::map<toolpath::FrameSite, KrlFrameEdit>& edits,
                             char tool_direction) {
  const Eigen::Vector3d local =
      tool_direction == 'z' ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
  KrlFrameTurn result;
  for (const bool in_dat : {false, true}) {
    const TurnAt at = [&](int line, int ordinal) -> std::optional<KrlFrameEdit> {
      const auto it = edits.find(toolpath::FrameSite{in_dat, line, ordinal});
      return it == edits.end() ? std::nullopt : std::optional<KrlFrameEdit>(it->second);
    };
    (in_dat ? result.dat : result.src) =
        turn_text(in_dat ? dat : src, in_dat ? "dat" : "src", at, false, local, result);
  }
  return result;
}

}  // namespace robomill::io
