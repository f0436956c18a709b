// libFuzzer target for the KUKA KRL reader.
//
// The input is a .src program, optionally followed by "\n---\n" and its .dat.
// Contract under test: read_krl either returns a Program or throws
// robomill::InputError. Any other exception, a crash, a hang, a sanitizer
// report, a non-finite coordinate or a tool axis that is not a unit vector is
// a finding.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "program_checks.hpp"
#include "robomill/core/error.hpp"
#include "robomill/io/program_readers.hpp"
#include "robomill/toolpath/program.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  const std::size_t split = bytes.find("\n---\n");
  robomill::io::KrlOptions options;
  options.source_name = "fuzz.src";
  options.dat_name = "fuzz.dat";
  options.max_bytes = 1u << 20;
  options.max_executed_statements = 20'000;  // keep each run fast; the bound itself is tested
  if (split != std::string_view::npos)
    options.dat_text = std::string(bytes.substr(split + 5));
  Eigen::Isometry3d base = Eigen::Isometry3d::Identity();
  base.translation() = Eigen::Vector3d(0.5, -0.25, 0.1);
  base.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  options.bases[1] = base;
  options.tool_direction = (size % 2 == 0) ? 'x' : 'z';
  try {
    robomill::fuzz::check_program(robomill::io::read_krl(bytes.substr(0, split), options), false);
  } catch (const robomill::InputError&) {
    // Refused with a message: the expected outcome for most inputs.
  }
  return 0;
}
