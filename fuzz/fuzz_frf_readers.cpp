// libFuzzer target for the measured-FRF readers (UFF58/58b and CSV).
//
// Contract under test: whatever bytes a file holds, parse_uff58 and
// parse_frf_csv either return FRFs or throw robomill::InputError. Any other
// exception, a crash, a hang, a sanitizer report or unbounded memory is a
// finding. Every UFF file that is accepted is also written back (ASCII and
// binary) and read again: the round trip must succeed and be bit-exact.

#include <bit>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "robomill/core/error.hpp"
#include "robomill/io/frf_csv.hpp"
#include "robomill/io/uff58.hpp"

namespace {

using robomill::io::UffFrf;

bool same_bits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

void check_round_trip(const std::vector<UffFrf>& frfs, robomill::io::UffEncoding encoding) {
  const std::vector<UffFrf> again =
      robomill::io::parse_uff58(robomill::io::format_uff58(frfs, encoding), "round-trip.uff");
  if (again.size() != frfs.size())
    __builtin_trap();
  for (std::size_t n = 0; n < frfs.size(); ++n) {
    const auto& a = frfs[n].frf;
    const auto& b = again[n].frf;
    if (a.frequency_hz.size() != b.frequency_hz.size() || a.kind != b.kind ||
        a.response_axis != b.response_axis || a.reference_axis != b.reference_axis)
      __builtin_trap();
    for (std::size_t i = 0; i < a.frequency_hz.size(); ++i) {
      if (!same_bits(a.frequency_hz[i], b.frequency_hz[i]) ||
          !same_bits(a.value[i].real(), b.value[i].real()) ||
          !same_bits(a.value[i].imag(), b.value[i].imag()))
        __builtin_trap();
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  try {
    const std::vector<UffFrf> frfs = robomill::io::parse_uff58(bytes, "fuzz.uff");
    // A failure here is a writer or reader bug, not a rejection: let it escape.
    check_round_trip(frfs, robomill::io::UffEncoding::ascii);
    check_round_trip(frfs, robomill::io::UffEncoding::binary);
  } catch (const robomill::InputError& error) {
    if (std::string_view(error.field()) == "round-trip.uff")
      __builtin_trap();
  }
  try {
    robomill::io::FrfCsvOptions options;
    options.scale_to_si = 1e-3;
    const robomill::dynamics::Frf frf =
        robomill::io::parse_frf_csv(std::string(bytes), "fuzz.csv", options);
    (void)frf;
  } catch (const robomill::InputError&) {
    // Rejected with a message: the expected outcome for most inputs.
  }
  return 0;
}
