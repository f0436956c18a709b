// libFuzzer target for the job parser (DESIGN.md §3).
//
// Contract under test: whatever bytes a job file holds, parse_job either
// returns a Job or throws robomill::InputError. Any other exception, a crash,
// a hang, or a sanitizer report (ASan, UBSan) is a finding.
//
// Lines of the form `#set key.path=value` in the input (YAML comments, so the
// document itself is unaffected) are also fed through parse_override and
// applied as --set overrides, which fuzzes the override path as well.

#include <cstddef>
#include <cstdint>
#include <string_view>
#include <vector>

#include "robomill/core/error.hpp"
#include "robomill/job/job.hpp"

namespace {

std::vector<robomill::job::Override> overrides_in(std::string_view text) {
  constexpr std::string_view kPrefix = "#set ";
  std::vector<robomill::job::Override> overrides;
  std::size_t position = 0;
  while (position < text.size() && overrides.size() < 8) {
    std::size_t end = text.find('\n', position);
    if (end == std::string_view::npos)
      end = text.size();
    const std::string_view line = text.substr(position, end - position);
    if (line.substr(0, kPrefix.size()) == kPrefix) {
      try {
        overrides.push_back(robomill::job::parse_override(line.substr(kPrefix.size())));
      } catch (const robomill::InputError&) {
        // A malformed assignment is a legitimate rejection.
      }
    }
    position = end + 1;
  }
  return overrides;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    const robomill::job::Job job = robomill::job::parse_job(text, "fuzz.yaml", overrides_in(text));
    (void)job;
  } catch (const robomill::InputError&) {
    // Rejected with a message: the expected outcome for most inputs.
  }
  return 0;
}
