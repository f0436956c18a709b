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

#include "program_checks.hpp"
#include "robomill/core/error.hpp"
#include "robomill/io/program_readers.hpp"
#include "robomill/toolpath/program.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  robomill::io::AptOptions options;
  options.source_name = "fuzz.cl";
  options.max_bytes = 1u << 20;
  try {
    robomill::fuzz::check_program(robomill::io::read_apt(text, options), false);
  } catch (const robomill::InputError&) {
    // Refused with a message: the expected outcome for most inputs.
  }
  return 0;
}
