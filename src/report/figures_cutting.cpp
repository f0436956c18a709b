// The figures of the cutting-process commands' reports: the cutting forces
// and their spectrum (`forces`), the time-domain simulation's forces,
// displacements and spectra (`simulate`), the tool's deflection over the
// axial depth (`deflection`) and the identified cutting law against the
// measured mean forces (`identify-cutting`). Split off figures.cpp.

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <string>
#include <vector>

#include "detail.hpp"

namespace robomill::report::detail {
namespace {

using nlohmann::json;

/// Colour `i` of `n` along Viridis (for sweeps: depth, speed).
std::string sequential(std::size_t i, std::size_t n) {
  static constexpr double stops[5][3] = {
      {68, 1, 84}, {59, 82, 139}, {33, 145, 140}, {94, 201, 98}, {253, 231, 37}};
  const double u = n > 1 ? 4.0 * static_cast<double>(i) / static_cast<double>(n - 1) : 0.0;
  const std::size_t a = std::min<std::size_t>(3, static_cast<std::size_t>(u));
  const double w = u - static_cast<double>(a);
  auto mix = [&](int c) {
    return static_cast<int>(std::lround(stops[a][c] * (1.0 - w) + stops[a + 1][c] * w));
  };
  return fmt::format("rgb({},{},{})", mix(0), mix(1), mix(2));
}

/// A log axis showing `decades` below the largest value (spectra span 15
/// decades of round-off below their peaks; what matters is near the top).
void log_range(json& axis_json, const std::vector<std::vector<double>>& series, double decades) {
  double peak = 0.0;
  for (const auto& v : series)
    for (double x : v)
      if (std::isfinite(x) && x > peak)
        peak = x;
  if (!(peak > 0.0))
    return;
  const double top = std::log10(peak) + 0.3;
  axis_json["range"] = {rounded(top - decades - 0.3), rounded(top)};
}

// A vertical dashed line at x on every row of a figure (a shape in paper y).
void vertical_marker(Figure& figure, double x, const std::string& label) {
  if (!std::isfinite(x))
    return;
  figure.layout["shapes"].push_back({{"type", "line"},
                                     {"xref", "x"},
                                     {"yref", "paper"},
                                     {"x0", rounded(x)},
                                     {"x1", rounded(x)},
                                     {"y0", 0},
                                     {"y1", 1},
                                     {"line", {{"color", "#888"}, {"dash", "dot"}, {"width", 1}}}});
  figure.layout["annotations"].push_back({{"x", rounded(x)},
                                          {"xref", "x"},
                                          {"y", 1},
                                          {"yref", "paper"},
                                          {"text", label},
                                          {"showarrow", false},
                                          {"yanchor", "bottom"},
                                          {"font", {{"size", 11}, {"color", "#555"}}}});
}

}  // namespace

void forces_figures(const Outputs& o, Content& c) {
  const auto t = o.table("forces.csv", c);
  if (!t)
    return;
  const std::string x = t->has("angle_deg") ? "angle_deg" : "t_s";
  const std::vector<double> xs = t->numbers(x);
  Figure f;
  f.title = "Cutting forces and spindle torque";
  f.caption = "Forces on the tool in the tool frame (x feed, z tool axis) over the spindle angle.";
  stack(f, axis_title(x), {"force (N)", "torque (N·m)"}, {2.0, 1.0});
  std::size_t k = 0;
  for (const char* col : {"fx_N", "fy_N", "fz_N"})
    if (t->has(col))
      f.data.push_back(line_trace(xs, t->numbers(col), column_quantity(col), k++));
  if (t->has("torque_Nm")) {
    json torque = line_trace(xs, t->numbers("torque_Nm"), "torque", 4);
    f.data.push_back(on_row(torque, 1));
  }
  c.figures.push_back(std::move(f));

  // Harmonic content: the amplitude spectrum of whole revolutions (a DFT
  // over the samples; bins are multiples of the spindle frequency).
  const std::vector<double> time = t->numbers("t_s");
  if (time.size() >= 8 && time.size() <= 20000) {
    const double dt = time[1] - time[0];
    const std::size_t n = time.size();
    if (dt > 0.0) {
      const double tooth_hz = summary_number(o.summary, "tooth_passing_hz");
      const double f_max = std::isfinite(tooth_hz) ? 12.5 * tooth_hz : 0.5 / dt;
      Figure s;
      s.title = "Force spectrum";
      s.caption =
          "Single-sided amplitude of each force component (DFT of the whole-revolution "
          "record); peaks at the tooth-passing frequency and its harmonics.";
      s.layout["xaxis"] = axis("frequency (Hz)");
      s.layout["yaxis"] = axis("amplitude (N)");
      s.layout["barmode"] = "group";
      std::size_t kk = 0;
      for (const char* col : {"fx_N", "fy_N", "fz_N"}) {
        if (!t->any_nonzero(col))
          continue;
        const std::vector<double> y = t->numbers(col);
        std::vector<double> freq, amplitude;
        for (std::size_t bin = 1; bin <= n / 2; ++bin) {
          const double fb = static_cast<double>(bin) / (static_cast<double>(n) * dt);
          if (fb > f_max)
            break;
          std::complex<double> sum = 0.0;
          for (std::size_t i = 0; i < n; ++i) {
            const double phase =
                -2.0 * std::numbers::pi * static_cast<double>(bin * i % n) / static_cast<double>(n);
            sum += (std::isfinite(y[i]) ? y[i] : 0.0) * std::polar(1.0, phase);
          }
          freq.push_back(fb);
          amplitude.push_back(2.0 * std::abs(sum) / static_cast<double>(n));
        }
        json bar = {{"type", "bar"},
                    {"name", column_quantity(col)},
                    {"x", values(freq)},
                    {"y", values(amplitude)},
                    {"marker", {{"color", color(kk++)}}}};
        s.data.push_back(bar);
      }
      if (!s.data.empty())
        c.figures.push_back(std::move(s));
    }
  }
}

void simulate_figures(const Outputs& o, Content& c) {
  const double chatter_hz = summary_number(o.summary, "chatter_freq_hz");
  if (const auto t = o.table("timeseries.csv", c)) {
    const std::vector<double> time = t->numbers("t_s");
    Figure f;
    f.title = "Forces and tool displacement over time";
    f.caption =
        "Time-domain simulation: cutting forces on the tool and the tool-tip "
        "displacement (tool frame).";
    stack(f, "time (s)", {"force (N)", "displacement (mm)"});
    std::size_t k = 0;
    for (const char* col : {"fx_N", "fy_N", "fz_N"})
      if (t->any_nonzero(col))
        f.data.push_back(line_trace(time, t->numbers(col), column_quantity(col), k++));
    k = 3;
    for (const char* col : {"x_mm", "y_mm", "z_mm"})
      if (t->any_nonzero(col)) {
        json d = line_trace(time, t->numbers(col), std::string("displacement ") + col[0], k++);
        f.data.push_back(on_row(d, 1));
      }
    if (f.data.empty())
      f.data.push_back(line_trace(time, t->numbers("fx_N"), "Fx", 0));
    c.figures.push_back(std::move(f));
  }
  if (const auto t = o.table("spectrum.csv", c, false)) {
    const std::string fcol = t->has("frequency_hz") ? "frequency_hz" : t->columns().front();
    const std::vector<double> freq = t->numbers(fcol);
    Figure f;
    f.title = "Spectra";
    f.caption = "Amplitude spectra of the steady part of the run (log scale).";
    stack(f, "frequency (Hz)", {"force amplitude (N)", "displacement amplitude (mm)"});
    f.layout["yaxis"]["type"] = "log";
    f.layout["yaxis2"]["type"] = "log";
    f.layout["yaxis"]["exponentformat"] = f.layout["yaxis2"]["exponentformat"] = "power";
    f.layout["yaxis"]["dtick"] = f.layout["yaxis2"]["dtick"] = 1;
    std::size_t k = 0;
    std::vector<std::vector<double>> forces_seen, displacements_seen;
    for (const char* col : {"fx_N", "fy_N", "fz_N"})
      if (t->any_nonzero(col)) {
        forces_seen.push_back(t->numbers(col));
        f.data.push_back(
            line_trace(freq, positive_or_gap(t->numbers(col)), column_quantity(col), k++));
      }
    k = 3;
    for (const char* col : {"x_mm", "y_mm", "z_mm"})
      if (t->any_nonzero(col)) {
        displacements_seen.push_back(t->numbers(col));
        json d = line_trace(freq, positive_or_gap(t->numbers(col)),
                            std::string("displacement ") + col[0], k++);
        f.data.push_back(on_row(d, 1));
      }
    log_range(f.layout["yaxis"], forces_seen, 6.0);
    log_range(f.layout["yaxis2"], displacements_seen, 6.0);
    if (std::isfinite(chatter_hz))
      vertical_marker(f, chatter_hz, fmt::format("chatter {} Hz", display(chatter_hz)));
    if (!f.data.empty())
      c.figures.push_back(std::move(f));
  }
}

void deflection_figures(const Outputs& o, Content& c) {
  const auto t = o.table("deflection.csv", c);
  if (!t)
    return;
  const std::vector<std::string> depths = t->distinct("ap_mm");
  Figure profile;
  profile.title = "Tool deflection along the tool";
  profile.caption = "Deflection of each tool node (z from the tip) for every axial depth ap.";
  stack(profile, "height above the tool tip z (mm)", {"deflection x (µm)", "deflection y (µm)"});
  std::size_t k = 0;
  for (const std::string& ap : depths) {
    const Table part = t->where("ap_mm", ap);
    char* end = nullptr;
    const std::string name = "ap " + display(std::strtod(ap.c_str(), &end)) + " mm";
    profile.data.push_back(line_trace(part.numbers("z_mm"), part.numbers("dx_um"), name, k));
    profile.data.back()["legendgroup"] = name;
    json dy = line_trace(part.numbers("z_mm"), part.numbers("dy_um"), name, k);
    dy["showlegend"] = false;
    dy["legendgroup"] = name;
    // A sweep: shallow to deep from purple to yellow.
    const std::string shade = sequential(k, depths.size());
    profile.data.back()["line"]["color"] = shade;
    dy["line"]["color"] = shade;
    profile.data.push_back(on_row(dy, 1));
    ++k;
  }
  c.figures.push_back(std::move(profile));
  const Table tip = t->where("node", "1");
  if (tip.rows() > 0) {
    Figure f;
    f.title = "Deflection and actual engagement over the axial depth";
    f.caption = "At the tool tip (node 1): deflection, actual radial depth and entry angle.";
    stack(f, "axial depth ap (mm)", {"tip deflection (µm)", "actual ae (mm)", "entry angle (°)"});
    const auto ap = tip.numbers("ap_mm");
    f.data.push_back(line_trace(ap, tip.numbers("dx_um"), "dx", 0));
    f.data.push_back(line_trace(ap, tip.numbers("dy_um"), "dy", 1));
    json ae = line_trace(ap, tip.numbers("ae_actual_mm"), "actual ae", 2);
    f.data.push_back(on_row(ae, 1));
    json entry = line_trace(ap, tip.numbers("entry_actual_deg"), "actual entry", 3);
    f.data.push_back(on_row(entry, 2));
    json nominal = line_trace(ap, tip.numbers("entry_nominal_deg"), "nominal entry", 7, "dash");
    f.data.push_back(on_row(nominal, 2));
    c.figures.push_back(std::move(f));
  }
}

void identify_cutting_figures(const Outputs& o, Content& c) {
  const auto t = o.table("fit.csv", c);
  if (!t)
    return;
  Figure f = xy_figure("Mean forces: measured and fitted", "feed per tooth (mm)", "mean force (N)");
  f.caption = "Markers: the measured mean forces; lines: the identified linear law.";
  const auto feed = t->numbers("feed_per_tooth_mm");
  std::vector<std::size_t> order(feed.size());
  for (std::size_t i = 0; i < order.size(); ++i)
    order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return feed[a] < feed[b]; });
  std::size_t k = 0;
  for (const char* axis_name : {"x", "y", "z"}) {
    const std::string measured = fmt::format("f{}_N", axis_name),
                      fitted = fmt::format("f{}_fit_N", axis_name);
    if (!t->has(measured))
      continue;
    f.data.push_back(marker_trace(feed, t->numbers(measured), "measured F" + std::string(axis_name),
                                  color(k), "circle", 8));
    if (t->has(fitted))
      f.data.push_back(line_trace(pick(feed, order), pick(t->numbers(fitted), order),
                                  "fitted F" + std::string(axis_name), k));
    ++k;
  }
  c.figures.push_back(std::move(f));
}

}  // namespace robomill::report::detail
