// The figures of `robomill listen`'s report (issue 22, docs/monitoring.md):
// the spectrogram with the onset, the spectrum with every line's cause
// marked (spindle and tooth comb, mains, ignored and steady lines, chatter),
// the recorded cuts on the predicted lobes, and the verdicts with the advice.

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

#include "detail.hpp"
#include "figure_helpers.hpp"

namespace robomill::report::detail {
namespace {

using json = nlohmann::json;

constexpr std::size_t kMaxSpectrumPoints = 6000;

struct CauseStyle {
  const char* cause;
  const char* label;
  const char* color;
  const char* symbol;
};
// Drawn over the grey PSD, one trace per cause (forced lines first).
constexpr CauseStyle kCauses[] = {
    {"spindle", "spindle harmonics", "#1f77b4", "line-ns-open"},
    {"tooth", "tooth-passing harmonics", "#2ca02c", "line-ns-open"},
    {"mains", "mains lines (set aside)", "#8c564b", "diamond-open"},
    {"ignored", "ignored lines (set aside)", "#7f7f7f", "diamond-open"},
    {"steady_line", "steady lines (set aside)", "#bcbd22", "diamond-open"},
    {"chatter", "chatter evidence", "#d62728", "circle"},
};

std::string text_of(const json& summary, const std::string& key) {
  if (!summary.contains(key))
    return "—";
  const json& v = summary[key];
  if (v.is_string())
    return v.get<std::string>();
  if (v.is_boolean())
    return v.get<bool>() ? "true" : "false";
  if (v.is_number())
    return display(v.get<double>());
  return "—";
}

void spectrum_figure(const Table& spectrum, const std::string& index, const json& recording,
                     Content& c) {
  const Table t = spectrum.has("recording") ? spectrum.where("recording", index) : spectrum;
  if (t.rows() == 0)
    return;
  const std::string power = t.columns().size() > 1 ? t.columns()[1] : "";
  const std::vector<double> f = t.numbers("freq_hz");
  const std::vector<double> p = t.numbers(power);
  const std::vector<std::string>& cause = t.text("cause");
  Figure fig = xy_figure(
      recording.value("file", std::string("recording")) + ": spectrum and what each line is",
      "frequency (Hz)", "power spectral density (" + column_unit(power) + ")");
  fig.layout["yaxis"]["type"] = "log";
  fig.layout["yaxis"]["exponentformat"] = "power";
  const std::vector<std::size_t> at = thin(f.size(), kMaxSpectrumPoints);
  std::vector<double> shown;
  for (std::size_t i : at)
    shown.push_back(p[i] > 0.0 ? p[i] : std::nan(""));
  json all = trace(pick(f, at), shown, "PSD");
  all["line"] = {{"color", "#999"}, {"width", 1}};
  fig.data.push_back(all);
  for (const CauseStyle& style : kCauses) {
    std::vector<double> x, y;
    for (std::size_t i = 0; i < f.size(); ++i)
      if (cause[i] == style.cause && p[i] > 0.0) {
        x.push_back(f[i]);
        y.push_back(p[i]);
      }
    if (x.empty())
      continue;
    const std::vector<std::size_t> keep = thin(x.size(), kMaxSpectrumPoints);
    json m = trace(pick(x, keep), pick(y, keep), style.label, "markers");
    m["marker"] = {{"color", style.color}, {"symbol", style.symbol}, {"size", 6}};
    fig.data.push_back(m);
  }
  const double chatter_hz = number_of(recording, "chatter_freq_hz");
  if (std::isfinite(chatter_hz)) {
    fig.layout["shapes"] = json::array({{{"type", "line"},
                                         {"xref", "x"},
                                         {"yref", "paper"},
                                         {"x0", rounded(chatter_hz)},
                                         {"x1", rounded(chatter_hz)},
                                         {"y0", 0},
                                         {"y1", 1},
                                         {"line", {{"color", "#d62728"}, {"dash", "dot"}}}}});
  }
  fig.caption = fmt::format(
      "Welch spectrum of the recording ({}). Each bin is attributed: the measured spindle "
      "frequency's harmonics (blue) and the tooth-passing comb (green) are the forced "
      "response; mains, ignored and steady lines are set aside; what stands above the floor "
      "elsewhere is chatter evidence (red). Verdict: {} — {}",
      recording.value("source", std::string("")), recording.value("verdict", std::string("")),
      recording.value("reason", std::string("")));
  c.figures.push_back(std::move(fig));
}

void spectrogram_figure(const Table& spectrogram, const std::string& index, const json& recording,
                        Content& c) {
  const Table t =
      spectrogram.has("recording") ? spectrogram.where("recording", index) : spectrogram;
  if (t.rows() == 0 || t.columns().size() < 3)
    return;
  const std::string power = t.columns()[2];
  const std::vector<double> time = t.numbers("t_s"), freq = t.numbers("freq_hz"),
                            p = t.numbers(power);
  // Rows are frame-major: the distinct times and frequencies in order.
  std::vector<double> times, freqs;
  for (std::size_t i = 0; i < time.size(); ++i) {
    if (times.empty() || time[i] != times.back())
      times.push_back(time[i]);
    if (times.size() == 1)
      freqs.push_back(freq[i]);
  }
  if (freqs.empty() || times.size() * freqs.size() != p.size())
    return;
  json z = json::array();
  for (std::size_t j = 0; j < freqs.size(); ++j) {
    std::vector<double> row;
    for (std::size_t i = 0; i < times.size(); ++i) {
      const double v = p[i * freqs.size() + j];
      row.push_back(v > 0.0 ? 10.0 * std::log10(v) : std::nan(""));
    }
    z.push_back(values(row));
  }
  Figure fig;
  fig.title = recording.value("file", std::string("recording")) + ": spectrogram";
  fig.data.push_back({{"type", "heatmap"},
                      {"x", values(times)},
                      {"y", values(freqs)},
                      {"z", z},
                      {"colorscale", "Viridis"},
                      {"colorbar", {{"title", "dB re 1 " + column_unit(power)}}}});
  fig.layout["xaxis"] = axis("time (s)");
  fig.layout["yaxis"] = axis("frequency (Hz)");
  const double onset = number_of(recording, "onset_s");
  if (std::isfinite(onset)) {
    fig.layout["shapes"] = json::array({{{"type", "line"},
                                         {"xref", "x"},
                                         {"yref", "paper"},
                                         {"x0", rounded(onset)},
                                         {"x1", rounded(onset)},
                                         {"y0", 0},
                                         {"y1", 1},
                                         {"line", {{"color", "#ff4136"}, {"width", 2}}}}});
  }
  fig.caption = "Short-time spectra over the recording (power in dB). " +
                (std::isfinite(onset)
                     ? fmt::format("The red line marks the chatter onset at {} s.", display(onset))
                     : std::string("No chatter onset."));
  c.figures.push_back(std::move(fig));
}

void lobes_figure(const Outputs& o, const json& recordings, Content& c) {
  const auto sld = o.table("sld.csv", c, false);
  if (!sld || !sld->has("spindle_rpm") || !sld->has("depth_limit_mm"))
    return;
  Figure fig =
      xy_figure("Recorded cuts on the predicted lobes", "spindle speed (rpm)", "axial depth (mm)");
  json lobe = trace(sld->numbers("spindle_rpm"), sld->numbers("depth_limit_mm"), "predicted limit");
  lobe["line"] = {{"color", "#1f77b4"}, {"width", 1.6}};
  fig.data.push_back(lobe);
  std::map<std::string, std::pair<std::vector<double>, std::vector<double>>> cuts;
  for (const json& r : recordings) {
    const double depth = number_of(r, "depth_mm");
    if (!std::isfinite(depth))
      continue;
    auto& [x, y] = cuts[r.value("verdict", std::string("unknown"))];
    x.push_back(number_of(r, "spindle_rpm_measured"));
    y.push_back(depth);
  }
  for (const auto& [verdict, xy] : cuts) {
    const bool chatter = verdict == "chatter", stable = verdict == "stable";
    json m = trace(xy.first, xy.second, "recorded: " + verdict, "markers");
    m["marker"] = {{"color", chatter  ? "#d62728"
                             : stable ? "#2ca02c"
                                      : "#7f7f7f"},
                   {"symbol", chatter  ? "x"
                              : stable ? "circle"
                                       : "question"},
                   {"size", 11}};
    fig.data.push_back(m);
  }
  fig.caption =
      "The job's predicted stability limit (sld.csv) with each recorded cut at its measured "
      "spindle speed and depth: red crosses chattered, green circles were stable.";
  c.figures.push_back(std::move(fig));
}

}  // namespace

void listen_figures(const Outputs& o, Content& c) {
  json recordings = o.summary.contains("recordings") && o.summary["recordings"].is_array()
                        ? o.summary["recordings"]
                        : json::array({o.summary});
  TextTable verdicts;
  verdicts.title = "Verdicts";
  verdicts.header = {"#",
                     "file",
                     "spindle (rpm, measured)",
                     "verdict",
                     "chatter (Hz)",
                     "chatter line fraction",
                     "once-per-rev. variance",
                     "onset (s)",
                     "try (rpm)",
                     "why"};
  for (std::size_t i = 0; i < recordings.size(); ++i) {
    const json& r = recordings[i];
    std::string advice;
    if (r.contains("recommended_spindle_rpm") && r["recommended_spindle_rpm"].is_array())
      for (std::size_t k = 0; k < std::min<std::size_t>(4, r["recommended_spindle_rpm"].size());
           ++k)
        advice += (k ? ", " : "") + display(r["recommended_spindle_rpm"][k].get<double>());
    verdicts.rows.push_back({std::to_string(i + 1), text_of(r, "file"),
                             text_of(r, "spindle_rpm_measured"), text_of(r, "verdict"),
                             text_of(r, "chatter_freq_hz"), text_of(r, "chatter_line_fraction"),
                             text_of(r, "once_per_revolution_variance"), text_of(r, "onset_s"),
                             advice.empty() ? "—" : advice, text_of(r, "reason")});
  }
  c.tables.push_back(std::move(verdicts));

  const auto spectrum = o.table("spectrum.csv", c, false);
  const auto spectrogram = o.table("spectrogram.csv", c, false);
  // At most four recordings get their own spectrogram and spectrum figures
  // (the rest are in the CSV files and the table).
  for (std::size_t i = 0; i < std::min<std::size_t>(4, recordings.size()); ++i) {
    const std::string index = std::to_string(i + 1);
    if (spectrogram)
      spectrogram_figure(*spectrogram, index, recordings[i], c);
    if (spectrum)
      spectrum_figure(*spectrum, index, recordings[i], c);
  }
  if (recordings.size() > 4)
    c.notes.push_back(
        fmt::format("Spectra of recordings 5 to {} are in spectrum.csv and "
                    "spectrogram.csv.",
                    recordings.size()));
  lobes_figure(o, recordings, c);
}

}  // namespace robomill::report::detail
