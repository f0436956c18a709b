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

#include "program_checks.hpp"
#include "robomill/core/error.hpp"
#include "robomill/io/program_readers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  robomill::io::GcodeOptions options;
  options.source_name = "fuzz.nc";
  options.max_bytes = 1u << 16;
  options.work_offsets_m[2] = Eigen::Vector3d(0.1, 0.05, -0.01);
  options.home_z_m = 0.3;
  try {
    robomill::fuzz::check_program(robomill::io::read_gcode(bytes, options), true);
  } catch (const robomill::InputError&) {
    // Refused with a message: the expected outcome for most inputs.
  }
  return 0;
}
