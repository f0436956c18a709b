// libFuzzer target for the APT / CL reader.
//
// Contract under test: whatever bytes a CL file holds, read_apt either returns
// a Program or throws robomill::InputError. Any other exception, a crash, a
// hang, a sanitizer report, a non-finite coordinate or a tool axis that is not
// a unit vector is a finding.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "robomill/core/error.hpp"
#include "robomill/io/program_readers.hpp"
#include "robomill/toolpath/program.hpp"

namespace {

bool finite(const Eigen::Vector3d& v) {
  return v.allFinite();
}
bool unit(const Eigen::Vector3d& v) {
  return v.allFinite() && std::abs(v.norm() - 1.0) < 1e-9;
}

void check(const robomill::toolpath::Program& program) {
  for (const auto& move : program.moves) {
    if (!finite(move.start_m) || !finite(move.end_m) || !finite(move.centre_m) ||
        !std::isfinite(move.sweep_rad) || !std::isfinite(move.feed_m_s) ||
        !std::isfinite(move.spindle_rad_s) || !std::isfinite(move.dwell_s) || move.feed_m_s < 0.0)
      __builtin_trap();
    if (!unit(move.axis_start) || !unit(move.axis_end))
      __builtin_trap();
    if (move.kind == robomill::toolpath::MotionKind::arc && !unit(move.normal))
      __builtin_trap();
    if (move.line < 1 || static_cast<std::size_t>(move.line) > program.line_count)
      __builtin_trap();
  }
  for (const auto& call : program.tool_calls)
    if ((call.diameter_m && !std::isfinite(*call.diameter_m)) ||
        (call.corner_radius_m && !std::isfinite(*call.corner_radius_m)))
      __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  robomill::io::AptOptions options;
  options.source_name = "fuzz.cl";
  options.max_bytes = 1u << 20;
  try {
    check(robomill::io::read_apt(text, options));
  } catch (const robomill::InputError&) {
    // Refused with a message: the expected outcome for most inputs.
  }
  return 0;
}
