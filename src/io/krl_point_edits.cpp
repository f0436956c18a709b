// The deflection compensation written into a KRL program (io/krl_point_edits.hpp).

#include "robomill/io/krl_point_edits.hpp"

#include <fmt/format.h>

#include <map>

#include "krl_aggregates.hpp"
#include "program_text.hpp"

namespace robomill::io {
namespace {

namespace ka = krl_aggregates;

// A point in the numbers of the base it is written in (mm).
Eigen::Vector3d in_base_mm(const toolpath::FrameSource& source, const Eigen::Vector3d& p_m) {
  return source.base_rotation.transpose() * (p_m - source.base_origin_m) / 1e-3;
}

std::vector<std::string_view> lines_of(std::string_view text) {
  std::vector<std::string_view> lines;
  std::size_t position = 0;
  while (position <= text.size()) {
    const std::size_t end = text.find('\n', position);
    if (end == std::string_view::npos) {
      lines.push_back(text.substr(position));
      break;
    }
    lines.push_back(text.substr(position, end + 1 - position));
    position = end + 1;
  }
  return lines;
}

}  // namespace

robot_path::WritableMoves krl_writable_moves(const toolpath::Program& program) {
  const std::size_t n = program.moves.size();
  robot_path::WritableMoves writable;
  writable.end.assign(n, 0);
  writable.points.assign(n, 0);
  writable.reason.assign(n, std::string());
  std::map<toolpath::FrameSite, int> ends_at;
  std::map<int, int> moves_on_line;
  if (program.first_frame)  // the program's first point is used too
    ++ends_at[program.first_frame->site];
  for (std::size_t m = 0; m < n; ++m) {
    ++moves_on_line[program.moves[m].line];
    if (m < program.frame_sources.size() && program.frame_sources[m])
      ++ends_at[program.frame_sources[m]->site];
  }
  for (std::size_t m = 0; m < n; ++m) {
    const toolpath::Move& move = program.moves[m];
    const auto& source = m < program.frame_sources.size() ? program.frame_sources[m] : std::nullopt;
    std::string& why = writable.reason[m];
    if (move.kind == toolpath::MotionKind::arc)
      why = "a CIRC: kept as programmed in a KRL program";
    else if (!source)
      why = "its end point is computed (a _REL move)";
    else if (!source->position_complete)
      why = "its point does not write all of X, Y and Z";
    else if (ends_at[source->site] > 1)
      why = fmt::format(
          "its point ({} line {}) is used more than once (a FOR loop over one point, a pose "
          "the program starts and ends at)",
          source->site.in_dat ? ".dat" : ".src", source->site.line);
    if (!why.empty())
      continue;
    writable.end[m] = 1;
    writable.points[m] = moves_on_line[move.line] == 1 &&
                         (move.axis_start - move.axis_end).norm() < 1e-9 &&
                         (move.tool_x_start - move.tool_x_end).norm() < 1e-9;
  }
  return writable;
}

KrlPointEdits write_krl_point_edits(std::string_view src, std::string_view dat,
                                    const toolpath::Program& program,
                                    const std::vector<robot_path::LineCorrection>& corrections,
                                    const std::vector<std::string>& comments) {
  KrlPointEdits result;
  // Per site, the correction that moves it; per .src line, what goes before.
  std::map<toolpath::FrameSite, std::size_t> at_site;
  for (std::size_t i = 0; i < corrections.size(); ++i) {
    const std::size_t m = corrections[i].move;
    const auto& source = m < program.frame_sources.size() ? program.frame_sources[m] : std::nullopt;
    if (!source || !source->position_complete || corrections[i].arc) {
      result.skipped.push_back({program.moves[m].line, "its end point cannot be written"});
      continue;
    }
    at_site[source->site] = i;
  }
  std::map<std::size_t, std::string> src_before, dat_after;  // 1-based lines
  auto edit_text = [&](std::string_view text, bool in_dat) {
    return ka::rewrite(text, [&](const ka::Aggregate& a) -> std::optional<std::string> {
      const auto it = at_site.find(toolpath::FrameSite{in_dat, a.line, a.ordinal});
      if (a.ordinal < 0 || it == at_site.end())
        return std::nullopt;
      const robot_path::LineCorrection& c = corrections[it->second];
      const toolpath::Move& move = program.moves[c.move];
      const toolpath::FrameSource& source = *program.frame_sources[c.move];
      // The end's numbers moved by the offset in the base.
      const Eigen::Vector3d offset_mm = source.base_rotation.transpose() * c.offset_m / 1e-3;
      std::vector<std::pair<std::string, double>> values;
      for (int k = 0; k < 3; ++k) {
        const std::string name(1, "XYZ"[k]);
        const auto item = std::find_if(a.items.begin(), a.items.end(),
                                       [&](const ka::Item& i) { return i.name == name; });
        const std::optional<double> v =
            item == a.items.end() ? std::nullopt
                                  : program_text::parse_number(a.inner.substr(
                                        item->value_begin, item->value_end - item->value_begin));
        if (!v) {
          result.skipped.push_back(
              {move.line, fmt::format("its point's {} is not a number ({} line {})", name,
                                      in_dat ? ".dat" : ".src", a.line)});
          return std::nullopt;
        }
        values.emplace_back(name, *v + offset_mm[k]);
      }
      // The comment (beside a .dat point, before an inline one's statement),
      // and the points inside the line before its statement.
      const std::string& comment = comments[it->second];
      std::string before = in_dat ? std::string() : "; " + comment + "\n";
      const std::size_t count = c.points.size();
      for (std::size_t k = 0; k < count; ++k) {
        const robot_path::CorrectionPoint& p = c.points[k];
        const Eigen::Vector3d at =
            in_base_mm(source, move.start_m + p.u * (move.end_m - move.start_m) + p.offset_m);
        before +=
            fmt::format("LIN {{X{},Y{},Z{}}} C_DIS ; {}, point {} of {}\n", ka::krl_value(at.x()),
                        ka::krl_value(at.y()), ka::krl_value(at.z()), comment, k + 1, count);
      }
      src_before[static_cast<std::size_t>(move.line)] += before;
      if (in_dat)
        dat_after[static_cast<std::size_t>(a.line)] = " ; " + comment;
      return ka::with_values(a.inner, a.items, values);
    });
  };
  const std::string src_edited = edit_text(src, false);
  const std::string dat_edited = edit_text(dat, true);
  // The inserted lines, in the text's own line ends.
  auto assemble = [](std::string_view text, const std::map<std::size_t, std::string>& before,
                     const std::map<std::size_t, std::string>& after) {
    const std::string_view newline =
        text.find("\r\n") != std::string_view::npos ? std::string_view("\r\n") : "\n";
    std::string out;
    std::size_t line = 1;
    for (std::string_view body : lines_of(text)) {
      if (const auto it = before.find(line); it != before.end())
        for (const char c : it->second)
          out += c == '\n' ? std::string(newline) : std::string(1, c);
      std::size_t content = body.size();
      while (content > 0 && (body[content - 1] == '\n' || body[content - 1] == '\r'))
        --content;
      out.append(body.substr(0, content));
      if (const auto it = after.find(line);
          it != after.end() && body.substr(0, content).find(';') == std::string_view::npos)
        out += it->second;
      out.append(body.substr(content));
      ++line;
    }
    return out;
  };
  result.src = assemble(src_edited, src_before, {});
  result.dat = assemble(dat_edited, {}, dat_after);
  return result;
}

}  // namespace robomill::io
