// `robomill listen JOB`: the chatter verdict of recorded cuts (issue 22,
// docs/monitoring.md). Each recording is read in blocks by its reader
// (io/recording.hpp) and judged by the monitoring module's detector; the
// advice puts a tooth-passing harmonic on the chatter frequency, and when the
// job also describes the structure (a stability: section with dynamics or a
// robot), the recorded cuts are drawn on the predicted lobes and the model's
// chatter frequency is compared with the recorded one.

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <optional>
#include <variant>

#include "robomill/analysis/stability_diagram.hpp"
#include "robomill/commands/commands.hpp"
#include "robomill/core/error.hpp"
#include "robomill/io/recording.hpp"
#include "robomill/monitoring/recording_analysis.hpp"

namespace robomill::commands {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// The spindle range the advice may recommend (rad/s): listen.spindle_range,
// else the advise scan's, else the stability diagram's, else half to one and
// a half times the commanded speed.
std::pair<double, double> advice_range(const job::Job& job, double commanded_rad_s,
                                       std::string& basis) {
  if (job.listen && job.listen->spindle_range_rad_s) {
    basis = "listen.spindle_range";
    return *job.listen->spindle_range_rad_s;
  }
  if (job.advise && job.advise->limits.speed_max_rad_s > job.advise->limits.speed_min_rad_s) {
    basis = "advise.speeds";
    return {job.advise->limits.speed_min_rad_s, job.advise->limits.speed_max_rad_s};
  }
  if (job.stability && job.stability->speed_to_rad_s > job.stability->speed_from_rad_s) {
    basis = "stability.speeds";
    return {job.stability->speed_from_rad_s, job.stability->speed_to_rad_s};
  }
  basis = "0.5-1.5 x the commanded speed";
  return {0.5 * commanded_rad_s, 1.5 * commanded_rad_s};
}

int listen_teeth(const job::Job& job) {
  if (job.listen && job.listen->teeth)
    return *job.listen->teeth;
  if (job.tool)
    return job.tool->teeth;
  throw InputError("listen.teeth", 0,
                   "the tooth count is needed for the tooth-passing comb: give the job a tool: "
                   "section or listen.teeth (1 for a single insert)");
}

monitoring::ListenOptions detector_options(const job::Job& job, const io::RecordingSpec& spec,
                                           double commanded_hz, int teeth) {
  monitoring::ListenOptions options;
  options.commanded_spindle_hz = commanded_hz;
  options.teeth = teeth;
  options.ignore = spec.ignore;
  if (job.listen) {
    const job::ListenSettings& s = *job.listen;
    options.spindle_search_fraction = s.spindle_search_fraction;
    options.chatter_energy_threshold = s.chatter_energy_threshold;
    options.detect_mains = s.detect_mains;
    options.detect_steady_lines = s.detect_steady_lines;
    options.band_low_hz = s.band_low_hz;
    options.band_high_hz = s.band_high_hz;
    options.segment_s = s.segment_s;
  }
  return options;
}

// The predicted limit and chatter frequency at a spindle speed, linear
// between the diagram's speeds (sorted); nullopt outside the diagram or where
// a speed has no finite limit.
struct Prediction {
  double depth_limit_m = 0.0;
  double chatter_hz = 0.0;
};
std::optional<Prediction> predicted_at(const std::vector<analysis::StabilityLimit>& limits,
                                       double spindle_rad_s) {
  for (std::size_t i = 1; i < limits.size(); ++i) {
    const analysis::StabilityLimit &a = limits[i - 1], &b = limits[i];
    if (!(spindle_rad_s >= std::min(a.spindle_rad_s, b.spindle_rad_s) &&
          spindle_rad_s <= std::max(a.spindle_rad_s, b.spindle_rad_s)) ||
        a.spindle_rad_s == b.spindle_rad_s)
      continue;
    const double w = (spindle_rad_s - a.spindle_rad_s) / (b.spindle_rad_s - a.spindle_rad_s);
    Prediction p{(1.0 - w) * a.depth_limit_m + w * b.depth_limit_m,
                 (1.0 - w) * a.chatter_frequency_hz + w * b.chatter_frequency_hz};
    if (!std::isfinite(p.depth_limit_m) || !std::isfinite(p.chatter_hz))
      return std::nullopt;
    return p;
  }
  return std::nullopt;
}

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

struct Judged {
  const io::RecordingSpec* spec = nullptr;
  monitoring::RecordingAnalysis analysis;
  monitoring::SignalInfo info;
  double commanded_rad_s = 0.0;
  std::optional<double> depth_m;
  std::vector<monitoring::SpindleSuggestion> advice;
  std::optional<Prediction> model;
};

nlohmann::json recording_json(const Judged& j, int teeth) {
  const monitoring::RecordingAnalysis& a = j.analysis;
  nlohmann::json recommended = nlohmann::json::array(), ranked = nlohmann::json::array();
  for (const auto& s : j.advice) {
    recommended.push_back(s.spindle_hz * 60.0);
    ranked.push_back({{"spindle_rpm", s.spindle_hz * 60.0},
                      {"tooth_harmonic", s.harmonic},
                      {"tooth_freq_hz", s.spindle_hz * teeth}});
  }
  nlohmann::json out = {
      {"file", j.spec->file.filename().string()},
      {"source", j.info.description},
      {"signal", monitoring::signal_kind_name(j.info.kind)},
      {"unit", monitoring::signal_kind_unit(j.info.kind)},
      {"chatter", verdict_json(a.verdict)},
      {"verdict", monitoring::verdict_name(a.verdict)},
      {"reason", a.reason},
      {"chatter_freq_hz", a.verdict == monitoring::Verdict::chatter && a.chatter_hz > 0.0
                              ? nlohmann::json(a.chatter_hz)
                              : nlohmann::json(nullptr)},
      {"strongest_nonharmonic_hz", finite_or_null(a.chatter_hz > 0.0 ? a.chatter_hz : NAN)},
      {"spindle_rpm_commanded", j.commanded_rad_s * 60.0 / kTwoPi},
      {"spindle_rpm_measured", a.spindle_hz_measured * 60.0},
      {"spindle_refined", a.spindle_refined},
      {"tooth_freq_hz", a.tooth_hz},
      {"teeth", teeth},
      {"chatter_energy_fraction", a.chatter_energy_fraction},
      {"forced_energy_fraction", a.forced_energy_fraction},
      {"ignored_energy_fraction", a.ignored_energy_fraction},
      {"floor_energy_fraction", a.floor_energy_fraction},
      {"onset_s", a.onset_s ? nlohmann::json(*a.onset_s) : nlohmann::json(nullptr)},
      {"clipped_fraction", a.clipped_fraction},
      {"duration_s", a.duration_s},
      {"sample_rate_hz", a.sample_rate_hz},
      {"resolution_hz", a.resolution_hz},
      {"recommended_spindle_rpm", recommended},
      {"advice", ranked},
      {"note", j.spec->note}};
  if (j.depth_m)
    out["depth_mm"] = *j.depth_m * 1e3;
  if (j.model) {
    nlohmann::json model = {{"depth_limit_mm", j.model->depth_limit_m * 1e3},
                            {"chatter_freq_hz", j.model->chatter_hz}};
    if (j.depth_m)
      model["chatter_predicted"] = *j.depth_m > j.model->depth_limit_m;
    if (a.verdict == monitoring::Verdict::chatter && a.chatter_hz > 0.0 &&
        j.model->chatter_hz > 0.0) {
      model["chatter_freq_mismatch_hz"] = a.chatter_hz - j.model->chatter_hz;
      model["chatter_freq_mismatch_pct"] = 100.0 * (a.chatter_hz / j.model->chatter_hz - 1.0);
    }
    out["model"] = std::move(model);
  }
  return out;
}

// The advice's spindle range (rad/s) and where it comes from: the last
// recording's (advice_range), reported in summary.json.
struct AdviceRange {
  std::pair<double, double> rad_s{0.0, 0.0};
  std::string basis;
};

// One recording judged: read and analysed (its progress bar staged as
// "listen i/n" when there are several), the advice for a chatter verdict,
// and the model's prediction at the measured speed when there is a diagram.
Judged judge_recording(const job::Job& job, std::size_t r, int teeth,
                       const std::optional<analysis::StabilityDiagram>& diagram,
                       const Progress& progress, AdviceRange& range) {
  const io::RecordingSpec& spec = job.recordings[r];
  Judged j;
  j.spec = &spec;
  j.commanded_rad_s = spec.spindle_rad_s ? *spec.spindle_rad_s : job.process->spindle_rad_s;
  j.depth_m = spec.depth_m;
  if (!j.depth_m && job.process && !job.recordings_listed)
    j.depth_m = job.process->axial_depth_m;
  const double commanded_hz = j.commanded_rad_s / kTwoPi;
  monitoring::ListenOptions options = detector_options(job, spec, commanded_hz, teeth);
  const std::string stage = job.recordings.size() > 1
                                ? fmt::format("listen {}/{}", r + 1, job.recordings.size())
                                : std::string("listen");
  const auto bar = [&](double fraction) {
    if (progress)
      progress(stage, fraction);
  };
  options.progress = bar;
  const std::unique_ptr<monitoring::SignalSource> source = io::open_recording(spec);
  j.info = source->info();
  j.analysis = monitoring::analyze_recording(*source, options);
  bar(1.0);
  range.rad_s = advice_range(job, j.commanded_rad_s, range.basis);
  if (j.analysis.verdict == monitoring::Verdict::chatter && j.analysis.chatter_hz > 0.0)
    j.advice = monitoring::suggest_spindle_speeds(
        j.analysis.chatter_hz, teeth, range.rad_s.first / kTwoPi, range.rad_s.second / kTwoPi);
  if (diagram)
    j.model = predicted_at(diagram->primary(), j.analysis.spindle_hz_measured * kTwoPi);
  return j;
}

// The PSD columns' name: the signal's unit when every recording has the same
// kind, SI otherwise.
std::string power_column(const std::vector<Judged>& judged) {
  bool same_kind = true;
  for (const Judged& j : judged)
    same_kind = same_kind && j.info.kind == judged.front().info.kind;
  return same_kind ? psd_column(judged.front().info.kind) : std::string("psd_SI2_per_Hz");
}

// spectrum.csv: every recording's Welch PSD with each bin's cause;
// spectrogram.csv: its short-time spectra thinned to kSpectrogramBands bands
// and each frame's chatter share.
void add_spectrum_tables(const std::vector<Judged>& judged, const std::string& power,
                         CommandResult& result) {
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
io::CsvTable recordings_table(const std::vector<Judged>& judged) {
  io::CsvTable table({"recording", "file", "note", "spindle_rpm_commanded", "spindle_rpm_measured",
                      "depth_mm", "chatter", "chatter_freq_hz", "chatter_energy_fraction",
                      "onset_s", "recommended_spindle_rpm", "model_depth_limit_mm",
                      "model_chatter_freq_hz", "reason"});
  for (std::size_t r = 0; r < judged.size(); ++r) {
    const Judged& j = judged[r];
    const monitoring::RecordingAnalysis& a = j.analysis;
    std::string reason = a.reason;
    std::replace(reason.begin(), reason.end(), ',', ';');
    std::string note = j.spec->note;
    std::replace(note.begin(), note.end(), ',', ';');
    const auto or_nan = [](bool has, double v) { return has ? v : std::nan(""); };
    const auto cell = [](double v) -> io::CsvTable::Cell {
      if (std::isfinite(v))
        return v;
      return std::string("");
    };
    table.add_cells(
        {static_cast<double>(r + 1), j.spec->file.filename().string(), note,
         j.commanded_rad_s * 60.0 / kTwoPi, a.spindle_hz_measured * 60.0,
         cell(or_nan(j.depth_m.has_value(), j.depth_m.value_or(0.0) * 1e3)),
         std::string(monitoring::verdict_name(a.verdict)),
         cell(
             or_nan(a.verdict == monitoring::Verdict::chatter && a.chatter_hz > 0.0, a.chatter_hz)),
         a.chatter_energy_fraction, cell(or_nan(a.onset_s.has_value(), a.onset_s.value_or(0.0))),
         cell(or_nan(!j.advice.empty(),
                     j.advice.empty() ? 0.0 : j.advice.front().spindle_hz * 60.0)),
         cell(or_nan(j.model.has_value(), j.model ? j.model->depth_limit_m * 1e3 : 0.0)),
         cell(or_nan(j.model.has_value(), j.model ? j.model->chatter_hz : 0.0)), reason});
  }
  return table;
}

// summary.json: the first (or only) recording's keys at the top level, as
// DESIGN.md names them, and every recording under "recordings".
nlohmann::json listen_summary(const job::Job& job, const std::vector<Judged>& judged,
                              const nlohmann::json& list, const AdviceRange& range,
                              const std::string& power, const std::optional<CommandResult>& lobes,
                              double elapsed_s) {
  nlohmann::json summary = {{"command", "listen"}};
  for (const auto& [key, value] : list.front().items())
    summary[key] = value;
  int chattering = 0, stable = 0, unknown = 0;
  for (const Judged& j : judged) {
    chattering += j.analysis.verdict == monitoring::Verdict::chatter;
    stable += j.analysis.verdict == monitoring::Verdict::stable;
    unknown += j.analysis.verdict == monitoring::Verdict::unknown;
  }
  summary["recordings"] = list;
  summary["recordings_chatter"] = chattering;
  summary["recordings_stable"] = stable;
  summary["recordings_unknown"] = unknown;
  summary["advice_spindle_range_rpm"] = {range.rad_s.first * 60.0 / kTwoPi,
                                         range.rad_s.second * 60.0 / kTwoPi};
  summary["advice_spindle_range_basis"] = range.basis;
  summary["threshold"] = job.listen ? job.listen->chatter_energy_threshold : 0.5;
  summary["psd_column"] = power;
  summary["model"] =
      lobes ? nlohmann::json("stability lobes of the job (sld.csv)") : nlohmann::json(nullptr);
  if (lobes)
    summary["model_method"] = lobes->summary.value("method", "");
  summary["elapsed_s"] = elapsed_s;
  return summary;
}

// The command's message: one line per recording with its verdict.
std::string listen_message(const std::vector<Judged>& judged) {
  std::string message;
  for (const Judged& j : judged) {
    const monitoring::RecordingAnalysis& a = j.analysis;
    std::string verdict;
    if (a.verdict == monitoring::Verdict::chatter) {
      verdict = fmt::format("CHATTER at {:.1f} Hz (share {:.2f})", a.chatter_hz,
                            a.chatter_energy_fraction);
      if (a.onset_s)
        verdict += fmt::format(" from {:.2f} s", *a.onset_s);
      if (!j.advice.empty()) {
        verdict += "; try";
        for (std::size_t i = 0; i < std::min<std::size_t>(3, j.advice.size()); ++i)
          verdict += fmt::format(" {:.0f}", j.advice[i].spindle_hz * 60.0);
        verdict += " rpm";
      }
    } else if (a.verdict == monitoring::Verdict::stable) {
      verdict = fmt::format("stable (chatter share {:.2f})", a.chatter_energy_fraction);
    } else {
      verdict = "unknown: " + a.reason;
    }
    message += fmt::format("listen: {} ({:.2f} s, spindle {:.0f} rpm measured): {}\n",
                           j.spec->file.filename().string(), a.duration_s,
                           a.spindle_hz_measured * 60.0, verdict);
  }
  return message;
}

}  // namespace

CommandResult compute_listen(const job::Job& job, int threads, const Progress& progress) {
  if (job.recordings.empty())
    throw InputError("recording", 0,
                     "robomill listen needs a recording: section (or recordings: [...]) naming "
                     "the recorded signal");
  const int teeth = listen_teeth(job);
  const auto start = std::chrono::steady_clock::now();

  // The model's lobes, when the job describes the structure.
  std::optional<analysis::StabilityDiagram> diagram;
  std::optional<CommandResult> lobes;  // what `stability` writes: sld.csv and its method
  if (job.stability && job.tool && job.cutting && job.process) {
    diagram = analysis::stability_diagram(job, threads);
    lobes = stability_result(job, *diagram);
  }

  std::vector<Judged> judged;
  judged.reserve(job.recordings.size());
  AdviceRange range;
  for (std::size_t r = 0; r < job.recordings.size(); ++r)
    judged.push_back(judge_recording(job, r, teeth, diagram, progress, range));

  CommandResult result;
  const std::string power = power_column(judged);
  add_spectrum_tables(judged, power, result);

  nlohmann::json list = nlohmann::json::array();
  for (const Judged& j : judged)
    list.push_back(recording_json(j, teeth));
  if (job.recordings_listed)
    result.tables.emplace_back("recordings", recordings_table(judged));
  if (lobes) {
    result.tables.emplace_back("sld", *lobes->table("sld"));
  }

  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  result.summary = listen_summary(job, judged, list, range, power, lobes, elapsed_s);
  result.message = listen_message(judged);
  return result;
}

}  // namespace robomill::commands
