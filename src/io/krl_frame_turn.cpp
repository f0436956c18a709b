// A KRL program's frames turned about the tool axis (io/krl_frame_turn.hpp).

#include "robomill/io/krl_frame_turn.hpp"

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <map>
#include <optional>

#include "krl_aggregates.hpp"
#include "krl_rotation.hpp"
#include "program_text.hpp"
#include "robomill/core/constants.hpp"

namespace robomill::io {
namespace {

namespace ka = krl_aggregates;

// KUKA's A, B, C (deg): R = Rz(A) Ry(B) Rx(C).
using krl_rotation::rotation_abc;

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

// The edit of the Cartesian aggregate at (line, ordinal): nullopt keeps it.
using TurnAt = std::function<std::optional<KrlFrameEdit>(int line, int ordinal)>;

// Turns the aggregates of one text; `file` names it in refusals. `all`:
// every frame is to turn, so one without all of A, B, C is refused (one
// without any inherits the turned frame before it).
std::string turn_text(std::string_view text, const std::string& file, const TurnAt& turn_at,
                      bool all, const Eigen::Vector3d& local_axis, KrlFrameTurn& result) {
  return ka::rewrite(text, [&](const ka::Aggregate& a) -> std::optional<std::string> {
    if (a.ordinal < 0 || a.placement)
      return std::nullopt;
    const std::optional<KrlFrameEdit> edit = turn_at(a.line, a.ordinal);
    const ka::Item* abc[3] = {nullptr, nullptr, nullptr};
    for (const ka::Item& item : a.items)
      for (int k = 0; k < 3; ++k)
        if (item.name == std::string(1, "ABC"[k]))
          abc[k] = &item;
    const int found = (abc[0] != nullptr) + (abc[1] != nullptr) + (abc[2] != nullptr);
    if (!edit || (all && found == 0))
      return std::nullopt;
    if (found < 3 && !edit->in_force_abc_deg) {
      result.refused.push_back(
          {file, a.line,
           "a partial orientation (not all of A, B, C): the frame before sets the rest"});
      return std::nullopt;
    }
    std::array<double, 3> values = edit->in_force_abc_deg.value_or(std::array<double, 3>{});
    for (int k = 0; k < 3; ++k) {
      if (!abc[k])
        continue;
      const auto v = program_text::parse_number(
          a.inner.substr(abc[k]->value_begin, abc[k]->value_end - abc[k]->value_begin));
      if (!v) {
        result.refused.push_back({file, a.line, "A, B or C written as an expression"});
        return std::nullopt;
      }
      values[static_cast<std::size_t>(k)] = *v;
    }
    const std::array<double, 3> turned =
        abc_of(rotation_abc(values[0], values[1], values[2]) *
               Eigen::AngleAxisd(-edit->turn_rad, local_axis).toRotationMatrix());
    ++result.frames;
    return ka::with_values(a.inner, a.items,
                           {{"A", turned[0]}, {"B", turned[1]}, {"C", turned[2]}});
  });
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
