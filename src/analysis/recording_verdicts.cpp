#include "robomill/analysis/recording_verdicts.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <tuple>
#include <utility>

#include "robomill/core/constants.hpp"
#include "robomill/core/error.hpp"

namespace robomill::analysis {
namespace {

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

// The predicted limit and chatter frequency at a spindle speed, linear
// between the diagram's speeds (sorted); nullopt outside the diagram or where
// a speed has no finite limit.
std::optional<PredictedCut> predicted_at(const std::vector<StabilityLimit>& limits,
                                         double spindle_rad_s) {
  for (std::size_t i = 1; i < limits.size(); ++i) {
    const StabilityLimit &a = limits[i - 1], &b = limits[i];
    if (!(spindle_rad_s >= std::min(a.spindle_rad_s, b.spindle_rad_s) &&
          spindle_rad_s <= std::max(a.spindle_rad_s, b.spindle_rad_s)) ||
        a.spindle_rad_s == b.spindle_rad_s)
      continue;
    const double w = (spindle_rad_s - a.spindle_rad_s) / (b.spindle_rad_s - a.spindle_rad_s);
    PredictedCut p{(1.0 - w) * a.depth_limit_m + w * b.depth_limit_m,
                   (1.0 - w) * a.chatter_frequency_hz + w * b.chatter_frequency_hz};
    if (!std::isfinite(p.depth_limit_m) || !std::isfinite(p.chatter_hz))
      return std::nullopt;
    return p;
  }
  return std::nullopt;
}

// One recording judged: read and analysed (its progress bar staged as
// "listen i/n" when there are several), the advice for a chatter verdict,
// and the model's prediction at the measured speed when there is a diagram.
RecordingVerdict judge_recording(
    const job::Job& job, std::size_t r, int teeth, const std::optional<StabilityDiagram>& diagram,
    const std::function<void(const std::string& stage, double fraction)>& progress,
    std::string& basis) {
  const io::RecordingSpec& spec = job.recordings[r];
  RecordingVerdict j;
  j.recording = spec;
  j.teeth = teeth;
  j.commanded_spindle_rad_s = spec.spindle_rad_s ? *spec.spindle_rad_s : job.process->spindle_rad_s;
  j.depth_m = spec.depth_m;
  if (!j.depth_m && job.process && !job.recordings_listed)
    j.depth_m = job.process->axial_depth_m;
  // The job's detector settings (listen:, else the defaults) for this cut.
  monitoring::ListenOptions options =
      job.listen ? job.listen->detector : monitoring::ListenOptions{};
  options.commanded_spindle_hz = j.commanded_spindle_rad_s / kTwoPi;
  options.teeth = teeth;
  options.ignore = spec.ignore;
  if (!spec.tachometer.empty()) {
    j.tachometer = io::read_tachometer(spec);
    options.tachometer_spindle_hz = j.tachometer->spindle_hz;
  }
  const std::string stage = job.recordings.size() > 1
                                ? fmt::format("listen {}/{}", r + 1, job.recordings.size())
                                : std::string("listen");
  const auto bar = [&](double fraction) {
    if (progress)
      progress(stage, fraction);
  };
  options.progress = bar;
  const std::unique_ptr<monitoring::SignalSource> source = io::open_recording(spec);
  std::tie(j.advice_spindle_min_rad_s, j.advice_spindle_max_rad_s) =
      advice_range(job, j.commanded_spindle_rad_s, basis);
  judge_signal(*source, options, j.advice_spindle_min_rad_s / kTwoPi,
               j.advice_spindle_max_rad_s / kTwoPi, j);
  bar(1.0);
  if (diagram)
    j.prediction = predicted_at(diagram->primary(), j.analysis.spindle_hz_measured * kTwoPi);
  return j;
}

}  // namespace

void judge_signal(monitoring::SignalSource& source, const monitoring::ListenOptions& options,
                  double advice_min_hz, double advice_max_hz, RecordingVerdict& verdict) {
  verdict.signal = source.info();
  verdict.analysis = monitoring::analyze_recording(source, options);
  const monitoring::RecordingAnalysis& a = verdict.analysis;
  if (a.verdict == monitoring::Verdict::chatter && a.chatter_hz > 0.0)
    verdict.advice = monitoring::suggest_spindle_speeds(a.chatter_hz, options.teeth, advice_min_hz,
                                                        advice_max_hz);
}

RecordingVerdicts recording_verdicts(
    const job::Job& job, int threads,
    const std::function<void(const std::string& stage, double fraction)>& progress) {
  if (job.recordings.empty())
    throw InputError("recording", 0,
                     "robomill listen needs a recording: section (or recordings: [...]) naming "
                     "the recorded signal");
  const int teeth = listen_teeth(job);

  RecordingVerdicts result;
  // The model's lobes, when the job describes the structure.
  if (job.stability && job.tool && job.cutting && job.process)
    result.diagram = stability_diagram(job, threads);

  result.recordings.reserve(job.recordings.size());
  for (std::size_t r = 0; r < job.recordings.size(); ++r)
    result.recordings.push_back(
        judge_recording(job, r, teeth, result.diagram, progress, result.advice_range_basis));
  return result;
}

}  // namespace robomill::analysis
