// `robomill listen JOB`: the chatter verdict of recorded cuts (issue 22,
// docs/monitoring.md), computed by analysis/recording_verdicts.hpp (each
// recording read by its reader and judged by the monitoring module's
// detector, the advice, and with a stability: section the lobes and the
// model's prediction at each recorded cut), written as spectrum.csv,
// spectrogram.csv, recordings.csv, sld.csv and summary.json.

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <variant>

#include "robomill/analysis/recording_verdicts.hpp"
#include "robomill/analysis/stability_diagram.hpp"
#include "robomill/commands/commands.hpp"
#include "robomill/core/constants.hpp"

namespace robomill::commands {
namespace {

nlohmann::json finite_or_null(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

nlohmann::json verdict_json(monitoring::Verdict verdict) {
  switch (verdict) {
    case monitoring::Verdict::chatter:
      return true;
    case monitoring::Verdict::stable:
      return false;
    default:
      return "unknown";
  }
}

// The PSD column's name with the signal's unit squared per Hz.
std::string psd_column(monitoring::SignalKind kind) {
  using monitoring::SignalKind;
  switch (kind) {
    case SignalKind::sound:
      return "psd_Pa2_per_Hz";
    case SignalKind::acceleration:
      return "psd_m2_per_s4_per_Hz";
    case SignalKind::velocity:
      return "psd_m2_per_s2_per_Hz";
    case SignalKind::displacement:
      return "psd_m2_per_Hz";
    case SignalKind::force:
      return "psd_N2_per_Hz";
  }
  return "psd_per_Hz";
}

// The spectrogram's frequencies thinned to at most `limit` bands (the mean
// power of consecutive bins), so spectrogram.csv stays a readable size.
constexpr std::size_t kSpectrogramBands = 256;

// The PSD columns' name: the signal's unit when every recording has the same
// kind, SI otherwise.
std::string power_column(const std::vector<analysis::RecordingVerdict>& judged) {
  bool same_kind = true;
  for (const analysis::RecordingVerdict& j : judged)
    same_kind = same_kind && j.signal.kind == judged.front().signal.kind;
  return same_kind ? psd_column(judged.front().signal.kind) : std::string("psd_SI2_per_Hz");
}

// spectrum.csv: every recording's Welch PSD with each bin's cause;
// spectrogram.csv: its short-time spectra thinned to kSpectrogramBands bands
// and each frame's chatter line fraction (the verdict's indicator).
void add_spectrum_tables(const std::vector<analysis::RecordingVerdict>& judged,
                         const std::string& power, CommandResult& result) {
  io::CsvTable spectrum({"freq_hz", power, "cause", "recording"});
  io::CsvTable spectrogram({"t_s", "freq_hz", power, "chatter_fraction", "recording"});
  for (std::size_t r = 0; r < judged.size(); ++r) {
    const monitoring::RecordingAnalysis& a = judged[r].analysis;
    const double index = static_cast<double>(r + 1);
    for (std::size_t k = 0; k < a.frequency_hz.size(); ++k)
      spectrum.add_cells({a.frequency_hz[k], a.psd[k],
                          std::string(monitoring::line_cause_name(a.cause[k])), index});
    const std::size_t bins = a.spectrogram_frequency_hz.size();
    const std::size_t group =
        std::max<std::size_t>(1, (bins + kSpectrogramBands - 1) / kSpectrogramBands);
    for (std::size_t i = 0; i < a.spectrogram_time_s.size(); ++i) {
      const double share = i < a.frame_chatter_fraction.size() ? a.frame_chatter_fraction[i] : 0.0;
      for (std::size_t b = 0; b < bins; b += group) {
        const std::size_t end = std::min(bins, b + group);
        double sum = 0.0;
        for (std::size_t k = b; k < end; ++k)
          sum += a.spectrogram_psd[i * bins + k];
        spectrogram.add_row(
            {a.spectrogram_time_s[i],
             0.5 * (a.spectrogram_frequency_hz[b] + a.spectrogram_frequency_hz[end - 1]),
             sum / static_cast<double>(end - b), share, index});
      }
    }
  }
  result.tables.emplace_back("spectrum", std::move(spectrum));
  result.tables.emplace_back("spectrogram", std::move(spectrogram));
}

// recordings.csv (a job that lists its recordings): one row per recording.
io::CsvTable recordings_table(const std::vector<analysis::RecordingVerdict>& judged) {
  io::CsvTable table({"recording", "file", "note", "spindle_rpm_commanded", "spindle_rpm_measured",
                      "depth_mm", "chatter", "chatter_freq_hz", "chatter_energy_fraction",
                      "chatter_line_fraction", "once_per_revolution_variance", "onset_s",
                      "recommended_spindle_rpm", "model_depth_limit_mm", "model_chatter_freq_hz",
                      "reason"});
  for (std::size_t r = 0; r < judged.size(); ++r) {
    const analysis::RecordingVerdict& j = judged[r];
    const monitoring::RecordingAnalysis& a = j.analysis;
    std::string reason = a.reason;
    std::replace(reason.begin(), reason.end(), ',', ';');
    std::string note = j.recording.note;
    std::replace(note.begin(), note.end(), ',', ';');
    const auto or_nan = [](bool has, double v) { return has ? v : std::nan(""); };
    const auto cell = [](double v) -> io::CsvTable::Cell {
      if (std::isfinite(v))
        return v;
      return std::string("");
    };
    table.add_cells(
        {static_cast<double>(r + 1), j.recording.file.filename().string(), note,
         j.commanded_spindle_rad_s * 60.0 / kTwoPi, a.spindle_hz_measured * 60.0,
         cell(or_nan(j.depth_m.has_value(), j.depth_m.value_or(0.0) * 1e3)),
         std::string(monitoring::verdict_name(a.verdict)),
         cell(
             or_nan(a.verdict == monitoring::Verdict::chatter && a.chatter_hz > 0.0, a.chatter_hz)),
         a.chatter_energy_fraction, a.chatter_line_fraction, a.once_per_revolution_variance,
         cell(or_nan(a.onset_s.has_value(), a.onset_s.value_or(0.0))),
         cell(or_nan(!j.advice.empty(),
                     j.advice.empty() ? 0.0 : j.advice.front().spindle_hz * 60.0)),
         cell(or_nan(j.prediction.has_value(),
                     j.prediction ? j.prediction->depth_limit_m * 1e3 : 0.0)),
         cell(or_nan(j.prediction.has_value(), j.prediction ? j.prediction->chatter_hz : 0.0)),
         reason});
  }
  return table;
}

// summary.json: the first (or only) recording's keys at the top level, as
// DESIGN.md names them, and every recording under "recordings".
nlohmann::json listen_summary(const job::Job& job, const analysis::RecordingVerdicts& verdicts,
                              const nlohmann::json& list, const std::string& power,
                              const std::optional<CommandResult>& lobes, double elapsed_s) {
  nlohmann::json summary = {{"command", "listen"}};
  for (const auto& [key, value] : list.front().items())
    summary[key] = value;
  int chattering = 0, stable = 0, unknown = 0;
  for (const analysis::RecordingVerdict& j : verdicts.recordings) {
    chattering += j.analysis.verdict == monitoring::Verdict::chatter;
    stable += j.analysis.verdict == monitoring::Verdict::stable;
    unknown += j.analysis.verdict == monitoring::Verdict::unknown;
  }
  summary["recordings"] = list;
  summary["recordings_chatter"] = chattering;
  summary["recordings_stable"] = stable;
  summary["recordings_unknown"] = unknown;
  // The last recording's range (its basis is the same for every recording).
  const analysis::RecordingVerdict& last = verdicts.recordings.back();
  summary["advice_spindle_range_rpm"] = {last.advice_spindle_min_rad_s * 60.0 / kTwoPi,
                                         last.advice_spindle_max_rad_s * 60.0 / kTwoPi};
  summary["advice_spindle_range_basis"] = verdicts.advice_range_basis;
  summary["threshold"] = job.listen ? job.listen->detector.chatter_line_threshold
                                    : monitoring::ListenOptions{}.chatter_line_threshold;
  summary["psd_column"] = power;
  summary["model"] =
      lobes ? nlohmann::json("stability lobes of the job (sld.csv)") : nlohmann::json(nullptr);
  if (lobes)
    summary["model_method"] = lobes->summary.value("method", "");
  summary["elapsed_s"] = elapsed_s;
  return summary;
}

// The command's message: one line per recording with its verdict.
std::string listen_message(const std::vector<analysis::RecordingVerdict>& judged) {
  std::string message;
  for (const analysis::RecordingVerdict& j : judged) {
    const monitoring::RecordingAnalysis& a = j.analysis;
    std::string verdict;
    if (a.verdict == monitoring::Verdict::chatter) {
      verdict = fmt::format("CHATTER at {:.1f} Hz (line fraction {:.2f})", a.chatter_hz,
                            a.chatter_line_fraction);
      if (a.onset_s)
        verdict += fmt::format(" from {:.2f} s", *a.onset_s);
      if (!j.advice.empty()) {
        verdict += "; try";
        for (std::size_t i = 0; i < std::min<std::size_t>(3, j.advice.size()); ++i)
          verdict += fmt::format(" {:.0f}", j.advice[i].spindle_hz * 60.0);
        verdict += " rpm";
      }
    } else if (a.verdict == monitoring::Verdict::stable) {
      verdict = fmt::format("stable (chatter line fraction {:.2f})", a.chatter_line_fraction);
    } else {
      verdict = "unknown: " + a.reason;
    }
    if (a.engaged_start_s && a.engaged_end_s && a.verdict != monitoring::Verdict::unknown)
      verdict += fmt::format(" [judged {:.2f}-{:.2f} s, where the cut's comb stands]",
                             *a.engaged_start_s, *a.engaged_end_s);
    message += fmt::format("listen: {} ({:.2f} s, spindle {:.0f} rpm measured): {}\n",
                           j.recording.file.filename().string(), a.duration_s,
                           a.spindle_hz_measured * 60.0, verdict);
  }
  return message;
}

}  // namespace

// One recording's keys in summary.json (its "recordings" entries, and the
// first recording's at the top level).
nlohmann::json listen_recording_json(const analysis::RecordingVerdict& j) {
  const monitoring::RecordingAnalysis& a = j.analysis;
  nlohmann::json recommended = nlohmann::json::array(), ranked = nlohmann::json::array();
  for (const auto& s : j.advice) {
    recommended.push_back(s.spindle_hz * 60.0);
    ranked.push_back({{"spindle_rpm", s.spindle_hz * 60.0},
                      {"tooth_harmonic", s.harmonic},
                      {"tooth_freq_hz", s.spindle_hz * j.teeth}});
  }
  nlohmann::json out = {
      {"file", j.recording.file.filename().string()},
      {"source", j.signal.description},
      {"signal", monitoring::signal_kind_name(j.signal.kind)},
      {"unit", monitoring::signal_kind_unit(j.signal.kind)},
      {"chatter", verdict_json(a.verdict)},
      {"verdict", monitoring::verdict_name(a.verdict)},
      {"reason", a.reason},
      {"chatter_freq_hz", a.verdict == monitoring::Verdict::chatter && a.chatter_hz > 0.0
                              ? nlohmann::json(a.chatter_hz)
                              : nlohmann::json(nullptr)},
      {"strongest_nonharmonic_hz", finite_or_null(a.chatter_hz > 0.0 ? a.chatter_hz : NAN)},
      {"spindle_rpm_commanded", j.commanded_spindle_rad_s * 60.0 / kTwoPi},
      {"spindle_rpm_measured", a.spindle_hz_measured * 60.0},
      {"spindle_refined", a.spindle_refined},
      {"spindle_source", a.spindle_source},
      {"tachometer_pulses",
       j.tachometer ? nlohmann::json(j.tachometer->pulses) : nlohmann::json(nullptr)},
      {"tachometer_period_spread",
       j.tachometer ? nlohmann::json(j.tachometer->period_spread) : nlohmann::json(nullptr)},
      {"tooth_freq_hz", a.tooth_hz},
      {"teeth", j.teeth},
      {"chatter_energy_fraction", a.chatter_energy_fraction},
      {"forced_energy_fraction", a.forced_energy_fraction},
      {"ignored_energy_fraction", a.ignored_energy_fraction},
      {"floor_energy_fraction", a.floor_energy_fraction},
      {"chatter_line_fraction", a.chatter_line_fraction},
      {"once_per_revolution_variance", a.once_per_revolution_variance},
      {"once_per_tooth_variance", a.once_per_tooth_variance},
      {"chatter_growth_db_per_s", a.chatter_growth_db_per_s
                                      ? nlohmann::json(*a.chatter_growth_db_per_s)
                                      : nlohmann::json(nullptr)},
      {"onset_s", a.onset_s ? nlohmann::json(*a.onset_s) : nlohmann::json(nullptr)},
      {"engaged_start_s",
       a.engaged_start_s ? nlohmann::json(*a.engaged_start_s) : nlohmann::json(nullptr)},
      {"engaged_end_s",
       a.engaged_end_s ? nlohmann::json(*a.engaged_end_s) : nlohmann::json(nullptr)},
      {"clipped_fraction", a.clipped_fraction},
      {"duration_s", a.duration_s},
      {"sample_rate_hz", a.sample_rate_hz},
      {"resolution_hz", a.resolution_hz},
      {"recommended_spindle_rpm", recommended},
      {"advice", ranked},
      {"note", j.recording.note}};
  if (j.depth_m)
    out["depth_mm"] = *j.depth_m * 1e3;
  if (j.prediction) {
    nlohmann::json model = {{"depth_limit_mm", j.prediction->depth_limit_m * 1e3},
                            {"chatter_freq_hz", j.prediction->chatter_hz}};
    if (j.depth_m)
      model["chatter_predicted"] = *j.depth_m > j.prediction->depth_limit_m;
    if (a.verdict == monitoring::Verdict::chatter && a.chatter_hz > 0.0 &&
        j.prediction->chatter_hz > 0.0) {
      model["chatter_freq_mismatch_hz"] = a.chatter_hz - j.prediction->chatter_hz;
      model["chatter_freq_mismatch_pct"] = 100.0 * (a.chatter_hz / j.prediction->chatter_hz - 1.0);
    }
    out["model"] = std::move(model);
  }
  return out;
}

CommandResult compute_listen(const job::Job& job, int threads, const Progress& progress) {
  const auto start = std::chrono::steady_clock::now();
  const analysis::RecordingVerdicts verdicts = analysis::recording_verdicts(job, threads, progress);
  const std::vector<analysis::RecordingVerdict>& judged = verdicts.recordings;
  std::optional<CommandResult> lobes;  // what `stability` writes: sld.csv and its method
  if (verdicts.diagram)
    lobes = stability_result(job, *verdicts.diagram);

  CommandResult result;
  const std::string power = power_column(judged);
  add_spectrum_tables(judged, power, result);

  nlohmann::json list = nlohmann::json::array();
  for (const analysis::RecordingVerdict& j : judged)
    list.push_back(listen_recording_json(j));
  if (job.recordings_listed)
    result.tables.emplace_back("recordings", recordings_table(judged));
  if (lobes) {
    result.tables.emplace_back("sld", *lobes->table("sld"));
  }

  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.summary = listen_summary(job, verdicts, list, power, lobes, elapsed_s);
  result.message = listen_message(judged);
  return result;
}

}  // namespace robomill::commands
