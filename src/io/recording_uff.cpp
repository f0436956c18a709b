// UFF58 time records (function type 1) as recordings: io/uff58's reader
// parses the file (ASCII or binary 58b, dataset 164 units); `channel` picks
// the record (1-based), 0 averages records of equal rate and length.

#include <cmath>
#include <string>
#include <vector>

#include "recording_detail.hpp"
#include "robomill/io/recording.hpp"
#include "robomill/io/uff58.hpp"

namespace robomill::io {
namespace recording_detail {

std::unique_ptr<monitoring::SignalSource> open_uff(const RecordingSpec& spec) {
  std::vector<UffTimeRecord> records;
  try {
    records = read_uff58_time_records(spec.file);
  } catch (const InputError& error) {
    // The UFF reader names the file as its field and the file's line; say
    // both in the message, under the job's field and line.
    const std::string where =
        file_name(spec) + (error.line() > 0 ? " line " + std::to_string(error.line()) : "");
    std::string why = error.what();
    if (const auto colon = why.find(": "); colon != std::string::npos)
      why.erase(0, colon + 2);
    fail(spec, "file", where + ": " + why);
  }
  const int count = static_cast<int>(records.size());
  if (spec.channel > count)
    fail(spec, "channel",
         file_name(spec) + " has " + std::to_string(count) + " time record" +
             (count == 1 ? "" : "s") + ", got channel " + std::to_string(spec.channel));
  std::vector<double> samples;
  const UffTimeRecord* chosen = nullptr;
  if (spec.channel == 0) {
    chosen = &records.front();
    samples.assign(chosen->value.size(), 0.0);
    for (const UffTimeRecord& record : records) {
      if (record.value.size() != chosen->value.size() ||
          std::abs(record.dt_s - chosen->dt_s) > 1e-9 * chosen->dt_s)
        fail(spec, "channel",
             file_name(spec) +
                 ": the mean of all records needs records of the same length "
                 "and rate; record at line " +
                 std::to_string(record.line) + " differs from the first");
      for (std::size_t i = 0; i < samples.size(); ++i)
        samples[i] += record.value[i] / static_cast<double>(count);
    }
  } else {
    chosen = &records[static_cast<std::size_t>(spec.channel - 1)];
    samples = std::move(records[static_cast<std::size_t>(spec.channel - 1)].value);
  }
  const double rate = 1.0 / chosen->dt_s;
  if (!std::isfinite(rate))
    fail(spec, "file",
         file_name(spec) + ": time increment " + number(chosen->dt_s) + " s gives no sample rate");
  check_rate_agrees(spec, rate);
  std::string description =
      file_name(spec) + ", " +
      (spec.channel == 0
           ? "mean of " + std::to_string(count) + " records"
           : "record " + std::to_string(spec.channel) + " of " + std::to_string(count)) +
      (chosen->label.empty() || chosen->label == "NONE" || spec.channel == 0
           ? ""
           : " ('" + chosen->label + "')") +
      (chosen->unit.empty() ? "" : ", unit " + chosen->unit) +
      (chosen->unit_is_si ? "" : " (no SI conversion known; scaled by `scale` only)");
  return memory_source(spec, std::move(samples), rate, chosen->start_s, std::move(description));
}

}  // namespace recording_detail
}  // namespace robomill::io
