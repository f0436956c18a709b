// libFuzzer target for the G-code reader (io/program_readers.hpp).
//
// Contract under test: whatever bytes a program holds, read_gcode either
// returns a Program or throws robomill::InputError. Any other exception, a
// crash, a hang, a sanitizer report or unbounded memory is a finding, and so
// is an accepted program with a non-finite coordinate, a move that does not
// start where the previous one ended, or a tool axis that is not a unit
// vector.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "robomill/core/error.hpp"
#include "robomill/io/program_readers.hpp"

namespace {

bool finite(const Eigen::Vector3d& v) {
  return v.allFinite();
}

bool unit(const Eigen::Vector3d& v) {
  return std::abs(v.norm() - 1.0) <= 1e-9;
}

void check(const robomill::toolpath::Program& program) {
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  for (const robomill::toolpath::Move& move : program.moves) {
    if (!finite(move.start_m) || !finite(move.end_m) || !finite(move.centre_m) ||
        !std::isfinite(move.sweep_rad) || !std::isfinite(move.feed_m_s) ||
        !std::isfinite(move.spindle_rad_s) || !std::isfinite(move.dwell_s))
      __builtin_trap();
    if (!unit(move.axis_start) || !unit(move.axis_end))
      __builtin_trap();
    if (move.kind == robomill::toolpath::MotionKind::arc && !unit(move.normal))
      __builtin_trap();
    if (move.feed_m_s < 0.0 || move.dwell_s < 0.0 || move.line < 1)
      __builtin_trap();
    if ((move.start_m - previous).norm() > 1e-9 * (1.0 + previous.norm()))
      __builtin_trap();
    previous = move.end_m;
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  robomill::io::GcodeOptions options;
  options.source_name = "fuzz.nc";
  options.max_bytes = 1u << 16;
  options.work_offsets_m[2] = Eigen::Vector3d(0.1, 0.05, -0.01);
  options.home_z_m = 0.3;
  try {
    check(robomill::io::read_gcode(bytes, options));
  } catch (const robomill::InputError&) {
    // Refused with a message: the expected outcome for most inputs.
  }
  return 0;
}
